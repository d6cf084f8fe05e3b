#!/bin/sh
# End-to-end: the smoke picture as a PNG file at 1280x720, read back by an
# independent decoder (FFmpeg's, not libpng) to the pixels of the PPM that
# rs_img writes by hand.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"

t_png_1280x720_compressed() {
    command -v ffmpeg >/dev/null 2>&1 || t_skip_install "no ffmpeg (tools/deps.sh test)"
    "$RS_BIN" smoke --size 1280x720 -o x.png 2>e.txt || { cat e.txt; return 1; }
    "$RS_BIN" smoke --size 1280x720 -o x.ppm 2>e.txt || { cat e.txt; return 1; }
    size=$(wc -c <x.png)
    [ "$size" -lt 1000000 ] || { echo "x.png is $size bytes (want well under 1 MB)"; return 1; }
    ffmpeg -v error -i x.png -f rawvideo -pix_fmt rgb24 png.rgb || return 1
    tail -c $((1280 * 720 * 3)) x.ppm >ppm.rgb
    [ "$(wc -c <png.rgb)" = $((1280 * 720 * 3)) ] || { echo "ffmpeg decoded $(wc -c <png.rgb) bytes"; return 1; }
    cmp png.rgb ppm.rgb || { echo "x.png decodes to other pixels than x.ppm holds"; return 1; }
}

t_run png_1280x720_compressed
t_done
