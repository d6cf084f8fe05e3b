/* cmd/job_poster: the poster frame's choice on the demos (it shows what
 * it says it shows), the fallbacks, and --ticks deciding which render
 * writes it.  (tests/test_poster.sh renders one.) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../cmd/job_poster.h"
#include "t.h"

static const char *const demos[] = {"dojo", "harbor", "mistvale", "plaza", "quarry", "shallows", "snowfield", "temple"};

static void read_demo(const char *name, rp_replay *rp)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/demos/%s.rsr", RS_SOURCE_DIR, name);
    rs_err e = {0};
    T_ASSERTF(rp_read(path, rp, &e), "%s", e.msg);
}

/* The state whose frame is frame `tick` (after tick + 1 steps). */
static void state_at(const rp_replay *rp, uint64_t tick, g_state *st)
{
    g_init(st, rp->stage, rp->seed);
    for (uint64_t t = 0; t <= tick; t++)
        g_step(st, &rp->inputs[2 * t], NULL);
}

static void t_demos_show_the_end(void)
{
    int kos = 0;
    for (size_t i = 0; i < sizeof demos / sizeof *demos; i++) {
        rp_replay rp = {0};
        read_demo(demos[i], &rp);
        int why = -1;
        uint64_t tick = job_poster_tick(&rp, &why);
        T_ASSERTF(tick < rp.ticks, "%s: tick %llu of %llu", demos[i], (unsigned long long)tick,
                  (unsigned long long)rp.ticks);
        g_state st;
        state_at(&rp, tick, &st);
        printf("  %s: frame %llu of %llu, %s\n", demos[i], (unsigned long long)tick, (unsigned long long)rp.ticks,
               job_poster_why_name(why));
        if (why == JOB_POSTER_KO) {
            /* the fallen fighter is down, the round is over */
            kos++;
            T_ASSERTF(st.f[0].move == G_MV_KO || st.f[1].move == G_MV_KO, "%s: nobody lies KO at frame %llu", demos[i],
                      (unsigned long long)tick);
            T_ASSERTF(st.phase == G_PHASE_ROUND_END || st.phase == G_PHASE_MATCH_END, "%s: phase %d", demos[i],
                      st.phase);
        } else if (why == JOB_POSTER_RING_OUT)
            T_ASSERTF(st.phase == G_PHASE_ROUND_END || st.phase == G_PHASE_MATCH_END, "%s: phase %d", demos[i],
                      st.phase);
        else if (why == JOB_POSTER_MATCH_END)
            T_EQ(st.phase, G_PHASE_MATCH_END);
        else
            T_EQ(tick, rp.ticks / 2);
        /* a finished demo never falls back to the middle */
        if (rp.winner >= 0)
            T_ASSERTF(why != JOB_POSTER_MIDDLE, "%s: finished (winner %d) but poster at the middle", demos[i], rp.winner);
        rp_free(&rp);
    }
    T_ASSERTF(kos > 0, "no demo ends in a KO: the KO case went untested");
}

/* The last knock-out, not the first: later ticks end later rounds. */
static void t_last_ko_not_first(void)
{
    rp_replay rp = {0};
    read_demo("dojo", &rp);
    int why;
    uint64_t full = job_poster_tick(&rp, &why);
    g_state st;
    g_init(&st, rp.stage, rp.seed);
    uint64_t first_end = 0;
    for (uint64_t t = 0; t < rp.ticks && !first_end; t++) {
        g_events ev = {0};
        g_step(&st, &rp.inputs[2 * t], &ev);
        for (int k = 0; k < ev.n; k++)
            if (ev.ev[k].type == G_EV_KO || ev.ev[k].type == G_EV_RING_OUT || ev.ev[k].type == G_EV_TIME_UP)
                first_end = t;
    }
    T_ASSERT(first_end > 0);
    if (st.round < 2 && rp.rounds[0] + rp.rounds[1] < 2)
        T_SKIP_ENV("dojo has one round only");
    T_ASSERTF(full > first_end + JOB_POSTER_AFTER_KO, "poster frame %llu is the first round's end (%llu)",
              (unsigned long long)full, (unsigned long long)first_end);
    rp_free(&rp);
}

/* Cut before any round ends: the middle; cut just after a KO: clamped
 * to the last tick. */
static void t_fallbacks(void)
{
    rp_replay rp = {0};
    read_demo("dojo", &rp);
    uint64_t all = rp.ticks;
    int why;
    rp.ticks = 600; /* 10 s: still in the first round */
    T_EQ(job_poster_tick(&rp, &why), 300);
    T_EQ(why, JOB_POSTER_MIDDLE);
    rp.ticks = all;
    uint64_t full = job_poster_tick(&rp, &why);
    if ((why == JOB_POSTER_KO || why == JOB_POSTER_RING_OUT) && full + 1 < all) { /* not itself clamped */
        rp.ticks = full - JOB_POSTER_AFTER_KO + 5; /* 5 frames after the KO */
        T_EQ(job_poster_tick(&rp, &why), rp.ticks - 1);
    }
    rp.ticks = all;
    rp_free(&rp);
}

/* --ticks: only the range that holds the frame writes it. */
static void t_plan_by_range(void)
{
    rp_replay rp = {0};
    read_demo("dojo", &rp);
    rs_err e = {0};
    job_poster p;
    T_ASSERT(job_poster_plan(&p, NULL, &rp, 0, rp.ticks, &e));
    T_ASSERT(!p.due);
    T_ASSERTF(job_poster_plan(&p, "x.png", &rp, 0, rp.ticks, &e), "%s", e.msg);
    T_ASSERT(p.due);
    uint64_t at = p.tick;
    T_ASSERT(job_poster_plan(&p, "x.png", &rp, at, at + 1, &e) && p.due);
    T_ASSERT(job_poster_plan(&p, "x.png", &rp, 0, at, &e) && !p.due);
    T_ASSERT(at + 1 == rp.ticks || (job_poster_plan(&p, "x.png", &rp, at + 1, rp.ticks, &e) && !p.due));
    T_ASSERT(!job_poster_plan(&p, "/nonexistent-dir/x.png", &rp, 0, rp.ticks, &e));
    T_CONTAINS(e.msg, "x.png: the folder /nonexistent-dir does not exist");
    rp_free(&rp);
}

T_MAIN({"demos_show_the_end", t_demos_show_the_end}, {"last_ko_not_first", t_last_ko_not_first},
       {"fallbacks", t_fallbacks}, {"plan_by_range", t_plan_by_range})
