/* runtime/render/r_graph: passes that declare what they read and write,
 * skipped when not needed, checked when added and when run, timed. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_graph.h"
#include "t.h"

enum { R_A = 1u << 0, R_B = 1u << 1, R_C = 1u << 2, R_OUT = 1u << 3 };
static const char *const names[] = {"a", "b", "c", "out"};

typedef struct world {
    bool want_b;
    int order[16], n; /* which passes ran, in order */
} world;

static bool yes(void *u)
{
    (void)u;
    return true;
}
static bool want_b(void *u) { return ((world *)u)->want_b; }
static void log_pass(world *w, int id) { w->order[w->n++] = id; }
static void run0(void *u) { log_pass(u, 0); }
static void run1(void *u) { log_pass(u, 1); }
static void run2(void *u) { log_pass(u, 2); }
static void run3(void *u) { log_pass(u, 3); }

static void t_validation_at_add(void)
{
    r_graph g;
    rs_err e = {0};
    r_graph_init(&g, 0, names, 4);
    /* reading what nobody wrote */
    T_ASSERT(!r_graph_add(&g, &(r_pass){"blur", R_A, R_B, yes, run0, 0}, &e));
    T_CONTAINS(e.msg, "pass 'blur' reads 'a', which no earlier pass writes");
    /* a persistent resource may be read without a writer */
    r_graph_init(&g, R_A, names, 4);
    T_ASSERTF(r_graph_add(&g, &(r_pass){"blur", R_A, R_B, yes, run0, 0}, &e), "%s", e.msg);
    /* an optional read is checked the same way */
    T_ASSERT(!r_graph_add(&g, &(r_pass){"late", 0, R_OUT, yes, run1, R_C}, &e));
    T_CONTAINS(e.msg, "pass 'late' reads 'c', which no earlier pass writes");
    /* duplicate names, missing functions */
    T_ASSERT(!r_graph_add(&g, &(r_pass){"blur", 0, R_C, yes, run1, 0}, &e));
    T_CONTAINS(e.msg, "two passes named 'blur'");
    T_ASSERT(!r_graph_add(&g, &(r_pass){"x", 0, R_C, NULL, run1, 0}, &e));
    T_CONTAINS(e.msg, "no name, run or needed");
    T_ASSERT(!r_graph_add(&g, &(r_pass){NULL, 0, R_C, yes, run1, 0}, &e));
    /* capacity */
    r_graph_init(&g, 0, names, 4);
    char nm[R_GRAPH_MAX + 1][8];
    for (int i = 0; i < R_GRAPH_MAX; i++) {
        snprintf(nm[i], sizeof nm[i], "p%d", i);
        T_ASSERT(r_graph_add(&g, &(r_pass){nm[i], 0, R_A, yes, run0, 0}, &e));
    }
    T_ASSERT(!r_graph_add(&g, &(r_pass){"one_more", 0, R_A, yes, run0, 0}, &e));
    T_CONTAINS(e.msg, "more than");
    T_EQ(r_graph_find(&g, "p3"), 3);
    T_EQ(r_graph_find(&g, "nope"), -1);
}

static void build(r_graph *g)
{
    rs_err e = {0};
    r_graph_init(g, 0, names, 4);
    T_ASSERT(r_graph_add(g, &(r_pass){"make_a", 0, R_A, yes, run0, 0}, &e));
    T_ASSERT(r_graph_add(g, &(r_pass){"make_b", R_A, R_B, want_b, run1, 0}, &e));
    T_ASSERT(r_graph_add(g, &(r_pass){"use_a", R_A, R_C, yes, run2, 0}, &e));
    T_ASSERT(r_graph_add(g, &(r_pass){"final", R_C, R_OUT, yes, run3, 0}, &e));
}

static void t_skipped_pass_is_not_called(void)
{
    r_graph g;
    build(&g);
    world w = {.want_b = false};
    r_graph_mask ran = r_graph_run(&g, &w);
    T_EQ(ran, 0xD); /* passes 0, 2, 3 */
    T_EQ(w.n, 3);
    T_EQ(w.order[0], 0);
    T_EQ(w.order[1], 2);
    T_EQ(w.order[2], 3);
    T_EQ(g.stats[1].skips, 1);
    T_EQ(g.stats[1].runs, 0);
    w = (world){.want_b = true};
    ran = r_graph_run(&g, &w);
    T_EQ(ran, 0xF);
    T_EQ(w.n, 4);
    T_EQ(w.order[1], 1); /* in declaration order */
    T_EQ(g.stats[0].runs, 2);
    T_EQ(g.frame, 2);
    T_EQ(g.last_ran, 0xF);
    T_ASSERT(!r_graph_error(&g)[0]);
}

/* A needed() that says yes while its input's writer said no is a bug the
 * graph catches at run time: the reader is skipped, the error kept. */
static bool b_needed_flag;
static bool b_needed(void *u)
{
    (void)u;
    return b_needed_flag;
}
static void t_inconsistent_needed_is_an_error(void)
{
    r_graph g;
    rs_err e = {0};
    r_graph_init(&g, 0, names, 4);
    T_ASSERT(r_graph_add(&g, &(r_pass){"make_b", 0, R_B, b_needed, run0, 0}, &e));
    T_ASSERT(r_graph_add(&g, &(r_pass){"use_b", R_B, R_OUT, yes, run1, 0}, &e));
    world w = {0};
    b_needed_flag = true;
    T_EQ(r_graph_run(&g, &w), 3);
    T_ASSERT(!r_graph_error(&g)[0]);
    b_needed_flag = false;
    w.n = 0;
    T_EQ(r_graph_run(&g, &w), 0);
    T_EQ(w.n, 0);
    T_CONTAINS(r_graph_error(&g), "frame 1: pass 'use_b' needs 'b', whose writer was skipped");
    /* the first error is kept */
    r_graph_run(&g, &w);
    T_CONTAINS(r_graph_error(&g), "frame 1:");
}

/* r_graph_run_skip: the passes in the mask are not called and not counted,
 * and a reader of what they write is no error (their last contents stand
 * in); the others run as usual. */
static void t_run_skip(void)
{
    r_graph g;
    rs_err e = {0};
    r_graph_init(&g, 0, names, 4);
    T_ASSERT(r_graph_add(&g, &(r_pass){"make_b", 0, R_B, yes, run0, 0}, &e));
    T_ASSERT(r_graph_add(&g, &(r_pass){"use_b", R_B, R_C, yes, run1, 0}, &e));
    T_ASSERT(r_graph_add(&g, &(r_pass){"out", R_C, R_OUT, yes, run2, 0}, &e));
    world w = {0};
    T_EQ(r_graph_run_skip(&g, &w, 0x1 | 0x4), 0x2);
    T_EQ(w.n, 1);
    T_EQ(w.order[0], 1);
    T_EQ(g.stats[0].runs + g.stats[0].skips, 0);
    T_EQ(g.stats[1].runs, 1);
    T_ASSERTF(!r_graph_error(&g)[0], "%s", r_graph_error(&g));
    w.n = 0;
    T_EQ(r_graph_run(&g, &w), 0x7);
    T_EQ(w.n, 3);
}

/* Timing on a GL context: every pass that ran gets a time, skipped ones
 * none, and the report names them all. */
static int frames_seen;
static r_graph_mask last_ran_seen;
static void on_frame(void *u, uint64_t frame, r_graph_mask ran, const double *gpu, const double *cpu)
{
    (void)u, (void)frame, (void)gpu;
    frames_seen++;
    last_ran_seen = ran;
    for (int i = 0; i < 4; i++)
        if (ran & ((r_graph_mask)1 << i))
            T_ASSERT(cpu[i] >= 0 && cpu[i] < 10000);
}
static GLuint fbo_for_test;
static void gl_pass(void *u)
{
    log_pass(u, 9);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo_for_test);
    gl.ClearColor(0.5f, 0.5f, 0.5f, 1);
    for (int i = 0; i < 20; i++)
        gl.Clear(GL_COLOR_BUFFER_BIT);
}

static void t_timing_and_report(void)
{
    plat *p = t_context("egl");
    GLuint tex;
    gl.GenTextures(1, &tex);
    gl.BindTexture(GL_TEXTURE_2D, tex);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 256, 256, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    gl.GenFramebuffers(1, &fbo_for_test);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo_for_test);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    r_graph g;
    rs_err e = {0};
    r_graph_init(&g, 0, names, 4);
    T_ASSERT(r_graph_add(&g, &(r_pass){"clears", 0, R_A, yes, gl_pass, 0}, &e));
    T_ASSERT(r_graph_add(&g, &(r_pass){"sometimes", R_A, R_B, want_b, run1, 0}, &e));
    T_ASSERT(r_graph_add(&g, &(r_pass){"last", R_A, R_OUT, yes, run3, 0}, &e));
    r_graph_timing(&g, on_frame, NULL);
    T_ASSERT(g.gpu_timer); /* GL 3.3+ on every backend we run */
    world w = {0};
    for (int f = 0; f < 10; f++) {
        w.n = 0;
        w.want_b = f % 2;
        r_graph_run(&g, &w);
    }
    T_ASSERT(frames_seen <= 10 - R_GRAPH_LAG + 1); /* read back lagged, never waited on */
    r_graph_flush(&g);
    T_EQ(frames_seen, 10);
    T_EQ(last_ran_seen, 0x7); /* frame 9 wanted b */
    T_EQ(g.stats[1].runs, 5);
    T_EQ(g.stats[1].skips, 5);
    T_ASSERT(g.stats[0].gpu_ms > 0);
    T_ASSERT(g.stats[0].gpu_ms < 60000);
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    r_graph_report(&g, f);
    fclose(f);
    T_CONTAINS(buf, "clears");
    T_CONTAINS(buf, "sometimes");
    T_CONTAINS(buf, "total");
    /* "sometimes": 5 runs, 5 skipped */
    char *line = strstr(buf, "sometimes");
    int runs = 0, skips = 0;
    T_ASSERT(sscanf(line, "sometimes %d %d", &runs, &skips) == 2);
    T_EQ(runs, 5);
    T_EQ(skips, 5);
    free(buf);
    r_graph_release(&g);
    T_EQ(gl.GetError(), GL_NO_ERROR);
    plat_destroy(p);
}

T_MAIN({"validation_at_add", t_validation_at_add}, {"skipped_pass_is_not_called", t_skipped_pass_is_not_called},
       {"inconsistent_needed_is_an_error", t_inconsistent_needed_is_an_error}, {"run_skip", t_run_skip},
       {"timing_and_report", t_timing_and_report})
