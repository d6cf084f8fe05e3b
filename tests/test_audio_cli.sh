#!/bin/sh
# End-to-end: `replay sound` and `replay events` through the real binary:
# the WAV's format and length, a range equal to that slice of the whole,
# loudness as ffmpeg measures it, stdout, the cue listing, and the errors.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
DEMO=$SRC/demos/temple.rsr

short_replay() { # 1200 ticks on the dojo, CPU against CPU
    "$RS_BIN" record --ai --quiet --seconds 20 --seed 21 -o short.rsr 2>/dev/null
}

probe() { # FILE -> "codec rate channels samples"
    ffprobe -v error -select_streams a:0 -count_packets -show_entries stream=codec_name,sample_rate,channels,duration_ts \
        -of csv=p=0 "$1" | tr ',' ' '
}

t_sound_wav_and_its_slices() {
    short_replay || return 1
    "$RS_BIN" replay sound short.rsr -o all.wav 2>all.txt || { cat all.txt; return 1; }
    "$RS_BIN" replay sound short.rsr -o part.wav --ticks 600:660 2>part.txt || { cat part.txt; return 1; }
    set -- $(probe part.wav)
    [ "$1 $2 $3 $4" = "pcm_s16le 48000 2 48000" ] || { echo "part.wav: $*"; return 1; }
    set -- $(probe all.wav)
    [ "$4" = $((1200 * 800)) ] || { echo "all.wav: $* (want 1200 ticks x 800 frames)"; return 1; }
    # ticks 600..659 are bytes 600*800*4.. of the whole track's samples
    tail -c +$((44 + 600 * 800 * 4 + 1)) all.wav | head -c $((60 * 800 * 4)) >slice.raw
    tail -c +45 part.wav >part.raw
    cmp slice.raw part.raw || { echo "ticks 600:660 differ from that slice of the whole"; return 1; }
    # float, and standard output, give the same samples as the file
    "$RS_BIN" replay sound short.rsr -o f.wav --ticks 600:660 --float 2>/dev/null || return 1
    set -- $(probe f.wav)
    [ "$1" = pcm_f32le ] || { echo "f.wav: $*"; return 1; }
    "$RS_BIN" replay sound short.rsr -o - --ticks 600:660 >stdout.wav 2>/dev/null || return 1
    cmp stdout.wav part.wav || { echo "-o - differs from the file"; return 1; }
    grep -q "ticks 600:660, 48000 frames; match .* -> -16.0 LUFS" part.txt || { cat part.txt; return 1; }
}

# Loudness as another meter measures it: ffmpeg's ebur128 filter (its own
# BS.1770 code, not the libebur128 we normalize with) on the 16-bit WAV, to
# a thousandth of a LU (its metadata; the summary rounds to 0.1).  The
# integrated loudness within 0.2 LU of the target and of what we report;
# the true peak within 0.2 dB of ours and under the -1 dBTP ceiling, and at
# the default target, where temple's peaks need the limiter (which aims 0.2
# dB under the ceiling), over -1.45 dBTP.  A target or a ceiling 0.5 dB off
# fails.  Measured: -16.01 LUFS -1.20 dBTP, -23.00 LUFS -5.7 dBTP.
t_sound_loudness_measured_by_ffmpeg() {
    "$RS_BIN" replay sound "$DEMO" -o a.wav 2>a.txt || { cat a.txt; return 1; }
    "$RS_BIN" replay sound "$DEMO" -o b.wav --loudness -23 2>b.txt || { cat b.txt; return 1; }
    for f in a:-16:limited b:-23:free; do
        set -- $(echo "$f" | tr : ' ')
        ffmpeg -hide_banner -nostats -loglevel error -i "$1.wav" \
            -af "ebur128=peak=true:metadata=1,ametadata=mode=print:file=$1.meta" -f null - || return 1
        # ours, from "... -> -16.0 LUFS -1.2 dBTP (gain +2.5 dB)"
        ours=$(sed -n 's/.* -> \(-[0-9.]*\) LUFS \(-[0-9.]*\) dBTP.*/\1 \2/p' "$1.txt")
        [ -n "$ours" ] || { cat "$1.txt"; return 1; }
        awk -F= -v want="$2" -v mode="$3" -v ours="$ours" '
            $1 == "lavfi.r128.I" { i = $2 }
            $1 ~ /^lavfi\.r128\.true_peaks_ch/ && $2 > p { p = $2 }
            function off(a, b) { return a > b ? a - b : b - a }
            END {
                split(ours, o, " "); tp = 20 * log(p) / log(10)
                printf "    target %s: ffmpeg %.3f LUFS %.2f dBTP; ours %s LUFS %s dBTP\n", want, i, tp, o[1], o[2]
                if (i == "" || off(i, want) > 0.2) { print "integrated " i " LUFS, the target " want; exit 1 }
                if (off(i, o[1]) > 0.2) { print "ffmpeg says " i " LUFS, we said " o[1]; exit 1 }
                if (off(tp, o[2]) > 0.2) { printf "ffmpeg says %.2f dBTP, we said %s\n", tp, o[2]; exit 1 }
                if (tp > -1.0) { printf "true peak %.2f dBTP over the -1 dBTP ceiling\n", tp; exit 1 }
                if (mode == "limited" && tp < -1.45) { printf "true peak %.2f dBTP: the limiter held it too low\n", tp; exit 1 }
            }' "$1.meta" || return 1
    done
    "$RS_BIN" replay sound "$DEMO" -o c.wav --loudness off --ticks 0:60 2>c.txt || return 1
    grep -q "not normalized" c.txt || { cat c.txt; return 1; }
}

# The track is streamed: a match 9 times longer peaks within 10% of the
# same resident memory (it grew by 1.2 MB a second of match when the track
# was held whole: 167 MB for 1 minute, 876 MB for 10)
t_sound_memory_is_flat() {
    [ -x /usr/bin/time ] || { t_skip_install "no /usr/bin/time (Debian package time)"; return; }
    "$RS_BIN" record --ai --quiet --seconds 20 --seed 5 -o m1.rsr 2>/dev/null &&
        "$RS_BIN" record --ai --quiet --seconds 180 --seed 5 -o m9.rsr 2>/dev/null || return 1
    for m in m1 m9; do
        /usr/bin/time -f %M -o $m.rss "$RS_BIN" replay sound $m.rsr -o /dev/null -y 2>/dev/null || return 1
    done
    awk -v a="$(cat m1.rss)" -v b="$(cat m9.rss)" 'BEGIN { printf "    replay sound peak RSS: 20 s %d kB, 180 s %d kB\n", a, b;
        exit !(b <= a * 1.10) }'
}

t_events_list_the_cues() {
    "$RS_BIN" replay events "$DEMO" --ticks 0:900 >e.txt 2>err.txt || { cat err.txt; return 1; }
    grep -q '^0 voice_round1 +0.00 1.00 \[round\]$' e.txt || { head -3 e.txt; return 1; }
    grep -q '^59 bell ' e.txt && grep -q '^59 voice_fight ' e.txt || { grep '^59 ' e.txt; return 1; }
    # every hit sound is on a tick with a hit event; none past the range
    awk '$2 ~ /^hit_/ && !/\[.*hit.*\]/ { print; bad = 1 } $1 >= 900 { print; bad = 1 } END { exit bad }' e.txt ||
        return 1
    grep -q ' hit_' e.txt || { echo "no hit in ticks 0..899"; return 1; }
    "$RS_BIN" replay events "$DEMO" --ticks 600:660 >f.txt || return 1
    awk '$1 < 600 || $1 >= 660 { exit 1 }' f.txt || { cat f.txt; return 1; }
}

t_errors() {
    expect_fail 2 "sound needs -o OUT.wav" "$RS_BIN" replay sound "$DEMO" || return 1
    : >exists.wav
    expect_fail 1 "exists.wav: exists \(use -y to overwrite\)" "$RS_BIN" replay sound "$DEMO" -o exists.wav || return 1
    expect_fail 1 "folder nowhere does not exist" "$RS_BIN" replay sound "$DEMO" -o nowhere/x.wav || return 1
    expect_fail 2 "--loudness 'loud': expected LUFS from -70 to 0, or off" \
        "$RS_BIN" replay sound "$DEMO" -o a.wav --loudness loud || return 1
    expect_fail 2 "--loudness '3'" "$RS_BIN" replay sound "$DEMO" -o a.wav --loudness 3 || return 1
    expect_fail 2 "--ticks '9:3': the end must be after the start" "$RS_BIN" replay sound "$DEMO" -o a.wav --ticks 9:3 ||
        return 1
    expect_fail 1 "past the replay's end \(2537 ticks\)" "$RS_BIN" replay sound "$DEMO" -o a.wav --ticks 0:3000 || return 1
    expect_fail 2 "belong to 'replay sound'" "$RS_BIN" replay info "$DEMO" --float || return 1
    expect_fail 2 "belong to 'replay sound'" "$RS_BIN" replay verify "$DEMO" -o a.wav || return 1
    printf 'RSRP broken' >bad.rsr
    expect_fail 1 "bad.rsr" "$RS_BIN" replay sound bad.rsr -o a.wav || return 1
    [ ! -e a.wav ] && [ ! -e a.wav.part ] || { echo "a refused run left a file"; return 1; }
}

t_run sound_wav_and_its_slices sound_loudness_measured_by_ffmpeg sound_memory_is_flat events_list_the_cues errors
t_done
