/* The fighters' shadows (SSFSM, docs/renderer.md, "Shadows"): the key light's depth
 * map, the blurred silhouette projected on the stage, the z-prepass and
 * the screen-space shadow mask with its filter.  Six passes, run on
 * stages with `shadows = yes`; r_game.c puts them first in the graph. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../game/g_skel.h"
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

/* With the shadow map and the silhouette the same size (the standard
 * preset's 512), one draw of the fighters makes both: the silhouette is
 * every fragment drawn, and with GL_LEQUAL the first fragment at a texel
 * always passes (the depth is cleared to 1, and the polygon offset may
 * clamp one to 1), so depth-testing it covers what the silhouette's own
 * draw without a depth test did; a fragment that fails lands on a texel
 * already covered.  Equal depths write the same value, so the map is
 * LESS's too.  Most of either pass was the fighters' vertices and
 * triangles, not their fragments (llvmpipe, single-threaded at 640x360:
 * a mesh with half the triangles took the silhouette's 1.2 ms to 0.6). */
static void run_shadow_map(void *u)
{
    r_game *r = u;
    bool both = r->shadow_sil_fbo != 0;
    gl.BindFramebuffer(GL_FRAMEBUFFER, both ? r->shadow_sil_fbo : r->shadow_fbo);
    gl.Viewport(0, 0, r->shadow_size, r->shadow_size);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(both ? GL_LEQUAL : GL_LESS);
    gl.DepthMask(GL_TRUE);
    if (both)
        gl.ClearColor(0, 0, 0, 0);
    gl.Clear(GL_DEPTH_BUFFER_BIT | (both ? GL_COLOR_BUFFER_BIT : 0));
    gl.Enable(GL_POLYGON_OFFSET_FILL);
    gl.PolygonOffset(2.0f, 4.0f);
    /* the capsules are closed: the nearest surface faces the light, so
     * the back faces only cost fragments (most of this pass on llvmpipe) */
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_BACK);
    light_view_draw(r, r->prog[both ? P_SIL : P_DEPTH]);
    gl.Disable(GL_POLYGON_OFFSET_FILL);
    gl.Disable(GL_CULL_FACE);
    gl.DepthFunc(GL_LESS);
}

static void run_silhouette(void *u)
{
    r_game *r = u;
    if (r->shadow_sil_fbo) /* drawn with the shadow map */
        return;
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->sil_fbo[0]);
    gl.Viewport(0, 0, r->sil_size, r->sil_size);
    gl.Disable(GL_DEPTH_TEST);
    /* closed capsules: their front faces cover what the whole mesh does */
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_BACK);
    gl.ClearColor(0, 0, 0, 0);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    light_view_draw(r, r->prog[P_SIL]);
    gl.Disable(GL_CULL_FACE);
}


/* The texels of the silhouette (level 0, x0 y0 x1 y1, x1 y1 exclusive)
 * the fighters can cover: each capsule's ends projected by the light
 * (orthographic), grown by its radius and a texel for rasterisation.
 * The light's box is fitted round a sphere holding both fighters, so
 * they fill only part of it: the mip chain draws inside this. */
static void sil_footprint(const r_game *r, int b[4])
{
    const float *L = r->f.light.m;
    float sx = sqrtf(L[0] * L[0] + L[4] * L[4] + L[8] * L[8]), sy = sqrtf(L[1] * L[1] + L[5] * L[5] + L[9] * L[9]);
    float lo[2] = {1e9f, 1e9f}, hi[2] = {-1e9f, -1e9f};
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < G_BONES; k++) {
            const float *m = r->f.bones[i][k];
            float len = fx_to_float(g_bones[k].length), rad = fx_to_float(g_bones[k].radius);
            for (int e = 0; e < 2; e++) {
                float p[3] = {m[12] + m[0] * len * e, m[13] + m[1] * len * e, m[14] + m[2] * len * e};
                float x = L[0] * p[0] + L[4] * p[1] + L[8] * p[2] + L[12];
                float y = L[1] * p[0] + L[5] * p[1] + L[9] * p[2] + L[13];
                lo[0] = fminf(lo[0], x - rad * sx), hi[0] = fmaxf(hi[0], x + rad * sx);
                lo[1] = fminf(lo[1], y - rad * sy), hi[1] = fmaxf(hi[1], y + rad * sy);
            }
        }
    float n = (float)r->sil_size;
    for (int a = 0; a < 2; a++) {
        /* NaN (a broken matrix) or out of the map: the whole map */
        float t0 = (lo[a] * 0.5f + 0.5f) * n - 1, t1 = (hi[a] * 0.5f + 0.5f) * n + 1;
        b[a] = t0 >= 0 && t0 <= n ? (int)floorf(t0) : 0;
        b[a + 2] = t1 >= 0 && t1 <= n ? (int)ceilf(t1) : r->sil_size;
        if (!(t0 <= t1))
            b[a] = 0, b[a + 2] = r->sil_size;
    }
}

/* Blurred mipmap projection shadow: level k = blur(downsample(level k-1)),
 * for 4 levels.  Each draw reads one level while writing another (or the
 * same level of the other texture); BASE/MAX_LEVEL restrict what the
 * sampler can see to the level read, so there is no feedback loop, and
 * the shaders then address it as level 0.
 * Only the texels that can be non-zero are drawn (a scissor per level),
 * the rest cleared: the same bytes as drawing all, for a fraction of the
 * fragments (llvmpipe pays per fragment; level 1 is 3/4 of them). */
static void restrict_level(GLuint tex, int k)
{
    gl.BindTexture(GL_TEXTURE_2D, tex);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, k);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, k);
}

/* Bind fbo, clear it whole, and scissor the draws that follow to b (x0 y0
 * x1 y1): the draw then binds the same framebuffer, so the clear goes in
 * with it (llvmpipe flushes on a framebuffer change, not on a clear). */
static void clear_then_scissor(GLuint fbo, const int b[4])
{
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.Disable(GL_SCISSOR_TEST);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    gl.Enable(GL_SCISSOR_TEST);
    gl.Scissor(b[0], b[1], b[2] - b[0], b[3] - b[1]);
}

/* Level k's box from level k-1's: where it can be non-zero.  The
 * downsample reads source texels 2i-1..2i+2, each blur reaches 4 texels
 * (downsample.frag, blur.frag); a texel more for rounding. */
static void sil_level_box(int b[4], int n)
{
    for (int a = 0; a < 2; a++) {
        b[a] = b[a] / 2 - 2 - 4 - 1, b[a + 2] = (b[a + 2] + 1) / 2 + 1 + 4 + 1;
        b[a] = b[a] < 0 ? 0 : b[a], b[a + 2] = b[a + 2] > n ? n : b[a + 2];
    }
}

/* an R8 target's byte for x */
static uint8_t unorm8(float x)
{
    x = x * 255.0f + 0.5f;
    return x <= 0 ? 0 : x >= 255 ? 255 : (uint8_t)x;
}

/* blur.frag's REACH blur (texel weights kw[0..reach]) of src (w x h)
 * inside the box b (x0 y0 x1 y1) along x (across) or y, each result
 * rounded to a byte where its R8 target rounds: into bytes when dst_b,
 * else into dst_f as floats (the byte / 255).  A tap off the image reads
 * zero (zero_border: the silhouette's border) or the edge's texel (the
 * mask's clamp). */
static void blur_box(const float *src, int w, int h, const int b[4], const float kw[5], int reach, bool across,
                     bool zero_border, float *dst_f, uint8_t *dst_b)
{
    size_t step = across ? 1 : (size_t)w;
    for (int y = b[1]; y < b[3]; y++)
        for (int x = b[0]; x < b[2]; x++) {
            size_t at = (size_t)y * (size_t)w + (size_t)x;
            float c = kw[0] * src[at];
            /* every tap on the image: no edge to test (most texels) */
            bool inside = across ? x >= reach && x + reach < w : y >= reach && y + reach < h;
            for (int t = 1; t <= reach && inside; t++)
                c += kw[t] * (src[at - (size_t)t * step] + src[at + (size_t)t * step]);
            for (int t = 1; t <= reach && !inside; t++) {
                float side[2];
                for (int e = 0; e < 2; e++) {
                    int xx = across ? x + (e ? t : -t) : x, yy = across ? y : y + (e ? t : -t);
                    bool off = xx < 0 || xx >= w || yy < 0 || yy >= h;
                    xx = xx < 0 ? 0 : xx >= w ? w - 1 : xx, yy = yy < 0 ? 0 : yy >= h ? h - 1 : yy;
                    side[e] = off && zero_border ? 0 : src[(size_t)yy * (size_t)w + (size_t)xx];
                }
                c += kw[t] * (side[0] + side[1]);
            }
            if (dst_b)
                dst_b[at] = unorm8(c);
            else
                dst_f[at] = (float)unorm8(c) * (1.0f / 255);
        }
}

/* The same levels in C (r->cpu_paths: a software rasteriser).  Level 0
 * is read back; each level is made from the one before as the passes
 * below make it, rounded to bytes where their R8 targets round (after the
 * downsample, the blur across, the blur down), zero outside its box as
 * the clear leaves it, and uploaded whole.  On llvmpipe those passes cost
 * 1.7-2.2 ms a frame on one thread, most of it their fixed costs: twelve
 * draws and eight clears on small targets, each a flush. */
static bool sil_mips_cpu(r_game *r, int b[4])
{
    int n0 = r->sil_size;
    size_t bytes = 0, n1 = (size_t)(n0 / 2) * (size_t)(n0 / 2);
    for (int k = 0; k < SIL_LEVELS; k++)
        bytes += (size_t)(n0 >> k) * (size_t)(n0 >> k);
    bytes = (bytes + 15) & ~(size_t)15;
    size_t need = bytes + 2 * n1 * sizeof(float);
    if (need > r->sil_buf_n) {
        uint8_t *p = realloc(r->sil_buf, need);
        if (!p)
            return false; /* the GL passes instead */
        r->sil_buf = p, r->sil_buf_n = need;
    }
    uint8_t *lev[SIL_LEVELS];
    lev[0] = r->sil_buf;
    for (int k = 1; k < SIL_LEVELS; k++)
        lev[k] = lev[k - 1] + (size_t)(n0 >> (k - 1)) * (size_t)(n0 >> (k - 1));
    float *down = (float *)(void *)(r->sil_buf + bytes), *across = down + n1;
    /* the texture, not its framebuffer: with the silhouette drawn through
     * that same framebuffer (a silhouette of 1024), llvmpipe's
     * glReadPixels (Mesa 22.3) returned the previous frame's level 0 */
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.BindTexture(GL_TEXTURE_2D, r->sil_tex);
    gl.GetTexImage(GL_TEXTURE_2D, 0, GL_RED, GL_UNSIGNED_BYTE, lev[0]);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    float kw[5];
    int reach = r_blur_kernel(1, kw);
    gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl.BindTexture(GL_TEXTURE_2D, r->sil_tex);
    for (int k = 1; k < SIL_LEVELS; k++) {
        int n = n0 >> k, pn = n0 >> (k - 1);
        sil_level_box(b, n);
        const uint8_t *src = lev[k - 1];
        uint8_t *dst = lev[k];
        memset(dst, 0, (size_t)n * (size_t)n);
        memset(down, 0, (size_t)n * (size_t)n * sizeof *down);
        memset(across, 0, (size_t)n * (size_t)n * sizeof *across);
        /* the 4x4 box of the level before (off it: zero, the border) */
        for (int j = b[1]; j < b[3]; j++)
            for (int i = b[0]; i < b[2]; i++) {
                int s = 0;
                for (int y = 2 * j - 1; y <= 2 * j + 2; y++)
                    for (int x = 2 * i - 1; x <= 2 * i + 2; x++)
                        s += x >= 0 && x < pn && y >= 0 && y < pn ? src[(size_t)y * (size_t)pn + (size_t)x] : 0;
                down[(size_t)j * (size_t)n + (size_t)i] = (float)unorm8((float)s * (1.0f / (16 * 255.0f))) * (1.0f / 255);
            }
        /* the blurs, each tap off the level zero */
        blur_box(down, n, n, b, kw, reach, true, true, across, NULL);
        blur_box(across, n, n, b, kw, reach, false, true, NULL, dst);
        gl.TexSubImage2D(GL_TEXTURE_2D, k, 0, 0, n, n, GL_RED, GL_UNSIGNED_BYTE, dst);
    }
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    return true;
}

static void run_silhouette_mips(void *u)
{
    r_game *r = u;
    int b[4];
    sil_footprint(r, b);
    if (r->cpu_paths && sil_mips_cpu(r, b))
        return;
    gl.Disable(GL_DEPTH_TEST);
    gl.ClearColor(0, 0, 0, 0);
    for (int k = 1; k < SIL_LEVELS; k++) {
        int n = r->sil_size >> k;
        sil_level_box(b, n);
        restrict_level(r->sil_tex, k - 1);
        clear_then_scissor(r->sil_fbo[k], b);
        r_down_into(r, r->sil_fbo[k], r->sil_tex, 0, n, n, -1, 1);
        restrict_level(r->sil_tex, k);
        clear_then_scissor(r->sil_tmp_fbo[k], b);
        r_blur_texels_into(r, r->sil_tmp_fbo[k], r->sil_tex, 0, n, n, 1, 0, true);
        restrict_level(r->sil_tmp, k);
        r_blur_texels_into(r, r->sil_fbo[k], r->sil_tmp, 0, n, n, 0, 1, true);
    }
    gl.Disable(GL_SCISSOR_TEST);
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

/* The fighters' box in mask pixels (x0 y0 x1 y1, x1 y1 exclusive): render
 * pixels taken to the mask's, rounded outwards. */
static void mask_box(const r_game *r, int m[4])
{
    const int *b = r->f.fig_box;
    if (r->mask_w == r->f.w && r->mask_h == r->f.h) {
        m[0] = b[0], m[1] = b[1], m[2] = b[0] + b[2], m[3] = b[1] + b[3];
        return;
    }
    double sx = (double)r->mask_w / r->f.w, sy = (double)r->mask_h / r->f.h;
    m[0] = (int)floor(b[0] * sx), m[1] = (int)floor(b[1] * sy);
    m[2] = (int)ceil((b[0] + b[2]) * sx), m[3] = (int)ceil((b[1] + b[3]) * sy);
}

/* The bound mask buffer: all 1 (lit), then draws limited to the fighters'
 * box. */
static void mask_clear_and_scissor(r_game *r)
{
    gl.Disable(GL_SCISSOR_TEST);
    gl.ClearColor(1, 1, 1, 1);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    gl.Enable(GL_SCISSOR_TEST);
    int m[4];
    mask_box(r, m);
    gl.Scissor(m[0], m[1], m[2] - m[0], m[3] - m[1]);
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

/* The filter in C (r->cpu_paths: a software rasteriser), for blur steps
 * of at most a texel (the mask at 1440 rows or fewer): the mask is read
 * back, grown and blurred inside the fighters' box as mask_grow.frag and
 * blur.frag's REACH variants do, each step rounded to a byte where its R8
 * target rounds, 1 outside the box as the clears leave it, and uploaded
 * as the final mask.  On llvmpipe the three passes and their clears cost
 * 1.3-1.6 ms a frame on one thread for a box of about 10,000 texels. */
static bool mask_filter_cpu(r_game *r, float k)
{
    int w = r->mask_w, h = r->mask_h, b[4];
    float kw[5];
    int reach = r_blur_kernel(k, kw);
    if (!(k > 0 && k <= 1))
        return false;
    mask_box(r, b);
    b[0] = b[0] < 0 ? 0 : b[0], b[1] = b[1] < 0 ? 0 : b[1];
    b[2] = b[2] > w ? w : b[2], b[3] = b[3] > h ? h : b[3];
    size_t n = (size_t)w * (size_t)h, need = 2 * n + 16 + 2 * n * sizeof(float); /* 16: the floats' alignment */
    if (need > r->mask_buf_n) {
        uint8_t *p = realloc(r->mask_buf, need);
        if (!p)
            return false;
        r->mask_buf = p, r->mask_buf_n = need;
    }
    uint8_t *src = r->mask_buf, *out = src + n;
    float *grown = (float *)(void *)(out + n + (16 - (2 * n) % 16) % 16), *across = grown + n;
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.BindTexture(GL_TEXTURE_2D, r->mask_tex[0]);
    gl.GetTexImage(GL_TEXTURE_2D, 0, GL_RED, GL_UNSIGNED_BYTE, src);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    for (size_t i = 0; i < n; i++)
        grown[i] = across[i] = 1;
    memset(out, 255, n);
    /* grow: the minimum of the 3x3 bilinear taps k texels apart (k <= 1:
     * mask_grow.frag's one tap each side); a tap k to the left of texel x
     * is k of texel x - 1 and 1 - k of x, so each is two weights of the
     * texels next to it, clamped at the edges */
    const float kk = k, k1 = 1 - k, inv = 1.0f / 255;
    for (int y = b[1]; y < b[3]; y++) {
        const uint8_t *rows[3] = {src + (size_t)(y > 0 ? y - 1 : 0) * (size_t)w, src + (size_t)y * (size_t)w,
                                  src + (size_t)(y + 1 < h ? y + 1 : h - 1) * (size_t)w};
        for (int x = b[0]; x < b[2]; x++) {
            int xa = x > 0 ? x - 1 : 0, xb = x + 1 < w ? x + 1 : w - 1;
            float t[3][3];
            for (int q = 0; q < 3; q++) {
                float c = (float)rows[q][x] * inv;
                t[q][0] = kk * (float)rows[q][xa] * inv + k1 * c, t[q][1] = c, t[q][2] = k1 * c + kk * (float)rows[q][xb] * inv;
            }
            float lo = 1;
            for (int c = 0; c < 3; c++) {
                float up = kk * t[0][c] + k1 * t[1][c], mid = t[1][c], down = k1 * t[1][c] + kk * t[2][c];
                lo = fminf(lo, fminf(mid, fminf(up, down)));
            }
            grown[(size_t)y * (size_t)w + (size_t)x] = (float)unorm8(lo) * inv;
        }
    }
    /* the blurs (clamped at the edges), across then down */
    blur_box(grown, w, h, b, kw, reach, true, false, across, NULL);
    blur_box(across, w, h, b, kw, reach, false, false, NULL, out);
    gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl.BindTexture(GL_TEXTURE_2D, r->mask_tex[1]);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RED, GL_UNSIGNED_BYTE, out);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    r->mask_final = 1;
    return true;
}

/* SSFSM step 3: grow dark by 1/720 of the frame height, then blur (sigma
 * 2/720 of it) (mask 0 -> 1 -> 0 -> 1) */
static void run_mask_filter(void *u)
{
    r_game *r = u;
    GLuint p = r->prog[P_GROW];
    float k = mask_unit(r);
    if (r->cpu_paths && mask_filter_cpu(r, k))
        return;
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->mask_fbo[1]);
    gl.Viewport(0, 0, r->mask_w, r->mask_h);
    mask_clear_and_scissor(r);
    gl.UseProgram(p);
    r_bind_tex(p, "u_src", 0, GL_TEXTURE_2D, r->mask_tex[0]);
    gl.Uniform1f(r_loc(p, "u_radius"), k);
    r_fullscreen(r);
    /* outside the box both buffers hold 1, so the blur reads the truth there */
    r_blur_texels_into(r, r->mask_fbo[0], r->mask_tex[1], 0, r->mask_w, r->mask_h, k, 0, false);
    r_blur_texels_into(r, r->mask_fbo[1], r->mask_tex[0], 0, r->mask_w, r->mask_h, 0, k, false);
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
