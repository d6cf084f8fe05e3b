/* runtime/util: errors, files, images. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../runtime/util/rs_err.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_hash.h"
#include "../runtime/util/rs_img.h"
#include "../runtime/util/rs_oiio.h"
#include "t.h"

static void t_err_one_line(void)
{
    rs_err e = {0};
    T_ASSERT(!rs_fail(&e, 3, "a\nb %d", 7));
    T_EQ(e.code, 3);
    T_ASSERT(strcmp(e.msg, "a b 7") == 0);
    rs_err_prefix(&e, "file.txt");
    T_ASSERT(strcmp(e.msg, "file.txt: a b 7") == 0);
    T_ASSERT(!rs_fail(NULL, 1, "no crash without an err"));
}

/* Module blocks: a code names its list; *_error_text bodies share one lookup. */
static void t_err_modules(void)
{
    T_ASSERT(!strcmp(rs_err_module_name(3), "local"));
    T_ASSERT(!strcmp(rs_err_module_name(RS_ERR_BASE(RS_ERR_MOD_RP) + 1), "replay"));
    T_ASSERT(!strcmp(rs_err_module_name(RS_ERR_BASE(RS_ERR_MOD_SVC) + 255), "service"));
    T_ASSERT(!strcmp(rs_err_module_name(RS_ERR_BASE(RS_ERR_MOD_COUNT)), "?"));
    T_ASSERT(!strcmp(rs_err_module_name(-1), "?"));
    static const char *const texts[] = {"first", "second"};
    int base = RS_ERR_BASE(RS_ERR_MOD_CAP);
    T_ASSERT(!strcmp(rs_err_text_of(0, RS_ERR_MOD_CAP, texts, 2), "ok"));
    T_ASSERT(!strcmp(rs_err_text_of(base, RS_ERR_MOD_CAP, texts, 2), "?"));
    T_ASSERT(!strcmp(rs_err_text_of(base + 1, RS_ERR_MOD_CAP, texts, 2), "first"));
    T_ASSERT(!strcmp(rs_err_text_of(base + 2, RS_ERR_MOD_CAP, texts, 2), "second"));
    T_ASSERT(!strcmp(rs_err_text_of(base + 3, RS_ERR_MOD_CAP, texts, 2), "?"));
    T_ASSERT(!strcmp(rs_err_text_of(base + 1, RS_ERR_MOD_MV, texts, 2), "?")); /* another module's code */
}

static void t_read_file_limits(void)
{
    const char *d = t_tmpdir();
    t_write(d, "f.txt", "hello");
    char p[512];
    snprintf(p, sizeof p, "%s/f.txt", d);
    size_t n = 0;
    rs_err e = {0};
    char *s = rs_read_file(p, 100, &n, &e);
    T_ASSERT(s && n == 5 && strcmp(s, "hello") == 0);
    free(s);
    T_ASSERT(!rs_read_file(p, 4, &n, &e));
    T_EQ(e.code, RS_FILE_ERR_TOO_BIG);
    T_CONTAINS(e.msg, "f.txt");
    snprintf(p, sizeof p, "%s/missing.txt", d);
    T_ASSERT(!rs_read_file(p, 100, &n, &e));
    T_EQ(e.code, RS_FILE_ERR_OPEN);
    T_CONTAINS(e.msg, "missing.txt: cannot open");
}

/* PNGs are read back by an independent decoder, FFmpeg's own (not libpng):
 * `ffmpeg -i f.png -f rawvideo -pix_fmt FMT -`; NULL when it fails or
 * gives other than n bytes. */
static uint8_t *ffmpeg_decode(const char *path, const char *pix_fmt, size_t n)
{
    if (system("command -v ffmpeg >/dev/null 2>&1") != 0)
        T_SKIP_INSTALL("no ffmpeg to read the PNG back (tools/deps.sh test)");
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "ffmpeg -v error -i '%s' -f rawvideo -pix_fmt %s - 2>/dev/null", path, pix_fmt);
    FILE *p = popen(cmd, "r");
    T_ASSERT(p);
    uint8_t *px = malloc(n + 1);
    size_t got = fread(px, 1, n + 1, p);
    int st = pclose(p);
    if (st != 0 || got != n) {
        free(px);
        return NULL;
    }
    return px;
}

/* grey, RGB and RGBA at odd sizes (301x251 RGBA is several zlib blocks),
 * noise and gradients, back to the same bytes */
static void t_png_roundtrip(void)
{
    static const struct {
        int w, h, ch;
        const char *pix_fmt;
    } cases[] = {{1, 1, 1, "gray"}, {17, 5, 1, "gray"}, {3, 7, 3, "rgb24"},
                 {301, 251, 3, "rgb24"}, {1, 9, 4, "rgba"}, {301, 251, 4, "rgba"}};
    srand(7);
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        int w = cases[c].w, h = cases[c].h, ch = cases[c].ch;
        size_t n = (size_t)w * h * ch;
        uint8_t *px = malloc(n);
        for (size_t i = 0; i < n; i++) /* left half noise, right half a ramp */
            px[i] = (int)(i / ch % w) < w / 2 ? (uint8_t)rand() : (uint8_t)(i * 3 + c);
        char path[512];
        snprintf(path, sizeof path, "%s/a%zu.png", t_tmpdir(), c);
        rs_err e = {0};
        T_ASSERTF(rs_png_write(path, w, h, ch, px, &e), "%s", e.msg);
        uint8_t *back = ffmpeg_decode(path, cases[c].pix_fmt, n);
        T_ASSERTF(back, "%s: ffmpeg could not read %dx%d with %d channels back", path, w, h, ch);
        for (size_t i = 0; i < n; i++)
            T_ASSERTF(back[i] == px[i], "%dx%d, %d channels: byte %zu (pixel %zu,%zu) is %u, wrote %u", w, h, ch, i,
                      i / ch % w, i / ch / w, back[i], px[i]);
        char part[600];
        snprintf(part, sizeof part, "%s.part", path);
        T_ASSERT(access(part, F_OK) != 0);
        free(back);
        free(px);
    }
}

/* A smooth 1280x720 picture (the smoke test's kind) is compressed: far
 * below its 2.76 MB of raw RGB.  Unfiltered rows (rs_img.c says why) keep
 * a gradient at about a sixth; stored blocks were larger than raw. */
static void t_png_compressed(void)
{
    int w = 1280, h = 720;
    uint8_t *px = malloc((size_t)w * h * 3);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            uint8_t *p = px + ((size_t)y * w + x) * 3;
            p[0] = (uint8_t)(x * 255 / (w - 1));
            p[1] = (uint8_t)(y * 255 / (h - 1));
            p[2] = (uint8_t)((x + y) / 8);
        }
    char path[512];
    snprintf(path, sizeof path, "%s/smooth.png", t_tmpdir());
    rs_err e = {0};
    T_ASSERTF(rs_png_write(path, w, h, 3, px, &e), "%s", e.msg);
    struct stat st;
    T_ASSERT(stat(path, &st) == 0);
    size_t raw = (size_t)w * h * 3;
    T_ASSERTF((size_t)st.st_size * 5 < raw, "%s: %lld bytes for %zu raw: not compressed", path,
              (long long)st.st_size, raw);
    free(px);
}

static void t_png_failure_leaves_nothing(void)
{
    uint8_t px[16 * 16 * 3] = {0};
    char path[512];
    snprintf(path, sizeof path, "%s/no/such/dir/a.png", t_tmpdir());
    rs_err e = {0};
    T_ASSERT(!rs_png_write(path, 16, 16, 3, px, &e));
    T_CONTAINS(e.msg, "a.png: cannot create (as ");
    T_CONTAINS(e.msg, "a.png.part): No such file or directory");
    T_ASSERT(access(path, F_OK) != 0);
    T_ASSERT(!rs_png_write("/dev/full/x.png", 0, 16, 3, px, &e));
    T_CONTAINS(e.msg, "cannot write a 0x16 image");
}

static void t_png_disk_full(void)
{
    /* a file size limit makes the write itself fail half way (as a full
     * disk does): an error naming the file, and no .part left behind */
    signal(SIGXFSZ, SIG_IGN);
    struct rlimit old, rl;
    T_ASSERT(getrlimit(RLIMIT_FSIZE, &old) == 0);
    rl = (struct rlimit){4096, old.rlim_max}; /* soft only: it can be raised back */
    T_ASSERT(setrlimit(RLIMIT_FSIZE, &rl) == 0);
    static uint8_t px[256 * 256 * 3];
    for (size_t i = 0; i < sizeof px; i++) /* noise: compressed, still well over the 4 KB limit */
        px[i] = (uint8_t)rand();
    char path[512], part[600];
    snprintf(path, sizeof path, "%s/big.png", t_tmpdir());
    snprintf(part, sizeof part, "%s.part", path);
    rs_err e = {0};
    T_ASSERT(!rs_png_write(path, 256, 256, 3, px, &e));
    T_CONTAINS(e.msg, "big.png: write failed: File too large");
    T_ASSERT(access(path, F_OK) != 0 && access(part, F_OK) != 0);
    T_ASSERT(!rs_pnm_write(path, 256, 256, 3, px, &e)); /* wrong extension for PPM */
    snprintf(path, sizeof path, "%s/big.ppm", t_tmpdir());
    T_ASSERT(!rs_pnm_write(path, 256, 256, 3, px, &e));
    T_CONTAINS(e.msg, "big.ppm: write failed: File too large");
    T_ASSERT(setrlimit(RLIMIT_FSIZE, &old) == 0);
}

static void t_pnm_roundtrip(void)
{
    uint8_t px[5 * 3 * 3];
    for (int i = 0; i < (int)sizeof px; i++)
        px[i] = (uint8_t)(i * 7);
    char path[512];
    snprintf(path, sizeof path, "%s/a.ppm", t_tmpdir());
    rs_err e = {0};
    T_ASSERT(rs_image_write(path, 5, 3, 3, px, &e));
    rs_image img;
    T_ASSERTF(rs_pnm_read(path, &img, &e), "%s", e.msg);
    T_EQ(img.w, 5);
    T_EQ(img.h, 3);
    T_EQ(img.channels, 3);
    T_ASSERT(!memcmp(img.px, px, sizeof px));
    rs_image_free(&img);
}

static void t_pnm_bad_input(void)
{
    const char *d = t_tmpdir();
    static const struct {
        const char *name, *text, *want;
    } cases[] = {
        {"magic.ppm", "P3\n1 1\n255\n", "expected P5 or P6"},
        {"hdr.ppm", "P6\n1\n", "bad header"},
        {"huge.ppm", "P6\n99999 99999\n255\n", "unsupported size"},
        {"maxv.ppm", "P6\n1 1\n65535\n", "maxval"},
        {"short.ppm", "P6\n# comment\n4 4\n255\nabc", "truncated"},
        {"empty.ppm", "", "expected P5 or P6"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        t_write(d, cases[i].name, cases[i].text);
        char p[512];
        snprintf(p, sizeof p, "%s/%s", d, cases[i].name);
        rs_image img;
        rs_err e = {0};
        T_ASSERTF(!rs_pnm_read(p, &img, &e), "%s accepted", cases[i].name);
        T_CONTAINS(e.msg, cases[i].name);
        T_CONTAINS(e.msg, cases[i].want);
        T_ASSERT(img.px == NULL);
    }
}

static void t_pnm_random_corruption(void)
{
    /* a valid header with random bytes flipped must never crash or accept
     * more pixels than the file holds */
    const char *d = t_tmpdir();
    char good[64];
    int hl = snprintf(good, sizeof good, "P6\n4 3\n255\n");
    uint8_t buf[128];
    memcpy(buf, good, (size_t)hl);
    srand(1234);
    for (int iter = 0; iter < 300; iter++) {
        size_t n = (size_t)hl + 36;
        for (size_t i = (size_t)hl; i < n; i++)
            buf[i] = (uint8_t)rand();
        memcpy(buf, good, (size_t)hl);
        for (int k = 0; k < 3; k++)
            buf[rand() % hl] = (uint8_t)rand();
        n = (size_t)(rand() % (int)n) + 1;
        char p[512];
        snprintf(p, sizeof p, "%s/r.ppm", d);
        FILE *f = fopen(p, "wb");
        fwrite(buf, 1, n, f);
        fclose(f);
        rs_image img;
        rs_err e = {0};
        if (rs_pnm_read(p, &img, &e)) {
            T_ASSERT(img.w > 0 && img.h > 0 && (size_t)img.w * img.h * img.channels <= n);
            rs_image_free(&img);
        } else {
            T_ASSERT(e.msg[0] && img.px == NULL);
        }
    }
}

static void t_flip_rows(void)
{
    uint8_t px[3 * 2 * 1] = {1, 2, 3, 4, 5, 6};
    rs_flip_rows(px, 2, 3, 1);
    const uint8_t want[] = {5, 6, 3, 4, 1, 2};
    T_ASSERT(!memcmp(px, want, sizeof want));
}

/* The frame hash's values are stored in every --hashes list: they must not move. */
static void t_hash_vectors(void)
{
    T_EQ(rs_fnv1a64("", 0), 0xcbf29ce484222325ull);
    T_EQ(rs_fnv1a64("a", 1), 0xaf63dc4c8601ec8cull);
    T_EQ(rs_fnv1a64("foobar", 6), 0x85944171f73967e8ull);
    T_EQ(rs_crc32(0, "", 0), 0u);
    T_EQ(rs_crc32(0, "123456789", 9), 0xcbf43926u);
    /* continued in two pieces, the same as in one */
    T_EQ(rs_crc32(rs_crc32(0, "1234", 4), "56789", 5), 0xcbf43926u);
}

/* OpenImageIO's failures come back as rs_err ids naming the file. */
static void t_oiio_errors(void)
{
    rs_err err = {0};
    int w = 0, h = 0;
    float *px = (float *)&w; /* must be reset to NULL */
    T_ASSERT(!rs_oiio_read_float("/nonexistent/env.exr", &w, &h, &px, &err));
    T_ASSERT(px == NULL);
    T_ASSERT(err.code == RS_OIIO_ERR_READ || err.code == RS_OIIO_ERR_NOT_BUILT);
    T_ASSERT(strstr(err.msg, "/nonexistent/env.exr") != NULL);
    T_ASSERT(!strchr(err.msg, '\n'));
    T_ASSERT(!strcmp(rs_oiio_error_text(RS_OIIO_ERR_OK), "ok"));
    T_ASSERT(!strcmp(rs_oiio_error_text(RS_OIIO_ERR_COUNT), "unknown OpenImageIO error"));
}

/* The runner's two kinds of skip, driven by tests/test_harness.sh:
 * T_SKIP_PROBE=env or =install makes this case skip with that kind;
 * without it the case passes. */
static void t_harness_skip_probe(void)
{
    const char *k = getenv("T_SKIP_PROBE");
    if (k && !strcmp(k, "env"))
        T_SKIP_ENV("probe: the machine has no such thing");
    if (k && !strcmp(k, "install"))
        T_SKIP_INSTALL("probe: a tool is not installed");
}

T_MAIN({"err_one_line", t_err_one_line}, {"err_modules", t_err_modules},
       {"read_file_limits", t_read_file_limits},
       {"png_roundtrip", t_png_roundtrip}, {"png_compressed", t_png_compressed},
       {"png_failure_leaves_nothing", t_png_failure_leaves_nothing},
       {"png_disk_full", t_png_disk_full},
       {"pnm_roundtrip", t_pnm_roundtrip}, {"pnm_bad_input", t_pnm_bad_input},
       {"pnm_random_corruption", t_pnm_random_corruption}, {"flip_rows", t_flip_rows},
       {"hash_vectors", t_hash_vectors}, {"oiio_errors", t_oiio_errors},
       {"harness_skip_probe", t_harness_skip_probe})
