/* ringside bench quality: what each of the renderer's knobs costs and how
 * far it moves the picture, per stage, against a reference drawn at 4x4
 * pixels per output pixel with every knob at full; and from that the
 * quality presets (r_quality.h): for each error budget, the fastest
 * measured combination that stays inside it on every stage.
 *
 * Each configuration draws the same frames of each shipped demo (from the
 * same tick, effects warmed up as a full render would have them), brings
 * them to the output size with the capture's box filter, reads them back
 * and compares them with the reference's: PSNR over RGB (MSE pooled over
 * the frames) and SSIM on luma (Wang et al. 2004: 11x11 Gaussian window,
 * sigma 1.5).  The time is the draw and the downscale of a frame, finished
 * (glFinish), median over the frames. */
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../capture/cap.h"
#include "../capture/cap_scale.h"
#include "bench_chart.h"
#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "job_render.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_quality.h"
#include "../runtime/render/r_target.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_progress.h"
#include "job_err.h"

/* The demos and the tick each one's frames start at: where its stage
 * shows what it has (the golden images' ticks, tests/test_render.c). */
static const struct {
    const char *name;
    uint64_t tick;
} demos[] = {{"dojo", 1200},     {"harbor", 900},   {"mistvale", 700}, {"plaza", 1500},
             {"quarry", 3000},   {"shallows", 380}, {"snowfield", 900}, {"temple", 900}};
#define NDEMOS (int)(sizeof demos / sizeof *demos)
#define FRAME_STEP 15 /* ticks between the frames measured */

typedef struct config {
    const char *name;
    double scale;
    r_quality q;
    int kind; /* 0 a knob on its own, 1 a candidate combination for the presets, 2 the reference,
                 3 a shipped preset that is none of the others */
} config;

/* Cheap settings for the light-space maps, the shadow mask and the
 * effects' grids, as one knob set: each on its own is a row too (the fog
 * map's default, 128, is already small: 64 is a row of its own).  (Bloom
 * with one level is not among them: it takes the dojo's sunset glow to
 * 29 dB, measured.) */
#define CHEAP_Q .shadow_size = 512, .sil_size = 256, .mask_half = true, .lspsm_size = 1024, .water_grid = 32, .snow_light = 128
/* the cheap knobs that cost no stage much: all but the silhouette, which
 * takes temple and shallows down 1-2 dB on its own */
#define LEAN_Q .mask_half = true, .shadow_size = 512, .lspsm_size = 1024, .water_grid = 32, .snow_light = 128

static const config fixed_configs[] = {
    {"reference 4x", 4, {0}, 2},
    /* the render scale alone, then each knob on its own at 1x */
    {"1x", 1, {0}, 1},
    {"1.5x", 1.5, {0}, 1},
    {"2x (the old default)", 2, {0}, 1},
    {"1x fxaa", 1, {.aa = R_AA_FXAA}, 1},
    {"1x shadow 512", 1, {.shadow_size = 512}, 0},
    {"1x shadow 2048", 1, {.shadow_size = 2048}, 0},
    {"1x silhouette 256", 1, {.sil_size = 256}, 0},
    {"1x mask half", 1, {.mask_half = true}, 0},
    {"1x bloom 1 level", 1, {.bloom_levels = 1}, 0},
    {"1x lspsm 1024", 1, {.lspsm_size = 1024}, 0},
    {"1x lspsm static 2048", 1, {.lspsm_static = 2048}, 0},
    {"1x lspsm static 4096", 1, {.lspsm_static = 4096}, 0},
    {"1x fog 64", 1, {.fog_size = 64}, 0},
    {"1x water 32", 1, {.water_grid = 32}, 0},
    {"1x snow light 128", 1, {.snow_light = 128}, 0},
    {"1x scene 75%", 1, {.scene_pct = 75}, 0},
    /* combinations the presets choose among */
    {"1x cheap", 1, {CHEAP_Q}, 1},
    {"1x cheap fxaa", 1, {CHEAP_Q, .aa = R_AA_FXAA}, 1},
    {"1x fxaa mask half", 1, {.aa = R_AA_FXAA, .mask_half = true}, 1},
    {"1x lean", 1, {LEAN_Q}, 1},
    {"1x fxaa lean", 1, {LEAN_Q, .aa = R_AA_FXAA}, 1},
    {"1x lean scene 75%", 1, {LEAN_Q, .scene_pct = 75}, 1},
    {"1x cheap scene 75%", 1, {CHEAP_Q, .scene_pct = 75}, 1},
    {"1x lean scene 60%", 1, {LEAN_Q, .scene_pct = 60}, 1},
    {"1x lean scene 90%", 1, {LEAN_Q, .scene_pct = 90}, 1},
    /* each stage at its own size (its standard_scene_pct, chosen from the rows above) */
    {"1x lean stage scene", 1, {LEAN_Q, .stage_scene = true}, 1},
    {"1x lean stage scene static", 1, {LEAN_Q, .stage_scene = true, .lspsm_static = 2048}, 1},
    {"1x fxaa lean scene 75%", 1, {LEAN_Q, .aa = R_AA_FXAA, .scene_pct = 75}, 1},
    {"1x fxaa lean scene 85%", 1, {LEAN_Q, .aa = R_AA_FXAA, .scene_pct = 85}, 1},
    {"1.5x fxaa", 1.5, {.aa = R_AA_FXAA}, 1},
    {"1.5x cheap", 1.5, {CHEAP_Q}, 1},
    {"2x fxaa", 2, {.aa = R_AA_FXAA}, 1},
    {"2x cheap", 2, {CHEAP_Q}, 1},
    {"2x lean", 2, {LEAN_Q}, 1},
    {"2.5x", 2.5, {0}, 1},
    {"3x", 3, {0}, 1},
    {"3x cheap", 3, {CHEAP_Q}, 1},
};
#define NFIXED (int)(sizeof fixed_configs / sizeof *fixed_configs)
#define MAXCONFIGS (NFIXED + R_PRESETS)

/* the fixed ones, then each shipped preset that is not among them */
static config configs[MAXCONFIGS];
static int NCONFIGS;

typedef struct result {
    bool done;
    double ms, psnr, ssim;
    int scene_pct; /* the scene's size drawn, percent of the output's */
} result;

static void help(void)
{
    printf("usage: ringside bench quality [--size WxH] [--frames N] [--stages LIST] [--csv FILE]\n"
           "                              [--chart FILE.png] [-y|-n] [-q|-v]\n\n"
           "Draws the same frames of every shipped demo under each knob of the renderer\n"
           "(render scale, FXAA, shadow and silhouette map sizes, the shadow mask at half\n"
           "size, bloom levels, LSPSM and fog map sizes, LSPSM's static layers, the water grid, the snow's light\n"
           "map, the scene's size under the output's) and under\n"
           "combinations of them, brings each to the output size with the box filter, and\n"
           "compares it with a reference drawn at 4x4 pixels per output pixel with every\n"
           "knob at full: PSNR (RGB) and SSIM (luma), and the milliseconds a frame takes\n"
           "(draw and downscale, finished; median over the frames).  Then, for each quality\n"
           "preset's error budget, the fastest combination whose PSNR is inside it on every\n"
           "stage, beside the table the program ships (r_quality.c); and each preset's\n"
           "frame rate per stage as a ratio to the old default (2x).  docs/accuracy.md has\n"
           "the numbers.\n\n"
           "  --size WxH      output size (default 640x360, the service's default job)\n"
           "  --frames N      frames per stage, %d ticks apart, 1..30 (default 4)\n"
           "  --stages LIST   comma-separated demos (default all: dojo,harbor,mistvale,plaza,\n"
           "                  quarry,shallows,snowfield,temple)\n"
           "  --csv FILE      one row per stage and configuration (default\n"
           "                  out/bench-quality.csv; '-' standard output)\n"
           "  --chart FILE    frames per second of each configuration, labelled with its\n"
           "                  worst PSNR, as PNG and SVG beside it (default\n"
           "                  out/bench-quality.png; '' none)\n"
           "  -y, -n          replace a --csv or --chart FILE given here, or refuse it\n"
           CLI_LOG_HELP,
           FRAME_STEP);
}

/* SSIM of two 8-bit luma images (w x h), mean over the valid windows. */
static double ssim_luma(const float *a, const float *b, int w, int h)
{
    enum { R = 5 };
    double g[2 * R + 1], gs = 0;
    for (int i = -R; i <= R; i++)
        gs += g[i + R] = exp(-(double)(i * i) / (2 * 1.5 * 1.5));
    for (int i = 0; i <= 2 * R; i++)
        g[i] /= gs;
    if (w <= 2 * R || h <= 2 * R)
        return 1.0;
    size_t n = (size_t)w * h;
    /* five moments, blurred horizontally then vertically */
    double *m = calloc(n * 5, sizeof *m), *t = calloc(n * 5, sizeof *t);
    if (!m || !t) {
        free(m);
        free(t);
        return NAN;
    }
    for (size_t i = 0; i < n; i++) {
        m[i] = a[i], m[n + i] = b[i], m[2 * n + i] = (double)a[i] * a[i], m[3 * n + i] = (double)b[i] * b[i];
        m[4 * n + i] = (double)a[i] * b[i];
    }
    for (int k = 0; k < 5; k++)
        for (int y = 0; y < h; y++)
            for (int x = R; x < w - R; x++) {
                double s = 0;
                for (int i = -R; i <= R; i++)
                    s += g[i + R] * m[k * n + (size_t)y * w + x + i];
                t[k * n + (size_t)y * w + x] = s;
            }
    const double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
    double sum = 0;
    long cnt = 0;
    for (int y = R; y < h - R; y++)
        for (int x = R; x < w - R; x++) {
            double v[5];
            for (int k = 0; k < 5; k++) {
                double s = 0;
                for (int i = -R; i <= R; i++)
                    s += g[i + R] * t[k * n + (size_t)(y + i) * w + x];
                v[k] = s;
            }
            double ma = v[0], mb = v[1], va = v[2] - ma * ma, vb = v[3] - mb * mb, cov = v[4] - ma * mb;
            sum += ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            cnt++;
        }
    free(m);
    free(t);
    return sum / (double)cnt;
}

static void luma(const uint8_t *rgba, int npx, float *y)
{
    for (int i = 0; i < npx; i++)
        y[i] = (float)(0.2126 * rgba[4 * i] + 0.7152 * rgba[4 * i + 1] + 0.0722 * rgba[4 * i + 2]);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Draws demo d's frames under config c: their pixels (frames x w x h x 4,
 * top row first) into px, the median ms a frame into *ms and the scene's
 * size drawn into *scene_pct. */
static bool draw_frames(const char *data, int d, const config *c, int frames, int w, int h, uint8_t *px, double *ms,
                        int *scene_pct, rs_err *err)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/demos/%s.rsr", data, demos[d].name);
    rp_replay rp = {0};
    r_game *r = NULL;
    r_target src = {0};
    cap_scaler *sc = NULL;
    GLuint dtex = 0, dfbo = 0;
    bool ok = false;
    double t[31];
    int rw, rh;
    r_preset_render_size(&(r_preset){.scale = c->scale}, w, h, R_RENDER_MAX, &rw, &rh);
    if (!rp_read(path, &rp, err))
        goto done;
    /* one frame more, before the measured ones and neither timed nor kept:
     * llvmpipe compiles a program's code at its first draw */
    uint64_t first = demos[d].tick - FRAME_STEP, end = demos[d].tick + (uint64_t)FRAME_STEP * (uint64_t)(frames - 1) + 1;
    if (end > rp.ticks) {
        rs_fail(err, JOB_ERR_TICKS, "%s: too short for %d frames from tick %" PRIu64, path, frames, demos[d].tick);
        goto done;
    }
    if (!(r = r_game_create_opts(&(r_game_opts){.q = c->q, .quiet = true}, err)) || !r_game_prepare(r, rp.stage, err) ||
        !r_target_create(&src, rw, rh, err) || !(sc = cap_scaler_create(CAP_FILTER_BOX, rw, rh, w, h, err)))
        goto done;
    *scene_pct = r_scene_pct(&c->q, r_game_stage(r)->standard_scene_pct);
    gl.GenTextures(1, &dtex);
    gl.BindTexture(GL_TEXTURE_2D, dtex);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.GenFramebuffers(1, &dfbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, dfbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, dtex, 0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    job_render j;
    if (!job_render_begin(&j, &(job_render_desc){.rp = &rp, .game = r, .target = &src, .name = path,
                                                 .first = first, .end = end, .every = FRAME_STEP,
                                                 .no_check = true},
                          err))
        goto done;
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    for (int f = -1; f < frames; f++) {
        gl.Finish();
        double t0 = rs_now();
        if (job_render_next(&j, err) <= 0)
            goto done;
        cap_scaler_run(sc, src.tex, dfbo);
        gl.Finish();
        if (f < 0)
            continue;
        t[f] = (rs_now() - t0) * 1e3;
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, dfbo);
        gl.ReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, px + (size_t)f * w * h * 4); /* row 0 is the top */
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    }
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    qsort(t, (size_t)frames, sizeof *t, cmp_double);
    *ms = frames % 2 ? t[frames / 2] : (t[frames / 2 - 1] + t[frames / 2]) / 2;
    ok = true;
done:
    if (dfbo)
        gl.DeleteFramebuffers(1, &dfbo);
    if (dtex)
        gl.DeleteTextures(1, &dtex);
    cap_scaler_destroy(sc);
    if (src.fbo)
        r_target_destroy(&src);
    r_game_destroy(r);
    rp_free(&rp);
    return ok;
}

static void compare(const uint8_t *a, const uint8_t *ref, int frames, int w, int h, float *ya, float *yb, double *psnr,
                    double *ssim)
{
    size_t npx = (size_t)w * h;
    double se = 0, ss = 0;
    for (int f = 0; f < frames; f++) {
        const uint8_t *pa = a + (size_t)f * npx * 4, *pr = ref + (size_t)f * npx * 4;
        for (size_t i = 0; i < npx; i++)
            for (int k = 0; k < 3; k++) {
                double dd = (double)pa[4 * i + (size_t)k] - pr[4 * i + (size_t)k];
                se += dd * dd;
            }
        luma(pa, (int)npx, ya);
        luma(pr, (int)npx, yb);
        ss += ssim_luma(ya, yb, w, h);
    }
    *psnr = se == 0 ? 99.0 : 10 * log10(255.0 * 255.0 * (double)npx * 3 * frames / se);
    *ssim = ss / frames;
}

static bool q_equal(const r_quality *a, const r_quality *b)
{
    return a->shadow_size == b->shadow_size && a->sil_size == b->sil_size && a->mask_half == b->mask_half &&
           a->bloom_levels == b->bloom_levels && a->aa == b->aa && a->lspsm_size == b->lspsm_size &&
           a->lspsm_static == b->lspsm_static &&
           a->fog_size == b->fog_size && a->water_grid == b->water_grid && a->snow_light == b->snow_light &&
           a->scene_pct == b->scene_pct && a->stage_scene == b->stage_scene;
}

/* The config whose scale and knobs are these, or -1. */
static int config_like(double scale, const r_quality *q)
{
    for (int c = 0; c < NCONFIGS; c++)
        if (configs[c].scale == scale && q_equal(&configs[c].q, q))
            return c;
    return -1;
}

/* What the command line asks for. */
typedef struct quality_opts {
    int w, h, frames;
    bool use[NDEMOS];    /* the stages measured */
    int nuse;
    bool quiet, overwrite, user_csv, user_chart;
    const char *csv, *chart;
} quality_opts;

/* The results, one a stage and configuration, and what they sum to. */
typedef struct quality_res {
    result (*res)[MAXCONFIGS];
    double mean_ms[MAXCONFIGS], min_db[MAXCONFIGS], min_ssim[MAXCONFIGS];
} quality_res;

/* --stages a,b,...: the shipped demos to measure. */
static bool parse_stages(quality_opts *o, const char *arg)
{
    for (int d = 0; d < NDEMOS; d++)
        o->use[d] = false;
    for (const char *p = arg; *p;) {
        size_t k = strcspn(p, ",");
        int found = -1;
        for (int d = 0; d < NDEMOS; d++)
            if (strlen(demos[d].name) == k && !strncmp(p, demos[d].name, k))
                found = d;
        if (found < 0) {
            cli_error("bench", "--stages '%s': '%.*s' is not a shipped demo (dojo, harbor, mistvale, plaza, "
                      "quarry, shallows, snowfield, temple)", arg, (int)k, p);
            return false;
        }
        o->use[found] = true;
        p += k + (p[k] == ',');
    }
    return true;
}

/* The command line into o, checked, and the configurations listed; -1 to
 * go on, else the exit status. */
static int parse_options(int argc, char **argv, quality_opts *o)
{
    static const struct option opts[] = {{"size", required_argument, 0, 's'},   {"frames", required_argument, 0, 'f'},
                                         {"stages", required_argument, 0, 'S'}, {"csv", required_argument, 0, 'c'},
                                         {"chart", required_argument, 0, 'C'},  {"help", no_argument, 0, 'h'},         {"overwrite", no_argument, 0, 'y'},
                                         {"no-overwrite", no_argument, 0, 'n'}, {0}};
    *o = (quality_opts){.w = 640, .h = 360, .frames = 4, .csv = "out/bench-quality.csv", .chart = "out/bench-quality.png"};
    o->quiet = !rs_log_on(RS_LOG_INFO); /* -q, --loglevel (main took them) */
    for (int d = 0; d < NDEMOS; d++)
        o->use[d] = true;
    long v;
    int c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "hyn", opts, NULL)) != -1) {
        switch (c) {
        case 's': if (!cli_out_size("--size", optarg, &o->w, &o->h)) return RS_EXIT_USAGE; break;
        case 'f': if (!cli_int("--frames", optarg, 1, 30, &v)) return RS_EXIT_USAGE; o->frames = (int)v; break;
        case 'S': if (!parse_stages(o, optarg)) return RS_EXIT_USAGE; break;
        case 'c': o->csv = optarg; o->user_csv = true; break;
        case 'C': o->chart = optarg; o->user_chart = true; break;
        case 'y': o->overwrite = true; break;
        case 'n': o->overwrite = false; break;
        case 'h': help(); return RS_EXIT_OK;
        default: return cli_bad_option("bench", argv);
        }
    }
    if (optind != argc) {
        cli_error("bench", "unexpected argument '%s'", argv[optind]);
        return RS_EXIT_USAGE;
    }
    NCONFIGS = 0;
    for (int i = 0; i < NFIXED; i++)
        configs[NCONFIGS++] = fixed_configs[i];
    for (int i = 0; i < R_PRESETS; i++)
        if (config_like(r_presets[i].scale, &r_presets[i].q) < 0)
            configs[NCONFIGS++] = (config){r_presets[i].name, r_presets[i].scale, r_presets[i].q, 3};
    rs_err err = {0};
    if (o->chart && *o->chart && !bench_chart_check(o->chart, &err)) {
        cli_error("bench", "--chart %s", err.msg);
        return RS_EXIT_USAGE;
    }
    if ((o->user_csv && *o->csv && strcmp(o->csv, "-") && !cli_out_ok("bench", o->csv, o->overwrite)) ||
        (o->user_chart && *o->chart && !cli_out_ok("bench", o->chart, o->overwrite)))
        return RS_EXIT_USAGE;
    for (int d = 0; d < NDEMOS; d++)
        o->nuse += o->use[d];
    return -1;
}

/* Every configuration on every stage asked for, against the reference
 * (configuration 0, drawn first); then the means and the worst stages. */
static bool measure(const quality_opts *o, const char *data, quality_res *q, rs_err *err)
{
    int w = o->w, h = o->h, frames = o->frames;
    size_t fbytes = (size_t)w * h * 4 * (size_t)frames;
    uint8_t *ref = malloc(fbytes), *px = malloc(fbytes);
    float *ya = malloc((size_t)w * h * sizeof *ya), *yb = malloc((size_t)w * h * sizeof *yb);
    bool ok = ref && px && ya && yb;
    if (!ok)
        rs_fail(err, JOB_ERR_NOMEM, "out of memory");
    double t_start = rs_now();
    for (int d = 0, k = 0; ok && d < NDEMOS; d++) {
        if (!o->use[d])
            continue;
        k++;
        for (int ci = 0; ok && ci < NCONFIGS; ci++) {
            result *rr = &q->res[d][ci];
            if (!(ok = draw_frames(data, d, &configs[ci], frames, w, h, ci == 0 ? ref : px, &rr->ms, &rr->scene_pct, err)))
                break;
            if (ci == 0)
                rr->psnr = 99, rr->ssim = 1;
            else
                compare(px, ref, frames, w, h, ya, yb, &rr->psnr, &rr->ssim);
            rr->done = true;
            if (!o->quiet)
                fprintf(stderr, "bench quality: %s (%d/%d) %-22s %8.2f ms %7.2f dB  SSIM %.4f  [%.0f s]\n",
                        demos[d].name, k, o->nuse, configs[ci].name, rr->ms, rr->psnr, rr->ssim, rs_now() - t_start);
        }
    }
    free(ref);
    free(px);
    free(ya);
    free(yb);
    for (int ci = 0; ok && ci < NCONFIGS; ci++) {
        double sum = 0;
        q->min_db[ci] = 99, q->min_ssim[ci] = 1;
        for (int d = 0; d < NDEMOS; d++) {
            if (!o->use[d])
                continue;
            sum += q->res[d][ci].ms;
            q->min_db[ci] = fmin(q->min_db[ci], q->res[d][ci].psnr);
            q->min_ssim[ci] = fmin(q->min_ssim[ci], q->res[d][ci].ssim);
        }
        q->mean_ms[ci] = sum / o->nuse;
    }
    return ok;
}

/* The table: per configuration, mean ms and the worst stage. */
static void print_configs(const quality_opts *o, const quality_res *q)
{
    printf("bench quality: %dx%d output, %d frames a stage (%d ticks apart), reference: 4x4 pixels per output\n"
           "pixel, every knob at full; ms: draw + box downscale, finished, median a frame, mean over stages\n",
           o->w, o->h, o->frames, FRAME_STEP);
    printf("%-22s %9s %7s %9s %9s", "configuration", "ms/frame", "fps", "min dB", "min SSIM");
    for (int d = 0; d < NDEMOS; d++)
        if (o->use[d])
            printf(" %9.9s", demos[d].name);
    printf("\n");
    for (int ci = 0; ci < NCONFIGS; ci++) {
        printf("%-22s %9.2f %7.1f %9.2f %9.4f", configs[ci].name, q->mean_ms[ci], 1000 / q->mean_ms[ci], q->min_db[ci],
               q->min_ssim[ci]);
        for (int d = 0; d < NDEMOS; d++)
            if (o->use[d])
                printf(" %9.2f", q->res[d][ci].psnr);
        printf("\n");
    }
}

/* The presets: the fastest candidate inside each budget, against the
 * shipped ones, and their frame rates per stage. */
static void print_presets(const quality_opts *o, const quality_res *q)
{
    const double *mean_ms = q->mean_ms, *min_db = q->min_db;
    printf("\npresets (the fastest combination whose PSNR is inside the budget on every stage measured):\n");
    printf("%-10s %8s  %-22s %9s %9s  %s\n", "preset", "budget", "chosen", "ms/frame", "min dB", "shipped (r_quality.c)");
    int shipped[R_PRESETS];
    for (int i = 0; i < R_PRESETS; i++) {
        const r_preset *pr = &r_presets[i];
        int best = -1;
        if (pr->budget_db <= 0) {
            best = 0;
        } else {
            for (int ci = 1; ci < NCONFIGS; ci++)
                if (configs[ci].kind & 1 && min_db[ci] >= pr->budget_db && (best < 0 || mean_ms[ci] < mean_ms[best]))
                    best = ci;
        }
        shipped[i] = config_like(pr->scale, &pr->q);
        char budget[16];
        snprintf(budget, sizeof budget, pr->budget_db > 0 ? ">= %.0f dB" : "itself", pr->budget_db);
        printf("%-10s %8s  %-22s %9.2f %9.2f  %s\n", pr->name, budget, best >= 0 ? configs[best].name : "(none)",
               best >= 0 ? mean_ms[best] : 0.0, best >= 0 ? min_db[best] : 0.0,
               shipped[i] == best ? "the same" : configs[shipped[i]].name);
    }

    /* each shipped preset's frame rate per stage, against the old default (2x, every knob at full) */
    int old = config_like(2, &(r_quality){0});
    if (old < 0)
        return;
    printf("\nfps per stage and preset, and the ratio to the old default (2x):\n%-10s", "stage");
    for (int i = 0; i < R_PRESETS; i++)
        printf(" %17s", r_presets[i].name);
    printf(" %9s\n", "old (2x)");
    for (int d = 0; d < NDEMOS; d++) {
        if (!o->use[d])
            continue;
        printf("%-10s", demos[d].name);
        for (int i = 0; i < R_PRESETS; i++) {
            printf(" %8.1f (%5.2fx)", 1000 / q->res[d][shipped[i]].ms, q->res[d][old].ms / q->res[d][shipped[i]].ms);
        }
        printf(" %9.1f\n", 1000 / q->res[d][old].ms);
    }
}

/* --csv and --chart. */
static bool write_outputs(const quality_opts *o, const quality_res *q, rs_err *err)
{
    const char *csv = o->csv, *chart = o->chart;
    if (csv && *csv) {
        FILE *f = cli_bench_open("bench", csv, o->user_csv, o->overwrite);
        if (!f)
            return rs_fail(err, JOB_ERR_WRITE, "%s: not written", csv);
        fprintf(f, "stage,configuration,scale,aa,shadow_size,sil_size,mask_half,bloom_levels,lspsm_size,lspsm_static,fog_size,water_grid,"
                   "snow_light,scene_pct,ms_per_frame,psnr_db,ssim,frames,w,h\n");
        for (int d = 0; d < NDEMOS; d++)
            for (int ci = 0; o->use[d] && ci < NCONFIGS; ci++) {
                const config *cf = &configs[ci];
                const result *rr = &q->res[d][ci];
                fprintf(f, "%s,%s,%g,%s,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%.3f,%.3f,%.5f,%d,%d,%d\n", demos[d].name, cf->name, cf->scale,
                        cf->q.aa == R_AA_FXAA ? "fxaa" : "off", cf->q.shadow_size, cf->q.sil_size, cf->q.mask_half,
                        cf->q.bloom_levels, cf->q.lspsm_size, cf->q.lspsm_static, cf->q.fog_size, cf->q.water_grid, cf->q.snow_light, rr->scene_pct, rr->ms, rr->psnr, rr->ssim,
                        o->frames, o->w, o->h);
            }
        if (cli_fclose(f) != 0)
            return rs_fail(err, JOB_ERR_WRITE, "%s: cannot write", csv);
    }
    if (chart && *chart) {
        bench_bar bars[MAXCONFIGS];
        char labels[MAXCONFIGS][64];
        for (int ci = 0; ci < NCONFIGS; ci++) {
            if (ci == 0)
                snprintf(labels[ci], sizeof labels[ci], "%s", configs[ci].name);
            else
                snprintf(labels[ci], sizeof labels[ci], "%s, %.1f dB", configs[ci].name, q->min_db[ci]);
            bars[ci] = (bench_bar){labels[ci], 1000 / q->mean_ms[ci], configs[ci].kind & 1};
        }
        char title[160];
        snprintf(title, sizeof title, "bench quality: frames per second at %dx%d and the worst stage's PSNR", o->w, o->h);
        bench_chart bc = {title, "frames per second (fps), draw and downscale, higher is better", "fps", bars, NCONFIGS};
        if (!bench_chart_write(chart, &bc, err))
            return false;
    }
    return true;
}

int bench_quality(int argc, char **argv)
{
    quality_opts o;
    int status = parse_options(argc, argv, &o);
    if (status >= 0)
        return status;
    status = RS_EXIT_FAIL;
    rs_err err = {0};
    plat *p = NULL;
    quality_res q = {.res = calloc(NDEMOS, sizeof *q.res)};
    const char *data = rs_data_dir(&err);
    if (!q.res)
        rs_fail(&err, JOB_ERR_NOMEM, "out of memory");
    else if (data && (p = plat_create(&(plat_desc){.hidden = true}, &err)) && measure(&o, data, &q, &err)) {
        print_configs(&o, &q);
        print_presets(&o, &q);
        if (write_outputs(&o, &q, &err))
            status = RS_EXIT_OK;
    }
    if (status != RS_EXIT_OK)
        cli_error("bench", "%s", err.msg);
    plat_destroy(p);
    free(q.res);
    return status;
}
