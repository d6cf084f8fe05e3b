#!/bin/sh
# End-to-end: render's encoder options through the real binary, checked
# with ffprobe/ffmpeg (docs/capture.md, Encoders): the codec asked for,
# faststart MP4s, metadata from the replay, CRF and bitrate doing what they
# say, 4:4:4 tagged and decodable, bad settings refused by name, --hw on a
# machine without GPU devices, segments with a codec joined, and
# bench encode at a tiny size.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
DOJO="$SRC/demos/dojo.rsr"
TINY="--size 64x36 --render-size 128x72"
SMALL="--size 320x180 --render-size 320x180"

render() { "$RS_BIN" render "$DOJO" "$@"; }
probe() { ffprobe -v error -select_streams v:0 -show_entries "$2" -of default=nw=1:nk=1 "$1"; }
# the top-level MP4 boxes, in file order
boxes() {
    python3 - "$1" <<'EOF'
import struct, sys
d = open(sys.argv[1], 'rb').read()
i = 0
while i + 8 <= len(d):
    n, t = struct.unpack('>I4s', d[i:i + 8])
    if n == 1:
        n = struct.unpack('>Q', d[i + 8:i + 16])[0]
    print(t.decode('latin-1'))
    if n < 8:
        break
    i += n
EOF
}
moov_first() { boxes "$1" | grep -E '^(moov|mdat)$' | tr '\n' ' ' | grep -q '^moov mdat' || { echo "$1: boxes $(boxes "$1" | tr '\n' ' '), want moov before mdat"; return 1; }; }
no_hw_nodes() { ! ls /dev/nvidia0 /dev/dri/renderD* >/dev/null 2>&1; }

t_hevc_stream_tagged_hvc1() {
    render --ticks 0:20 $TINY --codec hevc -o h.mp4 2>err.txt || { cat err.txt; return 1; }
    [ "$(probe h.mp4 stream=codec_name)" = hevc ] || { echo "codec $(probe h.mp4 stream=codec_name), want hevc"; return 1; }
    [ "$(probe h.mp4 stream=codec_tag_string)" = hvc1 ] || { echo "tag $(probe h.mp4 stream=codec_tag_string), want hvc1"; return 1; }
    grep -q "encoder libx265" err.txt || { echo "the wrote line does not name libx265:"; cat err.txt; return 1; }
    render --ticks 0:20 $TINY --codec av1 -q -o a.webm || return 1
    [ "$(probe a.webm stream=codec_name)" = av1 ] || { echo "a.webm: $(probe a.webm stream=codec_name), want av1"; return 1; }
    render --ticks 0:20 $TINY -q -o v.webm || return 1
    [ "$(probe v.webm stream=codec_name)" = vp9 ] || { echo "v.webm: default $(probe v.webm stream=codec_name), want vp9"; return 1; }
}

t_mp4_index_before_media() {
    render --ticks 0:20 $TINY -q -o f.mp4 || return 1
    moov_first f.mp4 || return 1
    render --ticks 0:20 $TINY -q --codec hevc -o g.mp4 || return 1
    moov_first g.mp4
}

t_metadata_from_the_replay() {
    render --ticks 0:10 $TINY -q -o m.mp4 || return 1
    render --ticks 0:10 $TINY -q -o m.mkv || return 1
    info=$("$RS_BIN" replay info "$DOJO")
    stage=$(echo "$info" | sed -n 's/^stage *[0-9]* (\(.*\))$/\1/p')
    winner=$(echo "$info" | sed -n 's/^winner *//p')
    players=$(echo "$info" | sed -n 's/^players *//p')
    version=$("$RS_BIN" version | grep -Eo '[0-9]+\.[0-9]+\.[0-9]+' | head -1)
    for f in m.mp4 m.mkv; do
        ffprobe -v error -show_entries format_tags -of default=nw=1 "$f" | tr 'A-Z' 'a-z' | sed 's/^tag://' >tags.txt
        for want in "stage=$stage" "winner=$winner" "players=$players" "ringside_version=$version" \
            "title=dojo.rsr: P1 (cpu) vs P2 (cpu), $stage"; do
            want=$(echo "$want" | tr 'A-Z' 'a-z')
            grep -qxF "$want" tags.txt || { echo "$f: no tag '$want' in:"; cat tags.txt; return 1; }
        done
    done
}

t_crf_and_bitrate() {
    render --ticks 0:60 $SMALL -q --audio off --crf 18 -o q18.mp4 || return 1
    render --ticks 0:60 $SMALL -q --audio off --crf 40 -o q40.mp4 || return 1
    a=$(stat -c %s q18.mp4) b=$(stat -c %s q40.mp4)
    [ "$b" -lt $((a / 2)) ] || { echo "--crf 40 gives $b bytes, --crf 18 $a: want less than half"; return 1; }
    render --ticks 0:60 $SMALL -q --audio off --bitrate 100k -o b100.mp4 || return 1
    render --ticks 0:60 $SMALL -q --audio off --bitrate 600k -o b600.mp4 || return 1
    # one second of video (no sound: the bytes are the video's): bytes * 8 is the rate; x264's average undershoots on a clip this short, never overshoots much
    for r in 100 600; do
        bits=$(( $(probe b$r.mp4 stream=bit_rate) ))
        [ "$bits" -gt $((r * 1000 / 4)) ] && [ "$bits" -lt $((r * 1000 * 3 / 2)) ] ||
            { echo "--bitrate ${r}k gave $bits bit/s"; return 1; }
    done
    [ "$(stat -c %s b600.mp4)" -gt $(( $(stat -c %s b100.mp4) * 3 )) ] || { echo "600k is not 3x the size of 100k"; return 1; }
}

t_yuv444_tagged_and_decodes() {
    render --ticks 0:20 $TINY -q --pix-fmt yuv444p -o c.mp4 || return 1
    [ "$(probe c.mp4 stream=pix_fmt)" = yuv444p ] || { echo "pix_fmt $(probe c.mp4 stream=pix_fmt)"; return 1; }
    [ "$(probe c.mp4 stream=color_space)" = bt709 ] && [ "$(probe c.mp4 stream=color_range)" = tv ] ||
        { echo "colour tags: $(probe c.mp4 stream=color_space) $(probe c.mp4 stream=color_range)"; return 1; }
    [ "$(ffmpeg -v error -i c.mp4 -map 0:v -f framemd5 - | grep -vc '^#')" = 20 ] || { echo "c.mp4 does not decode to 20 frames"; return 1; }
    # the same frames as 4:2:0: luma agrees closely (same coefficients; only chroma resolution differs)
    render --ticks 0:20 $TINY -q --crf 10 -o l420.mkv || return 1
    render --ticks 0:20 $TINY -q --crf 10 --pix-fmt yuv444p -o l444.mkv || return 1
    psnr=$(ffmpeg -v info -i l420.mkv -i l444.mkv -lavfi "[0]extractplanes=y[a];[1]extractplanes=y[b];[a][b]psnr" -f null - 2>&1 |
        sed -n 's/.*average:\([0-9.inf]*\).*/\1/p')
    awk -v p="$psnr" 'BEGIN { exit !(p == "inf" || p + 0 > 38) }' || { echo "luma of 4:2:0 and 4:4:4 differ: PSNR $psnr"; return 1; }
}

t_bad_settings_refused() {
    expect_fail 2 "x.webm: WebM does not hold h264" render --ticks 0:2 $TINY --codec h264 -o x.webm || return 1
    expect_fail 2 "x.mp4: MP4 does not hold vp9" render --ticks 0:2 $TINY --codec vp9 -o x.mp4 || return 1
    expect_fail 2 "--preset 'quick' is not one of libx264's presets \(ultrafast, .*placebo\)" render --ticks 0:2 $TINY --preset quick -o x.mp4 || return 1
    expect_fail 2 "--preset '20' is not one of libvpx-vp9's presets \(-8\.\.8\)" render --ticks 0:2 $TINY --preset 20 -o x.webm || return 1
    expect_fail 2 "--crf and --bitrate exclude each other" render --ticks 0:2 $TINY --crf 20 --bitrate 1M -o x.mp4 || return 1
    expect_fail 2 "--crf 60: libx264 takes 1\.\.51" render --ticks 0:2 $TINY --crf 60 -o x.mp4 || return 1
    expect_fail 2 "--codec 'h265': expected h264, hevc, vp9 or av1" render --ticks 0:2 $TINY --codec h265 -o x.mp4 || return 1
    expect_fail 2 "--bitrate '4X'" render --ticks 0:2 $TINY --bitrate 4X -o x.mp4 || return 1
    expect_fail 2 "--pix-fmt 'rgb24'" render --ticks 0:2 $TINY --pix-fmt rgb24 -o x.mp4 || return 1
    expect_fail 2 "x.y4m: --codec, --crf.* apply to .mp4, .mkv and .webm" render --ticks 0:2 $TINY --crf 20 -o x.y4m || return 1
    [ ! -e x.mp4 ] && [ ! -e x.webm ] && [ ! -e x.mp4.part ] || { echo "a refused render left a file"; ls; return 1; }
}

t_hw_without_devices() {
    no_hw_nodes || t_skip_env "this machine has a GPU device node: the fallback is not what runs"
    expect_fail 1 "x.mp4: --hw nvenc: no device /dev/nvidia0" render --ticks 0:2 $TINY --hw nvenc -o x.mp4 || return 1
    expect_fail 1 "x.mp4: --hw vaapi: no device /dev/dri/renderD" render --ticks 0:2 $TINY --hw vaapi --codec hevc -o x.mp4 || return 1
    expect_fail 1 "--hw nvenc: NVENC has no vp9 encoder" render --ticks 0:2 $TINY --hw nvenc -o x.webm || return 1
    # auto: nothing to try, nothing to say; the software encoder is named in the wrote line
    render --ticks 0:10 $TINY -o a.mp4 2>err.txt || { cat err.txt; return 1; }
    ! grep -qi "hardware\|nvenc\|vaapi" err.txt || { echo "--hw auto spoke without a device:"; cat err.txt; return 1; }
    grep -q "encoder libx264$" err.txt || { echo "the wrote line does not end with the encoder:"; cat err.txt; return 1; }
    render --ticks 0:10 $TINY --hw off -q -o o.mp4 || return 1
}

t_segments_with_a_codec_join() {
    for r in 0:40 40:90 90:120; do
        render --ticks $r $TINY -q --codec hevc --crf 30 --segment jh -o s${r%:*}.mp4 || { echo "segment $r"; return 1; }
    done
    "$RS_BIN" join -q --segment jh -o j.mp4 s0.mp4 s40.mp4 s90.mp4 || return 1
    [ "$(probe j.mp4 stream=codec_name)/$(probe j.mp4 stream=codec_tag_string)" = hevc/hvc1 ] ||
        { echo "joined: $(probe j.mp4 stream=codec_name)/$(probe j.mp4 stream=codec_tag_string)"; return 1; }
    moov_first j.mp4 || return 1
    ffprobe -v error -show_entries format_tags=stage -of default=nw=1:nk=1 j.mp4 | grep -qx dojo || { echo "join lost the metadata"; return 1; }
    for s in s0 s40 s90; do ffmpeg -v error -i $s.mp4 -f framemd5 - | grep -v '^#' | cut -d, -f6; done >segs.md5
    ffmpeg -v error -i j.mp4 -f framemd5 - | grep -v '^#' | cut -d, -f6 >joined.md5
    [ "$(wc -l <joined.md5)" = 120 ] && cmp -s segs.md5 joined.md5 || { echo "joined frames differ from the segments'"; return 1; }
    # a segment with other codec parameters cannot be stream-copied with the rest
    render --ticks 40:90 $TINY -q -y --segment jh -o s40.mp4 || return 1
    "$RS_BIN" join --segment jh -o k.mp4 --progress-fd 3 s0.mp4 s40.mp4 s90.mp4 3>bad.txt 2>err.txt
    [ $? = 3 ] && grep -q "^bad 1 codec " bad.txt || { echo "mixed h264/hevc segments not refused:"; cat bad.txt err.txt; return 1; }
}

t_bench_encode_tiny() {
    "$RS_BIN" bench encode --frames 3 $TINY --quick -q --csv b.csv >out.txt 2>err.txt || { cat out.txt err.txt; return 1; }
    for c in h264 hevc vp9 av1; do
        grep -Eq "^$c +lib[a-z0-9-]+ +[a-z0-9-]+ +[0-9]+ +[0-9.]+ +[0-9.]+ +[0-9.]+ +[0-9.]+ +0\.[0-9]+$" out.txt ||
            { echo "no row for $c:"; cat out.txt; return 1; }
    done
    [ "$(wc -l <b.csv)" = 5 ] || { echo "b.csv: $(wc -l <b.csv) lines, want a header and 4 rows"; cat b.csv; return 1; }
    # quality is measured: every PSNR is a finite number in a sane range
    awk -F, 'NR > 1 && !($11 > 25 && $11 < 80 && $13 > 0.5 && $13 <= 1) { bad = 1; print } END { exit bad }' b.csv
}

t_run hevc_stream_tagged_hvc1 mp4_index_before_media metadata_from_the_replay crf_and_bitrate yuv444_tagged_and_decodes \
    bad_settings_refused hw_without_devices segments_with_a_codec_join bench_encode_tiny
t_done
