/* Shared helpers of the renderer's GL tests (t_render.h). */
#include "t_render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "../runtime/render/r_game.h"
#include "../runtime/render/r_stage.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_img.h"
#include "t.h"

void t_state_at(const char *demo, uint64_t tick, g_state *prev, g_state *cur)
{
    char path[1024];
    snprintf(path, sizeof path, RS_SOURCE_DIR "/demos/%s.rsr", demo);
    rp_replay rp;
    rs_err e = {0};
    T_ASSERTF(rp_read(path, &rp, &e), "%s", e.msg);
    T_ASSERT(tick <= rp.ticks);
    g_init(cur, rp.stage, rp.seed);
    *prev = *cur;
    for (uint64_t t = 0; t < tick; t++) {
        *prev = *cur;
        g_step(cur, &rp.inputs[2 * t], NULL);
    }
    rp_free(&rp);
}

void t_fb_make(t_fb *f, int w, int h)
{
    gl.GenFramebuffers(1, &f->fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, f->fbo);
    gl.GenRenderbuffers(2, f->rb);
    gl.BindRenderbuffer(GL_RENDERBUFFER, f->rb[0]);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, f->rb[0]);
    gl.BindRenderbuffer(GL_RENDERBUFFER, f->rb[1]);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, w, h);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, f->rb[1]);
    T_EQ(gl.CheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
}

void t_fb_free(t_fb *f)
{
    gl.DeleteFramebuffers(1, &f->fbo);
    gl.DeleteRenderbuffers(2, f->rb);
}

r_game *t_game_opts(const r_game_opts *o)
{
    r_game_opts d = {0};
    if (o)
        d = *o;
    d.cache_dir = "";
    d.quiet = true;
    rs_err e = {0};
    r_game *r = r_game_create_opts(&d, &e);
    T_ASSERTF(r, "%s", e.msg);
    return r;
}

r_game *t_game_new(bool mask)
{
    return t_game_opts(&(r_game_opts){.mask = mask});
}

void t_draw(r_game *r, const t_fb *f, const g_state *prev, const g_state *cur, int w, int h)
{
    t_draw_read(r, f, prev, cur, w, h, NULL, false);
}

void t_draw_read(r_game *r, const t_fb *f, const g_state *prev, const g_state *cur, int w, int h, uint8_t *px,
                 bool top_down)
{
    rgl_error_reset();
    gl.BindFramebuffer(GL_FRAMEBUFFER, f->fbo);
    rs_err e = {0};
    T_ASSERTF(r_game_draw(r, prev, cur, 1.0f, w, h, &e), "%s", e.msg);
    if (px) {
        gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
        gl.ReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, px);
        if (top_down)
            rs_flip_rows(px, w, h, 4);
    }
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    T_EQ(rgl_error_count(), 0);
    T_EQ(gl.GetError(), GL_NO_ERROR);
    T_ASSERTF(!r_graph_error(r_game_graph(r))[0], "pass graph: %s", r_graph_error(r_game_graph(r)));
}

bool t_pass_ran(r_game *r, const char *name)
{
    r_graph *g = r_game_graph(r);
    int i = r_graph_find(g, name);
    T_ASSERTF(i >= 0, "no pass '%s'", name);
    return (g->last_ran >> i) & 1;
}

float *t_read(r_game *r, const char *what, int channels, int w, int h)
{
    float *px = malloc((size_t)w * (size_t)h * (size_t)channels * sizeof *px);
    T_ASSERT(px);
    int rw = 0, rh = 0;
    T_ASSERTF(r_game_read_buffer(r, what, px, &rw, &rh), "no buffer '%s'", what);
    T_EQ(rw, w);
    T_EQ(rh, h);
    return px;
}

void t_dump_hdr(const char *name, const float *px, int w, int h)
{
    const char *dir = getenv("T_DUMP");
    if (!dir)
        return;
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.ppm", dir, name);
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return;
    fprintf(fp, "P6\n%d %d\n255\n", w, h);
    for (int y = h - 1; y >= 0; y--)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                float v = px[4 * ((size_t)y * w + x) + c];
                v = v > 0 ? v / (1 + v) : 0;
                fputc((int)(255 * powf(v, 1 / 2.2f) + 0.5f), fp);
            }
    fclose(fp);
}

void t_stage_extremes(r_stage *st)
{
    st->sun_intensity = R_HALF_MAX;
    st->key.intensity = st->counter.intensity = R_HALF_MAX;
    for (int c = 0; c < 3; c++)
        st->sky_zenith[c] = st->sky_horizon[c] = st->ground[c] = R_HALF_MAX;
    st->exposure = 1000;
}

/* One picture of a demo with its stage file, the way render makes it:
 * the `history` ticks before it are advanced first (r_game_advance: the
 * stage effects' simulations step, and a frame is drawn only where an
 * effect needs it, as render's warm-up does), so the simulations
 * (docs/effects.md) have that much past.  The effect contract makes this
 * the picture drawing every one of those frames gives (test_fx_history
 * holds it to that), for a fraction of the time. */
void t_picture(const char *demo, uint64_t tick, uint64_t history, const r_game_opts *o, int w, int h, uint8_t *px)
{
    g_state prev, cur;
    uint64_t first = tick > history ? tick - history : 0;
    t_state_at(demo, first, &prev, &cur);
    char path[1024];
    snprintf(path, sizeof path, RS_SOURCE_DIR "/demos/%s.rsr", demo);
    rp_replay rp;
    rs_err e = {0};
    T_ASSERTF(rp_read(path, &rp, &e), "%s", e.msg);
    r_game *r = t_game_opts(o);
    t_fb f;
    t_fb_make(&f, w, h);
    gl.BindFramebuffer(GL_FRAMEBUFFER, f.fbo);
    for (uint64_t t = first; t < tick; t++) {
        T_ASSERTF(r_game_advance(r, &prev, &cur, w, h, tick - t, NULL, &e), "advancing tick %llu: %s",
                  (unsigned long long)t, e.msg);
        prev = cur;
        g_step(&cur, &rp.inputs[2 * t], NULL);
    }
    t_draw_read(r, &f, &prev, &cur, w, h, px, true);
    rp_free(&rp);
    t_fb_free(&f);
    r_game_destroy(r);
}
