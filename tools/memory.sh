#!/bin/sh
# tools/memory.sh [--minutes LIST] [--sound-minutes LIST] [--size WxH] BIN
#
# Peak resident memory against the replay's length, for the paths that run
# long: for each length in --minutes (default 1,10) a CPU-vs-CPU replay is
# recorded and rendered (`BIN render R -o x.mp4 --size WxH --jobs 1`, with
# sound), its resident memory sampled every 5 s as it goes and its peak
# taken by /usr/bin/time; for each length in --sound-minutes (default
# 1,10,60) `BIN replay sound R -o /dev/null` likewise.  docs/audio.md and
# docs/capture.md ("Memory") have what it printed.
#
#   tools/memory.sh build/ringside
#   tools/memory.sh --minutes 1 --sound-minutes 1,60 build/ringside
set -eu
minutes="1 10" sound="1 10 60" size=320x180
while [ $# -gt 0 ]; do
    case "$1" in
    --minutes) minutes=$(echo "$2" | tr , ' '); shift 2 ;;
    --sound-minutes) sound=$(echo "$2" | tr , ' '); shift 2 ;;
    --size) size=$2; shift 2 ;;
    -h | --help) sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "memory.sh: unknown option $1" >&2; exit 2 ;;
    *) break ;;
    esac
done
[ $# -eq 1 ] || { echo "usage: tools/memory.sh [--minutes LIST] [--sound-minutes LIST] [--size WxH] BIN" >&2; exit 2; }
bin=$1
[ -x /usr/bin/time ] || { echo "memory.sh: needs /usr/bin/time (Debian package time)" >&2; exit 1; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/memory-XXXXXX")
trap 'rm -rf "$tmp"' EXIT

replay() { # MINUTES -> path of a recorded replay of that length
    r=$tmp/m$1.rsr
    [ -f "$r" ] || "$bin" record --ai --quiet --seconds $(($1 * 60)) --seed 5 -o "$r"
    echo "$r"
}

# runs "$@" under /usr/bin/time, printing its resident memory every 5 s
sampled() {
    /usr/bin/time -f '%M %e' -o "$tmp/t" "$@" &
    pid=$!
    t=0
    while kill -0 $pid 2>/dev/null; do
        sleep 5
        t=$((t + 5))
        c=$(pgrep -P $pid | head -1 || true)
        [ -n "$c" ] && [ -r /proc/$c/status ] && awk -v t=$t '/^VmRSS/ { printf "    %4d s  %6.1f MB\n", t, $2 / 1024 }' /proc/$c/status
    done
    wait $pid
    read -r peak wall <"$tmp/t"
    awk -v p="$peak" -v w="$wall" 'BEGIN { printf "    peak %.1f MB, %s s\n", p / 1024, w }'
}

for m in $minutes; do
    r=$(replay "$m")
    echo "render, $m min, $size, --jobs 1, to .mp4 with sound:"
    sampled "$bin" render "$r" -o "$tmp/x.mp4" -y --quiet --size "$size" --jobs 1
done
for m in $sound; do
    r=$(replay "$m")
    echo "replay sound, $m min:"
    sampled "$bin" replay sound "$r" -o /dev/null -y
done
