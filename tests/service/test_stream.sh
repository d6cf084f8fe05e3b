#!/bin/sh
# Watching while it renders (docs/service.md): a job's live HLS stream,
# GET /jobs/N/stream.m3u8 and its pieces, grows as units finish, in tick
# order, and ends with #EXT-X-ENDLIST once the job is done; its frames are
# the video's.  The first segment is short (first_segment_seconds).  Real
# HTTP, SQLite, real renders; small sizes.
. "$(dirname "$0")/../lib.sh"
. "$(dirname "$0")/svc_lib.sh"

vframes() { ffmpeg -v error -i "$1" -map 0:v -f framemd5 - | grep -v '^#' | cut -d, -f6; }

t_watch_while_it_renders() {
    command -v ffmpeg >/dev/null || t_skip_install "ffmpeg not installed"
    "$RS_BIN" record --ai --quiet --stage dojo --seconds 6 --seed 5 -o six.rsr || return 1
    # drawn at 320x180 so the second unit takes long enough to be seen running
    svc_start d $SVC_FAST --render-size 320x180 --workers 1 --first-segment-seconds 2 || return 1
    id=$(svc_submit six.rsr) || return 1
    # 2 s, then 4 s (first_segment_seconds 2, doubling)
    curl -s "$SVC_URL/jobs/$id" | python3 -c 'import json,sys
j = json.load(sys.stdin)
t = [s["ticks"] for s in j["segments"]]
assert t == [[0, 120], [120, 360]], t' || { curl -s "$SVC_URL/jobs/$id"; return 1; }
    # a playlist with pieces and no end while the job runs
    i=0
    while :; do
        curl -sf -o live.m3u8 "$SVC_URL/jobs/$id/stream.m3u8" || { echo "no playlist"; return 1; }
        st=$(svc_field "$id" state)
        grep -q '\.ts$' live.m3u8 && [ "$st" = running ] && break
        [ "$st" = done ] && { echo "never saw the stream while the job ran"; return 1; }
        sleep 0.1; i=$((i + 1)); [ $i -lt 600 ] || { echo "no piece listed in 60 s"; return 1; }
    done
    ! grep -q ENDLIST live.m3u8 || { echo "a running job's playlist has an end"; cat live.m3u8; return 1; }
    # the job says how much of it can be watched: the first unit's 2 s (or all 6, if the second just finished)
    ss=$(svc_field "$id" stream_s)
    [ "$ss" = 2.0 ] || { [ "$ss" = 6.0 ] && [ "$(svc_field "$id" segments.1.state)" = done ]; } ||
        { echo "stream_s $ss with the first unit listed"; return 1; }
    head -6 live.m3u8 | grep -qx '#EXT-X-PLAYLIST-TYPE:EVENT' && grep -qx '#EXT-X-TARGETDURATION:2' live.m3u8 ||
        { cat live.m3u8; return 1; }
    grep -qx 'stream/0.ts' live.m3u8 || { echo "the first piece is not tick 0's"; cat live.m3u8; return 1; }
    # a listed piece plays: H.264 and AAC, 120 frames
    curl -sf -o p0.ts "$SVC_URL/jobs/$id/stream/0.ts" || return 1
    [ "$(ffprobe -v error -show_entries stream=codec_name -of csv=p=0 p0.ts | grep . | sort -u | tr '\n' ' ')" = "aac h264 " ] ||
        { echo "piece 0 is not H.264 and AAC"; return 1; }
    [ "$(vframes p0.ts | wc -l)" = 120 ] || { echo "piece 0 is not 120 frames"; return 1; }
    # a piece not listed yet is 404 (unless its unit finished meanwhile)
    c=$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/jobs/$id/stream/240.ts")
    [ "$c" = 404 ] || [ "$(svc_field "$id" segments.1.state)" = done ] || { echo "an unlisted piece: $c"; return 1; }
    # a listed piece damaged while the job runs: its segment is rendered again (503 meanwhile)
    p=$(find "d/videos/$id.stream" -name t0.ts) && [ -n "$p" ] || { echo "no piece 0"; return 1; }
    printf 'x' | dd of="$p" bs=1 seek=1000 conv=notrunc 2>/dev/null
    c=$(curl -s -D hdr.txt -o /dev/null -w '%{http_code}' "$SVC_URL/jobs/$id/stream/0.ts")
    [ "$c" = 503 ] && grep -qi '^retry-after: 10' hdr.txt || { echo "a damaged piece of a running job: $c"; return 1; }
    svc_wait_state "$id" done 120 || return 1
    [ "$(svc_field "$id" segments.0.renders)" = 2 ] || { echo "segment 0 was not rendered again"; return 1; }
    # the same bytes as the piece first listed
    curl -sf -o p0-again.ts "$SVC_URL/jobs/$id/stream/0.ts" && cmp p0.ts p0-again.ts || { echo "piece 0 changed"; return 1; }
    curl -sf -o end.m3u8 "$SVC_URL/jobs/$id/stream.m3u8" || return 1
    tail -1 end.m3u8 | grep -qx '#EXT-X-ENDLIST' || { cat end.m3u8; return 1; }
    [ "$(svc_field "$id" stream_s)" = 6.0 ] || { echo "a done job's stream_s: $(svc_field "$id" stream_s)"; return 1; }
    # it only grew: what was listed is still listed, in the same place
    head -n "$(wc -l <live.m3u8)" end.m3u8 | cmp -s - live.m3u8 || { echo "the playlist changed what it listed"; return 1; }
    # every frame of the video, none twice, straight from the daemon
    curl -sf -o v.mp4 "$SVC_URL/jobs/$id/video" || return 1
    [ "$(vframes v.mp4 | wc -l)" = 360 ] && [ "$(vframes "$SVC_URL/jobs/$id/stream.m3u8" | md5sum)" = "$(vframes v.mp4 | md5sum)" ] ||
        { echo "the stream is not the video's frames"; return 1; }
    # the job's stream goes with it
    [ -d "d/videos/$id.stream" ] || { echo "no stream folder"; return 1; }
    curl -sf -X DELETE "$SVC_URL/jobs/$id" >/dev/null || return 1
    [ ! -e "d/videos/$id.stream" ] || { echo "DELETE left the stream"; return 1; }
    [ "$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/jobs/$id/stream.m3u8")" = 404 ] || return 1
    svc_stop
}

t_no_stream_answers() {
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 3 -o a.rsr || return 1
    svc_start d $SVC_FAST || return 1
    # a .webm job (VP9) has no HLS stream, and says why
    id=$(svc_submit a.rsr format=webm) || return 1
    c=$(curl -s -o body.txt -w '%{http_code}' "$SVC_URL/jobs/$id/stream.m3u8")
    [ "$c" = 404 ] && grep -q 'H.264 or HEVC' body.txt || { echo "$c $(cat body.txt)"; return 1; }
    svc_wait_state "$id" done 60 || return 1
    [ ! -e "d/videos/$id.stream" ] || { echo "a webm job got a stream folder"; return 1; }
    # no such job; a malformed piece name
    [ "$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/jobs/99/stream.m3u8")" = 404 ] || return 1
    [ "$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/jobs/$id/stream/01.ts")" = 404 ] || return 1
    # a damaged piece is never sent (410, named in the log)
    id=$(svc_submit a.rsr) || return 1
    svc_wait_state "$id" done 60 || return 1
    p=$(find "d/videos/$id.stream" -name t0.ts) && [ -n "$p" ] || { echo "no piece 0"; return 1; }
    printf 'x' | dd of="$p" bs=1 seek=1000 conv=notrunc 2>/dev/null
    c=$(curl -s -o body.txt -w '%{http_code}' "$SVC_URL/jobs/$id/stream/0.ts")
    [ "$c" = 410 ] || { echo "a damaged piece: $c"; return 1; }
    grep -q "t0.ts: not the bytes of its index" d.log || { tail -5 d.log; return 1; }
    # what a killed render left in the folder goes with the next sweep; a live one's stays
    sh -c 'exit 0' & dead=$!
    wait $dead
    k=$(dirname "$p")
    touch "$k/.t120.ts.$dead.part" "$k/.u0.idx.$SVC_PID.part"
    i=0
    while [ -e "$k/.t120.ts.$dead.part" ]; do
        sleep 0.5; i=$((i + 1)); [ $i -lt 30 ] || { echo "a dead render's temporary stays"; ls -la "$k"; return 1; }
    done
    [ -e "$k/.u0.idx.$SVC_PID.part" ] || { echo "a live process's temporary was removed"; return 1; }
    svc_stop
}

# GET /jobs/events (docs/service.md, "Events"): the page of jobs, then each
# change of a job on it, pushed; a token's stream shows its own jobs only;
# a revoked token's stream ends, the 65th stream is refused, and stopping
# the daemon ends the rest.
t_events_pushed() {
    "$RS_BIN" record --ai --quiet --seconds 2 --seed 3 -o a.rsr || return 1
    alice=$("$RS_BIN" serve token add alice --data d 2>add.err) || { cat add.err; return 1; }
    bob=$("$RS_BIN" serve token add bob --data d 2>add.err) || { cat add.err; return 1; }
    svc_start d $SVC_FAST --workers 1 || return 1
    [ "$(curl -s -o /dev/null -w '%{http_code}' "$SVC_URL/jobs/events")" = 401 ] || { echo "no token: not 401"; return 1; }
    [ "$(curl -s -o /dev/null -w '%{http_code}' -H "Authorization: Bearer $alice" "$SVC_URL/jobs/events?limit=0")" = 400 ] ||
        { echo "limit=0: not 400"; return 1; }
    curl -sN -H "Authorization: Bearer $alice" "$SVC_URL/jobs/events" >a.ev 2>/dev/null &
    ca=$!
    curl -sN -H "Authorization: Bearer $bob" "$SVC_URL/jobs/events?limit=1" >b.ev 2>/dev/null &
    cb=$!
    i=0
    until grep -q '^data: {"jobs":\[\],"next":null}$' a.ev && grep -q '^event: jobs$' b.ev; do
        sleep 0.1; i=$((i + 1)); [ $i -lt 50 ] || { echo "no first page"; cat a.ev b.ev; return 1; }
    done
    submit() { curl -s -X POST --data-binary @a.rsr -H "Authorization: Bearer $1" "$SVC_URL/jobs?name=a.rsr" | json_get id; }
    ia=$(submit "$alice") && ib=$(submit "$bob") || return 1
    # alice's job comes onto her page, runs and is done: pushed, never polled
    i=0
    until grep -q "^data: {\"id\":$ia,\"state\":\"done\"" a.ev; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 300 ] || { echo "no done event"; tail -c 2000 a.ev; return 1; }
    done
    grep -q "^data: {\"jobs\":\[{\"id\":$ia,\"state\":\"queued\"" a.ev || { echo "the job did not come queued onto the page"; return 1; }
    grep -q "^data: {\"id\":$ia,\"state\":\"running\",.*\"stream_s\":" a.ev || { echo "no running event with stream_s"; return 1; }
    ! grep -q "\"id\":$ib," a.ev || { echo "alice's stream shows bob's job"; return 1; }
    i=0
    until grep -q "\"id\":$ib,\"state\":\"done\"" b.ev; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 300 ] || { echo "bob's stream: no done event"; tail -c 2000 b.ev; return 1; }
    done
    ! grep -q "\"id\":$ia," b.ev || { echo "bob's stream shows alice's job"; return 1; }
    curl -s -H "Authorization: Bearer $alice" "$SVC_URL/metrics" | grep -qx 'ringside_event_streams 2' ||
        { echo "metrics:"; curl -s -H "Authorization: Bearer $alice" "$SVC_URL/metrics" | grep event; return 1; }
    # a revoked token's stream ends within seconds, saying why
    "$RS_BIN" serve token revoke alice --data d 2>/dev/null || return 1
    i=0
    while kill -0 $ca 2>/dev/null; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 50 ] || { echo "the revoked token's stream goes on"; return 1; }
    done
    tail -2 a.ev | grep -qx 'data: {"reason":"the token was revoked"}' || { tail -3 a.ev; return 1; }
    # at most 64 streams: the 65th is told to come back
    for n in $(seq 63); do curl -sN -H "Authorization: Bearer $bob" "$SVC_URL/jobs/events" >/dev/null 2>&1 & done
    i=0
    until curl -s -H "Authorization: Bearer $bob" "$SVC_URL/metrics" | grep -qx 'ringside_event_streams 64'; do
        sleep 0.1; i=$((i + 1)); [ $i -lt 100 ] || { echo "64 streams did not open"; return 1; }
    done
    c=$(curl -s -o body.txt -D head.txt -w '%{http_code}' -H "Authorization: Bearer $bob" "$SVC_URL/jobs/events")
    [ "$c" = 503 ] && grep -qi '^retry-after: 5' head.txt && grep -q '64 event streams are open' body.txt ||
        { echo "the 65th stream: $c $(cat body.txt)"; return 1; }
    # stopping the daemon ends every stream, at once
    t0=$(date +%s)
    svc_stop
    [ "$SVC_RC" = 0 ] || { echo "the daemon exited $SVC_RC"; tail -20 d.log; return 1; }
    [ $(($(date +%s) - t0)) -lt 10 ] || { echo "the daemon took $(($(date +%s) - t0)) s to stop with streams open"; return 1; }
    wait $cb
    tail -2 b.ev | grep -qx 'data: {"reason":"the daemon is stopping"}' || { tail -3 b.ev; return 1; }
}

t_run ${T_ONLY:-watch_while_it_renders no_stream_answers events_pushed}
t_done
