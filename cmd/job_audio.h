/* job_audio: a video's soundtrack, for `render` and `join`: the options
 * (--audio, --audio-bitrate, --loudness, --wav), the track of the ticks the
 * command writes (au_replay_open: the whole match measured and normalized,
 * then the range read out, so any range is exactly that range of the whole
 * render's samples; streamed, never held whole), the sink's audio stream,
 * and the WAV beside the output.
 *
 *   job_audio a = {0};
 *   job_audio_option(&a, opt, optarg)        for each of the four options
 *   job_audio_plan(&a, &sink, rp, ...)       before the first frame: measures
 *                                            the match, gives the sink its
 *                                            track to read
 *   ... render; cap_close ...
 *   job_audio_commit(&a, err)                writes --wav
 *   job_audio_free(&a)
 *
 * Runs on the command's thread; the sink's writer thread reads the track
 * (the stream is its own until cap_close; then the WAV reads it again). */
#ifndef JOB_AUDIO_H
#define JOB_AUDIO_H

#include <stdbool.h>
#include <stdint.h>

#include "../capture/cap_sink.h"
#include "../runtime/audio/au.h"
#include "../runtime/replay/rp.h"

#define JOB_AUDIO_LUFS_DEFAULT -16.0
#define JOB_AUDIO_LUFS_MIN -40.0
#define JOB_AUDIO_LUFS_MAX -5.0

typedef enum job_audio_mode { JOB_AUDIO_AUTO, JOB_AUDIO_ON, JOB_AUDIO_OFF } job_audio_mode;

/* The options' getopt values (long only). */
enum { JOB_AUDIO_OPT_AUDIO = 0x300, JOB_AUDIO_OPT_BITRATE, JOB_AUDIO_OPT_LOUDNESS, JOB_AUDIO_OPT_WAV };

typedef struct job_audio {
    job_audio_mode mode;  /* AUTO: on when the output's container carries audio */
    int64_t bitrate;      /* bits/s; 0: the codec's default */
    double lufs;          /* the integrated target; 0: JOB_AUDIO_LUFS_DEFAULT */
    const char *wav;      /* the track as a WAV beside the output; NULL: none */
    bool overwrite;       /* -y for the WAV */
    au_replay_stream *track; /* opened by job_audio_plan when anything needs it */
    bool muxed;           /* the sink has the track */
} job_audio;

/* One of the options; false after printing the error (named, with the
 * value and what was expected) as "ringside CMD: ...". */
bool job_audio_option(job_audio *a, const char *cmd, int opt, const char *arg);

/* Checks what can be checked before any work: --audio on with an output
 * that carries none, the bitrate for the container's codec, the WAV's
 * name (-y/-n, its folder).  False with err filled (usage: *usage set). */
bool job_audio_check(job_audio *a, const char *cmd, cap_sink *s, bool *usage, rs_err *err);

/* Measures the match and opens the stream of ticks first..end-1 of rp
 * when the sink gets audio or a WAV is asked for, and hands the sink its
 * track.  rp must live until job_audio_free. */
bool job_audio_plan(job_audio *a, cap_sink *s, const rp_replay *rp, const char *name, uint64_t first, uint64_t end,
                    rs_err *err);

/* After the output is in place (the sink closed): the WAV, the track read
 * again from its start (atomically: au_wav_open's temporary name). */
bool job_audio_commit(job_audio *a, rs_err *err);

/* "; audio aac 192 kb/s, -16.0 LUFS (gain +3.2 dB)" for the summary line,
 * "" when there is no audio. */
void job_audio_describe(const job_audio *a, const cap_sink *s, char *out, size_t n);

void job_audio_free(job_audio *a);

#endif
