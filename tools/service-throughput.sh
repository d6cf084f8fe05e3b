#!/bin/sh
# Jobs per hour of `ringside serve` on this machine: starts a daemon with
# N workers on a fresh SQLite queue, submits the bundled demo replays
# (default size: 640x360 video, game drawn at 1280x720), waits until all
# are done and prints wall time, jobs/hour and frames/s.
#   tools/service-throughput.sh [WORKERS] [COPIES] [extra serve options...]
# docs/service.md records the results.
set -eu
workers=${1:-1}
copies=${2:-1}
[ $# -ge 2 ] && shift 2 || shift $#
src=$(cd "$(dirname "$0")/.." && pwd)
bin=${RS_BIN:-$src/build/ringside}
dir=$(mktemp -d "${TMPDIR:-/tmp}/ringside-tput-XXXXXX")
trap 'kill "$pid" 2>/dev/null; rm -rf "$dir"' EXIT
"$bin" serve --listen 127.0.0.1:0 --data "$dir/data" --workers "$workers" "$@" >"$dir/log" 2>&1 &
pid=$!
port=""
while [ -z "$port" ]; do
    sleep 0.2
    kill -0 "$pid" || { cat "$dir/log"; exit 1; }
    port=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\)\/.*/\1/p' "$dir/log")
done
url=http://127.0.0.1:$port
start=$(date +%s.%N)
ids="" frames=0 n=0
c=0
while [ $c -lt "$copies" ]; do
    for d in "$src"/demos/*.rsr; do
        r=$(curl -sf -X POST --data-binary @"$d" "$url/jobs?name=$(basename "$d")")
        ids="$ids $(echo "$r" | sed 's/.*"id":\([0-9]*\).*/\1/')"
        frames=$((frames + $(echo "$r" | sed 's/.*"frames_total":\([0-9]*\).*/\1/')))
        n=$((n + 1))
    done
    c=$((c + 1))
done
for id in $ids; do
    while :; do
        st=$(curl -sf "$url/jobs/$id" | sed 's/.*"state":"\([a-z]*\)".*/\1/')
        [ "$st" = done ] && break
        [ "$st" = failed ] && { echo "job $id failed"; curl -s "$url/jobs/$id"; exit 1; }
        sleep 1
    done
done
end=$(date +%s.%N)
awk -v s="$start" -v e="$end" -v n="$n" -v f="$frames" -v w="$workers" 'BEGIN {
    t = e - s
    printf "workers %d: %d jobs (%d frames) in %.1f s: %.1f jobs/hour, %.1f frames/s\n", w, n, f, t, n * 3600 / t, f / t
}'
grep ": done:" "$dir/log" | sed 's/^/  /'
