#!/bin/sh
# tools/realtime.sh [--quality Q] [--demos LIST] [--ticks A:B] [--runs N] BIN [BIN...]
#
# The default job, whole, per demo: `BIN render demos/D.rsr -o OUT.mp4
# --quality Q` (sound, the default encoder, the default --jobs), timed with
# /usr/bin/time: wall seconds, x real time (the video's length / wall),
# and CPU seconds per second of video ((user + sys) / the video's length).
# With several BINs (an old build and a new one) each demo is rendered by
# each in turn, so a machine that drifts slows both alike, and a ratio
# column compares each BIN's wall time with the first's.  --runs N repeats
# every render N times and reports the median wall and CPU.
# docs/benchmarks.md ("Real time without a GPU") has what it printed.
#
#   tools/realtime.sh build/ringside                      every demo, standard
#   tools/realtime.sh --quality draft --demos dojo,temple old/ringside build/ringside
set -eu
quality=standard demos="dojo harbor mistvale plaza quarry shallows snowfield temple" ticks="" runs=1
while [ $# -gt 0 ]; do
    case "$1" in
    --quality) quality=$2; shift 2 ;;
    --demos) demos=$(echo "$2" | tr , ' '); shift 2 ;;
    --ticks) ticks=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    -h | --help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "realtime.sh: unknown option $1" >&2; exit 2 ;;
    *) break ;;
    esac
done
[ $# -ge 1 ] || { echo "usage: tools/realtime.sh [--quality Q] [--demos LIST] [--ticks A:B] [--runs N] BIN..." >&2; exit 2; }
here=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/realtime-XXXXXX")
trap 'rm -rf "$tmp"' EXIT
command -v /usr/bin/time >/dev/null 2>&1 || { echo "realtime.sh: needs /usr/bin/time (Debian package time)" >&2; exit 1; }

printf '%-10s %6s  %-28s %8s %8s %10s %8s\n' demo frames build "wall s" "x real" "cpu s/s" "vs first"
for d in $demos; do
    rp=$here/demos/$d.rsr
    n=$("$1" replay info "$rp" | sed -n 's/^duration *\([0-9]*\) ticks.*/\1/p')
    [ -z "$ticks" ] || n=$((${ticks#*:} - ${ticks%:*}))
    first=""
    for bin in "$@"; do
        : >"$tmp/w" && : >"$tmp/c"
        r=0
        while [ $r -lt "$runs" ]; do
            /usr/bin/time -f '%e %U %S' -o "$tmp/t" "$bin" render "$rp" -o "$tmp/out.mp4" -y --quiet --quality "$quality" \
                ${ticks:+--ticks "$ticks"} || { echo "realtime.sh: $bin failed on $d" >&2; exit 1; }
            read -r wall user sys <"$tmp/t"
            echo "$wall" >>"$tmp/w"
            awk -v u="$user" -v s="$sys" 'BEGIN { print u + s }' >>"$tmp/c"
            r=$((r + 1))
        done
        wall=$(sort -n "$tmp/w" | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')
        cpu=$(sort -n "$tmp/c" | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }')
        [ -n "$first" ] || first=$wall
        awk -v d="$d" -v n="$n" -v b="$bin" -v w="$wall" -v c="$cpu" -v f="$first" 'BEGIN {
            v = n / 60; printf "%-10s %6d  %-28s %8.1f %8.2f %10.2f %8.2f\n", d, n, substr(b, length(b) > 28 ? length(b) - 27 : 1), w, v / w, c / v, w / f }'
    done
done
