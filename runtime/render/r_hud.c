/* The HUD: health bars, round wins, the timer and the round messages,
 * drawn over the tone-mapped output in the 5x7 font (r_font.h). */
#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../game/g_game.h"
#include "r_font.h"
#include "r_local.h"

static bool need_hud(void *u)
{
    r_game *r = u;
    return !r->opts.no_hud && !r->opts.mask;
}

/* Each quad grows by a pixel each side (its uv with it), so the shader's
 * coverage (hud.frag) can soften edges that fall between pixels: the HUD
 * is sized in fractions of the height, and looks the same at any size. */
static void quad(r_game *r, float x, float y, float w, float h, const float c[4], float u0, float v0, float u1, float v1)
{
    if (r->nhud + 6 > HUD_MAX_QUADS * 6 || w <= 0 || h <= 0)
        return;
    float du = (u1 - u0) / w, dv = (v1 - v0) / h;
    /* a glyph's cell has a blank column and row on its right and bottom:
     * growing there would read the next glyph's texels */
    bool glyph = u0 >= 0;
    x -= 1, y -= 1, w += glyph ? 1 : 2, h += glyph ? 1 : 2, u0 -= du, v0 -= dv;
    if (!glyph)
        u1 += du, v1 += dv;
    hud_vertex q[4] = {{x, y, u0, v0, c[0], c[1], c[2], c[3]},
                       {x + w, y, u1, v0, c[0], c[1], c[2], c[3]},
                       {x + w, y + h, u1, v1, c[0], c[1], c[2], c[3]},
                       {x, y + h, u0, v1, c[0], c[1], c[2], c[3]}};
    const int order[6] = {0, 1, 2, 0, 2, 3};
    for (int k = 0; k < 6; k++)
        r->hud[r->nhud++] = q[order[k]];
}

/* uv -2..-1 across a rect tells the shader it is one (and where in it) */
static void rect(r_game *r, float x, float y, float w, float h, const float c[4])
{
    quad(r, x, y, w, h, c, -2, -2, -1, -1);
}

static float text_width(const char *s, float px)
{
    return (float)strlen(s) * 6 * px - px;
}

/* Text with a drop shadow; px is the size of one font pixel. */
static void text(r_game *r, const char *s, float x, float y, float px, const float c[4])
{
    static const float shadow[4] = {0, 0, 0, 1};
    for (int pass = 0; pass < 2; pass++) {
        float cx = x + (pass ? 0 : px * 0.6f), cy = y + (pass ? 0 : px * 0.6f);
        for (const char *p = s; *p; p++, cx += 6 * px) {
            int g = -1;
            for (int k = 0; k < R_FONT_GLYPHS; k++)
                if (r_font_glyphs[k].c == *p)
                    g = k;
            if (g < 0 || *p == ' ')
                continue;
            float u0 = (float)(g * 6) / (6 * R_FONT_GLYPHS), u1 = (float)(g * 6 + 6) / (6 * R_FONT_GLYPHS);
            quad(r, cx, cy, 6 * px, 8 * px, pass ? c : shadow, u0, 0, u1, 1);
        }
    }
}

static void centered(r_game *r, const char *s, int w, float y, float px, const float c[4])
{
    text(r, s, (w - text_width(s, px)) / 2, y, px, c);
}

static void build_hud(r_game *r, const g_state *st, int w, int h)
{
    r->nhud = 0;
    float unit = h / 100.0f; /* HUD sizes scale with the window height */
    const float back[4] = {0.05f, 0.05f, 0.07f, 1}, white[4] = {1, 1, 1, 1}, gold[4] = {1, 0.8f, 0.2f, 1};
    float bar_w = w * 0.36f, bar_h = 3.2f * unit, top = 3 * unit;
    for (int i = 0; i < 2; i++) {
        float x = i == 0 ? w * 0.05f : w * 0.95f - bar_w;
        float frac = (float)st->f[i].health / G_MAX_HEALTH;
        float fill[4] = {1.0f, 0.25f + 0.6f * frac, 0.1f, 1};
        rect(r, x - 0.4f * unit, top - 0.4f * unit, bar_w + 0.8f * unit, bar_h + 0.8f * unit, back);
        float fw = bar_w * frac;
        rect(r, i == 0 ? x + bar_w - fw : x, top, fw, bar_h, fill); /* bars drain towards the centre */
        const float *col = r_fighter_color[i];
        const float name_c[4] = {col[0] + 0.2f, col[1] + 0.2f, col[2] + 0.2f, 1};
        text(r, i == 0 ? "P1" : "P2", i == 0 ? x : x + bar_w - text_width("P2", 0.5f * unit), top + bar_h + 1.2f * unit,
             0.5f * unit, name_c);
        for (int k = 0; k < G_ROUNDS_TO_WIN; k++) { /* round wins */
            float px = i == 0 ? x + bar_w - (k + 1) * 3 * unit : x + k * 3 * unit;
            rect(r, px, top + bar_h + 1.2f * unit, 2.2f * unit, 2.2f * unit, k < st->f[i].rounds_won ? gold : back);
        }
    }
    char buf[32];
    int secs = (st->round_timer + G_HZ - 1) / G_HZ;
    snprintf(buf, sizeof buf, "%02d", secs > 99 ? 99 : secs);
    centered(r, buf, w, 1.5f * unit, 0.9f * unit, white);

    const char *msg = NULL;
    switch (st->phase) {
    case G_PHASE_INTRO:
        snprintf(buf, sizeof buf, st->phase_ticks < 60 ? "ROUND %d" : "FIGHT!", st->round);
        msg = buf;
        break;
    case G_PHASE_ROUND_END:
        msg = st->round_result == G_RES_KO         ? "K.O."
              : st->round_result == G_RES_RING_OUT ? "RING OUT"
              : st->round_result == G_RES_TIME     ? (st->round_winner ? "TIME" : "DRAW")
                                                   : "DRAW";
        break;
    case G_PHASE_MATCH_END:
        if (st->match_winner > 0)
            snprintf(buf, sizeof buf, "P%d WINS", st->match_winner);
        else
            snprintf(buf, sizeof buf, "DRAW GAME");
        msg = buf;
        break;
    default: break;
    }
    if (msg)
        centered(r, msg, w, 38 * unit, 1.6f * unit, gold);
}

/* Which program draws quad q: P_HUD_RECT for a rect (u < -0.5, rect()
 * above); for a glyph, P_HUD_2TAPS when a font texel is at least a screen
 * pixel wide and high (the pixel's box then touches at most 2x2 texels,
 * hud.frag), else P_HUD. */
static int quad_program(const r_game *r, int q)
{
    const hud_vertex *v = &r->hud[q * 6]; /* corners 0, 1, 2: x0 y0, x1 y0, x1 y1 */
    if (v[0].u < -0.5f)
        return P_HUD_RECT;
    float tex_w = 6.0f * R_FONT_GLYPHS, tex_h = 8.0f;
    float px_x = (v[1].x - v[0].x) / ((v[1].u - v[0].u) * tex_w), px_y = (v[2].y - v[0].y) / ((v[2].v - v[0].v) * tex_h);
    return px_x >= 1.01f && px_y >= 1.01f ? P_HUD_2TAPS : P_HUD;
}

/* The quads in their order, each run of one program one draw: the same
 * blending order as a single draw, without the glyphs' filter on the
 * bars' pixels (llvmpipe runs both sides of hud.frag's old branch: about
 * 1 ms a frame at 640x360, most of the HUD's cost). */
static void run_hud(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    build_hud(r, f->cur, f->out_w, f->out_h); /* at the output's size, whatever the scene's */
    gl.BindFramebuffer(GL_FRAMEBUFFER, (GLuint)f->out_fbo);
    gl.Viewport(0, 0, f->out_w, f->out_h);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    gl.Enable(GL_BLEND); /* coverage in alpha; the output's alpha stays */
    gl.BlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    gl.BindVertexArray(r->hud_vao);
    gl.BindBuffer(GL_ARRAY_BUFFER, r->hud_vbo);
    gl.BufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(r->nhud * sizeof(hud_vertex)), r->hud);
    for (int q = 0, nq = r->nhud / 6; q < nq;) {
        int id = quad_program(r, q), end = q + 1;
        while (end < nq && quad_program(r, end) == id)
            end++;
        GLuint p = r->prog[id];
        gl.UseProgram(p);
        gl.Uniform2f(r_loc(p, "u_screen"), (float)f->out_w, (float)f->out_h);
        if (id != P_HUD_RECT)
            r_bind_tex(p, "u_font", 0, GL_TEXTURE_2D, r->font_tex);
        gl.DrawArrays(GL_TRIANGLES, q * 6, (end - q) * 6);
        q = end;
    }
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
    gl.Disable(GL_BLEND);
}

GLuint r_hud_font(void)
{
    /* one row of 6x8 cells (a blank column and row between glyphs) */
    enum { CW = 6, CH = 8 };
    int w = CW * R_FONT_GLYPHS;
    uint8_t *px = calloc((size_t)w * CH, 1);
    if (!px)
        return 0;
    for (int g = 0; g < R_FONT_GLYPHS; g++)
        for (int y = 0; y < R_FONT_H; y++)
            for (int x = 0; x < R_FONT_W; x++)
                if (r_font_glyphs[g].rows[y] & (0x10 >> x))
                    px[(size_t)y * w + g * CW + x] = 255;
    GLuint t = r_tex2d(GL_R8, w, CH, GL_RED, GL_UNSIGNED_BYTE, px, GL_NEAREST, GL_CLAMP_TO_EDGE);
    free(px);
    return t;
}

const r_pass r_hud_pass = {"hud", RES_OUT, RES_OUT, need_hud, run_hud, 0};
