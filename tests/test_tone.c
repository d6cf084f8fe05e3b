/* runtime/render/r_tone and shaders/tonemap.frag: the YCbCr tone curve
 * (docs/renderer.md, "Tone map, bloom, flare"), its lookup table, and the shader that uses it,
 * against the curve and against points of it worked out outside the code (KNOWN). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_fx_core.h"
#include "../runtime/render/r_shader.h"
#include "../runtime/render/r_tone.h"
#include "t.h"

static const double STEP = 1.0 / 255.0; /* one 8-bit output step */

static void t_curve_shape(void)
{
    /* (1 - exp(-x^2))^1.5 with gamma 1: values checked by hand */
    T_ASSERT(r_tone_curve(0, 2.2) == 0);
    T_ASSERT(r_tone_curve(-1, 2.2) == 0);
    T_ASSERT(r_tone_curve(NAN, 2.2) == 0);
    T_ASSERT(fabs(r_tone_curve(1, 1) - pow(1 - exp(-1.0), 1.5)) < 1e-12);
    T_ASSERT(fabs(r_tone_curve(1, 1) - 0.5025) < 1e-4);
    /* gamma folded in */
    T_ASSERT(fabs(r_tone_curve(0.7, 2.2) - pow(r_tone_curve(0.7, 1), 1 / 2.2)) < 1e-12);
    /* monotonic, within [0, 1], 1 at the top */
    double prev = 0;
    for (int i = 1; i <= 4000; i++) {
        double x = i * 0.001, y = r_tone_curve(x, 2.2);
        T_ASSERTF(y >= prev && y <= 1, "x %.3f: %.9f after %.9f", x, y, prev);
        prev = y;
    }
    T_ASSERT(1 - r_tone_curve(R_TONE_X_MAX, 2.2) < 1e-6);
    T_ASSERT(r_tone_curve(1e30, 2.2) == 1);
}

/* Known points of the curve, worked outside the code: Python's decimal
 * module at 40 digits, ((1 - exp(-x^2))^1.5)^(1/gamma) as exp(1.5 ln(1 -
 * exp(-x^2)) / gamma), rounded to 10 places (Python's floats give the same
 * 10 places).  1e-9: the literals' own rounding.  An exponent of 1.55 instead
 * of 1.5 moves them by up to 0.012, exp(-1.01 x^2) by up to 0.003. */
static const struct {
    double x, gamma, want;
} KNOWN[] = {
    {0.18, 1, 0.0056923639},  {0.5, 1, 0.1040340194},  {1, 1, 0.5025738332},  {2, 1, 0.9726527268},
    {4, 1, 0.9999998312},     {16, 1, 1.0},            {0.18, 2.2, 0.0954285838}, {0.5, 2.2, 0.3574880553},
    {1, 2.2, 0.7314451431},   {2, 2.2, 0.9874753804},  {4, 2.2, 0.9999999233}, {16, 2.2, 1.0},
    {0.18, 10, 0.5963885067}, {1, 10, 0.9335121768},   {0, 2.2, 0},
};

static void t_curve_known_points(void)
{
    for (size_t k = 0; k < sizeof KNOWN / sizeof KNOWN[0]; k++) {
        double got = r_tone_curve(KNOWN[k].x, KNOWN[k].gamma);
        T_ASSERTF(fabs(got - KNOWN[k].want) < 1e-9, "curve(%g) at gamma %g: %.10f, worked out %.10f", KNOWN[k].x,
                  KNOWN[k].gamma, got, KNOWN[k].want);
    }
}

static void t_lut_entries_are_the_curve(void)
{
    float lut[256];
    r_tone_lut(lut, 256, 2.2);
    T_ASSERT(lut[0] == 0);
    for (int k = 0; k < 256; k++) {
        double u = k / 255.0;
        T_ASSERTF(fabs(lut[k] - r_tone_curve(u * u * R_TONE_X_MAX, 2.2)) < 1e-7, "entry %d", k);
    }
    /* the lookup hits the entries exactly at their x */
    for (int k = 0; k < 256; k += 17) {
        double u = k / 255.0;
        T_ASSERT(fabs(r_tone_lookup(lut, 256, 2.2, u * u * R_TONE_X_MAX, 0) - lut[k]) < 1e-6);
    }
    /* beyond the table: flat at the last entry */
    T_ASSERT(r_tone_lookup(lut, 256, 2.2, 1e9, 0) == lut[255]);
    T_ASSERT(r_tone_lookup(lut, 256, 2.2, -5, 0) == 0);
    /* high gamma: the index power grows (m = gamma / 2 above 4) */
    T_ASSERT(r_tone_index_power(2.2) == 2 && r_tone_index_power(4) == 2 && r_tone_index_power(10) == 5);
    r_tone_lut(lut, 256, 10);
    for (int k = 0; k < 256; k += 15) {
        double u = k / 255.0;
        T_ASSERTF(fabs(lut[k] - r_tone_curve(pow(u, 5) * R_TONE_X_MAX, 10)) < 1e-7, "gamma 10 entry %d", k);
    }
}

/* The goal: < 0.1 of an 8-bit step at the default size. */
static void t_default_lut_error_under_a_tenth_step(void)
{
    double e = r_tone_max_error(R_TONE_LUT_DEFAULT, 2.2, 0);
    fprintf(stderr, "    n %d gamma 2.2: max error %.5f steps\n", R_TONE_LUT_DEFAULT, e / STEP);
    T_ASSERTF(e < 0.1 * STEP, "max error %.5f of an 8-bit step", e / STEP);
    /* and it converges: 4x the entries, well under a quarter of the error */
    double e4 = r_tone_max_error(4 * R_TONE_LUT_DEFAULT, 2.2, 0);
    T_ASSERTF(e4 < e / 4, "n %d: %.6f, n %d: %.6f", R_TONE_LUT_DEFAULT, e, 4 * R_TONE_LUT_DEFAULT, e4);
    /* a texture unit's 8-bit weights would cost more than the table */
    double e8 = r_tone_max_error(R_TONE_LUT_DEFAULT, 2.2, 8);
    T_ASSERTF(e8 > e, "8-bit weights %.6f vs exact %.6f", e8, e);
}

/* Across the whole gamma range a stage file allows (0.1..10). */
static void t_every_gamma_meets_the_goal(void)
{
    const double gammas[] = {0.1, 0.45, 1.0, 1.8, 2.2, 3.0, 4.0, 5.0, 7.0, 10.0};
    for (size_t g = 0; g < sizeof gammas / sizeof gammas[0]; g++) {
        double e = r_tone_max_error(R_TONE_LUT_DEFAULT, gammas[g], 0);
        fprintf(stderr, "    gamma %4.2f: %.4f steps\n", gammas[g], e / STEP);
        T_ASSERTF(e < 0.1 * STEP, "gamma %.2f: %.4f of an 8-bit step", gammas[g], e / STEP);
    }
    /* the curve itself near 0 at high gamma: x^(3/gamma), no cancellation */
    T_ASSERTF(fabs(r_tone_curve(1e-9, 10) - pow(1e-9, 0.3)) < 1e-6, "%.9g", r_tone_curve(1e-9, 10));
}

static void t_small_tables_fail_the_goal(void)
{
    /* the measurement is real: 16 entries cannot meet it */
    T_ASSERT(r_tone_max_error(16, 2.2, 0) > 0.1 * STEP);
    /* 32 entries neither at gamma 2.2, 64 not at gamma 1 (the knee); 128 do at 2.2 */
    T_ASSERT(r_tone_max_error(32, 2.2, 0) > 0.1 * STEP);
    T_ASSERT(r_tone_max_error(64, 1.0, 0) > 0.1 * STEP);
    T_ASSERT(r_tone_max_error(128, 2.2, 0) < 0.1 * STEP);
    /* the default meets it for gamma 1 too */
    T_ASSERT(r_tone_max_error(R_TONE_LUT_DEFAULT, 1.0, 0) < 0.1 * STEP);
}

/* w x rows RGBA float pixels through tonemap.frag, with the default-size
 * table for gamma, into a float target: out gets them back (RGBA). */
static void tone_draw(double gamma, float exposure, float saturation, const float *in, int w, int rows, float *out)
{
    rs_err e = {0};
    GLuint prog = r_program(&(r_program_desc){.vs = "cap_fullscreen.vert", .fs = "tonemap.frag"}, &e);
    T_ASSERTF(prog, "%s", e.msg);
    GLuint tex[3], fbo;
    gl.GenTextures(3, tex);
    gl.BindTexture(GL_TEXTURE_2D, tex[0]);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, w, rows, 0, GL_RGBA, GL_FLOAT, in);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    float lut[R_TONE_LUT_DEFAULT];
    r_tone_lut(lut, R_TONE_LUT_DEFAULT, gamma);
    gl.BindTexture(GL_TEXTURE_1D, tex[1]);
    gl.TexImage1D(GL_TEXTURE_1D, 0, GL_R32F, R_TONE_LUT_DEFAULT, 0, GL_RED, GL_FLOAT, lut);
    gl.TexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.BindTexture(GL_TEXTURE_2D, tex[2]);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, w, rows, 0, GL_RGBA, GL_FLOAT, NULL);
    gl.GenFramebuffers(1, &fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex[2], 0);
    T_EQ(gl.CheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    gl.Viewport(0, 0, w, rows);
    gl.UseProgram(prog);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, tex[0]);
    gl.ActiveTexture(GL_TEXTURE1);
    gl.BindTexture(GL_TEXTURE_1D, tex[1]);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.Uniform1i(gl.GetUniformLocation(prog, "u_hdr"), 0);
    gl.Uniform1i(gl.GetUniformLocation(prog, "u_lut"), 1);
    gl.Uniform1i(gl.GetUniformLocation(prog, "u_lut_size"), R_TONE_LUT_DEFAULT);
    gl.Uniform1f(gl.GetUniformLocation(prog, "u_lut_inv_power"), (float)(1.0 / r_tone_index_power(gamma)));
    gl.Uniform1f(gl.GetUniformLocation(prog, "u_exposure"), exposure);
    gl.Uniform1f(gl.GetUniformLocation(prog, "u_saturation"), saturation);
    gl.Uniform1i(gl.GetUniformLocation(prog, "u_write_mask"), 0);
    GLuint vao;
    gl.GenVertexArrays(1, &vao);
    gl.BindVertexArray(vao);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    gl.ReadPixels(0, 0, w, rows, GL_RGBA, GL_FLOAT, out);
    T_EQ(gl.GetError(), GL_NO_ERROR);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.DeleteVertexArrays(1, &vao);
    gl.DeleteFramebuffers(1, &fbo);
    gl.DeleteTextures(3, tex);
    gl.DeleteProgram(prog);
}

/* The shader against the double-precision curve: a ramp of grey HDR
 * values (and colours) through tonemap.frag into a float target. */
enum { N = 512 };

static void shader_vs_curve(double gamma, float saturation)
{
    plat *p = t_context("egl");
    /* input: row 0 grey ramp x in [0, 6]; row 1 colours of the same luminance */
    static float in[2 * N * 4], out[2 * N * 4];
    for (int i = 0; i < N; i++) {
        float x = 6.0f * i / (N - 1) * (6.0f * i / (N - 1)) / 6.0f; /* denser near 0 */
        float *g = in + 4 * i, *c = in + 4 * (N + i);
        g[0] = g[1] = g[2] = x, g[3] = 1;
        c[0] = 1.5f * x, c[1] = 0.9f * x, c[2] = 0.4f * x, c[3] = 1;
    }
    tone_draw(gamma, 1.0f, saturation, in, N, 2, out);
    double worst = 0;
    for (int i = 0; i < N; i++) {
        const float *g = out + 4 * i, *c = out + 4 * (N + i);
        double want = r_tone_curve(in[4 * i], gamma);
        for (int k = 0; k < 3; k++)
            worst = fmax(worst, fabs(g[k] - want));
        T_ASSERTF(g[3] == 1.0f, "alpha %g", g[3]);
        /* a colour keeps its luminance's Y' (where nothing clips) */
        double y = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
        const float *ci = in + 4 * (N + i);
        double want_c = r_tone_curve(0.2126 * ci[0] + 0.7152 * ci[1] + 0.0722 * ci[2], gamma);
        if (c[0] < 0.999f && c[2] > 0.001f)
            T_ASSERTF(fabs(y - want_c) < 1e-3, "x %g: colour Y' %.5f, want %.5f", in[4 * i], y, want_c);
        if (saturation == 0)
            T_ASSERTF(fabs(c[0] - c[2]) < 1e-5, "saturation 0 left colour at x %g: %g %g", in[4 * i], c[0], c[2]);
        else if (want > 0.05 && want < 0.6) /* not clipped: red stays above blue */
            T_ASSERTF(c[0] > c[2], "x %g: hue lost (%g %g %g)", in[4 * i], c[0], c[1], c[2]);
        for (int k = 0; k < 4; k++)
            T_ASSERT(isfinite(c[k]) && isfinite(g[k]));
    }
    fprintf(stderr, "    gamma %.1f saturation %.0f: shader vs curve, max error %.5f steps\n", gamma, saturation,
            worst / STEP);
    /* float math on the GPU, the table's own error < 0.1 step: allow 0.15 */
    T_ASSERTF(worst < 0.15 * STEP, "shader vs curve: %.5f of an 8-bit step", worst / STEP);
    plat_destroy(p);
}

/* The shader against the worked-out points (KNOWN), and colour by the
 * curve's definition (docs/renderer.md): with Y the BT.709 luminance
 * (Kr 0.2126, Kb 0.0722) of the exposed input and Y' its curve, each
 * channel c goes to Y' + saturation (Y'/Y) (c - Y), i.e. c Y'/Y at
 * saturation 1; worked out as KNOWN's at gamma 2.2 for a red (1, 0.1,
 * 0.05: Y 0.28773, Y' 0.1778606094) and a blue (0.1, 0.15, 1.2: Y 0.21518,
 * Y' 0.1211589667).  0.05 of an 8-bit step: the table and float arithmetic
 * cost 0.015 (measured on llvmpipe); exp(-1.01 x^2) instead of exp(-x^2)
 * moves the greys by 0.13 to 0.74 of a step, an exponent of 1.55 by 0.1 to
 * 3.1, a luminance weight off by 0.002 the colours by 0.3 to 0.56. */
static void t_shader_known_points(void)
{
    const double TOL = 0.05 * STEP;
    static const float col[2][3] = {{1.0f, 0.1f, 0.05f}, {0.1f, 0.15f, 1.2f}};
    static const double want_col[2][2][3] = { /* [saturation 1, 0.5][colour][channel] */
        {{0.6181510770, 0.0618151077, 0.0309075539}, {0.0563058680, 0.0844588019, 0.6756704154}},
        {{0.3980058432, 0.1198378585, 0.1043840816}, {0.0887324173, 0.1028088843, 0.3984146911}},
    };
    plat *p = t_context("egl");
    enum { M = 16 };
    float in[M * 4] = {0}, out[M * 4];
    int n = 0, half = -1;
    for (size_t k = 0; k < sizeof KNOWN / sizeof KNOWN[0]; k++)
        if (KNOWN[k].gamma == 2.2) {
            half = KNOWN[k].x == 0.5 ? n : half;
            float *g = in + 4 * n++;
            g[0] = g[1] = g[2] = (float)KNOWN[k].x, g[3] = 1;
        }
    for (int c = 0; c < 2; c++)
        for (int ch = 0; ch < 4; ch++)
            in[4 * (n + c) + ch] = ch < 3 ? col[c][ch] : 1;
    double worst = 0;
    /* saturation 1, saturation 0.5, and exposure 2 (grey 0.5 becomes the curve at 1) */
    for (int pass = 0; pass < 3; pass++) {
        tone_draw(2.2, pass == 2 ? 2.0f : 1.0f, pass == 1 ? 0.5f : 1.0f, in, n + 2, 1, out);
        if (pass == 2) {
            double d = fabs(out[4 * half] - 0.7314451431);
            worst = fmax(worst, d);
            T_ASSERTF(d < TOL, "exposure 2 on grey 0.5: %.6f, worked out 0.7314451431", out[4 * half]);
            continue;
        }
        for (int i = 0, k = 0; pass == 0 && i < n; k++) {
            if (KNOWN[k].gamma != 2.2)
                continue;
            for (int ch = 0; ch < 3; ch++) {
                double d = fabs(out[4 * i + ch] - KNOWN[k].want);
                worst = fmax(worst, d);
                T_ASSERTF(d < TOL, "grey %g channel %d: %.6f, worked out %.6f (%.2f steps off)", KNOWN[k].x, ch,
                          out[4 * i + ch], KNOWN[k].want, d / STEP);
            }
            i++;
        }
        for (int c = 0; c < 2; c++)
            for (int ch = 0; ch < 3; ch++) {
                double got = out[4 * (n + c) + ch], want = want_col[pass][c][ch], d = fabs(got - want);
                worst = fmax(worst, d);
                T_ASSERTF(d < TOL, "(%g, %g, %g) at saturation %.1f, channel %d: %.6f, worked out %.6f (%.2f steps off)",
                          col[c][0], col[c][1], col[c][2], pass ? 0.5 : 1.0, ch, got, want, d / STEP);
            }
    }
    fprintf(stderr, "    shader vs worked-out points: max error %.5f steps\n", worst / STEP);
    plat_destroy(p);
}

static void t_shader_matches_curve_gamma_22(void) { shader_vs_curve(2.2, 1.0f); }
static void t_shader_matches_curve_gamma_1(void) { shader_vs_curve(1.0, 1.0f); }
static void t_shader_saturation_0_is_grey(void) { shader_vs_curve(2.2, 0.0f); }
static void t_shader_matches_curve_gamma_10(void) { shader_vs_curve(10.0, 1.0f); }

/* ---- bloom's levels: RGBE in RGBA8 (shaders/rgbe_common.glsl) ---- */

/* One pass of downsample.frag (defines) from src into a 1x1 target of
 * format dst_fmt; out gets the pixel as floats (RGBA8: the bytes / 255). */
static void down_1x1(const char *defines, GLuint src, GLenum dst_fmt, float out[4])
{
    rs_err e = {0};
    GLuint prog = r_program(&(r_program_desc){.vs = "cap_fullscreen.vert", .fs = "downsample.frag", .defines = defines}, &e);
    T_ASSERTF(prog, "%s", e.msg);
    GLuint vao, dst = r_tex2d(dst_fmt, 1, 1, GL_RGBA, GL_FLOAT, NULL, GL_NEAREST, GL_CLAMP_TO_EDGE), fbo = r_fbo_for(dst, 0, 0);
    T_EQ(gl.CheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    gl.Viewport(0, 0, 1, 1);
    gl.UseProgram(prog);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, src);
    gl.Uniform1i(gl.GetUniformLocation(prog, "u_src"), 0);
    gl.Uniform1f(gl.GetUniformLocation(prog, "u_lod"), 0);
    gl.Uniform2f(gl.GetUniformLocation(prog, "u_dst"), 1, 1);
    gl.Uniform1f(gl.GetUniformLocation(prog, "u_threshold"), -1);
    gl.Uniform1f(gl.GetUniformLocation(prog, "u_scale"), 1);
    gl.GenVertexArrays(1, &vao);
    gl.BindVertexArray(vao);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    gl.ReadPixels(0, 0, 1, 1, GL_RGBA, GL_FLOAT, out);
    T_EQ(gl.GetError(), GL_NO_ERROR);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.DeleteVertexArrays(1, &vao);
    gl.DeleteFramebuffers(1, &fbo);
    gl.DeleteTextures(1, &dst);
    gl.DeleteProgram(prog);
}

/* a w x h float image as the shaders sample bloom's: nearest, clamped */
static GLuint tex_of(GLenum fmt, int w, int h, const float *px)
{
    return r_tex2d(fmt, w, h, GL_RGBA, GL_FLOAT, px, GL_NEAREST, GL_CLAMP_TO_EDGE);
}

/* The format as docs/renderer.md states it, worked here without the
 * shader's code: RGB bytes / 255 x 2^(A byte - 128). */
static void rgbe_value(const float px[4], double v[3])
{
    int k = (int)lround(px[3] * 255);
    for (int c = 0; c < 3; c++)
        v[c] = round(px[c] * 255) / 255 * ldexp(1, k - 128);
}

static void t_bloom_levels_rgbe(void)
{
    plat *p = t_context("egl");
    /* a colour (v, v/3, v/40) at every power of two half floats hold, and between them */
    double worst = 0;
    int n = 0;
    for (double v = 1e-7; v <= 65504; v *= 1.7, n++) {
        float c[3] = {(float)v, (float)(v / 3), (float)(v / 40)}, src[4 * 4];
        for (int i = 0; i < 4; i++)
            src[4 * i] = c[0], src[4 * i + 1] = c[1], src[4 * i + 2] = c[2], src[4 * i + 3] = 1;
        /* a 2x2 source of one colour: the box down to 1x1 is that colour */
        GLuint hdr = tex_of(GL_RGBA32F, 2, 2, src);
        float enc[4], again[4];
        down_1x1("#define RGBE_OUT 1\n", hdr, GL_RGBA8, enc);
        double got[3];
        rgbe_value(enc, got);
        /* 8 bits of mantissa for the largest channel: within half a step of 2^k / 255, k its power of two */
        double step = ldexp(1, (int)lround(enc[3] * 255) - 128) / 255;
        T_ASSERTF(enc[0] >= 0.5f - 1e-6f && enc[0] <= 1, "%g: the largest channel's mantissa %.4f is outside [0.5, 1]", v, enc[0]);
        for (int ch = 0; ch < 3; ch++) {
            double d = fabs(got[ch] - c[ch]);
            T_ASSERTF(d <= 0.5001 * step, "%g channel %d: stored %g (%.2f steps off)", v, ch, got[ch], d / step);
            worst = fmax(worst, d / c[0]);
        }
        /* read back as a level and written again (RGBE_IN): the same bytes */
        GLuint lvl = tex_of(GL_RGBA8, 1, 1, enc);
        down_1x1("#define RGBE_IN 1\n#define RGBE_OUT 1\n", lvl, GL_RGBA8, again);
        for (int ch = 0; ch < 4; ch++)
            T_ASSERTF(lround(again[ch] * 255) == lround(enc[ch] * 255), "%g: channel %d %ld after a second pass, %ld before", v,
                      ch, lround(again[ch] * 255), lround(enc[ch] * 255));
        gl.DeleteTextures(1, &hdr);
        gl.DeleteTextures(1, &lvl);
    }
    /* zero, and what a half float cannot hold (clamped; NaN becomes 0) */
    const float odd[][3] = {{0, 0, 0}, {1e30f, 1, 0}, {NAN, 2, 0}};
    const double want[][3] = {{0, 0, 0}, {65504, 1, 0}, {0, 2, 0}};
    for (int k = 0; k < 3; k++) {
        float src[16];
        for (int i = 0; i < 4; i++)
            src[4 * i] = odd[k][0], src[4 * i + 1] = odd[k][1], src[4 * i + 2] = odd[k][2], src[4 * i + 3] = 1;
        GLuint hdr = tex_of(GL_RGBA32F, 2, 2, src);
        float enc[4];
        down_1x1("#define RGBE_OUT 1\n", hdr, GL_RGBA8, enc);
        double got[3];
        rgbe_value(enc, got);
        for (int ch = 0; ch < 3; ch++)
            T_ASSERTF(fabs(got[ch] - want[k][ch]) <= 0.004 * fmax(want[k][0], want[k][1]) + 1e-30, "case %d channel %d: %g, want %g",
                      k, ch, got[ch], want[k][ch]);
        gl.DeleteTextures(1, &hdr);
    }
    fprintf(stderr, "    %d colours, worst error %.3f%% of the largest channel\n", n, 100 * worst);
    plat_destroy(p);
}

T_MAIN({"curve_shape", t_curve_shape}, {"curve_known_points", t_curve_known_points},
       {"lut_entries_are_the_curve", t_lut_entries_are_the_curve},
       {"default_lut_error_under_a_tenth_step", t_default_lut_error_under_a_tenth_step},
       {"small_tables_fail_the_goal", t_small_tables_fail_the_goal},
       {"shader_matches_curve_gamma_22", t_shader_matches_curve_gamma_22},
       {"shader_matches_curve_gamma_1", t_shader_matches_curve_gamma_1},
       {"shader_saturation_0_is_grey", t_shader_saturation_0_is_grey},
       {"shader_known_points", t_shader_known_points},
       {"shader_matches_curve_gamma_10", t_shader_matches_curve_gamma_10},
       {"every_gamma_meets_the_goal", t_every_gamma_meets_the_goal}, {"bloom_levels_rgbe", t_bloom_levels_rgbe})
