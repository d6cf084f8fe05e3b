/* player/mv_y4m: the YUV4MPEG2 reader (no dependencies).
 *
 * A Y4M file is one header line, "YUV4MPEG2 " then space-separated tags,
 * each a letter and a value:
 *   W<int> H<int>     luma size (required; 1..16384 here)
 *   F<num>:<den>      frame rate (25:1 when absent, as mjpegtools does)
 *   I<p|t|b|m|?>      interlacing (only p and ? are played)
 *   A<num>:<den>      pixel aspect (0:0 is unknown, taken as 1:1)
 *   C<colorspace>     420jpeg (the default), 420, 420mpeg2, 420paldv, 422, 444, mono
 *   X<key>=<value>    extensions: XCOLORRANGE=FULL|LIMITED (FFmpeg) and our own
 *                     XCOLORMATRIX=BT601|BT709; other X tags are ignored
 * Unknown tag letters are ignored, as the format asks.  Then frames: "FRAME",
 * optional tags up to a newline, and the planes Y, Cb, Cr packed with no
 * padding.  That is the layout mv_src delivers, so a frame is one fread
 * straight into the destination, which may be mapped GPU memory.
 *
 * Errors name the file and number frames from 0, as --dump and --hashes do. */
#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "mv.h"

enum {
    HDR_MAX = 4096,       /* the header line, newline included */
    FRAME_HDR_MAX = 1024, /* a frame header line, newline included */
    DIM_MAX = 16384,
    SHOW_MAX = 40,        /* bytes of a bad value quoted in a message */
};

static const char MAGIC[] = "YUV4MPEG2 ";
enum { MAGIC_LEN = sizeof MAGIC - 1 };

typedef struct y4m_src {
    mv_src base; /* first, so (mv_src *) and (y4m_src *) casts work */
    FILE *f;
    rs_err failed; /* sticky: every read after an error repeats it */
} y4m_src;

/* A piece of the header: not NUL-terminated, may hold any byte. */
typedef struct span {
    const char *p;
    size_t n;
} span;

static span span_from(span s, size_t skip)
{
    return (span){s.p + skip, s.n - skip};
}

static bool span_is(span s, const char *lit)
{
    size_t n = strlen(lit);
    return s.n == n && memcmp(s.p, lit, n) == 0;
}

static char lower(char c)
{
    return c >= 'A' && c <= 'Z' ? (char)(c - 'A' + 'a') : c;
}

static bool span_is_nocase(span s, const char *lit)
{
    size_t n = strlen(lit);
    if (s.n != n)
        return false;
    for (size_t i = 0; i < n; i++)
        if (lower(s.p[i]) != lower(lit[i]))
            return false;
    return true;
}

static bool span_starts(span s, const char *lit)
{
    size_t n = strlen(lit);
    return s.n >= n && memcmp(s.p, lit, n) == 0;
}

static bool all_digits(span s)
{
    for (size_t i = 0; i < s.n; i++)
        if (s.p[i] < '0' || s.p[i] > '9')
            return false;
    return s.n > 0;
}

/* A printable copy for messages: at most SHOW_MAX bytes, odd bytes as '?'. */
static const char *show(span s, char out[SHOW_MAX + 4])
{
    size_t n = s.n < SHOW_MAX ? s.n : SHOW_MAX, o = 0;
    for (size_t i = 0; i < n; i++)
        out[o++] = s.p[i] >= 0x20 && s.p[i] < 0x7f && s.p[i] != '\'' ? s.p[i] : '?';
    if (n < s.n) {
        memcpy(out + o, "...", 3);
        o += 3;
    }
    out[o] = 0;
    return out;
}

/* Decimal digits only, no sign, value <= max; stops early on long runs. */
static bool parse_uint(span s, long max, long *out)
{
    if (!all_digits(s))
        return false;
    long v = 0;
    for (size_t i = 0; i < s.n; i++) {
        v = v * 10 + (s.p[i] - '0');
        if (v > max)
            return false;
    }
    *out = v;
    return true;
}

/* "<num>:<den>", each 0..INT_MAX. */
static bool parse_ratio(span s, int *num, int *den)
{
    const char *colon = memchr(s.p, ':', s.n);
    if (!colon)
        return false;
    size_t k = (size_t)(colon - s.p);
    long a, b;
    if (!parse_uint((span){s.p, k}, INT_MAX, &a) || !parse_uint(span_from(s, k + 1), INT_MAX, &b))
        return false;
    *num = (int)a;
    *den = (int)b;
    return true;
}

/* What the header said, on the way to an mv_info. */
typedef struct y4m_hdr {
    mv_info info;
    span cs; /* the C value; p is NULL when there was none */
    bool has_matrix;
} y4m_hdr;

static bool tag_dim(span v, char tag, int *out, rs_err *err)
{
    long x;
    char b[SHOW_MAX + 4];
    if (!parse_uint(v, DIM_MAX, &x) || x < 1)
        return rs_fail(err, MV_ERR_FORMAT, "bad %c value '%s' (want 1..%d)", tag, show(v, b), DIM_MAX);
    *out = (int)x;
    return true;
}

static bool tag_rate(span v, mv_info *i, rs_err *err)
{
    char b[SHOW_MAX + 4];
    if (!parse_ratio(v, &i->fps_num, &i->fps_den) || i->fps_num <= 0 || i->fps_den <= 0)
        return rs_fail(err, MV_ERR_FORMAT, "bad F value '%s' (want frame rate NUM:DEN, both > 0)", show(v, b));
    return true;
}

static bool tag_aspect(span v, mv_info *i, rs_err *err)
{
    char b[SHOW_MAX + 4];
    if (!parse_ratio(v, &i->sar_num, &i->sar_den))
        return rs_fail(err, MV_ERR_FORMAT, "bad A value '%s' (want pixel aspect NUM:DEN)", show(v, b));
    if (i->sar_num == 0 && i->sar_den == 0) { /* unknown */
        i->sar_num = i->sar_den = 1;
    } else if (i->sar_num == 0 || i->sar_den == 0) {
        return rs_fail(err, MV_ERR_FORMAT, "bad A value '%s' (want NUM:DEN both > 0, or 0:0)", show(v, b));
    }
    return true;
}

static bool tag_interlace(span v, rs_err *err)
{
    char b[SHOW_MAX + 4];
    if (span_is(v, "p") || span_is(v, "?"))
        return true;
    if (span_is(v, "t") || span_is(v, "b") || span_is(v, "m"))
        return rs_fail(err, MV_ERR_UNSUPPORTED, "interlaced video (I%s) is not supported: only progressive is played",
                       show(v, b));
    return rs_fail(err, MV_ERR_FORMAT, "bad I value '%s' (want p, t, b, m or ?)", show(v, b));
}

/* X<key>=<value>: the two we know; other extensions are ignored. */
static bool tag_ext(span v, y4m_hdr *h, rs_err *err)
{
    char b[SHOW_MAX + 4];
    if (span_starts(v, "COLORRANGE=")) {
        span r = span_from(v, strlen("COLORRANGE="));
        if (!span_is_nocase(r, "FULL") && !span_is_nocase(r, "LIMITED"))
            return rs_fail(err, MV_ERR_FORMAT, "bad XCOLORRANGE value '%s' (want FULL or LIMITED)", show(r, b));
        h->info.full_range = span_is_nocase(r, "FULL");
    } else if (span_starts(v, "COLORMATRIX=")) {
        span m = span_from(v, strlen("COLORMATRIX="));
        if (!span_is_nocase(m, "BT601") && !span_is_nocase(m, "BT709"))
            return rs_fail(err, MV_ERR_FORMAT, "bad XCOLORMATRIX value '%s' (want BT601 or BT709)", show(m, b));
        h->info.matrix = span_is_nocase(m, "BT709") ? MV_BT709 : MV_BT601;
        h->has_matrix = true;
    }
    return true;
}

static bool tag(span t, y4m_hdr *h, rs_err *err)
{
    span v = span_from(t, 1);
    switch (t.p[0]) {
    case 'W': return tag_dim(v, 'W', &h->info.w, err);
    case 'H': return tag_dim(v, 'H', &h->info.h, err);
    case 'F': return tag_rate(v, &h->info, err);
    case 'A': return tag_aspect(v, &h->info, err);
    case 'I': return tag_interlace(v, err);
    case 'C': h->cs = v; return true; /* checked once all tags are in */
    case 'X': return tag_ext(v, h, err);
    default: return true; /* unknown tags are ignored, as the format asks */
    }
}

static const struct colorspace {
    const char *name;
    int sx, sy, loc;
    bool mono;
} SPACES[] = {
    {"420jpeg", 1, 1, MV_CHROMA_CENTER, false},
    {"420", 1, 1, MV_CHROMA_CENTER, false},
    {"420mpeg2", 1, 1, MV_CHROMA_LEFT, false},
    {"420paldv", 1, 1, MV_CHROMA_TOPLEFT, false},
    {"422", 1, 0, MV_CHROMA_LEFT, false},
    {"444", 0, 0, MV_CHROMA_CENTER, false},
    {"mono", 0, 0, MV_CHROMA_CENTER, true},
};

/* Valid Y4M that we do not play: deeper samples (420p10, 444p16, mono16,
 * ...), alpha, and 4:1:1. */
static bool unplayed_space(span v)
{
    static const char *const bases[] = {"420p", "422p", "444p", "411p", "mono"};
    if (span_is(v, "444alpha") || span_is(v, "411"))
        return true;
    for (size_t i = 0; i < sizeof bases / sizeof bases[0]; i++)
        if (span_starts(v, bases[i]) && all_digits(span_from(v, strlen(bases[i]))))
            return true;
    return false;
}

static bool colorspace(y4m_hdr *h, rs_err *err)
{
    span v = h->cs.p ? h->cs : (span){"420jpeg", 7};
    char b[SHOW_MAX + 4];
    for (size_t i = 0; i < sizeof SPACES / sizeof SPACES[0]; i++) {
        const struct colorspace *c = &SPACES[i];
        if (span_is(v, c->name)) {
            h->info.sx = c->sx;
            h->info.sy = c->sy;
            h->info.chroma_loc = c->loc;
            h->info.mono = c->mono;
            snprintf(h->info.pixfmt, sizeof h->info.pixfmt, "%s", c->name);
            return true;
        }
    }
    if (unplayed_space(v))
        return rs_fail(err, MV_ERR_UNSUPPORTED,
                       "colorspace C%s is not supported: only 8-bit 4:2:0, 4:2:2, 4:4:4 and mono are played",
                       show(v, b));
    return rs_fail(err, MV_ERR_FORMAT,
                   "unknown colorspace 'C%s' (want 420jpeg, 420, 420mpeg2, 420paldv, 422, 444 or mono)", show(v, b));
}

bool mv_y4m_parse_header(const char *hdr, size_t len, mv_info *info, rs_err *err)
{
    y4m_hdr h = {.info = {.fps_num = 25, .fps_den = 1, .sar_num = 1, .sar_den = 1, .frames = -1}};
    size_t i = 0;
    while (i < len) {
        if (hdr[i] == ' ') {
            i++;
            continue;
        }
        size_t j = i;
        while (j < len && hdr[j] != ' ')
            j++;
        if (!tag((span){hdr + i, j - i}, &h, err))
            return false;
        i = j;
    }
    if (!h.info.w)
        return rs_fail(err, MV_ERR_FORMAT, "missing W (width) in the Y4M header");
    if (!h.info.h)
        return rs_fail(err, MV_ERR_FORMAT, "missing H (height) in the Y4M header");
    if (!colorspace(&h, err))
        return false;
    if (!h.has_matrix) {
        h.info.matrix = mv_guess_matrix(h.info.w, h.info.h);
        h.info.matrix_guessed = true;
    }
    snprintf(h.info.codec, sizeof h.info.codec, "y4m");
    mv_info_planes(&h.info);
    *info = h.info;
    return true;
}

/* --- the file --- */

/* Reads one line (the newline not stored) of at most max bytes, newline
 * included.  1: a line; 0: end of file first (*n bytes read); -1: read
 * error; 2: no newline within max bytes. */
static int read_line(FILE *f, char *buf, size_t max, size_t *n)
{
    *n = 0;
    for (;;) {
        int c = getc(f);
        if (c == EOF)
            return ferror(f) ? -1 : 0;
        if (c == '\n')
            return 1;
        if (*n + 1 >= max)
            return 2;
        buf[(*n)++] = (char)c;
    }
}

/* The file's frame count when every frame header is a bare "FRAME\n" and
 * the size says so exactly; -1 otherwise (pipes, frames with tags). */
static int64_t count_frames(FILE *f, size_t hdr_bytes, size_t frame_bytes)
{
    struct stat st;
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode) || st.st_size < (off_t)hdr_bytes)
        return -1;
    uint64_t data = (uint64_t)st.st_size - hdr_bytes, per = (uint64_t)frame_bytes + 6;
    return data % per == 0 ? (int64_t)(data / per) : -1;
}

/* Reads and parses the header line; false with err set (not yet prefixed). */
static bool read_header(FILE *f, mv_info *info, size_t *hdr_bytes, rs_err *err)
{
    char *line = malloc(HDR_MAX);
    if (!line)
        return rs_fail(err, MV_ERR_NOMEM, "out of memory");
    size_t n;
    int r = read_line(f, line, HDR_MAX, &n);
    bool ok = false;
    if (r < 0)
        rs_fail(err, MV_ERR_OPEN, "read error: %s", strerror(errno));
    else if (n < MAGIC_LEN || memcmp(line, MAGIC, MAGIC_LEN) != 0)
        rs_fail(err, MV_ERR_FORMAT, "not a Y4M file (no YUV4MPEG2 header)");
    else if (r == 0)
        rs_fail(err, MV_ERR_FORMAT, "the Y4M header line has no end (the file stops after %zu bytes)", n);
    else if (r == 2)
        rs_fail(err, MV_ERR_FORMAT, "the Y4M header line is longer than %d bytes", HDR_MAX);
    else
        ok = mv_y4m_parse_header(line + MAGIC_LEN, n - MAGIC_LEN, info, err);
    *hdr_bytes = n + 1;
    free(line);
    return ok;
}

static int y4m_read(mv_src *base, uint8_t *dst, rs_err *err);
static void y4m_close(mv_src *base);

mv_src *mv_y4m_open(const char *path, rs_err *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        rs_fail(err, MV_ERR_OPEN, "%s: cannot open: %s", path, strerror(errno));
        return NULL;
    }
    mv_info info;
    size_t hdr_bytes = 0;
    if (!read_header(f, &info, &hdr_bytes, err)) {
        rs_err_prefix(err, "%s", path);
        fclose(f);
        return NULL;
    }
    y4m_src *s = calloc(1, sizeof *s);
    if (!s) {
        rs_fail(err, MV_ERR_NOMEM, "%s: out of memory", path);
        fclose(f);
        return NULL;
    }
    info.frames = count_frames(f, hdr_bytes, mv_frame_bytes(&info));
    s->base.info = info;
    snprintf(s->base.path, sizeof s->base.path, "%s", path);
    s->base.read = y4m_read;
    s->base.close = y4m_close;
    s->f = f;
    return &s->base;
}

/* Sets the sticky error; returns -1 for read's "error". */
static int read_fail(y4m_src *s, int code, const char *fmt, ...) RS_PRINTF(3, 4);
static int read_fail(y4m_src *s, int code, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    rs_vfail(&s->failed, code, fmt, ap);
    va_end(ap);
    return -1;
}

/* "FRAME" then a newline, or a space, tags and a newline.  1: a header;
 * 0: clean end of stream; -1: error in s->failed. */
static int frame_header(y4m_src *s)
{
    char line[FRAME_HDR_MAX];
    size_t n;
    const char *path = s->base.path;
    long long no = (long long)s->base.index; /* 0-based, as --dump and --hashes number frames */
    int r = read_line(s->f, line, sizeof line, &n);
    if (r < 0)
        return read_fail(s, MV_ERR_OPEN, "%s: frame %lld: read error: %s", path, no, strerror(errno));
    if (r == 0 && n == 0)
        return 0;
    /* right so far: "FRAME" or the start of it, then maybe a space and tags */
    bool good = memcmp(line, "FRAME", n < 5 ? n : 5) == 0 && (n <= 5 || line[5] == ' ');
    if (r == 0 && good)
        return read_fail(s, MV_ERR_TRUNCATED, "%s: frame %lld truncated (the file ends inside its FRAME header)",
                         path, no);
    if (r != 1 || !good || n < 5)
        return read_fail(s, MV_ERR_FORMAT,
                         "%s: frame %lld: bad frame header (want \"FRAME\" and a newline within %d bytes)", path, no,
                         FRAME_HDR_MAX);
    return 1;
}

/* The planes, straight into dst: no copy, dst may be mapped GPU memory. */
static int frame_data(y4m_src *s, uint8_t *dst)
{
    size_t want = mv_frame_bytes(&s->base.info);
    size_t got = fread(dst, 1, want, s->f);
    long long no = (long long)s->base.index; /* 0-based, as --dump and --hashes number frames */
    if (got == want)
        return 1;
    if (ferror(s->f))
        return read_fail(s, MV_ERR_OPEN, "%s: frame %lld: read error: %s", s->base.path, no, strerror(errno));
    return read_fail(s, MV_ERR_TRUNCATED, "%s: frame %lld truncated (got %zu of %zu bytes)", s->base.path, no, got,
                     want);
}

static int y4m_read(mv_src *base, uint8_t *dst, rs_err *err)
{
    y4m_src *s = (y4m_src *)base;
    int r = s->failed.code ? -1 : frame_header(s);
    if (r == 1)
        r = frame_data(s, dst);
    if (r == 1)
        s->base.index++;
    if (r < 0 && err)
        *err = s->failed;
    return r;
}

static void y4m_close(mv_src *base)
{
    y4m_src *s = (y4m_src *)base;
    if (!s)
        return;
    fclose(s->f);
    free(s);
}
