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

vframes() { ffmpeg -v error -i "$1" -map 0:v -f framemd5 - | grep -v '^#' | cut -d, -f6; }

# Three daemons on one PostgreSQL queue with nothing on disk in common
# (files = queue, the default there): a split job uploaded to a is rendered
# by all of them and joined by one, and every daemon serves its video,
# hashes, poster, render log and stream from the queue.  DELETE takes its
# bytes out of the queue, and the other daemons' copies go at their sweep.
t_no_shared_disk() {
    svc_pg_case || return 1
    "$RS_BIN" record --ai --quiet --stage dojo --seconds 6 --seed 21 -o six.rsr || return 1
    "$RS_BIN" render six.rsr -o direct.mp4 --render-size 160x90 --size 160x90 --hashes direct.hashes --quiet || return 1
    for h in a b c; do
        # each its own data and output directory (h/videos)
        svc_start $h $SVC_FAST --queue "$PG_URI" --segment-seconds 1 || return 1
        eval "url_$h=\$SVC_URL"
    done
    grep -q "videos in a/videos, kept in the queue" a.log || { cat a.log; return 1; }
    SVC_URL=$url_a
    id=$(svc_submit six.rsr) || return 1
    svc_wait_state "$id" done 300 || return 1
    svc_units "$id" >units.txt
    [ "$(awk '$1 != "join" {sub(/\/[0-9]+$/, "", $5); print $5}' units.txt | sort -u | wc -l)" -ge 2 ] ||
        { cat units.txt; echo "one daemon rendered every segment"; return 1; }
    [ "$(awk '$4 != 1' units.txt | wc -l)" = 0 ] || { cat units.txt; echo "a unit was rendered twice"; return 1; }
    joined=$(grep -l "job $id: done: " a.log b.log c.log | head -1)
    fetched=$(grep -h "join: [0-9]* segment files* fetched from the queue" a.log b.log c.log)
    [ -n "$fetched" ] || { echo "the join fetched nothing from the queue"; return 1; }
    joined=${joined%.log}
    echo "joined by $joined: $fetched"
    # the join's machine has the video it made; the others fetch it
    joined_mp4=$joined/videos/$id.mp4
    [ -f "$joined_mp4" ] || { echo "no $joined_mp4"; return 1; }
    bytes=$(pg_psql "SELECT SUM(length(data)) FROM job_files WHERE job_id = $id")
    echo "bytes in the queue: $bytes"
    [ -z "$(pg_psql "SELECT name FROM job_files WHERE job_id = $id AND name LIKE 'seg/%'")" ] ||
        { echo "the segments stayed in the queue after the join"; return 1; }
    for h in a b c; do
        eval "u=\$url_$h"
        curl -sf -o $h.hashes "$u/jobs/$id/hashes" && cmp $h.hashes direct.hashes || { echo "daemon $h: hashes differ"; return 1; }
        curl -sf -o $h.mp4 "$u/jobs/$id/video" && cmp $h.mp4 "$joined_mp4" || { echo "daemon $h: not the joined video"; return 1; }
        [ -s video.txt ] || vframes $h.mp4 >video.txt
        [ "$(wc -l <video.txt)" = 360 ] || { echo "daemon $h: $(wc -l <video.txt) frames"; return 1; }
        [ "$(curl -s -o $h.png -w '%{http_code}' "$u/jobs/$id/poster")" = 200 ] || { echo "daemon $h: no poster"; return 1; }
        curl -sf "$u/jobs/$id/log" >$h.txt && [ "$(grep -c '^== ' $h.txt)" = 7 ] ||
            { echo "daemon $h: the log has not every unit:"; cat $h.txt; return 1; }
        vframes "$u/jobs/$id/stream.m3u8" | cmp -s - video.txt || { echo "daemon $h: the stream's frames differ"; return 1; }
    done
    # a copy damaged here is fetched again, not served
    piece=$(ls b/videos/$id.stream/*/t0.ts) || return 1
    printf 'x' | dd of="$piece" bs=1 seek=100 conv=notrunc 2>/dev/null
    [ "$(curl -s -o piece.ts -w '%{http_code}' "$url_b/jobs/$id/stream/0.ts")" = 200 ] || { echo "a damaged piece was not fetched again"; return 1; }
    grep -q "fetching it again from the queue" b.log || return 1
    # DELETE: the queue forgets its bytes; the other daemons' copies go,
    # and so does a fetch a dead process left half written
    sh -c 'exit 0' & dead=$!
    wait $dead
    touch "b/videos/.$id.mp4.fetch-0-$(hostname)-$dead" "b/videos/.99999.mp4.fetch-0-elsewhere-$dead"
    [ "$(curl -s -o /dev/null -w '%{http_code}' -X DELETE "$url_c/jobs/$id")" = 200 ] || return 1
    [ "$(pg_psql "SELECT COUNT(*) FROM job_files WHERE job_id = $id")" = 0 ] || { echo "its bytes stayed in the queue"; return 1; }
    i=0
    while ls -A a/videos b/videos c/videos | grep -q "^\.\{0,1\}$id\."; do
        sleep 0.5; i=$((i + 1))
        [ $i -lt 30 ] || { echo "copies stayed:"; ls -A a/videos b/videos c/videos; return 1; }
    done
    # another machine's (a shared directory): its pid is not ours to judge
    [ -e "b/videos/.99999.mp4.fetch-0-elsewhere-$dead" ] || { echo "another host's fetch was removed"; return 1; }
    svc_stop
}

t_run two_daemons_share_one_queue lease_of_a_dead_daemon_expires segments_of_one_job_on_both_daemons no_shared_disk
t_done
