/* The stage effects as a whole (runtime/render/r_fx.c, runtime/fx/) and the afterimage
 * motion blur: every effect's passes run only on stages that ask for the
 * effect, and the afterimage shows behind fast limbs, never over the
 * fighters.  Each effect's own tests are in tests/test_fx_<effect>.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_fx.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_stage.h"
#include "../runtime/replay/rp.h"
#include "t.h"
#include "t_render.h"

enum { W = 320, H = 180 };

static void load_stage(r_stage *st, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, RS_SOURCE_DIR "/stages/%s.stage", name);
    rs_err e = {0};
    T_ASSERTF(r_stage_load(st, path, &e), "%s", e.msg);
}

/* Does the stage ask for the module's effect? */
static bool wants(const r_stage *st, const char *module)
{
    if (!strcmp(module, "water"))
        return st->water;
    if (!strcmp(module, "snow"))
        return st->snow;
    if (!strcmp(module, "fog"))
        return st->fog;
    if (!strcmp(module, "afterimage"))
        return st->afterimage != R_AFTERIMAGE_OFF;
    if (!strcmp(module, "holes"))
        return st->holes;
    if (!strcmp(module, "lspsm")) /* the map and its focus; the buildings pass draws buildings */
        return st->lspsm || st->buildings > 0;
    T_ASSERTF(false, "unknown effect module '%s': add it here", module);
    return false;
}

/* "A stage without an effect runs none of its passes": every shipped
 * stage, a few frames of a fight, with the effects of every other stage
 * switched on in turn only where the stage asks for them. */
static void t_effects_run_only_where_asked(void)
{
    plat *p = t_context("egl");
    static const char *const stages[] = {"dojo", "harbor", "temple", "sunless", "shallows", "snowfield", "mistvale", "plaza", "quarry"};
    t_fb f;
    t_fb_make(&f, W, H);
    int ran_somewhere[16] = {0};
    for (size_t s = 0; s < sizeof stages / sizeof stages[0]; s++) {
        r_stage st;
        load_stage(&st, stages[s]);
        r_game *r = t_game_new(false);
        rs_err e = {0};
        T_ASSERTF(r_game_set_stage(r, &st, &e), "%s", e.msg);
        g_state prev, cur;
        /* holes are game state: the quarry demo's own match has them */
        t_state_at(st.holes ? "quarry" : "dojo", st.holes ? 3000 : 400, &prev, &cur);
        for (int k = 0; k < 10; k++) { /* ticks 400..409: fast limbs among them */
            t_draw(r, &f, &prev, &cur, W, H);
            for (int m = 0; m < r_fx_nmodules; m++) {
                const r_fx_module *mod = r_fx_modules[m];
                for (int ph = 0; ph < R_FX_PHASES; ph++)
                    for (int i = 0; i < mod->npass[ph]; i++) {
                        bool ran = t_pass_ran(r, mod->pass[ph][i].name);
                        T_ASSERTF(!ran || wants(&st, mod->name), "stage %s ran pass '%s' of effect %s it does not use",
                                  stages[s], mod->pass[ph][i].name, mod->name);
                        ran_somewhere[m] |= ran;
                    }
            }
            g_state next = cur;
            g_input in[2] = {0, 0};
            g_step(&next, in, NULL);
            prev = cur, cur = next;
        }
        r_game_destroy(r);
    }
    /* and each effect does run somewhere (or the check above proves nothing) */
    for (int m = 0; m < r_fx_nmodules; m++) {
        int n = 0;
        for (int ph = 0; ph < R_FX_PHASES; ph++)
            n += r_fx_modules[m]->npass[ph];
        T_ASSERTF(n == 0 || ran_somewhere[m], "effect %s never ran on the stage that asks for it", r_fx_modules[m]->name);
    }
    t_fb_free(&f);
    plat_destroy(p);
}

/* The HDR buffer (rgba, bottom-up) of a frame of the dojo demo, with the
 * afterimage mode given. */
static float *hdr_frame(r_game *r, t_fb *f, r_afterimage mode, const g_state *prev, const g_state *cur)
{
    r_stage st;
    load_stage(&st, "dojo");
    st.afterimage = mode;
    rs_err e = {0};
    T_ASSERTF(r_game_set_stage(r, &st, &e), "%s", e.msg);
    t_draw(r, f, prev, cur, W, H);
    float *px = malloc((size_t)W * H * 4 * sizeof *px);
    T_ASSERT(px);
    int w = 0, h = 0;
    T_ASSERT(r_game_read_buffer(r, "hdr", px, &w, &h));
    T_EQ(w, W);
    T_EQ(h, H);
    return px;
}

/* The pass draws only the fast bones' runs of the mesh's indices: the
 * same bytes as the whole mesh with the vertex shader clipping the slow
 * ones (r_game_opts.whole_meshes), on frames where some bones are fast
 * and some are not. */
static void t_afterimage_by_bone_ranges(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    static const uint64_t ticks[] = {408, 1500, 2200};
    int runs = 0;
    for (size_t k = 0; k < sizeof ticks / sizeof ticks[0]; k++) {
        g_state prev, cur;
        t_state_at("dojo", ticks[k], &prev, &cur);
        float *img[2];
        bool ran[2];
        for (int whole = 0; whole < 2; whole++) {
            r_game *r = t_game_opts(&(r_game_opts){.mask = true, .whole_meshes = whole == 1});
            img[whole] = hdr_frame(r, &f, R_AFTERIMAGE_VIEW, &prev, &cur);
            ran[whole] = t_pass_ran(r, "afterimage");
            r_game_destroy(r);
        }
        T_EQ(ran[0], ran[1]);
        runs += ran[0];
        T_ASSERTF(!memcmp(img[0], img[1], (size_t)W * H * 4 * sizeof(float)),
                  "dojo@%llu: the bones' ranges draw other pixels than the whole mesh", (unsigned long long)ticks[k]);
        free(img[0]), free(img[1]);
    }
    fprintf(stderr, "    the pass ran on %d of 3 frames\n", runs);
    T_ASSERTF(runs > 0, "the pass never ran");
    t_fb_free(&f);
    plat_destroy(p);
}

/* Tick 408 of the dojo demo: a blow lands, limbs move fast. */
static void t_afterimage_trails_fast_limbs_only(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    g_state prev, cur;
    t_state_at("dojo", 408, &prev, &cur);
    r_game *r = t_game_new(true); /* mask mode: HDR alpha = the fighters' mask */
    float *off = hdr_frame(r, &f, R_AFTERIMAGE_OFF, &prev, &cur);
    T_ASSERT(!t_pass_ran(r, "afterimage"));
    float *on = hdr_frame(r, &f, R_AFTERIMAGE_VIEW, &prev, &cur);
    T_ASSERT(t_pass_ran(r, "afterimage"));
    float *world = hdr_frame(r, &f, R_AFTERIMAGE_WORLD, &prev, &cur);
    T_ASSERT(t_pass_ran(r, "afterimage"));
    int changed = 0, over_fighter = 0, alpha_changed = 0, changed_world = 0, bad = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        const float *a = off + 4 * i, *b = on + 4 * i, *c = world + 4 * i;
        float d = fabsf(a[0] - b[0]) + fabsf(a[1] - b[1]) + fabsf(a[2] - b[2]);
        if (d > 1e-3f)
            changed++;
        if (fabsf(a[0] - c[0]) + fabsf(a[1] - c[1]) + fabsf(a[2] - c[2]) > 1e-3f)
            changed_world++;
        if (a[3] > 0.99f && d > 0) /* a fighter's pixel: the copy stays behind the model */
            over_fighter++;
        if (a[3] != b[3])
            alpha_changed++;
        for (int k = 0; k < 4; k++)
            bad += !isfinite(b[k]) || !isfinite(c[k]);
    }
    fprintf(stderr, "    afterimage: %d pixels changed (view space), %d (world space); %d over the fighters\n", changed,
            changed_world, over_fighter);
    T_ASSERTF(changed > 40, "only %d pixels changed: no visible afterimage", changed);
    T_ASSERTF(changed_world > 40, "only %d pixels changed in world space", changed_world);
    T_ASSERTF(changed < W * H / 10, "%d pixels changed: the copy is far too big", changed);
    T_EQ(over_fighter, 0);
    T_EQ(alpha_changed, 0); /* the blend keeps the mask */
    T_EQ(bad, 0);
    free(off), free(on), free(world);

    /* the same tick drawn again: nothing moved since, no pass */
    float *still = hdr_frame(r, &f, R_AFTERIMAGE_VIEW, &cur, &cur);
    T_ASSERT(!t_pass_ran(r, "afterimage"));
    free(still);
    /* a threshold above every limb's speed: no pass */
    r_stage st;
    load_stage(&st, "dojo");
    st.afterimage_speed = 1000;
    rs_err e = {0};
    T_ASSERTF(r_game_set_stage(r, &st, &e), "%s", e.msg);
    t_draw(r, &f, &prev, &cur, W, H);
    T_ASSERT(!t_pass_ran(r, "afterimage"));
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* A stretch of 8 with the fastest blow of the demo: still finite, still
 * only where the limbs were. */
static void t_afterimage_extremes(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    g_state prev, cur;
    t_state_at("dojo", 408, &prev, &cur);
    r_game *r = t_game_new(false);
    r_stage st;
    load_stage(&st, "dojo");
    st.afterimage_stretch = 8, st.afterimage_speed = 0;
    rs_err e = {0};
    T_ASSERTF(r_game_set_stage(r, &st, &e), "%s", e.msg);
    /* a teleport: the previous tick's state has the fighters 3 m away */
    g_state far = prev;
    far.f[0].x += FX(3.0), far.f[1].x -= FX(3.0);
    t_draw(r, &f, &far, &cur, W, H);
    T_ASSERT(t_pass_ran(r, "afterimage"));
    float *px = malloc((size_t)W * H * 4 * sizeof *px);
    T_ASSERT(px && r_game_read_buffer(r, "hdr", px, NULL, NULL));
    int bad = 0;
    for (size_t i = 0; i < (size_t)W * H * 4; i++)
        bad += !isfinite(px[i]) || px[i] < 0 || px[i] > 65504;
    T_EQ(bad, 0);
    free(px);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* One renderer going from stage to stage draws what a fresh one draws:
 * no effect leaves state behind (the water's mirrored sky once kept the
 * fog of the stage before). */
static void t_stage_switch_leaves_nothing_behind(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    g_state prev, cur;
    t_state_at("dojo", 408, &prev, &cur);
    static const char *const order[] = {"mistvale", "shallows", "snowfield", "mistvale", "dojo"};
    r_game *shared = t_game_new(false);
    for (size_t i = 0; i < sizeof order / sizeof order[0]; i++) {
        r_stage st;
        load_stage(&st, order[i]);
        rs_err e = {0};
        T_ASSERTF(r_game_set_stage(shared, &st, &e), "%s", e.msg);
        t_draw(shared, &f, &prev, &cur, W, H);
        float *a = malloc((size_t)W * H * 4 * sizeof *a), *b = malloc((size_t)W * H * 4 * sizeof *b);
        T_ASSERT(a && b && r_game_read_buffer(shared, "hdr", a, NULL, NULL));
        r_game *fresh = t_game_new(false);
        T_ASSERTF(r_game_set_stage(fresh, &st, &e), "%s", e.msg);
        t_draw(fresh, &f, &prev, &cur, W, H);
        T_ASSERT(r_game_read_buffer(fresh, "hdr", b, NULL, NULL));
        int differ = 0;
        for (size_t k = 0; k < (size_t)W * H * 4; k++)
            differ += a[k] != b[k];
        T_ASSERTF(differ == 0, "%s after %s: %d values differ from a fresh renderer's", order[i], i ? order[i - 1] : "-",
                  differ);
        r_game_destroy(fresh);
        free(a), free(b);
    }
    r_game_destroy(shared);
    t_fb_free(&f);
    plat_destroy(p);
}

static void t_empty_frame_is_refused(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    t_state_at("shallows", 300, &prev, &cur);
    r_game *r = t_game_new(false);
    rs_err e = {0};
    T_ASSERT(!r_game_draw(r, &prev, &cur, 1.0f, 0, 0, &e));
    T_CONTAINS(e.msg, "cannot draw a 0x0 frame");
    T_EQ(e.code, R_ERR_SIZE);
    rs_err_clear(&e);
    T_ASSERT(!r_game_draw(r, &prev, &cur, 1.0f, 64, -1, &e));
    T_EQ(e.code, R_ERR_SIZE);
    T_EQ(gl.GetError(), GL_NO_ERROR);
    r_game_destroy(r);
    plat_destroy(p);
}

/* Fighter i's screen box at W x H (bottom-up rows): its bones' ends
 * projected, grown by the widest bone's radius and 3 pixels. */
static void fighter_box(const g_state *st, int i, int box[4])
{
    r_mat4 vp = r_game_camera(st, W, H, NULL);
    g_capsule c[G_BONES];
    g_fighter_capsules(st, i, c);
    float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f, grow = 0;
    for (int k = 0; k < G_BONES; k++)
        for (int e = 0; e < 2; e++) {
            float z = fx_to_float(c[k].z) * (float)st->f[i].facing, x, y;
            r_vec3 w = r_v3(fx_to_float(e ? c[k].bx : c[k].ax), fx_to_float(e ? c[k].by : c[k].ay), z);
            T_ASSERT(r_project(vp, w, W, H, &x, &y));
            float x2, y2; /* a radius's length on screen, at this depth */
            T_ASSERT(r_project(vp, r_v3(w.x, w.y + fx_to_float(c[k].r), w.z), W, H, &x2, &y2));
            grow = fmaxf(grow, fabsf(y2 - y));
            x0 = fminf(x0, x), x1 = fmaxf(x1, x), y0 = fminf(y0, y), y1 = fmaxf(y1, y);
        }
    box[0] = (int)floorf(x0 - grow) - 3, box[1] = (int)floorf(y0 - grow) - 3;
    box[2] = (int)ceilf(x1 + grow) + 3, box[3] = (int)ceilf(y1 + grow) + 3;
}

static bool in_box(const int b[4], int x, int y) { return x >= b[0] && x <= b[2] && y >= b[1] && y <= b[3]; }

/* Tick 1005 of the dojo demo: P2 slides out of the ring while P1 stands
 * (its bones move 0.1 m/s), and the camera follows P2 (P1's bones move
 * 3 m/s in view space).  A fighter standing still leaves no copy in either
 * mode: the camera's motion used to put one beside P1's head and body.
 * P2, moving, does leave one. */
static void t_afterimage_still_fighter_leaves_none(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    g_state prev, cur;
    t_state_at("dojo", 1005, &prev, &cur);
    r_game *r = t_game_new(true);
    int still[4], moving[4];
    fighter_box(&cur, 0, still);
    fighter_box(&cur, 1, moving);
    float *off = hdr_frame(r, &f, R_AFTERIMAGE_OFF, &prev, &cur);
    for (r_afterimage mode = R_AFTERIMAGE_VIEW; mode <= R_AFTERIMAGE_WORLD; mode++) {
        float *on = hdr_frame(r, &f, mode, &prev, &cur);
        int by_still = 0, by_moving = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                const float *a = off + 4 * ((size_t)y * W + x), *b = on + 4 * ((size_t)y * W + x);
                if (!memcmp(a, b, 3 * sizeof *a))
                    continue;
                by_moving += in_box(moving, x, y);
                by_still += in_box(still, x, y) && !in_box(moving, x, y);
            }
        fprintf(stderr, "    %s: %d pixels changed by the standing fighter, %d by the moving one\n",
                mode == R_AFTERIMAGE_VIEW ? "view" : "world", by_still, by_moving);
        T_ASSERTF(by_still == 0, "the standing fighter leaves an afterimage over %d pixels", by_still);
        T_ASSERTF(by_moving > 20, "the moving fighter leaves only %d pixels of afterimage", by_moving);
        free(on);
    }
    free(off);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

T_MAIN({"stage_switch_leaves_nothing_behind", t_stage_switch_leaves_nothing_behind},
       {"empty_frame_is_refused", t_empty_frame_is_refused},
       {"effects_run_only_where_asked", t_effects_run_only_where_asked},
       {"afterimage_trails_fast_limbs_only", t_afterimage_trails_fast_limbs_only},
       {"afterimage_extremes", t_afterimage_extremes}, {"afterimage_by_bone_ranges", t_afterimage_by_bone_ranges},
       {"afterimage_still_fighter_leaves_none", t_afterimage_still_fighter_leaves_none})
