/* The stage effects' history hooks (runtime/render/r_fx.h): on each stage
 * with a stateful effect, advancing ticks 0..A-1 through r_game_advance
 * and drawing tick A gives the frame that drawing ticks 0..A gives, bit for
 * bit: the tone-mapped output and the HDR buffer. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/game/g_game.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_fx.h"
#include "../runtime/render/r_game.h"
#include "t.h"
#include "t_render.h"

enum { W = 160, H = 90 };

typedef struct frame_px {
    uint8_t rgba[W * H * 4];
    float *hdr;
} frame_px;

/* Tick `a` of demo drawn by r after ticks 0..a-1 were drawn (advance
 * false) or advanced (advance true). */
static void frame_at(const char *demo, uint64_t a, bool advance, frame_px *out)
{
    t_fb fb;
    t_fb_make(&fb, W, H);
    r_game *r = t_game_new(false);
    g_state prev, cur;
    for (uint64_t t = 0; t <= a; t++) {
        t_state_at(demo, t, &prev, &cur);
        if (t == a || !advance) {
            t_draw_read(r, &fb, &prev, &cur, W, H, t == a ? out->rgba : NULL, false);
            continue;
        }
        rgl_error_reset();
        gl.BindFramebuffer(GL_FRAMEBUFFER, fb.fbo);
        rs_err e = {0};
        T_ASSERTF(r_game_advance(r, &prev, &cur, W, H, a - t, NULL, &e), "%s", e.msg);
        gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
        T_EQ(rgl_error_count(), 0);
        T_EQ(gl.GetError(), GL_NO_ERROR);
    }
    out->hdr = t_read(r, "hdr", 4, W, H);
    r_game_destroy(r);
    t_fb_free(&fb);
}

static void same_frame(const char *demo, uint64_t a, const char *effect)
{
    frame_px *drawn = calloc(1, sizeof *drawn), *advanced = calloc(1, sizeof *advanced);
    T_ASSERT(drawn && advanced);
    frame_at(demo, a, false, drawn);
    frame_at(demo, a, true, advanced);
    int differ = 0;
    for (size_t i = 0; i < sizeof drawn->rgba; i++)
        differ += drawn->rgba[i] != advanced->rgba[i];
    T_ASSERTF(differ == 0, "%s (%s): tick %llu advanced then drawn differs from drawn throughout in %d of %d bytes",
              demo, effect, (unsigned long long)a, differ, (int)sizeof drawn->rgba);
    T_ASSERTF(!memcmp(drawn->hdr, advanced->hdr, (size_t)W * H * 4 * sizeof(float)),
              "%s (%s): the HDR buffers of tick %llu differ", demo, effect, (unsigned long long)a);
    free(drawn->hdr), free(advanced->hdr);
    free(drawn), free(advanced);
}

/* Every module with history has a way to move it on: an advance hook, or
 * the drawn frame (needs_frame). */
static void t_every_module_declares_its_history(void)
{
    for (int m = 0; m < r_fx_nmodules; m++) {
        const r_fx_module *mod = r_fx_modules[m];
        if (mod->warmup)
            T_ASSERTF(mod->advance || mod->needs_frame, "%s carries history but has no way to advance it", mod->name);
        if (mod->needs_frame)
            T_ASSERTF(mod->advance, "%s: a windowed module needs advance for the resets before its window", mod->name);
    }
}

/* r_game_history per stage, as docs/effects.md lists it: from tick 0 where
 * a simulation carries its state, LSPSM's window on plaza, nothing on the
 * stages without stateful effects. */
static void t_history_per_stage(void)
{
    plat *p = t_context("egl");
    r_game *r = t_game_new(false);
    static const struct {
        const char *stage;
        int64_t want;
    } want[] = {{"dojo", 0},
                {"harbor", 0},
                {"temple", 0},
                {"shallows", R_GAME_FROM_START},
                {"snowfield", R_GAME_FROM_START},
                {"mistvale", R_GAME_FROM_START},
                {"plaza", 228},
                {"quarry", 0}};
    for (int i = 0; i < (int)(sizeof want / sizeof want[0]); i++) {
        int st = -1;
        for (int k = 0; k < G_STAGES; k++)
            if (!strcmp(g_stages[k].name, want[i].stage))
                st = k;
        T_ASSERTF(st >= 0, "no stage %s", want[i].stage);
        rs_err err = {0};
        int64_t h = r_game_history(r, st, &err);
        T_ASSERTF(h == want[i].want, "%s: history %lld ticks, want %lld (%s)", want[i].stage, (long long)h,
                  (long long)want[i].want, err.msg);
    }
    r_game_destroy(r);
    plat_destroy(p);
}

/* The warm-up is needed: on each stage with a simulation, drawing a tick
 * straight after a restart (no history) differs from the full render, so
 * the checks above and tests/test_ticks.sh fail when a warm-up is skipped. */
static void t_history_matters(void)
{
    plat *p = t_context("egl");
    static const char *demos[] = {"shallows", "snowfield", "mistvale"};
    static const uint64_t at[] = {45, 120, 45}; /* the first footprints leave the stance's at 45 */
    for (int i = 0; i < 3; i++) {
        frame_px *drawn = calloc(1, sizeof *drawn), *cold = calloc(1, sizeof *cold);
        T_ASSERT(drawn && cold);
        frame_at(demos[i], at[i], false, drawn);
        t_fb fb;
        t_fb_make(&fb, W, H);
        r_game *r = t_game_new(false);
        g_state prev, cur;
        t_state_at(demos[i], at[i], &prev, &cur);
        t_draw_read(r, &fb, &prev, &cur, W, H, cold->rgba, false);
        r_game_destroy(r);
        t_fb_free(&fb);
        T_ASSERTF(memcmp(drawn->rgba, cold->rgba, sizeof drawn->rgba), "%s: tick %llu drawn cold equals the full render",
                  demos[i], (unsigned long long)at[i]);
        free(drawn->hdr);
        free(drawn), free(cold);
    }
    plat_destroy(p);
}

/* The ticks: long enough for contacts, splats and a stirred mist. */
static void t_fog_history(void)
{
    plat *p = t_context("egl");
    same_frame("mistvale", 45, "fog");
    plat_destroy(p);
}

static void t_snow_history(void)
{
    plat *p = t_context("egl");
    same_frame("snowfield", 45, "snow");
    plat_destroy(p);
}

static void t_water_history(void)
{
    plat *p = t_context("egl");
    same_frame("shallows", 45, "water");
    plat_destroy(p);
}

/* LSPSM's focus needs the drawn frame: r_game_advance draws it there. */
static void t_lspsm_history(void)
{
    plat *p = t_context("egl");
    same_frame("plaza", 6, "lspsm");
    plat_destroy(p);
}

T_MAIN({"every_module_declares_its_history", t_every_module_declares_its_history},
       {"history_per_stage", t_history_per_stage},
       {"history_matters", t_history_matters},
       {"fog_history", t_fog_history},
       {"snow_history", t_snow_history},
       {"water_history", t_water_history},
       {"lspsm_history", t_lspsm_history})
