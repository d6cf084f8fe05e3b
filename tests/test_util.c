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

/* An independent PNG reader for stored-deflate files: bitwise CRC, chunk
 * walk, stored blocks, Adler-32.  Returns the raw (filtered) scanlines. */
static uint32_t crc_bitwise(const uint8_t *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1)));
    }
    return ~c;
}

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static uint8_t *png_decode_stored(const uint8_t *f, size_t n, int *w, int *h, int *ctype, size_t *rawn)
{
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    T_ASSERT(n > 8 && memcmp(f, sig, 8) == 0);
    size_t o = 8;
    uint8_t *z = NULL;
    size_t zn = 0;
    bool end = false;
    while (o + 12 <= n && !end) {
        uint32_t len = rd32(f + o);
        T_ASSERT(o + 12 + len <= n);
        T_ASSERTF(crc_bitwise(f + o + 4, len + 4) == rd32(f + o + 8 + len), "bad CRC in chunk %.4s", f + o + 4);
        if (!memcmp(f + o + 4, "IHDR", 4)) {
            *w = (int)rd32(f + o + 8);
            *h = (int)rd32(f + o + 12);
            T_EQ(f[o + 16], 8);
            *ctype = f[o + 17];
        } else if (!memcmp(f + o + 4, "IDAT", 4)) {
            z = realloc(z, zn + len);
            memcpy(z + zn, f + o + 8, len);
            zn += len;
        } else if (!memcmp(f + o + 4, "IEND", 4)) {
            end = true;
        }
        o += 12 + len;
    }
    T_ASSERT(end && z && zn >= 6);
    T_ASSERT(((z[0] << 8) | z[1]) % 31 == 0 && (z[0] & 15) == 8);
    uint8_t *raw = malloc(zn);
    size_t rn = 0, zo = 2;
    for (;;) {
        uint8_t hdr = z[zo];
        T_ASSERTF((hdr & 6) == 0, "not a stored block");
        unsigned len = z[zo + 1] | z[zo + 2] << 8, nlen = z[zo + 3] | z[zo + 4] << 8;
        T_EQ(len ^ 0xffff, nlen);
        memcpy(raw + rn, z + zo + 5, len);
        rn += len;
        zo += 5 + len;
        if (hdr & 1)
            break;
    }
    uint32_t a = 1, b = 0;
    for (size_t i = 0; i < rn; i++) {
        a = (a + raw[i]) % 65521;
        b = (b + a) % 65521;
    }
    T_EQ(rd32(z + zo), (b << 16) | a);
    free(z);
    *rawn = rn;
    return raw;
}

static void t_png_roundtrip(void)
{
    /* 300x250 RGBA is > 65535 bytes: several stored blocks */
    int w = 300, h = 250;
    uint8_t *px = malloc((size_t)w * h * 4);
    srand(7);
    for (int i = 0; i < w * h * 4; i++)
        px[i] = (uint8_t)rand();
    char path[512];
    snprintf(path, sizeof path, "%s/a.png", t_tmpdir());
    rs_err e = {0};
    T_ASSERTF(rs_png_write(path, w, h, 4, px, &e), "%s", e.msg);
    size_t n;
    uint8_t *f = (uint8_t *)rs_read_file(path, 1 << 24, &n, &e);
    T_ASSERT(f);
    int gw = 0, gh = 0, ct = 0;
    size_t rn;
    uint8_t *raw = png_decode_stored(f, n, &gw, &gh, &ct, &rn);
    T_EQ(gw, w);
    T_EQ(gh, h);
    T_EQ(ct, 6);
    T_EQ(rn, (size_t)h * (w * 4 + 1));
    for (int y = 0; y < h; y++) {
        T_EQ(raw[y * (w * 4 + 1)], 0);
        T_ASSERTF(!memcmp(raw + y * (w * 4 + 1) + 1, px + y * w * 4, w * 4), "row %d differs", y);
    }
    struct stat st;
    char part[600];
    snprintf(part, sizeof part, "%s.part", path);
    T_ASSERT(stat(part, &st) != 0);
    free(raw);
    free(f);
    free(px);
}

static void t_png_failure_leaves_nothing(void)
{
    uint8_t px[16 * 16 * 3] = {0};
    char path[512];
    snprintf(path, sizeof path, "%s/no/such/dir/a.png", t_tmpdir());
    rs_err e = {0};
    T_ASSERT(!rs_png_write(path, 16, 16, 3, px, &e));
    T_CONTAINS(e.msg, "a.png.part: cannot create");
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

T_MAIN({"err_one_line", t_err_one_line}, {"err_modules", t_err_modules},
       {"read_file_limits", t_read_file_limits},
       {"png_roundtrip", t_png_roundtrip}, {"png_failure_leaves_nothing", t_png_failure_leaves_nothing},
       {"png_disk_full", t_png_disk_full},
       {"pnm_roundtrip", t_pnm_roundtrip}, {"pnm_bad_input", t_pnm_bad_input},
       {"pnm_random_corruption", t_pnm_random_corruption}, {"flip_rows", t_flip_rows},
       {"hash_vectors", t_hash_vectors}, {"oiio_errors", t_oiio_errors})
