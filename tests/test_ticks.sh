#!/bin/sh
# End-to-end: `render --ticks A:B` writes, bit for bit (--hashes), the
# frames a render from tick 0 writes at ticks A..B-1, on every shipped demo
# (so every stage and every effect that carries history: the water
# automaton, the snow height map, the mist, LSPSM's auto-focus), at another
# size and with the other capture mode.  docs/effects.md, "History".
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
export RINGSIDE_CACHE=off

# A is past LSPSM's window (228 ticks), so plaza's warm-up starts mid-replay.
A=240 B=243

# same DEMO A B ARGS...: the lines of A..B-1 of a full render equal a render of A:B
same() {
    demo=$1 a=$2 b=$3
    shift 3
    "$RS_BIN" render "$SRC/demos/$demo.rsr" --quiet -o /dev/null --ticks "0:$b" --hashes "full-$demo.h" "$@" 2>err.txt ||
        { cat err.txt; return 1; }
    "$RS_BIN" render "$SRC/demos/$demo.rsr" --quiet -o /dev/null --ticks "$a:$b" --hashes "part-$demo.h" "$@" 2>err.txt ||
        { cat err.txt; return 1; }
    sed -n "$((a + 1)),${b}p" "full-$demo.h" >want.h
    [ "$(wc -l <want.h)" = "$((b - a))" ] || { echo "$demo: the full render wrote $(wc -l <"full-$demo.h") lines"; return 1; }
    cmp -s want.h "part-$demo.h" || {
        echo "$demo $*: ticks $a:$b differ from the same ticks of a full render"
        diff want.h "part-$demo.h" | head -8
        return 1
    }
}

# lane NAME CMD...: CMD in the background, in the folder NAME (same's files
# have fixed names), its output in NAME.log; lanes_wait waits for every
# lane and shows the output of those that failed.  The renders are mostly
# one busy thread (start-up, the game, the capture), so two lanes fill the
# two cores that one leaves half idle.
T_LANES=""
lane() {
    name=$1
    shift
    mkdir -p "$name"
    (cd "$name" && "$@") >"$name.log" 2>&1 &
    T_LANES="$T_LANES $!:$name"
}
lanes_wait() {
    st=0
    for l in $T_LANES; do
        wait "${l%%:*}" || { echo "${l#*:}:"; cat "${l#*:}.log"; st=1; }
    done
    T_LANES=""
    return $st
}

# draft: the history is the same code at any quality, for less fixed cost a
# frame.  Only plaza needs to start past tick 228 (LSPSM's window, so its
# warm-up starts mid-replay); the others' history runs from tick 0 or not at
# all, which tick 60 shows as well as 240.  Plaza's draft and standard take
# the buildings' shadows from static layers, with no history (tick 60 at
# draft checks them); high's knobs at the same render size draw the LSPSM
# map, whose window is checked at 240.  Two lanes of about equal cost.
t_every_demo_from_a_mid_tick() {
    draft="--size 160x90 --render-size 160x90 --quality draft"
    at60() {
        for demo in "$@"; do
            same "$demo" 60 63 $draft || return 1
        done
    }
    plaza_and() { same plaza "$A" "$B" --size 160x90 --render-size 160x90 --quality high && at60 "$@"; }
    lane a plaza_and dojo harbor temple
    lane b at60 shallows snowfield mistvale quarry plaza
    lanes_wait
}

# another size, a downscale, the sequential capture (CPU downscale)
t_other_size_and_capture() {
    same shallows 100 103 --size 96x54 --render-size 192x108 --capture sequential || return 1
    same mistvale 100 103 --size 96x54 --render-size 192x108 --capture sequential || return 1
}

# 120 ticks at the default output size drawn at 640x360: the water's
# dying ripples reach the denormal range here (a flush that depended on
# the thread made 2 of these frames differ by one step of 8 bits, until
# the automaton flushed tiny heights itself); mistvale's mist too
t_long_range_at_640x360() {
    lane shallows same shallows 300 420 --size 320x180 --render-size 640x360
    lane mistvale same mistvale 300 420 --size 320x180 --render-size 640x360
    lanes_wait
}

# the summary says how far back the warm-up went: nothing on dojo, LSPSM's
# window (drawn) on plaza at high (none at standard: its static layers),
# from tick 0 on shallows
t_warmup_reported() {
    # plaza's standard preset takes the buildings' shadows from static
    # layers (no history); high draws the LSPSM map, whose focus has one
    for c in "dojo:standard:from tick 240 (0 ticks advanced, 0 of them drawn)" \
        "plaza:high:from tick 12 (228 ticks advanced, 228 of them drawn)" \
        "plaza:standard:from tick 240 (0 ticks advanced, 0 of them drawn)" \
        "shallows:standard:from tick 0 (240 ticks advanced, 0 of them drawn)"; do
        demo=${c%%:*} q=${c#*:} want=${c#*:*:}
        q=${q%%:*}
        "$RS_BIN" render "$SRC/demos/$demo.rsr" -o /dev/null --ticks 240:241 --size 64x36 --render-size 64x36 \
            --quality "$q" 2>err.txt || { cat err.txt; return 1; }
        grep -qF "warm-up for tick 240: the effects' history $want" err.txt || { echo "$demo:"; cat err.txt; return 1; }
    done
}

# the same range in seconds: --from/--to/--duration (seconds, MM:SS,
# HH:MM:SS) give the ticks --ticks gives, an end past the replay is clamped
# with a note, and what cannot be a range is bad usage (exit 2)
t_seconds_are_ticks() {
    small="--size 64x36 --render-size 64x36 --quality draft --quiet -o /dev/null"
    rp=$SRC/demos/temple.rsr
    "$RS_BIN" render "$rp" $small --ticks 90:120 --hashes ticks.h || return 1
    for range in "--from 1.5 --to 2" "--from 0:01.5 --duration 0.5" "--from 0:00:01.5 --to 0:02" "--from 1.508 --to 1.992"; do
        "$RS_BIN" render "$rp" $small $range -y --hashes secs.h 2>err.txt || { cat err.txt; return 1; }
        cmp -s ticks.h secs.h || { echo "$range: not the frames of --ticks 90:120"; head -2 secs.h; return 1; }
    done
    # 2537 ticks (42.283 s): from 42 s on, 45 s is past the end
    "$RS_BIN" render "$rp" $small --from 42 --to 45 --hashes end.h 2>err.txt || { cat err.txt; return 1; }
    [ "$(wc -l <end.h)" = 17 ] && grep -q "the replay ends at 42.283 s, so 42.000 s to 42.283 s are drawn" err.txt ||
        { echo "past the end:"; cat err.txt; wc -l end.h; return 1; }
    for bad in "--from 1:5" "--from -1" "--to 1e3" "--from 2 --to 1" "--to 1 --duration 1" "--ticks 0:10 --from 1" "--from 99"; do
        "$RS_BIN" render "$rp" $small $bad 2>err.txt
        st=$?
        [ $st = 2 ] && [ "$(wc -l <err.txt)" = 1 ] && grep -q "^ringside render: " err.txt ||
            { echo "$bad: exit $st (want 2), said:"; cat err.txt; return 1; }
    done
    grep -q "starts past the replay's end (42.283 s, 2537 ticks)" err.txt || { cat err.txt; return 1; }
    # minutes and seconds after a colon are under 60: the first past it is no time
    for bad in 0:60 0:59:60 0:60:00; do
        expect_fail 2 "^ringside render: --from '$bad': expected seconds \(12.5\), MM:SS" \
            "$RS_BIN" render "$rp" $small --from "$bad" || return 1
    done
}

# REPLAY '-': the replay from standard input, also for --jobs (the
# segments read a temporary copy, removed after); -o - to a reader that
# stops early: one line with the frame and exit status 4
t_stdin_and_a_closed_pipe() {
    small="--size 64x36 --render-size 64x36 --quality draft --quiet --ticks 0:40"
    rp=$SRC/demos/temple.rsr
    "$RS_BIN" render "$rp" $small -o /dev/null --hashes file.h || return 1
    "$RS_BIN" render - $small -o /dev/null --hashes stdin.h <"$rp" 2>err.txt || { cat err.txt; return 1; }
    cmp -s file.h stdin.h || { echo "the replay from standard input drew other frames"; return 1; }
    mkdir -p tmp
    TMPDIR=$PWD/tmp "$RS_BIN" render - $small -o split.mkv --jobs 2 <"$rp" 2>err.txt || { cat err.txt; return 1; }
    [ -s split.mkv ] && [ -z "$(ls tmp)" ] || { echo "--jobs 2 from standard input: $(ls tmp)"; cat err.txt; return 1; }
    head -c 100 "$rp" | "$RS_BIN" render - $small -o /dev/null 2>err.txt
    st=$?
    [ $st = 1 ] && grep -q "^ringside render: standard input: " err.txt || { echo "a cut replay: exit $st"; cat err.txt; return 1; }
    # the y4m header and one 64x36 frame are 3,512 bytes: the reader stops in the second
    { "$RS_BIN" render "$rp" $small --progress off -o - 2>err.txt; echo $? >st.txt; } | head -c 5000 >/dev/null
    [ "$(cat st.txt)" = 4 ] && grep -qx "ringside render: standard output: the reader closed the pipe at frame [0-9]*" err.txt ||
        { echo "a closed pipe: exit $(cat st.txt)"; cat err.txt; return 1; }
}

t_run every_demo_from_a_mid_tick other_size_and_capture long_range_at_640x360 warmup_reported seconds_are_ticks \
    stdin_and_a_closed_pipe
t_done
