#!/bin/sh
# Two daemons on one PostgreSQL queue (a real server started here, on
# loopback): they split the jobs, and no job is done twice.
here=$(cd "$(dirname "$0")/.." && pwd)
: "${RS_BIN:=$(dirname "$here")/build/ringside}"
. "$here/lib.sh"
. "$here/service/svc_lib.sh"
. "$here/pg.sh"
trap 'exit 143' TERM INT HUP

t_two_daemons_share_one_queue() {
    svc_pg_case || return 1
    svc_replays r 20 1 || return 1
    # two machines in miniature: own data directories, one queue, one
    # shared output directory
    mkdir -p shared
    svc_start a $SVC_FAST --queue "$PG_URI" --output shared --workers 1 || return 1
    url_a=$SVC_URL pid_a=$SVC_PID
    svc_start b $SVC_FAST --queue "$PG_URI" --output shared --workers 1 || return 1
    url_b=$SVC_URL pid_b=$SVC_PID
    grep -q "queue postgres" a.log || { cat a.log; return 1; }
    # clients split between the two front doors, all at once
    k=1
    while [ $k -le 20 ]; do
        u=$url_a; [ $((k % 2)) = 0 ] && u=$url_b
        curl -s -X POST --data-binary @r/r$k.rsr "$u/jobs?name=r$k.rsr" >sub$k.json &
        cpids="${cpids:-} $!"
        k=$((k + 1))
    done
    # only the clients: a bare `wait` would wait for the daemon too
    for c in $cpids; do wait "$c"; done
    ids=""
    for k in $(seq 1 20); do ids="$ids $(json_get id <sub$k.json)" || { cat sub$k.json; return 1; }; done
    # either daemon answers for every job
    SVC_URL=$url_a
    for id in $ids; do
        svc_wait_state "$id" done 300 || return 1
        [ "$(svc_field "$id" attempts)" = 1 ] || { echo "job $id took $(svc_field "$id" attempts) attempts"; return 1; }
        curl -sf -o "v$id.mp4" "$url_b/jobs/$id/video" || { echo "daemon b cannot serve job $id's video"; return 1; }
        [ "$(frames_of "v$id.mp4")" = 60 ] || { echo "job $id: $(frames_of "v$id.mp4") frames"; return 1; }
    done
    # each job rendered exactly once, and both daemons took a share
    grep -ho 'job [0-9]*: done' a.log b.log | sort | uniq -d >twice.txt
    [ ! -s twice.txt ] || { echo "done twice:"; cat twice.txt; return 1; }
    na=$(grep -c ': done: ' a.log) nb=$(grep -c ': done: ' b.log)
    echo "daemon a rendered $na jobs, daemon b $nb"
    [ $((na + nb)) = 20 ] || return 1
    [ "$na" -ge 3 ] && [ "$nb" -ge 3 ] || { echo "the split is lopsided: $na / $nb"; return 1; }
    svc_stop "$pid_a"
    [ "$SVC_RC" = 0 ] || return 1
    svc_stop "$pid_b"
    [ "$SVC_RC" = 0 ] || return 1
}

t_lease_of_a_dead_daemon_expires() {
    svc_pg_case || return 1
    "$RS_BIN" record --ai --quiet --seconds 8 --seed 4 -o long.rsr || return 1
    mkdir -p shared
    svc_start a $SVC_FAST --queue "$PG_URI" --output shared || return 1
    pid_a=$SVC_PID
    id=$(svc_submit long.rsr) || return 1
    svc_wait_state "$id" running 30 || return 1
    # machine a dies; b has never seen the job
    kill -KILL "$pid_a"
    svc_start b $SVC_FAST --queue "$PG_URI" --output shared || return 1
    svc_wait_state "$id" done 120 || return 1
    grep -q "job $id: re-queued (its lease expired: .*no attempt charged" b.log || { cat b.log; return 1; }
    # a dead daemon is no render failure: no attempt charged, one lease lost
    [ "$(svc_field "$id" attempts)" = 1 ] && [ "$(svc_field "$id" lost_leases)" = 1 ] || { curl -s "$SVC_URL/jobs/$id"; return 1; }
    curl -sf -o v.mp4 "$SVC_URL/jobs/$id/video" && [ "$(frames_of v.mp4)" = 480 ] || return 1
    svc_stop
}

# One split job, two daemons: each renders some of its segments; then one
# dies mid-job and the other finishes it without redoing finished segments.
t_segments_of_one_job_on_both_daemons() {
    svc_pg_case || return 1
    "$RS_BIN" record --ai --quiet --stage dojo --seconds 6 --seed 21 -o six.rsr || return 1
    "$RS_BIN" render six.rsr -o direct.mp4 --render-size 160x90 --size 160x90 --hashes direct.hashes --quiet || return 1
    mkdir -p shared
    svc_start a $SVC_FAST --queue "$PG_URI" --output shared --segment-seconds 1 || return 1
    url_a=$SVC_URL pid_a=$SVC_PID
    svc_start b $SVC_FAST --queue "$PG_URI" --output shared --segment-seconds 1 || return 1
    url_b=$SVC_URL
    id=$(svc_submit six.rsr) || return 1
    svc_wait_state "$id" done 300 || return 1
    svc_units "$id" >units.txt
    cat units.txt
    # segments finished by both daemons (owner host:pid-nonce/slot), each once
    [ "$(awk '$1 != "join" {sub(/\/[0-9]+$/, "", $5); print $5}' units.txt | sort -u | wc -l)" = 2 ] ||
        { echo "one daemon rendered every segment"; return 1; }
    [ "$(awk '$4 != 1' units.txt | wc -l)" = 0 ] || { echo "a unit was rendered twice"; return 1; }
    curl -sf -o v.hashes "$url_b/jobs/$id/hashes" && cmp v.hashes direct.hashes || { echo "hashes differ"; return 1; }
    # daemon a dies in the middle of a second one: b takes over its segment
    # once the lease expires, and nothing finished is rendered again
    SVC_URL=$url_a
    id2=$(svc_submit six.rsr) || return 1
    i=0
    until [ "$(svc_units "$id2" | awk '$2 == "done"' | wc -l)" -ge 2 ] && svc_worker_pid "$pid_a" "$id2" >/dev/null; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 600 ] || { svc_units "$id2"; return 1; }
    done
    kill -KILL "$pid_a"
    SVC_URL=$url_b
    svc_wait_state "$id2" done 300 || return 1
    svc_units "$id2" >units2.txt
    cat units2.txt
    grep -q "job $id2: segment [0-9]* (ticks [0-9-]*): re-queued (its lease expired" b.log || { echo "b never reaped a's segment"; return 1; }
    [ "$(awk '$4 != 1' units2.txt | wc -l)" = 0 ] || { echo "a unit was rendered twice"; return 1; }
    curl -sf -o v2.hashes "$url_b/jobs/$id2/hashes" && cmp v2.hashes direct.hashes || { echo "hashes differ"; return 1; }
    svc_no_leftovers "$id2" shared || return 1
    svc_stop
}

t_run two_daemons_share_one_queue lease_of_a_dead_daemon_expires segments_of_one_job_on_both_daemons
t_done
