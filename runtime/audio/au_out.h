/* Live audio output for play, movie and attract: one tick of audio in, to
 * a device or a file.
 *
 *   au_out *o = au_out_open(&opts, &err);    NULL: err says why; callers
 *                                            warn once and run silent
 *   each 60 Hz tick: au_out_write(o, pcm, AU_TICK_FRAMES)
 *   au_out_close(o)
 *
 * Backends:
 *   openal  OpenAL Soft (RS_HAVE_OPENAL): one streaming source fed small
 *           buffers, at most latency_ms (default 50) queued ahead, so a
 *           sound reaches the speaker at most that long after its tick.
 *           When the queue runs dry (the loop stalled) the gap is counted
 *           as an underrun and playback restarts with the next write.
 *   wav     headless: what would have been played, written to a WAV file
 *           (float32 or 16-bit), frame for frame, nothing dropped.
 *   null    accepts everything, plays nothing (a muted run; counts frames).
 *
 * au_out_write never blocks longer than one tick: with the device's queue
 * full it drops the oldest unplayed audio rather than stall the game. */
#ifndef AU_OUT_H
#define AU_OUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "au.h"

typedef struct au_out au_out;
typedef enum au_out_backend { AU_OUT_AUTO, AU_OUT_OPENAL, AU_OUT_WAV, AU_OUT_NULL } au_out_backend;

typedef struct au_out_opts {
    au_out_backend backend; /* AUTO: wav when wav_path is set, else openal */
    const char *wav_path;   /* the wav backend's file */
    bool wav_float;         /* write float32 samples (default 16-bit PCM) */
    const char *device;     /* OpenAL device name; NULL: the default one */
    float volume;           /* linear, applied at output; 0 -> 1; use the null backend for silence */
    int latency_ms;         /* openal: most audio queued ahead; 0 -> 50 */
} au_out_opts;

typedef struct au_out_stats {
    uint64_t frames;      /* frames written by the caller */
    uint64_t played;      /* frames the device has played (openal), = frames otherwise */
    uint64_t underruns;   /* times the device's queue ran dry after playback started */
    uint64_t dropped;     /* frames dropped because the queue was full */
    double latency_ms;    /* audio queued ahead of the speaker at the last write */
    double max_latency_ms;
    double write_ms;      /* time spent in au_out_write, summed */
} au_out_stats;

au_out *au_out_open(const au_out_opts *o, rs_err *err);
const char *au_out_backend_name(const au_out *o); /* "openal (device name)", "wav FILE", "null" */
/* pcm: frames stereo float frames, 48 kHz. */
bool au_out_write(au_out *o, const float *pcm, int frames, rs_err *err);
void au_out_stats_get(const au_out *o, au_out_stats *st);
/* Stops playback; the wav backend finishes its file (ok) or removes it. */
bool au_out_close(au_out *o, bool ok, rs_err *err);

#endif
