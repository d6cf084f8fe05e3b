#!/bin/sh
# Installs the Debian packages a make target needs, and nothing more.
#
#   tools/deps.sh GROUP...      e.g. tools/deps.sh build test
#
# Each group is a short package list (below).  A group whose packages are all
# present gets a stamp in $RS_DEPS_STAMPS (default build/deps), so the next
# call costs one file comparison.  Missing packages are installed with
# apt-get --no-install-recommends when we are root; otherwise the exact
# command is printed and we fail.  Set RS_NO_INSTALL=1 to only check.
set -eu

group_pkgs() {
    case "$1" in
    # compiler, GL headers, Mesa's EGL + llvmpipe, OSMesa fallback, GLFW window,
    # FFmpeg's libraries for video output (x264 and libvpx come with libavcodec),
    # OpenImageIO for image sequences and the reference resize; libpng for every
    # PNG; cairo and a DejaVu font for the benchmarks' charts; SQLite, libpq and
    # libmicrohttpd for the service (ringside serve); libswresample for movie
    # sound, libebur128 for loudness, OpenAL Soft for live sound
    build) echo "build-essential pkg-config libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri libosmesa6-dev libglfw3-dev libavformat-dev libavcodec-dev libavutil-dev libopenimageio-dev libpng-dev libcairo2-dev fonts-dejavu-core libsqlite3-dev libpq-dev libmicrohttpd-dev libswresample-dev libebur128-dev libopenal-dev" ;;
    # X server for the GLFW backend's tests (xvfb-run needs xauth); xdotool
    # presses keys in that window to prove a person can play; ffprobe (in
    # ffmpeg) is the independent player that checks our videos; xz packs the
    # GPU bundle (tools/gpu-bundle.sh, tests/test_gpu_bundle.sh); sox measures
    # and compares the soundtracks in the audio tests; glslangValidator (the
    # Khronos reference compiler) checks every shader variant; clang builds
    # the simulation a second time (its state hashes must equal gcc's);
    # systemd's systemd-analyze verifies the unit file make install writes;
    # python3 parses SVG, WAV and HTTP in the checks (not in a minimal image)
    # time: /usr/bin/time, the peak resident memory the flat-memory tests read
    test) echo "xvfb xauth xdotool ffmpeg xz-utils sox glslang-tools clang systemd python3 time" ;;
    # make test-service: a real PostgreSQL server for the two-daemon test,
    # Debian's Chromium for the dashboard test, driven by playwright-core,
    # which npm fetches and Node.js runs
    service) echo "postgresql chromium nodejs npm" ;;
    # make man checks every page it writes with groff -ww and mandoc -Tlint;
    # the docs test renders them with man -l
    man) echo "groff-base man-db mandoc" ;;
    # tools/gen-voice.sh: the announcer's lines, rendered once by espeak-ng
    voice) echo "espeak-ng" ;;
    *) echo "deps.sh: unknown group '$1' (known: build test service man voice)" >&2; return 1 ;;
    esac
}

[ $# -gt 0 ] || { echo "usage: tools/deps.sh GROUP..." >&2; exit 2; }
stamps=${RS_DEPS_STAMPS:-build/deps}

todo=""
for g in "$@"; do
    pkgs=$(group_pkgs "$g")
    if [ -f "$stamps/$g" ] && [ "$(cat "$stamps/$g")" = "$pkgs" ]; then
        touch "$stamps/$g" # newer than deps.sh again: make stops asking
        continue
    fi
    todo="$todo $g"
done
[ -n "$todo" ] || exit 0

if ! command -v dpkg-query >/dev/null 2>&1; then
    echo "deps.sh: no dpkg-query (not Debian?); make sure these are installed:" >&2
    for g in $todo; do echo "  $(group_pkgs "$g")" >&2; done
    exit 0
fi

missing=""
for g in $todo; do
    for p in $(group_pkgs "$g"); do
        # Node.js from its own packages (nodesource) carries npm and
        # conflicts with Debian's npm: any npm on PATH will do
        [ "$p" != npm ] || ! command -v npm >/dev/null 2>&1 || continue
        st=$(dpkg-query -W -f='${db:Status-Abbrev}' "$p" 2>/dev/null || true)
        case "$st" in ii*) ;; *) missing="$missing $p" ;; esac
    done
done

if [ -n "$missing" ]; then
    if [ "$(id -u)" != 0 ] || [ "${RS_NO_INSTALL:-0}" = 1 ]; then
        echo "deps.sh: missing Debian packages:$missing" >&2
        echo "deps.sh: install them with:" >&2
        echo "  sudo apt-get install -y --no-install-recommends$missing" >&2
        exit 1
    fi
    echo "deps.sh: installing$missing" >&2
    start=$(date +%s)
    export DEBIAN_FRONTEND=noninteractive
    # Package lists may be absent (fresh image) or stale: refresh once if the
    # first attempt cannot find or fetch something.
    if ! ls /var/lib/apt/lists/*_Packages >/dev/null 2>&1; then
        apt-get update -q >&2
    fi
    # shellcheck disable=SC2086
    if ! apt-get install -y -q --no-install-recommends $missing >&2; then
        apt-get update -q >&2
        apt-get install -y -q --no-install-recommends $missing >&2
    fi
    echo "deps.sh: installed in $(( $(date +%s) - start )) s" >&2
fi

mkdir -p "$stamps"
for g in $todo; do group_pkgs "$g" >"$stamps/$g"; done
