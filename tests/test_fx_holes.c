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

/* Is (x, y) inside the convex polygon of n points (either winding)? */
static bool in_polygon(const float (*pt)[2], int n, float x, float y)
{
    int pos = 0, neg = 0;
    for (int k = 0; k < n; k++) {
        const float *a = pt[k], *b = pt[(k + 1) % n];
        float c = (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
        pos += c > 0, neg += c < 0;
    }
    return pos == 0 || neg == 0;
}

enum { RIM_W = 640, RIM_H = 360, RIM_PTS = 96 };

/* Which rims' projected circles hold pixel (x, y) (bottom-up, centre at
 * +0.5) and all 8 points 1.5 pixels round it (1), none of them (-1), or
 * some (0: too near a rim to say). */
static int rim_side(const float (*rim)[RIM_PTS][2], const float (*box)[4], int nholes, int x, int y)
{
    static const float d[9][2] = {{0, 0}, {1.5f, 0}, {-1.5f, 0}, {0, 1.5f}, {0, -1.5f},
                                  {1.06f, 1.06f}, {1.06f, -1.06f}, {-1.06f, 1.06f}, {-1.06f, -1.06f}};
    float cx = (float)x + 0.5f, cy = (float)y + 0.5f;
    int in = 0;
    for (int k = 0; k < 9; k++)
        for (int i = 0; i < nholes; i++) {
            float px = cx + d[k][0], py = cy + d[k][1];
            if (px >= box[i][0] && px <= box[i][2] && py >= box[i][1] && py <= box[i][3] &&
                in_polygon(rim[i], RIM_PTS, px, py)) {
                in++;
                break;
            }
        }
    return in == 9 ? 1 : in == 0 ? -1 : 0;
}

/* The crater's rim is the sphere's circle on the floor, radius
 * sqrt(1 - 0.4^2) r: the sphere's mesh has a row of vertices on it at both
 * levels of detail (the coarse one below 540 rows drawn, the fine one the
 * options ask for).  At 640x360, every ring-top pixel 1.5 pixels or more
 * inside a rim's projected circle is cut (deeper than without the holes),
 * and none 1.5 pixels or more outside every rim. */
static void t_rims_are_circles(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, RIM_W, RIM_H);
    r_stage st = quarry();
    g_state prev, cur;
    t_state_at("quarry", TICK, &prev, &cur);
    static float rim[G_MAX_HOLES][RIM_PTS][2], box[G_MAX_HOLES][4];
    r_mat4 vp = r_game_camera(&cur, RIM_W, RIM_H, NULL);
    for (int i = 0; i < cur.nholes; i++) {
        const g_hole *h = &cur.holes[i];
        float rr = sqrtf(1 - 0.4f * 0.4f) * fx_to_float(h->r);
        for (int k = 0; k < RIM_PTS; k++) {
            float a = (float)k * 6.2831853f / RIM_PTS;
            r_vec3 q = r_v3(fx_to_float(h->x) + rr * cosf(a), 0, fx_to_float(h->z) + rr * sinf(a));
            T_ASSERTF(r_project(vp, q, RIM_W, RIM_H, &rim[i][k][0], &rim[i][k][1]), "hole %d behind the eye", i);
        }
        box[i][0] = box[i][1] = 1e9f, box[i][2] = box[i][3] = -1e9f;
        for (int k = 0; k < RIM_PTS; k++)
            for (int a = 0; a < 2; a++)
                box[i][a] = fminf(box[i][a], rim[i][k][a]), box[i][a + 2] = fmaxf(box[i][a + 2], rim[i][k][a]);
    }
    for (int fine = 0; fine < 2; fine++) {
        r_game *r = t_game_opts(&(r_game_opts){.mask = true, .fine_mesh = fine == 1});
        g_state p0 = prev, c0 = cur;
        p0.nholes = c0.nholes = 0;
        t_draw_read(r, &f, &p0, &c0, RIM_W, RIM_H, NULL, false);
        float *doff = t_read(r, "depth", 1, RIM_W, RIM_H), *hoff = t_read(r, "hdr", 4, RIM_W, RIM_H);
        rs_err e = {0};
        T_ASSERTF(r_game_set_stage(r, &st, &e), "%s", e.msg);
        t_draw_read(r, &f, &prev, &cur, RIM_W, RIM_H, NULL, false);
        T_EQ(fx_holes_drawn(r), cur.nholes);
        float *don = t_read(r, "depth", 1, RIM_W, RIM_H);
        int inside = 0, missed = 0, outside = 0, stray = 0;
        for (int y = 0; y < RIM_H; y++)
            for (int x = 0; x < RIM_W; x++) {
                size_t i = (size_t)y * RIM_W + x;
                if (hoff[4 * i + 3] != 0) /* a fighter in front */
                    continue;
                int side = rim_side((const float(*)[RIM_PTS][2])rim, (const float(*)[4])box, cur.nholes, x, y);
                bool cut = don[i] > doff[i];
                inside += side == 1, missed += side == 1 && !cut;
                outside += side == -1, stray += side == -1 && cut;
            }
        fprintf(stderr, "    %s mesh: %d pixels surely inside a rim, %d of them not cut; %d surely outside, %d cut\n",
                fine ? "fine" : "coarse", inside, missed, outside, stray);
        T_ASSERTF(inside > 5000, "only %d pixels inside the rims", inside);
        T_ASSERTF(missed == 0 && stray == 0, "%s mesh: %d pixels inside a rim not cut, %d outside cut",
                  fine ? "fine" : "coarse", missed, stray);
        free(doff), free(hoff), free(don);
        r_game_destroy(r);
    }
    t_fb_free(&f);
    plat_destroy(p);
}

T_MAIN({"holes_cut_the_ring_only_there", t_holes_cut_the_ring_only_there}, {"rims_are_circles", t_rims_are_circles},
       {"thirty_holes_and_extremes", t_thirty_holes_and_extremes})
