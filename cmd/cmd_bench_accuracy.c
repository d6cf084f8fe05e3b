/* ringside bench accuracy: run time against error
 *   - the downscale filters, against OpenImageIO's resize (lanczos3 when
 *     downsizing) of the same full-size frames, plus the error of the
 *     RGB -> YCbCr 4:2:0 conversion;
 *   - the IBL prefilter: integration resolution against a brute-force
 *     integration over a fine cube;
 *   - the tone-curve table: size against the analytic curve;
 *   - the water automaton: Courant number against stability;
 *   - LSPSM shadow-map texel density against uniform shadow mapping. */
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../capture/cap.h"
#include "../capture/cap_scale.h"
#include "cli.h"
#include "job_render.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_game.h"
#include "../runtime/fx/fx_fog.h"
#include "../runtime/fx/fx_water_sim.h"
#include "../runtime/render/r_ibl.h"
#include "../runtime/render/r_lspsm.h"
#include "../runtime/render/r_stage.h"
#include "../runtime/render/r_tone.h"
#include "../runtime/render/r_target.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_img.h"
#include "../runtime/util/rs_oiio.h"
#include "../runtime/util/rs_progress.h"
#include "job_err.h"

static double psnr_rgb(const uint8_t *a, const float *ref, size_t npx)
{
    double se = 0;
    for (size_t i = 0; i < npx; i++)
        for (int k = 0; k < 3; k++) {
            double d = a[4 * i + (size_t)k] - ref[4 * i + (size_t)k];
            se += d * d;
        }
    return se == 0 ? 99.0 : 10 * log10(255.0 * 255.0 * (double)npx * 3 / se);
}

/* BT.709 limited range back to RGB, chroma repeated over its 2x2 block. */
static void i420_to_rgba(const uint8_t *yuv, int w, int h, float *rgba)
{
    const uint8_t *py = yuv, *pcb = yuv + (size_t)w * h, *pcr = pcb + (size_t)(w / 2) * (h / 2);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double l = (py[(size_t)y * w + x] - 16) / 219.0;
            double cb = (pcb[(size_t)(y / 2) * (w / 2) + x / 2] - 128) / 224.0 * 1.8556;
            double cr = (pcr[(size_t)(y / 2) * (w / 2) + x / 2] - 128) / 224.0 * 1.5748;
            double r = l + cr, b = l + cb, g = (l - 0.2126 * r - 0.0722 * b) / 0.7152;
            float *o = rgba + ((size_t)y * w + x) * 4;
            o[0] = (float)(fmin(fmax(r, 0), 1) * 255), o[1] = (float)(fmin(fmax(g, 0), 1) * 255);
            o[2] = (float)(fmin(fmax(b, 0), 1) * 255), o[3] = 255;
        }
}

/* Stratified sample texels of one map: k x k per face. */
#define IBL_SAMPLES_PER_EDGE 4

/* IBL prefilter accuracy: each source size against r_ibl_eval over a
 * reference cube of ref_size texels per face edge (every texel of it is an
 * integration direction: brute force), at 6 * 4 * 4 texels of each map,
 * key light on.  Error per sample: the largest channel difference over
 * the reference luminance. */
static bool ibl_table(const r_stage *st, const int *sizes, int nsizes, int ref_size, FILE *cf, rs_err *err)
{
    r_env ref_env = {0};
    if (!r_env_build(st, ref_size, &ref_env, err))
        return false;
    float key[3];
    r_ibl_key_dir(st, &ref_env, key);
    r_ibl_params dp;
    r_ibl_default_params(&dp);
    /* the reference, once: per map, per sample texel */
    enum { NS = 6 * IBL_SAMPLES_PER_EDGE * IBL_SAMPLES_PER_EDGE };
    static double ref[R_IBL_MAPS][NS][3];
    static int sf[R_IBL_MAPS][NS], si[R_IBL_MAPS][NS], sj[R_IBL_MAPS][NS];
    double t0 = rs_now();
    for (int m = 0; m < R_IBL_MAPS; m++) {
        int n = dp.out_size[m], k = 0;
        for (int f = 0; f < 6; f++)
            for (int a = 0; a < IBL_SAMPLES_PER_EDGE; a++)
                for (int b = 0; b < IBL_SAMPLES_PER_EDGE; b++, k++) {
                    sf[m][k] = f;
                    si[m][k] = (2 * b + 1) * n / (2 * IBL_SAMPLES_PER_EDGE);
                    sj[m][k] = (2 * a + 1) * n / (2 * IBL_SAMPLES_PER_EDGE);
                    float d[3];
                    r_cube_dir(f, si[m][k], sj[m][k], n, d);
                    r_ibl_eval(st, &ref_env, key, m, R_IBL_KEY_ON, d, ref[m][k]);
                }
    }
    double ref_s = rs_now() - t0;
    long threads = dp.threads ? dp.threads : sysconf(_SC_NPROCESSORS_ONLN);
    threads = threads < 1 ? 1 : threads > 8 ? 8 : threads; /* what r_ibl_build uses */
    r_env_free(&ref_env);
    printf("\nIBL prefilter (stage %s): source cube size vs a brute-force integration over a %d-per-edge cube\n"
           "(%d directions per output texel, %d sample texels per map, %.1f s); relative error = largest channel\n"
           "difference / reference luminance; ms for the whole set of six maps (%ld threads)\n",
           st->name, ref_size, 6 * ref_size * ref_size, NS, ref_s, threads);
    printf("%8s %10s %22s %22s %22s\n", "src", "ms/set", "diffuse rms / max", "spec16 rms / max", "spec128 rms / max");
    for (int z = 0; z < nsizes; z++) {
        r_ibl_params p = dp;
        p.src_size = sizes[z];
        r_ibl ibl = {0};
        if (!r_ibl_build(st, &p, NULL, &ibl, err))
            return false;
        printf("%8d %10.1f", sizes[z], ibl.ms);
        if (cf)
            fprintf(cf, "%d,%.3f", sizes[z], ibl.ms);
        for (int m = 0; m < R_IBL_MAPS; m++) {
            double se = 0, worst = 0;
            for (int k = 0; k < NS; k++) {
                const float *v = ibl.map[m][R_IBL_KEY_ON][sf[m][k]] + ((size_t)sj[m][k] * ibl.size[m] + si[m][k]) * 3;
                const double *r = ref[m][k];
                double lum = 0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2], d = 0;
                for (int c = 0; c < 3; c++)
                    d = fmax(d, fabs(v[c] - r[c]));
                double rel = d / fmax(lum, 1e-6);
                se += rel * rel;
                worst = fmax(worst, rel);
            }
            printf("      %7.4f / %7.4f", sqrt(se / NS), worst);
            if (cf)
                fprintf(cf, ",%.6f,%.6f", sqrt(se / NS), worst);
        }
        printf("%s\n", sizes[z] == dp.src_size ? "   <- default" : "");
        if (cf)
            fprintf(cf, "\n");
        r_ibl_free(&ibl);
    }
    return true;
}

/* Tone LUT: size against the analytic curve, in 8-bit output steps. */
static void tone_table(FILE *cf)
{
    static const int sizes[] = {16, 32, 64, 128, 256, 512, 1024, 4096};
    static const double gammas[] = {1.0, 2.2, 3.0, 10.0};
    printf("\nTone curve table (Y' = ((1 - exp(-x^2))^1.5)^(1/gamma)): size vs max |table - curve| in 8-bit\n"
           "output steps, x in 0..%.0f; exact interpolation (what the shader does) and with 8-bit weights\n"
           "(what a texture unit's linear filter would do); the goal is < 0.1 step at the default size\n",
           1.25 * R_TONE_X_MAX);
    printf("%8s", "entries");
    for (size_t g = 0; g < sizeof gammas / sizeof gammas[0]; g++)
        printf("   gamma %-4.1f", gammas[g]);
    printf("   2.2, 8-bit w\n");
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        printf("%8d", sizes[k]);
        if (cf)
            fprintf(cf, "%d", sizes[k]);
        for (size_t g = 0; g < sizeof gammas / sizeof gammas[0]; g++) {
            double e = r_tone_max_error(sizes[k], gammas[g], 0) * 255;
            printf("   %10.4f", e);
            if (cf)
                fprintf(cf, ",%.6f", e);
        }
        double e8 = r_tone_max_error(sizes[k], 2.2, 8) * 255;
        printf("   %10.4f%s\n", e8, sizes[k] == R_TONE_LUT_DEFAULT ? "   <- default" : "");
        if (cf)
            fprintf(cf, ",%.6f\n", e8);
    }
}

/* "8,16,32" -> sizes; false on anything else */
static bool parse_sizes(const char *s, int *out, int *n, int max_n)
{
    *n = 0;
    while (*s) {
        char *end;
        long v = strtol(s, &end, 10);
        if (end == s || v < 1 || v > 512 || *n >= max_n || (*end && *end != ','))
            return false;
        out[(*n)++] = (int)v;
        s = *end ? end + 1 : end;
    }
    return *n > 0;
}

static void help(void)
{
    printf("usage: ringside bench accuracy [--only capture|ibl|tone|water|fog|lspsm] [--frames N] [--size WxH]\n"
           "                               [--render-size WxH] [--ibl-sizes LIST] [--ibl-reference N]\n"
           "                               [--stage NAME] [--csv FILE] [-y|-n] [-q|-v]\n\n"
           "Run time against error, six tables:\n"
           "  capture  downscales N frames of demos/dojo.rsr with every GPU filter (box, bilinear,\n"
           "           nearest, lanczos3) and the CPU box of sequential capture, and compares each\n"
           "           with OpenImageIO's resize of the same full-size frame (its lanczos3): PSNR in\n"
           "           dB over RGB and ms per frame (glFinish-timed, 20 repetitions); also what the\n"
           "           RGB -> YCbCr 4:2:0 conversion loses.\n"
           "  ibl      prefilters the stage's environment from cubes of each --ibl-sizes edge and\n"
           "           compares the six maps' texels with a brute-force integration over a\n"
           "           --ibl-reference cube: RMS and max relative error, ms per set of maps.\n"
           "  tone     the tone-curve table's size against the analytic curve, in 8-bit steps.\n"
           "  water    the wave automaton's Courant number against stability: margin to the cap,\n"
           "           energy growth over a long forced run, CPU time per step (about 10 s).\n"
           "  fog      the fog map's size (32..512) against the time of its pass and the error of\n"
           "           the density it gives, against a 1024x1024 map of the same mist.\n"
           "  lspsm    shadow-map texel density near (2 m) and far (50 m) for light space perspective\n"
           "           shadow maps against uniform shadow mapping, 1024x1024 map, by light angle.\n\n"
           "  --only T            one table (default: all six)\n"
           "  --frames N          capture: frames from tick 600 on, 60 ticks apart (default 8)\n"
           "  --size WxH          capture: the downscaled size (default 640x360)\n"
           "  --render-size WxH   capture: the size the frames are drawn at (default 1280x720)\n"
           "  --ibl-sizes LIST    source cube edges, comma-separated (default 8,16,32,64)\n"
           "  --ibl-reference N   the reference cube's edge (default 128)\n"
           "  --stage NAME        the stage whose environment the IBL table uses (default dojo)\n"
           "  --csv FILE          also write the tables (default out/bench-accuracy.csv; the IBL,\n"
           "                      tone and LSPSM tables go to FILE's name with -ibl, -tone and\n"
           "                      -lspsm added).  A FILE given here must be in a folder that\n"
           "                      exists, and none of its tables may exist unless -y\n"
           "  -y, -n              replace those tables, or refuse them, naming one (the default)\n"
           CLI_LOG_HELP);
}

/* out/x.csv + "-ibl" -> out/x-ibl.csv */
static void csv_name(const char *csv, const char *suffix, char *out, size_t n)
{
    const char *dot = strrchr(csv, '.'), *slash = strrchr(csv, '/');
    if (!dot || (slash && dot < slash))
        dot = csv + strlen(csv);
    snprintf(out, n, "%.*s%s%s", (int)(dot - csv), csv, suffix, dot);
}

/* --csv given by the user (its rules, cli.h) or the default under out/;
 * set once from the options, before any table is written */
static struct {
    bool user, overwrite;
} csv_rules;

static FILE *csv_open(const char *path, const char *header, rs_err *err)
{
    FILE *f = cli_bench_open("bench", path, csv_rules.user, csv_rules.overwrite);
    if (!f) {
        rs_fail(err, JOB_ERR_WRITE, "%s: not written", path);
        return NULL;
    }
    fprintf(f, "%s\n", header);
    return f;
}

static bool csv_close(FILE *f, const char *path, rs_err *err)
{
    if (f && fclose(f) != 0)
        return rs_fail(err, JOB_ERR_WRITE, "%s: write failed", path);
    return true;
}

static int bench_capture_accuracy(int frames, int sw, int sh, int w, int h, const char *csv);

int bench_accuracy(int argc, char **argv)
{
    static const struct option opts[] = {{"frames", required_argument, 0, 'f'}, {"size", required_argument, 0, 's'},
                                         {"render-size", required_argument, 0, 'r'}, {"csv", required_argument, 0, 'c'},
                                         {"only", required_argument, 0, 'o'}, {"ibl-sizes", required_argument, 0, 'I'},
                                         {"ibl-reference", required_argument, 0, 'R'}, {"stage", required_argument, 0, 'S'},
                                         {"help", no_argument, 0, 'h'},
                                         {"overwrite", no_argument, 0, 'y'},    {"no-overwrite", no_argument, 0, 'n'},
                                         {0}};
    int frames = 8, sw = 1280, sh = 720, w = 640, h = 360, c, ref_size = 128;
    int sizes[16] = {8, 16, 32, 64}, nsizes = 4;
    long v;
    const char *csv = "out/bench-accuracy.csv", *only = NULL, *stage = "dojo";
    optind = 1;
    opterr = 0;
    csv_rules.user = csv_rules.overwrite = false;
    while ((c = getopt_long(argc, argv, "hyn", opts, NULL)) != -1) {
        switch (c) {
        case 'f': if (!cli_int("--frames", optarg, 1, 60, &v)) return RS_EXIT_USAGE; frames = (int)v; break;
        case 's': if (!cli_size("--size", optarg, 8192, &w, &h)) return RS_EXIT_USAGE; break;
        case 'r': if (!cli_size("--render-size", optarg, 8192, &sw, &sh)) return RS_EXIT_USAGE; break;
        case 'c': csv = optarg; csv_rules.user = true; break;
        case 'y': csv_rules.overwrite = true; break;
        case 'n': csv_rules.overwrite = false; break;
        case 'o':
            if (strcmp(optarg, "capture") && strcmp(optarg, "ibl") && strcmp(optarg, "tone") && strcmp(optarg, "water") &&
                strcmp(optarg, "fog") && strcmp(optarg, "lspsm")) {
                cli_error("bench", "--only '%s': expected capture, ibl, tone, water, fog or lspsm", optarg);
                return RS_EXIT_USAGE;
            }
            only = optarg;
            break;
        case 'I':
            if (!parse_sizes(optarg, sizes, &nsizes, 16)) {
                cli_error("bench", "--ibl-sizes '%s': expected up to 16 comma-separated edges in 1..512", optarg);
                return RS_EXIT_USAGE;
            }
            break;
        case 'R': if (!cli_int("--ibl-reference", optarg, 4, 512, &v)) return RS_EXIT_USAGE; ref_size = (int)v; break;
        case 'S': stage = optarg; break;
        case 'h': help(); return RS_EXIT_OK;
        default: return cli_bad_option("bench", argv);
        }
    }
    if (optind < argc) {
        cli_error("bench", "unexpected argument '%s'", argv[optind]);
        return cli_usage_error("bench");
    }
    if (csv_rules.user && !strcmp(csv, "-")) {
        cli_error("bench", "--csv -: accuracy writes several tables; give a file name");
        return RS_EXIT_USAGE;
    }
    static const char *const suffix[] = {"", "-ibl", "-tone", "-lspsm"}, *const table[] = {"capture", "ibl", "tone", "lspsm"};
    for (int i = 0; csv_rules.user && *csv && i < 4; i++) {
        char name[1200];
        csv_name(csv, suffix[i], name, sizeof name);
        if ((!only || !strcmp(only, table[i])) && !cli_out_ok("bench", i ? name : csv, csv_rules.overwrite))
            return RS_EXIT_FAIL;
    }
    rs_err err = {0};
    if ((!only || !strcmp(only, "capture")) && !cap_check_sizes(sw, sh, w, h, &err)) {
        cli_error("bench", "%s", err.msg);
        return RS_EXIT_USAGE;
    }
    if (!only || !strcmp(only, "capture")) {
        int st = bench_capture_accuracy(frames, sw, sh, w, h, csv);
        if (st != RS_EXIT_OK)
            return st;
    }
    char path[1200];
    FILE *cf = NULL;
    if (!only || !strcmp(only, "ibl")) {
        int gi = 0;
        r_stage st;
        if (!cli_stage(stage, &gi))
            return RS_EXIT_USAGE;
        csv_name(csv, "-ibl", path, sizeof path);
        bool ok = r_stage_for_game(&st, gi, &err) &&
                  (!*csv || (cf = csv_open(path, "src_size,ms_per_set,diffuse_rms,diffuse_max,spec16_rms,spec16_max,"
                                                 "spec128_rms,spec128_max", &err)));
        ok = ok && ibl_table(&st, sizes, nsizes, ref_size, cf, &err);
        ok = csv_close(cf, path, &err) && ok;
        cf = NULL;
        if (!ok) {
            cli_error("bench", "%s", err.msg);
            return RS_EXIT_FAIL;
        }
    }
    if (!only || !strcmp(only, "tone")) {
        csv_name(csv, "-tone", path, sizeof path);
        if (*csv && !(cf = csv_open(path, "entries,gamma_1,gamma_2.2,gamma_3,gamma_10,gamma_2.2_8bit_weights", &err))) {
            cli_error("bench", "%s", err.msg);
            return RS_EXIT_FAIL;
        }
        tone_table(cf);
        if (!csv_close(cf, path, &err)) {
            cli_error("bench", "%s", err.msg);
            return RS_EXIT_FAIL;
        }
    }
    if (!only || !strcmp(only, "water"))
        fx_water_sim_accuracy_rows(stdout);
    if (!only || !strcmp(only, "fog")) {
        plat *p = plat_create(&(plat_desc){.hidden = true}, &err);
        bool ok = p && fx_fog_accuracy_rows(stdout, &err);
        plat_destroy(p);
        if (!ok) {
            cli_error("bench", "fog map: %s", err.msg);
            return RS_EXIT_FAIL;
        }
    }
    if (!only || !strcmp(only, "lspsm")) {
        csv_name(csv, "-lspsm", path, sizeof path);
        if (*csv && !(cf = cli_bench_open("bench", path, csv_rules.user, csv_rules.overwrite)))
            return RS_EXIT_FAIL;
        r_lspsm_density_rows(stdout, cf);
        if (!csv_close(cf, path, &err)) {
            cli_error("bench", "%s", err.msg);
            return RS_EXIT_FAIL;
        }
    }
    return RS_EXIT_OK;
}

static int bench_capture_accuracy(int frames, int sw, int sh, int w, int h, const char *csv)
{
    rs_err err = {0};
    int status = RS_EXIT_FAIL;
    rp_replay rp = {0};
    plat *p = NULL;
    r_game *r = NULL;
    cap_scaler *sc[CAP_FILTERS] = {0};
    r_target src = {0};
    GLuint dfbo = 0, dtex = 0;
    size_t npx = (size_t)w * h;
    uint8_t *full = malloc((size_t)sw * sh * 4), *small = malloc(npx * 4), *yuv = malloc(npx * 2);
    float *ref = malloc(npx * 4 * sizeof(float)), *back = malloc(npx * 4 * sizeof(float));
    double psnr[CAP_FILTERS + 1] = {0}, ms[CAP_FILTERS + 1] = {0}, conv = 0;
    const char *data = rs_data_dir(&err);
    char demo[1200];
    if (!full || !small || !yuv || !ref || !back) {
        rs_fail(&err, JOB_ERR_NOMEM, "out of memory");
        goto done;
    }
    if (!data)
        goto done;
    snprintf(demo, sizeof demo, "%s/demos/dojo.rsr", data);
    if (!rp_read(demo, &rp, &err))
        goto done;
    if (rp.ticks < 600 + 60 * (uint64_t)frames) {
        rs_fail(&err, JOB_ERR_TICKS, "%s is too short for %d frames", demo, frames);
        goto done;
    }
    if (!(p = plat_create(&(plat_desc){.hidden = true}, &err)) || !(r = r_game_create(&err)))
        goto done;
    for (int f = 0; f < CAP_FILTERS; f++)
        if (!(sc[f] = cap_scaler_create((cap_filter)f, sw, sh, w, h, &err)))
            goto done;
    if (!r_target_create(&src, sw, sh, &err))
        goto done;
    gl.GenTextures(1, &dtex);
    gl.BindTexture(GL_TEXTURE_2D, dtex);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    gl.GenFramebuffers(1, &dfbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, dfbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, dtex, 0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);

    /* frame fr: the state after tick 600 + 60 fr, the tick before it as prev */
    job_render j;
    if (!job_render_begin(&j, &(job_render_desc){.rp = &rp, .game = r, .target = &src, .name = demo, .first = 599,
                                                 .end = 600 + 60 * (uint64_t)(frames - 1), .every = 60, .no_check = true},
                          &err))
        goto done;
    for (int fr = 0; fr < frames; fr++) {
        if (job_render_next(&j, &err) <= 0)
            goto done;
        gl.BindFramebuffer(GL_FRAMEBUFFER, src.fbo);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
        gl.ReadPixels(0, 0, sw, sh, GL_RGBA, GL_UNSIGNED_BYTE, full);
        gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
        rs_flip_rows(full, sw, sh, 4); /* top-down for the reference */
        if (!rs_oiio_resize(full, sw, sh, ref, w, h, &err))
            goto done;
        for (int f = 0; f < CAP_FILTERS; f++) {
            gl.Finish();
            double t0 = rs_now();
            for (int rep = 0; rep < 20; rep++)
                cap_scaler_run(sc[f], src.tex, dfbo);
            gl.Finish();
            ms[f] += (rs_now() - t0) * 1e3 / 20;
            gl.BindFramebuffer(GL_READ_FRAMEBUFFER, dfbo);
            gl.ReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, small); /* row 0 is the top */
            gl.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
            psnr[f] += psnr_rgb(small, ref, npx);
            if (f == CAP_FILTER_BOX) { /* what 4:2:0 YCbCr loses, on the box result */
                cap_cpu_rgba_to_i420(small, w, h, yuv);
                i420_to_rgba(yuv, w, h, back);
                conv += psnr_rgb(small, back, npx);
            }
        }
        rs_flip_rows(full, sw, sh, 4); /* the CPU path reads bottom-up */
        double t0 = rs_now();
        cap_cpu_downscale(full, sw, sh, small, w, h);
        ms[CAP_FILTERS] += (rs_now() - t0) * 1e3;
        psnr[CAP_FILTERS] += psnr_rgb(small, ref, npx);
    }
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    printf("bench accuracy: %d frames of demos/dojo.rsr, %dx%d to %dx%d, reference: %s resize (lanczos3)\n", frames,
           sw, sh, w, h, rs_oiio_version());
    printf("%-12s %10s %12s\n", "filter", "PSNR dB", "ms/frame");
    FILE *cf = NULL;
    if (csv && *csv) {
        if (!(cf = cli_bench_open("bench", csv, csv_rules.user, csv_rules.overwrite))) {
            rs_fail(&err, JOB_ERR_WRITE, "%s: not written", csv);
            goto done;
        }
        fprintf(cf, "filter,psnr_db,ms_per_frame,frames,render_w,render_h,w,h\n");
    }
    for (int f = 0; f <= CAP_FILTERS; f++) {
        const char *name = f < CAP_FILTERS ? cap_filter_name((cap_filter)f) : "cpu box";
        printf("%-12s %10.2f %12.3f%s\n", name, psnr[f] / frames, ms[f] / frames,
               f == CAP_FILTER_BOX ? "   <- default" : "");
        if (cf)
            fprintf(cf, "%s,%.3f,%.4f,%d,%d,%d,%d,%d\n", name, psnr[f] / frames, ms[f] / frames, frames, sw, sh, w, h);
    }
    printf("RGB -> YCbCr 4:2:0 (BT.709 limited) -> RGB on the box output: %.2f dB\n", conv / frames);
    if (cf) {
        fprintf(cf, "ycbcr420_roundtrip,%.3f,,%d,%d,%d,%d,%d\n", conv / frames, frames, sw, sh, w, h);
        if (fclose(cf) != 0) {
            rs_fail(&err, JOB_ERR_WRITE, "%s: write failed", csv);
            goto done;
        }
    }
    status = RS_EXIT_OK;
done:
    if (status != RS_EXIT_OK)
        cli_error("bench", "%s", err.msg);
    if (p) {
        for (int f = 0; f < CAP_FILTERS; f++)
            cap_scaler_destroy(sc[f]);
        r_target_destroy(&src);
        gl.DeleteFramebuffers(1, &dfbo);
        gl.DeleteTextures(1, &dtex);
        r_game_destroy(r);
        plat_destroy(p);
    }
    free(full);
    free(small);
    free(yuv);
    free(ref);
    free(back);
    rp_free(&rp);
    return status;
}
