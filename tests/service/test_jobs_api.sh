#!/bin/sh
# The job API the dashboard reads (docs/service.md, "HTTP API"): a poster per job, the render
# log, retry of a failed job, paging, the replay's header, queue position
# and ETA.  Real HTTP over loopback (curl), the real SQLite queue.
. "$(dirname "$0")/../lib.sh"
. "$(dirname "$0")/svc_lib.sh"

code() { # METHOD PATH [curl options...] -> the status; the body in body.txt
    m=$1 p=$2
    shift 2
    curl -s -o body.txt -w '%{http_code}' -X "$m" "$@" "$SVC_URL$p"
}

png_size() { python3 -c 'import struct,sys
b = open(sys.argv[1], "rb").read(24)
assert b[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
print("%dx%d" % struct.unpack(">II", b[16:24]))' "$1"; }

t_poster_log_and_fields() {
    "$RS_BIN" record --ai --quiet --seconds 2 --seed 5 --stage 2 -o a.rsr || return 1
    svc_start d $SVC_FAST || return 1
    id=$(svc_submit a.rsr) || return 1
    [ "$(code GET "/jobs/$id/poster")" = 404 ] || { echo "poster before the render: not 404"; cat body.txt; return 1; }
    svc_wait_state "$id" done 60 || return 1
    [ "$(code GET "/jobs/$id/poster" -D h.txt)" = 200 ] || { cat body.txt; return 1; }
    grep -qi '^content-type: image/png' h.txt || { cat h.txt; return 1; }
    cp body.txt poster.png
    [ "$(png_size poster.png)" = 160x90 ] || { echo "poster is $(png_size poster.png), want 160x90"; return 1; }
    [ -f d/videos/$id.png ] || { ls -la d/videos; return 1; }
    # the log: the attempt's header and the render's own lines
    [ "$(code GET "/jobs/$id/log" -D h.txt)" = 200 ] || { cat body.txt; return 1; }
    grep -qi '^content-type: text/plain' h.txt || { cat h.txt; return 1; }
    grep -q "^== render, attempt 1, process [0-9]*: exit status 0 after" body.txt || { cat body.txt; return 1; }
    # whole lines (the summary runs past 200 characters), under the names the
    # client knows: the job's video and poster, never the render's temporaries
    grep -q "^ringside render: wrote .*/videos/$id\.mp4: 120 frames 160x90 .*; encoder [a-z0-9]*$" body.txt ||
        { cat body.txt; return 1; }
    grep -q "^ringside render: poster .*/videos/$id\.png: frame [0-9]* (" body.txt || { cat body.txt; return 1; }
    ! grep -q '\.job[0-9]' body.txt || { echo "the log names temporary files:"; cat body.txt; return 1; }
    # the fields the dashboard shows
    curl -sf "$SVC_URL/jobs/$id" >j.json || return 1
    for f in stage:temple players.0:cpu players.1:cpu length_s:2.0 codec:h264 format:mp4 queue_position:null \
        poster:/jobs/$id/poster log:/jobs/$id/log; do
        got=$(json_get "${f%%:*}" <j.json)
        [ "$got" = "${f#*:}" ] || { echo "${f%%:*}: '$got', want '${f#*:}'"; cat j.json; return 1; }
    done
    [ "$(json_get bytes <j.json)" = "$(stat -c %s d/videos/$id.mp4)" ] || { cat j.json; return 1; }
    case "$(json_get render_s <j.json)" in [0-9]*) ;; *) cat j.json; return 1 ;; esac
    # the list carries them too
    curl -sf "$SVC_URL/jobs" | json_get jobs.0.stage | grep -qx temple || return 1
    # DELETE takes the poster and the log with the video
    [ "$(code DELETE "/jobs/$id")" = 200 ] || { cat body.txt; return 1; }
    [ ! -e d/videos/$id.png ] && [ ! -e d/videos/$id.log ] || { ls -la d/videos; return 1; }
    [ "$(code GET "/jobs/$id/poster")" = 404 ] || return 1
    svc_stop
}

t_other_tokens_get_404() {
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 3 -o a.rsr || return 1
    mkdir -p d
    a=$("$RS_BIN" serve token add alice --data d 2>/dev/null) || return 1
    b=$("$RS_BIN" serve token add bob --data d 2>/dev/null) || return 1
    svc_start d $SVC_FAST || return 1
    body=$(curl -s -X POST --data-binary @a.rsr -H "Authorization: Bearer $a" "$SVC_URL/jobs?name=a.rsr")
    id=$(echo "$body" | json_get id) || return 1
    i=0
    until [ "$(curl -s -H "Authorization: Bearer $a" "$SVC_URL/jobs/$id" | json_get state)" = done ]; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 300 ] || { echo "job $id not done"; return 1; }
    done
    [ "$(code GET "/jobs/$id/poster" -H "Authorization: Bearer $a")" = 200 ] || { cat body.txt; return 1; }
    [ "$(code GET "/jobs/$id/log" -H "Authorization: Bearer $a")" = 200 ] || { cat body.txt; return 1; }
    for r in "GET /poster" "GET /log" "POST /retry"; do
        c=$(code ${r% *} "/jobs/$id${r#* }" -H "Authorization: Bearer $b")
        [ "$c" = 404 ] || { echo "bob's $r of alice's job: $c"; cat body.txt; return 1; }
        c=$(code ${r% *} "/jobs/$id${r#* }")
        [ "$c" = 401 ] || { echo "$r without a token: $c"; return 1; }
    done
    svc_stop
}

t_retry_a_failed_job() {
    "$RS_BIN" record --ai --quiet --seconds 10 --seed 3 -o long.rsr || return 1
    svc_start d $SVC_FAST --max-attempts 1 || return 1
    id=$(svc_submit long.rsr) || return 1
    i=0
    until w=$(svc_worker_pid "$SVC_PID" "$id"); do
        sleep 0.1; i=$((i + 1)); [ $i -lt 300 ] || { echo "the render did not start"; return 1; }
    done
    sleep 0.5
    kill -KILL "$w"
    svc_wait_state "$id" failed 30 || return 1
    curl -sf "$SVC_URL/jobs/$id/log" | grep -q "^== render, attempt 1, process $w: killed by signal 9" ||
        { curl -s "$SVC_URL/jobs/$id/log"; return 1; }
    [ "$(code POST "/jobs/$id/retry")" = 200 ] || { cat body.txt; return 1; }
    case "$(json_get state <body.txt)" in queued | running) ;; *) cat body.txt; return 1 ;; esac
    [ "$(json_get error <body.txt)" = null ] || { cat body.txt; return 1; }
    svc_wait_state "$id" done 120 || return 1
    [ "$(svc_field "$id" attempts)" = 1 ] || { curl -s "$SVC_URL/jobs/$id"; return 1; }
    # the log keeps both attempts
    [ "$(curl -sf "$SVC_URL/jobs/$id/log" | grep -c '^== render, attempt 1')" = 2 ] || { curl -s "$SVC_URL/jobs/$id/log"; return 1; }
    [ "$(code POST "/jobs/$id/retry")" = 409 ] || { echo "retry of a done job: not 409"; cat body.txt; return 1; }
    grep -q "only a failed job can be retried" body.txt || { cat body.txt; return 1; }
    [ "$(code GET "/jobs/$id/retry")" = 405 ] || return 1
    [ "$(code POST "/jobs/999/retry")" = 404 ] || return 1
    svc_stop
}

t_paging_covers_every_job() {
    svc_replays r 5 1 || return 1
    svc_start d $SVC_FAST || return 1
    for k in 1 2 3 4 5; do svc_submit r/r$k.rsr >>ids.txt || return 1; done
    url="/jobs?limit=2" pages=0
    while [ "$url" != null ]; do
        curl -sf "$SVC_URL$url" >page.json || return 1
        python3 -c 'import json; [print(j["id"]) for j in json.load(open("page.json"))["jobs"]]' >>seen.txt
        url=$(json_get next <page.json)
        pages=$((pages + 1))
        [ $pages -le 4 ] || { echo "paging does not end"; return 1; }
    done
    [ "$(sort -n ids.txt | tr '\n' ' ')" = "$(sort -n seen.txt | tr '\n' ' ')" ] ||
        { echo "pages: $(cat seen.txt | tr '\n' ' '), jobs: $(cat ids.txt | tr '\n' ' ')"; return 1; }
    [ "$(sort seen.txt | uniq -d)" = "" ] || { echo "pages overlap"; return 1; }
    [ $pages = 3 ] || { echo "$pages pages of 2 for 5 jobs"; return 1; }
    svc_stop
}

t_queue_position_counts_down() {
    svc_replays r 4 3 || return 1
    svc_start d $SVC_FAST --workers 1 || return 1
    first=$(svc_submit r/r1.rsr) || return 1
    svc_wait_state "$first" done 60 || return 1 # one done: the render speed is known
    for k in 2 3 4; do last=$(svc_submit r/r$k.rsr) || return 1; done
    seen=""
    while :; do
        curl -sf "$SVC_URL/jobs/$last" >j.json || return 1
        st=$(json_get state <j.json)
        [ "$st" = queued ] || break
        p=$(json_get queue_position <j.json)
        case "$seen" in *" $p") ;; *) seen="$seen $p" ;; esac
        [ "$(json_get eta_s <j.json)" != null ] || { echo "a queued job without an ETA"; cat j.json; return 1; }
        sleep 0.1
    done
    case "$seen" in " 2 1" | " 3 2 1") ;; *) echo "positions seen:$seen"; return 1 ;; esac
    svc_wait_state "$last" done 60 || return 1
    svc_stop
}

# Encoder options as job parameters, inside the operator's bounds: a job
# that asks for HEVC gets an HEVC stream (and the JSON says so); what is
# outside the bounds or the container is refused at upload, naming it.
t_encoder_options() {
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 4 -o a.rsr || return 1
    svc_start d $SVC_FAST --presets veryfast,fast,4..13 --min-crf 20 --codecs h264,hevc,vp9 || return 1
    id=$(svc_submit a.rsr "codec=hevc&crf=30&preset=fast") || return 1
    svc_wait_state "$id" done 60 || return 1
    [ "$(ffprobe -v error -select_streams v -show_entries stream=codec_name -of csv=p=0 d/videos/$id.mp4)" = hevc ] ||
        { echo "job $id is not HEVC"; cat d.log; return 1; }
    curl -sf "$SVC_URL/jobs/$id" >j.json || return 1
    [ "$(json_get codec <j.json)" = hevc ] && [ "$(json_get encode <j.json)" = "codec=hevc crf=30 preset=fast quality=standard" ] &&
        [ "$(json_get quality <j.json)" = standard ] || { cat j.json; return 1; }
    # the quality preset: stored with the job, given to its renders, drawn at the size it sets
    id3=$(svc_submit a.rsr "quality=draft") || return 1
    svc_wait_state "$id3" done 60 || return 1
    curl -sf "$SVC_URL/jobs/$id3" >j3.json && [ "$(json_get quality <j3.json)" = draft ] || { cat j3.json; return 1; }
    curl -sf "$SVC_URL/jobs/$id3/log" | grep -q "(drawn at 160x90, the scene at 96x54, quality draft)" ||
        { echo "job $id3 was not rendered with quality draft"; curl -s "$SVC_URL/jobs/$id3/log"; return 1; }
    # a form field works like the query parameter
    id2=$(curl -s -F replay=@a.rsr -F format=webm -F codec=vp9 -F preset=8 "$SVC_URL/jobs" | json_get id) || return 1
    svc_wait_state "$id2" done 60 || return 1
    [ "$(ffprobe -v error -select_streams v -show_entries stream=codec_name -of csv=p=0 d/videos/$id2.webm)" = vp9 ] ||
        { echo "job $id2 is not VP9"; return 1; }
    for q in "codec=av1:setting codecs" "crf=10:setting min_crf" "preset=placebo:setting presets" \
        "codec=vp9&format=mp4:MP4 does not hold vp9" "codec=h265:codec 'h265'" "pix_fmt=rgb24:pix_fmt 'rgb24'" \
        "bitrate=900M:setting max_bitrate" "crf=25&bitrate=1M:exclude each other" "preset=x%3Bid:preset 'x;id'" \
        "quality=ultra:quality 'ultra': expected draft, standard, high or reference"; do
        [ "$(code POST "/jobs?${q%%:*}" --data-binary @a.rsr)" = 400 ] && grep -q "${q#*:}" body.txt ||
            { echo "'${q%%:*}': want 400 naming '${q#*:}'"; cat body.txt; return 1; }
    done
    svc_stop
}

t_run encoder_options poster_log_and_fields other_tokens_get_404 retry_a_failed_job paging_covers_every_job queue_position_counts_down
t_done
