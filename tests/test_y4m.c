/* player/mv_y4m: the Y4M header parser and reader.
 *
 * Headers are parsed from heap copies of exactly their length (no NUL), so
 * under ASan an over-read fails.  Files go to a fresh directory under
 * $RS_TEST_OUT (tests/run.sh: BUILD/test-output) or /tmp, removed when the
 * case passes and kept for a look when it fails.  The randomized cases use
 * a fixed-seed xorshift: a failure reproduces. */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../player/mv.h"
#include "t.h"

/* --- helpers --- */

/* Parses text through a heap copy of exactly strlen(text) bytes. */
static bool parse_n(const char *text, size_t n, mv_info *info, rs_err *e)
{
    char *p = malloc(n ? n : 1);
    T_ASSERT(p);
    memcpy(p, text, n);
    rs_err_clear(e);
    bool ok = mv_y4m_parse_header(p, n, info, e);
    free(p);
    return ok;
}

static mv_info parse_ok(const char *text)
{
    mv_info i;
    rs_err e;
    T_ASSERTF(parse_n(text, strlen(text), &i, &e), "\"%s\" refused: %s", text, e.msg);
    return i;
}

static void refuse(const char *text, int code, const char *needle)
{
    mv_info i;
    rs_err e;
    T_ASSERTF(!parse_n(text, strlen(text), &i, &e), "\"%s\" accepted", text);
    T_ASSERTF(e.code == code, "\"%s\": %s, want %s (%s)", text, mv_error_text(e.code), mv_error_text(code), e.msg);
    T_ASSERTF(strstr(e.msg, needle), "\"%s\": expected \"%s\" in \"%s\"", text, needle, e.msg);
}

static int expect_planes(int n, int shift)
{
    return (n + (1 << shift) - 1) >> shift;
}

/* The invariants of any accepted header (of an opened file: frames known). */
static void check_info(const mv_info *i, const char *what, bool file)
{
    T_ASSERTF(i->w >= 1 && i->w <= 16384 && i->h >= 1 && i->h <= 16384, "%s: %dx%d", what, i->w, i->h);
    T_ASSERTF(i->fps_num > 0 && i->fps_den > 0, "%s: F%d:%d", what, i->fps_num, i->fps_den);
    T_ASSERTF(i->sar_num > 0 && i->sar_den > 0, "%s: A%d:%d", what, i->sar_num, i->sar_den);
    T_ASSERTF(i->sx >= 0 && i->sx <= 1 && i->sy >= 0 && i->sy <= 1, "%s: shifts %d,%d", what, i->sx, i->sy);
    int cw = i->mono ? 0 : expect_planes(i->w, i->sx), ch = i->mono ? 0 : expect_planes(i->h, i->sy);
    T_ASSERTF(i->cw == cw && i->ch == ch, "%s: chroma %dx%d, want %dx%d", what, i->cw, i->ch, cw, ch);
    T_ASSERTF(i->matrix == MV_BT601 || i->matrix == MV_BT709, "%s: matrix %d", what, i->matrix);
    T_ASSERTF(i->chroma_loc >= MV_CHROMA_CENTER && i->chroma_loc <= MV_CHROMA_TOPLEFT, "%s: chroma_loc %d", what,
              i->chroma_loc);
    T_ASSERTF(file ? i->frames >= -1 : i->frames == -1, "%s: frames %lld", what, (long long)i->frames);
    T_ASSERTF(strcmp(i->codec, "y4m") == 0, "%s: codec %.32s", what, i->codec);
    T_ASSERTF(memchr(i->pixfmt, 0, sizeof i->pixfmt) && i->pixfmt[0], "%s: pixfmt not a string", what);
}

/* The directory for this case's files; see the top of the file. */
static char out_dir[512];
static char out_files[16][700];
static int out_count;

static const char *out_path(const char *name)
{
    if (!out_dir[0]) {
        const char *base = getenv("RS_TEST_OUT");
        snprintf(out_dir, sizeof out_dir, "%s/test_y4m-XXXXXX", base && *base ? base : "/tmp");
        T_ASSERTF(mkdtemp(out_dir), "mkdtemp %s: %s", out_dir, strerror(errno));
    }
    for (int i = 0; i < out_count; i++)
        if (!strcmp(strrchr(out_files[i], '/') + 1, name))
            return out_files[i];
    T_ASSERT(out_count < 16);
    snprintf(out_files[out_count], sizeof out_files[0], "%s/%s", out_dir, name);
    return out_files[out_count++];
}

static void out_done(void)
{
    for (int i = 0; i < out_count; i++)
        unlink(out_files[i]);
    if (out_dir[0])
        rmdir(out_dir);
    out_dir[0] = 0;
    out_count = 0;
}

static const char *write_file(const char *name, const void *data, size_t n)
{
    const char *p = out_path(name);
    FILE *f = fopen(p, "wb");
    T_ASSERTF(f, "%s: %s", p, strerror(errno));
    T_ASSERT(fwrite(data, 1, n, f) == n);
    T_ASSERT(fclose(f) == 0);
    return p;
}

static const char *write_text(const char *name, const char *text)
{
    return write_file(name, text, strlen(text));
}

/* A growing byte buffer for building files. */
typedef struct buf {
    uint8_t *p;
    size_t n, cap;
} buf;

static void put(buf *b, const void *data, size_t n)
{
    if (b->n + n > b->cap) {
        b->cap = (b->n + n) * 2 + 64;
        b->p = realloc(b->p, b->cap);
        T_ASSERT(b->p);
    }
    memcpy(b->p + b->n, data, n);
    b->n += n;
}

static void puts_(buf *b, const char *s)
{
    put(b, s, strlen(s));
}

/* Known bytes of frame k (never the same at one offset in two frames). */
static uint8_t pattern(int k, size_t off)
{
    return (uint8_t)(k * 37 + off * 7 + 1);
}

static void put_frame(buf *b, int k, size_t bytes, const char *frame_hdr)
{
    puts_(b, frame_hdr);
    for (size_t o = 0; o < bytes; o++) {
        uint8_t v = pattern(k, o);
        put(b, &v, 1);
    }
}

/* W5 H3 4:2:0: chroma 3x2, 15 + 2 * 6 = 27 bytes a frame. */
#define SMALL_HDR "YUV4MPEG2 W5 H3 F30000:1001 Ip A1:1 C420jpeg XYSCSS=420JPEG\n"
enum { SMALL_FRAME = 27, GUARD = 16 };

/* The small file with n frames; frame_hdrs[k] (NULL: "FRAME\n"). */
static buf small_file(int n, const char *const *frame_hdrs)
{
    buf b = {0};
    puts_(&b, SMALL_HDR);
    for (int k = 0; k < n; k++)
        put_frame(&b, k, SMALL_FRAME, frame_hdrs && frame_hdrs[k] ? frame_hdrs[k] : "FRAME\n");
    return b;
}

static mv_src *open_ok(const char *path)
{
    rs_err e = {0};
    mv_src *s = mv_y4m_open(path, &e);
    T_ASSERTF(s, "open %s: %s", path, e.msg);
    T_ASSERT(strcmp(s->path, path) == 0);
    T_ASSERT(s->read && s->close);
    T_EQ(s->index, 0);
    return s;
}

static void open_fails(const char *path, int code, const char *needle)
{
    rs_err e = {0};
    mv_src *s = mv_y4m_open(path, &e);
    T_ASSERTF(!s, "%s opened", path);
    T_ASSERTF(e.code == code, "%s: %s, want %s (%s)", path, mv_error_text(e.code), mv_error_text(code), e.msg);
    T_CONTAINS(e.msg, path);
    T_CONTAINS(e.msg, needle);
}

/* Reads frame k of the small file and checks every byte and the guard. */
static void read_small(mv_src *s, int k)
{
    uint8_t dst[SMALL_FRAME + GUARD];
    memset(dst, 0xa5, sizeof dst);
    rs_err e = {0};
    int r = s->read(s, dst, &e);
    T_ASSERTF(r == 1, "frame %d: read %d: %s", k + 1, r, e.msg);
    for (size_t o = 0; o < SMALL_FRAME; o++)
        T_ASSERTF(dst[o] == pattern(k, o), "frame %d byte %zu: %d, want %d", k + 1, o, dst[o], pattern(k, o));
    for (size_t o = SMALL_FRAME; o < sizeof dst; o++)
        T_ASSERTF(dst[o] == 0xa5, "frame %d: written past the frame at %zu", k + 1, o);
    T_EQ(s->index, k + 1);
}

static void read_fails(mv_src *s, int code, const char *needle)
{
    uint8_t dst[SMALL_FRAME];
    rs_err e = {0};
    int64_t before = s->index;
    T_EQ(s->read(s, dst, &e), -1);
    T_ASSERTF(e.code == code, "%s, want %s (%s)", mv_error_text(e.code), mv_error_text(code), e.msg);
    T_CONTAINS(e.msg, s->path);
    T_CONTAINS(e.msg, needle);
    T_EQ(s->index, before);
    /* sticky: the stream is not read on after an error */
    rs_err again = {0};
    T_EQ(s->read(s, dst, &again), -1);
    T_EQ(again.code, code);
    T_ASSERT(strcmp(again.msg, e.msg) == 0);
    T_EQ(s->read(s, dst, NULL), -1);
}

/* --- the header --- */

static void t_header_420jpeg(void)
{
    mv_info i = parse_ok("W1279 H719 F30000:1001 Ip A1:1 C420jpeg XYSCSS=420JPEG");
    check_info(&i, "420jpeg", false);
    T_EQ(i.w, 1279);
    T_EQ(i.h, 719);
    T_EQ(i.sx, 1);
    T_EQ(i.sy, 1);
    T_EQ(i.cw, 640);
    T_EQ(i.ch, 360);
    T_ASSERT(!i.mono);
    T_EQ(i.chroma_loc, MV_CHROMA_CENTER);
    T_EQ(i.fps_num, 30000);
    T_EQ(i.fps_den, 1001);
    T_EQ(i.sar_num, 1);
    T_EQ(i.sar_den, 1);
    T_ASSERT(!i.full_range);
    T_EQ(i.frames, -1);
    T_ASSERT(strcmp(i.codec, "y4m") == 0);
    T_ASSERT(strcmp(i.pixfmt, "420jpeg") == 0);
    T_EQ(mv_frame_bytes(&i), 1279 * 719 + 2 * 640 * 360);
}

static void t_header_colorspaces(void)
{
    static const struct {
        const char *c;
        int sx, sy, cw, ch, loc;
        bool mono;
    } want[] = {
        {"420jpeg", 1, 1, 640, 360, MV_CHROMA_CENTER, false},
        {"420", 1, 1, 640, 360, MV_CHROMA_CENTER, false},
        {"420mpeg2", 1, 1, 640, 360, MV_CHROMA_LEFT, false},
        {"420paldv", 1, 1, 640, 360, MV_CHROMA_TOPLEFT, false},
        {"422", 1, 0, 640, 719, MV_CHROMA_LEFT, false},
        {"444", 0, 0, 1279, 719, MV_CHROMA_CENTER, false},
        {"mono", 0, 0, 0, 0, MV_CHROMA_CENTER, true},
    };
    for (size_t k = 0; k < sizeof want / sizeof want[0]; k++) {
        char h[128];
        snprintf(h, sizeof h, "W1279 H719 C%s", want[k].c);
        mv_info i = parse_ok(h);
        check_info(&i, h, false);
        T_ASSERTF(i.sx == want[k].sx && i.sy == want[k].sy, "%s: shifts %d,%d", h, i.sx, i.sy);
        T_ASSERTF(i.cw == want[k].cw && i.ch == want[k].ch, "%s: chroma %dx%d", h, i.cw, i.ch);
        T_ASSERTF(i.chroma_loc == want[k].loc, "%s: chroma_loc %d", h, i.chroma_loc);
        T_ASSERTF(i.mono == want[k].mono, "%s: mono %d", h, i.mono);
        T_ASSERTF(strcmp(i.pixfmt, want[k].c) == 0, "%s: pixfmt %s", h, i.pixfmt);
    }
    /* even sizes and 1x1 */
    mv_info i = parse_ok("W1280 H720 C420mpeg2");
    T_ASSERT(i.cw == 640 && i.ch == 360);
    i = parse_ok("W1 H1");
    T_ASSERT(i.cw == 1 && i.ch == 1 && mv_frame_bytes(&i) == 3);
    i = parse_ok("W3 H3 Cmono");
    T_EQ(mv_frame_bytes(&i), 9);
}

static void t_header_defaults(void)
{
    mv_info i = parse_ok("W320 H240");
    check_info(&i, "defaults", false);
    T_ASSERT(strcmp(i.pixfmt, "420jpeg") == 0);
    T_ASSERT(i.sx == 1 && i.sy == 1 && i.cw == 160 && i.ch == 120);
    T_EQ(i.chroma_loc, MV_CHROMA_CENTER);
    T_ASSERT(i.fps_num == 25 && i.fps_den == 1);
    T_ASSERT(i.sar_num == 1 && i.sar_den == 1);
    T_ASSERT(!i.full_range && !i.mono);
    /* tag order does not matter; extra spaces are tolerated */
    i = parse_ok("  C444 H240   W320 ");
    T_ASSERT(i.w == 320 && i.h == 240 && i.cw == 320);
}

static void t_header_rate_aspect(void)
{
    mv_info i = parse_ok("W720 H576 F24000:1001 A128:117");
    T_ASSERT(i.fps_num == 24000 && i.fps_den == 1001);
    T_ASSERT(i.sar_num == 128 && i.sar_den == 117);
    i = parse_ok("W720 H576 F2147483647:1 A0:0");
    T_EQ(i.fps_num, 2147483647);
    T_ASSERT(i.sar_num == 1 && i.sar_den == 1);
    i = parse_ok("W720 H576 F1:60 A10:11");
    T_ASSERT(i.fps_num == 1 && i.fps_den == 60 && i.sar_num == 10 && i.sar_den == 11);
}

static void t_header_range(void)
{
    T_ASSERT(!parse_ok("W64 H64").full_range);
    T_ASSERT(parse_ok("W64 H64 XCOLORRANGE=FULL").full_range);
    T_ASSERT(parse_ok("W64 H64 XCOLORRANGE=full").full_range);
    T_ASSERT(!parse_ok("W64 H64 XCOLORRANGE=LIMITED").full_range);
    T_ASSERT(!parse_ok("W64 H64 XCOLORRANGE=FULL XCOLORRANGE=LIMITED").full_range);
    refuse("W64 H64 XCOLORRANGE=PC", MV_ERR_FORMAT, "XCOLORRANGE");
    /* what capture/cap_sink_y4m.c writes */
    mv_info i = parse_ok("W640 H360 F60:1 Ip A1:1 C420jpeg XCOLORRANGE=LIMITED");
    T_ASSERT(i.w == 640 && i.fps_num == 60 && !i.full_range && i.cw == 320 && i.ch == 180);
}

static void t_header_matrix(void)
{
    mv_info i = parse_ok("W1920 H1080 XCOLORMATRIX=BT601");
    T_ASSERT(i.matrix == MV_BT601 && !i.matrix_guessed);
    i = parse_ok("W720 H480 XCOLORMATRIX=bt709");
    T_ASSERT(i.matrix == MV_BT709 && !i.matrix_guessed);
    i = parse_ok("W720 H480 XCOLORMATRIX=Bt709 XCOLORRANGE=FULL");
    T_ASSERT(i.matrix == MV_BT709 && i.full_range);
    refuse("W64 H64 XCOLORMATRIX=BT2020", MV_ERR_FORMAT, "XCOLORMATRIX value 'BT2020'");
}

static void t_header_matrix_guess(void)
{
    mv_info i = parse_ok("W720 H480");
    T_ASSERT(i.matrix == MV_BT601 && i.matrix_guessed);
    i = parse_ok("W1280 H720");
    T_ASSERT(i.matrix == MV_BT709 && i.matrix_guessed);
    i = parse_ok("W720 H576");
    T_ASSERT(i.matrix == MV_BT601 && i.matrix_guessed);
    i = parse_ok("W720 H577");
    T_ASSERT(i.matrix == MV_BT709 && i.matrix_guessed);
}

static void t_header_ignores_unknown(void)
{
    mv_info i = parse_ok("W64 H32 XYSCSS=420JPEG XFOO Zwhatever y? C444");
    T_ASSERT(i.w == 64 && i.h == 32 && i.cw == 64);
    T_ASSERT(!i.full_range && i.matrix_guessed);
    /* I? is "unknown interlacing": played as progressive */
    parse_ok("W64 H32 I?");
}

static void t_header_refuse_interlaced(void)
{
    refuse("W720 H480 It", MV_ERR_UNSUPPORTED, "interlaced");
    refuse("W720 H480 Ib", MV_ERR_UNSUPPORTED, "interlaced");
    refuse("W720 H480 Im", MV_ERR_UNSUPPORTED, "interlaced");
    refuse("W720 H480 Ix", MV_ERR_FORMAT, "bad I value 'x'");
    refuse("W720 H480 Ipp", MV_ERR_FORMAT, "bad I value");
}

static void t_header_refuse_colorspace(void)
{
    static const char *const deep[] = {"420p10", "422p12", "444p16", "420p9", "444p14", "mono16", "444alpha", "411"};
    for (size_t k = 0; k < sizeof deep / sizeof deep[0]; k++) {
        char h[64];
        snprintf(h, sizeof h, "W64 H64 C%s", deep[k]);
        refuse(h, MV_ERR_UNSUPPORTED, deep[k]);
        refuse(h, MV_ERR_UNSUPPORTED, "only 8-bit 4:2:0, 4:2:2, 4:4:4 and mono");
    }
    refuse("W64 H64 Cyuv420p", MV_ERR_FORMAT, "unknown colorspace 'Cyuv420p'");
    refuse("W64 H64 C", MV_ERR_FORMAT, "unknown colorspace");
    refuse("W64 H64 C420p", MV_ERR_FORMAT, "unknown colorspace");
    refuse("W64 H64 C420JPEG", MV_ERR_FORMAT, "unknown colorspace");
}

static void t_header_refuse_size(void)
{
    refuse("W0 H64", MV_ERR_FORMAT, "bad W value '0'");
    refuse("W99999 H64", MV_ERR_FORMAT, "bad W value '99999'");
    refuse("W16385 H64", MV_ERR_FORMAT, "bad W value '16385'");
    refuse("Wabc H64", MV_ERR_FORMAT, "bad W value 'abc'");
    refuse("W H64", MV_ERR_FORMAT, "bad W value ''");
    refuse("W-64 H64", MV_ERR_FORMAT, "bad W value '-64'");
    refuse("W+64 H64", MV_ERR_FORMAT, "bad W value");
    refuse("W64x H64", MV_ERR_FORMAT, "bad W value '64x'");
    refuse("W64 H0", MV_ERR_FORMAT, "bad H value '0'");
    refuse("W64 H99999999999999999999999999999999", MV_ERR_FORMAT, "bad H value '9999");
    refuse("W64", MV_ERR_FORMAT, "missing H");
    refuse("H64 C420", MV_ERR_FORMAT, "missing W");
    refuse("", MV_ERR_FORMAT, "missing W");
    parse_ok("W16384 H16384");
    parse_ok("W0001 H1");
    /* a long bad value is quoted short, odd bytes shown as '?' */
    char h[2100] = "W64 H";
    memset(h + 5, '7', 2000);
    h[2005] = 0;
    refuse(h, MV_ERR_FORMAT, "bad H value '7777");
    refuse("W64 H1\x01\xff", MV_ERR_FORMAT, "bad H value '1?\?'");
}

static void t_header_refuse_rate(void)
{
    refuse("W64 H64 F0:1", MV_ERR_FORMAT, "bad F value '0:1'");
    refuse("W64 H64 F25:0", MV_ERR_FORMAT, "bad F value '25:0'");
    refuse("W64 H64 F25", MV_ERR_FORMAT, "bad F value '25'");
    refuse("W64 H64 F:1", MV_ERR_FORMAT, "bad F value");
    refuse("W64 H64 F25:1:1", MV_ERR_FORMAT, "bad F value");
    refuse("W64 H64 F2147483648:1", MV_ERR_FORMAT, "bad F value");
    refuse("W64 H64 A0:1", MV_ERR_FORMAT, "bad A value '0:1'");
    refuse("W64 H64 A1:0", MV_ERR_FORMAT, "bad A value");
    refuse("W64 H64 A1", MV_ERR_FORMAT, "bad A value");
}

/* The parser reads len bytes, not up to a NUL, and leaves info alone on failure. */
static void t_header_bounds(void)
{
    mv_info i;
    rs_err e;
    T_ASSERT(parse_n("W640 H480", 8, &i, &e) && i.w == 640 && i.h == 48);
    T_ASSERT(parse_n("W64 H48 It", 7, &i, &e) && i.h == 48);
    T_ASSERT(!parse_n("W64 H48", 3, &i, &e) && e.code == MV_ERR_FORMAT);
    T_ASSERT(!parse_n("W64 H48", 0, &i, &e) && e.code == MV_ERR_FORMAT);
    /* a NUL inside the text is just a byte */
    T_ASSERT(!parse_n("W64\0H48", 7, &i, &e) && e.code == MV_ERR_FORMAT);
    T_ASSERT(parse_n("W64 H48 \0", 9, &i, &e) && i.w == 64);
    memset(&i, 0x5a, sizeof i);
    mv_info copy = i;
    T_ASSERT(!parse_n("W64 H48 C420p10", 15, &i, &e));
    T_ASSERT(memcmp(&i, &copy, sizeof i) == 0);
    T_ASSERT(!mv_y4m_parse_header("W64 H64 It", 10, &i, NULL)); /* no err wanted */
}

/* --- files --- */

static void t_file_read_frames(void)
{
    buf b = small_file(3, NULL);
    const char *p = write_file("three.y4m", b.p, b.n);
    mv_src *s = open_ok(p);
    T_ASSERT(s->info.w == 5 && s->info.h == 3 && s->info.cw == 3 && s->info.ch == 2);
    T_ASSERT(s->info.fps_num == 30000 && s->info.fps_den == 1001);
    T_ASSERT(strcmp(s->info.codec, "y4m") == 0 && strcmp(s->info.pixfmt, "420jpeg") == 0);
    T_EQ(mv_frame_bytes(&s->info), SMALL_FRAME);
    T_EQ(s->info.frames, 3);
    for (int k = 0; k < 3; k++)
        read_small(s, k);
    uint8_t dst[SMALL_FRAME];
    rs_err e = {0};
    T_EQ(s->read(s, dst, &e), 0);
    T_EQ(e.code, 0);
    T_EQ(s->read(s, dst, &e), 0); /* and stays at the end */
    T_EQ(s->index, 3);
    mv_close(s);
    free(b.p);
    out_done();
}

static void t_file_frame_params(void)
{
    static const char *const hdrs[] = {NULL, "FRAME Ixyz\n", "FRAME Ip XFOO=1\n"};
    buf b = small_file(3, hdrs);
    const char *p = write_file("params.y4m", b.p, b.n);
    mv_src *s = open_ok(p);
    T_EQ(s->info.frames, -1); /* the size no longer says: unknown */
    for (int k = 0; k < 3; k++)
        read_small(s, k);
    uint8_t dst[SMALL_FRAME];
    T_EQ(s->read(s, dst, NULL), 0);
    mv_close(s);
    free(b.p);
    out_done();
}

static void t_file_empty_stream(void)
{
    const char *p = write_text("empty.y4m", SMALL_HDR);
    mv_src *s = open_ok(p);
    T_EQ(s->info.frames, 0);
    uint8_t dst[SMALL_FRAME];
    T_EQ(s->read(s, dst, NULL), 0);
    mv_close(s);
    /* mono: a frame is the Y plane alone */
    const char mono[] = "YUV4MPEG2 W2 H2 Cmono\nFRAME\nabcdFRAME\nefgh";
    p = write_text("mono.y4m", mono);
    s = open_ok(p);
    T_ASSERT(s->info.mono && s->info.cw == 0 && s->info.frames == 2);
    uint8_t y[4];
    T_ASSERT(s->read(s, y, NULL) == 1 && memcmp(y, "abcd", 4) == 0);
    T_ASSERT(s->read(s, y, NULL) == 1 && memcmp(y, "efgh", 4) == 0);
    T_EQ(s->read(s, y, NULL), 0);
    mv_close(s);
    out_done();
}

static void t_file_truncated_data(void)
{
    buf b = small_file(3, NULL);
    size_t cut = strlen(SMALL_HDR) + 6 + SMALL_FRAME + 6 + 10; /* 10 bytes into frame 1 (0-based) */
    const char *p = write_file("cut.y4m", b.p, cut);
    mv_src *s = open_ok(p);
    T_EQ(s->info.frames, -1);
    read_small(s, 0);
    read_fails(s, MV_ERR_TRUNCATED, "frame 1 truncated (got 10 of 27 bytes)");
    mv_close(s);
    /* cut right after the frame header: no data at all */
    p = write_file("cut0.y4m", b.p, strlen(SMALL_HDR) + 6);
    s = open_ok(p);
    read_fails(s, MV_ERR_TRUNCATED, "frame 0 truncated (got 0 of 27 bytes)");
    mv_close(s);
    free(b.p);
    out_done();
}

static void t_file_truncated_header(void)
{
    static const char *const hdrs[] = {NULL, "FRAME Ixyz\n"};
    buf b = small_file(2, hdrs);
    size_t f2 = strlen(SMALL_HDR) + 6 + SMALL_FRAME;
    size_t cuts[] = {f2 + 3, f2 + 5, f2 + 8}; /* "FRA", "FRAME", "FRAME Ix" */
    for (size_t k = 0; k < 3; k++) {
        const char *p = write_file("cuthdr.y4m", b.p, cuts[k]);
        mv_src *s = open_ok(p);
        read_small(s, 0);
        read_fails(s, MV_ERR_TRUNCATED, "frame 1 truncated");
        mv_close(s);
    }
    free(b.p);
    out_done();
}

static void t_file_bad_frame_header(void)
{
    static const char *const bad[] = {"FRAMX\n", "FRAMEX\n", "\n", "frame\n", "FRAME\tIp\n", "XFRAME\n"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        const char *hdrs[] = {NULL, bad[k], NULL};
        buf b = small_file(3, hdrs);
        const char *p = write_file("bad.y4m", b.p, b.n);
        mv_src *s = open_ok(p);
        read_small(s, 0);
        read_fails(s, MV_ERR_FORMAT, "frame 1: bad frame header");
        mv_close(s);
        free(b.p);
    }
    /* tags up to 1024 bytes are fine, a longer line is not a frame header */
    char line[1100] = "FRAME ";
    memset(line + 6, 'x', 1017);
    strcpy(line + 1023, "\n"); /* 1024 bytes with the newline */
    const char *hdrs[] = {line, NULL};
    buf b = small_file(1, hdrs);
    mv_src *s = open_ok(write_file("long.y4m", b.p, b.n));
    read_small(s, 0);
    mv_close(s);
    free(b.p);
    memset(line + 6, 'x', 1018);
    strcpy(line + 1024, "\n");
    b = small_file(1, hdrs);
    s = open_ok(write_file("long.y4m", b.p, b.n));
    read_fails(s, MV_ERR_FORMAT, "frame 0: bad frame header");
    mv_close(s);
    free(b.p);
    out_done();
}

static void t_file_bad_header(void)
{
    open_fails(write_text("img.ppm", "P6\n1 1\n255\nabc"), MV_ERR_FORMAT, "not a Y4M file (no YUV4MPEG2 header)");
    open_fails(write_text("empty", ""), MV_ERR_FORMAT, "not a Y4M file");
    open_fails(write_text("nospace.y4m", "YUV4MPEG2\n"), MV_ERR_FORMAT, "not a Y4M file");
    open_fails(write_text("w0.y4m", "YUV4MPEG2 W0 H4\nFRAME\n"), MV_ERR_FORMAT, ": bad W value '0'");
    open_fails(write_text("it.y4m", "YUV4MPEG2 W4 H4 It\n"), MV_ERR_UNSUPPORTED, ": interlaced");
    open_fails(write_text("p10.y4m", "YUV4MPEG2 W4 H4 C420p10\n"), MV_ERR_UNSUPPORTED,
               ": colorspace C420p10 is not supported");
    open_fails(write_text("noend.y4m", "YUV4MPEG2 W4 H4"), MV_ERR_FORMAT, "no end");
    /* the header line: 4096 bytes with its newline at most */
    char h[5000] = "YUV4MPEG2 W4 H4 X";
    size_t n = strlen(h);
    memset(h + n, 'y', 4095 - n);
    h[4095] = '\n';
    mv_src *s = open_ok(write_file("long.y4m", h, 4096));
    T_EQ(s->info.frames, 0);
    mv_close(s);
    memset(h + n, 'y', 4096 - n);
    h[4096] = '\n';
    open_fails(write_file("long.y4m", h, 4097), MV_ERR_FORMAT, "longer than 4096 bytes");
    out_done();
}

static void t_file_open_errors(void)
{
    const char *p = out_path("missing.y4m");
    open_fails(p, MV_ERR_OPEN, "cannot open");
    /* a directory opens but cannot be read */
    open_fails(out_dir, MV_ERR_OPEN, "read error");
    T_ASSERT(!mv_y4m_open(p, NULL)); /* no err wanted */
    out_done();
}

/* --- randomized --- */

static uint64_t rng_state = 0x9e3779b97f4a7c15u;

static uint64_t rng(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

static size_t below(size_t n)
{
    return n ? (size_t)(rng() % n) : 0;
}

enum { FUZZ_CAP = 512 };

static void insert(char *h, size_t *n, size_t at, const char *s, size_t k)
{
    if (*n + k > FUZZ_CAP)
        k = FUZZ_CAP - *n;
    memmove(h + at + k, h + at, *n - at);
    memcpy(h + at, s, k);
    *n += k;
}

/* One random edit of h[0..n). */
static void mutate(char *h, size_t *n)
{
    static const char alpha[] = "0123456789WHFIACXpjm:=? -+tbmonoalpha";
    static const char *const numbers[] = {"0", "1", "16384", "16385", "2147483647", "2147483648", ":", "0:0"};
    static const char *const tags[] = {" C420p10", " XCOLORRANGE=FULL", " XCOLORMATRIX=BT709", " It", " Cmono",
                                       " C444", " C444alpha", " W", " H7", " F1:0", " A0:0", " C420mpeg2"};
    size_t at = below(*n + 1);
    const char *v;
    switch (below(8)) {
    case 0: /* flip a bit */
        if (*n)
            h[below(*n)] ^= (char)(1u << below(8));
        break;
    case 1: /* insert a letter, digit or separator */
        insert(h, n, at, &alpha[below(sizeof alpha - 1)], 1);
        break;
    case 2: /* truncate */
        *n = below(*n + 1);
        break;
    case 3: { /* a long run of digits */
        char d[64];
        size_t k = 5 + below(sizeof d - 5);
        for (size_t i = 0; i < k; i++)
            d[i] = (char)('0' + below(10));
        insert(h, n, at, d, k);
        break;
    }
    case 4: { /* delete a range */
        size_t k = below(*n - at + 1);
        memmove(h + at, h + at + k, *n - at - k);
        *n -= k;
        break;
    }
    case 5: /* a number on the edge */
        v = numbers[below(sizeof numbers / sizeof numbers[0])];
        insert(h, n, at, v, strlen(v));
        break;
    case 6: { /* a random byte */
        char c = (char)below(256);
        insert(h, n, at, &c, 1);
        break;
    }
    default: /* a whole tag, at the end of a token */
        v = tags[below(sizeof tags / sizeof tags[0])];
        while (at < *n && h[at] != ' ')
            at++;
        insert(h, n, at, v, strlen(v));
        break;
    }
}

static const char *const FUZZ_BASES[] = {
    "W1280 H720 F30000:1001 Ip A1:1 C420jpeg XYSCSS=420JPEG",
    "W720 H480 F30:1 I? A10:11 C420mpeg2 XCOLORRANGE=FULL",
    "W1 H1 C444 XCOLORMATRIX=bt709",
    "W16384 H16384 Cmono A0:0 F1:1",
    "H9 W17 C422 XCOLORRANGE=LIMITED",
    "W640 H360 C420paldv F25:1",
    "W3 H5 C420",
};

static void t_fuzz_header(void)
{
    int accepted = 0, format = 0, unsupported = 0;
    char h[FUZZ_CAP];
    for (int it = 0; it < 20000; it++) {
        const char *base = FUZZ_BASES[below(sizeof FUZZ_BASES / sizeof FUZZ_BASES[0])];
        size_t n = strlen(base);
        memcpy(h, base, n);
        for (size_t m = 1 + below(4); m > 0; m--)
            mutate(h, &n);
        mv_info i;
        rs_err e;
        if (parse_n(h, n, &i, &e)) {
            char what[32];
            snprintf(what, sizeof what, "iteration %d", it);
            check_info(&i, what, false);
            accepted++;
        } else {
            T_ASSERTF(e.code == MV_ERR_FORMAT || e.code == MV_ERR_UNSUPPORTED, "iteration %d: code %d", it, e.code);
            T_ASSERTF(e.msg[0] && memchr(e.msg, 0, sizeof e.msg), "iteration %d: no message", it);
            format += e.code == MV_ERR_FORMAT;
            unsupported += e.code == MV_ERR_UNSUPPORTED;
        }
    }
    /* the edits must reach both sides, or this tests little */
    T_ASSERTF(accepted > 4000 && format > 12000 && unsupported > 400, "accepted %d, refused %d + %d unsupported",
              accepted, format, unsupported);
}

/* Small headers for the file fuzzer, each with its frame size. */
static const struct {
    const char *hdr;
    size_t frame;
} FUZZ_FILES[] = {
    {"YUV4MPEG2 W4 H2\n", 8 + 2 * 2},
    {"YUV4MPEG2 W3 H3 C444 XCOLORRANGE=FULL\n", 27},
    {"YUV4MPEG2 W5 H1 Cmono\n", 5},
    {"YUV4MPEG2 W2 H4 C422\n", 8 + 2 * 4},
    {"YUV4MPEG2 W7 H3 C420paldv F1:1\n", 21 + 2 * 8},
};

/* One random file: returns the frames a reader must deliver when the file
 * is intact (*intact), with their bytes in *frames. */
static buf fuzz_file(size_t pick, bool *intact, int *nframes, bool *bare, buf *frames)
{
    buf b = {0};
    size_t fb = FUZZ_FILES[pick].frame;
    char h[FUZZ_CAP + 1]; /* + the newline */
    size_t n = strlen(FUZZ_FILES[pick].hdr);
    memcpy(h, FUZZ_FILES[pick].hdr, n);
    *intact = below(8) != 0;
    if (!*intact) /* edit the header line (before its newline) */
        for (size_t m = 1 + below(3); m > 0 && n > 0; m--) {
            size_t keep = n - 1;
            mutate(h, &keep);
            h[keep] = '\n';
            n = keep + 1;
        }
    put(&b, h, n);
    *nframes = (int)below(5);
    *bare = true;
    for (int k = 0; k < *nframes; k++) {
        const char *fh = below(4) ? "FRAME\n" : "FRAME Ixyz\n";
        *bare &= fh[5] == '\n';
        size_t at = b.n;
        puts_(&b, fh);
        for (size_t o = 0; o < fb; o++) {
            uint8_t v = (uint8_t)rng();
            put(&b, &v, 1);
            put(frames, &v, 1);
        }
        if (!below(16)) { /* corrupt the frame header */
            b.p[at + below(6)] ^= (uint8_t)(1u << below(8));
            *intact = false;
        }
    }
    if (!below(6)) { /* garbage at the end */
        for (size_t k = 1 + below(200); k > 0; k--) {
            uint8_t v = (uint8_t)rng();
            put(&b, &v, 1);
        }
        *intact = false;
    }
    if (!below(4)) { /* truncate */
        b.n = below(b.n + 1);
        *intact = false;
    }
    return b;
}

static void fuzz_read_all(mv_src *s, size_t file_bytes, bool intact, int nframes, bool bare, const buf *frames)
{
    size_t fb = mv_frame_bytes(&s->info);
    uint8_t *dst = malloc(fb); /* exactly one frame: ASan catches a write past it */
    T_ASSERT(dst);
    size_t bound = file_bytes / (fb + 6);
    int got = 0, r;
    rs_err e = {0};
    while ((r = s->read(s, dst, &e)) == 1) {
        T_ASSERTF((size_t)got < bound, "%d frames from %zu bytes", got + 1, file_bytes);
        if (intact)
            T_ASSERTF(memcmp(dst, frames->p + (size_t)got * fb, fb) == 0, "frame %d differs", got + 1);
        got++;
        T_EQ(s->index, got);
    }
    T_ASSERTF(r == 0 || r == -1, "read returned %d", r);
    if (r == 0) {
        T_EQ(s->read(s, dst, &e), 0);
    } else {
        T_ASSERTF(e.code == MV_ERR_FORMAT || e.code == MV_ERR_TRUNCATED, "code %d: %s", e.code, e.msg);
        T_CONTAINS(e.msg, s->path);
        T_EQ(s->read(s, dst, &e), -1);
    }
    if (intact) {
        T_ASSERTF(r == 0 && got == nframes, "intact file: %d of %d frames, last read %d (%s)", got, nframes, r, e.msg);
        T_EQ(s->info.frames, bare ? nframes : -1);
    }
    free(dst);
}

static void t_fuzz_files(void)
{
    int opened = 0, refused = 0, intact_files = 0;
    for (int it = 0; it < 600; it++) {
        bool intact, bare;
        int nframes;
        buf frames = {0};
        buf b = fuzz_file(below(sizeof FUZZ_FILES / sizeof FUZZ_FILES[0]), &intact, &nframes, &bare, &frames);
        const char *p = write_file("fuzz.y4m", b.p, b.n);
        rs_err e = {0};
        mv_src *s = mv_y4m_open(p, &e);
        if (s) {
            check_info(&s->info, p, true);
            fuzz_read_all(s, b.n, intact, nframes, bare, &frames);
            mv_close(s);
            opened++;
            intact_files += intact;
        } else {
            T_ASSERTF(!intact, "intact file refused: %s", e.msg);
            T_ASSERTF(e.code == MV_ERR_FORMAT || e.code == MV_ERR_UNSUPPORTED, "code %d: %s", e.code, e.msg);
            T_CONTAINS(e.msg, p);
            refused++;
        }
        free(b.p);
        free(frames.p);
    }
    T_ASSERTF(opened > 300 && refused > 10 && intact_files > 100, "opened %d (%d intact), refused %d", opened,
              intact_files, refused);
    out_done();
}

/* Every id of the movie list has a text, and no two share one. */
static void t_error_ids_have_texts(void)
{
    T_EQ(RS_ERR_MODULE(MV_ERR_BASE + 1), RS_ERR_MOD_MV);
    T_EQ(RS_ERR_MODULE(MV_ERR_END - 1), RS_ERR_MOD_MV);
    T_ASSERT(!strcmp(rs_err_module_name(MV_ERR_FORMAT), "movie"));
    for (int a = MV_ERR_BASE + 1; a < MV_ERR_END; a++) {
        const char *t = mv_error_text(a);
        T_ASSERTF(t[0] && strcmp(t, "?") && strcmp(t, "ok"), "id %d has no text", a);
        for (int b = MV_ERR_BASE + 1; b < a; b++)
            T_ASSERTF(strcmp(t, mv_error_text(b)), "ids %d and %d share the text \"%s\"", b, a, t);
    }
    T_ASSERT(!strcmp(mv_error_text(MV_ERR_END), "?"));
}

T_MAIN({"error_ids_have_texts", t_error_ids_have_texts}, {"header_420jpeg", t_header_420jpeg}, {"header_colorspaces", t_header_colorspaces},
       {"header_defaults", t_header_defaults}, {"header_rate_aspect", t_header_rate_aspect},
       {"header_range", t_header_range}, {"header_matrix", t_header_matrix},
       {"header_matrix_guess", t_header_matrix_guess}, {"header_ignores_unknown", t_header_ignores_unknown},
       {"header_refuse_interlaced", t_header_refuse_interlaced},
       {"header_refuse_colorspace", t_header_refuse_colorspace}, {"header_refuse_size", t_header_refuse_size},
       {"header_refuse_rate", t_header_refuse_rate}, {"header_bounds", t_header_bounds},
       {"file_read_frames", t_file_read_frames}, {"file_frame_params", t_file_frame_params},
       {"file_empty_stream", t_file_empty_stream}, {"file_truncated_data", t_file_truncated_data},
       {"file_truncated_header", t_file_truncated_header}, {"file_bad_frame_header", t_file_bad_frame_header},
       {"file_bad_header", t_file_bad_header}, {"file_open_errors", t_file_open_errors},
       {"fuzz_header", t_fuzz_header}, {"fuzz_files", t_fuzz_files})
