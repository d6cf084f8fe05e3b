#!/bin/sh
# Sound in the service's videos (docs/service.md, "Sound"): a split job's
# segments are silent and its join mixes the replay's track once for the
# whole video (`join --replay`); a whole job's render has it too.  The
# joined audio is a single render's, decoded.  Real HTTP, SQLite, real
# renders; small sizes.
. "$(dirname "$0")/../lib.sh"
. "$(dirname "$0")/svc_lib.sh"

# the decoded sound of FILE as mono float32 into OUT; its length in samples
pcm_of() { ffmpeg -v error -y -i "$1" -map 0:a:0 -ac 1 -f f32le "$2" && echo $(($(wc -c <"$2") / 4)); }

t_joined_job_has_audio() {
    command -v ffmpeg >/dev/null || t_skip_install "ffmpeg not installed"
    "$RS_BIN" record --ai --quiet --stage dojo --seconds 3 --seed 5 -o three.rsr || return 1
    svc_start d $SVC_FAST --workers 2 --segment-seconds 1 || return 1
    id=$(svc_submit three.rsr) || return 1
    [ "$(svc_field "$id" segment_count)" = 3 ] || { curl -s "$SVC_URL/jobs/$id"; return 1; }
    svc_wait_state "$id" done 120 || return 1
    curl -sf -o v.mp4 "$SVC_URL/jobs/$id/video" || return 1
    [ "$(ffprobe -v error -select_streams a:0 -show_entries stream=codec_name -of csv=p=0 v.mp4)" = aac ] ||
        { echo "the joined video has no AAC stream"; ffprobe -v error -show_streams v.mp4 | grep codec_name; return 1; }
    # the same samples as one render of the whole replay (same encoder, same track)
    "$RS_BIN" render three.rsr -o direct.mp4 --render-size 160x90 --size 160x90 --quiet || return 1
    n=$(pcm_of v.mp4 v.f32) && m=$(pcm_of direct.mp4 d.f32) || return 1
    echo "joined: $n samples, direct render: $m"
    [ "$n" -ge 144000 ] && [ "$n" -le 145024 ] || { echo "joined audio is $n samples, not 3 s (+ one AAC frame)"; return 1; }
    cmp v.f32 d.f32 || { echo "the joined job's sound differs from a whole render's"; return 1; }
    # the segments themselves carry no sound
    seg=$(find d -name 's0-a1.mp4' | head -1)
    [ -z "$seg" ] || [ -z "$(ffprobe -v error -select_streams a -show_entries stream=codec_name -of csv=p=0 "$seg")" ] ||
        { echo "segment $seg has audio"; return 1; }
    svc_stop
}

t_whole_job_has_audio() {
    command -v ffmpeg >/dev/null || t_skip_install "ffmpeg not installed"
    "$RS_BIN" record --ai --quiet --stage dojo --seconds 2 --seed 6 -o two.rsr || return 1
    svc_start d $SVC_FAST --workers 1 || return 1
    id=$(svc_submit two.rsr) || return 1
    svc_wait_state "$id" done 120 || return 1
    curl -sf -o v.mp4 "$SVC_URL/jobs/$id/video" || return 1
    [ "$(ffprobe -v error -select_streams a:0 -show_entries stream=codec_name -of csv=p=0 v.mp4)" = aac ] ||
        { echo "the job's video has no AAC stream"; return 1; }
    svc_stop
}

# audio=off (query or form field): no sound in the segments' join or a whole render; the job JSON says so
t_audio_off() {
    command -v ffprobe >/dev/null || t_skip_install "ffprobe not installed"
    "$RS_BIN" record --ai --quiet --stage dojo --seconds 2 --seed 7 -o two.rsr || return 1
    svc_start d $SVC_FAST --workers 2 --segment-seconds 1 || return 1
    code=$(curl -s -o bad.json -w '%{http_code}' -X POST --data-binary @two.rsr "$SVC_URL/jobs?audio=maybe")
    [ "$code" = 400 ] && grep -q "audio 'maybe': expected on or off" bad.json || { echo "audio=maybe: $code $(cat bad.json)"; return 1; }
    id=$(svc_submit two.rsr "audio=off") || return 1
    on=$(svc_submit two.rsr) || return 1
    [ "$(svc_field "$id" audio)" = false ] && [ "$(svc_field "$on" audio)" = true ] ||
        { echo "job JSON audio: $(svc_field "$id" audio) / $(svc_field "$on" audio)"; return 1; }
    svc_wait_state "$id" done 120 && svc_wait_state "$on" done 120 || return 1
    curl -sf -o off.mp4 "$SVC_URL/jobs/$id/video" && curl -sf -o on.mp4 "$SVC_URL/jobs/$on/video" || return 1
    [ -z "$(ffprobe -v error -select_streams a -show_entries stream=codec_name -of csv=p=0 off.mp4)" ] ||
        { echo "audio=off: the video has sound"; return 1; }
    [ "$(ffprobe -v error -select_streams a -show_entries stream=codec_name -of csv=p=0 on.mp4)" = aac ] ||
        { echo "the default job has no sound"; return 1; }
    svc_stop
}

t_run ${T_ONLY:-joined_job_has_audio whole_job_has_audio audio_off}
t_done
