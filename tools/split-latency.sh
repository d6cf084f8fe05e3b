#!/bin/sh
# How long one replay takes through `ringside serve`, from upload to the
# first piece of its live stream and to the finished video: unsplit or
# split into segments, with N workers.
#
#   tools/split-latency.sh [-w WORKERS] [-s SEGMENT_SECONDS] [-f FIRST_SECONDS] [-1] REPLAY [SERVE OPTIONS...]
#
# Starts a daemon of build/ringside on a free loopback port with a fresh
# data directory, uploads REPLAY, waits for the job to finish and prints one
# line: wall seconds from upload to the first piece listed in
# GET /jobs/N/stream.m3u8 (time to first frame; "no stream" from a daemon
# without one), from upload to "done", the video's frames, frames per
# second, and game seconds per wall second.  It also prints the job's
# units (segments and join) as GET /jobs/N lists them, and with
# --files queue how long storing their files in the queue took.  -f sets
# first_segment_seconds (default: the daemon's, 2); -1 stops at the first
# piece and prints only its time.  The daemon is stopped
# and its directory removed at the end.  docs/service.md ("Throughput",
# "Watching while it renders") has the numbers it gave.
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
BIN=${RS_BIN:-$here/build/ringside}
workers=1 seg=0 first="" only_first=""
while getopts w:s:f:1h opt; do
    case $opt in
    1) only_first=1 ;;
    w) workers=$OPTARG ;;
    s) seg=$OPTARG ;;
    f) first="--first-segment-seconds $OPTARG" ;;
    h) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) exit 2 ;;
    esac
done
shift $((OPTIND - 1))
replay=${1:-}
[ -n "$replay" ] && [ -f "$replay" ] || { echo "split-latency: give a replay file" >&2; exit 2; }
shift
extra="$*" # the rest goes to serve

dir=$(mktemp -d "${TMPDIR:-/tmp}/ringside-latency-XXXXXX")
pid=""
cleanup() {
    [ -n "$pid" ] && kill -TERM "$pid" 2>/dev/null && wait "$pid" 2>/dev/null
    rm -rf "$dir"
}
trap cleanup EXIT INT TERM
# shellcheck disable=SC2086 # extra and first are lists of options
"$BIN" serve --listen 127.0.0.1:0 --data "$dir/data" --workers "$workers" --segment-seconds "$seg" \
    $first $extra >"$dir/serve.log" 2>&1 &
pid=$!
url=""
for _ in $(seq 200); do
    port=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\)\/.*/\1/p' "$dir/serve.log" | tail -1)
    if [ -n "$port" ] && curl -sf "http://127.0.0.1:$port/healthz" >/dev/null 2>&1; then
        url="http://127.0.0.1:$port"
        break
    fi
    kill -0 "$pid" 2>/dev/null || { cat "$dir/serve.log" >&2; exit 1; }
    sleep 0.1
done
[ -n "$url" ] || { echo "split-latency: the daemon did not come up" >&2; cat "$dir/serve.log" >&2; exit 1; }

field() { python3 -c 'import json,sys; v=json.load(sys.stdin).get(sys.argv[1]); print("" if v is None else v)' "$1"; }
t0=$(date +%s.%N)
id=$(curl -sf -X POST --data-binary @"$replay" -H 'Content-Type: application/octet-stream' \
    "$url/jobs?name=$(basename "$replay")" | field id)
[ -n "$id" ] || { echo "split-latency: upload refused" >&2; exit 1; }
tf="" # the first piece's time: polled every 0.1 s until it comes
while :; do
    if [ -z "$tf" ] && curl -sf "$url/jobs/$id/stream.m3u8" 2>/dev/null | grep -q '\.ts$'; then
        tf=$(date +%s.%N)
        if [ -n "$only_first" ]; then
            python3 -c 'import sys; print(f"{sys.argv[3]}: {float(sys.argv[1]) - float(sys.argv[2]):.1f} s to the first piece")' \
                "$tf" "$t0" "$replay"
            exit 0
        fi
    fi
    curl -sf "$url/jobs/$id" >"$dir/job.json" || { echo "split-latency: GET /jobs/$id failed" >&2; exit 1; }
    st=$(field state <"$dir/job.json")
    case $st in
    done) break ;;
    failed | cancelled) echo "split-latency: job $st: $(field error <"$dir/job.json")" >&2; exit 1 ;;
    esac
    if [ -z "$tf" ]; then sleep 0.1; else sleep 0.5; fi
done
t1=$(date +%s.%N)
frames=$(field frames_total <"$dir/job.json")
python3 - "$t0" "$t1" "$frames" "$workers" "$seg" "$replay" "$dir/job.json" "${tf:-none}" <<'EOF'
import json, sys
t0, t1, frames, workers, seg, replay, job, tf = sys.argv[1:]
wall = float(t1) - float(t0)
frames = int(frames)
first = "no stream" if tf == "none" else f"{float(tf) - float(t0):.1f} s to the first piece"
print(f"{replay}: {frames} frames, {workers} worker(s), segment_seconds {seg}: {first}, {wall:.1f} s from upload to done, "
      f"{frames / wall:.1f} fps, {frames / 60 / wall:.2f}x real time")
j = json.load(open(job))
for u in j.get("segments") or []:
    print("  segment " + json.dumps(u, sort_keys=True))
if j.get("join"):
    print("  join " + json.dumps(j["join"], sort_keys=True))
EOF
# a daemon that keeps the units' files in its queue (files = queue) says how long each store took
kept=$(sed -n 's/.*kept in the queue in \([0-9]*\) ms.*/\1/p' "$dir/serve.log")
[ -z "$kept" ] || echo "$kept" | awk '{n++; t+=$1; if ($1 > m) m=$1} END {printf "  kept in the queue: %d units, %d ms in all, at most %d ms\n", n, t, m}'

