/* The movie player: pacing, colour maths, the decode queue, and colour end
 * to end (clips made here by the ffmpeg command line).
 *
 * Colour references, none made with player/mv_csp.c:
 *   standard  std_to_rgb below: the BT.601 / BT.709 equations from their
 *             Kr, Kb and H.273's code-value ranges, inverted by hand, in
 *             double; checked itself against the published colour bars.
 *             mv_csp_make's matrix within 0.01 LSB of it over a grid of
 *             code values; the shader's float output on every clip within
 *             0.01 LSB wherever chroma is flat (so the texture unit's 8-bit
 *             filter weights play no part: 39-100% of a testsrc2 frame),
 *             its 8-bit output within 1 LSB there and 3 LSB everywhere.
 *   ffmpeg    swscale's own conversion (accurate rounding, full chroma
 *             interpolation, planar RGB out), told the stream's matrix,
 *             range and horizontal siting: within 1 LSB of the standard on
 *             every pixel, and of ours where chroma is flat.  Not for an
 *             odd size along a subsampled axis (it maps 161 chroma samples
 *             onto 321 pixels by 161/321, not 1/2).
 * A coefficient off by 0.002 moves saturated colours by 0.1-0.7 LSB: the
 * float comparisons see it, an 8-bit one would not. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../player/mv.h"
#include "../player/mv_csp.h"
#include "../player/mv_dec.h"
#include "../player/mv_player.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "t.h"

/* --- pacing --- */

static void runs(int num, int den, int ticks, int *out, int *n)
{
    int64_t prev = 0;
    int len = 0;
    *n = 0;
    for (int t = 0; t < ticks; t++) {
        int64_t f = mv_frame_for_tick(t, num, den);
        T_ASSERT(f >= prev && f - prev <= 3);
        if (t && f != prev) {
            out[(*n)++] = len;
            len = 0;
        }
        len++;
        prev = f;
    }
}

static void t_pacing(void)
{
    int r[1024], n;
    runs(60, 1, 61, r, &n);
    for (int i = 0; i < n; i++)
        T_EQ(r[i], 1);
    runs(30, 1, 61, r, &n);
    for (int i = 0; i < n; i++)
        T_EQ(r[i], 2);
    /* 24 fps over 60 ticks: 24 frames, 3,2,3,2 ... (2:3 pulldown) */
    runs(24, 1, 61, r, &n);
    T_EQ(n, 24);
    for (int i = 0; i < n; i++)
        T_EQ(r[i], i % 2 ? 2 : 3);
    T_EQ(mv_frame_for_tick(60, 24, 1), 24);
    /* 24000/1001: 2 and 3 ticks, and ~0.1% fewer frames */
    runs(24000, 1001, 601, r, &n);
    for (int i = 0; i < n; i++)
        T_ASSERT(r[i] == 2 || r[i] == 3);
    T_EQ(mv_frame_for_tick(600, 24000, 1001), 239);
    /* 25 fps: 5 frames per 12 ticks */
    T_EQ(mv_frame_for_tick(12, 25, 1), 5);
    /* 120 fps: every other frame */
    T_EQ(mv_frame_for_tick(7, 120, 1), 14);
    /* no frame before its time: frame f is due at tick f*60/fps */
    for (int t = 0; t < 1000; t++) {
        int64_t f = mv_frame_for_tick(t, 30000, 1001);
        T_ASSERT(f * 1001 * 60 <= (int64_t)t * 30000);
        T_ASSERT((f + 1) * 1001 * 60 > (int64_t)t * 30000);
    }
    T_EQ(mv_frame_for_tick((int64_t)1 << 40, 60, 1), (int64_t)1 << 40);
}

/* --- colour maths against the standards --- */

/* The reference, written from the standards and not from player/mv_csp.c.
 * BT.601 (Kr 0.299, Kb 0.114) and BT.709 (Kr 0.2126, Kb 0.0722), the only
 * matrices the player converts (a BT.2020 stream is shown with a guessed
 * one, said "(guessed)"):
 *     E'Y = Kr R + (1 - Kr - Kb) G + Kb B
 *     E'Cb = (B - E'Y) / (2 (1 - Kb)),  E'Cr = (R - E'Y) / (2 (1 - Kr))
 * and H.273's 8-bit code values: limited Y = 16 + 219 E'Y,
 * C = 128 + 224 E'C; full Y = 255 E'Y, C = 128 + 255 E'C.  Its inverse,
 * solved by hand from those three lines: R = E'Y + 2 (1 - Kr) E'Cr,
 * B = E'Y + 2 (1 - Kb) E'Cb, G = (E'Y - Kr R - Kb B) / (1 - Kr - Kb). */
static void std_weights(int matrix, double *kr, double *kb)
{
    *kr = matrix == MV_BT709 ? 0.2126 : 0.299;
    *kb = matrix == MV_BT709 ? 0.0722 : 0.114;
}

static void std_to_codes(int matrix, bool full, const double rgb[3], double ycc[3])
{
    double kr, kb;
    std_weights(matrix, &kr, &kb);
    double y = kr * rgb[0] + (1 - kr - kb) * rgb[1] + kb * rgb[2];
    double cb = (rgb[2] - y) / (2 * (1 - kb)), cr = (rgb[0] - y) / (2 * (1 - kr));
    ycc[0] = full ? 255 * y : 16 + 219 * y;
    ycc[1] = 128 + (full ? 255 : 224) * cb;
    ycc[2] = 128 + (full ? 255 : 224) * cr;
}

static void std_to_rgb(int matrix, bool full, double Y, double Cb, double Cr, double rgb[3])
{
    double kr, kb;
    std_weights(matrix, &kr, &kb);
    double y = full ? Y / 255 : (Y - 16) / 219;
    double cb = (Cb - 128) / (full ? 255 : 224), cr = (Cr - 128) / (full ? 255 : 224);
    rgb[0] = y + 2 * (1 - kr) * cr;
    rgb[2] = y + 2 * (1 - kb) * cb;
    rgb[1] = (y - kr * rgb[0] - kb * rgb[2]) / (1 - kr - kb);
}

/* The reference itself against published numbers: the 100% colour bars in
 * 8-bit limited range as video references tabulate them (e.g. K. Jack,
 * Video Demystified): white, yellow, cyan, green, magenta, red, blue, black. */
static void t_csp_reference_gives_published_bars(void)
{
    static const double bars[8][3] = {{1, 1, 1}, {1, 1, 0}, {0, 1, 1}, {0, 1, 0},
                                      {1, 0, 1}, {1, 0, 0}, {0, 0, 1}, {0, 0, 0}};
    static const int want[2][8][3] = {
        {{235, 128, 128}, {210, 16, 146}, {170, 166, 16}, {145, 54, 34},
         {106, 202, 222}, {81, 90, 240}, {41, 240, 110}, {16, 128, 128}}, /* BT.601 */
        {{235, 128, 128}, {219, 16, 138}, {188, 154, 16}, {173, 42, 26},
         {78, 214, 230}, {63, 102, 240}, {32, 240, 118}, {16, 128, 128}}, /* BT.709 */
    };
    for (int m = 0; m < 2; m++)
        for (int b = 0; b < 8; b++) {
            double ycc[3], back[3];
            std_to_codes(m, false, bars[b], ycc);
            for (int k = 0; k < 3; k++)
                T_ASSERTF(lround(ycc[k]) == want[m][b][k], "%s bar %d component %d: %.3f, published %d",
                          mv_matrix_name(m), b, k, ycc[k], want[m][b][k]);
            std_to_rgb(m, false, ycc[0], ycc[1], ycc[2], back);
            for (int k = 0; k < 3; k++)
                T_ASSERTF(fabs(back[k] - bars[b][k]) < 1e-12, "%s bar %d: the inverse is not the inverse",
                          mv_matrix_name(m), b);
        }
}

/* mv_csp_make's matrix and offsets, applied as shaders/movie.frag applies
 * them (rgb = m * (code/255 - offset)), against the reference over a grid
 * of code values.  0.01 LSB: m is stored in float (about 1e-4 LSB of
 * rounding); a coefficient off by 0.002 moves saturated colours by 0.1 to
 * 0.7 LSB. */
static void t_csp_matches_the_standards(void)
{
    /* black, white, zero chroma and the ends of both ranges, and between */
    static const int V[] = {0, 1, 16, 17, 40, 64, 90, 110, 127, 128, 129, 150, 180, 200, 235, 236, 240, 250, 254, 255};
    enum { NV = sizeof V / sizeof V[0] };
    for (int m = 0; m < 2; m++)
        for (int full = 0; full < 2; full++) {
            mv_csp c;
            mv_csp_make(m, full, &c);
            double worst = 0;
            int at[3] = {0, 0, 0};
            for (int i = 0; i < NV * NV * NV; i++) {
                int Y = V[i % NV], Cb = V[i / NV % NV], Cr = V[i / (NV * NV)];
                double s[3] = {Y / 255.0 - c.offset[0], Cb / 255.0 - c.offset[1], Cr / 255.0 - c.offset[2]}, want[3];
                std_to_rgb(m, full, Y, Cb, Cr, want);
                for (int k = 0; k < 3; k++) {
                    double got = c.m[k] * s[0] + c.m[3 + k] * s[1] + c.m[6 + k] * s[2];
                    double d = fabs(got - want[k]) * 255;
                    if (d > worst) {
                        worst = d;
                        at[0] = Y, at[1] = Cb, at[2] = Cr;
                    }
                }
            }
            T_ASSERTF(worst <= 0.01, "%s %s: %.4f LSB off the standard's matrix at Y %d Cb %d Cr %d", mv_matrix_name(m),
                      full ? "full" : "limited", worst, at[0], at[1], at[2]);
            /* and mv_csp_forward, the header's forward matrix for tests */
            double rgb[3] = {0.9, 0.25, 0.6}, a[3], b[3];
            mv_csp_forward(m, full, rgb, a);
            std_to_codes(m, full, rgb, b);
            for (int k = 0; k < 3; k++)
                T_ASSERTF(fabs(a[k] - b[k]) < 1e-9, "%s forward component %d: %.6f, the standard's %.6f", mv_matrix_name(m),
                          k, a[k], b[k]);
        }
}

/* --- the decode queue, with a source that makes frames up --- */

typedef struct fake_src {
    mv_src base;
    int64_t n, fail_at;
    int delay_us;
} fake_src;

static int fake_read(mv_src *b, uint8_t *dst, rs_err *err)
{
    fake_src *f = (fake_src *)b;
    if (f->delay_us)
        nanosleep(&(struct timespec){0, 1000L * f->delay_us * (long)(b->index % 3)}, NULL);
    if (b->index == f->fail_at)
        return rs_fail(err, MV_ERR_DECODE, "fake: frame %lld: broken", (long long)b->index) ? -1 : -1;
    if (b->index >= f->n)
        return 0;
    memset(dst, (int)(b->index & 0xff), mv_frame_bytes(&b->info));
    b->index++;
    return 1;
}

static void fake_close(mv_src *b)
{
    (void)b;
}

static void fake_init(fake_src *f, int64_t n, int64_t fail_at, int delay_us)
{
    memset(f, 0, sizeof *f);
    f->base.info = (mv_info){.w = 8, .h = 4, .sx = 1, .sy = 1, .fps_num = 60, .fps_den = 1};
    mv_info_planes(&f->base.info);
    f->base.read = fake_read;
    f->base.close = fake_close;
    f->n = n;
    f->fail_at = fail_at;
    f->delay_us = delay_us;
}

static void t_queue_order(void)
{
    fake_src f;
    fake_init(&f, 200, -1, 50);
    uint8_t mem[3][64], *slots[3] = {mem[0], mem[1], mem[2]};
    rs_err err = {0};
    mv_dec *d = mv_dec_start(&f.base, slots, 3, &err);
    T_ASSERT(d);
    int64_t want = 0;
    int held = -1;
    for (;;) {
        int slot;
        int64_t idx;
        int r = mv_dec_peek(d, -1, &slot, &idx);
        if (r == MV_DEC_END)
            break;
        T_EQ(r, MV_DEC_FRAME);
        T_EQ(idx, want);
        T_EQ(slots[slot][0], want & 0xff);
        mv_dec_pop(d);
        /* hold one frame back, as the PERSISTENT path does */
        if (held >= 0)
            mv_dec_release(d, held);
        held = slot;
        T_ASSERT(mv_dec_held(d) <= 1);
        want++;
    }
    T_EQ(want, 200);
    mv_dec_stop(d);
}

static void t_queue_error_after_frames(void)
{
    fake_src f;
    fake_init(&f, 100, 5, 0);
    uint8_t mem[4][64], *slots[4] = {mem[0], mem[1], mem[2], mem[3]};
    rs_err err = {0};
    mv_dec *d = mv_dec_start(&f.base, slots, 4, &err);
    T_ASSERT(d);
    int got = 0, slot, r;
    int64_t idx;
    while ((r = mv_dec_peek(d, -1, &slot, &idx)) == MV_DEC_FRAME) {
        mv_dec_pop(d);
        mv_dec_release(d, slot);
        got++;
    }
    T_EQ(got, 5);
    T_EQ(r, MV_DEC_ERROR);
    T_EQ(mv_dec_error(d)->code, MV_ERR_DECODE);
    T_CONTAINS(mv_dec_error(d)->msg, "frame 5: broken");
    mv_dec_stop(d);
}

static void t_queue_bad_slot_count(void)
{
    fake_src f;
    fake_init(&f, 100, 5, 0);
    uint8_t mem[1][64], *slots[1] = {mem[0]};
    rs_err err = {0};
    T_ASSERT(!mv_dec_start(&f.base, slots, 0, &err));
    T_EQ(err.code, MV_ERR_ARG);
    T_CONTAINS(err.msg, "decoder: 0 slots");
}

static void t_queue_bounded_stop(void)
{
    /* Nobody reads: the decoder fills every slot, then waits; stop must
     * join it without a frame being taken. */
    fake_src f;
    fake_init(&f, 1000, -1, 0);
    uint8_t mem[2][64], *slots[2] = {mem[0], mem[1]};
    rs_err err = {0};
    mv_dec *d = mv_dec_start(&f.base, slots, 2, &err);
    T_ASSERT(d);
    nanosleep(&(struct timespec){0, 20000000L}, NULL);
    int slot;
    int64_t idx;
    T_EQ(mv_dec_peek(d, 0, &slot, &idx), MV_DEC_FRAME);
    T_EQ(f.base.index, 2);
    mv_dec_stop(d);
}

/* --- colour end to end against ffmpeg --- */

typedef struct ccase {
    const char *name, *codec; /* "h264", "vp9", "y4m" */
    const char *pix_fmt;      /* ffmpeg's: yuv420p, yuv422p, yuv444p, gray, yuvj420p */
    int w, h;
    int matrix;
    bool full;
} ccase;

static bool have_ffmpeg(void)
{
    return system("ffmpeg -hide_banner -loglevel error -version >/dev/null 2>&1") == 0;
}

static bool run(const char *cmd)
{
    int r = system(cmd);
    if (r)
        fprintf(stderr, "command failed (%d): %s\n", r, cmd);
    return r == 0;
}

static uint8_t *read_all(const char *path, size_t want)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    uint8_t *b = malloc(want ? want : 1);
    size_t n = b ? fread(b, 1, want, f) : 0;
    fclose(f);
    if (n != want) {
        free(b);
        return NULL;
    }
    return b;
}

/* A plane's value at chroma coordinate (x, y), bilinear, edges clamped;
 * *flat stays true only if the 4x4 samples around it are all equal:
 * there a texture unit's 8-bit filter weights cannot change the result. */
static double bil(const uint8_t *p, int w, int h, double x, double y, bool *flat)
{
    int x0 = (int)floor(x), y0 = (int)floor(y);
    double ax = x - x0, ay = y - y0;
#define AT(X, Y) p[(size_t)((Y) < 0 ? 0 : (Y) >= h ? h - 1 : (Y)) * w + ((X) < 0 ? 0 : (X) >= w ? w - 1 : (X))]
    for (int dy = -1; dy <= 2 && *flat; dy++)
        for (int dx = -1; dx <= 2 && *flat; dx++)
            *flat = AT(x0 + dx, y0 + dy) == AT(x0, y0);
    return AT(x0, y0) * (1 - ax) * (1 - ay) + AT(x0 + 1, y0) * ax * (1 - ay) + AT(x0, y0 + 1) * (1 - ax) * ay +
           AT(x0 + 1, y0 + 1) * ax * ay;
#undef AT
}

/* The frame shown, drawn into a w x h target of `format` (GL_RGBA8 or
 * GL_RGBA32F: the shader's output before any 8-bit rounding) and read
 * back as RGB of `type`, GL's rows (bottom up). */
static void draw(mv_player *mp, int w, int h, GLenum format, GLenum type, void *out)
{
    GLuint tex, fbo;
    gl.GenTextures(1, &tex);
    gl.BindTexture(GL_TEXTURE_2D, tex);
    gl.TexImage2D(GL_TEXTURE_2D, 0, (GLint)format, w, h, 0, GL_RGBA, type, NULL);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.GenFramebuffers(1, &fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    T_EQ(gl.CheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    mv_player_draw(mp, w, h);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, w, h, GL_RGB, type, out);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.DeleteFramebuffers(1, &fbo);
    gl.DeleteTextures(1, &tex);
}

/* Differences in LSB: the largest and the PSNR. */
typedef struct diff {
    double max, se;
    size_t n;
} diff;

static void diff_add(diff *d, double e)
{
    d->max = fmax(d->max, fabs(e));
    d->se += e * e;
    d->n++;
}

static double diff_psnr(const diff *d)
{
    return d->n && d->se > 0 ? 10 * log10(255.0 * 255.0 * d->n / d->se) : 99;
}

static void check_case(const ccase *cc)
{
    if (!have_ffmpeg())
        T_SKIP_INSTALL("no ffmpeg command line (tools/deps.sh test installs it)");
    const char *dir = t_tmpdir();
    char clip[512], ref[512], planes[512], cmd[4096];
    const char *ext = !strcmp(cc->codec, "y4m") ? "y4m" : !strcmp(cc->codec, "vp9") ? "webm" : "mp4";
    snprintf(clip, sizeof clip, "%s/%s.%s", dir, cc->name, ext);
    snprintf(ref, sizeof ref, "%s/%s.gbrp", dir, cc->name);
    snprintf(planes, sizeof planes, "%s/%s.yuv", dir, cc->name);
    const char *mat = cc->matrix == MV_BT709 ? "bt709" : "smpte170m";
    const char *smat = cc->matrix == MV_BT709 ? "bt709" : "bt601";
    const char *rng = cc->full ? "pc" : "tv";
    const char *enc = !strcmp(cc->codec, "h264") ? "-c:v libx264 -preset ultrafast -qp 10"
                      : !strcmp(cc->codec, "vp9") ? "-c:v libvpx-vp9 -deadline realtime -crf 10 -b:v 0"
                                                  : "-f yuv4mpegpipe -strict -1";
    /* 3 frames at 60 fps: ticks 0..2 show frames 0..2 */
    snprintf(cmd, sizeof cmd,
             "ffmpeg -nostdin -hide_banner -loglevel error -y -f lavfi -i testsrc2=size=%dx%d:rate=60 -frames:v 3 "
             "-vf crop=%d:%d:0:0:exact=1,scale=out_color_matrix=%s:out_range=%s,format=%s -colorspace %s -color_primaries %s "
             "-color_trc %s -color_range %s %s '%s'",
             (cc->w + 1) & ~1, (cc->h + 1) & ~1, cc->w, cc->h, smat, rng, cc->pix_fmt, mat, cc->matrix == MV_BT709 ? "bt709" : "smpte170m",
             cc->matrix == MV_BT709 ? "bt709" : "smpte170m", rng, enc, clip);
    T_ASSERT(run(cmd));

    /* ours */
    struct plat *ctx = t_context("egl");
    rs_err err = {0};
    mv_player_opts o = {.wait = true};
    if (!strcmp(cc->codec, "y4m")) /* Y4M has no matrix tag: say it */
        o.matrix = cc->matrix == MV_BT709 ? MV_OVERRIDE_709 : MV_OVERRIDE_601;
    mv_player *mp = mv_player_open(clip, &o, &err);
    T_ASSERTF(mp, "%s", err.msg);
    const mv_info *i = mv_player_info(mp);
    T_EQ(i->w, cc->w);
    T_EQ(i->h, cc->h);
    T_EQ(i->matrix, cc->matrix);
    T_EQ(i->full_range, cc->full);
    int w = i->w, h = i->h;
    size_t n = (size_t)w * h * 3;

    /* ffmpeg's RGB (planar gbrp: with packed rgb24 output swscale puts
     * 4:2:0 chroma half a luma row low) and the decoded planes, frame 0.
     * swscale's chroma position: only for subsampled directions (an
     * explicit 0 on a full-resolution axis shifts it). */
    char pos[64] = "";
    if (i->sx)
        snprintf(pos, sizeof pos, ":in_h_chr_pos=%d", i->chroma_loc == MV_CHROMA_CENTER ? 128 : 0);
    snprintf(cmd, sizeof cmd,
             "ffmpeg -nostdin -hide_banner -loglevel error -y -i '%s' -frames:v 1 -vf '"
             "scale=in_color_matrix=%s:in_range=%s:out_range=pc%s:"
             "flags=bilinear+accurate_rnd+full_chroma_int,format=gbrp' -f rawvideo '%s'",
             clip, smat, rng, pos, ref);
    T_ASSERT(run(cmd));
    /* the planes as decoded: a yuvj format keeps full range as it is */
    const char *pf = i->mono ? "gray"
                     : i->sx == 0 ? (i->full_range ? "yuvj444p" : "yuv444p")
                     : i->sy == 0 ? (i->full_range ? "yuvj422p" : "yuv422p")
                                  : (i->full_range ? "yuvj420p" : "yuv420p");
    snprintf(cmd, sizeof cmd,
             "ffmpeg -nostdin -hide_banner -loglevel error -y -i '%s' -frames:v 1 -pix_fmt %s -f rawvideo '%s'", clip,
             pf, planes);
    T_ASSERT(run(cmd));
    uint8_t *fr = read_all(ref, n), *pl = read_all(planes, mv_frame_bytes(i));
    T_ASSERT(fr && pl);

    T_EQ(mv_player_tick(mp, &err), 1);
    T_EQ(mv_player_frame(mp), 0);
    uint8_t *ours = malloc(n);
    float *ours_f = malloc(n * sizeof *ours_f);
    draw(mp, w, h, GL_RGBA8, GL_UNSIGNED_BYTE, ours);
    draw(mp, w, h, GL_RGBA32F, GL_FLOAT, ours_f);

    /* the standards' reference (std_to_rgb) from the decoded planes, chroma
     * bilinear at the stream's H.273 siting */
    const uint8_t *Y = pl, *Cb = pl + (size_t)w * h, *Cr = Cb + (size_t)i->cw * i->ch;
    int sx = 1 << i->sx, sy = 1 << i->sy;
    double px = i->chroma_loc == MV_CHROMA_CENTER ? (sx - 1) / 2.0 : 0;
    double py = i->chroma_loc == MV_CHROMA_TOPLEFT ? 0 : (sy - 1) / 2.0;
    /* swscale maps an odd number of pixels along a subsampled axis by
     * 161/321 instead of 1/2, drifting by up to half a pixel at the far edge */
    bool odd = (i->sx && (w & 1)) || (i->sy && (h & 1));
    diff fl_flat = {0}, u8_flat = {0}, u8_all = {0}, ff_std = {0}, ff_flat = {0}, ff_all = {0};
    size_t nflat = 0, total = (size_t)w * h;
    double sat = 0; /* the largest chroma excursion among the flat pixels */
    for (int y = 0; y < h; y++) {
        size_t row = (size_t)(h - 1 - y) * w * 3;
        for (int x = 0; x < w; x++) {
            double cb = 128, cr = 128, rgb[3];
            bool flat = true;
            if (!i->mono && (sx > 1 || sy > 1)) {
                double cx = (x - px) / sx, cy = (y - py) / sy;
                cb = bil(Cb, i->cw, i->ch, cx, cy, &flat);
                cr = bil(Cr, i->cw, i->ch, cx, cy, &flat);
            } else if (!i->mono) {
                cb = Cb[(size_t)y * w + x];
                cr = Cr[(size_t)y * w + x];
            }
            std_to_rgb(i->matrix, i->full_range, Y[(size_t)y * w + x], cb, cr, rgb);
            nflat += flat;
            if (flat)
                sat = fmax(sat, fmax(fabs(cb - 128), fabs(cr - 128)));
            for (int k = 0; k < 3; k++) {
                static const int gbrp[3] = {2, 0, 1}; /* R, G, B in planes G, B, R */
                double want = (rgb[k] < 0 ? 0 : rgb[k] > 1 ? 1 : rgb[k]) * 255, want8 = floor(want + 0.5);
                int got = ours[row + x * 3 + k], ff = fr[(size_t)gbrp[k] * total + (size_t)y * w + x];
                diff_add(&u8_all, got - want8);
                if (flat) {
                    diff_add(&fl_flat, ours_f[row + x * 3 + k] * 255.0 - want);
                    diff_add(&u8_flat, got - want8);
                }
                if (!odd) {
                    diff_add(&ff_std, ff - want8);
                    diff_add(&ff_all, got - ff);
                    if (flat)
                        diff_add(&ff_flat, got - ff);
                }
            }
        }
    }
    char ffs[160] = "ffmpeg: not compared (odd size)";
    if (!odd)
        snprintf(ffs, sizeof ffs, "ffmpeg vs the standard %.0f LSB; vs ours %.0f LSB where flat, %.0f LSB, %.1f dB everywhere",
                 ff_std.max, ff_flat.max, ff_all.max, diff_psnr(&ff_all));
    fprintf(stderr,
            "  %s: %s %dx%d %s %s, chroma %s: vs the standard: float %.4f LSB and 8-bit %.0f LSB where chroma is "
            "flat (%.0f%% of pixels, chroma to 128 +- %.0f), 8-bit %.0f LSB, %.1f dB everywhere; %s\n",
            cc->name, i->pixfmt, w, h, mv_matrix_name(i->matrix), i->full_range ? "full" : "limited",
            i->mono ? "none" : i->chroma_loc == MV_CHROMA_CENTER ? "centre" : i->chroma_loc == MV_CHROMA_LEFT ? "left" : "top-left",
            fl_flat.max, u8_flat.max, 100.0 * nflat / total, sat, u8_all.max, diff_psnr(&u8_all), ffs);
    /* enough of the picture is compared exactly, saturated colours included */
    T_ASSERTF(nflat * 10 >= total * 3, "only %.1f%% of pixels have flat chroma", 100.0 * nflat / total);
    T_ASSERTF(i->mono || sat >= 100, "the flat pixels' chroma reaches only 128 +- %.0f", sat);
    /* the shader's output against the standards' matrix where the texture
     * unit's weights play no part: float rounding only (measured 0.0001) */
    T_ASSERTF(fl_flat.max <= 0.01, "vs the standard's matrix, in float where chroma is flat: %.4f LSB", fl_flat.max);
    T_ASSERTF(u8_flat.max <= 1, "vs the standard, 8-bit where chroma is flat: %.0f LSB", u8_flat.max);
    /* between chroma samples the texture unit weighs them in steps of 1/256:
     * measured 1-3 LSB on llvmpipe (0 where nothing is interpolated) */
    T_ASSERTF(u8_all.max <= 3 && diff_psnr(&u8_all) >= 55, "vs the standard, 8-bit: max %.0f LSB, PSNR %.1f dB",
              u8_all.max, diff_psnr(&u8_all));
    if (!odd) {
        /* ffmpeg, an implementation of its own, agrees with the reference */
        T_ASSERTF(ff_std.max <= 1, "ffmpeg vs the standard: %.0f LSB", ff_std.max);
        T_ASSERTF(ff_flat.max <= 1 && ff_all.max <= 3, "vs ffmpeg: %.0f LSB where chroma is flat, %.0f everywhere",
                  ff_flat.max, ff_all.max);
    }

    /* and the next two frames arrive in order */
    T_EQ(mv_player_tick(mp, &err), 1);
    T_EQ(mv_player_frame(mp), 1);
    T_EQ(mv_player_tick(mp, &err), 1);
    T_EQ(mv_player_frame(mp), 2);
    T_EQ(mv_player_tick(mp, &err), 0);
    free(fr);
    free(pl);
    free(ours);
    free(ours_f);
    mv_player_close(mp);
    plat_destroy(ctx);
}

#define CASE(n, codec, pf, w, h, m, full)                                                \
    static void t_colour_##n(void)                                                       \
    {                                                                                    \
        ccase c = {#n, codec, pf, w, h, m, full};                                        \
        check_case(&c);                                                                  \
    }
CASE(h264_420_709_tv, "h264", "yuv420p", 320, 240, MV_BT709, false)
CASE(h264_420_601_tv_odd, "h264", "yuv420p", 1278, 718, MV_BT601, false)
CASE(h264_422_709_pc, "h264", "yuv422p", 320, 240, MV_BT709, true)
CASE(h264_444_601_pc, "h264", "yuv444p", 320, 240, MV_BT601, true)
CASE(h264_420_601_pc, "h264", "yuvj420p", 320, 240, MV_BT601, true)
CASE(vp9_420_709_tv, "vp9", "yuv420p", 321, 241, MV_BT709, false)
CASE(vp9_422_601_pc, "vp9", "yuv422p", 320, 240, MV_BT601, true)
CASE(vp9_444_709_tv, "vp9", "yuv444p", 320, 240, MV_BT709, false)
CASE(y4m_420_601_tv_odd, "y4m", "yuv420p", 321, 241, MV_BT601, false)
CASE(y4m_422_709_pc, "y4m", "yuv422p", 320, 240, MV_BT709, true)
CASE(y4m_444_601_tv, "y4m", "yuv444p", 319, 239, MV_BT601, false)
CASE(y4m_gray_709_pc, "y4m", "gray", 320, 240, MV_BT709, true)

T_MAIN({"pacing", t_pacing}, {"csp_reference_gives_published_bars", t_csp_reference_gives_published_bars},
       {"csp_matches_the_standards", t_csp_matches_the_standards},
       {"queue_order", t_queue_order}, {"queue_error_after_frames", t_queue_error_after_frames},
       {"queue_bad_slot_count", t_queue_bad_slot_count},
       {"queue_bounded_stop", t_queue_bounded_stop}, {"colour_h264_420_709_tv", t_colour_h264_420_709_tv},
       {"colour_h264_420_601_tv_odd", t_colour_h264_420_601_tv_odd},
       {"colour_h264_422_709_pc", t_colour_h264_422_709_pc}, {"colour_h264_444_601_pc", t_colour_h264_444_601_pc},
       {"colour_h264_420_601_pc", t_colour_h264_420_601_pc}, {"colour_vp9_420_709_tv", t_colour_vp9_420_709_tv},
       {"colour_vp9_422_601_pc", t_colour_vp9_422_601_pc}, {"colour_vp9_444_709_tv", t_colour_vp9_444_709_tv},
       {"colour_y4m_420_601_tv_odd", t_colour_y4m_420_601_tv_odd},
       {"colour_y4m_422_709_pc", t_colour_y4m_422_709_pc}, {"colour_y4m_444_601_tv", t_colour_y4m_444_601_tv},
       {"colour_y4m_gray_709_pc", t_colour_y4m_gray_709_pc})
