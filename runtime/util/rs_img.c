#include "rs_img.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rs_file.h"
#include "rs_hash.h"

/* Largest image we accept from a file: 16384 x 16384 x 4. */
#define RS_IMG_MAX_DIM 16384

static void be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

/* Appends one chunk (length, type, data, CRC) at out; returns its size. */
static size_t png_chunk(uint8_t *out, const char *type, const uint8_t *data, uint32_t n)
{
    be32(out, n);
    memcpy(out + 4, type, 4);
    if (n)
        memcpy(out + 8, data, n);
    be32(out + 8 + n, rs_crc32(0, out + 4, (size_t)n + 4));
    return (size_t)n + 12;
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
    /* zlib stream of stored blocks: each row is a filter byte (0) + pixels */
    size_t row = (size_t)w * channels + 1, raw = row * h;
    size_t nblocks = (raw + 65534) / 65535;
    size_t zlen = 2 + raw + nblocks * 5 + 4;
    if (zlen > 0x7fffffffu)
        return rs_fail(err, RS_IMG_ERR_ARG, "%s: image too large for one PNG chunk", path);
    uint8_t *z = malloc(zlen), *rawbuf = malloc(raw);
    if (!z || !rawbuf) {
        free(z);
        free(rawbuf);
        return rs_fail(err, RS_IMG_ERR_IO, "%s: out of memory", path);
    }
    for (int y = 0; y < h; y++) {
        rawbuf[y * row] = 0;
        memcpy(rawbuf + y * row + 1, px + (size_t)y * w * channels, row - 1);
    }
    size_t o = 0;
    z[o++] = 0x78; /* deflate, 32K window */
    z[o++] = 0x01; /* no preset dictionary, fastest; (0x7801 % 31 == 0) */
    uint32_t a = 1, b = 0;
    for (size_t off = 0; off < raw || (raw == 0 && off == 0);) {
        size_t n = raw - off > 65535 ? 65535 : raw - off;
        z[o++] = off + n == raw ? 1 : 0; /* BFINAL, BTYPE=00 */
        z[o++] = (uint8_t)n;
        z[o++] = (uint8_t)(n >> 8);
        z[o++] = (uint8_t)~n;
        z[o++] = (uint8_t)(~n >> 8);
        memcpy(z + o, rawbuf + off, n);
        for (size_t i = 0; i < n; i++) {
            a = (a + rawbuf[off + i]) % 65521;
            b = (b + a) % 65521;
        }
        o += n;
        off += n;
        if (n == 0)
            break;
    }
    be32(z + o, (b << 16) | a);
    o += 4;
    free(rawbuf);

    static const uint8_t colour_type[5] = {0, 0, 0, 2, 6};
    uint8_t ihdr[13];
    be32(ihdr, (uint32_t)w);
    be32(ihdr + 4, (uint32_t)h);
    ihdr[8] = 8;
    ihdr[9] = colour_type[channels];
    ihdr[10] = ihdr[11] = ihdr[12] = 0;

    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    size_t n = 8 + (12 + 13) + (12 + o) + 12;
    uint8_t *file = malloc(n);
    if (!file) {
        free(z);
        return rs_fail(err, RS_IMG_ERR_IO, "%s: out of memory", path);
    }
    memcpy(file, sig, 8);
    size_t at = 8;
    at += png_chunk(file + at, "IHDR", ihdr, 13);
    at += png_chunk(file + at, "IDAT", z, (uint32_t)o);
    at += png_chunk(file + at, "IEND", NULL, 0);
    free(z);
    bool ok = rs_write_part(path, file, at, err) && rs_commit_file(path, err);
    free(file);
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
