#!/bin/sh
# End-to-end: the command-line conventions users' tools expect (README.md and the man pages):
# `-o -` streams (Y4M, NUT, Matroska) and nothing else reaches stdout;
# `-` for text outputs; ffmpeg's overwrite rules (-y / -n) on every kind of
# output; a missing folder named, never created; extensions in any case;
# progress lines off a terminal (--progress plain, the default there).
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
S="--size 64x36 --render-size 128x72 --ticks 0:12"

replay() { # 60 ticks on the dojo
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 5 -o r.rsr 2>/dev/null
}

need_ffprobe() {
    command -v ffprobe >/dev/null 2>&1 || t_skip_install "no ffprobe"
}

# frames FORMAT FILE: the frames ffprobe decodes, and the codec ("h264 12")
frames() {
    ffprobe -v error -f "$1" -count_frames -select_streams v:0 \
        -show_entries stream=codec_name,nb_read_frames -of default=nw=1:nk=1 -i "$2" | tr '\n' ' ' | sed 's/ $//'
}

t_stream_y4m_by_default() {
    need_ffprobe
    replay || return 1
    "$RS_BIN" render r.rsr $S -q -o - >s.y4m 2>e.txt || { cat e.txt; return 1; }
    got=$(frames yuv4mpegpipe s.y4m)
    [ "$got" = "rawvideo 12" ] || { echo "stdout: $got"; cat e.txt; return 1; }
    # the same bytes as a file, and through a real pipe
    "$RS_BIN" render r.rsr $S -q -o f.y4m || return 1
    cmp s.y4m f.y4m || return 1
    n=$("$RS_BIN" render r.rsr $S -q -o - | ffprobe -v error -count_frames -show_entries stream=nb_read_frames \
        -of default=nw=1:nk=1 -i -)
    [ "$n" = 12 ] || { echo "ffprobe on the pipe: '$n'"; return 1; }
}

t_stream_nut_and_mkv() {
    need_ffprobe
    replay || return 1
    for f in nut mkv; do
        "$RS_BIN" render r.rsr $S -q -o - --format $f 2>e.txt | cat >s.$f || { cat e.txt; return 1; }
        [ -s s.$f ] || { echo "$f: nothing on stdout"; cat e.txt; return 1; }
        ff=$f; [ $f = mkv ] && ff=matroska
        got=$(frames $ff s.$f)
        [ "$got" = "h264 12" ] || { echo "$f: $got"; cat e.txt; return 1; }
    done
    ls | grep -q part && { echo "a .part was left:"; ls; return 1; }
    # --format names the container where the name does not
    "$RS_BIN" render r.rsr $S -q -o clip.video --format mkv || return 1
    [ "$(frames matroska clip.video)" = "h264 12" ] || return 1
    expect_fail 2 "MP4 cannot be written to a pipe .*use --format mkv" "$RS_BIN" render r.rsr $S -q -o - --format mp4 || return 1
    [ ! -s out.txt ] || { echo "bytes on stdout after the refusal"; return 1; }
    expect_fail 2 "--format 'avi': expected y4m, nut, mkv, mp4 or webm" "$RS_BIN" render r.rsr $S -o - --format avi
}

t_stdout_holds_only_the_stream() {
    replay || return 1
    # progress (plain, fast), the summary, --passes: all on stderr
    RS_PROGRESS_INTERVAL=0 "$RS_BIN" render r.rsr $S --passes -o - >s.y4m 2>e.txt || { cat e.txt; return 1; }
    "$RS_BIN" render r.rsr $S -q -o f.y4m || return 1
    cmp s.y4m f.y4m || { echo "stdout is not just the stream"; head -c 300 s.y4m | od -c | head; return 1; }
    grep -q "wrote -: 12 frames" e.txt || { cat e.txt; return 1; }
    # a file output leaves stdout empty
    RS_PROGRESS_INTERVAL=0 "$RS_BIN" render r.rsr $S -o g.y4m >o.txt 2>e.txt || { cat e.txt; return 1; }
    [ ! -s o.txt ] || { echo "stdout:"; cat o.txt; return 1; }
}

t_overwrite_video() {
    replay || return 1
    "$RS_BIN" render r.rsr $S -q -o a.mp4 || return 1
    sum=$(cksum <a.mp4)
    for flags in "" -n --no-overwrite "-y -n"; do
        expect_fail 1 "^ringside render: a.mp4: exists \(use -y to overwrite\)$" "$RS_BIN" render r.rsr $S -q $flags -o a.mp4 ||
            return 1
        [ "$(wc -l <err.txt)" = 1 ] || { echo "more than one line:"; cat err.txt; return 1; }
        [ "$(cksum <a.mp4)" = "$sum" ] || { echo "a.mp4 touched ($flags)"; return 1; }
    done
    # -y replaces it: a shorter render, a different file
    "$RS_BIN" render r.rsr --size 64x36 --render-size 128x72 --ticks 0:6 -q -y -o a.mp4 || return 1
    [ "$(cksum <a.mp4)" != "$sum" ] || { echo "-y did not replace a.mp4"; return 1; }
    "$RS_BIN" render r.rsr $S -q --overwrite -o a.mp4 || return 1
    # devices are never "existing"
    "$RS_BIN" render r.rsr $S -q -o /dev/null || return 1
}

t_overwrite_images_and_hashes() {
    replay || return 1
    "$RS_BIN" render r.rsr $S -q -o f%04d.png --hashes h.txt || return 1
    # any one frame of the range that exists is refused, and nothing is written
    rm f00*.png h.txt
    : >f0007.png
    expect_fail 1 "^ringside render: f0007.png: exists \(use -y to overwrite\)$" "$RS_BIN" render r.rsr $S -q -o f%04d.png ||
        return 1
    [ "$(ls f*.png)" = f0007.png ] || { echo "frames written:"; ls; return 1; }
    "$RS_BIN" render r.rsr $S -q -y -o f%04d.png || return 1
    [ "$(ls f*.png | wc -l)" = 12 ] || return 1
    # --hashes is an output too: checked before the video is touched
    echo keep >h.txt
    expect_fail 1 "h.txt: exists \(use -y to overwrite\)" "$RS_BIN" render r.rsr $S -q -o v.y4m --hashes h.txt || return 1
    [ ! -e v.y4m ] && [ "$(cat h.txt)" = keep ] || { echo "touched on refusal"; return 1; }
    "$RS_BIN" render r.rsr $S -q -o v.y4m --hashes h.txt -y || return 1
    [ "$(wc -l <h.txt)" = 12 ] || return 1
    # movie --hashes and record -o follow the same rules
    echo keep >m.txt
    expect_fail 1 "m.txt: exists \(use -y to overwrite\)" "$RS_BIN" movie v.y4m --hashes m.txt -q || return 1
    "$RS_BIN" movie v.y4m --hashes m.txt -q -y || return 1
    [ "$(wc -l <m.txt)" -ge 12 ] || return 1
    expect_fail 1 "r.rsr: exists \(use -y to overwrite\)" "$RS_BIN" record --ai --quiet --seconds 1 -o r.rsr || return 1
    "$RS_BIN" record --ai --quiet --seconds 1 -y -o r.rsr 2>/dev/null || return 1
}

t_extensions_any_case() {
    need_ffprobe
    replay || return 1
    "$RS_BIN" render r.rsr $S -q -o z.MP4 || return 1
    [ "$(frames mov,mp4,m4a,3gp,3g2,mj2 z.MP4)" = "h264 12" ] || return 1
    "$RS_BIN" render r.rsr $S -q -o z.Y4M || return 1
    [ "$(head -c 9 z.Y4M)" = YUV4MPEG2 ] || return 1
    "$RS_BIN" render r.rsr $S -q -o F%04d.PNG || return 1
    [ "$(head -c 8 F0011.PNG | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || { echo "not a PNG"; return 1; }
    expect_fail 2 "^ringside render: f.png: a single image name; use a pattern such as f%06d.png$" \
        "$RS_BIN" render r.rsr $S -q -o f.png || return 1
    expect_fail 2 "shot.TIF: a single image name; use a pattern such as shot%06d.TIF" "$RS_BIN" render r.rsr $S -q -o shot.TIF
}

t_missing_folder_named() {
    replay || return 1
    expect_fail 1 "^ringside render: nodir/x.mp4: folder nodir does not exist$" "$RS_BIN" render r.rsr $S -q -o nodir/x.mp4 ||
        return 1
    expect_fail 1 "nodir/f0000.png: folder nodir does not exist" "$RS_BIN" render r.rsr $S -q -o nodir/f%04d.png || return 1
    expect_fail 1 "nodir/h.txt: folder nodir does not exist" "$RS_BIN" render r.rsr $S -q -o x.y4m --hashes nodir/h.txt ||
        return 1
    expect_fail 1 "a/b/r.rsr: folder a/b does not exist" "$RS_BIN" record --ai --quiet --seconds 1 -o a/b/r.rsr || return 1
    [ ! -e nodir ] && [ ! -e a ] && [ ! -e x.y4m ] || { echo "created:"; ls; return 1; }
    # with the folder there, the same commands work
    mkdir nodir && "$RS_BIN" render r.rsr $S -q -o nodir/f%04d.png || return 1
}

t_text_outputs_take_dash() {
    replay || return 1
    "$RS_BIN" render r.rsr $S -q -o /dev/null --hashes h.txt || return 1
    "$RS_BIN" render r.rsr $S -q -o v.y4m --hashes - >o.txt || return 1
    cmp o.txt h.txt || { echo "--hashes - differs from --hashes FILE"; return 1; }
    [ ! -e ./- ] || { echo "a file named '-'"; return 1; }
    expect_fail 2 "-o - and --hashes - both write to standard output" "$RS_BIN" render r.rsr $S -o - --hashes - || return 1
    "$RS_BIN" movie v.y4m --hashes - -q >m.txt || return 1
    [ "$(wc -l <m.txt)" -ge 12 ] && [ ! -e ./- ] || { cat m.txt; return 1; }
    "$RS_BIN" replay verify r.rsr --hashes - -q >v.txt 2>/dev/null || return 1
    [ "$(wc -l <v.txt)" = 60 ] || return 1
}

t_progress_plain_off_a_terminal() {
    replay || return 1
    # stderr is a file here: plain lines, the last one at 100%
    RS_PROGRESS_INTERVAL=0 "$RS_BIN" render r.rsr $S -o a.y4m 2>e.txt || { cat e.txt; return 1; }
    pat='^ringside render: [0-9]+/12 frames \([0-9]+%\), [0-9.]+ fps, [0-9.]+x, elapsed [0-9]+:[0-9][0-9], ETA [0-9]+:[0-9][0-9]$'
    [ "$(grep -Ec "$pat" e.txt)" -ge 2 ] || { echo "want plain lines:"; cat e.txt; return 1; }
    grep -E "$pat" e.txt | tail -1 | grep -q "12/12 frames (100%)" || { cat e.txt; return 1; }
    # speed is x real time: frames per second / 60
    grep -E "$pat" e.txt | tail -1 | tr -d ',x' |
        awk '{ fps = $6; x = $8; if (fps <= 0 || x - fps / 60 > 0.006 || fps / 60 - x > 0.006) exit 1 }' ||
        { echo "speed is not fps / 60:"; grep -E "$pat" e.txt | tail -1; return 1; }
    grep -q "$(printf '\r')" e.txt && { echo "a tty redraw in a log"; return 1; }
    # the default interval (5 s) gives only the last line on a short run
    "$RS_BIN" render r.rsr $S -y -o a.y4m 2>e.txt || return 1
    [ "$(grep -Ec "$pat" e.txt)" = 1 ] || { cat e.txt; return 1; }
    for off in "--progress off" --quiet; do
        RS_PROGRESS_INTERVAL=0 "$RS_BIN" render r.rsr $S -y $off -o a.y4m 2>e.txt || return 1
        grep -q "frames (" e.txt && { echo "$off printed progress:"; cat e.txt; return 1; }
    done
    # --progress tty forces the redrawn line, with speed and elapsed time
    "$RS_BIN" render r.rsr $S -y --progress tty -o a.y4m 2>e.txt || return 1
    grep -q "$(printf '\r')render: 12 / 12 frames (100%) .*x  elapsed 0:0" e.txt || { cat -v e.txt; return 1; }
    # the other commands with a progress line
    RS_PROGRESS_INTERVAL=0 "$RS_BIN" replay verify r.rsr 2>v.txt || return 1
    grep -Eq "^ringside verify: 60/60 ticks \(100%\), [0-9.]+ ticks/s, [0-9.]+x" v.txt || { cat v.txt; return 1; }
    expect_fail 2 "--progress 'loud': expected tty, plain or off" "$RS_BIN" render r.rsr $S --progress loud -o b.y4m
}

t_help_names_the_conventions() {
    "$RS_BIN" render --help >h.txt || return 1
    for w in "-y, --overwrite" "-n, --no-overwrite" "--format F" "--progress MODE" "or '-': a" "never asks"; do
        grep -q -- "$w" h.txt || { echo "render --help lacks '$w'"; return 1; }
    done
    for c in join record movie; do
        "$RS_BIN" $c --help | grep -q -- "-y" || { echo "$c --help lacks -y"; return 1; }
    done
}

t_run stream_y4m_by_default stream_nut_and_mkv stdout_holds_only_the_stream overwrite_video \
    overwrite_images_and_hashes extensions_any_case missing_folder_named text_outputs_take_dash \
    progress_plain_off_a_terminal help_names_the_conventions
t_done
