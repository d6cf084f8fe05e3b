#!/bin/sh
# How long one replay takes through `ringside serve`, from upload to the
# finished video: unsplit or split into segments, with N workers.
#
#   tools/split-latency.sh [-w WORKERS] [-s SEGMENT_SECONDS] REPLAY [SERVE OPTIONS...]
#
# Starts a daemon of build/ringside on a free loopback port with a fresh
# data directory, uploads REPLAY, waits for the job to finish and prints one
# line: wall seconds from upload to "done", the video's frames, frames per
# second, and game seconds per wall second.  With -s > 0 it also prints
# the job's units (segments and join) as GET /jobs/N lists them.  The
# daemon is stopped and its directory removed at the end.
# docs/service.md ("Split jobs: measured") has the numbers it gave.
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
BIN=${RS_BIN:-$here/build/ringside}
workers=1 seg=0
while getopts w:s:h opt; do
    case $opt in
    w) workers=$OPTARG ;;
    s) seg=$OPTARG ;;
    h) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
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
# shellcheck disable=SC2086 # extra is a list of options
"$BIN" serve --listen 127.0.0.1:0 --data "$dir/data" --workers "$workers" --segment-seconds "$seg" \
    $extra >"$dir/serve.log" 2>&1 &
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
while :; do
    curl -sf "$url/jobs/$id" >"$dir/job.json" || { echo "split-latency: GET /jobs/$id failed" >&2; exit 1; }
    st=$(field state <"$dir/job.json")
    case $st in
    done) break ;;
    failed | cancelled) echo "split-latency: job $st: $(field error <"$dir/job.json")" >&2; exit 1 ;;
    esac
    sleep 0.5
done
t1=$(date +%s.%N)
frames=$(field frames_total <"$dir/job.json")
python3 - "$t0" "$t1" "$frames" "$workers" "$seg" "$replay" "$dir/job.json" <<'EOF'
import json, sys
t0, t1, frames, workers, seg, replay, job = sys.argv[1:]
wall = float(t1) - float(t0)
frames = int(frames)
print(f"{replay}: {frames} frames, {workers} worker(s), segment_seconds {seg}: {wall:.1f} s from upload to done, "
      f"{frames / wall:.1f} fps, {frames / 60 / wall:.2f}x real time")
j = json.load(open(job))
for u in j.get("segments") or []:
    print("  segment " + json.dumps(u, sort_keys=True))
if j.get("join"):
    print("  join " + json.dumps(j["join"], sort_keys=True))
EOF
