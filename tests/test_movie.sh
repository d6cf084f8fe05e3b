#!/bin/sh
# End-to-end: ringside movie and ringside attract through the real binary,
# on clips made here by the ffmpeg command line (nothing committed).
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)

need_ffmpeg() { command -v ffmpeg >/dev/null || t_skip_install "no ffmpeg command line (tools/deps.sh test)"; }

# clip OUT RATE FRAMES SIZE [ffmpeg output options...]
clip() {
    out=$1 rate=$2 n=$3 size=$4
    shift 4
    ffmpeg -nostdin -hide_banner -loglevel error -y -f lavfi -i "testsrc2=size=$size:rate=$rate" -frames:v "$n" \
        "$@" "$out" || { echo "ffmpeg could not make $out"; return 1; }
}

t_pacing_24fps() {
    need_ffmpeg
    clip c24.y4m 24 24 160x120 -pix_fmt yuv420p || return 1
    "$RS_BIN" movie c24.y4m --hashes h.txt 2>e.txt || { cat e.txt; return 1; }
    [ "$(wc -l <h.txt)" = 60 ] || { echo "want 60 ticks for 24 frames at 24 fps"; cat e.txt; return 1; }
    # run lengths of the frame column: 3 2 3 2 ... (2:3 pulldown), 24 runs
    runs=$(awk '{ if (NR > 1 && $2 != f) { printf "%d ", n; n = 0 } f = $2; n++ } END { printf "%d", n }' h.txt)
    want=$(awk 'BEGIN { for (i = 0; i < 24; i++) printf (i ? " " : "") "%d", i % 2 ? 2 : 3 }')
    [ "$runs" = "$want" ] || { echo "cadence '$runs', want '$want'"; return 1; }
    # the picture changes exactly when the frame does
    bad=$(awk '{ if (NR > 1 && (($2 != f) != ($3 != h))) print; f = $2; h = $3 }' h.txt)
    [ -z "$bad" ] || { echo "hash and frame disagree: $bad"; return 1; }
    grep -q "60 ticks .* 24 frames shown, 36 repeated (cadence), 0 late, 0 dropped" e.txt || { cat e.txt; return 1; }
}

t_pacing_30_and_60() {
    need_ffmpeg
    clip c30.y4m 30 10 64x48 -pix_fmt yuv420p || return 1
    "$RS_BIN" movie c30.y4m --hashes h30.txt -q || return 1
    [ "$(awk '{ printf "%s ", $2 }' h30.txt)" = "0 0 1 1 2 2 3 3 4 4 5 5 6 6 7 7 8 8 9 9 " ] || { cat h30.txt; return 1; }
    clip c60.y4m 60 10 64x48 -pix_fmt yuv420p || return 1
    "$RS_BIN" movie c60.y4m --hashes h60.txt -q || return 1
    [ "$(awk '{ printf "%s ", $2 }' h60.txt)" = "0 1 2 3 4 5 6 7 8 9 " ] || { cat h60.txt; return 1; }
}

t_upload_paths_agree() {
    need_ffmpeg
    clip c.mp4 25 20 322x182 -pix_fmt yuv420p -c:v libx264 -preset ultrafast || return 1
    "$RS_BIN" movie c.mp4 --hashes pbo.txt --upload pbo 2>e.txt || { cat e.txt; return 1; }
    grep -q "upload pbo: .* (19 staged a tick ahead)" e.txt || { echo "PBO ping-pong did not stage ahead"; cat e.txt; return 1; }
    "$RS_BIN" movie c.mp4 --hashes direct.txt --upload direct -q || return 1
    cmp pbo.txt direct.txt || { echo "pbo and direct show different pictures"; return 1; }
    if "$RS_BIN" movie c.mp4 --hashes pers.txt --upload persistent 2>pe.txt; then
        cmp pbo.txt pers.txt || { echo "pbo and persistent show different pictures"; return 1; }
    else
        grep -q "needs glBufferStorage" pe.txt || { cat pe.txt; return 1; }
    fi
    # and the dump writes one image per movie frame
    "$RS_BIN" movie c.mp4 --dump d -q || return 1
    [ "$(ls d | wc -l)" = 20 ] && [ -s d/frame000019.ppm ] || { ls d; return 1; }
}

t_bad_files() {
    need_ffmpeg
    expect_fail 1 "nope.mp4: No such file" "$RS_BIN" movie nope.mp4 || return 1
    printf 'not a movie at all' >garbage.mp4
    expect_fail 1 "garbage.mp4: cannot open as a movie" "$RS_BIN" movie garbage.mp4 || return 1
    : >empty.mkv
    expect_fail 1 "empty.mkv: empty file" "$RS_BIN" movie empty.mkv || return 1
    # a Y4M cut inside frame 4: frames 0-3 are written, then a clear error
    clip full.y4m 60 8 64x48 -pix_fmt yuv420p || return 1
    hdr=$(head -n 1 full.y4m | wc -c)
    head -c $((hdr + 4 * (6 + 4608) + 6 + 1000)) full.y4m >cut.y4m
    expect_fail 1 "cut.y4m: frame 4 truncated" "$RS_BIN" movie cut.y4m --dump cut || return 1
    [ "$(ls cut | wc -l)" = 4 ] || { echo "frames before the cut were lost"; ls cut; return 1; }
    # formats we do not play, named
    clip rgb.mkv 30 2 64x48 -pix_fmt bgr0 -c:v ffv1 || return 1
    expect_fail 1 "rgb.mkv: pixel format bgr0 is not played" "$RS_BIN" movie rgb.mkv || return 1
    printf 'YUV4MPEG2 W64 H48 F30:1 C420p10\nFRAME\n' >deep.y4m
    expect_fail 1 "deep.y4m: .*(10|bit)" "$RS_BIN" movie deep.y4m || return 1
    # an MP4 whose container counts more frames than its edit list shows
    # plays to its end without an error
    clip long.mp4 30 60 64x48 -pix_fmt yuv420p -c:v libx264 -preset ultrafast -g 10 || return 1
    ffmpeg -nostdin -hide_banner -loglevel error -y -ss 0.5 -i long.mp4 -c copy edit.mp4 || return 1
    "$RS_BIN" movie edit.mp4 --hashes e.txt -q || { echo "a clean edit-list MP4 failed"; return 1; }
    expect_fail 2 "--upload 'fast': expected pbo, direct or persistent" "$RS_BIN" movie c.y4m --upload fast || return 1
    expect_fail 2 "no movie file given" "$RS_BIN" movie || return 1
}

t_attract_headless() {
    need_ffmpeg
    clip good.mp4 30 30 160x120 -pix_fmt yuv420p -c:v libx264 -preset ultrafast || return 1
    printf 'garbage' >bad.mkv
    clip full.y4m 60 40 64x48 -pix_fmt yuv420p || return 1
    head -c 20000 full.y4m >cut.y4m
    # the player walks up during the demo (from tick 64); --ticks 300 ends
    # soon after the loop, back from the match, has passed the bad files
    # again on its way to the demo (tick 284)
    cat >input.txt <<EOF
# a coin-op player walks up at tick 100
100 p2 punch
104 p2 -
EOF
    "$RS_BIN" attract good.mp4 bad.mkv cut.y4m --demo "$SRC/demos/harbor.rsr" missing.mp4 --idle 2 \
        --headless --ticks 300 --size 160x90 --script input.txt --screenshot s.ppm 2>e.txt || { cat e.txt; return 1; }
    cat e.txt
    grep -q "tick 0: movie good.mp4 (h264 160x120, 30/1 fps)" e.txt || return 1
    grep -q "skipping bad.mkv from now on: bad.mkv: cannot open" e.txt || return 1
    grep -q "skipping cut.y4m from now on: cut.y4m: frame 4 truncated" e.txt || return 1
    grep -q "skipping missing.mp4 from now on" e.txt || return 1
    grep -q "demo .*harbor.rsr (harbor" e.txt || return 1
    grep -q "tick 100: player 2 pressed a button: match on .*, player 2 against the CPU" e.txt || return 1
    grep -q "tick 223: no input for 2 s: back to the attract loop" e.txt || return 1
    # the loop goes on with the next item after the match, past the bad
    # files to the demo, and a bad file is logged once
    sed -n '/back to the attract loop/,$p' e.txt | grep -q "movie good.mp4" || return 1
    sed -n '/back to the attract loop/,$p' e.txt | grep -q "demo .*harbor.rsr" || return 1
    [ "$(grep -c "skipping cut.y4m" e.txt)" = 1 ] || { echo "cut.y4m logged more than once"; return 1; }
    grep -q "stopped (--ticks)" e.txt || return 1
    [ -s s.ppm ] || return 1
}

t_attract_match_over() {
    # nobody fights back: the CPU wins, and the loop comes back after the match.
    # A demo in the loop leaves the seed alone, so the match is on harbor
    # (over at tick 1554), cheaper to draw than the snowfield an empty loop
    # leads to
    printf '10 p1 start\n11 p1 -\n' >in.txt
    "$RS_BIN" attract --demo "$SRC/demos/dojo.rsr" --headless --ticks 1600 --idle 1000 --size 64x36 --script in.txt \
        2>e.txt || { cat e.txt; return 1; }
    grep -q "tick 10: player 1 pressed a button" e.txt || { cat e.txt; return 1; }
    grep -q "match over (winner: the CPU): back to the attract loop" e.txt || { cat e.txt; return 1; }
    sed -n '/back to the attract loop/,$p' e.txt | grep -q "demo .*dojo.rsr" || { cat e.txt; return 1; }
}

t_attract_nothing_playable() {
    printf 'YUV4MPEG2 W64 H48 F30:1\n' >empty.y4m # a movie without a frame is broken too
    "$RS_BIN" attract empty.y4m --headless --ticks 30 --size 64x36 2>e0.txt || { cat e0.txt; return 1; }
    [ "$(grep -c "movie empty.y4m" e0.txt)" = 1 ] || { echo "empty.y4m reopened"; cat e0.txt; return 1; }
    grep -q "skipping empty.y4m from now on: it has no frames" e0.txt || { cat e0.txt; return 1; }
    printf 'x' >bad.mp4
    "$RS_BIN" attract bad.mp4 --headless --ticks 30 --size 64x36 2>e.txt || { cat e.txt; return 1; }
    grep -q "skipping bad.mp4" e.txt && grep -q "nothing playable: a CPU-vs-CPU match" e.txt || { cat e.txt; return 1; }
}

t_attract_usage() {
    expect_fail 2 "--headless needs --ticks" "$RS_BIN" attract --headless || return 1
    printf '10 p3 start\n' >bad.txt
    expect_fail 1 "bad.txt:1: expected 'TICK p1\|p2 KEYS'" "$RS_BIN" attract --headless --ticks 5 --script bad.txt || return 1
    printf '10 p1 jump\n' >bad2.txt
    expect_fail 1 "bad2.txt:1:" "$RS_BIN" attract --headless --ticks 5 --script bad2.txt || return 1
}

# The issue's check: a window under Xvfb loops the movie and the demo,
# a key press starts a match, and the idle timeout brings the loop back.
t_attract_window_xvfb() {
    need_ffmpeg
    command -v xdotool >/dev/null && command -v Xvfb >/dev/null || t_skip_install "needs Xvfb and xdotool"
    clip m.mp4 30 60 320x192 -pix_fmt yuv420p -c:v libx264 -preset ultrafast || return 1
    disp=:$((140 + $$ % 50))
    Xvfb "$disp" -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 &
    xpid=$!
    sleep 1
    DISPLAY=$disp "$RS_BIN" attract m.mp4 --demo "$SRC/demos/dojo.rsr" --idle 2 --size 480x270 --ticks 540 2>e.txt &
    apid=$!
    sleep 3
    DISPLAY=$disp xdotool search --sync --name ringside windowfocus --sync keydown j sleep 0.2 keyup j >/dev/null 2>&1
    wait $apid
    rc=$?
    kill $xpid 2>/dev/null
    cat e.txt
    [ $rc = 0 ] || return 1
    grep -q "movie m.mp4" e.txt && grep -q "player 1 pressed a button" e.txt &&
        grep -q "no input for 2 s: back to the attract loop" e.txt || return 1
}

t_bench_upload() {
    "$RS_BIN" bench upload --frames 8 --runs 1 --size 320x192 --csv b.csv >o.txt 2>e.txt || { cat o.txt e.txt; return 1; }
    for m in direct pbo persistent; do
        grep -q "^$m " o.txt || { echo "no $m row"; cat o.txt; return 1; }
    done
    [ "$(wc -l <b.csv)" = 4 ] || { cat b.csv; return 1; }
    expect_fail 2 "unknown mode 'warp'" "$RS_BIN" bench upload --modes direct,warp || return 1
}

t_run bench_upload pacing_24fps pacing_30_and_60 upload_paths_agree bad_files attract_headless attract_match_over attract_nothing_playable \
    attract_usage attract_window_xvfb
t_done
