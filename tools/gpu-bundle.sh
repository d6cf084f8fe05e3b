#!/bin/sh
# tools/gpu-bundle.sh OUTDIR [--fast]
#
# Builds, on this Debian machine, a self-contained ringside for a bare GPU
# machine that has a GPU driver and nothing else of ours (no package
# registry, no network): the device tool's NVIDIA machines
# (docs/benchmarks.md, "On a real GPU").
#
#   OUTDIR/run ARGS...        runs the bundled ringside (EGL + FFmpeg only)
#   OUTDIR/payload.tar.xz     bin/ringside and every shared library it needs,
#                             glibc's loader included, from this machine's
#                             Debian packages (MANIFEST.txt lists them)
#   OUTDIR/share/ringside     shaders, stages and demos (RINGSIDE_DATA)
#   OUTDIR/tools              gpu-campaign.sh
#
# The launcher unpacks the payload once into a private folder (never over
# /), then starts the binary through the bundled loader with the bundle's
# libraries first and the machine's GPU driver (found where NVIDIA's or
# Mesa's EGL vendor library lies) after them.  Nothing outside the bundle
# but the driver and its own dependencies is used; tests/test_gpu_bundle.sh
# checks that with the system's libraries hidden.
#
# --fast compresses with xz -0 instead of -9 (the test's bundle: same
# layout, built in seconds rather than minutes).
set -eu

usage() {
    echo "usage: tools/gpu-bundle.sh OUTDIR [--fast]" >&2
    echo "  builds the GPU machine's bundle in OUTDIR (docs/benchmarks.md, 'On a real GPU')" >&2
    exit 2
}
out="" level=-9
for a in "$@"; do
    case "$a" in
    --fast) level=-0 ;;
    -h | --help)
        sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'
        exit 0
        ;;
    -*) echo "gpu-bundle: unknown option '$a'" >&2; usage ;;
    *) [ -z "$out" ] || usage; out=$a ;;
    esac
done
[ -n "$out" ] || usage

src=$(cd "$(dirname "$0")/.." && pwd)
limit_mib=60
build=${RS_BUNDLE_BUILD:-$src/build-gpu}
say() { echo "gpu-bundle: $*" >&2; }
die() { say "$*"; exit 1; }

for tool in readelf xz tar ldd; do
    command -v "$tool" >/dev/null 2>&1 || die "needs '$tool' (binutils, xz-utils, tar, libc-bin)"
done
[ "$(uname -m)" = x86_64 ] || die "the GPU machines are x86-64; this machine is $(uname -m)"

# 1. the binary: EGL and FFmpeg only (no OpenImageIO, PostgreSQL, SQLite,
#    libmicrohttpd, GLFW, OSMesa: they would double the bundle)
mkdir -p "$build"
conf=$build/config.mk.new
RS_ONLY="egl ffmpeg" "$src/tools/configure.sh" >"$conf"
if cmp -s "$conf" "$build/config.mk"; then rm -f "$conf"; touch "$build/config.mk"; else mv "$conf" "$build/config.mk"; fi
grep -q "RS_HAVE_EGL" "$build/config.mk" || die "no EGL on this machine (tools/deps.sh build)"
grep -q "RS_HAVE_FFMPEG" "$build/config.mk" || die "no FFmpeg libraries on this machine (tools/deps.sh build)"
# a make that runs this (make test, make asan) must not pass its variables
# on: neither through MAKEFLAGS nor through the environment (make exports
# its command line's SAN=1 to the recipes, and so to the tests)
unset MAKEFLAGS MFLAGS MAKELEVEL SAN DEBUG OPT EXTRA_CFLAGS WERROR
say "building $build/ringside (EGL + FFmpeg)"
# the Makefile names a BUILD inside the tree relatively: so must the target
case "$build" in "$src"/*) target=${build#"$src"/}/ringside ;; *) target=$build/ringside ;; esac
make -C "$src" -s -j"$(nproc 2>/dev/null || echo 2)" BUILD="$build" ONLY="egl ffmpeg" SAN= DEBUG= OPT=-O2 \
    "$target" >&2 ||
    die "the build failed"

# 2. stage the tree: bin/, lib/ (the loader and the closure of every NEEDED)
mkdir -p "$out"
out=$(cd "$out" && pwd)
stage=$(mktemp -d "${TMPDIR:-/tmp}/gpu-bundle-XXXXXX")
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/bin" "$stage/lib"
cp "$build/ringside" "$stage/bin/ringside"
strip --strip-unneeded "$stage/bin/ringside" 2>/dev/null || true

# ldd lists the whole closure, the loader included; the GPU driver is not
# in it (libglvnd's libEGL.so.1 loads the vendor library at run time)
ldd "$build/ringside" >"$stage/ldd.txt" || die "ldd failed on $build/ringside"
if grep -q "not found" "$stage/ldd.txt"; then
    grep "not found" "$stage/ldd.txt" >&2
    die "the binary needs libraries this machine lacks"
fi
loader=""
while read -r line; do
    case "$line" in
    *"=> /"*) path=${line#*=> }; path=${path%% (*} ;;
    /*) path=${line%% (*} ;;
    *) continue ;;
    esac
    name=$(basename "$path")
    case "$name" in ld-linux-x86-64.so.2) loader=$name ;; esac
    cp -L "$path" "$stage/lib/$name"
    pkg=$(dpkg -S "$path" 2>/dev/null | head -1 | cut -d: -f1 || true)
    [ -n "$pkg" ] || pkg=$(dpkg -S "$(readlink -f "$path")" 2>/dev/null | head -1 | cut -d: -f1 || true)
    ver=$( [ -n "$pkg" ] && dpkg-query -W -f='${Version}' "$pkg" 2>/dev/null || echo "?")
    printf '%s %s %s %s\n' "$name" "${pkg:-?}" "$ver" "$(wc -c <"$stage/lib/$name")" >>"$stage/libs.txt"
done <"$stage/ldd.txt"
[ -n "$loader" ] || die "no ld-linux-x86-64.so.2 in ldd's list"
# libglvnd's EGL (libEGL.so.1, libGLdispatch.so.0) comes from Debian's libegl1
# and libglvnd0; the vendor's library (NVIDIA's libEGL_nvidia.so.0, Mesa's
# libEGL_mesa.so.0) is the machine's
[ -f "$stage/lib/libEGL.so.1" ] || die "libEGL.so.1 is not in the closure"
! ls "$stage/lib" | grep -Eq '^lib(asan|ubsan|tsan|lsan)\.' || die "$build/ringside is a sanitizer build: remove $build"
for f in "$stage/lib/"*; do strip --strip-unneeded "$f" 2>/dev/null || true; done

# every NEEDED of every file must be in lib/ (the check the launcher's
# private search path relies on)
missing=""
for f in "$stage/bin/ringside" "$stage/lib/"*; do
    for n in $(readelf -d "$f" 2>/dev/null | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
        [ -f "$stage/lib/$n" ] || missing="$missing $(basename "$f"):$n"
    done
done
[ -z "$missing" ] || die "libraries needed but not bundled:$missing"

# 3. the payload and the rest
rm -rf "$out/share" "$out/tools"
rm -f "$out/payload.tar.xz" "$out/run" "$out/MANIFEST.txt"
say "compressing the payload (xz $level)"
(cd "$stage" && tar -cf - bin lib) | xz "$level" -T0 >"$out/payload.tar.xz.part"
mv "$out/payload.tar.xz.part" "$out/payload.tar.xz"
# share/ringside is RINGSIDE_DATA, laid out as `make install` does (bench
# capture finds its demo there)
mkdir -p "$out/share/ringside/demos" "$out/tools"
cp -r "$src/shaders" "$src/stages" "$out/share/ringside/"
cp "$src/demos/"*.rsr "$out/share/ringside/demos/"
[ -f "$src/tools/gpu-campaign.sh" ] && cp "$src/tools/gpu-campaign.sh" "$out/tools/"
id=$(sha256sum "$out/payload.tar.xz" | cut -c1-16)

cat >"$out/run" <<EOF
#!/bin/sh
# ringside from a bundle made by tools/gpu-bundle.sh; payload $id.
# Usage: run ARGS...  (the ringside command line).  Environment:
#   RINGSIDE_BUNDLE_CACHE  where the payload is unpacked (default \${TMPDIR:-/tmp}/ringside-bundle-$id)
#   RINGSIDE_DRIVER_DIRS   colon-separated folders holding the GPU driver's libraries
#                          (default: found from libEGL_nvidia.so.0 / libEGL_mesa.so.0)
#   RINGSIDE_BUNDLE_TRACE=1  print the command and the library path
set -eu
b=\$(cd "\$(dirname "\$0")" && pwd)
id=$id
cache=\${RINGSIDE_BUNDLE_CACHE:-\${TMPDIR:-/tmp}/ringside-bundle-\$id}
if [ ! -f "\$cache/.complete" ]; then
    tmp="\$cache.tmp.\$\$"
    rm -rf "\$tmp"
    mkdir -p "\$tmp"
    if command -v xz >/dev/null 2>&1; then
        xz -dc "\$b/payload.tar.xz" | tar -xf - -C "\$tmp"
    elif command -v python3 >/dev/null 2>&1; then
        python3 -c 'import sys, tarfile; tarfile.open(sys.argv[1], "r:xz").extractall(sys.argv[2])' "\$b/payload.tar.xz" "\$tmp"
    else
        echo "run: cannot unpack \$b/payload.tar.xz: neither xz nor python3 here" >&2
        exit 1
    fi
    touch "\$tmp/.complete"
    mkdir -p "\$(dirname "\$cache")"
    mv "\$tmp" "\$cache" 2>/dev/null || { rm -rf "\$tmp"; [ -f "\$cache/.complete" ] || exit 1; }
fi
# the GPU driver: the folders of the EGL vendor libraries, then of NVIDIA's others
drivers=\${RINGSIDE_DRIVER_DIRS:-}
if [ -z "\$drivers" ]; then
    for d in /usr/local/nvidia/lib64 /usr/local/nvidia/lib /usr/lib/x86_64-linux-gnu /usr/lib64 /lib/x86_64-linux-gnu /usr/lib; do
        for v in libEGL_nvidia.so.0 libEGL_mesa.so.0; do
            if [ -e "\$d/\$v" ]; then
                case ":\$drivers:" in *":\$d:"*) ;; *) drivers="\$drivers\${drivers:+:}\$d" ;; esac
            fi
        done
    done
    # elsewhere: where the machine's loader cache says
    if [ -z "\$drivers" ] && command -v ldconfig >/dev/null 2>&1; then
        f=\$(ldconfig -p 2>/dev/null | sed -n 's/.*libEGL_nvidia\.so\.0 .*=> //p' | head -1)
        [ -z "\$f" ] || drivers=\$(dirname "\$f")
    fi
fi
# libglvnd looks for vendor files in /usr/share and /etc; NVIDIA's may lie
# beside the driver instead
if [ -z "\${__EGL_VENDOR_LIBRARY_FILENAMES:-}\${__EGL_VENDOR_LIBRARY_DIRS:-}" ]; then
    vdirs=""
    for d in /usr/share/glvnd/egl_vendor.d /etc/glvnd/egl_vendor.d /usr/local/nvidia/share/glvnd/egl_vendor.d \\
        /usr/local/share/glvnd/egl_vendor.d; do
        for j in "\$d"/*.json; do
            [ -e "\$j" ] && vdirs="\$vdirs\${vdirs:+:}\$d"
            break
        done
    done
    [ -z "\$vdirs" ] || export __EGL_VENDOR_LIBRARY_DIRS="\$vdirs"
fi
export RINGSIDE_DATA="\${RINGSIDE_DATA:-\$b/share/ringside}"
path="\$cache/lib\${drivers:+:\$drivers}"
[ "\${RINGSIDE_BUNDLE_TRACE:-0}" = 0 ] || echo "run: \$cache/lib/$loader --library-path \$path \$cache/bin/ringside \$*" >&2
exec "\$cache/lib/$loader" --library-path "\$path" "\$cache/bin/ringside" "\$@"
EOF
chmod 755 "$out/run"

{
    echo "ringside GPU bundle, made by tools/gpu-bundle.sh on $(date -u +%Y-%m-%dT%H:%MZ)"
    echo "source: $(git -C "$src" describe --always --dirty 2>/dev/null || echo unknown)"
    echo "built on: $(. /etc/os-release && echo "$PRETTY_NAME"), $(ldd --version | head -1)"
    echo "payload: payload.tar.xz (xz $level), id $id"
    echo
    echo "library package version bytes"
    sort "$stage/libs.txt"
} >"$out/MANIFEST.txt"

total=$(du -sb "$out" | cut -f1)
nlib=$(wc -l <"$stage/libs.txt")
unpacked=$(du -sb "$stage/bin" "$stage/lib" | awk '{s += $1} END {print s}')
say "$out: $(awk -v b="$total" 'BEGIN {printf "%.1f MiB", b / 1048576}') ($nlib libraries, $(awk -v b="$unpacked" 'BEGIN {printf "%.0f MiB", b / 1048576}') unpacked)"
[ "$total" -le $((limit_mib * 1048576)) ] || die "the bundle is over $limit_mib MiB"
