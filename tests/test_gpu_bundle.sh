#!/bin/sh
# tools/gpu-bundle.sh: the bundle made for a bare GPU machine runs here on
# llvmpipe with the system's libraries hidden, so a library the bundle
# forgot is found here and not on the GPU machine (docs/benchmarks.md,
# "On a real GPU").
#
# Hiding: in a private mount namespace, /usr/lib/x86_64-linux-gnu (which is
# /lib/x86_64-linux-gnu too) is replaced by a folder holding only "the
# machine's GPU driver": Mesa's EGL vendor library and llvmpipe with their
# own dependencies, as NVIDIA's driver would be on the GPU machine.  Those
# dependencies include libc and other common libraries, which would hide a
# forgotten one, so the loader's own trace (LD_DEBUG=libs) is checked as
# well: every library ringside loads comes from the bundle, except the
# driver's own.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
export RINGSIDE_CACHE=off
B=$T_TMP/bundle
LIBDIR=/usr/lib/x86_64-linux-gnu

# the bundle is built once, with the fast compression (same layout)
build_bundle() {
    [ -x "$B/run" ] && return 0
    RS_BUNDLE_BUILD=${RS_BUNDLE_BUILD:-$SRC/build-gpu} "$SRC/tools/gpu-bundle.sh" "$B" --fast 2>bundle.log ||
        { cat bundle.log; return 1; }
}

# the driver's folder: the vendor library, the DRI driver, their closures
make_driver_dir() {
    drv=$1
    mkdir -p "$drv/dri"
    [ -e "$LIBDIR/libEGL_mesa.so.0" ] && [ -e "$LIBDIR/dri/swrast_dri.so" ] ||
        { echo "no Mesa EGL driver in $LIBDIR"; return 1; }
    cp -L "$LIBDIR/dri/swrast_dri.so" "$drv/dri/"
    for f in "$LIBDIR/libEGL_mesa.so.0" "$LIBDIR/dri/swrast_dri.so" /bin/sh /usr/bin/dirname; do
        echo "$f"
        ldd "$f" | sed -n 's/.*=> \(\/[^ ]*\) .*/\1/p; s/^[[:space:]]*\(\/[^ ]*\) .*/\1/p'
    done | sort -u | while read -r lib; do
        case "$lib" in "$LIBDIR"/dri/* | /bin/* | /usr/bin/*) continue ;; esac
        cp -L "$lib" "$drv/$(basename "$lib")"
    done
    # the loader by its usual name (/lib64/ld-linux-x86-64.so.2 points here)
    [ -e "$drv/ld-linux-x86-64.so.2" ] || { echo "no loader copied"; return 1; }
}

# hidden CMD...: CMD with LIBDIR replaced by the driver's folder
hidden() {
    unshare -m sh -c 'mount --bind "$0" '"$LIBDIR"' && exec "$@"' "$T_TMP/drv" "$@"
}

t_bundle_builds() {
    build_bundle || return 1
    size=$(du -sb "$B" | cut -f1)
    echo "bundle: $size bytes"
    [ "$size" -le $((60 * 1048576)) ] || { echo "over 60 MiB"; return 1; }
    for f in run payload.tar.xz MANIFEST.txt share/ringside/shaders share/ringside/stages share/ringside/demos/dojo.rsr; do
        [ -e "$B/$f" ] || { echo "missing $f"; return 1; }
    done
    grep -q "^libEGL.so.1 libegl1 " "$B/MANIFEST.txt" || { echo "no glvnd libEGL in the manifest"; return 1; }
    # no GPU driver, no OpenImageIO, no service libraries in the bundle
    if grep -Eq "^(libEGL_mesa|libEGL_nvidia|libOpenImageIO|libpq|libmicrohttpd|libsqlite3|libOSMesa|libglfw)" "$B/MANIFEST.txt"; then
        grep -E "^(libEGL_mesa|libEGL_nvidia|libOpenImageIO|libpq|libmicrohttpd|libsqlite3|libOSMesa|libglfw)" "$B/MANIFEST.txt"
        return 1
    fi
}

t_runs_with_system_libraries_hidden() {
    build_bundle || return 1
    unshare -m true 2>/dev/null || t_skip_env "no mount namespaces here (unshare -m): cannot hide the system's libraries"
    make_driver_dir "$T_TMP/drv" || return 1
    export RINGSIDE_BUNDLE_CACHE="$T_TMP/cache"
    "$B/run" version >ver.txt 2>err.txt || { cat err.txt; return 1; } # unpacks, outside the namespace
    # the hiding works: a system tool that needs more than libc fails inside
    if hidden ls / >/dev/null 2>&1; then
        echo "ls ran with $LIBDIR hidden: the hiding does not work"
        return 1
    fi
    hidden "$B/run" info >info.txt 2>err.txt || { cat err.txt; return 1; }
    grep -q "llvmpipe" info.txt || { cat info.txt; return 1; }
    grep -q "built backends  egl$" info.txt || { echo "not the bundle's EGL-only build:"; cat info.txt; return 1; }
    hidden "$B/run" smoke -o "$T_TMP/smoke.ppm" --size 160x90 >/dev/null 2>err.txt || { cat err.txt; return 1; }
    [ -s "$T_TMP/smoke.ppm" ] || { echo "smoke wrote nothing"; return 1; }
    # a short render through FFmpeg (x264) and the demos shipped in the bundle
    hidden "$B/run" render "$B/share/ringside/demos/dojo.rsr" --ticks 0:30 --size 160x90 --render-size 160x90 --quiet \
        -o "$T_TMP/short.mp4" --hashes "$T_TMP/bundle.h" 2>err.txt || { cat err.txt; return 1; }
    [ -s "$T_TMP/short.mp4" ] || { echo "no video"; return 1; }
    # the same frames as the system's build
    "$RS_BIN" render "$SRC/demos/dojo.rsr" --ticks 0:30 --size 160x90 --render-size 160x90 --quiet \
        -o /dev/null --hashes "$T_TMP/system.h" 2>err.txt || { cat err.txt; return 1; }
    cmp "$T_TMP/bundle.h" "$T_TMP/system.h" || { echo "the bundle's frames differ from build/ringside's"; return 1; }
}

# Whatever was hidden or not, the loader took every library from the bundle
# but the driver's own; a library with a bundle copy never came from
# elsewhere.
t_loads_only_bundle_libraries() {
    build_bundle || return 1
    export RINGSIDE_BUNDLE_CACHE="$T_TMP/cache"
    LD_DEBUG=libs "$B/run" render "$B/share/ringside/demos/dojo.rsr" --ticks 0:2 --size 64x36 --render-size 64x36 --quiet \
        -o "$T_TMP/t.mp4" 2>trace.txt || { tail -20 trace.txt; return 1; }
    # the launcher's shell and its tools trace too: keep the process that
    # became ringside, from the libraries its loader started with on
    awk '/calling init: / { p = $1; if (rs[p]) print $NF; else buf[p] = buf[p] $NF "\n"; next }
         /transferring control: / { p = $1; if (!rs[p]) buf[p] = ""; next }
         /initialize program: .*bin\/ringside/ { p = $1; rs[p] = 1; printf "%s", buf[p]; buf[p] = "" }' \
        trace.txt | sort -u >loaded.txt
    n=$(wc -l <loaded.txt)
    [ "$n" -gt 50 ] || { echo "only $n libraries in the loader's trace:"; head -20 trace.txt; return 1; }
    # the driver: Mesa's vendor library, the DRI driver and their closures
    for f in "$LIBDIR/libEGL_mesa.so.0" "$LIBDIR/dri/swrast_dri.so"; do
        basename "$f"
        ldd "$f" | sed -n 's/.*=> \(\/[^ ]*\) .*/\1/p' | xargs -n1 basename
    done | sort -u >driver.txt
    bad=0 outside=0
    while read -r lib; do
        case "$lib" in "$T_TMP/cache/"*) continue ;; esac
        outside=$((outside + 1))
        if [ -e "$T_TMP/cache/lib/$(basename "$lib")" ]; then
            echo "loaded from outside the bundle though bundled: $lib"
            bad=1
        fi
        grep -qxF "$(basename "$lib")" driver.txt ||
            { echo "loaded from outside the bundle and not the driver's: $lib"; bad=1; }
    done <loaded.txt
    echo "$n libraries loaded, $outside of them the driver's"
    [ "$bad" = 0 ]
}

# The campaign's dry run (tools/gpu-campaign.sh --quick, about 70 s here)
# through the bundle, from the source tree as on the GPU machine: every step
# runs and succeeds, and the report is what the device tool can bring back.
t_campaign_dry_run() {
    build_bundle || return 1
    export RINGSIDE_BUNDLE_CACHE="$T_TMP/cache"
    rep=$T_TMP/report
    (cd "$SRC" && RINGSIDE=$B/run "$SRC/tools/gpu-campaign.sh" "$rep" --quick) >out.txt 2>err.txt ||
        { tail -20 err.txt; return 1; }
    head -n 2 "$rep/summary.txt" | grep -q "llvmpipe" || { head -3 "$rep/summary.txt"; return 1; }
    n=$(find "$rep" -type f | wc -l)
    [ "$n" -le 8 ] || { echo "$n files in the report"; return 1; }
    for s in info smoke golden capture stages passes full-mp4 fp16 encoders upload; do
        line=$(sed -n '/^== steps/,$p' "$rep/summary.txt" | grep "^  $s ") ||
            { echo "step $s missing"; cat "$rep/summary.txt"; return 1; }
        # not skipped, timed out or failed; "N of M" with N = M; no golden outside
        if echo "$line" | grep -Eq "skipped \(deadline\)|timeout|failed\(|[1-9][0-9]* outside" ||
            echo "$line" | awk '{ for (i = 2; i < NF - 1; i++) if ($(i + 1) == "of" && $i != $(i + 2)) bad = 1 } END { exit !bad }'; then
            echo "step $s: $line"
            sed -n '/^== steps/,$p' "$rep/summary.txt"
            return 1
        fi
    done
    grep -q "ringside $B/run" "$rep/log.txt" || { echo "the campaign did not run the bundle"; head -5 "$rep/log.txt"; return 1; }
}

t_bad_usage() {
    expect_fail 2 "usage: tools/gpu-bundle.sh OUTDIR" "$SRC/tools/gpu-bundle.sh" || return 1
    expect_fail 2 "unknown option '--nope'" "$SRC/tools/gpu-bundle.sh" x --nope || return 1
}

t_run bundle_builds runs_with_system_libraries_hidden loads_only_bundle_libraries campaign_dry_run bad_usage
t_done
