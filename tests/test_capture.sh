#!/bin/sh
# End-to-end: ringside render, checked by an independent player (ffprobe).
# Small sizes and a short replay keep it quick on llvmpipe.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
SIZES="--render-size 320x180 --size 160x90"

# short_replay [SECONDS]: 2 s, 120 ticks: the intro (more frames than any
# ring or queue below); 1 s where a case needs only some frames of each kind
short_replay() {
    "$RS_BIN" record --ai --quiet --seconds "${1:-2}" --seed 21 -o short.rsr 2>/dev/null
}

probe() { # file -> "frames rate duration"
    ffprobe -v error -count_frames -select_streams v:0 \
        -show_entries stream=nb_read_frames,r_frame_rate:format=duration -of default=nw=1:nk=1 "$1" | tr '\n' ' '
}

t_async_equals_sequential() {
    short_replay || return 1
    "$RS_BIN" render short.rsr -o a.y4m $SIZES --quiet --hashes a.txt || return 1
    "$RS_BIN" render short.rsr -o s.y4m $SIZES --quiet --capture sequential --downscale gpu --hashes s.txt || return 1
    "$RS_BIN" render short.rsr -o p.y4m $SIZES --quiet --pbo 3 --queue 8 --hashes p.txt || return 1
    [ "$(wc -l <a.txt)" = 120 ] || { echo "want 120 hashes"; return 1; }
    cmp a.txt s.txt || { echo "async and sequential frames differ"; return 1; }
    cmp a.txt p.txt || { echo "pbo 3 / queue 8 frames differ"; return 1; }
    # frame numbers 0..119 in order
    [ "$(cut -d' ' -f1 a.txt | tr '\n' ' ')" = "$(seq -s' ' 0 119) " ] || { echo "frame order"; return 1; }
}

t_y4m_plays() {
    command -v ffprobe >/dev/null || t_skip_install "ffprobe not installed"
    short_replay || return 1
    "$RS_BIN" render short.rsr -o v.y4m $SIZES --quiet || return 1
    set -- $(probe v.y4m)
    [ "$1 $2" = "60/1 120" ] || { echo "y4m: rate/frames $1 $2"; return 1; }
    head -c 80 v.y4m | grep -q "^YUV4MPEG2 W160 H90 F60:1 Ip A1:1 C420jpeg XCOLORRANGE=LIMITED" || return 1
}

# the MP4 says 60/1, has a frame a tick and lasts the replay's time to the
# microsecond; the MKV has every frame too.  1 s, 60 frames, is well past
# x264's delay (veryfast: 10 frames of lookahead, 3 B-frames)
t_mp4_exact_timing() {
    command -v ffprobe >/dev/null || t_skip_install "ffprobe not installed"
    "$RS_BIN" render --help | grep -q "\.mp4" || t_skip_install "this build has no FFmpeg"
    short_replay 1 || return 1
    "$RS_BIN" render short.rsr -o v.mp4 $SIZES --quiet 2>e.txt || { cat e.txt; return 1; }
    [ ! -s e.txt ] || { echo "noise on stderr with --quiet:"; cat e.txt; return 1; }
    set -- $(probe v.mp4)
    [ "$1" = "60/1" ] && [ "$2" = 60 ] || { echo "mp4: rate $1 frames $2"; return 1; }
    [ "$3" = "1.000000" ] || { echo "mp4: duration $3, want 1.000000"; return 1; }
    ffprobe -v error -show_entries stream=codec_name,color_range,color_space -of csv=p=0 v.mp4 | grep -q "h264,tv,bt709" ||
        { ffprobe -v error -show_entries stream=codec_name,color_range,color_space -of csv=p=0 v.mp4; return 1; }
    "$RS_BIN" render short.rsr -o v.mkv $SIZES --quiet || return 1
    set -- $(probe v.mkv)
    [ "$2" = 60 ] || { echo "mkv frames $2"; return 1; }
}

t_disk_full() {
    short_replay || return 1
    expect_fail 1 "/dev/full: write failed: No space left on device" "$RS_BIN" render short.rsr -o /dev/full $SIZES --quiet ||
        return 1
    [ "$(wc -l <err.txt)" = 1 ] || { cat err.txt; return 1; }
    # an ordinary file that cannot grow: nothing left behind
    ( trap '' XFSZ; export ASAN_OPTIONS=detect_leaks=0; ulimit -f 200; exec "$RS_BIN" render short.rsr -o big.y4m $SIZES --quiet --hashes big.txt ) 2>err.txt
    [ $? = 1 ] || { echo "want exit 1"; cat err.txt; return 1; }
    grep -q "big.y4m: write failed: File too large" err.txt || { cat err.txt; return 1; }
    [ ! -e big.y4m ] && [ ! -e big.y4m.part ] && [ ! -e big.txt ] && [ ! -e big.txt.part ] ||
        { echo "left behind:"; ls; return 1; }
}

t_bad_input() {
    short_replay || return 1
    expect_fail 2 "must be even for 4:2:0" "$RS_BIN" render short.rsr -o x.y4m --size 161x90 || return 1
    expect_fail 2 "larger than the render size" "$RS_BIN" render short.rsr -o x.y4m --size 1920x1080 \
        --render-size 1280x720 || return 1
    expect_fail 2 "x.avi: unknown output type '.avi'" "$RS_BIN" render short.rsr -o x.avi || return 1
    expect_fail 1 "nope.rsr: cannot open" "$RS_BIN" render nope.rsr -o x.y4m || return 1
    expect_fail 2 "--capture 'fast'" "$RS_BIN" render short.rsr -o x.y4m --capture fast || return 1
    expect_fail 2 "--pbo '9'" "$RS_BIN" render short.rsr -o x.y4m --pbo 9 || return 1
    expect_fail 2 "-o OUT is required" "$RS_BIN" render short.rsr || return 1
    head -c 50 short.rsr >cut.rsr
    expect_fail 1 "cut.rsr: truncated: 50 bytes" "$RS_BIN" render cut.rsr -o x.y4m || return 1
    [ ! -e x.y4m ] && [ ! -e x.y4m.part ] && [ ! -e x.avi ] || { echo "output left behind"; return 1; }
}

t_streams_and_signals() {
    short_replay || return 1
    # a pipe through /dev/stdout is streamed, never renamed
    "$RS_BIN" render short.rsr -o /dev/stdout $SIZES --quiet | head -c 9 >hdr.txt
    [ "$(cat hdr.txt)" = "YUV4MPEG2" ] || { echo "no Y4M on the pipe"; return 1; }
    [ -L /dev/stdout ] || { echo "/dev/stdout is no longer a link!"; return 1; }
    "$RS_BIN" record --ai --quiet --seconds 60 --seed 22 -o long.rsr 2>/dev/null || return 1
    # one process (--jobs 1): its own .part appears at the start (test_render_jobs
    # interrupts a render in segments)
    "$RS_BIN" render long.rsr -o int.mp4 --quiet --jobs 1 2>err.txt &
    pid=$!
    # interrupt once the output exists (slow start-ups under ASan included)
    n=0
    while [ ! -e int.mp4.part ] && [ $n -lt 600 ]; do sleep 0.1; n=$((n + 1)); done
    sleep 0.5
    kill -INT $pid
    wait $pid
    rc=$?
    [ $rc = 1 ] || { echo "exit $rc after SIGINT"; cat err.txt; return 1; }
    grep -q "int.mp4: interrupted at frame" err.txt || { cat err.txt; return 1; }
    [ ! -e int.mp4 ] && [ ! -e int.mp4.part ] || { echo "partial output left"; return 1; }
    mkdir hd
    expect_fail 1 "hd: exists and is not a regular file" "$RS_BIN" render short.rsr -o v.y4m --hashes hd || return 1
    [ ! -e v.y4m ] || return 1
    expect_fail 2 "in the file name" "$RS_BIN" render short.rsr -o "d%02d/f.png" || return 1
}

t_queue_cap_in_report() {
    short_replay || return 1
    "$RS_BIN" render short.rsr -o /dev/null $SIZES --queue 4 2>r.txt || { cat r.txt; return 1; }
    hw=$(sed -n 's/.*high-water \([0-9]*\).*/\1/p' r.txt)
    [ -n "$hw" ] && [ "$hw" -le 4 ] || { cat r.txt; return 1; }
    grep -q "120 frames 160x90" r.txt || { cat r.txt; return 1; }
    # the default cap is 120 frames (about 2 s of video; capture/cap.h): behind
    # a reader that waits until the render stands still (the writer blocked on
    # the full pipe, the game thread on a full queue), the queue fills to it;
    # the writer holds one frame, so the high-water is 119 or 120
    # (3 s, 180 frames: more than the 120 queued and the about 21 past the
    # queue, in the pipe's 64 KiB, the writer and the PBOs; 2 s stops short)
    "$RS_BIN" record --ai --quiet --seconds 3 --seed 21 -o long.rsr 2>/dev/null || return 1
    sh -c 'echo $$ >render.pid; exec "$0" render long.rsr -o - --size 64x36 --render-size 64x36 --quality draft \
        --progress off 2>d.txt' "$RS_BIN" | { wait_still render.pid; cat >/dev/null; }
    hw=$(sed -n 's/.*high-water \([0-9]*\).*/\1/p' d.txt)
    grep -q ", queue 120, " d.txt && [ -n "$hw" ] && [ "$hw" -ge 119 ] && [ "$hw" -le 120 ] ||
        { echo "the default queue: high-water '$hw', want 119 or 120 of 120"; cat d.txt; return 1; }
}

# wait_still PIDFILE: until the process it names uses no CPU for half a
# second (at most 30 s)
wait_still() {
    i=0 last=-1
    while [ $i -lt 60 ]; do
        cpu=$(awk '{ print $14 + $15 }' "/proc/$(cat "$1" 2>/dev/null)/stat" 2>/dev/null)
        [ -n "$cpu" ] && [ "$cpu" = "$last" ] && return 0
        last=${cpu:--1}
        i=$((i + 1))
        sleep 0.5
    done
}

# the bench's rows, ratios, CSV and chart: small sizes (with a downscale),
# as no rate is checked, only the table's shape
t_bench_capture_small() {
    "$RS_BIN" bench capture --frames 10 --runs 1 --render-size 128x72 --size 64x36 --sink y4m --csv b.csv --chart b.png \
        >b.txt 2>&1 || { cat b.txt; return 1; }
    for row in render-only writer-only sequential "async pbo1 q0" "async pbo2 q120" "async pbo3 q8"; do
        grep -q "^$row " b.txt || { echo "no row $row"; cat b.txt; return 1; }
    done
    grep -q "^async (pbo 2, queue 120) / sequential: *[0-9.]*x" b.txt || { cat b.txt; return 1; }
    grep -q "^async / min(render-only" b.txt || { cat b.txt; return 1; }
    [ "$(wc -l <b.csv)" = 13 ] || { echo "csv rows"; cat b.csv; return 1; }
    [ "$(head -c 8 b.png | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || { echo "chart is not a PNG"; return 1; }
    [ ! -e out/bench-capture-scratch.y4m ] || { echo "scratch output left"; return 1; }
    # the null sink has no writer stage: its writer-only row has no rate
    # (it printed frames / 0 s: 571432139.7 fps)
    "$RS_BIN" bench capture --frames 10 --runs 1 --render-size 64x36 --size 64x36 --sink null --csv n.csv --chart '' \
        >n.txt 2>&1 || { cat n.txt; return 1; }
    grep -q '^writer-only *- ' n.txt || { echo "writer-only with the null sink:"; cat n.txt; return 1; }
    grep -q '^writer-only,,' n.csv || { cat n.csv; return 1; }
    grep -q '^render-only *[0-9]' n.txt || { cat n.txt; return 1; }
}

t_filters() {
    short_replay || return 1
    for f in box bilinear nearest lanczos3; do
        "$RS_BIN" render short.rsr -o "$f.y4m" $SIZES --quiet --filter $f --hashes "$f.txt" || { echo "filter $f"; return 1; }
        [ "$(wc -l <"$f.txt")" = 120 ] || return 1
    done
    ! cmp -s box.txt lanczos3.txt || { echo "lanczos3 gave the same frames as box"; return 1; }
    ! cmp -s box.txt nearest.txt || { echo "nearest gave the same frames as box"; return 1; }
    expect_fail 2 "--filter 'cubic'" "$RS_BIN" render short.rsr -o x.y4m --filter cubic || return 1
}

# bench quality at a tiny size: every configuration measured on each stage, the
# error falls as the render scale grows, the presets chosen, the CSV complete
t_bench_quality_small() {
    "$RS_BIN" bench quality --size 64x36 --frames 1 --stages dojo,temple --csv q.csv --chart q.png -q >q.txt 2>&1 ||
        { cat q.txt; return 1; }
    for row in "reference 4x" "1x" "1.5x" "2x (the old default)" "3x" "1x fxaa" "1x shadow 512" "1x mask half" \
        "1x bloom 1 level" "1x cheap"; do
        grep -q "^$row  *[0-9.]* *[0-9.]* *[0-9.]* *[0-9.]*  *[0-9.]* *[0-9.]*\$" q.txt || { echo "no row '$row'"; cat q.txt; return 1; }
    done
    # the reference against itself; more pixels drawn per output pixel, closer to it
    db() { awk -v r="$1" 'index($0, r) == 1 { print $(NF - 3) }' q.txt; }
    awk -v a="$(db '1x  ')" -v b="$(db '2x (the')" -v c="$(db '3x  ')" 'BEGIN { exit !(a < b && b < c) }' ||
        { echo "the error does not fall with the render scale"; cat q.txt; return 1; }
    grep -q "^reference 4x .* 99.00  *1.0000  *99.00  *99.00$" q.txt || { cat q.txt; return 1; }
    for p in draft standard high reference; do
        grep -q "^$p  " q.txt || { echo "no preset line $p"; cat q.txt; return 1; }
    done
    grep -q "^fps per stage and preset" q.txt && grep -q "^temple " q.txt || { cat q.txt; return 1; }
    rows=$(grep -c '^[a-z]' q.csv)
    cfgs=$(awk '/^configuration /{on=1; next} on && NF == 0 {exit} on {n++} END {print n}' q.txt)
    [ "$rows" = $((2 * cfgs + 1)) ] || { echo "q.csv: $rows lines for $cfgs configurations x 2 stages"; cat q.csv; return 1; }
    [ -s q.png ] && [ -s q.svg ] || { echo "no chart"; return 1; }
    expect_fail 2 "--stages 'dojo,moon': 'moon' is not a shipped demo" "$RS_BIN" bench quality --stages dojo,moon || return 1
}

t_bench_accuracy_small() {
    "$RS_BIN" bench accuracy --frames 1 --render-size 320x180 --size 160x90 --ibl-sizes 4,8,16 --ibl-reference 32 \
        --csv a.csv >a.txt 2>&1 ||
        { grep -q "no OpenImageIO" a.txt && t_skip_install "no OpenImageIO in this build"; cat a.txt; return 1; }
    for f in box bilinear nearest lanczos3 "cpu box"; do
        grep -Eq "^$f +[0-9]+\.[0-9]+ +[0-9]+\.[0-9]+" a.txt || { echo "no row $f"; cat a.txt; return 1; }
    done
    # the filters must rank as filters do: lanczos3 closest to the lanczos3 reference, nearest worst
    l=$(awk '$1=="lanczos3"{print $2}' a.txt) b=$(awk '$1=="box"{print $2}' a.txt) n=$(awk '$1=="nearest"{print $2}' a.txt)
    awk -v l="$l" -v b="$b" -v n="$n" 'BEGIN { exit !(l > b && b > n && n > 20) }' || { cat a.txt; return 1; }
    grep -q "RGB -> YCbCr 4:2:0" a.txt || return 1
    [ "$(wc -l <a.csv)" = 7 ] || { cat a.csv; return 1; }
    # IBL: the error falls as the source cube grows, for every map (rms and max)
    [ "$(wc -l <a-ibl.csv)" = 4 ] || { cat a-ibl.csv; return 1; }
    awk -F, 'NR > 1 { for (i = 3; i <= 8; i++) { if (NR > 2 && $i >= prev[i]) exit 1; prev[i] = $i } }' a-ibl.csv ||
        { echo "IBL error does not fall with the source size"; cat a-ibl.csv; return 1; }
    # tone: the default table (256) meets the goal at gamma 2.2, 16 entries do not
    awk -F, '$1 == 256 && $3 >= 0.1 { exit 1 } $1 == 16 && $3 < 0.1 { exit 1 }' a-tone.csv || { cat a-tone.csv; return 1; }
    grep -q "256 .*<- default" a.txt || { cat a.txt; return 1; }
    # water: every capped Courant number is stable; bypassing the cap past the limit is not
    awk '/^ +0\.[0-9]+ +0\.[0-9]+ +[0-9.]+ +[0-9.]+ / && !/bypassed/ { n++; if ($4 >= 1 || $8 != "yes") exit 1 }
         END { exit n < 5 }' a.txt || { echo "water table: an unstable capped row"; cat a.txt; return 1; }
    grep -Eq "^ +0\.7500 +0\.7500 .* 1\.9[0-9]+ .*cap bypassed" a.txt || { echo "water table: no unstable row"; cat a.txt; return 1; }
    # LSPSM: more texels near than uniform with the light across the view, uniform near parallel
    awk -F, '$1 == 90 && $7 <= 3 { exit 1 } $1 == 0 && ($7 < 0.999 || $7 > 1.001) { exit 1 }' a-lspsm.csv &&
        [ "$(wc -l <a-lspsm.csv)" = 6 ] || { cat a-lspsm.csv; return 1; }
}

t_image_sequences() {
    "$RS_BIN" render --help | grep -q "%06d.png" || t_skip_install "this build has no OpenImageIO"
    # 30 frames a sequence (more than the PBO ring); the 1 s replay bounds
    # what the cut one draws before its frame 5 fails
    short_replay 1 || return 1
    mkdir png exr && "$RS_BIN" render short.rsr --ticks 0:30 -o png/f%04d.png $SIZES --quiet || return 1
    [ "$(ls png | wc -l)" = 30 ] && [ -s png/f0000.png ] && [ -s png/f0029.png ] || { ls png | head; return 1; }
    ! ls png | grep -q part || { echo "part files left"; return 1; }
    if command -v ffprobe >/dev/null; then
        ffprobe -v error -show_entries stream=width,height -of csv=p=0 png/f0015.png | grep -q "^160,90" || return 1
    fi
    "$RS_BIN" render short.rsr --ticks 0:30 -o exr/f%03d.exr --render-size 320x180 --size 161x91 --quiet || return 1
    [ "$(ls exr | wc -l)" = 30 ] || return 1
    # a failure part way removes the frames already written (frame 5's
    # temporary name is taken by a directory, so frame 5 cannot be written;
    # a frame name that exists is refused before the render: test_cli_conv)
    mkdir -p cut/f0005.tif.part
    "$RS_BIN" render short.rsr -o cut/f%04d.tif $SIZES --quiet 2>err.txt
    [ $? = 1 ] || { echo "want exit 1"; cat err.txt; return 1; }
    grep -q "cut/f0005.tif.part" err.txt || { cat err.txt; return 1; }
    [ "$(ls cut)" = "f0005.tif.part" ] || { echo "partial sequence left:"; ls cut | head; return 1; }
    expect_fail 2 "needs one %d or %0Nd" "$RS_BIN" render short.rsr -o "f%s.png" || return 1
    expect_fail 2 "needs one %d or %0Nd" "$RS_BIN" render short.rsr -o "f%04d.jpg" || return 1
    expect_fail 2 "needs one %d or %0Nd" "$RS_BIN" render short.rsr -o "f%0999999d.png" || return 1
    expect_fail 2 "needs one %d or %0Nd" "$RS_BIN" render short.rsr -o "f%n.png" || return 1
}

t_run streams_and_signals image_sequences filters bench_accuracy_small bench_quality_small bench_capture_small async_equals_sequential y4m_plays mp4_exact_timing disk_full bad_input queue_cap_in_report
t_done
