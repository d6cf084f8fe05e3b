/* runtime/loop: the fixed-timestep accumulator, driven by a fake clock. */
#include <math.h>
#include <stdlib.h>

#include "../runtime/loop.h"
#include "t.h"

/* The fake display: each call to now() is one frame; frame k ends at
 * times[k].  The stub game counts what the loop asks of it. */
static double fake_t;
static double (*frame_dt)(int frame);
static int frame_no;

static double fake_now(void)
{
    return fake_t;
}

typedef struct stub {
    uint64_t steps, renders, max_ticks;
    float min_alpha, max_alpha;
} stub;

static void s_input(void *u, g_input in[2])
{
    (void)u;
    in[0] = in[1] = 0;
}
static void s_step(void *u, const g_input in[2])
{
    (void)in;
    ((stub *)u)->steps++;
}
static void s_render(void *u, float alpha)
{
    stub *s = u;
    s->renders++;
    if (alpha < s->min_alpha)
        s->min_alpha = alpha;
    if (alpha > s->max_alpha)
        s->max_alpha = alpha;
    fake_t += frame_dt(frame_no++); /* the frame takes this long */
}
static bool s_running(void *u)
{
    return ((stub *)u)->steps < ((stub *)u)->max_ticks;
}

static lp_stats run_for(double (*dt)(int), uint64_t ticks, stub *s)
{
    fake_t = 1000.0;
    frame_no = 0;
    frame_dt = dt;
    *s = (stub){.max_ticks = ticks, .min_alpha = 2, .max_alpha = -1};
    lp_game g = {s, s_input, s_step, s_render, s_running};
    lp_stats st;
    lp_run(&(lp_desc){.now = fake_now}, &g, &st);
    return st;
}

static double at60(int k) { (void)k; return 1.0 / 60; }
static double at30(int k) { (void)k; return 1.0 / 30; }
static double at144(int k) { (void)k; return 1.0 / 144; }
static double jitter60(int k) { return 1.0 / 60 + ((k * 7919) % 7 - 3) * 0.0001; } /* +-0.3 ms */
static double stall(int k) { return k == 100 ? 5.0 : 1.0 / 60; }
static double slow(int k) { (void)k; return 0.25; } /* 4 fps */

static void t_steady_60(void)
{
    stub s;
    lp_stats st = run_for(at60, 600, &s);
    T_EQ(st.ticks, 600);
    T_ASSERT(st.frames >= 600 && st.frames <= 601);
    T_EQ(st.late_ticks, 0);
    T_EQ(st.stalls, 0);
}

static void t_jitter_is_not_late(void)
{
    stub s;
    lp_stats st = run_for(jitter60, 3600, &s);
    T_EQ(st.ticks, 3600);
    T_EQ(st.late_ticks, 0);
}

static void t_30hz_display(void)
{
    stub s;
    lp_stats st = run_for(at30, 600, &s);
    T_EQ(st.ticks, 600);
    T_ASSERT(st.frames >= 300 && st.frames <= 301);
    T_ASSERT(st.late_ticks >= 299 && st.late_ticks <= 300); /* every second tick missed its frame */
}

static void t_144hz_interpolates(void)
{
    stub s;
    lp_stats st = run_for(at144, 600, &s);
    T_EQ(st.ticks, 600);
    T_ASSERT(st.frames >= 1430 && st.frames <= 1442);
    T_EQ(st.late_ticks, 0);
    T_ASSERT(s.min_alpha >= 0 && s.max_alpha < 1 && s.max_alpha > 0.5f);
}

static void t_stall_is_cut(void)
{
    stub s;
    lp_stats st = run_for(stall, 600, &s);
    T_EQ(st.stalls, 1);
    T_EQ(st.ticks, 600);
    /* a 5 s stall becomes 0.25 s = 15 ticks: 8 run in one frame, 7 dropped */
    T_EQ(st.dropped_ticks, 7);
    T_ASSERT(st.late_ticks >= 7);
}

static void t_slow_machine_drops_backlog(void)
{
    stub s;
    lp_stats st = run_for(slow, 160, &s);
    T_EQ(st.ticks, 160);
    /* 4 fps: 15 ticks due per frame, 8 run, 7 dropped (the first frame
     * comes before any time has passed) */
    T_EQ(st.frames, 21);
    T_EQ(st.dropped_ticks, 7 * 20);
}

static void t_no_drift_over_an_hour(void)
{
    /* an hour of 60 Hz frames: the tick count keeps exact pace with time */
    stub s;
    lp_stats st = run_for(jitter60, 216000, &s);
    T_EQ(st.ticks, 216000);
    T_ASSERT(fabs(st.seconds - 3600.0) < 0.05);
}

static void t_headless_one_tick_one_frame(void)
{
    stub s = {.max_ticks = 500, .min_alpha = 2, .max_alpha = -1};
    frame_dt = at60;
    lp_game g = {&s, s_input, s_step, s_render, s_running};
    lp_stats st;
    lp_run(&(lp_desc){.headless = true, .now = fake_now}, &g, &st);
    T_EQ(st.ticks, 500);
    T_EQ(st.frames, 500);
    T_ASSERT(s.min_alpha == 1.0f && s.max_alpha == 1.0f);
}

T_MAIN({"steady_60", t_steady_60}, {"jitter_is_not_late", t_jitter_is_not_late}, {"30hz_display", t_30hz_display},
       {"144hz_interpolates", t_144hz_interpolates}, {"stall_is_cut", t_stall_is_cut},
       {"slow_machine_drops_backlog", t_slow_machine_drops_backlog},
       {"no_drift_over_an_hour", t_no_drift_over_an_hour},
       {"headless_one_tick_one_frame", t_headless_one_tick_one_frame})
