/* Destruction holes on GL (runtime/fx/fx_holes.c, techniques D): the
 * craters change the picture only inside their rims, force their depth
 * into the depth buffer (deeper than the ring top), never cover a fighter
 * (the fighters are drawn after them: the mask is unchanged), 30 holes
 * draw, fp16 extremes stay finite, and a stage without `holes = yes`
 * draws none.  The game side is tests/test_holes.c.  T_DUMP=DIR writes
 * the frames as PPM. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/fx/fx_holes.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_stage.h"
#include "t.h"
#include "t_render.h"

enum { W = 320, H = 180 };
#define TICK 3000 /* of the quarry demo: nine holes, both fighters up */

static r_stage quarry(void)
{
    r_stage st;
    rs_err e = {0};
    T_ASSERTF(r_stage_load(&st, RS_SOURCE_DIR "/stages/quarry.stage", &e), "%s", e.msg);
    T_ASSERT(st.holes);
    return st;
}

static void draw(r_game *r, t_fb *f, const r_stage *st, const g_state *prev, const g_state *cur)
{
    rs_err e = {0};
    T_ASSERTF(r_game_set_stage(r, st, &e), "%s", e.msg);
    t_draw(r, f, prev, cur, W, H);
}

static float *read(r_game *r, const char *what, int channels)
{
    return t_read(r, what, channels, W, H);
}

static void dump(const char *name, const float *px)
{
    char n[64];
    snprintf(n, sizeof n, "holes_%s", name);
    t_dump_hdr(n, px, W, H);
}

/* Is pixel (x, y) (bottom-up) within a hole's rim, grown by `grow` pixels?
 * The rim circles projected as polygons of 48 points, their screen boxes. */
static bool in_some_rim(const g_state *st, int x, int y, float grow)
{
    r_mat4 vp = r_game_camera(st, W, H, NULL);
    for (int i = 0; i < st->nholes; i++) {
        const g_hole *h = &st->holes[i];
        float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f, rad = fx_to_float(h->r);
        for (int k = 0; k < 48; k++) {
            float a = (float)k * 6.2831853f / 48, sx, sy;
            /* the sphere's widest circle (r, 0.4 r above the floor) and its rim on the floor */
            for (int level = 0; level < 2; level++) {
                float rr = level ? rad : 0.92f * rad, yy = level ? 0.4f * rad : 0;
                r_vec3 p = r_v3(fx_to_float(h->x) + rr * cosf(a), yy, fx_to_float(h->z) + rr * sinf(a));
                if (!r_project(vp, p, W, H, &sx, &sy))
                    return true; /* behind the eye: no bound, count it in */
                x0 = fminf(x0, sx), y0 = fminf(y0, sy), x1 = fmaxf(x1, sx), y1 = fmaxf(y1, sy);
            }
        }
        if (x >= x0 - grow && x <= x1 + grow && y >= y0 - grow && y <= y1 + grow)
            return true;
    }
    return false;
}

/* The holes against the same state without them: changes only within the
 * rims, depth deeper there, the fighters' mask untouched. */
static void t_holes_cut_the_ring_only_there(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = t_game_new(true); /* mask mode: HDR alpha = the fighters */
    r_stage st = quarry();
    g_state prev, cur;
    t_state_at("quarry", TICK, &prev, &cur);
    T_ASSERTF(cur.nholes >= 5, "%d holes at tick %d", cur.nholes, TICK);
    draw(r, &f, &st, &prev, &cur);
    T_ASSERT(t_pass_ran(r, "holes"));
    T_EQ(fx_holes_drawn(r), cur.nholes);
    float *on = read(r, "hdr", 4), *don = read(r, "depth", 1);
    g_state p0 = prev, c0 = cur;
    p0.nholes = c0.nholes = 0;
    draw(r, &f, &st, &p0, &c0);
    T_ASSERT(!t_pass_ran(r, "holes"));
    float *off = read(r, "hdr", 4), *doff = read(r, "depth", 1);
    dump("on", on), dump("off", off);
    int changed = 0, outside = 0, deeper = 0, mask = 0, bad = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + x;
            const float *a = on + 4 * i, *b = off + 4 * i;
            bool d = fabsf(a[0] - b[0]) + fabsf(a[1] - b[1]) + fabsf(a[2] - b[2]) > 1e-3f;
            for (int c = 0; c < 4; c++)
                bad += !isfinite(a[c]);
            mask += a[3] != b[3];
            if (!d)
                continue;
            changed++;
            outside += !in_some_rim(&cur, x, y, 2);
            deeper += don[i] > doff[i];
        }
    fprintf(stderr, "    %d holes: %d pixels changed, %d of them deeper, %d outside the rims; mask changed in %d\n",
            cur.nholes, changed, deeper, outside, mask);
    T_EQ(bad, 0);
    T_ASSERTF(changed > 500, "only %d pixels changed: no visible holes", changed);
    T_ASSERTF(outside <= changed / 100, "%d changed pixels lie outside every hole", outside);
    T_ASSERTF(deeper >= changed * 9 / 10, "the craters' depth is not in the depth buffer (%d of %d deeper)", deeper,
              changed);
    T_EQ(mask, 0); /* the fighters are drawn after the holes, over them */
    free(on), free(off), free(don), free(doff);

    /* the look without holes draws none, whatever the game state */
    st.holes = false;
    draw(r, &f, &st, &prev, &cur);
    T_ASSERT(!t_pass_ran(r, "holes"));
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* 30 holes (the cap) all over the ring, and fp16 extremes: everything
 * drawn, nothing but finite values. */
static void t_thirty_holes_and_extremes(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = t_game_new(false);
    r_stage st = quarry();
    g_state prev, cur;
    t_state_at("quarry", TICK, &prev, &cur);
    cur.nholes = 0, cur.hole_seq = 0;
    for (int i = 0; i < 8 && cur.nholes < G_MAX_HOLES; i++)
        for (int j = 0; j < 8 && cur.nholes < G_MAX_HOLES; j++)
            g_hole_add(&cur, FX(-3.3) + i * FX(0.95), FX(-3.3) + j * FX(0.95), FX(0.42));
    T_EQ(cur.nholes, G_MAX_HOLES);
    prev.nholes = 0;
    for (int pass = 0; pass < 2; pass++) {
        if (pass)
            t_stage_extremes(&st);
        draw(r, &f, &st, &prev, &cur);
        T_ASSERT(t_pass_ran(r, "holes"));
        T_EQ(fx_holes_drawn(r), G_MAX_HOLES);
        float *px = read(r, "hdr", 4);
        dump(pass ? "thirty_extreme" : "thirty", px);
        int bad = 0;
        for (size_t i = 0; i < (size_t)W * H * 4; i++)
            bad += !isfinite(px[i]) || px[i] < 0;
        T_EQ(bad, 0);
        free(px);
    }
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

T_MAIN({"holes_cut_the_ring_only_there", t_holes_cut_the_ring_only_there},
       {"thirty_holes_and_extremes", t_thirty_holes_and_extremes})
