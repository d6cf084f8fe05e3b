/* ringside bench accuracy: run time against error for the downscale
 * filters, measured against OpenImageIO's resize (lanczos3 when
 * downsizing) of the same full-size frames, plus the error of the
 * RGB -> YCbCr 4:2:0 conversion. */
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../capture/cap.h"
#include "../capture/cap_oiio.h"
#include "../capture/cap_scale.h"
#include "cli.h"
#include "gl/rgl.h"
#include "platform/plat.h"
#include "render/r_game.h"
#include "render/r_target.h"
#include "replay/rp.h"
#include "util/rs_file.h"
#include "util/rs_img.h"
#include "util/rs_progress.h"

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

static void help(void)
{
    printf("usage: ringside bench accuracy [--frames N] [--size WxH] [--render-size WxH] [--csv FILE]\n\n"
           "Downscales N frames of demos/dojo.rsr with every GPU filter (box, bilinear,\n"
           "nearest, lanczos3) and the CPU box of sequential capture, and compares each\n"
           "with OpenImageIO's resize of the same full-size frame (its lanczos3): PSNR in dB\n"
           "over RGB and milliseconds per frame (glFinish-timed, 20 repetitions).  Also\n"
           "reports what the RGB -> YCbCr 4:2:0 conversion loses.\n\n"
           "  --frames N   frames from tick 600 on, 60 ticks apart (default 8)\n"
           "  --csv FILE   also write the table (default out/bench-accuracy.csv)\n");
}

int bench_accuracy(int argc, char **argv)
{
    static const struct option opts[] = {{"frames", required_argument, 0, 'f'}, {"size", required_argument, 0, 's'},
                                         {"render-size", required_argument, 0, 'r'}, {"csv", required_argument, 0, 'c'},
                                         {"help", no_argument, 0, 'h'},         {0}};
    int frames = 8, sw = 1280, sh = 720, w = 640, h = 360, c;
    long v;
    const char *csv = "out/bench-accuracy.csv";
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'f': if (!cli_int("--frames", optarg, 1, 60, &v)) return RS_EXIT_USAGE; frames = (int)v; break;
        case 's': if (!cli_size("--size", optarg, 8192, &w, &h)) return RS_EXIT_USAGE; break;
        case 'r': if (!cli_size("--render-size", optarg, 8192, &sw, &sh)) return RS_EXIT_USAGE; break;
        case 'c': csv = optarg; break;
        case 'h': help(); return RS_EXIT_OK;
        default:
            cli_error("bench", "bad option or missing value '%s'", argv[optind - 1]);
            return cli_usage_error("bench");
        }
    }
    rs_err err = {0};
    if (!cap_check_sizes(sw, sh, w, h, &err)) {
        cli_error("bench", "%s", err.msg);
        return RS_EXIT_USAGE;
    }
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
        rs_fail(&err, 1, "out of memory");
        goto done;
    }
    if (!data)
        goto done;
    snprintf(demo, sizeof demo, "%s/demos/dojo.rsr", data);
    if (!rp_read(demo, &rp, &err))
        goto done;
    if (rp.ticks < 600 + 60 * (uint64_t)frames) {
        rs_fail(&err, 1, "%s is too short for %d frames", demo, frames);
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

    g_state prev, cur;
    g_init(&cur, rp.stage, rp.seed);
    uint64_t tick = 0;
    for (int fr = 0; fr < frames; fr++) {
        uint64_t until = 600 + 60 * (uint64_t)fr;
        while (tick < until) {
            prev = cur;
            g_step(&cur, &rp.inputs[2 * tick++], NULL);
        }
        gl.BindFramebuffer(GL_FRAMEBUFFER, src.fbo);
        r_game_draw(r, &prev, &cur, 1.0f, sw, sh);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
        gl.ReadPixels(0, 0, sw, sh, GL_RGBA, GL_UNSIGNED_BYTE, full);
        gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
        rs_flip_rows(full, sw, sh, 4); /* top-down for the reference */
        char oerr[512];
        if (!cap_oiio_resize(full, sw, sh, ref, w, h, oerr, sizeof oerr)) {
            rs_fail(&err, 1, "%s", oerr);
            goto done;
        }
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
           sw, sh, w, h, cap_oiio_version());
    printf("%-12s %10s %12s\n", "filter", "PSNR dB", "ms/frame");
    FILE *cf = NULL;
    if (csv && *csv) {
        cf = rs_mkdirs_for(csv, &err) ? fopen(csv, "w") : NULL;
        if (!cf) {
            rs_fail(&err, 1, "%s: cannot create", csv);
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
            rs_fail(&err, 1, "%s: write failed", csv);
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
