/* Image files: PNG through libpng, binary PPM/PGM by hand (see rs_img.h). */
#include "rs_img.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <png.h>

#include "rs_file.h"

/* Largest image we accept from a file: 16384 x 16384 x 4. */
#define RS_IMG_MAX_DIM 16384

/* DESIGN: PNG through libpng at zlib level RS_PNG_LEVEL with no row filter.
 * Measured on 1280x720 RGBA frames (libpng 1.6.39, development machine): a
 * dithered game frame is 216 KB in 29 ms unfiltered at level 6, but 260 KB
 * in 76 ms with libpng's adaptive filters, which turn the dither into
 * noise; level 9 saves 4% more for twice the time, level 2 costs 46% more
 * bytes.  The smooth smoke picture is 104 KB unfiltered (6 KB filtered):
 * both far below the 3.69 MB of the stored blocks written before.  The file
 * is encoded in memory and written through rs_write_part, so a failed
 * write never leaves a file that looks finished. */
typedef struct png_mem {
    uint8_t *p;
    size_t n, cap;
    char why[160];
} png_mem;

static void png_mem_write(png_structp s, png_bytep data, size_t n)
{
    png_mem *m = png_get_io_ptr(s);
    if (n > m->cap - m->n) {
        size_t cap = m->cap ? m->cap : 1 << 16;
        while (cap - m->n < n)
            cap *= 2;
        uint8_t *p = realloc(m->p, cap);
        if (!p)
            png_error(s, "out of memory");
        m->p = p;
        m->cap = cap;
    }
    memcpy(m->p + m->n, data, n);
    m->n += n;
}

static void png_mem_flush(png_structp s)
{
    (void)s;
}

static void png_on_error(png_structp s, png_const_charp msg)
{
    png_mem *m = png_get_error_ptr(s);
    snprintf(m->why, sizeof m->why, "%s", msg);
    png_longjmp(s, 1);
}

static void png_on_warning(png_structp s, png_const_charp msg)
{
    (void)s;
    (void)msg; /* libpng warns only about what it then handles itself */
}

/* rows: h pointers into the caller's pixels, made before setjmp so nothing
 * that setjmp's return path reads is changed after it */
static bool png_encode(png_mem *m, int w, int h, int channels, png_bytepp rows)
{
    static const int colour_type[5] = {0, PNG_COLOR_TYPE_GRAY, 0, PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGBA};
    png_structp s = png_create_write_struct(PNG_LIBPNG_VER_STRING, m, png_on_error, png_on_warning);
    png_infop info = s ? png_create_info_struct(s) : NULL;
    if (!info) {
        png_destroy_write_struct(&s, NULL);
        snprintf(m->why, sizeof m->why, "out of memory");
        return false;
    }
    if (setjmp(png_jmpbuf(s))) {
        png_destroy_write_struct(&s, &info);
        return false;
    }
    png_set_write_fn(s, m, png_mem_write, png_mem_flush);
    png_set_IHDR(s, info, (png_uint_32)w, (png_uint_32)h, 8, colour_type[channels], PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(s, RS_PNG_LEVEL);
    png_set_filter(s, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
    png_set_rows(s, info, rows);
    png_write_png(s, info, PNG_TRANSFORM_IDENTITY, NULL);
    png_destroy_write_struct(&s, &info);
    return true;
}

static bool check_args(const char *path, int w, int h, int channels, rs_err *err)
{
    if (w <= 0 || h <= 0 || w > RS_IMG_MAX_DIM || h > RS_IMG_MAX_DIM || channels < 1 || channels > 4 || channels == 2)
        return rs_fail(err, RS_IMG_ERR_ARG, "%s: cannot write a %dx%d image with %d channels", path, w, h, channels);
    return true;
}

bool rs_png_write(const char *path, int w, int h, int channels, const uint8_t *px, rs_err *err)
{
    if (!check_args(path, w, h, channels, err))
        return false;
    png_bytepp rows = malloc((size_t)h * sizeof *rows);
    if (!rows)
        return rs_fail(err, RS_IMG_ERR_IO, "%s: out of memory", path);
    for (int y = 0; y < h; y++)
        rows[y] = (png_bytep)px + (size_t)y * w * channels; /* libpng only reads them */
    png_mem m = {0};
    bool ok = png_encode(&m, w, h, channels, rows);
    free(rows);
    if (!ok)
        rs_fail(err, RS_IMG_ERR_IO, "%s: libpng: %s", path, m.why);
    else
        ok = rs_write_part(path, m.p, m.n, err) && rs_commit_file(path, err);
    free(m.p);
    return ok;
}

static bool ends_with(const char *s, const char *suf);

bool rs_pnm_write(const char *path, int w, int h, int channels, const uint8_t *px, rs_err *err)
{
    if (!check_args(path, w, h, channels, err))
        return false;
    if (ends_with(path, ".pgm") != (channels == 1))
        return rs_fail(err, RS_IMG_ERR_ARG, "%s: %s", path,
                       channels == 1 ? "a grey image is written as .pgm" : "a colour image is written as .ppm or .png");
    int out_ch = channels == 1 ? 1 : 3;
    char hdr[64];
    size_t hn = (size_t)snprintf(hdr, sizeof hdr, "P%d\n%d %d\n255\n", out_ch == 1 ? 5 : 6, w, h);
    size_t n = hn + (size_t)w * h * out_ch;
    uint8_t *file = malloc(n);
    if (!file)
        return rs_fail(err, RS_IMG_ERR_IO, "%s: out of memory", path);
    memcpy(file, hdr, hn);
    for (size_t i = 0; i < (size_t)w * h; i++)
        memcpy(file + hn + i * out_ch, px + i * channels, (size_t)out_ch);
    bool ok = rs_write_part(path, file, n, err) && rs_commit_file(path, err);
    free(file);
    return ok;
}

/* Reads the next header integer, skipping whitespace and # comments. */
static bool pnm_int(const uint8_t *d, size_t n, size_t *o, int *v)
{
    for (;;) {
        while (*o < n && (d[*o] == ' ' || d[*o] == '\t' || d[*o] == '\r' || d[*o] == '\n'))
            (*o)++;
        if (*o < n && d[*o] == '#') {
            while (*o < n && d[*o] != '\n')
                (*o)++;
            continue;
        }
        break;
    }
    long x = 0;
    size_t start = *o;
    while (*o < n && d[*o] >= '0' && d[*o] <= '9' && x <= 100000)
        x = x * 10 + (d[(*o)++] - '0');
    if (*o == start || x > 100000)
        return false;
    *v = (int)x;
    return true;
}

bool rs_pnm_read(const char *path, rs_image *img, rs_err *err)
{
    memset(img, 0, sizeof *img);
    size_t n;
    uint8_t *d = (uint8_t *)rs_read_file(path, (size_t)RS_IMG_MAX_DIM * RS_IMG_MAX_DIM * 3 + 64, &n, err);
    if (!d)
        return false;
    size_t o = 2;
    int w, h, maxv, ch;
    if (n < 2 || d[0] != 'P' || (d[1] != '5' && d[1] != '6')) {
        rs_fail(err, RS_IMG_ERR_FORMAT, "%s: not a binary PPM/PGM (expected P5 or P6 at byte 0)", path);
        goto fail;
    }
    ch = d[1] == '6' ? 3 : 1;
    if (!pnm_int(d, n, &o, &w) || !pnm_int(d, n, &o, &h) || !pnm_int(d, n, &o, &maxv)) {
        rs_fail(err, RS_IMG_ERR_FORMAT, "%s: bad header near byte %zu (expected width height maxval)", path, o);
        goto fail;
    }
    if (w <= 0 || h <= 0 || w > RS_IMG_MAX_DIM || h > RS_IMG_MAX_DIM || maxv != 255) {
        rs_fail(err, RS_IMG_ERR_FORMAT, "%s: unsupported size %dx%d or maxval %d (expected 1..%d, maxval 255)", path, w,
                h, maxv, RS_IMG_MAX_DIM);
        goto fail;
    }
    o++; /* the single whitespace byte after maxval */
    size_t need = (size_t)w * h * ch;
    if (o > n || n - o < need) {
        rs_fail(err, RS_IMG_ERR_FORMAT, "%s: truncated: %zu pixel bytes at offset %zu, expected %zu", path,
                o > n ? 0 : n - o, o, need);
        goto fail;
    }
    img->px = malloc(need);
    if (!img->px) {
        rs_fail(err, RS_IMG_ERR_IO, "%s: out of memory", path);
        goto fail;
    }
    memcpy(img->px, d + o, need);
    img->w = w;
    img->h = h;
    img->channels = ch;
    free(d);
    return true;
fail:
    free(d);
    return false;
}

static bool ends_with(const char *s, const char *suf)
{
    size_t a = strlen(s), b = strlen(suf);
    return a >= b && strcmp(s + a - b, suf) == 0;
}

bool rs_image_write(const char *path, int w, int h, int channels, const uint8_t *px, rs_err *err)
{
    if (ends_with(path, ".png"))
        return rs_png_write(path, w, h, channels, px, err);
    if (ends_with(path, ".ppm") || ends_with(path, ".pgm"))
        return rs_pnm_write(path, w, h, channels, px, err);
    return rs_fail(err, RS_IMG_ERR_ARG, "%s: unknown image extension (expected .png, .ppm or .pgm)", path);
}

void rs_image_free(rs_image *img)
{
    free(img->px);
    img->px = NULL;
}

void rs_flip_rows(uint8_t *px, int w, int h, int channels)
{
    size_t row = (size_t)w * channels;
    uint8_t tmp[4096];
    for (int y = 0; y < h / 2; y++) {
        uint8_t *a = px + y * row, *b = px + (size_t)(h - 1 - y) * row;
        for (size_t o = 0; o < row; o += sizeof tmp) {
            size_t k = row - o < sizeof tmp ? row - o : sizeof tmp;
            memcpy(tmp, a + o, k);
            memcpy(a + o, b + o, k);
            memcpy(b + o, tmp, k);
        }
    }
}
