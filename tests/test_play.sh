#!/bin/sh
# End-to-end: ringside play, headless and in a window under Xvfb, with keys
# pressed by xdotool.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)

t_watch_headless() {
    # a 10 s match of the CPU players, watched to its end
    "$RS_BIN" record --ai --seconds 10 --seed 4 --quiet -o w.rsr 2>/dev/null || return 1
    "$RS_BIN" play --headless --replay w.rsr --size 160x90 --screenshot s.png 2>e.txt ||
        { cat e.txt; return 1; }
    ticks=$("$RS_BIN" replay info w.rsr | sed -n 's/^duration *\([0-9]*\) ticks.*/\1/p')
    grep -q "^ringside play: $ticks ticks .* $ticks frames, 0 late ticks" e.txt || { cat e.txt; return 1; }
    [ -s s.png ] || return 1
}

t_play_records_what_record_records() {
    # the CPU players of play and of record are the same program: same file
    "$RS_BIN" play --headless --p1 cpu --p2 cpu --seconds 8 --seed 9 --size 64x36 --record p.rsr -q || return 1
    "$RS_BIN" record --ai --seconds 8 --seed 9 --quiet -o r.rsr 2>/dev/null || return 1
    cmp p.rsr r.rsr || { echo "play --record and record differ"; return 1; }
    "$RS_BIN" replay verify --quiet p.rsr 2>/dev/null || return 1
}

t_window_under_xvfb() {
    command -v xvfb-run >/dev/null || t_skip_install "xvfb-run not installed"
    xvfb-run -a -s "-screen 0 1280x1024x24" "$RS_BIN" play --p1 cpu --p2 cpu --seconds 3 --size 640x360 \
        --screenshot w.ppm 2>e.txt || { cat e.txt; return 1; }
    grep -q "^ringside play: 180 ticks" e.txt || { cat e.txt; return 1; }
    # the picture is a game frame, not a blank window: many distinct colours
    n=$(tail -c +16 w.ppm | od -An -v -tx1 -w3 | sort -u | wc -l)
    [ "$n" -gt 50 ] || { echo "only $n colours in the window"; return 1; }
}

t_keys_reach_the_game() {
    command -v xdotool >/dev/null && command -v Xvfb >/dev/null || t_skip_install "needs Xvfb and xdotool"
    disp=:$((90 + $$ % 50))
    Xvfb "$disp" -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 &
    xpid=$!
    sleep 1
    DISPLAY=$disp "$RS_BIN" play --p1 human --p2 cpu --seconds 6 --seed 3 --size 640x360 --record k.rsr \
        --screenshot k.ppm 2>e.txt &
    gpid=$!
    sleep 2.5 # the round intro lasts 1.5 s of game time
    for key in d d j k s l; do
        DISPLAY=$disp xdotool search --sync --name ringside windowfocus --sync keydown "$key" sleep 0.3 keyup "$key" \
            >/dev/null 2>&1
    done
    wait $gpid
    rc=$?
    kill $xpid 2>/dev/null
    [ $rc = 0 ] || { cat e.txt; return 1; }
    p1=$("$RS_BIN" replay info k.rsr | sed -n 's/^input ticks *P1 \([0-9]*\),.*/\1/p')
    [ "${p1:-0}" -gt 20 ] || { echo "player 1 pressed nothing the game saw ($p1 input ticks)"; return 1; }
    "$RS_BIN" replay info k.rsr | grep -q "players      P1 human, P2 cpu" || return 1
    "$RS_BIN" replay verify --quiet k.rsr 2>/dev/null || return 1
}

t_no_display() {
    expect_fail 1 "glfw: cannot open a window" env -u DISPLAY -u WAYLAND_DISPLAY "$RS_BIN" play --seconds 1 || return 1
    [ "$(wc -l <err.txt)" = 1 ] || { cat err.txt; return 1; }
}

t_usage() {
    expect_fail 2 "--replay and --record together" "$RS_BIN" play --replay a.rsr --record b.rsr || return 1
    expect_fail 2 "--p2 'robot': expected human or cpu" "$RS_BIN" play --p2 robot || return 1
    expect_fail 2 "unknown image extension" "$RS_BIN" play --screenshot x.gif || return 1
    expect_fail 1 "nope.rsr: cannot open" "$RS_BIN" play --headless --replay nope.rsr || return 1
}

t_run watch_headless play_records_what_record_records window_under_xvfb keys_reach_the_game no_display usage
t_done
