/* Destruction holes as game state (runtime/game/g_holes.c, techniques D):
 * placement never overlaps and stays on the ring, at most 30 with the
 * out-of-view ones evicted first, the view test agrees with the renderer's
 * camera, heavy hits make holes only on destructible stages, a new match
 * clears them, and the state hash covers them there and only there.  No GL. */
#include <math.h>
#include <stdlib.h>

#include "../runtime/game/g_game.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_math.h"
#include "../runtime/replay/rp.h"
#include "t.h"

enum { QUARRY = 7 };

static g_state quarry(void)
{
    T_ASSERT(g_stages[QUARRY].destructible && !strcmp(g_stages[QUARRY].name, "quarry"));
    g_state st;
    g_init(&st, QUARRY, 5);
    return st;
}

static unsigned lcg(unsigned *s)
{
    *s = *s * 1103515245u + 12345u;
    return *s >> 8;
}

static void check_invariants(const g_state *st, int line)
{
    fx half = g_stages[st->stage].ring_half;
    T_ASSERTF(st->nholes >= 0 && st->nholes <= G_MAX_HOLES, "line %d: %d holes", line, st->nholes);
    for (int i = 0; i < st->nholes; i++) {
        const g_hole *h = &st->holes[i];
        fx rim = fx_mul(h->r, FX(0.92));
        T_ASSERTF(fx_abs(h->x) + rim < half && fx_abs(h->z) + rim < half, "line %d: hole %d leaves the ring", line, i);
        T_ASSERT(h->r > 0 && h->id > 0 && h->id <= st->hole_seq);
        for (int k = 0; k < i; k++) {
            T_ASSERTF(!g_holes_overlap(h, &st->holes[k]), "line %d: holes %d and %d overlap", line, i, k);
            T_ASSERTF(st->holes[k].id < h->id, "line %d: creation order lost", line);
        }
    }
}

/* Randomized: thousands of craters asked for all over (and off) the ring,
 * with the fighters anywhere; the rules hold after every one. */
static void t_never_overlap_never_off_the_ring(void)
{
    unsigned s = 99;
    for (int trial = 0; trial < 40; trial++) {
        g_state st = quarry();
        int placed = 0;
        for (int k = 0; k < 200; k++) {
            st.f[0].x = (fx)(lcg(&s) % (unsigned)FX(8)) - FX(4);
            st.f[1].x = (fx)(lcg(&s) % (unsigned)FX(8)) - FX(4);
            fx x = (fx)(lcg(&s) % (unsigned)FX(10)) - FX(5), z = (fx)(lcg(&s) % (unsigned)FX(10)) - FX(5);
            fx r = FX(0.2) + (fx)(lcg(&s) % (unsigned)FX(0.8));
            placed += g_hole_add(&st, x, z, r);
            check_invariants(&st, __LINE__);
        }
        T_ASSERT(placed > 30); /* room is found, and the cap is reached */
        T_EQ(st.nholes, G_MAX_HOLES);
        T_EQ(st.hole_seq, placed);
    }
    /* a crater wider than the ring never fits */
    g_state st = quarry();
    T_ASSERT(!g_hole_add(&st, 0, 0, FX(5)));
    T_ASSERT(!g_hole_add(&st, 0, 0, 0));
    T_EQ(st.nholes, 0);
}

/* 30 holes, then more: out-of-view holes go first, oldest first; when all
 * are in view, the oldest. */
static void t_cap_evicts_out_of_view_first(void)
{
    g_state st = quarry();
    st.f[0].x = FX(-1), st.f[1].x = FX(1); /* the camera frames the centre */
    /* fill the ring on a grid of small craters */
    for (int i = 0; i < 6 && st.nholes < G_MAX_HOLES; i++)
        for (int j = 0; j < 6 && st.nholes < G_MAX_HOLES; j++)
            g_hole_add(&st, FX(-3.1) + i * FX(1.24), FX(-3.1) + j * FX(1.24), FX(0.4));
    T_EQ(st.nholes, G_MAX_HOLES);
    int out = 0;
    for (int i = 0; i < st.nholes; i++)
        out += !g_hole_in_view(&st, &st.holes[i]);
    T_ASSERTF(out > 0 && out < G_MAX_HOLES, "%d of 30 out of view: the test needs both kinds", out);
    int first_out = -1;
    for (int i = 0; i < st.nholes && first_out < 0; i++)
        if (!g_hole_in_view(&st, &st.holes[i]))
            first_out = i;
    int32_t gone = st.holes[first_out].id, oldest = st.holes[0].id;
    T_ASSERT(first_out > 0 || !g_hole_in_view(&st, &st.holes[0]));
    /* make room where the evicted one was, so the new one can go there */
    g_hole old = st.holes[first_out];
    T_ASSERT(!g_hole_add(&st, old.x, old.z, old.r)); /* overlaps: refused, nothing evicted */
    T_EQ(st.nholes, G_MAX_HOLES);
    /* a crater somewhere free: ask with a tiny one in the grid's gaps */
    bool added = false;
    for (int i = 0; i < 6 && !added; i++)
        for (int j = 0; j < 6 && !added; j++)
            added = g_hole_add(&st, FX(-2.48) + i * FX(1.24), FX(-2.48) + j * FX(1.24), FX(0.1));
    T_ASSERT(added);
    T_EQ(st.nholes, G_MAX_HOLES);
    for (int i = 0; i < st.nholes; i++)
        T_ASSERTF(st.holes[i].id != gone, "the oldest out-of-view hole (id %d) should have gone", gone);
    if (first_out > 0)
        T_EQ(st.holes[0].id, oldest); /* the oldest stayed: it is in view */
    check_invariants(&st, __LINE__);
    /* everything in view: the oldest goes */
    g_state all = quarry();
    for (int k = 0; k < G_MAX_HOLES; k++) {
        all.holes[k] = (g_hole){FX(-0.3) + (k % 6) * FX(0.12), FX(-0.3) + (k / 6) * FX(0.12), FX(0.01), k + 1};
        T_ASSERT(g_hole_in_view(&all, &all.holes[k]));
    }
    all.nholes = G_MAX_HOLES, all.hole_seq = G_MAX_HOLES;
    T_ASSERT(g_hole_add(&all, FX(2.5), FX(-2.5), FX(0.3)));
    T_EQ(all.holes[0].id, 2);
    T_EQ(all.holes[G_MAX_HOLES - 1].id, G_MAX_HOLES + 1);
}

/* The game's fixed-point view test against the renderer's camera: the
 * crater's centre projected at 16:9 with the crater's radius as margin.
 * They may disagree only within a few centimetres of the frame's edge. */
static void t_in_view_matches_the_camera(void)
{
    unsigned s = 7;
    int agree = 0, n = 0, in = 0;
    for (int k = 0; k < 20000; k++) {
        g_state st = quarry();
        st.f[0].x = (fx)(lcg(&s) % (unsigned)FX(8)) - FX(4);
        st.f[1].x = (fx)(lcg(&s) % (unsigned)FX(8)) - FX(4);
        g_hole h = {(fx)(lcg(&s) % (unsigned)FX(8)) - FX(4), (fx)(lcg(&s) % (unsigned)FX(8)) - FX(4), FX(0.4), 1};
        r_mat4 view, proj;
        r_game_camera_parts(&st, 1600, 900, &view, &proj, NULL);
        /* the renderer: is the centre within the frame grown by the radius
         * (in view space: the same test as the game's, in floats)? */
        r_vec3 p = r_v3(fx_to_float(h.x), 0, fx_to_float(h.z));
        const float *m = view.m;
        float vx = m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12], vy = m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13];
        float vz = -(m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14]);
        float r = fx_to_float(h.r), t = tanf(0.375f);
        bool want = vz > 0.2f && fabsf(vx) - r <= vz * t * 16 / 9 && fabsf(vy) - r <= vz * t;
        bool got = g_hole_in_view(&st, &h);
        /* near the edge (within 5 cm) either answer is fine */
        bool edge = fabsf(fabsf(vx) - r - vz * t * 16 / 9) < 0.05f || fabsf(fabsf(vy) - r - vz * t) < 0.05f;
        if (edge)
            continue;
        n++;
        agree += want == got;
        in += want;
    }
    fprintf(stderr, "    %d of %d agree (%d in view)\n", agree, n, in);
    T_EQ(agree, n);
    T_ASSERT(in > n / 10 && in < n * 9 / 10);
}

/* The quarry demo: knockdowns make holes, a new match clears them, and
 * only a destructible stage's hash covers holes. */
static void t_heavy_hits_make_holes_in_the_demo(void)
{
    rp_replay rp;
    rs_err e = {0};
    T_ASSERTF(rp_read(RS_SOURCE_DIR "/demos/quarry.rsr", &rp, &e), "%s", e.msg);
    T_EQ(rp.stage, QUARRY);
    g_state st;
    g_init(&st, rp.stage, rp.seed);
    int knockdowns = 0, made = 0;
    for (uint64_t t = 0; t < rp.ticks; t++) {
        g_events ev = {0};
        int before = st.hole_seq;
        g_step(&st, &rp.inputs[2 * t], &ev);
        for (int k = 0; k < ev.n; k++)
            knockdowns += ev.ev[k].type == G_EV_KNOCKDOWN;
        made += st.hole_seq - before;
        check_invariants(&st, __LINE__);
    }
    fprintf(stderr, "    quarry demo: %d knockdowns, %d holes\n", knockdowns, made);
    T_ASSERT(made >= 5 && made <= knockdowns);
    /* the hash covers the holes here */
    g_state a = st, b = st;
    T_ASSERT(a.nholes > 0);
    b.holes[0].r += 1;
    T_ASSERT(g_hash(&a) != g_hash(&b));
    /* but not on another stage, where there are none: the old hashes stay */
    g_state d1, d2;
    g_init(&d1, 0, 1);
    d2 = d1;
    d2.nholes = 1, d2.holes[0] = (g_hole){1, 2, 3, 4};
    T_EQ(g_hash(&d1), g_hash(&d2));
    /* a new match clears them */
    g_state n = st;
    g_input in[2] = {0, 0};
    for (int k = 0; k < 100000 && !(n.matches > st.matches && n.phase == G_PHASE_INTRO); k++)
        g_step(&n, in, NULL);
    T_ASSERT(n.matches > st.matches && n.phase == G_PHASE_INTRO);
    T_EQ(n.nholes, 0);
    T_EQ(n.hole_seq, 0);
    rp_free(&rp);
    /* and no other stage makes holes */
    for (int s = 0; s < G_STAGES; s++)
        T_ASSERT(g_stages[s].destructible == (s == QUARRY));
}

T_MAIN({"never_overlap_never_off_the_ring", t_never_overlap_never_off_the_ring},
       {"cap_evicts_out_of_view_first", t_cap_evicts_out_of_view_first},
       {"in_view_matches_the_camera", t_in_view_matches_the_camera},
       {"heavy_hits_make_holes_in_the_demo", t_heavy_hits_make_holes_in_the_demo})
