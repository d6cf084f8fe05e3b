/* The render pass graph: "skip every pass a scene does not need".
 *
 * A pass declares the resources it reads and writes (bits of a mask, named
 * by the renderer) and a needed() test on the frame.  r_graph_run calls
 * needed() for each pass in order and runs only those that say yes; a pass
 * that is not needed costs nothing: no FBO bind, no draw, no texture
 * update.  Passes are added in execution order, and r_graph_add checks
 * that everything a pass reads is written by an earlier pass or is
 * persistent (textures built at load, the previous frame's results).
 * At run time a pass whose input was not produced this frame (its
 * writer was skipped) is a needed() bug: the pass is skipped and the
 * graph records the error (r_graph_error), which the tests check.
 *
 * Timing (--passes): each pass that runs is bracketed with a
 * pair of GL_TIMESTAMP queries, read back R_GRAPH_LAG frames later so the CPU
 * never waits for the GPU; CPU time (submission) is measured too, and is
 * what gets reported where timer queries are missing.
 *
 * On a software renderer (llvmpipe, softpipe) work is deferred until a
 * later pass forces a flush, so a cheap pass that reads a texture gets
 * billed for the draws queued before it.  There timing finishes each pass
 * (glFinish) so every pass is billed for its own work; the frame gets a
 * little slower, which is the price of an honest table. */
#ifndef R_GRAPH_H
#define R_GRAPH_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "../gl/rgl.h"
#include "../util/rs_err.h"

#define R_GRAPH_MAX 48 /* passes; r_graph_mask has a bit for each */
#define R_GRAPH_LAG 4

typedef struct r_pass {
    const char *name;
    uint32_t reads, writes;
    bool (*needed)(void *user);
    void (*run)(void *user);
    /* used when their writer ran this frame (the pass asks r_graph_ran):
     * checked at add like reads, but a skipped writer is no error */
    uint32_t may_read;
} r_pass;

typedef struct r_pass_stats {
    uint64_t runs, skips;
    double gpu_ms, cpu_ms;       /* sums over runs */
    double gpu_max_ms, cpu_max_ms;
} r_pass_stats;

/* Called once per frame when its timings are known (lagged). */
typedef uint64_t r_graph_mask; /* one bit per pass, in order */

typedef void (*r_graph_frame_fn)(void *user, uint64_t frame, r_graph_mask ran, const double *gpu_ms, const double *cpu_ms);

typedef struct r_graph {
    r_pass pass[R_GRAPH_MAX];
    r_pass_stats stats[R_GRAPH_MAX];
    int n;
    uint32_t persistent;          /* resources valid without a writer this frame */
    const char *resource[32];     /* names, for messages */
    uint64_t frame;
    r_graph_mask last_ran;
    r_graph_mask ran_now;             /* passes run so far in the frame being run */
    char error[256];              /* first run-time inconsistency, "" if none */
    /* timing */
    bool timing, gpu_timer;
    bool serial;                  /* glFinish after each timed pass (software renderers) */
    GLuint query[R_GRAPH_LAG][R_GRAPH_MAX][2]; /* GL_TIMESTAMP before and after each pass */
    struct {
        bool pending;
        uint64_t frame;
        r_graph_mask ran;
        double cpu_ms[R_GRAPH_MAX];
    } slot[R_GRAPH_LAG];
    r_graph_frame_fn on_frame;
    void *on_frame_user;
} r_graph;

void r_graph_init(r_graph *g, uint32_t persistent, const char *const *resource_names, int nresources);
bool r_graph_add(r_graph *g, const r_pass *p, rs_err *err);
/* Turns timing on (needs a GL context; GPU timer queries when GL 3.3 or
 * ARB_timer_query is there, else CPU time only). */
void r_graph_timing(r_graph *g, r_graph_frame_fn fn, void *user);
/* Runs one frame; returns the mask of passes that ran (bit i = pass i). */
r_graph_mask r_graph_run(r_graph *g, void *user);
/* The same without the passes in `skip`: they are neither run nor counted,
 * and what they write counts as produced (their last contents stand in).
 * For frames drawn only for what they leave behind (r_game_advance). */
r_graph_mask r_graph_run_skip(r_graph *g, void *user, r_graph_mask skip);
/* Collects every outstanding timing (blocking). */
void r_graph_flush(r_graph *g);
void r_graph_release(r_graph *g);
const char *r_graph_error(const r_graph *g);
int r_graph_find(const r_graph *g, const char *name);
/* A table: pass, runs, skipped, mean and max GPU ms, mean CPU ms. */
void r_graph_report(const r_graph *g, FILE *f);

#endif
