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

# draft: the history is the same code at any quality, for less fixed cost a
# frame.  Only plaza needs to start past tick 228 (LSPSM's window, so its
# warm-up starts mid-replay); the others' history runs from tick 0 or not at
# all, which tick 60 shows as well as 240
t_every_demo_from_a_mid_tick() {
    for demo in dojo harbor temple shallows snowfield mistvale quarry; do
        same "$demo" 60 63 --size 160x90 --render-size 160x90 --quality draft || return 1
    done
    same plaza "$A" "$B" --size 160x90 --render-size 160x90 --quality draft
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
    same shallows 300 420 --size 320x180 --render-size 640x360 || return 1
    same mistvale 300 420 --size 320x180 --render-size 640x360 || return 1
}

# the summary says how far back the warm-up went: nothing on dojo, LSPSM's
# window (drawn) on plaza, from tick 0 on shallows
t_warmup_reported() {
    for c in "dojo:from tick 240 (0 ticks advanced, 0 of them drawn)" \
        "plaza:from tick 12 (228 ticks advanced, 228 of them drawn)" \
        "shallows:from tick 0 (240 ticks advanced, 0 of them drawn)"; do
        demo=${c%%:*} want=${c#*:}
        "$RS_BIN" render "$SRC/demos/$demo.rsr" -o /dev/null --ticks 240:241 --size 64x36 --render-size 64x36 \
            2>err.txt || { cat err.txt; return 1; }
        grep -qF "warm-up for tick 240: the effects' history $want" err.txt || { echo "$demo:"; cat err.txt; return 1; }
    done
}

t_run every_demo_from_a_mid_tick other_size_and_capture long_range_at_640x360 warmup_reported
t_done
