#!/bin/sh
# `ringside serve` end to end: real HTTP over loopback (curl), the real
# SQLite queue, real render processes, ffprobe on every video.
. "$(dirname "$0")/../lib.sh"
. "$(dirname "$0")/svc_lib.sh"

t_readme_flow() {
    # what README.md shows: multipart upload, poll, download
    "$RS_BIN" record --ai --quiet --seconds 2 --seed 5 -o fight.rsr || return 1
    svc_start d $SVC_FAST || return 1
    body=$(curl -s -F replay=@fight.rsr -F size=160x90 "$SVC_URL/jobs")
    id=$(echo "$body" | json_get id)
    [ "$(echo "$body" | json_get state)" = queued ] || { echo "submit: $body"; return 1; }
    svc_wait_state "$id" done 60 || return 1
    [ "$(svc_field "$id" name)" = fight.rsr ] || { echo "name lost"; return 1; }
    [ "$(svc_field "$id" progress)" = 1.0 ] || { echo "progress $(svc_field "$id" progress)"; return 1; }
    curl -sf -o fight.mp4 "$SVC_URL/jobs/$id/video" || return 1
    [ "$(frames_of fight.mp4)" = 120 ] || { echo "frames: $(frames_of fight.mp4)"; return 1; }
    curl -sf -o fight.hashes "$SVC_URL/jobs/$id/hashes" || return 1
    [ "$(wc -l <fight.hashes)" = 120 ] || { echo "hash lines: $(wc -l <fight.hashes)"; return 1; }
    # the daemon's video is what `ringside render` makes of the same replay
    "$RS_BIN" render fight.rsr -o direct.mp4 --render-size 160x90 --size 160x90 --hashes direct.hashes --quiet || return 1
    cmp fight.hashes direct.hashes || { echo "the service's frames differ from render's"; return 1; }
    svc_stop
    [ "$SVC_RC" = 0 ] || { echo "serve exit $SVC_RC after SIGTERM"; return 1; }
}

t_twenty_concurrent_jobs() {
    svc_replays r 20 1 || return 1
    svc_start d $SVC_FAST --workers 2 || return 1
    # 20 clients at once
    k=1
    while [ $k -le 20 ]; do
        curl -s -X POST --data-binary @r/r$k.rsr "$SVC_URL/jobs?name=r$k.rsr$( [ $((k % 2)) = 0 ] && echo '&format=webm')" \
            >sub$k.json &
        cpids="${cpids:-} $!"
        k=$((k + 1))
    done
    # only the clients: a bare `wait` would wait for the daemon too
    for c in $cpids; do wait "$c"; done
    k=1
    ids=""
    while [ $k -le 20 ]; do
        id=$(json_get id <sub$k.json) || { echo "submit $k: $(cat sub$k.json)"; return 1; }
        ids="$ids $id:$k"
        k=$((k + 1))
    done
    [ "$(echo $ids | tr ' ' '\n' | cut -d: -f1 | sort -u | wc -l)" = 20 ] || { echo "ids not unique: $ids"; return 1; }
    for p in $ids; do
        id=${p%%:*} k=${p##*:}
        svc_wait_state "$id" done 300 || return 1
        fmt=$(svc_field "$id" format)
        curl -sf -o "v$k.$fmt" "$SVC_URL/jobs/$id/video" || { echo "job $id: no video"; return 1; }
        n=$(frames_of "v$k.$fmt")
        [ "$n" = 60 ] || { echo "job $id ($fmt): ffprobe counts $n frames, want 60"; return 1; }
    done
    curl -s "$SVC_URL/metrics" >metrics.txt
    grep -q '^ringside_jobs{state="done"} 20$' metrics.txt || { cat metrics.txt; return 1; }
    grep -q '^ringside_frames_rendered_total 1200$' metrics.txt || { grep frames metrics.txt; return 1; }
    svc_stop
}

t_worker_killed_mid_render() {
    "$RS_BIN" record --ai --quiet --seconds 12 --seed 9 -o long.rsr || return 1
    svc_start d $SVC_FAST || return 1
    id=$(svc_submit long.rsr) || return 1
    # wait until it is well into the render, then kill the render process
    i=0
    while [ "$(svc_field "$id" frames_done)" -lt 60 ] 2>/dev/null; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 300 ] || { echo "no progress"; return 1; }
    done
    w=$(svc_worker_pid "$SVC_PID" "$id") || { echo "no render process for job $id"; return 1; }
    kill -KILL "$w"
    svc_wait_state "$id" done 120 || return 1
    [ "$(svc_field "$id" attempts)" = 2 ] || { echo "attempts $(svc_field "$id" attempts), want 2"; return 1; }
    grep -q "job $id: the render process was killed by signal 9" d.log || { cat d.log; return 1; }
    curl -sf -o v.mp4 "$SVC_URL/jobs/$id/video" || return 1
    [ "$(frames_of v.mp4)" = 720 ] || { echo "frames $(frames_of v.mp4)"; return 1; }
    curl -s "$SVC_URL/metrics" | grep -q '^ringside_worker_failures_total 1$' || return 1
    # nothing of the killed attempt is left behind
    [ -z "$(ls -A d/videos | grep -v "^$id\.")" ] || { ls -la d/videos; return 1; }
    svc_stop
}

t_daemon_killed_and_restarted() {
    svc_replays r 6 2 || return 1
    svc_start d $SVC_FAST || return 1
    ids=""
    for k in 1 2 3 4 5 6; do ids="$ids $(svc_submit r/r$k.rsr)" || return 1; done
    first=${ids# }
    first=${first%% *}
    svc_wait_state "$first" done 60 || return 1
    # mid-queue: one job running, four queued
    sleep 2
    kill -KILL "$SVC_PID"
    wait "$SVC_PID" 2>/dev/null
    # its render died with it (PR_SET_PDEATHSIG): no orphan writes a video
    sleep 0.5
    # (only renders running in this test's directory: other suites may run beside it)
    for o in $(pgrep -f "ringside render d/work/job"); do
        [ "$(readlink "/proc/$o/cwd" 2>/dev/null)" = "$PWD" ] && { echo "an orphan render survived: $o"; return 1; }
    done
    svc_start d $SVC_FAST || return 1
    grep -q "re-queued (its daemon stopped; no attempt charged" d.log ||
        echo "(no job was running at the kill)"
    for id in $ids; do
        svc_wait_state "$id" done 120 || return 1
        curl -sf -o "v$id.mp4" "$SVC_URL/jobs/$id/video" || return 1
        [ "$(frames_of "v$id.mp4")" = 120 ] || { echo "job $id: $(frames_of "v$id.mp4") frames"; return 1; }
    done
    [ "$(curl -s "$SVC_URL/jobs?limit=100" | json_get jobs | python3 -c 'import sys,ast; print(len(ast.literal_eval(sys.stdin.read())))')" = 6 ] ||
        { echo "job count changed"; return 1; }
    svc_stop
}

t_sigterm_lets_running_jobs_finish() {
    "$RS_BIN" record --ai --quiet --seconds 4 --seed 2 -o a.rsr || return 1
    svc_start d $SVC_FAST || return 1
    id=$(svc_submit a.rsr) || return 1
    q=$(svc_submit a.rsr) || return 1
    svc_wait_state "$id" running 30 || return 1
    kill -TERM "$SVC_PID"
    sleep 0.5
    # draining: no new jobs, but the API still answers
    code=$(curl -s -o resp.json -w '%{http_code}' -X POST --data-binary @a.rsr "$SVC_URL/jobs")
    [ "$code" = 503 ] || { echo "POST while draining: $code"; return 1; }
    wait "$SVC_PID"
    rc=$?
    [ "$rc" = 0 ] || { echo "exit $rc"; return 1; }
    grep -q "job $id: done" d.log || { cat d.log; return 1; }
    # the queued one was not started, and it is still there after a restart
    svc_start d $SVC_FAST || return 1
    svc_wait_state "$q" done 60 || return 1
    svc_stop
}

t_sigterm_after_grace_requeues() {
    "$RS_BIN" record --ai --quiet --seconds 20 --seed 2 -o long.rsr || return 1
    svc_start d $SVC_FAST --grace 1 || return 1
    id=$(svc_submit long.rsr) || return 1
    i=0
    while [ "$(svc_field "$id" frames_done)" -lt 30 ] 2>/dev/null; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 300 ] || { echo "no progress"; return 1; }
    done
    svc_stop
    [ "$SVC_RC" = 0 ] || { echo "exit $SVC_RC"; cat d.log; return 1; }
    grep -q "job $id: re-queued: the daemon is shutting down" d.log || { cat d.log; return 1; }
    # the attempt was given back: a shutdown is not the job's fault
    svc_start d $SVC_FAST || return 1
    [ "$(svc_field "$id" state)" != failed ] || return 1
    svc_wait_state "$id" done 120 || return 1
    [ "$(svc_field "$id" attempts)" = 1 ] || { echo "attempts $(svc_field "$id" attempts), want 1"; return 1; }
    svc_stop
}

t_bad_uploads_get_4xx() {
    "$RS_BIN" record --ai --quiet --seconds 2 --seed 4 -o good.rsr || return 1
    svc_start d $SVC_FAST --max-upload 64K || return 1
    post() { # FILE WANT_CODE PATTERN [QUERY]
        code=$(curl -s -o resp.json -w '%{http_code}' -X POST --data-binary @"$1" "$SVC_URL/jobs?name=$1${4:+&$4}")
        [ "$code" = "$2" ] || { echo "$1: HTTP $code, want $2: $(cat resp.json)"; return 1; }
        json_get error <resp.json | grep -Eq -- "$3" || { echo "$1: error lacks /$3/: $(cat resp.json)"; return 1; }
    }
    : >empty.rsr
    post empty.rsr 400 "empty upload" || return 1
    head -c 3000 /dev/urandom >garbage.rsr
    post garbage.rsr 400 'garbage.rsr: not a ringside replay' || return 1
    head -c 50 good.rsr >cut.rsr
    post cut.rsr 400 'cut.rsr: .*(ends|truncated|expected)' || return 1
    head -c 100000 /dev/zero >big.rsr
    post big.rsr 413 "over the limit of 65536 bytes" || return 1
    printf '\211PNG\r\n\032\n0000000000000000' >pic.png
    post pic.png 400 'pic.png: not a ringside replay' || return 1
    post good.rsr 400 "size '12x': expected WxH" "size=12x" || return 1
    post good.rsr 400 "size 4000x4000" "size=4000x4000" || return 1
    post good.rsr 400 "format 'avi'" "format=avi" || return 1
    # sizes the renderer cannot make from what it draws (160x90 here)
    post good.rsr 400 "size 320x180: .*larger than the render size" "size=320x180" || return 1
    # a multipart part without a name (libmicrohttpd hands it over nameless)
    printf -- '--XYZ\r\nFoo: bar\r\n\r\nAAAA\r\n--XYZ--\r\n' >noname.txt
    code=$(curl -s -o resp.json -w '%{http_code}' -H 'Content-Type: multipart/form-data; boundary=XYZ' \
        --data-binary @noname.txt "$SVC_URL/jobs")
    [ "$code" = 400 ] || { echo "nameless multipart part: $code $(cat resp.json)"; return 1; }
    # a wrong version byte gets the parser's own message
    python3 -c 'import sys; b=bytearray(open("good.rsr","rb").read()); b[4]=99; open("v99.rsr","wb").write(b)'
    post v99.rsr 400 'version' || return 1
    # chunked upload over the limit (no Content-Length to refuse early)
    code=$(curl -s -o resp.json -w '%{http_code}' -H 'Transfer-Encoding: chunked' -X POST --data-binary @big.rsr "$SVC_URL/jobs")
    [ "$code" = 413 ] || { echo "chunked big: $code $(cat resp.json)"; return 1; }
    # unknown paths and methods
    [ "$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/jobs/abc")" = 404 ] || return 1
    [ "$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/jobs/999")" = 404 ] || return 1
    [ "$(curl -s -o /dev/null -w '%{http_code}' -X PUT "$SVC_URL/jobs/1")" = 405 ] || return 1
    [ "$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/nope")" = 404 ] || return 1
    # still serving, and nothing bad was queued
    id=$(svc_submit good.rsr) || return 1
    [ "$id" = 1 ] || { echo "a refused upload took an id: $id"; return 1; }
    svc_wait_state "$id" done 60 || return 1
    curl -s "$SVC_URL/metrics" | grep -q '^ringside_uploads_rejected_total 12$' || { curl -s "$SVC_URL/metrics" | grep rejected; return 1; }
    svc_stop
}

t_local_problems_do_not_burn_attempts() {
    # the work directory vanishes under a running daemon: the next job
    # recreates it instead of failing every job for good
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 4 -o a.rsr || return 1
    svc_start d $SVC_FAST || return 1
    rm -rf d/work
    id=$(svc_submit a.rsr) || return 1
    svc_wait_state "$id" done 60 || return 1
    [ "$(svc_field "$id" attempts)" = 1 ] || { echo "attempts $(svc_field "$id" attempts)"; return 1; }
    svc_stop
}

t_ctrl_c_to_the_whole_group() {
    # Ctrl-C at a terminal signals the daemon's whole process group: the
    # renders are in their own groups, so the daemon drains as for SIGTERM
    "$RS_BIN" record --ai --quiet --seconds 3 --seed 2 -o a.rsr || return 1
    mkdir -p d
    setsid "$RS_BIN" serve --listen 127.0.0.1:0 --data d $SVC_FAST >>d.log 2>&1 &
    SVC_PID=$!
    SVC_PIDS="$SVC_PIDS $SVC_PID"
    trap svc_cleanup EXIT
    i=0
    until port=$(sed -n 's/.*listening on http:\/\/127\.0\.0\.1:\([0-9]*\)\/.*/\1/p' d.log) && [ -n "$port" ]; do
        sleep 0.1; i=$((i + 1)); [ $i -lt 100 ] || { cat d.log; return 1; }
    done
    SVC_URL=http://127.0.0.1:$port
    id=$(svc_submit a.rsr) || return 1
    i=0
    while [ "$(svc_field "$id" frames_done)" -lt 10 ] 2>/dev/null; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 300 ] || { echo "no progress"; return 1; }
    done
    kill -INT "-$SVC_PID" # dash's kill takes no "--"
    wait "$SVC_PID"
    rc=$?
    [ "$rc" = 0 ] || { echo "exit $rc"; cat d.log; return 1; }
    grep -q "job $id: done" d.log || { echo "the running job did not finish in the grace period"; cat d.log; return 1; }
}

t_cancel_queued_and_running() {
    "$RS_BIN" record --ai --quiet --seconds 20 --seed 6 -o long.rsr || return 1
    svc_start d $SVC_FAST || return 1
    a=$(svc_submit long.rsr) || return 1
    b=$(svc_submit long.rsr) || return 1
    svc_wait_state "$a" running 30 || return 1
    i=0
    until w=$(svc_worker_pid "$SVC_PID" "$a"); do sleep 0.2; i=$((i + 1)); [ $i -lt 50 ] || return 1; done
    [ "$(curl -s -o c.json -w '%{http_code}' -X DELETE "$SVC_URL/jobs/$b")" = 200 ] || { cat c.json; return 1; }
    [ "$(json_get state <c.json)" = cancelled ] || return 1
    [ "$(curl -s -o c.json -w '%{http_code}' -X DELETE "$SVC_URL/jobs/$a")" = 200 ] || { cat c.json; return 1; }
    # the render process goes away within a heartbeat or two
    i=0
    while kill -0 "$w" 2>/dev/null; do sleep 0.2; i=$((i + 1)); [ $i -lt 50 ] || { echo "render $w still runs"; return 1; }; done
    [ "$(svc_field "$a" state)" = cancelled ] || return 1
    # a second DELETE removes the cancelled job from the queue, a third finds nothing
    [ "$(curl -s -o c.json -w '%{http_code}' -X DELETE "$SVC_URL/jobs/$a")" = 200 ] || { cat c.json; return 1; }
    [ "$(json_get deleted <c.json)" = true ] || { cat c.json; return 1; }
    [ "$(curl -s -o c.json -w '%{http_code}' -X DELETE "$SVC_URL/jobs/$a")" = 404 ] || { cat c.json; return 1; }
    [ "$(curl -s -o c.json -w '%{http_code}' -X DELETE "$SVC_URL/jobs/99")" = 404 ] || return 1
    sleep 1
    [ -z "$(ls -A d/videos)" ] || { echo "a cancelled job left files:"; ls -la d/videos; return 1; }
    svc_stop
}

t_watchdog_kills_a_stalled_render() {
    "$RS_BIN" record --ai --quiet --seconds 6 --seed 3 -o a.rsr || return 1
    svc_start d $SVC_FAST --watchdog 5 || return 1
    id=$(svc_submit a.rsr) || return 1
    i=0
    while [ "$(svc_field "$id" frames_done)" -lt 20 ] 2>/dev/null; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 300 ] || { echo "no progress"; return 1; }
    done
    w=$(svc_worker_pid "$SVC_PID" "$id") || return 1
    kill -STOP "$w" # hung: alive, but no frames
    svc_wait_state "$id" done 90 || return 1
    grep -q "job $id: no progress for 5 s" d.log || { cat d.log; return 1; }
    svc_field "$id" attempts | grep -qx 2 || return 1
    curl -s "$SVC_URL/metrics" | grep -q '^ringside_watchdog_kills_total 1$' || return 1
    svc_stop
}

t_retry_cap_dead_letters() {
    "$RS_BIN" record --ai --quiet --seconds 20 --seed 3 -o long.rsr || return 1
    svc_start d $SVC_FAST --max-attempts 2 || return 1
    id=$(svc_submit long.rsr) || return 1
    for attempt in 1 2; do
        i=0
        until [ "$(svc_field "$id" attempts)" = $attempt ] && w=$(svc_worker_pid "$SVC_PID" "$id"); do
            sleep 0.2; i=$((i + 1)); [ $i -lt 150 ] || { echo "attempt $attempt did not start"; return 1; }
        done
        sleep 0.5
        kill -KILL "$w"
    done
    svc_wait_state "$id" failed 30 || return 1
    svc_field "$id" error | grep -q "gave up after 2 attempts: the render process was killed by signal 9" ||
        { svc_field "$id" error; return 1; }
    sleep 1
    [ "$(svc_field "$id" state)" = failed ] || return 1
    svc_stop
}

t_config_file_and_errors() {
    printf 'workers = 2\n# a comment\n\nlisten = 127.0.0.1:0\nsize = 320x180  # trailing\n' >good.conf
    "$RS_BIN" serve --config good.conf --workers 3 --print-config >cfg.txt || return 1
    grep -qx 'workers = 3' cfg.txt && grep -qx 'size = 320x180' cfg.txt || { cat cfg.txt; return 1; }
    printf 'workers = 2\nlease = 1\n' >bad.conf
    expect_fail 2 '^ringside serve: bad.conf:2: lease: 1 is out of range \(expected 3\.\.3600\)' \
        "$RS_BIN" serve --config bad.conf || return 1
    printf 'workers 2\n' >bad2.conf
    expect_fail 2 "bad2.conf:1: expected 'name = value'" "$RS_BIN" serve --config bad2.conf || return 1
    printf 'colour = red\n' >bad3.conf
    expect_fail 2 "bad3.conf:1: unknown setting 'colour'" "$RS_BIN" serve --config bad3.conf || return 1
    expect_fail 1 "no-such.conf: cannot open the config file" "$RS_BIN" serve --config no-such.conf || return 1
    expect_fail 2 "size: '640' is not a size" "$RS_BIN" serve --size 640 || return 1
    expect_fail 2 "format: 'avi' is not one of mp4\|webm\|mkv" "$RS_BIN" serve --format avi || return 1
    expect_fail 2 "unexpected argument 'extra'" "$RS_BIN" serve extra || return 1
    # every setting is an option, with dashes or underscores; unknown ones are named
    "$RS_BIN" serve --max-seconds 60 --max_attempts 5 --token-seconds-per-hour 10 --retention 2h --print-config \
        >cfg2.txt || return 1
    grep -qx 'max_seconds = 60' cfg2.txt && grep -qx 'max_attempts = 5' cfg2.txt &&
        grep -qx 'token_seconds_per_hour = 10' cfg2.txt && grep -qx 'retention = 7200' cfg2.txt || { cat cfg2.txt; return 1; }
    expect_fail 2 "unknown option '--max-secs'" "$RS_BIN" serve --max-secs 60 || return 1
    expect_fail 2 "option '--workers' needs a value" "$RS_BIN" serve --workers || return 1
    expect_fail 1 "queue 'nonsense'" "$RS_BIN" serve --data dd --queue nonsense --listen 127.0.0.1:0 || return 1
    # one daemon per SQLite queue
    svc_start d $SVC_FAST || return 1
    expect_fail 1 "another daemon \(process $SVC_PID\) uses this queue" \
        "$RS_BIN" serve --data d --listen 127.0.0.1:0 || return 1
    "$RS_BIN" serve --help | grep -q "max_attempts" || return 1
    svc_stop
}

t_range_requests() {
    "$RS_BIN" record --ai --quiet --seconds 2 --seed 1 -o a.rsr || return 1
    svc_start d $SVC_FAST || return 1
    id=$(svc_submit a.rsr) || return 1
    svc_wait_state "$id" done 60 || return 1
    curl -sf -o full.mp4 "$SVC_URL/jobs/$id/video" || return 1
    size=$(stat -c %s full.mp4)
    curl -s -D h.txt -r 100-199 -o part.bin "$SVC_URL/jobs/$id/video"
    grep -q "^HTTP/1.1 206" h.txt && grep -qi "^Content-Range: bytes 100-199/$size" h.txt || { cat h.txt; return 1; }
    tail -c +101 full.mp4 | head -c 100 | cmp - part.bin || return 1
    curl -s -r -50 -o tail.bin "$SVC_URL/jobs/$id/video"
    tail -c 50 full.mp4 | cmp - tail.bin || return 1
    [ "$(curl -s -o /dev/null -w '%{http_code}' -r "$size-" "$SVC_URL/jobs/$id/video")" = 416 ] || return 1
    svc_stop
}

t_run ${T_ONLY:-readme_flow twenty_concurrent_jobs worker_killed_mid_render daemon_killed_and_restarted \
    sigterm_lets_running_jobs_finish sigterm_after_grace_requeues ctrl_c_to_the_whole_group \
    local_problems_do_not_burn_attempts bad_uploads_get_4xx \
    cancel_queued_and_running watchdog_kills_a_stalled_render \
    retry_cap_dead_letters config_file_and_errors range_requests}
t_done
