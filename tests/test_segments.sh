#!/bin/sh
# End-to-end: render --segment and join through the real binary
# (docs/segments.md).  demos/dojo.rsr ticks 0:240 as three segments of
# different lengths (70, 90, 80 ticks), joined, against one render of the
# whole range; .mkv the same way, .webm at a tiny size; then every way a
# segment or the output can be bad.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
DOJO="$SRC/demos/dojo.rsr"
SIZES="--size 160x90 --render-size 320x180"
TINY="--size 64x36 --render-size 128x72"
FIX="$T_TMP/fixtures"

# fixture FMT [SIZES] [RANGES...]: segments s<A>.FMT of job 'job7' in $FIX/FMT, made once for the suite
fixture() {
    fmt=$1 sizes=$2
    shift 2
    [ -e "$FIX/$fmt/done" ] && return 0
    mkdir -p "$FIX/$fmt" || return 1
    for r in "$@"; do
        "$RS_BIN" render "$DOJO" --ticks "$r" $sizes -q --segment job7 -o "$FIX/$fmt/s${r%:*}.$fmt" \
            --hashes "$FIX/$fmt/s${r%:*}.hashes" || { echo "segment $r of $fmt failed"; return 1; }
    done
    touch "$FIX/$fmt/done"
}
mp4_fixture() {
    fixture mp4 "$SIZES" 0:70 70:160 160:240 || return 1
    # the single render: only its hashes matter, so no encoder
    [ -e "$FIX/whole.hashes" ] || "$RS_BIN" render "$DOJO" --ticks 0:240 $SIZES -q -o /dev/null --hashes "$FIX/whole.hashes"
}
# a private copy of the mp4 segments, to damage
copy_mp4() { mp4_fixture && cp "$FIX"/mp4/s* . ; }

# presentation timestamps in ticks, sorted, one a line
pts_ticks() { ffprobe -v error -show_entries packet=pts_time -of csv=p=0 "$1" | awk '{ printf "%d\n", $1 * 60 + 0.5 }' | sort -n; }
# ticks of the keyframes
key_ticks() { ffprobe -v error -show_entries packet=pts_time,flags -of csv=p=0 "$1" | awk -F, '$2 ~ /K/ { printf "%d\n", $1 * 60 + 0.5 }' | sort -n; }
# the decoded frames' MD5s, in order
frames() { ffmpeg -v error -i "$1" -f framemd5 - | grep -v '^#' | cut -d, -f6; }
# the same of the video stream alone
vframes() { ffmpeg -v error -i "$1" -map 0:v -f framemd5 - | grep -v '^#' | cut -d, -f6; }
# no output and no temporary left for OUT.mp4 / OUT.hashes
nothing_left() {
    for f in "$1.mp4" "$1.mp4.part" "$1.hashes" "$1.hashes.part"; do
        [ ! -e "$f" ] || { echo "$f left behind"; return 1; }
    done
}

# the checks every joined video must pass: N frames of ticks 0..N-1 at 60/1,
# keyframes at KEYS, decoded frames = the segments' decoded frames in order
check_joined() {
    out=$1 n=$2 keys=$3
    shift 3
    [ "$(ffprobe -v error -count_packets -show_entries stream=nb_read_packets -of csv=p=0 "$out")" = "$n" ] ||
        { echo "$out: not $n packets"; return 1; }
    [ "$(ffprobe -v error -show_entries stream=r_frame_rate -of csv=p=0 "$out")" = 60/1 ] || { echo "$out: not 60/1"; return 1; }
    [ "$(pts_ticks "$out")" = "$(seq 0 $((n - 1)))" ] || { echo "$out: timestamps are not ticks 0..$((n - 1))"; pts_ticks "$out" | head; return 1; }
    for k in $keys; do
        key_ticks "$out" | grep -qx "$k" || { echo "$out: no keyframe at tick $k"; key_ticks "$out"; return 1; }
    done
    for s in "$@"; do frames "$s"; done >segs.md5
    frames "$out" >joined.md5
    [ "$(wc -l <joined.md5)" = "$n" ] || { echo "$out: $(wc -l <joined.md5) frames decoded, want $n"; return 1; }
    cmp -s segs.md5 joined.md5 || { echo "$out: decoded frames differ from the segments'"; return 1; }
}

t_mp4_segments_join_to_the_single_render() {
    mp4_fixture || return 1
    S="$FIX/mp4"
    # each segment alone: its own ticks, a keyframe first, a manifest
    [ "$(pts_ticks "$S/s70.mp4")" = "$(seq 70 159)" ] || { echo "s70.mp4 timestamps are not ticks 70..159"; return 1; }
    [ "$(key_ticks "$S/s70.mp4" | head -1)" = 70 ] || { echo "s70.mp4 does not start on a keyframe"; return 1; }
    grep -qx "ticks 70 160" "$S/s70.mp4.seg" && grep -qx "key job7" "$S/s70.mp4.seg" && grep -qx "frames 90" "$S/s70.mp4.seg" &&
        grep -qx "bytes $(wc -c <"$S/s70.mp4")" "$S/s70.mp4.seg" || { cat "$S/s70.mp4.seg"; return 1; }
    "$RS_BIN" join --segment job7 -o j.mp4 --hashes j.hashes --progress-fd 3 "$S/s0.mp4" "$S/s70.mp4" "$S/s160.mp4" \
        3>prog.txt 2>err.txt || { cat err.txt; return 1; }
    grep -q "wrote j.mp4: 240 frames (ticks 0..239) from 3 segments" err.txt || { cat err.txt; return 1; }
    [ "$(tail -1 prog.txt)" = "frames 240 240" ] || { cat prog.txt; return 1; }
    check_joined j.mp4 240 "0 70 160" "$S/s0.mp4" "$S/s70.mp4" "$S/s160.mp4" || return 1
    # per-frame hashes equal one render of the whole range
    cmp j.hashes "$FIX/whole.hashes" || { echo "joined --hashes differ from a single render's"; return 1; }
    # decode order: dts rise by exactly one tick a packet, across the joins too
    ffprobe -v error -show_entries packet=dts_time -of csv=p=0 j.mp4 |
        awk 'NR > 1 && int(($1 - p) * 60 + 0.5) != 1 { print "dts step at packet " NR ": " p " -> " $1; bad = 1 } { p = $1 } END { exit bad }' ||
        return 1
    [ "$(ffprobe -v error -show_entries stream=duration -of csv=p=0 j.mp4)" = 4.000000 ] || { echo "duration not 4 s"; return 1; }
    # faststart: the index (moov) before the frames (mdat)
    [ "$(ffprobe -v trace j.mp4 2>&1 | grep -o "type:'\(moov\|mdat\)'" | head -2 | tr '\n' ' ')" = "type:'moov' type:'mdat' " ] ||
        { echo "j.mp4: moov is not before mdat"; return 1; }
    # colour tags survive the copy
    [ "$(ffprobe -v error -show_entries stream=color_range,color_primaries -of csv=p=0 j.mp4)" = "tv,bt709" ] ||
        { echo "j.mp4 lost its colour tags"; return 1; }
}

t_mkv_and_webm() {
    mp4_fixture && fixture mkv "$SIZES" 0:70 70:160 160:240 && fixture webm "$TINY" 0:30 30:80 80:120 || return 1
    S="$FIX/mkv"
    "$RS_BIN" join --segment job7 -o j.mkv --hashes j.hashes -q "$S/s0.mkv" "$S/s70.mkv" "$S/s160.mkv" || return 1
    check_joined j.mkv 240 "0 70 160" "$S/s0.mkv" "$S/s70.mkv" "$S/s160.mkv" || return 1
    cmp j.hashes "$FIX/whole.hashes" || { echo "joined .mkv --hashes differ from a single render's"; return 1; }
    S="$FIX/webm"
    "$RS_BIN" join --segment job7 -o j.webm --hashes w.hashes -q "$S/s0.webm" "$S/s30.webm" "$S/s80.webm" || return 1
    check_joined j.webm 120 "0 30 80" "$S/s0.webm" "$S/s30.webm" "$S/s80.webm" || return 1
    cat "$S/s0.hashes" "$S/s30.hashes" "$S/s80.hashes" | cmp - w.hashes || { echo "joined .webm --hashes are not the segments'"; return 1; }
    # a container that is not the output's
    expect_fail 3 "s0.webm: a webm segment, and the output is mkv" \
        "$RS_BIN" join --segment job7 -o x.mkv "$S/s0.webm" "$FIX/mkv/s70.mkv" "$FIX/mkv/s160.mkv" || return 1
    [ ! -e x.mkv ] && [ ! -e x.mkv.part ] || { echo "output left"; return 1; }
}

# bad_join INDEX REASON FILE-PATTERN SEG...: exit 3, 'bad INDEX REASON' on fd 3, the file on stderr, nothing written
bad_join() {
    index=$1 reason=$2 pat=$3
    shift 3
    "$RS_BIN" join --segment job7 -o jx.mp4 --hashes jx.hashes --progress-fd 3 "$@" 3>bad.txt 2>err.txt
    rc=$?
    [ "$rc" = 3 ] || { echo "exit $rc, want 3 ($reason)"; cat err.txt; return 1; }
    grep -q "^bad $index $reason " bad.txt || { echo "no 'bad $index $reason' line:"; cat bad.txt; return 1; }
    [ "$(grep -c '^bad ' bad.txt)" = 1 ] || { echo "more than one bad segment:"; cat bad.txt; return 1; }
    ! grep -q '^frames' bad.txt || { echo "copied although a segment is bad"; return 1; }
    grep -Eq -- "$pat" err.txt || { echo "stderr lacks /$pat/"; cat err.txt; return 1; }
    nothing_left jx
}

t_bad_segments_exit_3() {
    copy_mp4 || return 1
    # truncated
    cp s70.mp4 keep.mp4
    head -c 5000 keep.mp4 >s70.mp4
    bad_join 1 size "s70.mp4: 5000 bytes, the manifest says [0-9]+" s0.mp4 s70.mp4 s160.mp4 || return 1
    # damaged in place (same size): the packet CRC
    cp keep.mp4 s70.mp4
    printf '\125\252' | dd of=s70.mp4 bs=1 seek=200 conv=notrunc 2>/dev/null
    bad_join 1 media "s70.mp4: packet CRC-32 [0-9a-f]{8}, the manifest says" s0.mp4 s70.mp4 s160.mp4 || return 1
    cp keep.mp4 s70.mp4
    # another job's or an earlier attempt's
    cp s160.mp4.seg keep.seg
    sed -i 's/^key job7$/key job6/' s160.mp4.seg
    bad_join 2 key "s160.mp4: segment of 'job6', not of 'job7'" s0.mp4 s70.mp4 s160.mp4 || return 1
    cp keep.seg s160.mp4.seg
    # unfinished: no manifest
    mv s0.mp4.seg keep.seg
    bad_join 0 missing "s0.mp4: no manifest s0.mp4.seg" s0.mp4 s70.mp4 s160.mp4 || return 1
    mv keep.seg s0.mp4.seg
    # a gap in the ticks
    bad_join 1 ticks "s160.mp4: ticks 160..239, expected to start at 70" s0.mp4 s160.mp4 || return 1
    # and an overlap: a segment given twice starts before the one before it ends
    bad_join 2 ticks "s70.mp4: ticks 70..159, expected to start at 160" s0.mp4 s70.mp4 s70.mp4 || return 1
    # the first does not start at --first
    "$RS_BIN" join --segment job7 -o jx.mp4 --first 70 -q s70.mp4 s160.mp4 || { echo "--first 70 refused"; return 1; }
    [ "$(pts_ticks jx.mp4 | head -1)" = 0 ] && [ "$(pts_ticks jx.mp4 | wc -l)" = 170 ] || { echo "--first 70: wrong timestamps"; return 1; }
    rm jx.mp4
    # a hash list edited
    cp s70.hashes keep.hashes
    sed -i '3s/ [0-9a-f]*$/ 0123456789abcdef/' s70.hashes
    bad_join 1 hashes "s70.hashes: its FNV-1a is [0-9a-f]+, the manifest says" s0.mp4 s70.mp4 s160.mp4 || return 1
    head -5 keep.hashes >s70.hashes
    bad_join 1 hashes "s70.hashes: 5 lines, expected 90" s0.mp4 s70.mp4 s160.mp4 || return 1
    cp keep.hashes s70.hashes
    # a manifest that is not one
    echo "hello" >>s0.mp4.seg
    bad_join 0 manifest "s0.mp4.seg: has text after the 'replay' line" s0.mp4 s70.mp4 s160.mp4 || return 1
    # two bad at once: both named, in order
    cp "$FIX/mp4/s0.mp4.seg" .
    rm s160.mp4
    head -c 100 keep.mp4 >s70.mp4
    "$RS_BIN" join --segment job7 -o jx.mp4 --progress-fd 3 s0.mp4 s70.mp4 s160.mp4 3>bad.txt 2>err.txt
    [ $? = 3 ] || { echo "want exit 3"; cat err.txt; return 1; }
    [ "$(cut -d' ' -f1-3 bad.txt | tr '\n' ' ')" = "bad 1 size bad 2 missing " ] || { cat bad.txt; return 1; }
    nothing_left jx
}

t_output_failures_exit_1() {
    copy_mp4 || return 1
    set -- s0.mp4 s70.mp4 s160.mp4
    # the output directory is gone
    expect_fail 1 "^ringside join: gone/jx.mp4: folder gone does not exist$" \
        "$RS_BIN" join --segment job7 -o gone/jx.mp4 --hashes gone/jx.hashes "$@" || return 1
    [ ! -e gone ] || { echo "join made the vanished directory"; return 1; }
    # a directory in the output's place: refused before anything is written, not even the hash list
    mkdir jx.mp4
    expect_fail 1 "^ringside join: jx.mp4: exists and is not a regular file$" "$RS_BIN" join --segment job7 -y -o jx.mp4 --hashes jx.hashes "$@" ||
        return 1
    rmdir jx.mp4
    nothing_left jx || return 1
    # disk full (a file-size limit): the index rewrite at the end cannot grow the file
    ( trap '' XFSZ; export ASAN_OPTIONS=detect_leaks=0; ulimit -f 16; exec "$RS_BIN" join --segment job7 -o jx.mp4 --hashes jx.hashes "$@" ) 2>err.txt
    [ $? = 1 ] || { echo "want exit 1"; cat err.txt; return 1; }
    grep -q "jx.mp4: write failed: File too large" err.txt || { cat err.txt; return 1; }
    nothing_left jx || return 1
    # a read-only directory (root writes anyway: then there is nothing to test)
    mkdir ro && chmod 555 ro
    if ! touch ro/probe 2>/dev/null; then
        expect_fail 1 "ro/jx.mp4: cannot create (as ro/jx.mp4.part): Permission denied" "$RS_BIN" join --segment job7 -o ro/jx.mp4 "$@" || return 1
    fi
    rm -rf ro
    # usage errors
    expect_fail 2 "--segment KEY is required" "$RS_BIN" join -o jx.mp4 "$@" || return 1
    expect_fail 2 "--segment 'a b': expected a key" "$RS_BIN" join --segment 'a b' -o jx.mp4 "$@" || return 1
    expect_fail 2 "-o jx.avi: expected .mp4, .mkv or .webm" "$RS_BIN" join --segment job7 -o jx.avi "$@" || return 1
    expect_fail 2 "no segments given" "$RS_BIN" join --segment job7 -o jx.mp4 || return 1
    nothing_left jx
}

t_segment_render_rules() {
    expect_fail 2 "--segment writes .mp4, .mkv or .webm, not x.y4m" "$RS_BIN" render "$DOJO" --segment k -o x.y4m || return 1
    expect_fail 2 "--segment 'a/b': expected a key" "$RS_BIN" render "$DOJO" --segment a/b -o x.mp4 || return 1
    expect_fail 2 "--hashes must be x.hashes \(where join looks for it\), not x.txt" \
        "$RS_BIN" render "$DOJO" --segment k -o x.mp4 --hashes x.txt || return 1
    "$RS_BIN" render "$DOJO" --ticks 10:20 $TINY -q --segment k -o x.mp4 --hashes x.hashes || return 1
    [ -e x.mp4.seg ] && [ "$(wc -l <x.hashes)" = 10 ] && [ "$(head -c 3 x.hashes)" = "10 " ] || { ls; return 1; }
    # a render over it that fails (disk full) takes the old manifest with it: the old
    # files no longer say "complete", and nothing new appears
    ( trap '' XFSZ; export ASAN_OPTIONS=detect_leaks=0; ulimit -f 1; exec "$RS_BIN" render "$DOJO" --ticks 10:30 $TINY -q \
        --segment k -y -o x.mp4 --hashes x.hashes ) 2>err.txt
    [ $? = 1 ] || { echo "want exit 1"; cat err.txt; return 1; }
    grep -q "x.mp4" err.txt || { cat err.txt; return 1; }
    [ ! -e x.mp4.seg ] && [ ! -e x.mp4.part ] && [ ! -e x.hashes.part ] || { echo "left behind:"; ls; return 1; }
    expect_fail 3 "x.mp4: no manifest x.mp4.seg" "$RS_BIN" join --segment k -o y.mp4 --first 10 x.mp4
}

# render --hls-dir: the pieces a service streams while a job renders
# (capture/cap_hls.h).  Two segments with their pieces put back to back
# play as the joined video; a whole render's playlist plays as the video;
# a unit's pieces never change once indexed, unless they went bad.
hls_playlist() { # DIR UNIT... -> an HLS playlist of those units' pieces
    d=$1
    shift
    printf '#EXTM3U\n#EXT-X-VERSION:7\n#EXT-X-TARGETDURATION:2\n#EXT-X-PLAYLIST-TYPE:EVENT\n'
    for u in "$@"; do
        awk -v d="$d" '$1 == "piece" { printf "#EXTINF:%.6f,\n%s/t%d.ts\n", $3 / 60, d, $2 }' "$d/u$u.idx"
    done
    printf '#EXT-X-ENDLIST\n'
}
t_hls_pieces() {
    # a short match: its whole track (made once per folder) is quick to make
    "$RS_BIN" record --ai --quiet --seconds 5 --seed 8 -o m.rsr || return 1
    for r in 0:150 150:240; do
        "$RS_BIN" render m.rsr --ticks "$r" $TINY -q --segment job7 -o "s${r%:*}.mp4" --hashes "s${r%:*}.hashes" \
            --hls-dir hls || { echo "segment $r with --hls-dir failed"; return 1; }
    done
    # pieces at the keyframes: 0 and 120 in the first unit (every 120 frames), 150 in the second
    [ "$(grep -h '^piece' hls/u0.idx hls/u150.idx | cut -d' ' -f2,3 | tr '\n' ' ')" = "0 120 120 30 150 90 " ] ||
        { cat hls/u0.idx hls/u150.idx; return 1; }
    [ -s hls/track.0.ts ] && [ ! -e hls/track.1.ts ] || { echo "not one part of track"; ls hls; return 1; }
    "$RS_BIN" join --segment job7 -y -q -o joined.mp4 --replay m.rsr s0.mp4 s150.mp4 || return 1
    hls_playlist hls 0 150 >live.m3u8
    [ "$(vframes joined.mp4 | wc -l)" = 240 ] && [ "$(vframes joined.mp4 | md5sum)" = "$(vframes live.m3u8 | md5sum)" ] ||
        { echo "the pieces are not the joined video's frames"; return 1; }
    # the pieces have the sound of their time: 4 s is 187.5 AAC frames
    n=$(ffprobe -v error -count_packets -select_streams a -show_entries stream=nb_read_packets -of csv=p=0 live.m3u8 | grep -m1 .)
    [ "$n" -ge 186 ] && [ "$n" -le 190 ] || { echo "$n audio packets for 4 s (about 188)"; return 1; }
    for p in hls/t*.ts; do
        case $p in hls/track.*) continue ;; esac
        ffprobe -v error -show_entries stream=codec_name -of csv=p=0 "$p" | tr '\n' ' ' | grep -q "h264 aac" ||
            { echo "$p: not H.264 and AAC"; return 1; }
    done
    # indexed pieces stay: the same unit drawn again (other bytes: --crf 30) keeps them
    sum=$(cat hls/t0.ts hls/t120.ts | md5sum)
    "$RS_BIN" render m.rsr --ticks 0:150 $TINY -q -y --crf 30 --segment job7 -o s0b.mp4 --hashes s0b.hashes --hls-dir hls || return 1
    [ "$(cat hls/t0.ts hls/t120.ts | md5sum)" = "$sum" ] || { echo "a listed unit's pieces changed"; return 1; }
    # ... unless one went bad: then the unit is cut again
    printf x >>hls/t120.ts
    "$RS_BIN" render m.rsr --ticks 0:150 $TINY -q -y --crf 30 --segment job7 -o s0b.mp4 --hashes s0b.hashes --hls-dir hls || return 1
    [ "$(cat hls/t0.ts hls/t120.ts | md5sum)" != "$sum" ] && grep -q "^piece 120 30 $(stat -c %s hls/t120.ts) " hls/u0.idx ||
        { echo "a damaged piece was not cut again"; return 1; }
    # a whole render (its pts from 0 at its first tick) writes its own finished
    # playlist; --audio off: pieces without sound, and no track made
    "$RS_BIN" render m.rsr --ticks 60:200 $TINY -q -o whole.mp4 --audio off --hls-dir w || return 1
    grep -q '^#EXT-X-ENDLIST' w/stream.m3u8 && [ "$(grep -c '^t' w/stream.m3u8)" = 2 ] && grep -q '^t180.ts' w/stream.m3u8 ||
        { cat w/stream.m3u8; return 1; }
    [ "$(vframes whole.mp4 | md5sum)" = "$(vframes w/stream.m3u8 | md5sum)" ] || { echo "the whole render's stream is not its frames"; return 1; }
    [ ! -e w/track.0.ts ] && [ -z "$(ffprobe -v error -select_streams a -show_entries stream=codec_name -of csv=p=0 w/t60.ts)" ] ||
        { echo "--audio off made a track or sound"; return 1; }
    # what has no HLS pieces is refused before any work
    for o in "x.webm" "x.mkv --codec vp9" "x.y4m"; do
        "$RS_BIN" render m.rsr --ticks 0:10 $TINY -q -o $o --hls-dir h2 2>err.txt
        [ $? = 2 ] && grep -q "HLS pieces are H.264 or HEVC" err.txt && [ ! -e h2 ] || { echo "-o $o"; cat err.txt; return 1; }
    done
}

# The track in parts of 10 s: a unit's pieces wait for the parts of their
# own time, and a segment's render ends then, leaving the rest of the track
# to its maker; a piece across two parts has the sound of both; a render
# whose maker died says so instead of waiting.
aac_packets() { ffprobe -v error -count_packets -select_streams a -show_entries stream=nb_read_packets -of csv=p=0 "$1" | grep -m1 .; }
t_hls_track_parts() {
    "$RS_BIN" record --ai --quiet --seconds 120 --seed 8 -o m.rsr || return 1
    "$RS_BIN" render m.rsr --ticks 0:60 $TINY -q --segment j --hls-dir h -o s0.mp4 || return 1
    # 12 parts; the encoding of the other 110 s goes on after the render
    [ -s h/track.0.ts ] && [ ! -e h/track.11.ts ] || { echo "the render waited for the whole track"; ls h; return 1; }
    n=$(aac_packets h/t0.ts)
    [ "$n" -ge 46 ] && [ "$n" -le 48 ] || { echo "$n audio packets in 1 s (about 47)"; return 1; }
    # ticks 570..689 take the end of part 0 and the start of part 1
    "$RS_BIN" render m.rsr --ticks 570:690 $TINY -q --segment j --hls-dir h -o s570.mp4 || return 1
    n=$(aac_packets h/t570.ts)
    [ "$n" -ge 92 ] && [ "$n" -le 95 ] || { echo "$n audio packets in 2 s across two parts (about 94)"; return 1; }
    i=0
    while [ ! -e h/track.11.ts ] && [ $i -lt 300 ]; do sleep 0.1; i=$((i + 1)); done
    [ -e h/track.11.ts ] && [ ! -e h/track.12.ts ] || { echo "the track was not finished in the background"; ls h; return 1; }
    sleep 0.2
    [ -z "$(find h -name '.track.*.part')" ] || { echo "temporaries left:"; ls -a h; return 1; }
    # a maker killed before the frames are done: the cut says so and exits 1
    ( export ASAN_OPTIONS=detect_leaks=0; exec "$RS_BIN" render m.rsr --ticks 0:60 $TINY -q --segment j --hls-dir h2 -o k.mp4 ) 2>err.txt &
    rpid=$!
    t0=$(date +%s)
    i=0
    while [ -z "$(pgrep -P $rpid)" ] && [ $i -lt 100 ]; do sleep 0.02; i=$((i + 1)); done
    kill -9 $(pgrep -P $rpid) 2>/dev/null
    wait $rpid
    st=$?
    [ $(($(date +%s) - t0)) -le 15 ] || { echo "the render waited $(($(date +%s) - t0)) s for a dead maker"; return 1; }
    [ $st = 1 ] && grep -q "h2/track.0.ts: missing, and no process is making the match's sound" err.txt ||
        { echo "exit $st with the maker killed"; cat err.txt; return 1; }
}

t_help() {
    "$RS_BIN" render --help >h.txt && grep -q -- "--segment KEY" h.txt || { echo "render --help lacks --segment"; return 1; }
    "$RS_BIN" join --help >h.txt || return 1
    for w in --segment --hashes --first --progress-fd "bad INDEX REASON" "3 one or more segments are bad"; do
        grep -q -- "$w" h.txt || { echo "join --help lacks '$w'"; return 1; }
    done
    "$RS_BIN" --help | grep -q "^  join " || { echo "ringside --help does not list join"; return 1; }
}

t_run mp4_segments_join_to_the_single_render mkv_and_webm bad_segments_exit_3 output_failures_exit_1 segment_render_rules \
    hls_pieces hls_track_parts help
t_done
