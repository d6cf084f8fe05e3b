/* The sound options movie and attract share, and opening their output
 * (runtime/audio/au_out.h):
 *
 *   --mute            no sound (with --audio-out: a silent file of the
 *                     right length)
 *   --volume V        linear 0..1 (0 is --mute)
 *   --audio-out F.wav what would be played, to a 16-bit WAV instead of
 *                     the device (headless or not)
 *   --audio-device N  an OpenAL device by name (default: the system's)
 *
 * Headless without --audio-out plays nothing and says nothing; in a window
 * with no audio device the command prints one warning line and runs
 * silent. */
#ifndef SND_OUT_H
#define SND_OUT_H

#include <stdbool.h>

#include "../runtime/audio/au_out.h"

typedef struct snd_opts {
    bool mute;
    float volume;       /* 0 -> 1 */
    const char *wav;    /* --audio-out */
    const char *device; /* --audio-device */
} snd_opts;

/* --volume: a number 0..1; 0 sets mute.  False (message printed) when bad. */
bool snd_volume_arg(const char *cmd, const char *arg, snd_opts *o);
/* NULL with *fatal false: run silent (the warning, if any, printed);
 * NULL with *fatal true: the --audio-out file cannot be written (message
 * printed: stop before the loop starts). */
au_out *snd_open(const char *cmd, const snd_opts *o, bool headless, bool overwrite, bool *fatal);
/* "ringside CMD: audio: ..." with the output's counts; nothing for NULL. */
void snd_summary(const char *cmd, const au_out *out, const char *source);
/* Finishes the output (the WAV renamed into place when ok). */
bool snd_close(const char *cmd, au_out *out, bool ok);

#endif
