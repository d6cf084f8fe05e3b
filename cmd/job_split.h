/* job_split: one `render` as segments drawn at once by child processes of
 * this binary, then joined by stream copy with the whole range's sound
 * (render --jobs; docs/capture.md, "Parallel segments").
 *
 * Why: on a machine without a GPU the renderer is llvmpipe, whose threads
 * wait for each other at every pass that reads the one before it and for
 * the game thread between frames; two single-threaded renderers drawing
 * two halves of the match keep both cores busy (dojo 600 frames: 20.9 s
 * as one process, 14.4 s as two).  The segments are the service's
 * (render --ticks A:B --segment KEY, docs/segments.md): every frame is
 * the one a single render draws there, the effects' history warmed up at
 * each segment's start, and join checks every segment before it writes.
 *
 *   job_split_desc d = {...};
 *   int status = job_split_run(&d, &err);   RS_EXIT_* (cli.h)
 *
 * The children: `render REPLAY --ticks A:B --segment KEY -o DIR/sK.EXT`
 * with the options the user gave (d.pass), --audio off, --quiet and
 * --progress-fd 3, LP_NUM_THREADS set to share the cores (unless the
 * user set it); DIR is a hidden folder beside the output, removed at the
 * end whatever happens.  While they draw, this process mixes the sound
 * (job_audio_plan: the whole match, normalized, cut to the ticks); then
 * it joins the segments into the output as `join` does (verified, stream
 * copied, .part then renamed: nothing partial is ever left).  A child that fails stops the
 * others and its last message is the render's; Ctrl-C and SIGTERM
 * (d.stop) stop them all. */
#ifndef JOB_SPLIT_H
#define JOB_SPLIT_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>

#include "../capture/cap_sink.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_err.h"
#include "../runtime/util/rs_progress.h"
#include "job_audio.h"

/* A segment shorter than this is not worth a process of its own (start-up
 * is about 0.7 s on llvmpipe, plus the effects' warm-up). */
#define JOB_SPLIT_MIN_FRAMES 600
#define JOB_SPLIT_MAX 64

typedef struct job_split_desc {
    const char *exe;            /* this binary (/proc/self/exe) */
    const char *replay;         /* the replay's path */
    const char *out;            /* the video: .mp4, .mkv or .webm (cap_seg_format_of) */
    uint64_t first, end;        /* ticks first..end-1 */
    int jobs;                   /* segments, drawn at once: 2..JOB_SPLIT_MAX */
    const char *const *pass;    /* the render options every segment gets, NULL-terminated */
    const rp_replay *rp;        /* the replay, read */
    cap_sink *sink;             /* the output's sink (its codec, its audio settings), not opened */
    job_audio *audio;           /* the sound's options, checked against sink (job_audio_check) */
    const char *hashes;         /* --hashes FILE ("-": standard output), or NULL */
    const char *poster;         /* --poster FILE.png, or NULL */
    bool overwrite;             /* -y (the outputs were checked by the caller) */
    rs_progress_mode progress;
    int progress_fd;            /* --progress-fd, or -1 */
    bool quiet;
    const char *what;           /* for the summary: "640x360 (drawn at ..., quality standard)" */
    const char *said;           /* a note the caller printed already (the encoder's), or NULL */
    volatile sig_atomic_t *stop; /* set by the caller's signal handler */
} job_split_desc;

/* The number of CPUs this process may run on (affinity), at least 1. */
int job_split_cpus(void);

/* Segments for `auto`: one per CPU, each at least JOB_SPLIT_MIN_FRAMES;
 * 1 means do not split. */
int job_split_auto(uint64_t frames);

/* Renders, joins, reports; returns the exit status (err filled when not 0). */
int job_split_run(const job_split_desc *d, rs_err *err);

#endif
