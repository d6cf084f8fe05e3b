#!/bin/sh
# End-to-end: render --jobs (cmd/job_split.c): a video drawn as segments at
# once by child processes and joined, against one render of the same ticks
# (docs/capture.md, "Parallel segments").
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
DOJO="$SRC/demos/dojo.rsr"
SIZES="--size 160x90 --render-size 320x180"

# nothing of a parallel render left beside OUT: no segment folder, no .part
nothing_left() {
    ls -a | grep -q '^\.ringside-render-' && { echo "segment folder left: $(ls -a)"; return 1; }
    ls | grep -q '\.part$' && { echo "partial file left: $(ls)"; return 1; }
    pgrep -f "ringside render $DOJO" >/dev/null && { echo "a segment's render is still running"; return 1; }
    return 0
}

t_split_equals_single() {
    "$RS_BIN" render "$DOJO" --ticks 0:240 $SIZES --jobs 3 --hashes par.hashes -o par.mp4 2>err.txt ||
        { cat err.txt; return 1; }
    grep -q 'wrote par.mp4: 240 frames 160x90 .*; 3 segments at once (--jobs 3), joined in .*; audio aac' err.txt ||
        { echo "summary:"; cat err.txt; return 1; }
    "$RS_BIN" render "$DOJO" --ticks 0:240 $SIZES --jobs 1 --hashes one.hashes -o one.mp4 -q || return 1
    # the same pictures, frame for frame (the hash of every frame's bytes)
    cmp one.hashes par.hashes || { echo "the frames differ from one render's"; return 1; }
    [ "$(wc -l <par.hashes)" = 240 ] || return 1
    [ "$(ffprobe -v error -select_streams v -count_packets -show_entries stream=nb_read_packets -of csv=p=0 par.mp4)" = 240 ] ||
        { echo "not 240 video packets"; return 1; }
    # the sound in one piece: as long as the picture, as the single render's
    a=$(ffprobe -v error -select_streams a -show_entries stream=codec_name,duration -of csv=p=0 par.mp4)
    b=$(ffprobe -v error -select_streams a -show_entries stream=codec_name,duration -of csv=p=0 one.mp4)
    [ "$a" = "$b" ] && [ -n "$a" ] || { echo "audio '$a', single render's '$b'"; return 1; }
    # packet for packet the single render's (the split one's is encoded while
    # its segments draw, and the join only writes it: job_split.c)
    a=$(ffmpeg -v error -i par.mp4 -map 0:a -c copy -f framemd5 - | grep -v '^#' | md5sum)
    b=$(ffmpeg -v error -i one.mp4 -map 0:a -c copy -f framemd5 - | grep -v '^#' | md5sum)
    [ "$a" = "$b" ] || { echo "the audio packets differ from the single render's"; return 1; }
    nothing_left
}

# the segment that holds the poster's frame writes it; the same PNG as one render's
t_poster() {
    t=$("$RS_BIN" replay info "$DOJO" | sed -n 's/^poster *frame \([0-9]*\) .*/\1/p')
    [ -n "$t" ] || { echo "replay info names no poster frame"; return 1; }
    r=$((t - 40)):$((t + 60)) # the frame in the second of two segments
    "$RS_BIN" render "$DOJO" --ticks $r $SIZES --jobs 1 --poster one.png -o one.mp4 2>err1.txt || { cat err1.txt; return 1; }
    grep -q "poster one.png: frame $t" err1.txt || { echo "no poster in the single render:"; cat err1.txt; return 1; }
    "$RS_BIN" render "$DOJO" --ticks $r $SIZES --jobs 2 --poster par.png -o par.mp4 -q || return 1
    cmp one.png par.png || { echo "posters differ"; return 1; }
    nothing_left
}

t_refused() {
    expect_fail 2 'only a .mp4, .mkv or .webm file' "$RS_BIN" render "$DOJO" --ticks 0:240 --jobs 2 -o x.y4m || return 1
    expect_fail 2 'with --segment' "$RS_BIN" render "$DOJO" --ticks 0:240 --jobs 2 --segment k -o x.mp4 || return 1
    expect_fail 2 'with --passes' "$RS_BIN" render "$DOJO" --ticks 0:240 --jobs 2 --passes -o x.mp4 || return 1
    expect_fail 2 "--jobs '0'" "$RS_BIN" render "$DOJO" --jobs 0 -o x.mp4 || return 1
    expect_fail 1 'nope.stage' "$RS_BIN" render "$DOJO" --ticks 0:240 --jobs 2 --stage-file nope.stage -o x.mp4 || return 1
    [ ! -e x.mp4 ] && [ ! -e x.y4m ] && nothing_left
}

# a segment that cannot be written: the render fails naming the segment, nothing is left
t_segment_fails() {
    sh -c "trap '' XFSZ; ulimit -f 20; exec \"$RS_BIN\" render \"$DOJO\" --ticks 0:240 $SIZES --jobs 2 -o x.mp4" 2>err.txt
    rc=$?
    [ "$rc" = 1 ] || { echo "exit $rc"; cat err.txt; return 1; }
    grep -q 'x.mp4: segment [12] of 2 (ticks .*): .*File too large' err.txt || { cat err.txt; return 1; }
    [ ! -e x.mp4 ] && nothing_left
}

t_interrupted() {
    "$RS_BIN" render "$DOJO" --ticks 0:1200 $SIZES --jobs 2 -o x.mp4 --progress off 2>err.txt &
    pid=$!
    sleep 3
    kill -TERM $pid
    wait $pid
    rc=$?
    [ "$rc" = 1 ] || { echo "exit $rc"; cat err.txt; return 1; }
    grep -q 'x.mp4: interrupted at frame [0-9]* of 1200; the partial output was removed' err.txt || { cat err.txt; return 1; }
    sleep 0.5
    [ ! -e x.mp4 ] && nothing_left
}

# auto: one segment per CPU on llvmpipe, each of at least 600 frames
t_auto() {
    "$RS_BIN" render "$SRC/demos/temple.rsr" --ticks 0:1200 --size 64x36 --quality draft --audio off -o a.mp4 2>err.txt ||
        { cat err.txt; return 1; }
    "$RS_BIN" info 2>&1 | grep -q llvmpipe || t_skip_env "not llvmpipe: auto renders in one process"
    if [ "$(nproc)" -ge 2 ]; then
        grep -q '2 segments at once (--jobs 2)' err.txt || { cat err.txt; return 1; }
    else
        ! grep -q 'segments at once' err.txt || { cat err.txt; return 1; }
    fi
    # a short render: one process
    "$RS_BIN" render "$SRC/demos/temple.rsr" --ticks 0:300 --size 64x36 --quality draft --audio off -o b.mp4 2>err.txt &&
        ! grep -q 'segments at once' err.txt || { cat err.txt; return 1; }
}

t_run split_equals_single poster refused segment_fails interrupted auto
t_done
