#!/bin/sh
# Split jobs end to end (docs/service.md, "Segments"): a job cut into
# segments that any worker renders (`render --ticks A:B --segment KEY`),
# joined by stream copy (`ringside join`); the video's frame hashes equal
# a single `render --hashes` of the same replay.  Real HTTP, SQLite, real
# renders; dojo replays (exact from any tick).
. "$(dirname "$0")/../lib.sh"
. "$(dirname "$0")/svc_lib.sh"

dojo() { # SECONDS SEED FILE
    "$RS_BIN" record --ai --quiet --stage dojo --seconds "$1" --seed "$2" -o "$3"
}

# the single-process render the service's video must equal
direct_hashes() { # REPLAY OUT [DRAWN SIZE]
    "$RS_BIN" render "$1" -o direct.mp4 --render-size "${3:-160x90}" --size 160x90 --hashes "$2" --quiet
}

# the job's video and hash list are those of a single render, and nothing
# but N.fmt and N.hashes is left in the output directory
check_video() { # ID REPLAY FRAMES [DRAWN SIZE]
    curl -sf -o "v$1.hashes" "$SVC_URL/jobs/$1/hashes" || { echo "job $1: no hashes"; return 1; }
    direct_hashes "$2" "d$1.hashes" "${4:-}" || return 1
    cmp "v$1.hashes" "d$1.hashes" || { echo "job $1: the joined video's frames differ from render's"; return 1; }
    curl -sf -o "v$1.mp4" "$SVC_URL/jobs/$1/video" || return 1
    [ "$(frames_of "v$1.mp4")" = "$3" ] || { echo "job $1: ffprobe counts $(frames_of "v$1.mp4") frames"; return 1; }
    svc_no_leftovers "$1" "${SPLIT_OUT:-d/videos}"
}

t_two_workers_one_video() {
    # the done-when case: 4 s in 1 s segments on 2 workers
    # (drawn at 640x360: at 160x90 a second of frames renders faster than
    # the loop below can see two segments running)
    dojo 4 5 four.rsr || return 1
    svc_start d $SVC_FAST --render-size 640x360 --workers 2 --segment-seconds 1 || return 1
    id=$(svc_submit four.rsr) || return 1
    [ "$(svc_field "$id" segment_count)" = 4 ] || { curl -s "$SVC_URL/jobs/$id"; return 1; }
    # progress counts every segment while they run
    seen=0
    while [ "$(svc_field "$id" state)" != done ]; do
        curl -sf "$SVC_URL/jobs/$id" >j.json || return 1
        python3 - j.json <<'EOF' && seen=1
import json, sys
j = json.load(open(sys.argv[1]))
running = [s for s in j["segments"] if s["state"] == "running"]
ok = (j["state"] == "running" and 0 < j["frames_done"] < j["frames_total"] and j["fps"] > 0
      and j["eta_s"] is not None and len(running) == 2)
sys.exit(0 if ok else 1)
EOF
        [ "$(svc_field "$id" state)" = failed ] && { curl -s "$SVC_URL/jobs/$id"; return 1; }
        sleep 0.3
    done
    [ "$seen" = 1 ] || { echo "never saw two segments running with progress, fps and an ETA"; return 1; }
    check_video "$id" four.rsr 240 640x360 || return 1
    svc_units "$id" >units.txt
    cat units.txt
    # every segment rendered once, by both workers between them
    [ "$(awk '$1 != "join" && $2 == "done" && $4 == 1' units.txt | wc -l)" = 4 ] || { echo "segments rendered more than once"; return 1; }
    [ "$(awk '{print $5}' units.txt | sed 's/.*\///' | sort -u | wc -l)" = 2 ] || { echo "one worker did it all"; return 1; }
    [ "$(svc_field "$id" join.state)" = done ] || return 1
    svc_stop
}

t_segment_retried_alone() {
    dojo 4 7 four.rsr || return 1
    svc_start d $SVC_FAST --segment-seconds 1 || return 1
    id=$(svc_submit four.rsr) || return 1
    # kill the render of segment 1 (ticks 60-120) while it runs: segment 1 alone
    # runs again.  Found by its own command line and stopped first, so it cannot
    # finish between the look and the kill (waiting for its progress to show let
    # a fast render end first, and the kill hit segment 2)
    i=0
    until w=$(svc_worker_pid "$SVC_PID" "$id") && tr '\0' ' ' <"/proc/$w/cmdline" 2>/dev/null | grep -q -- '--ticks 60:120'; do
        sleep 0.05; i=$((i + 1)); [ $i -lt 1200 ] || { echo "segment 1 never ran"; return 1; }
    done
    kill -STOP "$w"
    kill -KILL "$w"
    svc_wait_state "$id" done 120 || return 1
    svc_units "$id" >units.txt
    cat units.txt
    [ "$(awk '$1 == 1 {print $3}' units.txt)" = 2 ] || { echo "segment 1 was not retried"; return 1; }
    [ "$(awk '$1 != 1 && $1 != "join" && $3 != 1' units.txt | wc -l)" = 0 ] || { echo "other segments were retried"; return 1; }
    grep -q "job $id: segment 1 (ticks 60-120): the render process was killed by signal 9" d.log || { cat d.log; return 1; }
    check_video "$id" four.rsr 240 || return 1
    svc_stop
}

t_segment_out_of_attempts_fails_the_job() {
    dojo 3 8 three.rsr || return 1
    svc_start d $SVC_FAST --segment-seconds 1 --max-attempts 1 || return 1
    id=$(svc_submit three.rsr) || return 1
    # segment 0's render, found by its command line and stopped first (as
    # in segment_retried_alone: waiting for frames to show let segment 0
    # finish first with 2026-11-29's renders, and the kill hit segment 1)
    i=0
    until w=$(svc_worker_pid "$SVC_PID" "$id") && tr '\0' ' ' <"/proc/$w/cmdline" 2>/dev/null | grep -q -- '--ticks 0:60'; do
        sleep 0.05; i=$((i + 1)); [ $i -lt 1200 ] || { echo "segment 0 never ran"; return 1; }
    done
    kill -STOP "$w"
    kill -KILL "$w"
    svc_wait_state "$id" failed 60 || return 1
    svc_field "$id" error | grep -q "^gave up after 1 attempt: segment 0 (ticks 0-60): the render process was killed by signal 9" ||
        { svc_field "$id" error; return 1; }
    [ "$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/jobs/$id/video")" = 404 ] || return 1
    svc_no_leftovers "$id" || return 1
    svc_stop
}

t_cancel_cancels_every_segment() {
    dojo 8 9 eight.rsr || return 1
    svc_start d $SVC_FAST --workers 2 --segment-seconds 1 || return 1
    id=$(svc_submit eight.rsr) || return 1
    i=0
    until [ "$(svc_field "$id" segments.0.state)" = done ]; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 300 ] || { echo "no segment done"; return 1; }
    done
    [ "$(curl -s -o c.json -w '%{http_code}' -X DELETE "$SVC_URL/jobs/$id")" = 200 ] || { cat c.json; return 1; }
    # every render stops, no unit is left to do, and the files go
    i=0
    while pgrep -P "$SVC_PID" >/dev/null; do sleep 0.2; i=$((i + 1)); [ $i -lt 60 ] || { echo "renders still run"; return 1; }; done
    svc_units "$id" >units.txt
    cat units.txt
    [ "$(awk '$2 != "done" && $2 != "cancelled"' units.txt | wc -l)" = 0 ] || return 1
    [ "$(svc_field "$id" state)" = cancelled ] || return 1
    svc_no_leftovers "$id" || return 1
    svc_stop
}

# Workers and the daemon killed (SIGKILL) at random points: the job
# finishes, no finished segment is rendered again, nothing is left over.
t_killed_at_random() {
    dojo 8 11 eight.rsr || return 1
    seed=$(od -An -N2 -tu2 /dev/urandom | tr -d ' ')
    echo "random seed $seed"
    # R = a number below $1 (not in $(...): the seed must advance here)
    rnd() { seed=$(( (seed * 1103515245 + 12345) % 2147483648 )); R=$(( seed / 65536 % $1 )); }
    # enough attempts that the kills cannot run a segment out of them
    opts="$SVC_FAST --workers 2 --segment-seconds 1 --max-attempts 20"
    svc_start d $opts || return 1
    id=$(svc_submit eight.rsr) || return 1
    kills=0 daemon_kills=0 round=0
    while [ $round -lt 6 ] && [ "$(svc_field "$id" state)" != done ]; do
        round=$((round + 1))
        rnd 2; s=$R; rnd 10
        sleep "$s.$R"
        # children in the first round and the daemon by the second, at least
        rnd 3
        if [ $round != 1 ] && { [ $R = 0 ] || [ $daemon_kills = 0 ]; }; then
            echo "round $round: daemon killed"
            kill -KILL "$SVC_PID"
            wait "$SVC_PID" 2>/dev/null
            daemon_kills=$((daemon_kills + 1))
            svc_start d $opts || return 1
        else
            n=0
            for c in $(pgrep -P "$SVC_PID"); do
                n=$((n + 1))
                rnd 2
                [ $R = 0 ] && [ $n -gt 1 ] && continue # the first always, the others by chance
                echo "round $round: child $c killed: $(tr '\0' ' ' <"/proc/$c/cmdline" 2>/dev/null | cut -c1-100)"
                kill -KILL "$c" 2>/dev/null && kills=$((kills + 1))
            done
        fi
    done
    echo "$kills renders killed, $daemon_kills daemon kills"
    [ $kills -gt 0 ] && [ $daemon_kills -gt 0 ] || { echo "the job finished before the kills (too fast?)"; return 1; }
    svc_wait_state "$id" done 300 || return 1
    svc_units "$id" >units.txt
    cat units.txt
    # a segment the queue recorded as done was never handed out again
    [ "$(awk '$1 != "join" && $4 != 1' units.txt | wc -l)" = 0 ] || { echo "a finished segment was rendered twice"; return 1; }
    check_video "$id" eight.rsr 480 || return 1
    [ -z "$(ls -A d/work)" ] || { echo "left in the work directory:"; ls -la d/work; return 1; }
    svc_stop
}

# The join checks every segment against its manifest and key: a truncated
# one and another job's are rendered again, never joined.
t_join_rejects_bad_and_foreign_segments() {
    dojo 4 13 four.rsr || return 1
    # another job's segment 1: the same ticks, another key
    "$RS_BIN" render four.rsr --ticks 60:120 --segment job99-foreign -o foreign.mp4 --hashes foreign.hashes \
        --render-size 160x90 --size 160x90 --quiet || return 1
    svc_start d $SVC_FAST --segment-seconds 1 || return 1
    id=$(svc_submit four.rsr) || return 1
    i=0
    until [ "$(svc_field "$id" segments.1.state)" = done ]; do
        sleep 0.1; i=$((i + 1)); [ $i -lt 600 ] || { echo "segment 1 not done"; return 1; }
    done
    dir=$(echo d/videos/.job"$id"-*)
    [ -d "$dir" ] || { ls -la d/videos; return 1; }
    ls -la "$dir"
    # segment 0 truncated; segment 1 replaced by the foreign one, manifest and all
    s0=$dir/s0-a1.mp4
    head -c $(( $(stat -c %s "$s0") / 2 )) "$s0" >t && mv t "$s0"
    cp foreign.mp4 "$dir/s1-a1.mp4"
    cp foreign.mp4.seg "$dir/s1-a1.mp4.seg"
    cp foreign.hashes "$dir/s1-a1.hashes"
    svc_wait_state "$id" done 120 || { cat d.log; return 1; }
    grep -q "job $id: join: the join found bad segment files" d.log || { grep "job $id" d.log; return 1; }
    svc_units "$id" >units.txt
    cat units.txt
    [ "$(awk '$1 == 0 || $1 == 1 {print $4}' units.txt | tr '\n' ' ')" = "2 2 " ] || { echo "not rendered again"; return 1; }
    [ "$(awk '$1 == 2 || $1 == 3 {print $4}' units.txt | tr '\n' ' ')" = "1 1 " ] || return 1
    [ "$(svc_field "$id" join.attempts)" = 1 ] || { echo "the bad segments cost the join an attempt"; return 1; }
    check_video "$id" four.rsr 240 || return 1
    svc_stop
}

# A full disk under the join: the job goes back without an attempt counted
# and no half-written video is left; with room again it finishes.
t_join_disk_full_requeues() {
    mnt=$T_TMP/join_disk_full/out
    mkdir -p "$mnt"
    mount -t tmpfs -o size=64m tmpfs "$mnt" 2>/dev/null || t_skip_env "cannot mount a tmpfs (not root?)"
    SVC_ON_EXIT="umount -l $mnt"
    SPLIT_OUT=$mnt
    dojo 4 17 four.rsr || return 1
    svc_start d $SVC_FAST --segment-seconds 1 --output "$mnt" || return 1
    id=$(svc_submit four.rsr) || return 1
    # the last segment running: stop the daemon, let the render finish,
    # fill the disk, and go on: the join is next
    i=0
    until [ "$(svc_field "$id" segments.3.state)" = running ] && w=$(svc_worker_pid "$SVC_PID" "$id"); do
        sleep 0.1; i=$((i + 1)); [ $i -lt 600 ] || { echo "segment 3 never ran"; return 1; }
    done
    kill -STOP "$SVC_PID"
    i=0
    while [ -d "/proc/$w" ] && [ "$(cut -d' ' -f3 "/proc/$w/stat")" != Z ]; do
        sleep 0.1; i=$((i + 1)); [ $i -lt 300 ] || { kill -CONT "$SVC_PID"; echo "the render did not end"; return 1; }
    done
    dd if=/dev/zero of="$mnt/filler" bs=64k 2>/dev/null
    kill -CONT "$SVC_PID"
    i=0
    until grep -q "job $id: join: the join could not write the video" d.log; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 300 ] || { grep "job $id" d.log; df -k "$mnt"; return 1; }
    done
    [ "$(svc_field "$id" state)" != failed ] || return 1
    [ -z "$(ls -A "$mnt" | grep "^\.job$id-.*-j")" ] || { echo "a half-written join is left"; ls -la "$mnt"; return 1; }
    rm -f "$mnt/filler"
    svc_wait_state "$id" done 120 || return 1
    [ "$(svc_field "$id" join.attempts)" = 1 ] || { echo "join attempts $(svc_field "$id" join.attempts)"; return 1; }
    check_video "$id" four.rsr 240 || return 1
    svc_stop
}

t_run ${T_ONLY:-two_workers_one_video segment_retried_alone segment_out_of_attempts_fails_the_job \
    cancel_cancels_every_segment killed_at_random join_rejects_bad_and_foreign_segments join_disk_full_requeues}
t_done
