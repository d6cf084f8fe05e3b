/* Post passes on the HDR image: bloom, the sun's visibility and the
 * lens flare, and the tone map into the output. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "r_bloom.h"
#include "r_local.h"
#include "r_tone.h"

static bool need_always(void *u)
{
    (void)u;
    return true;
}

static bool need_bloom(void *u)
{
    r_game *r = u;
    return r->stage.bloom > 0;
}

static bool need_sun(void *u)
{
    r_game *r = u;
    return r->f.sun_on_screen;
}

/* The bloom's levels have BLOOM_ROWS and BLOOM_ROWS / 2 rows at any
 * render size (the width by aspect), so the glow is the same fraction of
 * the frame: the HDR image is halved until one step more would pass
 * BLOOM_ROWS, and the last step resamples to it (a ratio in (1, 2]; 2 at
 * 720 rows, where the pyramid is what it was at 1/4 and 1/8 size). */
void r_bloom_plan(int w, int h, int *steps, int *w4)
{
    int n = 1;
    while (n < BLOOM_XSTEPS + 2 && ((long)BLOOM_ROWS << n) < h)
        n++;
    *steps = n;
    long v = ((long)w * BLOOM_ROWS * 2 + h) / (2L * h); /* rounded */
    *w4 = v > 0 ? (int)v : 1;
}

/* step k's target (1 <= k < bloom_steps): b2, then the extra halvings;
 * the last, the first level: b4, or bc for the CPU's blurs */
static GLuint bloom_step_fbo(r_game *r, int k)
{
    return k == r->bloom_steps ? (r->cpu_paths ? r->bc_fbo : r->b4_fbo[0]) : k == 1 ? r->b2_fbo : r->bx_fbo[k - 2];
}

static GLuint bloom_step_tex(r_game *r, int k)
{
    return k == 1 ? r->b2_tex : r->bx_tex[k - 2];
}

static void bloom_step_size(r_game *r, int k, int *w, int *h)
{
    *w = k == r->bloom_steps ? r->b4_w : r_half(r->f.w, k);
    *h = k == r->bloom_steps ? BLOOM_ROWS : r_half(r->f.h, k);
}

/* the step into b4, the first of the levels, encodes (P_DOWN_RGBE); b2,
 * the halvings and bc are floats */
static GLuint bloom_step_prog(r_game *r, int k)
{
    return r->prog[k == r->bloom_steps && !r->cpu_paths ? P_DOWN_RGBE : P_DOWN];
}

static void run_bloom_bright(void *u)
{
    r_game *r = u;
    int w, h;
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    bloom_step_size(r, 1, &w, &h);
    r_down_with(r, bloom_step_prog(r, 1), bloom_step_fbo(r, 1), r->hdr_tex, 0, w, h, r->stage.bloom_threshold, r->f.exposure);
}

/* The same levels and glow in C (r_bloom.c), on a software rasteriser:
 * the first level is read back as floats (and the flare's image when it
 * ran), and the glow goes up as the one texture the tone map taps.  On
 * llvmpipe the GL's five passes over the levels (run_bloom_blur, below)
 * cost 3.4 ms a 640x360 frame on one thread; the reads, the C and the
 * upload about 1.4. */
static void bloom_blur_cpu(r_game *r, bool level2, bool flare)
{
    frame *f = &r->f;
    r_bloom_cpu b = {.w4 = r->b4_w, .h4 = BLOOM_ROWS, .w8 = r->b8_w, .h8 = BLOOM_ROWS / 2, .level2 = level2,
                     .bloom = r->stage.bloom, .fw = r_half(f->w, 2), .fh = r_half(f->h, 2)};
    r_blur_kernel(1, b.kw);
    size_t n4 = 4 * (size_t)b.w4 * (size_t)b.h4, nf = flare ? 4 * (size_t)b.fw * (size_t)b.fh : 0;
    size_t need = 2 * n4 + nf + r_bloom_scratch_floats(&b);
    if (need > r->bloom_buf_n) {
        float *p = realloc(r->bloom_buf, need * sizeof *p);
        if (!p)
            return; /* the glow keeps the last frame's */
        r->bloom_buf = p, r->bloom_buf_n = need;
    }
    float *level = r->bloom_buf, *glow = level + n4, *fl = glow + n4, *scratch = fl + nf;
    /* from the textures, not their framebuffers (r_shadow.c's
     * sil_mips_cpu says why) */
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.BindTexture(GL_TEXTURE_2D, r->bc_tex);
    gl.GetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, level);
    if (flare) {
        gl.BindTexture(GL_TEXTURE_2D, r->fl_tex);
        gl.GetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, fl);
        b.flare = fl;
    }
    r_bloom_glow(&b, level, scratch, glow);
    gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.BindTexture(GL_TEXTURE_2D, r->glow_tex);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, b.w4, b.h4, GL_RGBA, GL_FLOAT, glow);
    gl.BindTexture(GL_TEXTURE_2D, 0);
}

/* The levels, then the glow: the one image the tone map adds.  The first
 * level is blurred across, the second level is made from that (down, then
 * blurred both ways), and the first level's blur down the columns writes
 * the glow: u_bloom x (itself + the second level) + the flare when it
 * ran (blur.frag's GLOW).  The tone map then taps one texture a pixel
 * where it tapped three: at 640x360 on llvmpipe each full-size tap costs
 * about 1 ms, the glow's two extra taps at bloom's size a quarter of
 * that.  The second level is made from the first blurred across only, not
 * both ways as before (a slightly narrower glow down the columns).
 * The levels are RGBE in RGBA8 (rgbe_common.glsl), read texel by texel:
 * on llvmpipe a 9-tap blur of them costs a third of the 5 bilinear taps of
 * RGBA16F it replaced (0.69 against 1.9-2.0 ms at 320x180, one thread);
 * the glow, which the tone map filters, stays RGBA16F (RGBA32F where
 * bloom_blur_cpu makes it). */
static void run_bloom_blur(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    int w, h;
    for (int k = 2; k <= r->bloom_steps; k++) {
        bloom_step_size(r, k, &w, &h);
        r_down_with(r, bloom_step_prog(r, k), bloom_step_fbo(r, k), bloom_step_tex(r, k - 1), 0, w, h, -1, 1);
    }
    if (r->cpu_paths) {
        bloom_blur_cpu(r, r->opts.q.bloom_levels != 1, r_ran(f, r, "flare"));
        return;
    }
    int w4 = r->b4_w, h4 = BLOOM_ROWS, w8 = r->b8_w, h8 = BLOOM_ROWS / 2;
    GLuint blur = r->prog[P_BLUR_RGBE];
    r_blur_rgbe_setup(blur, r->b4_fbo[1], r->b4_tex[0], w4, h4, true);
    r_fullscreen(r);
    /* the quality knob r_quality.bloom_levels 1: the BLOOM_ROWS level alone */
    bool level2 = r->opts.q.bloom_levels != 1, flare = r_ran(f, r, "flare");
    if (level2) {
        r_down_with(r, r->prog[P_DOWN_RGBE_IN], r->b8_fbo[0], r->b4_tex[1], 0, w8, h8, -1, 1);
        r_blur_rgbe_setup(blur, r->b8_fbo[1], r->b8_tex[0], w8, h8, true);
        r_fullscreen(r);
        r_blur_rgbe_setup(blur, r->b8_fbo[0], r->b8_tex[1], w8, h8, false);
        r_fullscreen(r);
    }
    GLuint p = r->prog[P_GLOW + (level2 ? 1 : 0) + (flare ? 2 : 0)];
    r_blur_rgbe_setup(p, r->glow_fbo, r->b4_tex[1], w4, h4, false);
    gl.Uniform1f(r_loc(p, "u_bloom"), r->stage.bloom);
    if (level2)
        r_bind_tex(p, "u_level2", 1, GL_TEXTURE_2D, r->b8_tex[0]);
    if (flare)
        r_bind_tex(p, "u_flare_img", 2, GL_TEXTURE_2D, r->fl_tex);
    r_fullscreen(r);
}

static void run_sun_visibility(void *u)
{
    r_game *r = u;
    GLuint p = r->prog[P_SUNVIS];
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->sunvis_fbo);
    gl.Viewport(0, 0, 1, 1);
    gl.Disable(GL_DEPTH_TEST);
    gl.UseProgram(p);
    r_bind_tex(p, "u_depth", 0, GL_TEXTURE_2D, r->depth_tex);
    gl.Uniform2f(r_loc(p, "u_sun"), r->f.sun_px[0], r->f.sun_px[1]);
    gl.Uniform1f(r_loc(p, "u_radius"), r->f.h * 0.012f);
    r_fullscreen(r);
}

static void run_tonemap(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    /* the glow: bloom's (with the flare in it), else the flare's own */
    bool bloom = r_ran(f, r, "bloom_blur"), flare = r_ran(f, r, "flare");
    GLuint glow = bloom ? r->glow_tex : flare ? r->fl_tex : 0;
    /* r_quality.scene_pct: the scene drawn smaller.  Without an AA pass
     * the tone map runs at the scene's size into sc_tex and a linear blit
     * scales its 8-bit image up (the blit's taps cost a fraction of the
     * tone map's at the output's size); the AA pass, which also wants the
     * luma at the output's size, gets the SCALED variant there instead. */
    bool scaled = f->w != f->out_w || f->h != f->out_h, at_scene = scaled && r->sc_fbo;
    GLuint p = r->prog[P_TONE + (glow ? 1 : 0) + (scaled && !at_scene ? 2 : 0)];
    /* with anti-aliasing the AA pass (r_aa.c) writes the output from ldr_tex */
    gl.BindFramebuffer(GL_FRAMEBUFFER, at_scene ? r->sc_fbo : r->opts.q.aa ? r->ldr_fbo : (GLuint)f->out_fbo);
    gl.Viewport(0, 0, at_scene ? f->w : f->out_w, at_scene ? f->h : f->out_h);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.UseProgram(p);
    r_bind_tex(p, "u_hdr", 0, GL_TEXTURE_2D, r->hdr_tex);
    r_bind_tex(p, "u_lut", 1, GL_TEXTURE_1D, r->lut_tex);
    gl.Uniform1i(r_loc(p, "u_lut_size"), r->lut_size);
    gl.Uniform1f(r_loc(p, "u_lut_inv_power"), (float)(1.0 / r_tone_index_power(r->lut_gamma)));
    gl.Uniform1f(r_loc(p, "u_exposure"), f->exposure);
    gl.Uniform1f(r_loc(p, "u_saturation"), f->saturation);
    gl.Uniform1i(r_loc(p, "u_write_mask"), r->opts.mask);
    if (scaled && !at_scene)
        gl.Uniform2f(r_loc(p, "u_out"), (float)f->out_w, (float)f->out_h);
    if (glow)
        r_bind_tex(p, "u_glow", 2, GL_TEXTURE_2D, glow);
    r_fullscreen(r);
    if (at_scene) {
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, r->sc_fbo);
        gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)f->out_fbo);
        gl.BlitFramebuffer(0, 0, f->w, f->h, 0, 0, f->out_w, f->out_h, GL_COLOR_BUFFER_BIT, GL_LINEAR);
        gl.BindFramebuffer(GL_FRAMEBUFFER, (GLuint)f->out_fbo);
    }
}

/* The flare image (glow and ghosts along the axis through the centre,
 * scaled by the sun's visibility) at quarter size: it is smooth, and six
 * flare-texture taps per output pixel cost more than the rest of the tone
 * map (13 of 19 ms at 1280x720 on llvmpipe).  The tone map taps it once. */
static void run_flare(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    GLuint p = r->prog[P_FLARE];
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->fl_fbo);
    gl.Viewport(0, 0, r_half(f->w, 2), r_half(f->h, 2));
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.UseProgram(p);
    r_bind_tex(p, "u_flare", 0, GL_TEXTURE_2D, r->flare_tex);
    r_bind_tex(p, "u_sun_vis", 1, GL_TEXTURE_2D, r->sunvis_tex);
    gl.Uniform2f(r_loc(p, "u_size"), (float)r_half(f->w, 2), (float)r_half(f->h, 2));
    gl.Uniform2f(r_loc(p, "u_sun_uv"), f->sun_px[0] / (float)f->w, f->sun_px[1] / (float)f->h);
    const float *c = r->stage.sun_color;
    float k = fminf(r->stage.sun_intensity * 0.08f, 50.0f) * f->exposure;
    gl.Uniform3f(r_loc(p, "u_flare_color"), c[0] * k, c[1] * k, c[2] * k);
    gl.Uniform1f(r_loc(p, "u_aspect"), (float)f->w / (float)f->h);
    r_fullscreen(r);
}

void r_update_lut(r_game *r)
{
    if (r->stage.gamma == r->lut_gamma)
        return;
    float *lut = malloc((size_t)r->lut_size * sizeof *lut);
    if (!lut)
        return;
    r_tone_lut(lut, r->lut_size, r->stage.gamma);
    gl.BindTexture(GL_TEXTURE_1D, r->lut_tex);
    gl.TexSubImage1D(GL_TEXTURE_1D, 0, 0, r->lut_size, GL_RED, GL_FLOAT, lut);
    gl.BindTexture(GL_TEXTURE_1D, 0);
    free(lut);
    r->lut_gamma = r->stage.gamma;
}


/* the flare first: bloom's last blur adds it to the glow */
const r_pass r_post_passes[R_POST_NPASS] = {
    {"sun_visibility", RES_DEPTH, RES_SUNVIS, need_sun, run_sun_visibility, 0},
    {"flare", RES_SUNVIS, RES_FLARE, need_sun, run_flare, 0},
    {"bloom_bright", RES_HDR, RES_BLOOM, need_bloom, run_bloom_bright, 0},
    {"bloom_blur", RES_BLOOM, RES_BLOOM, need_bloom, run_bloom_blur, RES_FLARE},
    {"tonemap", RES_HDR | RES_ENV, RES_OUT, need_always, run_tonemap, RES_BLOOM | RES_FLARE},
};
