# Helpers for the service's end-to-end tests (sourced after tests/lib.sh).
#   svc_start NAME [serve options...]   starts `ringside serve` on a free
#       loopback port with data in ./NAME; sets SVC_URL and SVC_PID
#   svc_stop [PID]                      SIGTERM and wait (exit status kept in SVC_RC)
#   svc_submit FILE [QUERY]             prints the new job id
#   svc_field ID FIELD                  one field of GET /jobs/ID
#   svc_wait_state ID STATE [SECONDS]   until the job is in STATE (fails on failed)
#   svc_replays DIR N SECONDS           N short CPU replays (different seeds)
SVC_SRC=$(cd "$(dirname "$0")/../.." && pwd)
SVC_BIN_DIR=$(dirname "$RS_BIN")
SVC_PIDS=""
# what else a case must undo when it ends (pg_stop, say)
SVC_ON_EXIT=":"
svc_cleanup() {
    for p in $SVC_PIDS; do kill -KILL "$p" 2>/dev/null; done
    $SVC_ON_EXIT
}

# small and fast: the tests check the service, not the picture; and a job
# no longer than segment_seconds is one unit, as most cases expect (the
# growing plan's own cases, test_stream.sh, ask for it)
SVC_FAST="--render-size 160x90 --size 160x90 --lease 6 --log-level debug --first-segment-seconds 0"

json_get() { # FIELD < json
    python3 -c 'import json,sys
v = json.load(sys.stdin)
for k in sys.argv[1].split("."):
    v = v[int(k)] if isinstance(v, list) else v.get(k)
print("null" if v is None else (str(v).lower() if isinstance(v, bool) else v))' "$1"
}

svc_start() {
    name=$1
    shift
    mkdir -p "$name"
    "$RS_BIN" serve --listen 127.0.0.1:0 --data "$name" "$@" >>"$name.log" 2>&1 &
    SVC_PID=$!
    SVC_PIDS="$SVC_PIDS $SVC_PID"
    # every daemon a test case started dies with the case, whatever happened
    # (each case is a subshell: this trap is the case's own)
    trap svc_cleanup EXIT
    i=0
    while [ $i -lt 100 ]; do
        port=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\)\/.*/\1/p' "$name.log" | tail -1)
        if [ -n "$port" ] && curl -sf "http://127.0.0.1:$port/healthz" >/dev/null 2>&1; then
            SVC_URL="http://127.0.0.1:$port"
            return 0
        fi
        kill -0 "$SVC_PID" 2>/dev/null || { echo "daemon $name exited:"; cat "$name.log"; return 1; }
        sleep 0.1
        i=$((i + 1))
    done
    echo "daemon $name did not come up"
    cat "$name.log"
    return 1
}

svc_stop() {
    p=${1:-$SVC_PID}
    kill -TERM "$p" 2>/dev/null
    wait "$p"
    SVC_RC=$?
}

svc_submit() { # FILE [QUERY] -> id
    body=$(curl -s -X POST --data-binary @"$1" -H 'Content-Type: application/octet-stream' \
        "$SVC_URL/jobs?name=$(basename "$1")${2:+&$2}") || { echo "curl failed" >&2; return 1; }
    id=$(echo "$body" | json_get id 2>/dev/null)
    case "$id" in '' | null | *[!0-9]*) echo "submit $1 failed: $body" >&2; return 1 ;; esac
    echo "$id"
}

svc_field() { curl -sf "$SVC_URL/jobs/$1" | json_get "$2"; }

svc_wait_state() { # ID STATE [SECONDS]
    limit=${3:-120}
    start=$(date +%s)
    while :; do
        st=$(svc_field "$1" state 2>/dev/null)
        [ "$st" = "$2" ] && return 0
        if [ "$st" = failed ] && [ "$2" != failed ]; then
            echo "job $1 failed: $(svc_field "$1" error)"
            return 1
        fi
        if [ $(( $(date +%s) - start )) -ge "$limit" ]; then
            echo "job $1 is '$st' after ${limit} s, waiting for '$2'"
            curl -s "$SVC_URL/jobs/$1"
            return 1
        fi
        sleep 0.2
    done
}

# the render child of a daemon working on job ID (its replay path names the job)
svc_worker_pid() { # DAEMON_PID ID
    for c in $(pgrep -P "$1"); do
        if tr '\0' ' ' <"/proc/$c/cmdline" 2>/dev/null | grep -q "job$2-"; then
            echo "$c"
            return 0
        fi
    done
    return 1
}

svc_replays() { # DIR N SECONDS
    mkdir -p "$1"
    k=1
    while [ $k -le "$2" ]; do
        "$RS_BIN" record --ai --quiet --seconds "$3" --seed $((k * 11)) --stage $((k % 3)) -o "$1/r$k.rsr" || return 1
        k=$((k + 1))
    done
}

# ffprobe's count of decoded frames
frames_of() { ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 "$1"; }

# a split job's units, one line each: INDEX STATE ATTEMPTS RENDERS WORKER
# (INDEX "join" for the join; WORKER the slot that rendered it, or "-")
svc_units() { # ID
    curl -sf "$SVC_URL/jobs/$1" | python3 -c 'import json,sys
j = json.load(sys.stdin)
for s in j.get("segments", []):
    print(s["index"], s["state"], s["attempts"], s["renders"], s["worker"] or "-")
u = j.get("join")
if u:
    print("join", u["state"], u["attempts"], u["renders"], u["worker"] or "-")'
}

# nothing of job ID is left in the output directory but ID.fmt and
# ID.hashes (the sweep runs every 10 s: waits up to 15 s)
svc_no_leftovers() { # ID [OUTPUT_DIR]
    out=${2:-d/videos}
    i=0
    while ls -A "$out" | grep -q "^\.job$1-"; do
        sleep 0.5; i=$((i + 1))
        [ $i -lt 30 ] || { echo "job $1 left files:"; ls -laR "$out"; return 1; }
    done
}

# A case on a throwaway PostgreSQL server (tests/pg.sh): starts it, stops it
# when the case ends (ON_EXIT, default pg_stop, runs then), skips the case
# where PostgreSQL is not installed.  Sets PG_URI.
svc_pg_case() {
    pgdir=$(mktemp -d "${TMPDIR:-/tmp}/ringside-pg-XXXXXX") || return 1
    SVC_ON_EXIT=${1:-pg_stop}
    trap svc_cleanup EXIT
    pg_start "$pgdir"
    rc=$?
    [ "$rc" = 77 ] && t_skip_install "PostgreSQL is not installed (tools/deps.sh service installs it)"
    [ "$rc" = 0 ] || return 1
}
