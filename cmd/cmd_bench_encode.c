/* ringside bench encode: each software encoder of this FFmpeg, at a few
 * presets and CRF points, over the same frames: encode speed, size and
 * quality (PSNR, SSIM) after decoding again.  docs/capture.md, Encoders,
 * has the table and the defaults chosen from it.
 *
 * The frames are rendered once (demos/dojo.rsr from tick 600, after the
 * intro, through the capture's own downscale and BT.709 conversion into
 * memory), so every encoder sees the very same I420 bytes and the render
 * does not count in the encode time.
 *
 * DESIGN: quality is measured here, not with FFmpeg's filters: PSNR over Y
 * and over all three planes (every sample weighted equally, so Y counts
 * 4x per pixel as in the I420 layout), SSIM on Y over 8x8 windows moved 4
 * pixels at a time (the windows and constants of Wang et al. 2004 without
 * the Gaussian weights, as x264's --ssim and FFmpeg's ssim filter do).
 * cmd_bench_accuracy.c's PSNR compares RGB floats against a resampler and
 * is not this.  No VMAF: the FFmpeg here has no libvmaf. */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../capture/cap.h"
#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "job_render.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_target.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_progress.h"
#include "job_err.h"

/* what is tried per codec: presets fast to slow, CRF points from high quality to low */
typedef struct trial_set {
    cap_codec codec;
    const char *encoder; /* the software encoder the presets belong to */
    const char *presets[3];
    int crf[3];
} trial_set;

static const trial_set sets[] = {
    {CAP_CODEC_H264, "libx264", {"ultrafast", "veryfast", "medium"}, {18, 23, 28}},
    {CAP_CODEC_HEVC, "libx265", {"ultrafast", "superfast", "medium"}, {20, 25, 30}},
    {CAP_CODEC_VP9, "libvpx-vp9", {"8", "6", "4"}, {24, 32, 40}},
    {CAP_CODEC_AV1, "libsvtav1", {"12", "10", "8"}, {28, 35, 42}},
    {CAP_CODEC_AV1, "libaom-av1", {"8", "6", "4"}, {24, 32, 40}},
};

static void help(void)
{
    printf("usage: ringside bench encode [--frames N] [--size WxH] [--render-size WxH]\n"
           "                             [--codecs LIST] [--quick] [--csv FILE] [-q|-v]\n\n"
           "Renders N frames of demos/dojo.rsr (from tick 600) once into memory as I420,\n"
           "then encodes them with each software encoder of this FFmpeg at three presets\n"
           "and three CRF points, decodes the result with libavcodec and prints, per\n"
           "encoding: encode fps, kbit/s at 60 fps, PSNR of Y and of all planes (dB) and\n"
           "SSIM of Y, against the frames encoded.  No VMAF (this FFmpeg has no libvmaf).\n\n"
           "  --frames N         frames (default 180)\n"
           "  --size WxH         encoded size, even (default 640x360)\n"
           "  --render-size WxH  drawn size (default 1280x720)\n"
           "  --codecs LIST      comma-separated among h264,hevc,vp9,av1 (default: all there are)\n"
           "  --quick            only each encoder's default preset and CRF (one row each)\n"
           "  --csv FILE         also write the table as CSV\n"
           CLI_LOG_HELP);
}

/* memory sink: frame i of the render into slot i */
typedef struct mem_frames {
    uint8_t *buf;
    size_t frame_bytes;
    int n;
} mem_frames;

static bool mem_open(cap_sink *s, rs_err *err)
{
    (void)s, (void)err;
    return true;
}

static bool mem_write(cap_sink *s, const uint8_t *frame, uint64_t index, rs_err *err)
{
    mem_frames *m = s->impl;
    if (index >= (uint64_t)m->n)
        return rs_fail(err, CAP_ERR_ARG, "bench encode: frame %llu of %d", (unsigned long long)index, m->n);
    memcpy(m->buf + m->frame_bytes * index, frame, m->frame_bytes);
    return true;
}

static bool mem_close(cap_sink *s, bool ok, rs_err *err)
{
    (void)s, (void)err;
    return ok;
}

static const cap_sink_ops mem_ops = {"memory", mem_open, mem_write, mem_close};

static bool render_frames(int frames, int sw, int sh, int w, int h, bool quiet, mem_frames *m, rs_err *err)
{
    rp_replay rp = {0};
    plat *p = NULL;
    r_game *r = NULL;
    r_target t = {0};
    bool ok = false;
    const char *data = rs_data_dir(err);
    char demo[1200];
    if (!data)
        return false;
    snprintf(demo, sizeof demo, "%s/demos/dojo.rsr", data);
    if (!rp_read(demo, &rp, err))
        return false;
    uint64_t first = rp.ticks >= 600 + (uint64_t)frames ? 600 : 0;
    if (rp.ticks < first + (uint64_t)frames) {
        rs_fail(err, JOB_ERR_TICKS, "%s has %llu ticks, fewer than %d frames", demo, (unsigned long long)rp.ticks, frames);
        goto done;
    }
    if (!(p = plat_create(&(plat_desc){.hidden = true}, err)) || !(r = r_game_create(err)) ||
        !r_game_prepare(r, rp.stage, err) || !r_target_create(&t, sw, sh, err))
        goto done;
    cap_sink s;
    memset(&s, 0, sizeof s);
    s.ops = &mem_ops;
    s.impl = m;
    s.w = w;
    s.h = h;
    cap *c = cap_open(&(cap_desc){.src_w = sw, .src_h = sh, .w = w, .h = h}, &s, err);
    if (!c)
        goto done;
    job_render j;
    rs_progress prog;
    rs_progress_start(&prog, "render", "frames", (uint64_t)frames, quiet);
    bool drew = job_render_begin(&j, &(job_render_desc){.rp = &rp, .game = r, .target = &t, .cap = c, .name = demo,
                                                        .first = first, .end = first + (uint64_t)frames, .no_check = true},
                                 err);
    while (drew && j.frames < (uint64_t)frames) {
        drew = job_render_next(&j, err) > 0;
        rs_progress_update(&prog, j.frames);
    }
    rs_progress_end(&prog);
    ok = cap_close(c, drew, NULL, err) && drew;
done:
    if (r) {
        r_target_destroy(&t);
        r_game_destroy(r);
    }
    plat_destroy(p);
    rp_free(&rp);
    return ok;
}

/* sums of squared differences per plane of one I420 frame */
static void sq_err(const uint8_t *a, const uint8_t *b, int w, int h, double *y, double *all)
{
    size_t ny = (size_t)w * h, n = cap_frame_bytes(CAP_I420, w, h);
    double sy = 0, s = 0;
    for (size_t i = 0; i < n; i++) {
        double d = (double)a[i] - b[i];
        s += d * d;
        if (i < ny)
            sy += d * d;
    }
    *y += sy;
    *all += s;
}

static double psnr(double sse, double samples)
{
    return sse > 0 ? 10 * log10(255.0 * 255.0 * samples / sse) : 99.0;
}

/* mean SSIM of the Y plane over 8x8 windows, stride 4 */
static double ssim_y(const uint8_t *a, const uint8_t *b, int w, int h)
{
    const double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
    double sum = 0;
    int n = 0;
    for (int y = 0; y + 8 <= h; y += 4)
        for (int x = 0; x + 8 <= w; x += 4) {
            double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
            for (int j = 0; j < 8; j++)
                for (int i = 0; i < 8; i++) {
                    double p = a[(size_t)(y + j) * w + x + i], q = b[(size_t)(y + j) * w + x + i];
                    sa += p, sb += q, saa += p * p, sbb += q * q, sab += p * q;
                }
            double ma = sa / 64, mb = sb / 64;
            double va = saa / 64 - ma * ma, vb = sbb / 64 - mb * mb, cov = sab / 64 - ma * mb;
            sum += (2 * ma * mb + c1) * (2 * cov + c2) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            n++;
        }
    return n ? sum / n : 1.0;
}

static bool wanted(const char *list, cap_codec c)
{
    if (!list)
        return true;
    const char *name = cap_codec_name(c);
    size_t len = strlen(name);
    for (const char *p = list; (p = strstr(p, name)); p += len)
        if ((p == list || p[-1] == ',') && (p[len] == ',' || !p[len]))
            return true;
    return false;
}

int bench_encode(int argc, char **argv)
{
    static const struct option opts[] = {{"frames", required_argument, 0, 'f'}, {"size", required_argument, 0, 's'},
                                         {"render-size", required_argument, 0, 'r'}, {"codecs", required_argument, 0, 'C'},
                                         {"quick", no_argument, 0, 'k'},           {"csv", required_argument, 0, 'c'},
                                         {"help", no_argument, 0, 'h'},
                                         {0}};
    long frames = 180;
    int w = 640, h = 360, sw = 1280, sh = 720, c;
    const char *csv = NULL, *codecs = NULL;
    bool quick = false, quiet = !rs_log_on(RS_LOG_INFO);
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'f': if (!cli_int("--frames", optarg, 1, 10000, &frames)) return RS_EXIT_USAGE; break;
        case 's': if (!cli_size("--size", optarg, 8192, &w, &h)) return RS_EXIT_USAGE; break;
        case 'r': if (!cli_size("--render-size", optarg, 8192, &sw, &sh)) return RS_EXIT_USAGE; break;
        case 'C':
            for (const char *p = optarg; *p;) {
                char name[16];
                size_t len = strcspn(p, ",");
                snprintf(name, sizeof name, "%.*s", (int)(len < sizeof name ? len : sizeof name - 1), p);
                cap_codec cc;
                if (!cap_codec_parse(name, &cc)) {
                    cli_error("bench", "--codecs '%s': '%s' is not one of h264, hevc, vp9, av1", optarg, name);
                    return RS_EXIT_USAGE;
                }
                p += len + (p[len] == ',');
            }
            codecs = optarg;
            break;
        case 'k': quick = true; break;
        case 'c': csv = optarg; break;
        case 'h': help(); return RS_EXIT_OK;
        default: return cli_bad_option("bench", argv);
        }
    }
    rs_err err = {0};
    if (!cap_check_sizes(sw, sh, w, h, &err)) {
        cli_error("bench", "%s", err.msg);
        return RS_EXIT_USAGE;
    }
    int status = RS_EXIT_FAIL, rows = 0;
    size_t fb = cap_frame_bytes(CAP_I420, w, h);
    mem_frames m = {malloc(fb * (size_t)frames), fb, (int)frames};
    uint8_t *back = malloc(fb * (size_t)frames);
    FILE *cf = NULL;
    if (!m.buf || !back) {
        rs_fail(&err, JOB_ERR_NOMEM, "out of memory for %ld frames of %dx%d", frames, w, h);
        goto done;
    }
    if (!render_frames((int)frames, sw, sh, w, h, quiet, &m, &err))
        goto done;
    if (csv && !(cf = rs_mkdirs_for(csv, &err) ? fopen(csv, "w") : NULL)) {
        rs_fail(&err, JOB_ERR_CREATE, "%s: cannot create", csv);
        goto done;
    }
    if (cf)
        fprintf(cf, "codec,encoder,preset,crf,frames,width,height,encode_fps,kbit_s,bytes,psnr_y,psnr_yuv,ssim_y\n");
    printf("bench encode: %ld frames of demos/dojo.rsr at %dx%d (drawn at %dx%d), software encoders, 60 fps\n", frames, w,
           h, sw, sh);
    printf("%-5s %-11s %-10s %4s %9s %9s %8s %9s %8s\n", "codec", "encoder", "preset", "crf", "enc fps", "kbit/s",
           "PSNR-Y", "PSNR-YUV", "SSIM-Y");
    for (size_t si = 0; si < sizeof sets / sizeof sets[0]; si++) {
        const trial_set *ts = &sets[si];
        const char *have = cap_enc_software(ts->codec, w, h);
        if (!wanted(codecs, ts->codec) || !have || strcmp(have, ts->encoder) != 0)
            continue; /* one encoder per codec: the one render would use */
        for (int pi = 0; pi < 3; pi++)
            for (int ci = 0; ci < 3; ci++) {
                if (quick && (pi || ci))
                    continue;
                cap_enc e = {.codec = ts->codec, .crf = quick ? 0 : ts->crf[ci]};
                if (!quick)
                    snprintf(e.preset, sizeof e.preset, "%s", ts->presets[pi]);
                cap_enc_trial t;
                rs_err te = {0};
                if (!cap_enc_trial_run(&e, w, h, m.buf, (int)frames, back, &t, &te)) {
                    printf("%-5s %-11s failed: %s\n", cap_codec_name(ts->codec), ts->encoder, te.msg);
                    continue;
                }
                double sy = 0, sa = 0, ss = 0;
                for (long f = 0; f < frames; f++) {
                    sq_err(m.buf + fb * (size_t)f, back + fb * (size_t)f, w, h, &sy, &sa);
                    ss += ssim_y(m.buf + fb * (size_t)f, back + fb * (size_t)f, w, h);
                }
                double py = psnr(sy, (double)w * h * frames), pa = psnr(sa, (double)fb * frames), sim = ss / frames;
                double fps = t.encode_s > 0 ? frames / t.encode_s : 0, kbps = t.bytes * 8.0 * 60 / frames / 1000;
                printf("%-5s %-11s %-10s %4d %9.1f %9.1f %8.2f %9.2f %8.4f\n", cap_codec_name(ts->codec), t.encoder,
                       t.preset, t.crf, fps, kbps, py, pa, sim);
                fflush(stdout);
                if (cf)
                    fprintf(cf, "%s,%s,%s,%d,%ld,%d,%d,%.2f,%.1f,%llu,%.3f,%.3f,%.5f\n", cap_codec_name(ts->codec),
                            t.encoder, t.preset, t.crf, frames, w, h, fps, kbps, (unsigned long long)t.bytes, py, pa, sim);
                rows++;
            }
    }
    if (cf) {
        bool wrote = fclose(cf) == 0;
        cf = NULL;
        if (!wrote) {
            rs_fail(&err, JOB_ERR_WRITE, "%s: write failed", csv);
            goto done;
        }
    }
    if (!rows) {
        rs_fail(&err, JOB_ERR_NO_RESULT, "no encoder gave a result");
        goto done;
    }
    status = RS_EXIT_OK;
done:
    if (status != RS_EXIT_OK)
        cli_error("bench", "%s", err.msg);
    if (cf)
        fclose(cf);
    free(m.buf);
    free(back);
    return status;
}
