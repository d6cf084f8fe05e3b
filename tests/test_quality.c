/* The renderer's quality knobs (r_quality in r_game.h) on llvmpipe:
 *   - zero and the knobs spelled out at their defaults draw the same bytes;
 *   - FXAA brings a 1:1 render closer to a 4x supersampled reference (box
 *     downscaled) and leaves every pixel of a flat area alone;
 *   - the light-space maps and the water grid are built at the asked size,
 *     and sizes out of range are refused with a message.
 * T_AA_SIZE=WxH measures the FXAA gain at that size (the docs' numbers are
 * at 640x360: T_AA_SIZE=640x360 build/tests/test_quality fxaa). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/fx/fx_fog.h"
#include "../runtime/fx/fx_snow_tex.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_quality.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/replay/rp.h"
#include "t.h"
#include "t_render.h"

/* One w x h frame of demo at tick (history ticks drawn first), RGBA top-down. */
static uint8_t *frame_of(const char *demo, uint64_t tick, uint64_t history, const r_game_opts *o, int w, int h)
{
    uint8_t *px = malloc((size_t)w * h * 4);
    T_ASSERT(px);
    t_picture(demo, tick, history, o, w, h, px);
    return px;
}

/* b, k times the size of a w x h picture, box averaged down to w x h
 * (gamma-encoded bytes, as a viewer's downscale does), RGBA. */
static uint8_t *box_down(const uint8_t *b, int w, int h, int k)
{
    uint8_t *o = malloc((size_t)w * h * 4);
    T_ASSERT(o);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 4; c++) {
                int s = 0;
                for (int j = 0; j < k; j++)
                    for (int i = 0; i < k; i++)
                        s += b[(((size_t)(y * k + j)) * (size_t)(w * k) + (size_t)(x * k + i)) * 4 + (size_t)c];
                o[((size_t)y * w + x) * 4 + (size_t)c] = (uint8_t)((s + k * k / 2) / (k * k));
            }
    return o;
}

/* PSNR over RGB of a against ref, over the pixels where mask is set (NULL: all). */
static double psnr_of(const uint8_t *a, const uint8_t *ref, const bool *mask, int n)
{
    double se = 0;
    int m = 0;
    for (int i = 0; i < n; i++) {
        if (mask && !mask[i])
            continue;
        m++;
        for (int c = 0; c < 3; c++) {
            double d = (double)a[4 * i + c] - ref[4 * i + c];
            se += d * d;
        }
    }
    return se > 0 ? 10 * log10(255.0 * 255.0 / (se / (m * 3.0))) : 99;
}

static double luma(const uint8_t *p)
{
    return (0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2]) / 255.0;
}

/* ---- aa off is today's path ---- */

static void t_defaults_spelled_out_are_zero(void)
{
    plat *p = t_context("egl");
    enum { W = 320, H = 180 };
    uint8_t *a = frame_of("dojo", 1200, 0, NULL, W, H);
    r_game_opts o = {.q = {.shadow_size = 1024, .sil_size = 512, .aa = R_AA_OFF, .water_grid = 64, .scene_pct = 100}};
    uint8_t *b = frame_of("dojo", 1200, 0, &o, W, H);
    T_ASSERTF(!memcmp(a, b, (size_t)W * H * 4), "dojo: the knobs at their defaults drew other bytes than zero");
    free(a), free(b);
    a = frame_of("shallows", 380, 10, NULL, W, H);
    b = frame_of("shallows", 380, 10, &o, W, H);
    T_ASSERTF(!memcmp(a, b, (size_t)W * H * 4), "shallows: water_grid 64 drew other bytes than zero");
    free(a), free(b);
    plat_destroy(p);
}

/* ---- FXAA ---- */

/* The gain against a 4x reference, and FXAA's changes only near edges. */
static void fxaa_on(const char *demo, uint64_t tick, int w, int h, double gain[2])
{
    r_game_opts off = {.no_hud = true}, on = {.no_hud = true, .q = {.aa = R_AA_FXAA}};
    uint8_t *a = frame_of(demo, tick, 0, &off, w, h);
    uint8_t *b = frame_of(demo, tick, 0, &on, w, h);
    uint8_t *ref = frame_of(demo, tick, 0, &off, 4 * w, 4 * h);
    uint8_t *ref_small = box_down(ref, w, h, 4);
    bool *edge = calloc((size_t)w * h, 1);
    T_ASSERT(edge);
    const char *dump = getenv("T_DUMP"); /* the three pictures, to look at */
    if (dump) {
        char path[1024];
        const uint8_t *img[3] = {a, b, ref};
        const char *tag[3] = {"off", "fxaa", "ref4x"};
        for (int k = 0; k < 3; k++) {
            int m = k == 2 ? 4 : 1;
            snprintf(path, sizeof path, "%s/aa_%s_%s.ppm", dump, demo, tag[k]);
            FILE *fp = fopen(path, "wb");
            if (!fp)
                continue;
            fprintf(fp, "P6\n%d %d\n255\n", w * m, h * m);
            for (size_t i = 0; i < (size_t)w * h * m * m; i++)
                fwrite(img[k] + 4 * i, 1, 3, fp);
            fclose(fp);
        }
    }
    /* flat: the 3x3 neighbourhood's luma spans less than FXAA's floor
     * (fxaa.frag EDGE_MIN 0.0625); every such pixel must be untouched */
    int flat = 0, flat_changed = 0, changed = 0;
    for (int y = 1; y < h - 1; y++)
        for (int x = 1; x < w - 1; x++) {
            double lo = 1, hi = 0;
            for (int j = -1; j <= 1; j++)
                for (int i = -1; i <= 1; i++) {
                    double l = luma(a + (((size_t)(y + j)) * w + (size_t)(x + i)) * 4);
                    lo = fmin(lo, l), hi = fmax(hi, l);
                }
            size_t o = ((size_t)y * w + x) * 4;
            bool diff = memcmp(a + o, b + o, 4) != 0;
            changed += diff;
            if (hi - lo < 0.06) {
                flat++;
                flat_changed += diff;
            }
            edge[(size_t)y * w + x] = hi - lo >= 0.06; /* where aliasing can be */
        }
    /* over the whole frame, and over the edges of the 1:1 picture alone:
     * where the look itself depends on the render size (dojo's sun glow),
     * the whole frame's error hides what anti-aliasing does */
    double p_off = psnr_of(a, ref_small, NULL, w * h), p_on = psnr_of(b, ref_small, NULL, w * h);
    double e_off = psnr_of(a, ref_small, edge, w * h), e_on = psnr_of(b, ref_small, edge, w * h);
    fprintf(stderr,
            "    %s@%llu %dx%d: PSNR vs 4x supersampled, frame %.2f dB without AA, %.2f with FXAA (%+.2f); "
            "edges %.2f, %.2f (%+.2f); %d pixels changed, %d flat, %d of them changed\n",
            demo, (unsigned long long)tick, w, h, p_off, p_on, p_on - p_off, e_off, e_on, e_on - e_off, changed, flat,
            flat_changed);
    T_ASSERTF(flat_changed == 0, "%s: FXAA changed %d pixels of flat areas", demo, flat_changed);
    T_ASSERTF(flat > w * h / 4, "%s: too few flat pixels (%d) for the test to mean anything", demo, flat);
    gain[0] = p_on - p_off, gain[1] = e_on - e_off;
    free(a), free(b), free(ref), free(ref_small), free(edge);
}

static void t_fxaa(void)
{
    plat *p = t_context("egl");
    int w = 320, h = 180;
    const char *s = getenv("T_AA_SIZE");
    if (s && sscanf(s, "%dx%d", &w, &h) != 2)
        T_ASSERTF(0, "T_AA_SIZE=%s: want WxH", s);
    double dojo[2], temple[2];
    fxaa_on("dojo", 1200, w, h, dojo);
    fxaa_on("temple", 900, w, h, temple);
    /* measured at 320x180 (docs/renderer.md, Quality knobs): temple +2.07
     * dB on the frame, +2.17 on edges; dojo +0.01 and +0.05, its error
     * being the sun's glow, which grows with the render size */
    T_ASSERTF(temple[0] >= 1.0 && temple[1] >= 1.0, "FXAA gains on temple %.2f dB (frame), %.2f (edges): want >= 1",
              temple[0], temple[1]);
    T_ASSERTF(dojo[0] >= 0 && dojo[1] >= 0, "FXAA loses on dojo: %.2f dB (frame), %.2f (edges)", dojo[0], dojo[1]);
    plat_destroy(p);
}

/* ---- the procedural patterns (scene.frag) ---- */

/* A 1:1 frame (no FXAA, no HUD) against the same frame drawn at 4x4 and
 * box downscaled, in dB over RGB. */
static double one_to_four(const char *demo, uint64_t tick, int w, int h)
{
    r_game_opts o = {.no_hud = true};
    uint8_t *a = frame_of(demo, tick, 0, &o, w, h);
    uint8_t *ref = frame_of(demo, tick, 0, &o, 4 * w, 4 * h);
    uint8_t *ref_small = box_down(ref, w, h, 4);
    double db = psnr_of(a, ref_small, NULL, w * h);
    fprintf(stderr, "    %s@%llu %dx%d: 1:1 against 4x4 supersampled %.2f dB\n", demo, (unsigned long long)tick, w, h, db);
    free(a), free(ref), free(ref_small);
    return db;
}

/* The planks' seams (every stage's ring), the paving's joints and the
 * buildings' windows (plaza) are box-filtered over each pixel's footprint,
 * so at 1:1 they are what a supersampled picture shows, not a seam or a
 * window edge that a pixel centre hits or misses.  Measured at 320x180,
 * before the filtering and after: plaza 33.75 -> 36.88 dB, temple 35.26 ->
 * 37.23 (quarry 35.19 -> 36.19, harbor 40.87 -> 42.46). */
static void t_patterns_filtered(void)
{
    plat *p = t_context("egl");
    double plaza = one_to_four("plaza", 1500, 320, 180), temple = one_to_four("temple", 900, 320, 180);
    T_ASSERTF(plaza >= 36.0, "plaza at 1:1 is %.2f dB from its 4x4 picture: want >= 36 (the windows and joints filtered)",
              plaza);
    T_ASSERTF(temple >= 36.5, "temple at 1:1 is %.2f dB from its 4x4 picture: want >= 36.5 (the seams filtered)", temple);
    plat_destroy(p);
}

/* The early out (r_aa.c): the marked pass draws one full pass's bytes,
 * with a minority of the pixels marked for the filter, and FXAA does
 * change the picture (so the comparison can fail). */
static void t_fxaa_early_out_same_bytes(void)
{
    plat *p = t_context("egl");
    const struct {
        const char *demo;
        uint64_t tick;
    } cases[] = {{"temple", 900}, {"dojo", 1200}, {"plaza", 1500}};
    int w = 320, h = 180;
    size_t n = (size_t)w * h * 4;
    uint8_t *fast = malloc(n), *plain = malloc(n), *off = malloc(n), *st = malloc((size_t)w * h);
    T_ASSERT(fast && plain && off && st);
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        g_state prev, cur;
        t_state_at(cases[c].demo, cases[c].tick, &prev, &cur);
        t_fb f;
        t_fb_make(&f, w, h);
        r_game *r = t_game_opts(&(r_game_opts){.q = {.aa = R_AA_FXAA}});
        t_draw_read(r, &f, &prev, &cur, w, h, fast, true);
        /* the marks: the stencil the pass left */
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, f.fbo);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
        gl.ReadPixels(0, 0, w, h, GL_STENCIL_INDEX, GL_UNSIGNED_BYTE, st);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
        int marked = 0;
        for (int i = 0; i < w * h; i++)
            marked += st[i] == 1;
        r_game_destroy(r);
        r = t_game_opts(&(r_game_opts){.q = {.aa = R_AA_FXAA}, .aa_plain = true});
        t_draw_read(r, &f, &prev, &cur, w, h, plain, true);
        r_game_destroy(r);
        r = t_game_opts(NULL);
        t_draw_read(r, &f, &prev, &cur, w, h, off, true);
        r_game_destroy(r);
        t_fb_free(&f);
        size_t diff = 0, changed = 0;
        for (size_t i = 0; i < n; i++)
            diff += fast[i] != plain[i], changed += plain[i] != off[i];
        T_ASSERTF(diff == 0, "%s@%llu: %zu bytes differ between the marked and the plain pass", cases[c].demo,
                  (unsigned long long)cases[c].tick, diff);
        T_ASSERTF(changed > 0, "%s: FXAA changed nothing", cases[c].demo);
        T_ASSERTF(marked > 0 && marked < w * h / 2, "%s: %d of %d pixels marked for the filter", cases[c].demo, marked,
                  w * h);
    }
    free(fast), free(plain), free(off), free(st);
    plat_destroy(p);
}

/* With the shadow map and the silhouette the same size (the standard
 * preset's 512), shadow_map draws both at once: the depth map, every
 * silhouette level and the frame must be those of the two passes apart. */
static void t_shadow_and_silhouette_in_one_draw(void)
{
    plat *p = t_context("egl");
    enum { W = 320, H = 180, N = 512, LEVELS = 5 }; /* SIL_LEVELS */
    static const struct {
        const char *demo;
        uint64_t tick;
    } cases[] = {{"temple", 900}, {"dojo", 1500}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        g_state prev, cur;
        t_state_at(cases[c].demo, cases[c].tick, &prev, &cur);
        t_fb f;
        t_fb_make(&f, W, H);
        uint8_t *img[2];
        float *map[2], *lv[2][LEVELS];
        for (int apart = 0; apart < 2; apart++) {
            r_game *r = t_game_opts(&(r_game_opts){.q = {.shadow_size = N, .sil_size = N}, .light_apart = apart == 1});
            img[apart] = malloc((size_t)W * H * 4);
            T_ASSERT(img[apart]);
            t_draw_read(r, &f, &prev, &cur, W, H, img[apart], true);
            map[apart] = t_read(r, "shadow", 1, N, N);
            for (int k = 0; k < LEVELS; k++) {
                char name[16] = "silhouette";
                if (k)
                    snprintf(name, sizeof name, "silhouette%d", k);
                lv[apart][k] = t_read(r, name, 4, N >> k, N >> k);
            }
            T_ASSERT(t_pass_ran(r, "shadow_map") && t_pass_ran(r, "silhouette"));
            r_game_destroy(r);
        }
        int covered = 0;
        for (int i = 0; i < N * N; i++)
            covered += lv[0][0][4 * i] > 0.5f;
        fprintf(stderr, "    %s@%llu: silhouette %d texels covered\n", cases[c].demo, (unsigned long long)cases[c].tick,
                covered);
        T_ASSERTF(covered > N * N / 1000, "%s: the one draw's silhouette is empty (%d texels)", cases[c].demo, covered);
        T_ASSERTF(!memcmp(map[0], map[1], sizeof(float) * N * N), "%s: the depth maps differ", cases[c].demo);
        for (int k = 0; k < LEVELS; k++)
            T_ASSERTF(!memcmp(lv[0][k], lv[1][k], sizeof(float) * 4 * (N >> k) * (N >> k)), "%s: silhouette level %d differs",
                      cases[c].demo, k);
        T_ASSERTF(!memcmp(img[0], img[1], (size_t)W * H * 4), "%s: the frames differ", cases[c].demo);
        for (int a = 0; a < 2; a++) {
            free(img[a]), free(map[a]);
            for (int k = 0; k < LEVELS; k++)
                free(lv[a][k]);
        }
        t_fb_free(&f);
    }
    plat_destroy(p);
}

/* The pass is in the graph: runs with aa on, skipped (and no target) off. */
static void t_fxaa_pass_in_graph(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    t_state_at("temple", 900, &prev, &cur);
    t_fb f;
    t_fb_make(&f, 64, 36);
    r_game *r = t_game_opts(NULL);
    t_draw(r, &f, &prev, &cur, 64, 36);
    T_ASSERT(!t_pass_ran(r, "fxaa"));
    r_game_destroy(r);
    r = t_game_opts(&(r_game_opts){.q = {.aa = R_AA_FXAA}});
    t_draw(r, &f, &prev, &cur, 64, 36);
    T_ASSERT(t_pass_ran(r, "fxaa"));
    T_ASSERT(t_pass_ran(r, "hud"));
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* T_AA_COST=1: the pass table of 60 frames of temple at 640x360 with
 * FXAA on (the docs' cost; skipped otherwise). */
static void t_fxaa_cost(void)
{
    if (!getenv("T_AA_COST"))
        T_SKIP_ENV("T_AA_COST not set");
    plat *p = t_context("egl");
    g_state prev, cur;
    t_state_at("temple", 900, &prev, &cur);
    t_fb f;
    t_fb_make(&f, 640, 360);
    r_game *r = t_game_opts(&(r_game_opts){.q = {.aa = R_AA_FXAA}});
    r_game_passes(r, false, NULL);
    for (int i = 0; i < 60; i++)
        t_draw(r, &f, &prev, &cur, 640, 360);
    r_game_report(r, stderr);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* ---- sizes ---- */

static void t_light_maps_at_the_asked_size(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    t_state_at("temple", 900, &prev, &cur);
    t_fb f;
    t_fb_make(&f, 160, 90);
    static const int sizes[][2] = {{0, 0}, {256, 128}, {2048, 1024}};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        r_game *r = t_game_opts(&(r_game_opts){.q = {.shadow_size = sizes[i][0], .sil_size = sizes[i][1]}});
        t_draw(r, &f, &prev, &cur, 160, 90);
        int sh = sizes[i][0] ? sizes[i][0] : 1024, sl = sizes[i][1] ? sizes[i][1] : 512;
        float *d = t_read(r, "shadow", 1, sh, sh);
        float *s = t_read(r, "silhouette", 1 * 4, sl, sl);
        float *s4 = t_read(r, "silhouette4", 4, sl >> 4, sl >> 4);
        /* drawn into at that size: the fighters cover part of each map */
        int near = 0, cover = 0, cover4 = 0;
        for (int k = 0; k < sh * sh; k++)
            near += d[k] < 1.0f;
        for (int k = 0; k < sl * sl; k++)
            cover += s[4 * k] > 0.5f;
        for (int k = 0; k < (sl >> 4) * (sl >> 4); k++)
            cover4 += s4[4 * k] > 0.01f;
        fprintf(stderr, "    shadow %d: %.2f%% of texels hit; silhouette %d: %.2f%% covered, level 4 %d texels\n", sh,
                100.0 * near / (sh * sh), sl, 100.0 * cover / (sl * sl), cover4);
        T_ASSERTF(near > sh * sh / 1000 && near < sh * sh / 2, "shadow %d: %d texels hit", sh, near);
        T_ASSERTF(cover > sl * sl / 1000 && cover < sl * sl / 2, "silhouette %d: %d texels covered", sl, cover);
        T_ASSERTF(cover4 > 0, "silhouette %d: level 4 empty", sl);
        free(d), free(s), free(s4);
        r_game_destroy(r);
    }
    t_fb_free(&f);
    plat_destroy(p);
}

/* A knob against its default on one frame of demo at 320x180: the knob
 * must change the picture (else it is ignored), by less than min_db. */
static void knob_moves_a_little(const char *demo, uint64_t tick, r_quality q, const char *what, double min_db)
{
    enum { W = 320, H = 180 };
    uint8_t *a = frame_of(demo, tick, 10, NULL, W, H);
    uint8_t *b = frame_of(demo, tick, 10, &(r_game_opts){.q = q}, W, H);
    double psnr = psnr_of(a, b, NULL, W * H);
    fprintf(stderr, "    %s, %s against the default: PSNR %.1f dB\n", demo, what, psnr);
    T_ASSERTF(psnr < 99, "%s drew the same bytes as the default: the knob is ignored", what);
    T_ASSERTF(psnr > min_db, "%s differs too much from the default: %.1f dB, want > %.0f", what, psnr, min_db);
    free(a), free(b);
}

/* snow_light: the snow's light map at the asked side (0: 256), and a
 * smaller map moves snowfield's picture a little, not a lot. */
static void t_snow_light(void)
{
    plat *p = t_context("egl");
    knob_moves_a_little("snowfield", 900, (r_quality){.snow_light = 128}, "snow light 128", 40);
    for (int k = 0; k < 2; k++) {
        r_game *r = t_game_opts(&(r_game_opts){.q = {.snow_light = k ? 64 : 0}});
        t_fb f;
        t_fb_make(&f, 64, 36);
        g_state prev, cur;
        t_state_at("snowfield", 900, &prev, &cur);
        t_draw(r, &f, &prev, &cur, 64, 36);
        T_EQ(fx_snow_light_size(r), k ? 64 : 256);
        t_fb_free(&f);
        r_game_destroy(r);
    }
    plat_destroy(p);
}

/* scene_pct: the scene and its passes drawn at that share of the output
 * (the HDR image 240x135 for 320x180 at 75%), the tone map scaling it up:
 * the picture moves a little, not a lot, and the HUD stays at the output's
 * size, where it was (the pixels it touches are the same set). */
static void t_scene_pct(void)
{
    plat *p = t_context("egl");
    enum { W = 320, H = 180 };
    knob_moves_a_little("temple", 900, (r_quality){.scene_pct = 75}, "scene 75%", 30);
    uint8_t *px[2][2];
    for (int k = 0; k < 2; k++)
        for (int hud = 0; hud < 2; hud++)
            px[k][hud] = frame_of("dojo", 1200, 0, &(r_game_opts){.no_hud = !hud, .q = {.scene_pct = k ? 75 : 0}}, W, H);
    long both = 0, either = 0;
    for (int i = 0; i < W * H; i++) {
        bool a = memcmp(px[0][0] + 4 * i, px[0][1] + 4 * i, 3) != 0, b = memcmp(px[1][0] + 4 * i, px[1][1] + 4 * i, 3) != 0;
        both += a && b, either += a || b;
    }
    fprintf(stderr, "    the HUD's pixels at 100%% and at 75%%: %ld in both of %ld in either\n", both, either);
    T_ASSERTF(either > 500 && both * 10 > either * 9, "the HUD touched other pixels at 75%%: %ld in both of %ld", both, either);
    for (int k = 0; k < 2; k++)
        free(px[k][0]), free(px[k][1]);
    /* stage: r_quality.stage_scene, the stage file's standard_scene_pct
     * (dojo 75, temple 100) unless scene_pct says otherwise */
    static const struct {
        int pct, w, h, want_w, want_h;
        bool stage;
        const char *demo;
    } c[] = {{0, 320, 180, 320, 180, false, "dojo"},  {75, 320, 180, 240, 135, false, "dojo"}, {50, 64, 36, 32, 18, false, "dojo"},
             {60, 101, 57, 61, 34, false, "dojo"},   {0, 320, 180, 240, 135, true, "dojo"},   {0, 320, 180, 320, 180, true, "temple"},
             {60, 320, 180, 192, 108, true, "dojo"}};
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
        r_game *r = t_game_opts(&(r_game_opts){.q = {.scene_pct = c[i].pct, .stage_scene = c[i].stage}});
        t_fb f;
        t_fb_make(&f, c[i].w, c[i].h);
        g_state prev, cur;
        t_state_at(c[i].demo, 900, &prev, &cur);
        t_draw(r, &f, &prev, &cur, c[i].w, c[i].h);
        float *hdr = malloc((size_t)c[i].w * c[i].h * 4 * sizeof *hdr);
        int hw = 0, hh = 0;
        T_ASSERT(hdr && r_game_read_buffer(r, "hdr", hdr, &hw, &hh));
        T_ASSERTF(hw == c[i].want_w && hh == c[i].want_h, "%s, scene_pct %d%s at %dx%d: the scene is %dx%d, want %dx%d",
                  c[i].demo, c[i].pct, c[i].stage ? " and the stage's" : "", c[i].w, c[i].h, hw, hh, c[i].want_w, c[i].want_h);
        free(hdr);
        t_fb_free(&f);
        r_game_destroy(r);
    }
    plat_destroy(p);
}

static void t_water_grid(void)
{
    plat *p = t_context("egl");
    knob_moves_a_little("shallows", 380, (r_quality){.water_grid = 16}, "water grid 16", 25);
    plat_destroy(p);
}

/* fog_size: the mist's density map at the asked edge (0: the look's 128),
 * and a smaller map moves mistvale's picture a little, not a lot. */
static void t_fog_size(void)
{
    plat *p = t_context("egl");
    enum { W = 320, H = 180 };
    const int want[] = {0, 64, 256};
    uint8_t *px[3];
    for (int i = 0; i < 3; i++) {
        r_game_opts o = {.q = {.fog_size = want[i]}};
        px[i] = frame_of("mistvale", 700, 10, &o, W, H);
        /* the map's size: a game made with the same knob, one frame drawn */
        g_state prev, cur;
        t_state_at("mistvale", 700, &prev, &cur);
        r_game *r = t_game_opts(&o);
        t_fb f;
        t_fb_make(&f, 64, 36);
        t_draw(r, &f, &prev, &cur, 64, 36);
        int size = 0;
        T_ASSERT(fx_fog_read_map(r, NULL, &size, NULL));
        T_ASSERTF(size == (want[i] ? want[i] : 128), "fog_size %d: a %d map", want[i], size);
        t_fb_free(&f);
        r_game_destroy(r);
    }
    for (int i = 1; i < 3; i++) {
        double se = 0;
        for (size_t k = 0; k < (size_t)W * H * 4; k += 4)
            for (int c = 0; c < 3; c++)
                se += (double)(px[0][k + c] - px[i][k + c]) * (px[0][k + c] - px[i][k + c]);
        double psnr = se > 0 ? 10 * log10(255.0 * 255.0 / (se / (W * H * 3))) : 99;
        fprintf(stderr, "    mistvale, fog map %d vs 128: PSNR %.1f dB\n", want[i], psnr);
        T_ASSERTF(se > 0, "fog_size %d drew the same bytes as 128: the knob is ignored", want[i]);
        T_ASSERTF(psnr > 30, "fog_size %d differs too much from 128: %.1f dB", want[i], psnr);
    }
    for (int i = 0; i < 3; i++)
        free(px[i]);
    plat_destroy(p);
}

/* ---- the silhouette mip chain ---- */

/* One texel of src (n x n, RGBA floats, red used), 0 outside (clamp to border). */
static float sil_at(const float *src, int n, int x, int y)
{
    return x < 0 || y < 0 || x >= n || y >= n ? 0.0f : src[4 * ((size_t)y * n + x)];
}

/* The chain as downsample.frag and blur.frag define it, in floats: a 4x4
 * box to half size, then the 9-tap Gaussian (sigma 2) along x, then y. */
static float *sil_level_cpu(const float *src, int n)
{
    int h = n / 2;
    float *d = calloc((size_t)h * h * 4, sizeof *d), *t = calloc((size_t)h * h * 4, sizeof *t);
    T_ASSERT(d && t);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < h; x++) {
            float s = 0;
            for (int j = -1; j <= 2; j++)
                for (int i = -1; i <= 2; i++)
                    s += sil_at(src, n, 2 * x + i, 2 * y + j);
            d[4 * ((size_t)y * h + x)] = s / 16;
        }
    /* blur.frag's 5 bilinear taps as 9 texel weights */
    const float w0 = 0.2042f, w1 = 0.3040f, w2 = 0.0931f, f1 = 0.3846f, f2 = 0.2308f;
    const float w[5] = {w0, w1 * (1 - f1), w1 * f1, w2 * (1 - f2), w2 * f2};
    for (int pass = 0; pass < 2; pass++) {
        const float *a = pass ? t : d;
        float *b = pass ? d : t;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < h; x++) {
                float s = w[0] * sil_at(a, h, x, y);
                for (int k = 1; k < 5; k++)
                    s += w[k] * (pass ? sil_at(a, h, x, y - k) + sil_at(a, h, x, y + k)
                                      : sil_at(a, h, x - k, y) + sil_at(a, h, x + k, y));
                b[4 * ((size_t)y * h + x)] = s;
            }
    }
    free(t);
    return d;
}

/* silhouette_mips draws each level only round the fighters (a scissor):
 * every level must still be the whole chain's, computed here from the
 * level the GPU built before it (llvmpipe: 8-bit texels and bilinear
 * weights, so a small tolerance). */
static void t_silhouette_mips_whole(void)
{
    plat *p = t_context("egl");
    static const struct { const char *demo; uint64_t tick; int sil; } cases[] = {
        {"dojo", 1200, 0}, {"temple", 900, 256}, {"harbor", 600, 1024}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        g_state prev, cur;
        t_fb f;
        t_fb_make(&f, 160, 90);
        r_game *r = t_game_opts(&(r_game_opts){.q = {.sil_size = cases[c].sil}});
        /* a frame of another pose first: texels it left must not survive */
        t_state_at(cases[c].demo, cases[c].tick - 500, &prev, &cur);
        t_draw(r, &f, &prev, &cur, 160, 90);
        t_state_at(cases[c].demo, cases[c].tick, &prev, &cur);
        t_draw(r, &f, &prev, &cur, 160, 90);
        int n = cases[c].sil ? cases[c].sil : 512;
        float *lv = t_read(r, "silhouette", 4, n, n);
        for (int k = 1; k < 5; k++) {
            char name[16];
            snprintf(name, sizeof name, "silhouette%d", k);
            float *gpu = t_read(r, name, 4, n >> k, n >> k), *cpu = sil_level_cpu(lv, n >> (k - 1));
            float worst = 0, mass = 0;
            int at = 0;
            for (int i = 0; i < (n >> k) * (n >> k); i++) {
                float e = fabsf(gpu[4 * i] - cpu[4 * i]);
                mass += cpu[4 * i];
                if (e > worst)
                    worst = e, at = i;
            }
            fprintf(stderr, "    %s sil %d level %d: max |gpu - cpu| %.4f at (%d, %d), mass %.1f\n", cases[c].demo, n, k,
                    worst, at % (n >> k), at / (n >> k), mass);
            T_ASSERTF(mass > 1, "%s level %d: empty", cases[c].demo, k);
            T_ASSERTF(worst < 0.02f, "%s sil %d level %d: texel (%d, %d) is %.3f, the whole chain gives %.3f", cases[c].demo,
                      n, k, at % (n >> k), at / (n >> k), gpu[4 * at], cpu[4 * at]);
            free(cpu), free(lv);
            lv = gpu;
        }
        free(lv);
        r_game_destroy(r);
        t_fb_free(&f);
    }
    plat_destroy(p);
}

static void refused(r_quality q, const char *says)
{
    rs_err e = {0};
    r_game *r = r_game_create_opts(&(r_game_opts){.cache_dir = "", .quiet = true, .q = q}, &e);
    T_ASSERTF(!r, "accepted, want refused with '%s'", says);
    T_CONTAINS(e.msg, says);
}

static void t_out_of_range_refused(void)
{
    plat *p = t_context("egl");
    refused((r_quality){.shadow_size = 100}, "shadow_size 100 out of range");
    refused((r_quality){.shadow_size = 8192}, "128..4096");
    refused((r_quality){.sil_size = 32}, "sil_size 32 out of range");
    refused((r_quality){.sil_size = 4096}, "64..2048");
    refused((r_quality){.water_grid = 8}, "water_grid 8 out of range");
    refused((r_quality){.water_grid = 512}, "16..256");
    refused((r_quality){.shadow_size = -1}, "shadow_size -1");
    refused((r_quality){.aa = (r_aa)7}, "aa 7 unknown");
    refused((r_quality){.fog_size = 32}, "fog_size 32 out of range");
    refused((r_quality){.fog_size = 2048}, "64..1024");
    refused((r_quality){.bloom_levels = 3}, "bloom_levels 3 out of range");
    refused((r_quality){.snow_light = 32}, "snow_light 32 out of range");
    refused((r_quality){.snow_light = 512}, "64..256");
    refused((r_quality){.scene_pct = 49}, "scene_pct 49 out of range");
    refused((r_quality){.scene_pct = 101}, "50..100");
    /* the ends of the ranges are taken */
    r_game_destroy(t_game_opts(&(r_game_opts){.q = {.shadow_size = 128, .sil_size = 64, .water_grid = 256,
                                                     .fog_size = 1024, .bloom_levels = 1, .scene_pct = 50}}));
    plat_destroy(p);
}

/* The presets are pinned to the table users read (docs/accuracy.md, "The
 * presets"), not to a copy of r_presets: each row's scale, budget and
 * knobs are parsed from the doc and must be exactly the program's, every
 * field of r_quality, so a knob changed on one side only fails here. */
static void t_presets_are_the_documented_table(void)
{
    size_t n;
    rs_err e = {0};
    char *doc = rs_read_file(RS_SOURCE_DIR "/docs/accuracy.md", 1 << 22, &n, &e);
    T_ASSERTF(doc, "%s", e.msg);
    for (int i = 0; i < R_PRESETS; i++) {
        const r_preset *p = &r_presets[i];
        char key[40];
        snprintf(key, sizeof key, "\n| `%s`", p->name);
        const char *row = strstr(doc, key);
        T_ASSERTF(row, "docs/accuracy.md has no row for the preset %s", p->name);
        if (!row)
            continue;
        row += 1;
        const char *end = strchr(row, '\n');
        char line[512];
        snprintf(line, sizeof line, "%.*s", (int)(end ? end - row : (long)strlen(row)), row);
        /* | `name` | budget | what it is | ... */
        char *col[6] = {0};
        int nc = 0;
        for (char *c = strchr(line, '|'); c && nc < 6; c = strchr(c + 1, '|'))
            col[nc++] = c + 1;
        T_ASSERTF(nc >= 4, "%s: a row of %d columns", p->name, nc);
        if (nc < 4)
            continue;
        double budget = 0;
        bool is_ref = !strncmp(col[1], " the reference", 14);
        T_ASSERTF(is_ref || sscanf(col[1], " >= %lf dB", &budget) == 1, "%s: budget '%.20s'", p->name, col[1]);
        T_ASSERTF(fabs(budget - p->budget_db) < 1e-9, "%s: budget %.1f dB in the doc, %.1f in r_presets", p->name, budget,
                  p->budget_db);
        /* the knobs, as the doc spells them */
        r_quality q = {0};
        double scale = 0;
        char what[256];
        snprintf(what, sizeof what, "%.*s", (int)(col[3] - col[2] - 1), col[2]);
        for (char *tok = strtok(what, ",("); tok; tok = strtok(NULL, ",(")) {
            while (*tok == ' ')
                tok++;
            int v, a, b, used = 0;
            if (sscanf(tok, "%dx%d", &a, &b) == 2 && a == b)
                scale = a;
            else if (sscanf(tok, "%dx", &a) == 1)
                scale = a;
            else if (!strncmp(tok, "FXAA", 4))
                q.aa = R_AA_FXAA;
            else if (!strncmp(tok, "the stage's scene size", 22))
                q.stage_scene = true;
            else if (!strncmp(tok, "mask half", 9))
                q.mask_half = true;
            else if (sscanf(tok, "shadow %d", &v) == 1)
                q.shadow_size = v;
            else if (sscanf(tok, "silhouette %d", &v) == 1)
                q.sil_size = v;
            else if (sscanf(tok, "LSPSM static %d", &v) == 1)
                q.lspsm_static = v;
            else if (sscanf(tok, "LSPSM %d", &v) == 1)
                q.lspsm_size = v;
            else if (sscanf(tok, "water %d", &v) == 1)
                q.water_grid = v;
            else if (sscanf(tok, "snow light %d", &v) == 1)
                q.snow_light = v;
            else if (sscanf(tok, "scene %d%%%n", &v, &used) == 1 && used > 0)
                q.scene_pct = v;
            else if (sscanf(tok, "fog %d", &v) == 1)
                q.fog_size = v;
            else if (sscanf(tok, "bloom %d", &v) == 1)
                q.bloom_levels = v;
        }
        T_ASSERTF(scale == p->scale, "%s: scale %g in the doc, %g in r_presets", p->name, scale, p->scale);
        T_ASSERTF(!memcmp(&q, &p->q, sizeof q),
                  "%s: the doc's knobs (aa %d, mask_half %d, shadow %d, silhouette %d, lspsm %d, water %d, fog %d, bloom %d, "
                  "snow light %d, scene %d%%) are not r_presets' (aa %d, mask_half %d, shadow %d, silhouette %d, lspsm %d, "
                  "water %d, fog %d, bloom %d, snow light %d, scene %d%%)",
                  p->name, q.aa, q.mask_half, q.shadow_size, q.sil_size, q.lspsm_size, q.water_grid, q.fog_size,
                  q.bloom_levels, q.snow_light, q.scene_pct, p->q.aa, p->q.mask_half, p->q.shadow_size, p->q.sil_size,
                  p->q.lspsm_size, p->q.water_grid, p->q.fog_size, p->q.bloom_levels, p->q.snow_light, p->q.scene_pct);
    }
    free(doc);
}

T_MAIN({"presets_are_the_documented_table", t_presets_are_the_documented_table}, {"patterns_filtered", t_patterns_filtered}, {"defaults_spelled_out_are_zero", t_defaults_spelled_out_are_zero}, {"fxaa", t_fxaa},
       {"fxaa_early_out_same_bytes", t_fxaa_early_out_same_bytes},
       {"fxaa_pass_in_graph", t_fxaa_pass_in_graph}, {"fxaa_cost", t_fxaa_cost}, {"light_maps_at_the_asked_size", t_light_maps_at_the_asked_size},
       {"shadow_and_silhouette_in_one_draw", t_shadow_and_silhouette_in_one_draw},
       {"silhouette_mips_whole", t_silhouette_mips_whole},
       {"water_grid", t_water_grid}, {"snow_light", t_snow_light}, {"scene_pct", t_scene_pct}, {"fog_size", t_fog_size}, {"out_of_range_refused", t_out_of_range_refused})
