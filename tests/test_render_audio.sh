#!/bin/sh
# End-to-end: a rendered video's soundtrack (render --audio, --wav, join
# --replay), checked by an independent decoder (ffprobe, ffmpeg).  Small
# sizes and a short AI replay keep it quick on llvmpipe.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SIZES="--render-size 128x72 --size 64x36"

need_ffmpeg() {
    command -v ffprobe >/dev/null && command -v ffmpeg >/dev/null || t_skip_install "ffmpeg/ffprobe not installed"
    command -v python3 >/dev/null || t_skip_install "python3 not installed"
}

replay6() { # 360 ticks: the intro and the start of round 1, with hits
    "$RS_BIN" record --ai --quiet --seconds 6 --seed 21 -o r.rsr 2>/dev/null
}

# stream durations of FILE's video and audio: "V A" in seconds ("N/A" when missing)
durations() {
    v=$(ffprobe -v error -select_streams v:0 -show_entries stream=duration -of csv=p=0 "$1")
    a=$(ffprobe -v error -select_streams a:0 -show_entries stream=duration -of csv=p=0 "$1")
    # Matroska keeps no stream durations: the packets' end then
    [ "$v" = N/A ] && v=$(ffprobe -v error -select_streams v:0 -show_entries packet=pts_time,duration_time -of csv=p=0 "$1" |
        awk -F, '{e = $1 + $2; if (e > m) m = e} END {print m}')
    [ "$a" = N/A ] && a=$(ffprobe -v error -select_streams a:0 -show_entries packet=pts_time,duration_time -of csv=p=0 "$1" |
        awk -F, '{e = $1 + $2; if (e > m) m = e} END {print m}')
    echo "${v:-none} ${a:-none}"
}

codec_of() { # FILE STREAM -> codec name, or nothing
    ffprobe -v error -select_streams "$2" -show_entries stream=codec_name -of csv=p=0 "$1"
}

pcm() { # FILE OUT: the decoded audio as mono float32 (the mean of the channels)
    ffmpeg -v error -y -i "$1" -map 0:a:0 -ac 1 -f f32le "$2"
}

# python: LAG a.f32 b.f32 -> the lag of b against a (samples) with the highest correlation, and that correlation
lag_corr() {
    python3 - "$1" "$2" <<'EOF'
import sys, array
a = array.array('f'); a.frombytes(open(sys.argv[1], 'rb').read())
b = array.array('f'); b.frombytes(open(sys.argv[2], 'rb').read())
n = min(len(a), len(b)) - 2000
def corr(lag):
    sab = saa = sbb = 0.0
    for i in range(1000, n, 3):
        x, y = a[i], b[i + lag]
        sab += x * y; saa += x * x; sbb += y * y
    return sab / ((saa * sbb) ** 0.5 or 1)
best = max(range(-96, 97, 8), key=corr)
best = max(range(best - 8, best + 9), key=corr)
print(best, "%.4f" % corr(best))
EOF
}

# a 4-second range to MP4: AAC, as long as the video within one frame (1/60 s)
t_mp4_aac_duration() {
    need_ffmpeg
    replay6 || return 1
    "$RS_BIN" render r.rsr -o v.mp4 $SIZES --ticks 60:300 --quiet || return 1
    [ "$(codec_of v.mp4 a:0)" = aac ] || { echo "no AAC stream: $(codec_of v.mp4 a:0)"; return 1; }
    set -- $(durations v.mp4)
    echo "video $1 s, audio $2 s"
    awk -v v="$1" -v a="$2" 'BEGIN { d = v - a; if (d < 0) d = -d; exit !(v == 4 && d <= 1 / 60) }' ||
        { echo "durations differ by more than 1/60 s (or the video is not 4 s)"; return 1; }
}

# the same replay twice: the same decoded samples, and not silence
t_deterministic_pcm() {
    need_ffmpeg
    replay6 || return 1
    "$RS_BIN" render r.rsr -o a.mp4 $SIZES --ticks 0:240 --quiet || return 1
    "$RS_BIN" render r.rsr -o b.mp4 $SIZES --ticks 0:240 --quiet --capture sequential --queue 0 || return 1
    pcm a.mp4 a.f32 && pcm b.mp4 b.f32 || return 1
    [ "$(md5sum <a.f32)" = "$(md5sum <b.f32)" ] || { echo "decoded audio differs between two renders"; return 1; }
    ffmpeg -v error -f f32le -ar 48000 -ac 1 -i a.f32 -af astats=metadata=0 -f null - 2>&1 | grep -m1 "RMS level dB" |
        awk '{ if ($NF == "-inf" || $NF < -60) { print "silent: " $0; exit 1 } }' || return 1
}

# EBU R128 integrated loudness of the whole match, within 1 LU of the target: -16 by default, --loudness -23
t_loudness_target() {
    need_ffmpeg
    replay6 || return 1
    "$RS_BIN" render r.rsr -o v.mp4 $SIZES --quiet --wav d.wav || return 1
    "$RS_BIN" render r.rsr -o /dev/null --format y4m $SIZES --quiet --wav q.wav --loudness -23 || return 1
    for f in d.wav:-16 v.mp4:-16 q.wav:-23; do
        i=$(ffmpeg -nostats -i "${f%%:*}" -map 0:a:0 -af ebur128=peak=true -f null - 2>&1 | awk '/Integrated loudness:/ { g = 1 } g && /I:/ { print $2; exit }')
        echo "${f%%:*}: $i LUFS (target ${f#*:})"
        awk -v i="$i" -v t="${f#*:}" 'BEGIN { d = i - t; if (d < 0) d = -d; exit !(i != "" && d <= 1) }' || return 1
    done
}

t_webm_opus() {
    need_ffmpeg
    replay6 || return 1
    "$RS_BIN" render r.rsr -o v.webm $SIZES --ticks 60:300 --quiet --audio-bitrate 96k || return 1
    [ "$(codec_of v.webm a:0)" = opus ] || { echo "no Opus stream: $(codec_of v.webm a:0)"; return 1; }
    set -- $(durations v.webm)
    echo "video $1 s, audio $2 s"
    awk -v v="$1" -v a="$2" 'BEGIN { d = v - a; if (d < 0) d = -d; exit !(d <= 1 / 60) }' || return 1
}

# --audio off: no audio stream; Y4M: none either, --wav writes the track of exactly the rendered ticks
t_off_and_wav() {
    need_ffmpeg
    replay6 || return 1
    "$RS_BIN" render r.rsr -o v.mkv $SIZES --ticks 0:60 --quiet --audio off || return 1
    [ -z "$(codec_of v.mkv a)" ] || { echo "--audio off wrote an audio stream"; return 1; }
    "$RS_BIN" render r.rsr -o v.y4m $SIZES --ticks 30:90 --quiet --wav t.wav || return 1
    [ "$(ffprobe -v error -show_entries stream=sample_rate,channels,duration_ts -of csv=p=0 t.wav)" = "48000,2,48000" ] ||
        { echo "t.wav: $(ffprobe -v error -show_entries stream=sample_rate,channels,duration_ts -of csv=p=0 t.wav)"; return 1; }
    # the WAV obeys -n like every output
    expect_fail 1 "t.wav: exists \(use -y to overwrite\)" "$RS_BIN" render r.rsr -o w.y4m $SIZES --ticks 30:90 --wav t.wav || return 1
    [ ! -e w.y4m ] || { echo "w.y4m written though the WAV was refused"; return 1; }
}

# --ticks A:B has exactly those samples of the whole render's track
t_ticks_cut() {
    need_ffmpeg
    replay6 || return 1
    "$RS_BIN" render r.rsr -o /dev/null --format y4m $SIZES --quiet --wav all.wav || return 1
    "$RS_BIN" render r.rsr -o /dev/null --format y4m $SIZES --ticks 100:160 --quiet --wav cut.wav || return 1
    ffmpeg -v error -i all.wav -f s16le all.raw && ffmpeg -v error -i cut.wav -f s16le cut.raw || return 1
    # tick 100 starts at sample frame 80000: 4 bytes a frame
    tail -c +$((100 * 800 * 4 + 1)) all.raw | head -c $((60 * 800 * 4)) >want.raw
    [ "$(wc -c <cut.raw)" = $((60 * 800 * 4)) ] || { echo "cut.wav: $(wc -c <cut.raw) bytes of samples"; return 1; }
    cmp want.raw cut.raw || { echo "--ticks 100:160 is not that range of the whole track"; return 1; }
}

# sound lines up with the picture: the decoded MP4/MKV/WebM audio is the track (--wav) at lag 0, within 1 ms
t_sync_containers() {
    need_ffmpeg
    replay6 || return 1
    "$RS_BIN" render r.rsr -o /dev/null --format y4m $SIZES --ticks 0:240 --quiet --wav t.wav || return 1
    ffmpeg -v error -i t.wav -ac 1 -f f32le t.f32 || return 1
    for c in mp4 mkv webm; do
        "$RS_BIN" render r.rsr -o "v.$c" $SIZES --ticks 0:240 --quiet || return 1
        pcm "v.$c" "v.$c.f32" || return 1
        set -- $(lag_corr t.f32 "v.$c.f32")
        echo "$c: lag $1 samples, correlation $2"
        [ "${1#-}" -le 48 ] || { echo "$c: the sound is $1 samples off its frames"; return 1; }
        awk -v c="$2" 'BEGIN { exit !(c >= 0.99) }' || return 1
    done
}

# a hit's sound starts at its frame: the hits of `replay events`, each onset in the decoded MP4 within 1 ms of
# tick * 800 samples.  The music and the crowd play under the hits, so the onset is looked for above 3 kHz, where
# a hit is a sharp step: the first 0.5 ms window with 5% of the peak energy of the 20 ms around the tick.
t_hit_onset() {
    need_ffmpeg
    replay6 || return 1
    "$RS_BIN" replay events r.rsr >ev.txt || return 1
    ticks=$(awk '$2 ~ /^hit_/ && $1 < 240 { print $1 }' ev.txt | head -3 | tr '\n' ' ')
    [ -n "$ticks" ] || { echo "no hit in the replay's events:"; head ev.txt; return 1; }
    "$RS_BIN" render r.rsr -o v.mp4 $SIZES --ticks 0:240 --quiet || return 1
    ffmpeg -v error -i v.mp4 -map 0:a:0 -ac 1 -af highpass=f=3000,highpass=f=3000 -f f32le v.f32 || return 1
    python3 - v.f32 $ticks <<'EOF' || return 1
import sys, array
x = array.array('f'); x.frombytes(open(sys.argv[1], 'rb').read())
bad = 0
for tick in map(int, sys.argv[2:]):
    at, w = tick * 800, 24
    e = {i: sum(v * v for v in x[i:i + w]) / w for i in range(at - 480, at + 480, w)}
    peak = max(e.values())
    onset = min(i for i in e if e[i] >= 0.05 * peak) - at
    print("hit at tick %d: onset %+d samples (%+.2f ms) from its frame's time" % (tick, onset, onset / 48.0))
    bad += abs(onset) > 48
sys.exit(bad)
EOF
}

# segments + join --replay: the sound of a whole render, one piece, the right length
t_join_audio() {
    need_ffmpeg
    replay6 || return 1
    "$RS_BIN" render r.rsr -o s1.mp4 $SIZES --ticks 0:100 --segment k1 --quiet || return 1
    "$RS_BIN" render r.rsr -o s2.mp4 $SIZES --ticks 100:240 --segment k1 --quiet || return 1
    [ -z "$(codec_of s1.mp4 a)" ] || { echo "a segment carries audio"; return 1; }
    "$RS_BIN" join --segment k1 --replay r.rsr -o j.mp4 --quiet s1.mp4 s2.mp4 || return 1
    "$RS_BIN" join --segment k1 -o silent.mp4 --quiet s1.mp4 s2.mp4 || return 1
    [ -z "$(codec_of silent.mp4 a)" ] || { echo "join without --replay wrote audio"; return 1; }
    "$RS_BIN" render r.rsr -o w.mp4 $SIZES --ticks 0:240 --quiet || return 1
    set -- $(durations j.mp4)
    echo "joined: video $1 s, audio $2 s"
    awk -v v="$1" -v a="$2" 'BEGIN { d = v - a; if (d < 0) d = -d; exit !(v == 4 && d <= 1 / 60) }' || return 1
    pcm j.mp4 j.f32 && pcm w.mp4 w.f32 || return 1
    set -- $(lag_corr w.f32 j.f32)
    echo "join vs whole render: lag $1, correlation $2"
    [ "$1" = 0 ] && awk -v c="$2" 'BEGIN { exit !(c >= 0.99) }' || return 1
    # the manifests name their replay: another one is refused, naming the segment, and nothing is written
    grep -q "^replay $(python3 -c 'import sys
h = 0xcbf29ce484222325
for b in open("r.rsr", "rb").read(): h = ((h ^ b) * 0x100000001b3) & (2**64 - 1)
print("%016x" % h)')\$" s1.mp4.seg || { echo "s1.mp4.seg does not name r.rsr's FNV-1a:"; cat s1.mp4.seg; return 1; }
    "$RS_BIN" record --ai --quiet --seconds 6 --seed 22 -o other.rsr 2>/dev/null || return 1
    expect_fail 2 "--replay other.rsr: not the replay segment 0 \(s1.mp4\) was rendered from" \
        "$RS_BIN" join --segment k1 --replay other.rsr -o x.mp4 s1.mp4 s2.mp4 || return 1
    [ ! -e x.mp4 ] || { echo "x.mp4 written with another replay's sound"; return 1; }
}

t_bad_options() {
    replay6 || return 1
    expect_fail 2 "--audio-bitrate 'x': expected bits a second" "$RS_BIN" render r.rsr -o v.mp4 --audio-bitrate x || return 1
    expect_fail 2 "v.mp4: --audio-bitrate 5000k: AAC takes 32k..512k" "$RS_BIN" render r.rsr -o v.mp4 --audio-bitrate 5M || return 1
    expect_fail 2 "v.webm: --audio-bitrate 600k: Opus takes 16k..510k" "$RS_BIN" render r.rsr -o v.webm --audio-bitrate 600k || return 1
    expect_fail 2 "--audio 'yes': expected on or off" "$RS_BIN" render r.rsr -o v.mp4 --audio yes || return 1
    expect_fail 2 "--audio on: v.y4m carries no audio" "$RS_BIN" render r.rsr -o v.y4m --audio on || return 1
    expect_fail 2 "--loudness '-3': expected an integrated loudness in LUFS from -40 to -5" \
        "$RS_BIN" render r.rsr -o v.mp4 --loudness -3 || return 1
    expect_fail 2 "--audio on: s.mp4 carries no audio \(segments are silent" \
        "$RS_BIN" render r.rsr -o s.mp4 --segment k --ticks 0:10 --audio on || return 1
    expect_fail 2 "--audio-bitrate and --loudness need --replay" "$RS_BIN" join --segment k -o j.mp4 --audio-bitrate 128k s.mp4 || return 1
    [ -z "$(ls v.* s.* j.* 2>/dev/null)" ] || { echo "a refused run left files: $(ls)"; return 1; }
}

t_run mp4_aac_duration deterministic_pcm loudness_target webm_opus off_and_wav ticks_cut sync_containers hit_onset \
    join_audio bad_options
t_done
