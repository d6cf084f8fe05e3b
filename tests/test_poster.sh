#!/bin/sh
# End-to-end: render --poster writes the chosen frame as a PNG of the
# output size, the same pixels as the video's frame there; with --ticks
# only the range holding it writes one; a missing folder is named.
# (tests/test_poster.c checks the choice itself.)
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
SIZES="--render-size 320x180 --size 160x90"
DOJO="$SRC/demos/dojo.rsr" # its poster frame: 4414, the last knock-out (test_poster.c prints it)

# "W H CHANNELS" and an md5 of the RGB pixels of a PNG
png_info() {
    python3 - "$1" <<'PY'
import sys, zlib, struct, hashlib
b = open(sys.argv[1], 'rb').read()
assert b[:8] == b'\x89PNG\r\n\x1a\n', 'not a PNG'
o, idat, w = 8, b'', 0
while o < len(b):
    n, t = struct.unpack('>I4s', b[o:o + 8])
    d = b[o + 8:o + 8 + n]
    if t == b'IHDR':
        w, h, depth, ct = struct.unpack('>IIBB', d[:10])
    if t == b'IDAT':
        idat += d
    o += 12 + n
ch = {2: 3, 6: 4}[ct]
raw, px, prev = zlib.decompress(idat), bytearray(), bytearray(w * ch)
row = w * ch + 1
for y in range(h):
    f, line = raw[y * row], bytearray(raw[y * row + 1:(y + 1) * row])
    for i in range(len(line)):
        a = line[i - ch] if i >= ch else 0
        c = prev[i - ch] if i >= ch else 0
        p = a + prev[i] - c
        pr = a if abs(p - a) <= abs(p - prev[i]) and abs(p - a) <= abs(p - c) else prev[i] if abs(p - prev[i]) <= abs(p - c) else c
        line[i] = (line[i] + [0, a, prev[i], (a + prev[i]) // 2, pr][f]) & 255
    prev = line
    px += b''.join(bytes(line[x * ch:x * ch + 3]) for x in range(w))
print(w, h, ch, hashlib.md5(px).hexdigest())
PY
}

t_poster_is_the_video_frame() {
    "$RS_BIN" render "$DOJO" --ticks 4412:4416 $SIZES --capture sequential --poster p.png -o a.y4m 2>e.txt ||
        { cat e.txt; return 1; }
    grep -q "poster p.png: frame 4414 (the last knock-out)" e.txt || { cat e.txt; return 1; }
    [ ! -e p.png.part ] || { echo "p.png.part left"; return 1; }
    set -- $(png_info p.png)
    [ "$1 $2 $3" = "160 90 3" ] || { echo "poster is $1x$2 with $3 channels, want 160x90 RGB"; return 1; }
    # the video's own frame 4414, as an image, through the same (CPU) downscale
    "$RS_BIN" render "$DOJO" --ticks 4414:4415 $SIZES --capture sequential -q -o 'f%04d.png' || return 1
    set -- "$4" $(png_info f4414.png)
    [ "$1" = "$5" ] || { echo "the poster differs from frame 4414 of the video"; return 1; }
}

t_only_the_range_holding_it_writes_it() {
    "$RS_BIN" render "$DOJO" --ticks 4400:4404 $SIZES --poster p.png -o a.y4m 2>e.txt || { cat e.txt; return 1; }
    [ ! -e p.png ] && [ ! -e p.png.part ] || { echo "a range without frame 4414 wrote a poster"; return 1; }
    # it says so, even with -q (a segment, whose skip is the plan, does not)
    grep -q "^ringside render: --poster p.png: not written: its frame, tick 4414 (.*), is outside --ticks 4400:4404$" e.txt ||
        { cat e.txt; return 1; }
    "$RS_BIN" render "$DOJO" --ticks 4400:4404 $SIZES --poster p.png -o b.y4m -q 2>q.txt || { cat q.txt; return 1; }
    grep -q "not written" q.txt || { cat q.txt; return 1; }
}

t_missing_folder_named() {
    expect_fail 1 "nodir/p.png: the folder nodir does not exist \\(--poster\\)" \
        "$RS_BIN" render "$DOJO" --ticks 4400:4404 $SIZES --poster nodir/p.png -o a.y4m || return 1
    [ ! -e a.y4m ] || { echo "the video was written anyway"; return 1; }
}

t_help_says_so() {
    "$RS_BIN" render --help >h.txt || return 1
    grep -q -- "--poster FILE.png" h.txt || { cat h.txt; return 1; }
    grep -q -- "--ticks, written only by the render whose range holds it" h.txt || { cat h.txt; return 1; }
}

# like every output (README, Conventions): an existing poster is refused
# without -y, naming it, and nothing is written; -y replaces it
t_existing_poster_needs_y() {
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 5 -o s.rsr || return 1
    "$RS_BIN" render s.rsr -q --size 64x36 --render-size 128x72 -o v.mp4 --poster p.png || return 1
    rm -f v.mp4
    "$RS_BIN" render s.rsr -q --size 64x36 --render-size 128x72 -o v.mp4 --poster p.png 2>err.txt &&
        { echo "an existing poster was overwritten without -y"; return 1; }
    grep -q "p.png: exists (use -y to overwrite)" err.txt || { cat err.txt; return 1; }
    [ ! -e v.mp4 ] || { echo "the video was written although the poster was refused"; return 1; }
    "$RS_BIN" render s.rsr -q -y --size 64x36 --render-size 128x72 -o v.mp4 --poster p.png || return 1
}

t_run existing_poster_needs_y poster_is_the_video_frame only_the_range_holding_it_writes_it missing_folder_named help_says_so
t_done
