/* The fighters' shadows (SSFSM, techniques A5): the key light's depth
 * map, the blurred silhouette projected on the stage, the z-prepass and
 * the screen-space shadow mask with its filter.  Six passes, run on
 * stages with `shadows = yes`; r_game.c puts them first in the graph. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "r_local.h"

static bool need_shadows(void *u)
{
    r_game *r = u;
    return r->stage.shadows;
}

static void light_view_draw(r_game *r, GLuint p)
{
    gl.UseProgram(p);
    gl.UniformMatrix4fv(r_loc(p, "u_view_proj"), 1, GL_FALSE, r->f.light.m);
    r_draw_fighters(r, p);
}

static void run_shadow_map(void *u)
{
    r_game *r = u;
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->shadow_fbo);
    gl.Viewport(0, 0, r->shadow_size, r->shadow_size);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.DepthMask(GL_TRUE);
    gl.Clear(GL_DEPTH_BUFFER_BIT);
    gl.Enable(GL_POLYGON_OFFSET_FILL);
    gl.PolygonOffset(2.0f, 4.0f);
    gl.Disable(GL_CULL_FACE);
    light_view_draw(r, r->prog[P_DEPTH]);
    gl.Disable(GL_POLYGON_OFFSET_FILL);
}

static void run_silhouette(void *u)
{
    r_game *r = u;
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->sil_fbo[0]);
    gl.Viewport(0, 0, r->sil_size, r->sil_size);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    gl.ClearColor(0, 0, 0, 0);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    light_view_draw(r, r->prog[P_SIL]);
}


/* Blurred mipmap projection shadow: level k = blur(downsample(level k-1)),
 * for 4 levels.  Each draw reads one level while writing another (or the
 * same level of the other texture); BASE/MAX_LEVEL restrict what the
 * sampler can see to the level read, so there is no feedback loop, and
 * the shaders then address it as level 0. */
static void restrict_level(GLuint tex, int k)
{
    gl.BindTexture(GL_TEXTURE_2D, tex);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, k);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, k);
}

static void run_silhouette_mips(void *u)
{
    r_game *r = u;
    gl.Disable(GL_DEPTH_TEST);
    for (int k = 1; k < SIL_LEVELS; k++) {
        int n = r->sil_size >> k;
        restrict_level(r->sil_tex, k - 1);
        r_down_into(r, r->sil_fbo[k], r->sil_tex, 0, n, n, -1, 1);
        restrict_level(r->sil_tex, k);
        r_blur_into(r, r->sil_tmp_fbo[k], r->sil_tex, 0, n, n, 1, 0);
        restrict_level(r->sil_tmp, k);
        r_blur_into(r, r->sil_fbo[k], r->sil_tmp, 0, n, n, 0, 1);
    }
    gl.BindTexture(GL_TEXTURE_2D, r->sil_tex);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, SIL_LEVELS - 1);
}

/* SSFSM step 1b: the fighters' depth as the camera sees them */
static void run_z_prepass(void *u)
{
    r_game *r = u;
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->depth_fbo);
    gl.Viewport(0, 0, r->f.w, r->f.h);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.DepthMask(GL_TRUE);
    gl.ClearDepth(1.0);
    gl.Clear(GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_BACK);
    r_camera_uniforms(r, r->prog[P_DEPTH]);
    r_draw_fighters(r, r->prog[P_DEPTH]);
}

/* The mask's scale: mask pixels per render pixel (1, or 1/2 with
 * q.mask_half) and mask pixels per 1/720 of the frame height, the unit
 * its grow and blur are sized in (docs/renderer.md). */
static float mask_unit(const r_game *r)
{
    return (float)r->mask_h / R_REF_ROWS;
}

/* The bound mask buffer: all 1 (lit), then draws limited to the fighters'
 * box (render pixels, taken to the mask's, rounded outwards). */
static void mask_clear_and_scissor(r_game *r)
{
    gl.Disable(GL_SCISSOR_TEST);
    gl.ClearColor(1, 1, 1, 1);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    gl.Enable(GL_SCISSOR_TEST);
    const int *b = r->f.fig_box;
    if (r->mask_w == r->f.w && r->mask_h == r->f.h) {
        gl.Scissor(b[0], b[1], b[2], b[3]);
        return;
    }
    double sx = (double)r->mask_w / r->f.w, sy = (double)r->mask_h / r->f.h;
    int x0 = (int)floor(b[0] * sx), y0 = (int)floor(b[1] * sy);
    int x1 = (int)ceil((b[0] + b[2]) * sx), y1 = (int)ceil((b[1] + b[3]) * sy);
    gl.Scissor(x0, y0, x1 - x0, y1 - y0);
}

static void run_shadow_mask(void *u)
{
    r_game *r = u;
    GLuint p = r->prog[P_MASK];
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->mask_fbo[0]);
    gl.Viewport(0, 0, r->mask_w, r->mask_h);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    mask_clear_and_scissor(r);
    gl.UseProgram(p);
    r_bind_tex(p, "u_depth", 0, GL_TEXTURE_2D, r->depth_tex);
    r_bind_tex(p, "u_shadow_map", 1, GL_TEXTURE_2D, r->shadow_tex);
    gl.UniformMatrix4fv(r_loc(p, "u_inv_view_proj"), 1, GL_FALSE, r->f.inv_vp.m);
    gl.UniformMatrix4fv(r_loc(p, "u_light_proj"), 1, GL_FALSE, r->f.light.m);
    gl.Uniform2f(r_loc(p, "u_size"), (float)r->f.w, (float)r->f.h);
    gl.Uniform1f(r_loc(p, "u_step"), r->mask_h == r->f.h ? 1.0f : 2.0f);
    gl.Uniform1f(r_loc(p, "u_bias"), 0.0015f);
    r_fullscreen(r);
    gl.Disable(GL_SCISSOR_TEST);
}

/* SSFSM step 3: grow dark by 1/720 of the frame height, then blur (sigma
 * 2/720 of it) (mask 0 -> 1 -> 0 -> 1) */
static void run_mask_filter(void *u)
{
    r_game *r = u;
    GLuint p = r->prog[P_GROW];
    float k = mask_unit(r);
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->mask_fbo[1]);
    gl.Viewport(0, 0, r->mask_w, r->mask_h);
    mask_clear_and_scissor(r);
    gl.UseProgram(p);
    r_bind_tex(p, "u_src", 0, GL_TEXTURE_2D, r->mask_tex[0]);
    gl.Uniform1f(r_loc(p, "u_radius"), k);
    r_fullscreen(r);
    /* outside the box both buffers hold 1, so the blur reads the truth there */
    r_blur_into(r, r->mask_fbo[0], r->mask_tex[1], 0, r->mask_w, r->mask_h, k, 0);
    r_blur_into(r, r->mask_fbo[1], r->mask_tex[0], 0, r->mask_w, r->mask_h, 0, k);
    gl.Disable(GL_SCISSOR_TEST);
    r->mask_final = 1;
}


const r_pass r_shadow_passes[R_SHADOW_NPASS] = {
    {"shadow_map", RES_ENV, RES_SHADOW, need_shadows, run_shadow_map, 0},
    {"silhouette", RES_ENV, RES_SIL, need_shadows, run_silhouette, 0},
    {"silhouette_mips", RES_SIL, RES_SIL, need_shadows, run_silhouette_mips, 0},
    {"z_prepass", RES_ENV, RES_DEPTH, need_shadows, run_z_prepass, 0},
    {"shadow_mask", RES_DEPTH | RES_SHADOW, RES_MASK, need_shadows, run_shadow_mask, 0},
    {"mask_filter", RES_MASK, RES_MASK, need_shadows, run_mask_filter, 0},
};
