#!/bin/sh
# End-to-end: the movies' sound in `ringside movie` and `ringside attract`,
# and the attract loop's game sound, through the real binary with
# --audio-out, on clips made here by the ffmpeg command line (nothing
# committed).  The soundtrack is compared with ffmpeg's own decode
# (-ac 2 -ar 48000) by tests/au_xcorr.c, compiled here.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
XCORR=$T_TMP/au_xcorr

need_tools() {
    command -v ffmpeg >/dev/null && command -v soxi >/dev/null || t_skip_install "needs ffmpeg and sox (tools/deps.sh test)"
    [ -x "$XCORR" ] || ${CC:-cc} -O2 -o "$XCORR" "$SRC/tests/au_xcorr.c" -lm || { echo "cannot build au_xcorr"; return 1; }
}

# mkmovie OUT VIDEO_SECONDS AUDIO_SOURCE [ffmpeg output options...]: 64x36 at 30 fps
# with the lavfi audio source given ("" for none)
mkmovie() {
    out=$1 vd=$2 asrc=$3
    shift 3
    if [ -n "$asrc" ]; then
        ffmpeg -nostdin -hide_banner -loglevel error -y -f lavfi -i "testsrc2=size=64x36:rate=30:d=$vd" \
            -f lavfi -i "$asrc" -c:v mpeg4 "$@" "$out" || { echo "ffmpeg could not make $out"; return 1; }
    else
        ffmpeg -nostdin -hide_banner -loglevel error -y -f lavfi -i "testsrc2=size=64x36:rate=30:d=$vd" \
            -c:v mpeg4 "$@" "$out" || { echo "ffmpeg could not make $out"; return 1; }
    fi
}

# f32 IN OUT: IN's audio as ffmpeg decodes it, stereo 48 kHz float
f32() { ffmpeg -nostdin -hide_banner -loglevel error -y -i "$1" -vn -ac 2 -ar 48000 -f f32le "$2"; }

# ref MOVIE OUT: ffmpeg's decode of MOVIE's audio from the picture's first
# frame on: the player's tick 0.  ffmpeg's raw decode starts at the first
# decoded sample, which can lie before the picture: AAC in Matroska keeps
# the encoder's 1024 priming samples (the muxer starts the video 23 ms in),
# Opus in WebM starts 7 ms before.  The player cuts what lies before the
# picture, so ffmpeg is told to cut it too (atrim at the track's own rate,
# before resampling, as the player does).  In MP4 (edit lists) both start at 0.
ref() {
    v=$(ffprobe -v error -select_streams v:0 -show_entries stream=start_time -of csv=p=0 "$1") &&
        a=$(ffprobe -v error -select_streams a:0 -read_intervals %+#1 -show_entries frame=best_effort_timestamp_time \
            -of csv=p=0 "$1" | head -n 1) &&
        r=$(ffprobe -v error -select_streams a:0 -show_entries stream=sample_rate -of csv=p=0 "$1") || return 1
    skip=$(awk -v v="$v" -v a="$a" -v r="$r" 'BEGIN { d = (v - a) * r; printf "%d", (d > 0 ? d + 0.5 : 0) }')
    echo "  $1: the picture starts $skip samples into the sound"
    ffmpeg -nostdin -hide_banner -loglevel error -y -i "$1" -vn -af "atrim=start_sample=$skip" -ac 2 -ar 48000 -f f32le "$2"
}

# xc A.f32 B.f32 [FROM COUNT [MAXLAG]]: sets corr, lag, rms_a, rms_b
xc() {
    r=$("$XCORR" "$@") || return 1
    echo "  xcorr $*: $r"
    set -- $r
    corr=$2 lag=$4 rms_a=$6 rms_b=$8
}

ge() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a >= b) }'; }

# the issue's check: attract with a movie that has sound, headless, writes
# a WAV that matches ffmpeg's decode of the track (corr >= 0.99, |offset| <= 48)
t_attract_movie_matches_ffmpeg() {
    need_tools || return 1
    mkmovie m.mkv 2 "anoisesrc=d=2:c=pink:r=44100:a=0.25" -c:a aac -ac 2 || return 1
    "$RS_BIN" attract m.mkv --headless --ticks 120 --size 64x36 --audio-out x.wav 2>e.txt || { cat e.txt; return 1; }
    [ "$(soxi -s x.wav)" = 96000 ] || { echo "want 120 ticks x 800 frames"; soxi x.wav; return 1; }
    f32 x.wav got.f32 && ref m.mkv ref.f32 || return 1
    xc got.f32 ref.f32 || return 1
    ge "$corr" 0.99 && [ "$lag" -ge -48 ] && [ "$lag" -le 48 ] || { echo "corr $corr at offset $lag frames"; return 1; }
    # WebM with Opus (its pre-skip), and MP4 with AAC against ffmpeg's raw decode as is
    ffmpeg -nostdin -hide_banner -loglevel error -y -f lavfi -i testsrc2=size=64x36:rate=30:d=2 \
        -f lavfi -i "anoisesrc=d=2:c=pink:r=48000:a=0.25" -c:v libvpx-vp9 -deadline realtime -c:a libopus -ac 2 w.webm &&
        ffmpeg -nostdin -hide_banner -loglevel error -y -f lavfi -i testsrc2=size=64x36:rate=30:d=2 \
            -f lavfi -i "anoisesrc=d=2:c=pink:r=44100:a=0.25" -c:v libx264 -preset ultrafast -c:a aac -ac 2 a.mp4 || return 1
    "$RS_BIN" attract w.webm --headless --ticks 120 --size 64x36 --audio-out w.wav -q &&
        "$RS_BIN" attract a.mp4 --headless --ticks 120 --size 64x36 --audio-out a.wav -q || return 1
    f32 w.wav gotw.f32 && ref w.webm refw.f32 && f32 a.wav gota.f32 && f32 a.mp4 rawa.f32 || return 1
    xc gotw.f32 refw.f32 || return 1
    ge "$corr" 0.99 && [ "$lag" -ge -48 ] && [ "$lag" -le 48 ] || { echo "webm: corr $corr at offset $lag frames"; return 1; }
    xc gota.f32 rawa.f32 || return 1
    ge "$corr" 0.99 && [ "$lag" -ge -48 ] && [ "$lag" -le 48 ] || { echo "mp4: corr $corr at offset $lag frames"; return 1; }
}

# a button press starts a match: the movie's sound stops on that tick, the
# match has its own; --attract-sound off silences the loop, not the match
t_button_cuts_movie_sound_and_attract_sound_off() {
    need_tools || return 1
    mkmovie m.mkv 2 "anoisesrc=d=2:c=pink:r=48000:a=0.25" -c:a pcm_s16le -ac 2 || return 1
    printf '60 p1 punch\n62 p1 -\n' >in.txt
    "$RS_BIN" attract m.mkv --headless --ticks 240 --size 64x36 --script in.txt --audio-out on.wav 2>e.txt ||
        { cat e.txt; return 1; }
    f32 on.wav on.f32 && ref m.mkv ref.f32 || return 1
    xc on.f32 ref.f32 0 48000 0 || return 1 # ticks 0..59: the movie
    ge "$corr" 0.99 || { echo "before the press: not the movie's sound"; return 1; }
    xc on.f32 ref.f32 48000 48000 0 || return 1 # ticks 60..119: the match, not the movie
    ge "$corr" 0.2 && { echo "the movie's sound goes on after the press"; return 1; }
    xc on.f32 on.f32 49600 140800 0 || return 1
    ge "$rms_a" 0.001 || { echo "the match is silent"; return 1; }
    "$RS_BIN" attract m.mkv --headless --ticks 240 --size 64x36 --script in.txt --audio-out off.wav \
        --attract-sound off 2>e2.txt || { cat e2.txt; return 1; }
    f32 off.wav off.f32 || return 1
    xc off.f32 off.f32 0 48000 0 || return 1
    [ "$rms_a" = 0.000000 ] || { echo "--attract-sound off: the loop is not silent"; return 1; }
    xc off.f32 on.f32 49600 140800 0 || return 1
    ge "$corr" 0.999 || { echo "--attract-sound off changed the match's sound"; return 1; }
    expect_fail 2 "--attract-sound 'loud': expected on or off" "$RS_BIN" attract --attract-sound loud || return 1
}

# a demo in the loop sounds exactly like the replay's soundtrack (unnormalized)
t_demo_sounds_like_its_replay() {
    need_tools || return 1
    "$RS_BIN" attract --demo "$SRC/demos/dojo.rsr" --headless --ticks 300 --size 64x36 --audio-out d.wav 2>e.txt ||
        { cat e.txt; return 1; }
    "$RS_BIN" replay sound "$SRC/demos/dojo.rsr" --ticks 0:300 --loudness off -o r.wav 2>e2.txt || { cat e2.txt; return 1; }
    a=$(ffmpeg -nostdin -loglevel error -i d.wav -f s16le - | md5sum) && b=$(ffmpeg -nostdin -loglevel error -i r.wav -f s16le - | md5sum) ||
        return 1
    [ "$a" = "$b" ] || { echo "the demo's sound differs from replay sound"; soxi d.wav r.wav; return 1; }
    sox d.wav -n stat 2>&1 | grep -q "RMS     amplitude:     0.000000" && { echo "the demo is silent"; return 1; }
    return 0
}

# one_format NAME AUDIO_SOURCE [ffmpeg audio options...]: a 1 s movie plays 60
# ticks whose sound is ffmpeg's decode of its track, at offset 0
one_format() {
    name=$1 src=$2
    shift 2
    mkmovie "$name.mkv" 1 "$src" "$@" || return 1
    "$RS_BIN" movie "$name.mkv" --headless --audio-out "$name.wav" 2>e.txt || { cat e.txt; return 1; }
    grep "sound:" e.txt
    [ "$(soxi -s "$name.wav")" = 48000 ] || { echo "$name: want 60 ticks of sound"; return 1; }
    f32 "$name.wav" got.f32 && ref "$name.mkv" ref.f32 || return 1
    n=$(($(stat -c %s ref.f32) / 8))
    [ "$n" -gt 48000 ] && n=48000
    xc got.f32 ref.f32 0 "$n" 48 || return 1
    ge "$corr" 0.99 && [ "$lag" = 0 ] || { echo "$name: corr $corr at lag $lag"; return 1; }
}

# movie: layouts, rates and sample formats all play, downmixed and resampled as ffmpeg does
t_movie_layouts_rates_formats() {
    need_tools || return 1
    one_format mono-s16-44k "sine=f=440:sample_rate=44100:d=1" -c:a pcm_s16le -ac 1 || return 1
    one_format 51-aac-48k "aevalsrc=sin(2*PI*220*t)|0.5*sin(2*PI*330*t)|0.7*sin(2*PI*440*t)|0.3*sin(2*PI*110*t)|0.4*sin(2*PI*550*t)|0.6*sin(2*PI*660*t):c=5.1:s=48000:d=1" \
        -c:a aac || return 1
    one_format u8-32k "sine=f=300:sample_rate=32000:d=1" -c:a pcm_u8 -ac 2 || return 1
    one_format float-44k "anoisesrc=d=1:c=pink:r=44100:a=0.3" -c:a pcm_f32le -ac 2 || return 1
    one_format mp3-32k "anoisesrc=d=1:c=white:r=32000:a=0.2" -c:a libmp3lame -ac 1 || return 1
    grep -q "sound: mp3 32000 Hz mono fltp" e.txt || { echo "the summary does not name the stream"; return 1; }
}

t_movie_without_audio() {
    need_tools || return 1
    mkmovie v.mkv 1 "" || return 1
    "$RS_BIN" movie v.mkv --headless --audio-out v.wav 2>e.txt || { cat e.txt; return 1; }
    grep -q "sound: none (no audio stream)" e.txt || { cat e.txt; return 1; }
    [ "$(soxi -s v.wav)" = 48000 ] || return 1
    sox v.wav -n stat 2>&1 | grep -q "Maximum amplitude:     0.000000" || { echo "not silent"; return 1; }
}

# audio shorter than the picture: silence after it; longer: cut with the picture
t_movie_audio_shorter_and_longer() {
    need_tools || return 1
    mkmovie short.mkv 1 "anoisesrc=d=0.5:c=pink:r=44100:a=0.3" -c:a pcm_s16le -ac 2 || return 1
    "$RS_BIN" movie short.mkv --headless --audio-out short.wav 2>e.txt || { cat e.txt; return 1; }
    [ "$(soxi -s short.wav)" = 48000 ] || return 1
    f32 short.wav got.f32 && ref short.mkv ref.f32 || return 1
    xc got.f32 ref.f32 0 23000 0 && ge "$corr" 0.99 || return 1
    xc got.f32 got.f32 24100 23900 0 && [ "$rms_a" = 0.000000 ] || { echo "sound after the track's end"; return 1; }
    mkmovie long.mkv 1 "anoisesrc=d=3:c=pink:r=44100:a=0.3" -c:a aac -ac 2 || return 1
    "$RS_BIN" movie long.mkv --headless --audio-out long.wav 2>e.txt || { cat e.txt; return 1; }
    grep -q "60 ticks" e.txt && [ "$(soxi -s long.wav)" = 48000 ] || { cat e.txt; soxi long.wav; return 1; }
    f32 long.wav got.f32 && ref long.mkv ref.f32 || return 1
    xc got.f32 ref.f32 0 48000 0 && ge "$corr" 0.99 || return 1
}

# bytes of some AAC packets overwritten: they are skipped, the picture and
# the rest of the sound play on, and the sound after the damage is still in
# its place (compared with the undamaged file's decode).  Tones, not noise:
# AAC codes noise as noise (PNS) from a generator a skipped packet puts out
# of step, so noise would differ after the damage whatever its timing.
t_movie_broken_audio_packets() {
    need_tools || return 1
    command -v python3 >/dev/null || t_skip_install "needs python3"
    mkmovie good.mkv 3 "aevalsrc=0.3*sin(2*PI*440*t)+0.2*sin(2*PI*277*t):s=44100:d=3" -c:a aac -ac 2 || return 1
    ffprobe -v error -select_streams a -show_entries packet=size,pos -of csv=p=0 good.mkv >pk.txt || return 1
    python3 - <<'EOF' || return 1
data = bytearray(open('good.mkv', 'rb').read())
pk = [tuple(map(int, l.split(','))) for l in open('pk.txt')]
for k in range(40, 100, 4):  # packets 40..99 (0.9 s .. 2.3 s), every fourth
    size, pos = pk[k]
    for i in range(size // 4, size // 4 + 24):
        data[pos + i] = (i * 73 + 11) & 255
open('bad.mkv', 'wb').write(data)
EOF
    "$RS_BIN" movie bad.mkv --headless --audio-out bad.wav 2>e.txt || { cat e.txt; return 1; }
    cat e.txt
    grep -q "180 ticks .* 90 frames shown" e.txt || { echo "the picture did not play on"; return 1; }
    grep -Eq "sound: aac .* [1-9][0-9]* damaged packets skipped" e.txt || { echo "no damaged packet counted"; return 1; }
    [ "$(soxi -s bad.wav)" = 144000 ] || return 1
    f32 bad.wav got.f32 && ref good.mkv ref.f32 || return 1
    xc got.f32 ref.f32 120000 24000 48 || return 1 # 2.5 s .. 3 s, after the damage
    ge "$corr" 0.99 && [ "$lag" = 0 ] || { echo "the sound after the damage moved (lag $lag) or differs"; return 1; }
}

t_movie_sound_options() {
    need_tools || return 1
    mkmovie m.mkv 1 "anoisesrc=d=1:c=pink:r=48000:a=0.25" -c:a pcm_s16le -ac 2 || return 1
    "$RS_BIN" movie m.mkv --headless --audio-out full.wav -q || return 1
    "$RS_BIN" movie m.mkv --headless --audio-out half.wav --volume 0.5 -q || return 1
    f32 full.wav full.f32 && f32 half.wav half.f32 || return 1
    xc half.f32 full.f32 0 48000 0 || return 1
    awk -v a="$rms_a" -v b="$rms_b" 'BEGIN { r = a / b; exit !(r > 0.495 && r < 0.505) }' ||
        { echo "--volume 0.5: level ratio $rms_a / $rms_b"; return 1; }
    "$RS_BIN" movie m.mkv --headless --audio-out mute.wav --mute -q || return 1
    [ "$(soxi -s mute.wav)" = 48000 ] || return 1
    sox mute.wav -n stat 2>&1 | grep -q "Maximum amplitude:     0.000000" || { echo "--mute is not silent"; return 1; }
    expect_fail 2 "--volume '1.5': expected a number from 0" "$RS_BIN" movie m.mkv --headless --volume 1.5 || return 1
    expect_fail 1 "--audio-out full.wav: exists" "$RS_BIN" movie m.mkv --headless --audio-out full.wav || return 1
    expect_fail 1 "--audio-out nodir/x.wav" "$RS_BIN" movie m.mkv --headless --audio-out nodir/x.wav || return 1
    # in a window with no such audio device: one warning line, and it plays silent
    command -v Xvfb >/dev/null || t_skip_install "needs Xvfb for the window case"
    disp=:$((190 + $$ % 50))
    Xvfb "$disp" -screen 0 640x480x24 -nolisten tcp >/dev/null 2>&1 &
    xpid=$!
    sleep 1
    DISPLAY=$disp "$RS_BIN" movie m.mkv --audio-device "no such device" 2>w.txt
    rc=$?
    kill $xpid 2>/dev/null
    cat w.txt
    [ $rc = 0 ] || return 1
    [ "$(grep -c "warning" w.txt)" = 1 ] && grep -q "warning: .*no such device.*running silent" w.txt || return 1
    grep -q "60 ticks" w.txt || return 1
}

t_run attract_movie_matches_ffmpeg button_cuts_movie_sound_and_attract_sound_off demo_sounds_like_its_replay \
    movie_layouts_rates_formats movie_without_audio movie_audio_shorter_and_longer movie_broken_audio_packets \
    movie_sound_options
t_done
