#!/bin/sh
# Renders the announcer's lines with espeak-ng into runtime/audio/voice/
# (mono 16-bit WAV at espeak's 22050 Hz), the files the build embeds
# (runtime/audio/au_voice_data.S).  Run it once after changing a line or
# the voice below, and commit the WAVs with it:
#
#   tools/gen-voice.sh            (installs espeak-ng first: tools/deps.sh voice)
#
# The binary resamples the clips to 48 kHz and trims their silence when it
# builds the sound bank (runtime/audio/au_voice.c).  espeak-ng is a formant
# synthesizer: no recordings of anyone go into the repository.
set -eu
cd "$(dirname "$0")/.."
tools/deps.sh voice

out=runtime/audio/voice
mkdir -p "$out"
# the announcer: espeak-ng's English with a low, slow, loud male variant
say() { # FILE TEXT
    espeak-ng -v en-us+m3 -p 28 -s 135 -a 100 -g 4 -w "$out/$1.wav" "$2"
}
say round1 "Round one!"
say round2 "Round two!"
say round3 "Round three!"
say round4 "Round four!"
say round5 "Final round!"
say fight "Fight!"
say ko "K. O.!"
say ring_out "Ring out!"
say time "Time!"
say draw "Draw!"
say p1_wins "Player one wins!"
say p2_wins "Player two wins!"
ls -l "$out"
