#!/bin/sh
# End-to-end: the sound of ringside play.  Headless runs write what would
# have been played to a WAV; it must be the replay's own soundtrack (replay
# sound --loudness off) sample for sample.  Window runs (Xvfb) use OpenAL
# Soft's null driver, or none at all.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
REPLAY=$SRC/demos/harbor.rsr

# frames in a WAV (sox's soxi), and its RMS amplitude
wav_frames() { soxi -s "$1"; }
wav_rms() { sox "$1" -n stat 2>&1 | sed -n 's/^RMS *amplitude: *//p'; }

need_sox() { command -v sox >/dev/null || t_skip_install "sox not installed (tools/deps.sh test)"; }

t_headless_wav_length() {
    need_sox
    "$RS_BIN" play --headless --replay "$REPLAY" --seconds 2 --size 64x36 --audio-out a.wav 2>e.txt ||
        { cat e.txt; return 1; }
    grep -q "^ringside play: 120 ticks .*; audio: wav a.wav, [0-9.]* ms a tick" e.txt || { cat e.txt; return 1; }
    n=$(wav_frames a.wav)
    [ "$n" = $((120 * 800)) ] || { echo "a.wav: $n frames, want $((120 * 800))"; return 1; }
}

t_same_as_replay_sound() {
    need_sox
    "$RS_BIN" play --headless --replay "$REPLAY" --seconds 3 --size 64x36 --audio-out p.wav -q || return 1
    "$RS_BIN" replay sound "$REPLAY" --ticks 0:180 --loudness off -o r.wav 2>/dev/null || return 1
    cmp p.wav r.wav || { echo "play --audio-out and replay sound --loudness off differ"; return 1; }
    # and it is a soundtrack, not two equal silences
    rms=$(wav_rms p.wav)
    awk -v r="$rms" 'BEGIN { exit !(r > 0.01) }' || { echo "p.wav is near silent (RMS $rms)"; return 1; }
}

t_volume_scales() {
    need_sox
    "$RS_BIN" play --headless --replay "$REPLAY" --seconds 2 --size 64x36 --audio-out full.wav -q || return 1
    "$RS_BIN" play --headless --replay "$REPLAY" --seconds 2 --size 64x36 --audio-out half.wav --volume 0.5 -q ||
        return 1
    full=$(wav_rms full.wav) half=$(wav_rms half.wav)
    awk -v f="$full" -v h="$half" 'BEGIN { r = h / f; exit !(r > 0.499 && r < 0.501) }' ||
        { echo "RMS $half at --volume 0.5, $full at 1: not half"; return 1; }
}

t_mute_and_headless_are_silent() {
    "$RS_BIN" play --headless --replay "$REPLAY" --seconds 1 --size 64x36 --mute 2>e.txt || { cat e.txt; return 1; }
    grep -q "; audio: off$" e.txt || { cat e.txt; return 1; }
    # headless without --audio-out: silent, and not a word about it
    "$RS_BIN" play --headless --replay "$REPLAY" --seconds 1 --size 64x36 2>e.txt || { cat e.txt; return 1; }
    [ "$(wc -l <e.txt)" = 1 ] && grep -q "; audio: off$" e.txt || { cat e.txt; return 1; }
    [ -z "$(ls ./*.wav 2>/dev/null)" ] || { echo "a WAV was written: $(ls ./*.wav)"; return 1; }
    # muted with --audio-out: the silence that was played, tick for tick (as movie and attract)
    "$RS_BIN" play --headless --replay "$REPLAY" --seconds 1 --size 64x36 --mute --audio-out m.wav 2>e.txt ||
        { cat e.txt; return 1; }
    [ "$(soxi -s m.wav)" = 48000 ] || { echo "m.wav: $(soxi -s m.wav) frames, not 48000"; return 1; }
    sox m.wav -n stat 2>&1 | grep -q "Maximum amplitude: *0.000000" || { sox m.wav -n stat; return 1; }
}

t_usage() {
    expect_fail 2 "--volume '2': expected a number from 0 \(silent\) to 1 \(full\)" "$RS_BIN" play --headless --seconds 1 --volume 2 || return 1
    expect_fail 2 "--volume 'loud': expected a number from 0 \(silent\) to 1 \(full\)" "$RS_BIN" play --headless --seconds 1 --volume loud ||
        return 1
    expect_fail 2 "--volume '-0.1'" "$RS_BIN" play --headless --seconds 1 --volume -0.1 || return 1
    expect_fail 2 "--audio-out x.mp3: expected a \.wav file" "$RS_BIN" play --headless --seconds 1 --audio-out x.mp3 ||
        return 1
}

# refused before the game starts: no summary line, nothing written
t_unwritable_audio_out() {
    expect_fail 1 "nodir/a.wav: folder nodir does not exist" \
        "$RS_BIN" play --headless --replay "$REPLAY" --size 64x36 --audio-out nodir/a.wav || return 1
    ! grep -q "ticks" err.txt || { cat err.txt; return 1; }
    mkdir d.wav
    expect_fail 1 "d.wav" "$RS_BIN" play --headless --replay "$REPLAY" --size 64x36 --audio-out d.wav || return 1
    ! grep -q "ticks" err.txt || { cat err.txt; return 1; }
}

need_display() {
    [ -n "${DISPLAY:-}" ] || t_skip_env "no X display (tests/run.sh starts Xvfb)"
}

# no audio device: one warning line, and the game runs silent to its end.
# ALSA with an empty configuration is a machine without a sound card (and
# ALSA prints its own complaints unless ringside keeps them quiet)
t_window_no_device() {
    need_display
    : >asound.conf
    ALSOFT_DRIVERS=alsa ALSA_CONFIG_PATH=$PWD/asound.conf "$RS_BIN" play --p1 cpu --p2 cpu --seconds 1 --size 64x36 \
        2>e.txt || { cat e.txt; return 1; }
    [ "$(grep -c warning e.txt)" = 1 ] && [ "$(wc -l <e.txt)" = 2 ] || { cat e.txt; return 1; }
    grep -q "^ringside play: warning: .*audio device.*; the game runs silent$" e.txt || { cat e.txt; return 1; }
    grep -q "^ringside play: 60 ticks .*; audio: off$" e.txt || { cat e.txt; return 1; }
}

# a window on OpenAL Soft's null driver: the summary reports the device
# path (latency and underruns depend on how busy the machine is: the
# figures are test_au_out's, with a steady writer)
t_window_openal() {
    need_display
    printf '[general]\nperiod_size = 256\nperiods = 2\n' >alsoft.conf
    ALSOFT_DRIVERS=null ALSOFT_CONF=$PWD/alsoft.conf "$RS_BIN" play --p1 cpu --p2 cpu --seconds 1 --size 64x36 \
        2>e.txt || { cat e.txt; return 1; }
    grep -Eq "; audio: openal \(OpenAL Soft\), [0-9.]+ ms a tick \(mix and output\), latency max [0-9.]+ ms, [0-9]+ underruns, [0-9]+ frames dropped$" \
        e.txt || { cat e.txt; return 1; }
    [ "$(wc -l <e.txt)" = 1 ] || { cat e.txt; return 1; }
}

# --audio-out in a window: the file gets every tick the game ran
t_window_audio_out() {
    need_display
    need_sox
    "$RS_BIN" play --p1 cpu --p2 cpu --seconds 1 --size 64x36 --audio-out w.wav 2>e.txt || { cat e.txt; return 1; }
    grep -q "^ringside play: 60 ticks .*; audio: wav w.wav" e.txt || { cat e.txt; return 1; }
    [ "$(wav_frames w.wav)" = $((60 * 800)) ] || { echo "w.wav: $(wav_frames w.wav) frames"; return 1; }
}

t_run headless_wav_length same_as_replay_sound volume_scales mute_and_headless_are_silent usage unwritable_audio_out \
    window_no_device window_openal window_audio_out
t_done
