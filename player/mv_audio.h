/* mv_audio: a movie's soundtrack, decoded on its own thread and read on
 * the 60 Hz tick, in the mixer's format (runtime/audio/au.h: 48 kHz
 * stereo interleaved float).
 *
 * Timeline.  Frame 0 of the soundtrack is the video's first presentation
 * time, so tick t of the picture (movie time t/60 .. (t+1)/60) has the
 * audio frames [t * AU_TICK_FRAMES, (t+1) * AU_TICK_FRAMES).  Audio that
 * starts after the video is preceded by silence, audio before it is cut;
 * a hole in the stream's timestamps (a broken packet skipped) is filled
 * with silence so what follows stays in place.  Both the reader and the
 * picture count ticks, never a clock: there is nothing to drift.
 *
 * Conversion: libswresample, from any rate, sample format (u8, s16, s32,
 * float, double, planar or packed) and channel layout: mono is copied to
 * both sides, 5.1 and the rest downmixed with libswresample's matrix (the
 * one `ffmpeg -ac 2` uses), so a track decoded here and by
 * `ffmpeg -ac 2 -ar 48000` agree.
 *
 * Memory is bounded: the decoder runs at most MV_AUDIO_AHEAD frames ahead
 * of the reader, then sleeps until the reader catches up. */
#ifndef MV_AUDIO_H
#define MV_AUDIO_H

#include <stdbool.h>
#include <stdint.h>

#include "../runtime/audio/au.h"
#include "mv.h"

#define MV_AUDIO_AHEAD (2 * AU_RATE) /* the ring: two seconds */

typedef struct mv_audio mv_audio;

typedef struct mv_audio_info {
    char codec[32];   /* "aac", "opus", "pcm_s16le", ... */
    char format[16];  /* the decoder's sample format: "fltp", "s16", "u8", ... */
    char layout[48];  /* "mono", "stereo", "5.1(side)", ... */
    int rate;         /* the stream's sample rate, Hz */
    int channels;
} mv_audio_info;

typedef struct mv_audio_stats {
    int64_t reads;       /* reads (ticks) served */
    int64_t late;        /* reads not decoded in time: silence instead, the reader moved on */
    int64_t bad_packets; /* packets the decoder refused: skipped, the picture goes on */
    int64_t filled;      /* frames of silence put where the stream had no audio */
    int64_t discarded;   /* decoded frames the reader had already passed (after a late read) */
    int64_t frames;      /* 48 kHz frames decoded */
    double cpu_ms;       /* the decode thread's CPU time: demux, decode, resample */
} mv_audio_stats;

/* Opens the best audio stream of path (the one libavformat pairs with the
 * best video stream) and starts its decode thread.  NULL when there is
 * nothing to play: err->code 0 when the file simply has no audio stream
 * (or the build has no FFmpeg), an MV_ERR_* id naming the file and the
 * problem when its audio cannot be decoded.  Either way the movie plays,
 * silent. */
mv_audio *mv_audio_open(const char *path, rs_err *err);
const mv_audio_info *mv_audio_info_get(const mv_audio *a);

/* The soundtrack's frames [pos, pos + frames) into out (frames stereo
 * frames).  Reads must move forward (pos at or after the end of the last
 * read); frames past the end of the track are silence.  Not yet decoded:
 * with wait, waits for them; without, writes silence, counts the read
 * late, returns false and moves on (those frames are dropped when they
 * arrive), so a slow decoder never stalls the tick. */
bool mv_audio_read(mv_audio *a, int64_t pos, float *out, int frames, bool wait);
/* Waits up to timeout_ms until the first `frames` frames are decoded (or
 * the track is over): called once before playback starts, so the first
 * tick is not late. */
void mv_audio_prime(mv_audio *a, int frames, int timeout_ms);
void mv_audio_stats_get(mv_audio *a, mv_audio_stats *st);
/* Stops and joins the thread. */
void mv_audio_close(mv_audio *a);

#endif
