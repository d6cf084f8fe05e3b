/* capture/: the writer queue (cap, order, errors), the CPU reference
 * conversions, the GPU path against the CPU path, and both against BT.709
 * as the test writes it from the standard (bt709_reference). */
#define _GNU_SOURCE /* usleep */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../capture/cap.h"
#include "../capture/cap_seg.h"
#include "../capture/cap_writer.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/util/rs_hash.h"
#include "t.h"

/* A sink that checks order, can be slow, and can fail at a given frame. */
typedef struct fake {
    uint64_t next, fail_at;
    int delay_us;
    bool closed, committed;
} fake;

static bool f_open(cap_sink *s, rs_err *e)
{
    (void)s, (void)e;
    return true;
}
static bool f_write(cap_sink *s, const uint8_t *frame, uint64_t index, rs_err *e)
{
    fake *f = s->impl;
    if (f->delay_us)
        usleep((useconds_t)f->delay_us);
    if (index != f->next || frame[0] != (uint8_t)index || frame[7] != (uint8_t)(index >> 8))
        return rs_fail(e, CAP_ERR_FAILED, "frame %llu out of order or torn", (unsigned long long)index);
    f->next++;
    if (f->fail_at && index + 1 == f->fail_at)
        return rs_fail(e, CAP_ERR_WRITE, "fake: No space left on device");
    return true;
}
static bool f_close(cap_sink *s, bool ok, rs_err *e)
{
    (void)e;
    fake *f = s->impl;
    f->closed = true;
    f->committed = ok;
    return ok;
}
static const cap_sink_ops fake_ops = {"fake", f_open, f_write, f_close};

static void run_queue(int cap_frames, int delay_us, int frames, uint64_t fail_at, bool *ok_out, cap_writer_stats *st,
                      fake *f, rs_err *err)
{
    *f = (fake){.fail_at = fail_at, .delay_us = delay_us};
    cap_sink s = {.ops = &fake_ops, .impl = f, .w = 8, .h = 8};
    cap_writer *w = cap_writer_start(&s, 16, cap_frames, NULL, err);
    T_ASSERT(w);
    bool ok = true;
    for (int i = 0; i < frames && ok; i++) {
        uint8_t *slot = cap_writer_acquire(w);
        if (!slot) {
            ok = false;
            break;
        }
        memset(slot, 0, 16);
        slot[0] = (uint8_t)i;
        slot[7] = (uint8_t)(i >> 8);
        ok = cap_writer_submit(w, slot);
    }
    bool fin = cap_writer_finish(w, st, err);
    *ok_out = ok && fin;
}

static void t_queue_cap_holds(void)
{
    /* a slow sink: the queue fills to its cap and never beyond */
    for (int capn = 1; capn <= 8; capn *= 2) {
        bool ok;
        cap_writer_stats st;
        fake f;
        rs_err e = {0};
        run_queue(capn, 300, 60, 0, &ok, &st, &f, &e);
        T_ASSERTF(ok, "%s", e.msg);
        T_EQ(st.frames, 60);
        T_EQ(f.next, 60);
        T_ASSERTF(st.high_water <= capn && st.high_water >= capn - 1, "cap %d, high-water %d", capn, st.high_water);
        T_ASSERT(st.full_waits > 0);
    }
}

static void t_inline_queue(void)
{
    bool ok;
    cap_writer_stats st;
    fake f;
    rs_err e = {0};
    run_queue(0, 0, 100, 0, &ok, &st, &f, &e);
    T_ASSERT(ok);
    T_EQ(st.frames, 100);
    T_EQ(st.high_water, 0);
}

static void t_writer_error_reaches_the_game_thread(void)
{
    for (int capn = 0; capn <= 8; capn += 8) {
        bool ok;
        cap_writer_stats st;
        fake f;
        rs_err e = {0};
        run_queue(capn, 100, 500, 37, &ok, &st, &f, &e);
        T_ASSERT(!ok);
        T_EQ(e.code, CAP_ERR_WRITE); /* the sink's own id, carried across the thread */
        T_CONTAINS(e.msg, "No space left on device");
        T_EQ(st.frames, 36); /* frames before the failing one */
        T_ASSERT(f.next <= 40); /* the writer stopped: it did not write the rest */
    }
}

static void t_hash_is_fnv1a(void)
{
    T_EQ(rs_fnv1a64("", 0), 0xcbf29ce484222325ull);
    T_EQ(rs_fnv1a64("a", 1), 0xaf63dc4c8601ec8cull);
}

static void t_cpu_yuv_known_colours(void)
{
    /* BT.709 limited range: black 16/128/128, white 235/128/128, pure red
     * Y = 16 + 219 * 0.2126 = 62.6, Cr = 240 */
    uint8_t rgba[2 * 2 * 4], out[6];
    const uint8_t cols[3][3] = {{0, 0, 0}, {255, 255, 255}, {255, 0, 0}};
    const uint8_t want[3][3] = {{16, 128, 128}, {235, 128, 128}, {63, 102, 240}};
    for (int c = 0; c < 3; c++) {
        for (int i = 0; i < 4; i++) {
            memcpy(rgba + 4 * i, cols[c], 3);
            rgba[4 * i + 3] = 255;
        }
        cap_cpu_rgba_to_i420(rgba, 2, 2, out);
        T_ASSERTF(out[0] == want[c][0] && out[4] == want[c][1] && out[5] == want[c][2], "colour %d: %u %u %u", c,
                  out[0], out[4], out[5]);
    }
}

static void t_cpu_downscale_averages_and_flips(void)
{
    /* 4x2 source (bottom-up): bottom row 0, 100, 200, 40; top row all 80 */
    uint8_t src[4 * 2 * 4] = {0};
    const uint8_t bottom[4] = {0, 100, 200, 40};
    for (int x = 0; x < 4; x++) {
        src[x * 4] = bottom[x];
        src[(4 + x) * 4] = 80;
    }
    uint8_t dst[2 * 1 * 4];
    cap_cpu_downscale(src, 4, 2, dst, 2, 1); /* the exact-2x path */
    T_EQ(dst[0], 65);  /* (0 + 100 + 80 + 80) / 4 */
    T_EQ(dst[4], 100); /* (200 + 40 + 80 + 80) / 4 */
    uint8_t odd[3 * 1 * 4];
    cap_cpu_downscale(src, 4, 2, odd, 3, 1); /* 4/3 footprints: coverage weights */
    T_EQ(odd[0], 53);  /* (0 + 100/3 + 80 + 80/3) / (8/3) = 52.5 -> 53 */
    uint8_t dst2[2 * 2 * 4];
    cap_cpu_downscale(src, 4, 2, dst2, 2, 2); /* 2x1 boxes; output row 0 is the top */
    T_EQ(dst2[0], 80);
    T_EQ(dst2[8], 50);
    /* the 2x fast path and the general path agree (to rounding) */
    static uint8_t big[64 * 48 * 4], a[32 * 24 * 4], gen[32 * 24 * 4];
    for (int i = 0; i < (int)sizeof big; i++)
        big[i] = (uint8_t)(i * 37 + i / 7);
    cap_cpu_downscale(big, 64, 48, a, 32, 24);
    cap_cpu_downscale_area(big, 64, 48, gen, 32, 24);
    for (int i = 0; i < (int)sizeof a; i++)
        T_ASSERTF(abs(a[i] - gen[i]) <= 1, "byte %d: fast %u, general %u", i, a[i], gen[i]);
    for (int k = 0; k < 4; k++) { /* top-left output = mean of the top-left 2x2 (source rows 47 and 46) */
        int s = big[(47 * 64 + 0) * 4 + k] + big[(47 * 64 + 1) * 4 + k] + big[(46 * 64 + 0) * 4 + k] +
                big[(46 * 64 + 1) * 4 + k];
        T_EQ(a[k], (s + 2) >> 2);
    }
}

static void t_sizes(void)
{
    rs_err e = {0};
    T_ASSERT(cap_check_sizes(1280, 720, 640, 360, &e));
    T_ASSERT(!cap_check_sizes(1280, 720, 641, 360, &e));
    T_EQ(e.code, CAP_ERR_SIZE);
    T_CONTAINS(e.msg, "must be even");
    T_ASSERT(!cap_check_sizes(640, 360, 1280, 720, &e));
    T_EQ(e.code, CAP_ERR_SIZE);
    T_CONTAINS(e.msg, "larger than the render size");
    T_ASSERT(!cap_check_sizes(1280, 720, 100, 90, &e));
    T_EQ(e.code, CAP_ERR_SIZE);
    T_CONTAINS(e.msg, "more than 8 times");
    T_ASSERT(!cap_check_sizes(0, 720, 100, 90, &e));
    T_EQ(e.code, CAP_ERR_SIZE);
}

/* The sink errors a caller can act on, each with its id (no GL needed). */
static void t_sink_errors(void)
{
    cap_sink s;
    rs_err e = {0};
    T_ASSERT(!cap_sink_for("out.avi", 64, 64, &s, &e));
    T_EQ(e.code, CAP_ERR_OUTPUT);
    T_CONTAINS(e.msg, "out.avi: unknown output type '.avi'");
    T_ASSERT(!cap_sink_for("frame%d%d.png", 64, 64, &s, &e));
    T_EQ(e.code, CAP_ERR_OUTPUT);
    /* a directory where the output should go */
    char dir[600];
    snprintf(dir, sizeof dir, "%s/d.y4m", t_tmpdir());
    T_ASSERT(mkdir(dir, 0755) == 0);
    T_ASSERTF(cap_sink_for(dir, 64, 64, &s, &e), "%s", e.msg);
    T_ASSERT(!s.ops->open(&s, &e));
    T_EQ(e.code, CAP_ERR_CREATE);
    T_CONTAINS(e.msg, "exists and is not a regular file");
    /* a parent that is a file */
    char file[600], below[700];
    snprintf(file, sizeof file, "%s/f", t_tmpdir());
    t_write(t_tmpdir(), "f", "x");
    snprintf(below, sizeof below, "%s/sub/o.y4m", file);
    T_ASSERTF(cap_sink_for(below, 64, 64, &s, &e), "%s", e.msg);
    T_ASSERT(!s.ops->open(&s, &e));
    T_EQ(e.code, CAP_ERR_CREATE);
    /* disk full: the frames are buffered, the failure shows when they are flushed */
    T_ASSERTF(cap_sink_for("/dev/full", 64, 64, &s, &e), "%s", e.msg);
    T_ASSERTF(s.ops->open(&s, &e), "%s", e.msg);
    static uint8_t frame[64 * 64 * 3 / 2];
    bool ok = true;
    for (uint64_t i = 0; ok && i < 400; i++) /* more than the 1 MiB buffer */
        ok = s.ops->write(&s, frame, i, &e);
    ok = s.ops->close(&s, ok, &e) && ok;
    T_ASSERT(!ok);
    T_EQ(e.code, CAP_ERR_WRITE);
    T_CONTAINS(e.msg, "/dev/full: write failed: No space left on device");
}

/* Every id has a text, and no two share one. */
static void t_error_ids_have_texts(void)
{
    T_EQ(RS_ERR_MODULE(CAP_ERR_BASE + 1), RS_ERR_MOD_CAP);
    T_EQ(RS_ERR_MODULE(CAP_ERR_END - 1), RS_ERR_MOD_CAP);
    T_ASSERT(!strcmp(rs_err_module_name(CAP_ERR_WRITE), "capture"));
    for (int a = CAP_ERR_BASE + 1; a < CAP_ERR_END; a++) {
        const char *t = cap_error_text(a);
        T_ASSERTF(t[0] && strcmp(t, "?") && strcmp(t, "ok"), "id %d has no text", a);
        for (int b = CAP_ERR_BASE + 1; b < a; b++)
            T_ASSERTF(strcmp(t, cap_error_text(b)), "ids %d and %d share the text \"%s\"", b, a, t);
    }
    T_ASSERT(!strcmp(cap_error_text(CAP_ERR_END), "?"));
    /* join's 'bad INDEX REASON' words come from the ids' names */
    T_ASSERT(!strcmp(cap_error_name(CAP_ERR_SEG_KEY), "SEG_KEY"));
    T_ASSERT(!strcmp(cap_error_name(CAP_ERR_SEG_HASHES), "SEG_HASHES"));
    T_ASSERT(!strcmp(cap_error_name(CAP_ERR_END), "?"));
}

/* The names a segment's files go by (join finds them by these rules). */
static void t_segment_names(void)
{
    char p[64];
    cap_seg_hashes_path("out/.job4/s2.mp4", p, sizeof p);
    T_ASSERT(!strcmp(p, "out/.job4/s2.hashes"));
    cap_seg_hashes_path("a.dir/seg", p, sizeof p); /* a dot in a directory is no extension */
    T_ASSERT(!strcmp(p, "a.dir/seg.hashes"));
    cap_seg_manifest_path("out/s2.webm", p, sizeof p);
    T_ASSERT(!strcmp(p, "out/s2.webm.seg"));
    T_ASSERT(!strcmp(cap_seg_format_of("x/s.mkv"), "mkv") && !strcmp(cap_seg_format_of("s.webm"), "webm"));
    T_ASSERT(!cap_seg_format_of("s.y4m") && !cap_seg_format_of("mp4") && !cap_seg_format_of("a.mp4/s"));
    T_ASSERT(cap_seg_key_ok("job42-a3") && cap_seg_key_ok("j:1.2_x") &&
             cap_seg_key_ok("aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa"));
    T_ASSERT(!cap_seg_key_ok("") && !cap_seg_key_ok("a b") && !cap_seg_key_ok("a/b") && !cap_seg_key_ok("k\n") &&
             !cap_seg_key_ok("aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa"));
}

/* A segment's hash list is exactly what the render writes ("%llu %016llx"):
 * tick numbers with a leading zero once passed (found by fuzz_seg). */
static void t_segment_hash_list(void)
{
    static const char good[] = "128 0123456789abcdef\n129 fedcba9876543210\n";
    uint64_t fnv = 0;
    rs_err e = {0};
    T_ASSERTF(cap_seg_hashes_parse(good, strlen(good), "s.hashes", 128, 130, &fnv, &e), "%s", e.msg);
    T_EQ(fnv, rs_fnv1a64(good, strlen(good)));
    static const char *const bad[] = {
        "0128 0123456789abcdef\n129 fedcba9876543210\n", /* a leading zero */
        "128 0123456789ABCDEF\n129 fedcba9876543210\n", /* upper-case hex */
        "+128 0123456789abcdef\n129 fedcba9876543210\n",
        "128 0123456789abcdef\n129 fedcba9876543210",     /* no last newline */
        "128 0123456789abcdef\n",                         /* a line short */
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        rs_err_clear(&e);
        T_ASSERTF(!cap_seg_hashes_parse(bad[i], strlen(bad[i]), "s.hashes", 128, 130, &fnv, &e), "accepted: %s",
                  bad[i]);
        T_EQ(e.code, CAP_ERR_SEG_HASHES);
        T_ASSERTF(!strncmp(e.msg, "s.hashes: ", 10), "%s", e.msg);
    }
    T_ASSERT(cap_seg_hashes_parse("0 0123456789abcdef\n", 19, "s.hashes", 0, 1, &fnv, &e)); /* "0" is no leading zero */
}

/* A test picture in a texture: gradients and hard edges; `shift` moves
 * the checkerboard so every frame differs. */
static GLuint test_texture(int w, int h, uint8_t *px, int shift)
{
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            uint8_t *p = px + ((size_t)y * w + x) * 4;
            p[0] = (uint8_t)(x * 255 / (w - 1));
            p[1] = (uint8_t)(y * 255 / (h - 1));
            p[2] = ((x + shift) / 16 + y / 16) % 2 ? 220 : 30;
            p[3] = 255;
        }
    GLuint t;
    gl.GenTextures(1, &t);
    gl.BindTexture(GL_TEXTURE_2D, t);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, px);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    return t;
}

/* Captures one texture through cap into an in-memory frame. */
#define GRAB_FRAMES 7
typedef struct grab {
    uint8_t frame[GRAB_FRAMES][160 * 90 * 3 / 2];
    int n;
} grab;
static bool g_open(cap_sink *s, rs_err *e)
{
    (void)s, (void)e;
    return true;
}
static bool g_write(cap_sink *s, const uint8_t *frame, uint64_t index, rs_err *e)
{
    grab *g = s->impl;
    if ((int)index != g->n || g->n >= GRAB_FRAMES)
        return rs_fail(e, 1, "frame %llu arrived as number %d", (unsigned long long)index, g->n);
    memcpy(g->frame[g->n++], frame, sizeof g->frame[0]);
    return true;
}
static bool g_close(cap_sink *s, bool ok, rs_err *e)
{
    (void)s, (void)e;
    return ok;
}
static const cap_sink_ops grab_ops = {"grab", g_open, g_write, g_close};

/* glReadPixels calls, counted through the gl table */
static PFNGLREADPIXELSPROC real_read_pixels;
static int read_calls;
static void APIENTRY counting_read_pixels(GLint x, GLint y, GLsizei w, GLsizei h, GLenum f, GLenum t, void *d)
{
    read_calls++;
    real_read_pixels(x, y, w, h, f, t, d);
}

/* Captures GRAB_FRAMES distinct pictures, in order, with one glReadPixels
 * a frame whatever the path: NVIDIA's driver spent 17-20 ms of CPU a frame
 * when the planes came back in three reads into one PBO (docs/capture.md). */
static void capture_all(const GLuint *tex, int src_w, int src_h, cap_mode mode, cap_downscale ds, int pbo, grab *g)
{
    cap_sink s = {.ops = &grab_ops, .impl = g, .w = 160, .h = 90, .fmt = CAP_I420};
    rs_err e = {0};
    cap *c = cap_open(&(cap_desc){.src_w = src_w, .src_h = src_h, .w = 160, .h = 90, .mode = mode, .downscale = ds,
                                  .pbo = pbo},
                      &s, &e);
    T_ASSERTF(c, "%s", e.msg);
    real_read_pixels = gl.ReadPixels;
    gl.ReadPixels = counting_read_pixels;
    read_calls = 0;
    for (int i = 0; i < GRAB_FRAMES; i++)
        T_ASSERT(cap_frame(c, tex[i], &e));
    cap_stats st;
    T_ASSERTF(cap_close(c, true, &st, &e), "%s", e.msg);
    gl.ReadPixels = real_read_pixels;
    T_ASSERTF(read_calls == GRAB_FRAMES, "%d glReadPixels calls for %d frames (mode %d, downscale %d, ring %d)", read_calls,
              GRAB_FRAMES, (int)mode, (int)ds, pbo);
    T_EQ(st.frames, GRAB_FRAMES);
    T_EQ(g->n, GRAB_FRAMES);
}

static double psnr(const uint8_t *a, const uint8_t *b, size_t n)
{
    double se = 0;
    for (size_t i = 0; i < n; i++)
        se += (double)(a[i] - b[i]) * (a[i] - b[i]);
    return se == 0 ? 99.0 : 10 * log10(255.0 * 255.0 * n / se);
}

/* The I420 frame a w x h RGBA picture (GL rows, bottom up) should make,
 * unrounded, from the standard and not from capture/: BT.709's Kr 0.2126
 * and Kb 0.0722, E'Y = Kr R + (1 - Kr - Kb) G + Kb B, E'Cb = (B - E'Y) /
 * (2 (1 - Kb)), E'Cr = (R - E'Y) / (2 (1 - Kr)), limited range Y = 16 +
 * 219 E'Y, C = 128 + 224 E'C; chroma from the mean of each 2x2 block (sited
 * at the centre, as the capture documents). */
static void bt709_reference(const uint8_t *px, int w, int h, double *out)
{
    const double kr = 0.2126, kb = 0.0722;
    double *cb = out + (size_t)w * h, *cr = cb + (size_t)(w / 2) * (h / 2);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const uint8_t *p = px + ((size_t)(h - 1 - y) * w + x) * 4; /* frame rows top down */
            out[(size_t)y * w + x] = 16 + 219 * (kr * p[0] + (1 - kr - kb) * p[1] + kb * p[2]) / 255;
        }
    for (int y = 0; y < h / 2; y++)
        for (int x = 0; x < w / 2; x++) {
            double rgb[3] = {0, 0, 0};
            for (int k = 0; k < 4; k++) {
                const uint8_t *p = px + ((size_t)(h - 1 - (2 * y + k / 2)) * w + 2 * x + k % 2) * 4;
                for (int c = 0; c < 3; c++)
                    rgb[c] += p[c] / (4 * 255.0);
            }
            double l = kr * rgb[0] + (1 - kr - kb) * rgb[1] + kb * rgb[2];
            cb[(size_t)y * (w / 2) + x] = 128 + 224 * (rgb[2] - l) / (2 * (1 - kb));
            cr[(size_t)y * (w / 2) + x] = 128 + 224 * (rgb[0] - l) / (2 * (1 - kr));
        }
}

/* Every sample is the reference rounded, but those within 0.01 of a
 * rounding tie (float arithmetic may go either way there): a conversion
 * constant off by 0.002 moves samples by up to 0.4 LSB and shows as
 * hundreds of differences. */
static void check_bt709(const uint8_t *frame, const double *ref, size_t n, const char *what, int index)
{
    size_t bad = 0, first = n, ties = 0;
    for (size_t k = 0; k < n; k++) {
        double f = ref[k] - floor(ref[k]);
        if (fabs(f - 0.5) < 0.01) {
            ties++;
            T_ASSERTF(abs(frame[k] - (int)floor(ref[k])) <= 1, "%s frame %d sample %zu: %u, reference %.4f", what, index, k,
                      frame[k], ref[k]);
        } else if (frame[k] != (int)floor(ref[k] + 0.5)) {
            bad++;
            first = k < first ? k : first;
        }
    }
    T_ASSERTF(bad == 0, "%s frame %d: %zu of %zu samples are not BT.709 rounded, the first sample %zu: %u, reference %.4f",
              what, index, bad, n, first, first < n ? frame[first] : 0, first < n ? ref[first] : 0);
    T_ASSERTF(ties * 20 < n, "%s frame %d: %zu of %zu samples near a tie", what, index, ties, n);
}

/* sw x sh frames (320x180: a 2x downscale; 160x90: the output's size,
 * where the conversion reads the frame itself) through every path */
static void gpu_vs_cpu(const char *backend, int sw, int sh)
{
    plat *p = t_context(backend);
    static uint8_t px[GRAB_FRAMES][320 * 180 * 4];
    GLuint tex[GRAB_FRAMES];
    for (int i = 0; i < GRAB_FRAMES; i++)
        tex[i] = test_texture(sw, sh, px[i], 5 * i);
    static grab gpu_async, gpu_seq, cpu_seq, pbo1, pbo3, pbo8;
    memset(&gpu_async, 0, sizeof gpu_async);
    capture_all(tex, sw, sh, CAP_ASYNC, CAP_DS_GPU, 2, &gpu_async);
    capture_all(tex, sw, sh, CAP_SEQUENTIAL, CAP_DS_GPU, 0, &gpu_seq);
    capture_all(tex, sw, sh, CAP_SEQUENTIAL, CAP_DS_CPU, 0, &cpu_seq);
    capture_all(tex, sw, sh, CAP_ASYNC, CAP_DS_GPU, 1, &pbo1);
    capture_all(tex, sw, sh, CAP_ASYNC, CAP_DS_GPU, 3, &pbo3);
    capture_all(tex, sw, sh, CAP_ASYNC, CAP_DS_GPU, 8, &pbo8); /* a ring longer than the clip */
    size_t n = sizeof gpu_async.frame[0];
    for (int i = 0; i < GRAB_FRAMES; i++) {
        /* same downscale, same bytes, frame by frame, whatever the path or ring */
        T_ASSERTF(!memcmp(gpu_async.frame[i], gpu_seq.frame[i], n), "frame %d: async != sequential", i);
        T_ASSERTF(!memcmp(gpu_async.frame[i], pbo1.frame[i], n), "frame %d: ring 1 differs", i);
        T_ASSERTF(!memcmp(gpu_async.frame[i], pbo3.frame[i], n), "frame %d: ring 3 differs", i);
        T_ASSERTF(!memcmp(gpu_async.frame[i], pbo8.frame[i], n), "frame %d: ring 8 differs", i);
        if (i)
            T_ASSERTF(memcmp(gpu_async.frame[i], gpu_async.frame[i - 1], n), "frames %d and %d are equal", i - 1, i);
        /* GPU and CPU implement the same maths: only rounding may differ */
        double q = psnr(gpu_async.frame[i], cpu_seq.frame[i], n);
        T_ASSERTF(q > 50, "frame %d: GPU vs CPU conversion PSNR %.1f dB", i, q);
        if (sw == 160 && sh == 90) { /* the frame itself converted: each against the standard */
            static double ref[sizeof gpu_async.frame[0]];
            bt709_reference(px[i], sw, sh, ref);
            check_bt709(gpu_async.frame[i], ref, n, "GPU", i);
            check_bt709(cpu_seq.frame[i], ref, n, "CPU", i);
        }
    }
    /* orientation: the texture's GL row 0 (bottom) has green 0, the top 255 */
    uint8_t top_left_y = gpu_async.frame[0][0], bottom_left_y = gpu_async.frame[0][(size_t)89 * 160];
    T_ASSERTF(top_left_y > bottom_left_y + 60, "flipped? top-left Y %u, bottom-left Y %u", top_left_y, bottom_left_y);
    gl.DeleteTextures(GRAB_FRAMES, tex);
    plat_destroy(p);
}

static void t_gpu_matches_cpu_egl(void) { gpu_vs_cpu("egl", 320, 180); }
static void t_gpu_matches_cpu_osmesa(void) { gpu_vs_cpu("osmesa", 320, 180); }
static void t_gpu_matches_cpu_same_size(void) { gpu_vs_cpu("egl", 160, 90); }

T_MAIN({"queue_cap_holds", t_queue_cap_holds}, {"inline_queue", t_inline_queue},
       {"writer_error_reaches_the_game_thread", t_writer_error_reaches_the_game_thread},
       {"hash_is_fnv1a", t_hash_is_fnv1a}, {"cpu_yuv_known_colours", t_cpu_yuv_known_colours},
       {"cpu_downscale_averages_and_flips", t_cpu_downscale_averages_and_flips}, {"sizes", t_sizes},
       {"sink_errors", t_sink_errors}, {"error_ids_have_texts", t_error_ids_have_texts},
       {"segment_names", t_segment_names},
       {"segment_hash_list", t_segment_hash_list},
       {"gpu_matches_cpu_egl", t_gpu_matches_cpu_egl}, {"gpu_matches_cpu_osmesa", t_gpu_matches_cpu_osmesa},
       {"gpu_matches_cpu_same_size", t_gpu_matches_cpu_same_size})
