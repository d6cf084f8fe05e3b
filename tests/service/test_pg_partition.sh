#!/bin/sh
# A PostgreSQL queue that stops answering (the server paused with SIGSTOP,
# as a partition looks to a client whose packets are still acknowledged):
# the daemon keeps answering /healthz within bounded time (503, "ok":
# false), logs the queue's error, and after SIGCONT recovers: a job
# submitted then is done.  A real server started here, on loopback.
here=$(cd "$(dirname "$0")/.." && pwd)
: "${RS_BIN:=$(dirname "$here")/build/ringside}"
. "$here/lib.sh"
. "$here/service/svc_lib.sh"
. "$here/pg.sh"
trap 'exit 143' TERM INT HUP

# every process of the throwaway cluster: the postmaster and its children
pg_pids() {
    pm=$(head -1 "$PG_DIR/data/postmaster.pid") || return 1
    echo "$pm" $(pgrep -P "$pm")
}

t_stalled_server_does_not_stall_the_daemon() {
    pg_cont() { [ -n "${stopped:-}" ] && kill -CONT $stopped 2>/dev/null; pg_stop; }
    svc_pg_case pg_cont || return 1
    "$RS_BIN" record --ai --quiet --seconds 2 --seed 4 -o g.rsr || return 1
    # lease 6: statements time out after 2 s, a call waits at most 3 s
    svc_start a $SVC_FAST --queue "$PG_URI" --lease 6 || return 1
    id=$(svc_submit g.rsr) || return 1
    svc_wait_state "$id" done 30 || return 1
    stopped=$(pg_pids) || return 1
    kill -STOP $stopped
    start=$(date +%s)
    # 10 s paused, far past the statement timeout: every answer within 5 s
    for k in 1 2 3; do
        code=$(curl -s -m 5 -o h.json -w '%{http_code}' "$SVC_URL/healthz")
        [ "$code" != 000 ] || { echo "/healthz: no answer in 5 s while the server is paused"; return 1; }
        [ "$code" = 503 ] && [ "$(json_get ok <h.json)" = false ] || { echo "/healthz: $code $(cat h.json)"; return 1; }
    done
    while [ $(( $(date +%s) - start )) -lt 10 ]; do sleep 0.5; done
    kill -CONT $stopped
    stopped=
    grep -Eq "no answer in 3.0 s|could not reconnect" a.log || { cat a.log; return 1; }
    # recovered: the daemon's own handles reconnect, a new job is done
    id=$(svc_submit g.rsr) || return 1
    svc_wait_state "$id" done 30 || { cat a.log; return 1; }
    [ "$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/healthz")" = 200 ] || return 1
    svc_stop
}

t_run ${T_ONLY:-stalled_server_does_not_stall_the_daemon}
t_done
