#!/bin/sh
# Crash bookkeeping (docs/service.md): daemons killed with SIGKILL at
# random moments charge no attempt and leave no file behind; a render that
# always fails still ends in the dead letter; retention and DELETE remove
# finished jobs' files.
. "$(dirname "$0")/../lib.sh"
. "$(dirname "$0")/svc_lib.sh"

# the hidden, partial and work files left in data directory D: one a line
crash_leftovers() { # D
    { ls -A "$1/work" 2>/dev/null | sed "s|^|$1/work/|"; ls -A "$1/videos" | grep '^\.' | sed "s|^|$1/videos/|"
      find "$1" -name '*.part'; } | sort -u
}

# Starts a daemon on d, lets it run for a while, SIGKILLs it; KILLS times,
# the moments drawn from awk's generator with SEED (the same run each time).
# A kill waits, past its moment, until the daemon has files of its own on
# disk (a render under way: up to 10 s more), so that every kill lands in
# the middle of work however fast the renders have become: with the
# renders of 2026-11-29 the jobs were all done before the fourth kill.
crash_kill_run() { # KILLS SEED [serve options...]
    kills=$1 seed=$2
    shift 2
    for delay in $(awk -v n="$kills" -v s="$seed" 'BEGIN { srand(s); for (i = 0; i < n; i++) printf "%.1f ", 1 + 4 * rand() }'); do
        svc_start d $SVC_FAST "$@" || return 1
        sleep "$delay"
        w=0
        while [ $w -lt 100 ] && ! crash_leftovers d | grep -q -- "-$SVC_PID-"; do
            sleep 0.1
            w=$((w + 1))
        done
        kill -KILL "$SVC_PID"
        wait "$SVC_PID" 2>/dev/null
        echo "killed the daemon after $delay s"
    done
}

# CRASH_JOBS, CRASH_KILLS, CRASH_SEED and CRASH_MAX_ATTEMPTS make the larger
# run of docs/service.md; its figures go to the file CRASH_REPORT names
t_random_kills_charge_nothing_and_leave_nothing() {
    n=${CRASH_JOBS:-8} kills=${CRASH_KILLS:-4} seed=${CRASH_SEED:-21} cap=${CRASH_MAX_ATTEMPTS:-1}
    # 6 s replays: enough work that the last daemon killed has some (3 s
    # ones were all rendered before it by 2026-11-29's renderer)
    svc_replays r "$n" 6 || return 1
    svc_start d $SVC_FAST --workers 2 || return 1
    ids="" k=1
    while [ $k -le "$n" ]; do ids="$ids $(svc_submit r/r$k.rsr)" || return 1; k=$((k + 1)); done
    svc_stop
    crash_kill_run "$kills" "$seed" --workers 2 --max-attempts "$cap" || return 1
    # what the last killed daemon left: its pid in every name
    dead=$SVC_PID
    before=$(crash_leftovers d | wc -l)
    crash_leftovers d | grep -q -- "-$dead-" || { echo "the kill left nothing: the case tests nothing"; return 1; }
    svc_start d $SVC_FAST --workers 2 --max-attempts "$cap" || return 1
    # swept at start-up, though the jobs they belong to are not over yet
    if crash_leftovers d | grep -- "-$dead-"; then echo "the dead daemon's files survived the start-up"; return 1; fi
    bad=0 failed=0 charged=0 lost=0
    for id in $ids; do
        svc_wait_state "$id" done 300 || { bad=1; failed=$((failed + 1)); }
        a=$(svc_field "$id" attempts) l=$(svc_field "$id" lost_leases)
        charged=$((charged + a))
        [ "$l" = null ] || lost=$((lost + l))
        [ "$a" = 1 ] || { echo "job $id: attempts $a, want 1 (a daemon crash charged it)"; bad=1; }
    done
    grep "re-queued\|lost its daemon" d.log
    left=$(crash_leftovers d)
    [ -z "$left" ] || { echo "leftover files after the last restart:"; echo "$left"; bad=1; }
    svc_stop
    [ -z "$(crash_leftovers d)" ] || { echo "leftovers after the drain:"; crash_leftovers d; bad=1; }
    figures="$n jobs, $kills kills, max_attempts $cap: $failed failed, $charged attempts charged, $lost leases lost,"
    figures="$figures $before leftover files before the last restart, $(crash_leftovers d | wc -l) after it and the drain"
    echo "$figures"
    [ -z "${CRASH_REPORT:-}" ] || echo "$figures" >>"$CRASH_REPORT"
    return $bad
}

t_lost_daemon_is_bounded() {
    # a job whose unit keeps losing its daemon is failed at SVC_LOST_MAX
    # lost leases, with a true reason (the count is made to look as if
    # nine daemons had died under it already)
    "$RS_BIN" record --ai --quiet --seconds 20 --seed 4 -o long.rsr || return 1
    svc_start d $SVC_FAST --max-attempts 1 || return 1
    id=$(svc_submit long.rsr) || return 1
    svc_wait_state "$id" running 30 || return 1
    kill -KILL "$SVC_PID"
    wait "$SVC_PID" 2>/dev/null
    [ "$(sqlite3 d/queue.db "SELECT lost FROM units WHERE job_id = $id")" = 0 ] || return 1
    sqlite3 d/queue.db "UPDATE units SET lost = 9 WHERE job_id = $id" || return 1
    svc_start d $SVC_FAST --max-attempts 1 || return 1
    [ "$(svc_field "$id" state)" = failed ] || { curl -s "$SVC_URL/jobs/$id"; return 1; }
    [ "$(svc_field "$id" error)" = "lost its daemon 10 times (lease expired)" ] || { svc_field "$id" error; return 1; }
    [ "$(svc_field "$id" lost_leases)" = 10 ] || return 1
    grep -q "job $id: failed: lost its daemon 10 times" d.log || { cat d.log; return 1; }
    svc_stop
}

t_retention_and_delete() {
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 5 -o a.rsr || return 1
    svc_start d $SVC_FAST --retention 2 || return 1
    a=$(svc_submit a.rsr) || return 1
    svc_wait_state "$a" done 60 || return 1
    # retention: 2 s after it finished, the next sweep (every 10 s) removes it
    i=0
    until [ "$(svc_field "$a" expired)" = true ]; do
        sleep 0.5; i=$((i + 1)); [ $i -lt 40 ] || { echo "job $a never expired"; curl -s "$SVC_URL/jobs/$a"; return 1; }
    done
    [ -z "$(ls -A d/videos)" ] || { echo "expired files stay:"; ls -la d/videos; return 1; }
    [ "$(curl -s -o v.json -w '%{http_code}' "$SVC_URL/jobs/$a/video")" = 410 ] || { cat v.json; return 1; }
    grep -q "removed by retention" v.json || { cat v.json; return 1; }
    svc_stop
    # DELETE of a done job: its files and its row go
    svc_start d $SVC_FAST || return 1
    b=$(svc_submit a.rsr) || return 1
    svc_wait_state "$b" done 60 || return 1
    for ext in mp4 hashes png log stream; do # the video, its hashes, its poster, its render log, its stream
        [ -e "d/videos/$b.$ext" ] || { echo "no $b.$ext after the job:"; ls -la d/videos; return 1; }
    done
    [ "$(curl -s -o c.json -w '%{http_code}' -X DELETE "$SVC_URL/jobs/$b")" = 200 ] || { cat c.json; return 1; }
    [ "$(json_get files_removed <c.json)" = 5 ] || { cat c.json; return 1; }
    [ -z "$(ls -A d/videos)" ] || { echo "DELETE left files:"; ls -la d/videos; return 1; }
    [ "$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/jobs/$b")" = 404 ] || return 1
    [ "$(curl -s -o /dev/null -w '%{http_code}' -X DELETE "$SVC_URL/jobs/$b")" = 404 ] || return 1
    svc_stop
}

t_run ${T_ONLY:-random_kills_charge_nothing_and_leave_nothing lost_daemon_is_bounded \
    retention_and_delete}
t_done
