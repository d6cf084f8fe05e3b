/* Capture: rendered frames -> downscale -> readback -> writer thread -> sink.
 *
 * Two paths, both kept because the benchmark compares them:
 *   sequential (the original): glReadPixels of the full frame into client
 *     memory, downscale and convert to YCbCr on the CPU, write, all on the
 *     game thread;
 *   async: downscale (area average) and convert to YCbCr 4:2:0 on the GPU
 *     (1.5 bytes a pixel instead of 4), glReadPixels into pixel-buffer object
 *     i of a ring, map the oldest one (ring size - 1 frames late: one with
 *     the default 2, as in the seed) once its fence has passed, copy into a frame slot, hand it to the writer
 *     thread behind a queue capped at 120 frames.
 * Either path can use either downscale (`downscale`), so outputs can be
 * compared byte for byte: same downscale, same bytes. */
#ifndef CAP_H
#define CAP_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "../runtime/gl/rgl.h"
#include "cap_scale.h"
#include "cap_sink.h"

typedef enum cap_mode { CAP_ASYNC, CAP_SEQUENTIAL } cap_mode;
typedef enum cap_downscale { CAP_DS_DEFAULT, CAP_DS_GPU, CAP_DS_CPU } cap_downscale;

#define CAP_DEFAULT_PBO 2
#define CAP_DEFAULT_QUEUE 120
#define CAP_MAX_PBO 8
#define CAP_MAX_SCALE 8     /* render size / output size, per axis */

/* Zero means default for every field. */
typedef struct cap_desc {
    int src_w, src_h;        /* rendered frame */
    int w, h;                /* output; even, at most the render size */
    cap_mode mode;           /* default async */
    cap_downscale downscale; /* default: GPU for async, CPU for sequential */
    cap_filter filter;       /* GPU downscale filter, default box (the CPU path is always box) */
    int pbo;                 /* ring size, default 2 */
    int queue;               /* writer queue cap, default 120 */
    bool no_writer;          /* write on the game thread: no writer thread, no queue
                              * (always so in sequential mode) */
    FILE *hashes;            /* optional: "index hash" per output frame */
    const char *hashes_name; /* its name as the user gave it, for messages (NULL: "the frame hash list") */
} cap_desc;

typedef struct cap_stats {
    uint64_t frames;
    int high_water;           /* most frames queued at once (<= queue cap) */
    uint64_t fence_waits;     /* maps that found their fence not yet passed */
    double ms_downscale;      /* GPU or CPU downscale + colour conversion, game thread */
    double ms_readback;       /* glReadPixels calls (sequential: includes the wait for the GPU) */
    double ms_fence_wait;     /* time blocked on fences before mapping */
    double ms_map_copy;       /* map + copy into a frame slot */
    double ms_queue_wait;     /* game thread blocked on a full queue */
    double ms_write;          /* writer: sink encode + write */
    uint64_t full_waits;
} cap_stats;

typedef struct cap cap;

/* Needs a current GL context.  Opens the sink (which must come from
 * cap_sink_for) and starts the writer. */
cap *cap_open(const cap_desc *desc, cap_sink *sink, rs_err *err);
/* One rendered frame: src is an RGBA8 texture of src_w x src_h (bottom-up,
 * as GL renders).  Returns false when the pipeline has failed (disk full,
 * encoder error); cap_close then reports why. */
bool cap_frame(cap *c, GLuint src, rs_err *err);
/* Drains the ring and the queue, closes the sink: committed when ok and
 * nothing failed, removed otherwise.  Always frees c. */
bool cap_close(cap *c, bool ok, cap_stats *stats, rs_err *err);

/* CPU reference implementations (also used by the sequential path). */
void cap_cpu_downscale(const uint8_t *src_bottom_up, int sw, int sh, uint8_t *dst_rgba, int w, int h);
/* The general area average (cap_cpu_downscale takes an integer shortcut at
 * exactly 2x); exposed so tests can hold the shortcut to it. */
void cap_cpu_downscale_area(const uint8_t *src_bottom_up, int sw, int sh, uint8_t *dst_rgba, int w, int h);
void cap_cpu_rgba_to_i420(const uint8_t *rgba, int w, int h, uint8_t *i420);

/* Checks sizes; a clear message for each way they can be wrong.  4:2:0
 * output (video) needs even sizes; RGBA output (image sequences) does not. */
bool cap_check_sizes(int src_w, int src_h, int w, int h, rs_err *err);
bool cap_check_sizes_for(cap_pixfmt fmt, int src_w, int src_h, int w, int h, rs_err *err);

#endif
