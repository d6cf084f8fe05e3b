/* runtime/render/r_tone and shaders/tonemap.frag: the YCbCr tone curve
 * (docs/renderer.md, "Tone map, bloom, flare"), its lookup table, and the shader that uses it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
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

/* The shader against the double-precision curve: a ramp of grey HDR
 * values (and colours) through tonemap.frag into a float target. */
enum { N = 512 };

static void shader_vs_curve(double gamma, float saturation)
{
    plat *p = t_context("egl");
    rs_err e = {0};
    GLuint prog = r_program(&(r_program_desc){.vs = "cap_fullscreen.vert", .fs = "tonemap.frag"}, &e);
    T_ASSERTF(prog, "%s", e.msg);
    /* input: row 0 grey ramp x in [0, 6]; row 1 colours of the same luminance */
    static float in[2 * N * 4];
    for (int i = 0; i < N; i++) {
        float x = 6.0f * i / (N - 1) * (6.0f * i / (N - 1)) / 6.0f; /* denser near 0 */
        float *g = in + 4 * i, *c = in + 4 * (N + i);
        g[0] = g[1] = g[2] = x, g[3] = 1;
        c[0] = 1.5f * x, c[1] = 0.9f * x, c[2] = 0.4f * x, c[3] = 1;
    }
    GLuint tex[3], fbo;
    gl.GenTextures(3, tex);
    gl.BindTexture(GL_TEXTURE_2D, tex[0]);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, N, 2, 0, GL_RGBA, GL_FLOAT, in);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    float lut[R_TONE_LUT_DEFAULT];
    r_tone_lut(lut, R_TONE_LUT_DEFAULT, gamma);
    gl.BindTexture(GL_TEXTURE_1D, tex[1]);
    gl.TexImage1D(GL_TEXTURE_1D, 0, GL_R32F, R_TONE_LUT_DEFAULT, 0, GL_RED, GL_FLOAT, lut);
    gl.TexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.BindTexture(GL_TEXTURE_2D, tex[2]);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, N, 2, 0, GL_RGBA, GL_FLOAT, NULL);
    gl.GenFramebuffers(1, &fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex[2], 0);
    T_EQ(gl.CheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    gl.Viewport(0, 0, N, 2);
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
    gl.Uniform1f(gl.GetUniformLocation(prog, "u_exposure"), 1.0f);
    gl.Uniform1f(gl.GetUniformLocation(prog, "u_saturation"), saturation);
    gl.Uniform1i(gl.GetUniformLocation(prog, "u_write_mask"), 0);
    GLuint vao;
    gl.GenVertexArrays(1, &vao);
    gl.BindVertexArray(vao);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    static float out[2 * N * 4];
    gl.ReadPixels(0, 0, N, 2, GL_RGBA, GL_FLOAT, out);
    T_EQ(gl.GetError(), GL_NO_ERROR);
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
    gl.DeleteVertexArrays(1, &vao);
    gl.DeleteFramebuffers(1, &fbo);
    gl.DeleteTextures(3, tex);
    gl.DeleteProgram(prog);
    plat_destroy(p);
}

static void t_shader_matches_curve_gamma_22(void) { shader_vs_curve(2.2, 1.0f); }
static void t_shader_matches_curve_gamma_1(void) { shader_vs_curve(1.0, 1.0f); }
static void t_shader_saturation_0_is_grey(void) { shader_vs_curve(2.2, 0.0f); }
static void t_shader_matches_curve_gamma_10(void) { shader_vs_curve(10.0, 1.0f); }

T_MAIN({"curve_shape", t_curve_shape}, {"lut_entries_are_the_curve", t_lut_entries_are_the_curve},
       {"default_lut_error_under_a_tenth_step", t_default_lut_error_under_a_tenth_step},
       {"small_tables_fail_the_goal", t_small_tables_fail_the_goal},
       {"shader_matches_curve_gamma_22", t_shader_matches_curve_gamma_22},
       {"shader_matches_curve_gamma_1", t_shader_matches_curve_gamma_1},
       {"shader_saturation_0_is_grey", t_shader_saturation_0_is_grey},
       {"shader_matches_curve_gamma_10", t_shader_matches_curve_gamma_10},
       {"every_gamma_meets_the_goal", t_every_gamma_meets_the_goal})
