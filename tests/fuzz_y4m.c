/* libFuzzer target for the movie sources' own parsing (player/): mv_open's
 * choice of reader by content (mv_src.c) and the Y4M reader (mv_y4m.c),
 * its header line and its frames.  `make fuzz` builds it; seeds in
 * tests/fuzz/y4m/.  The input is a movie file, given to mv_open as a file
 * (a memfd: the reader stats and reads it as any file).  This build has no
 * FFmpeg, so what is not Y4M must be refused by the FFmpeg reader's
 * fallback, an empty file as empty.  A Y4M file that opens must hold the
 * header's documented bounds, give the same header as
 * mv_y4m_parse_header on its first line, and write back (the tags this
 * reader keeps) to a header that parses to the same; its frames are read
 * to the end, and an error must name the file and stay (the next read
 * fails the same way).  The capture side only writes Y4M (cap_sink_y4m.c):
 * there is no other Y4M parser. */
#define _GNU_SOURCE /* memfd_create */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "../player/mv.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

enum { FRAMES_MAX = 64, FRAME_BYTES_MAX = 1 << 20 };

static bool same_header(const mv_info *a, const mv_info *b)
{
    return a->w == b->w && a->h == b->h && a->cw == b->cw && a->ch == b->ch && a->sx == b->sx && a->sy == b->sy &&
           a->mono == b->mono && a->matrix == b->matrix && a->full_range == b->full_range &&
           a->matrix_guessed == b->matrix_guessed && a->chroma_loc == b->chroma_loc && a->fps_num == b->fps_num &&
           a->fps_den == b->fps_den && a->sar_num == b->sar_num && a->sar_den == b->sar_den &&
           !strcmp(a->codec, b->codec) && !strcmp(a->pixfmt, b->pixfmt);
}

static void check_header(const mv_info *i, const uint8_t *data, size_t size)
{
    bool ok = i->w >= 1 && i->w <= 16384 && i->h >= 1 && i->h <= 16384 && i->fps_num > 0 && i->fps_den > 0 &&
              i->sar_num > 0 && i->sar_den > 0 && (i->matrix == MV_BT601 || i->matrix == MV_BT709) &&
              !strcmp(i->codec, "y4m") && i->frames >= -1 &&
              (i->mono ? i->cw == 0 && i->ch == 0
                       : i->sx >= 0 && i->sx <= 1 && i->sy >= 0 && i->sy <= 1 &&
                             i->cw == (i->w + (1 << i->sx) - 1) >> i->sx && i->ch == (i->h + (1 << i->sy) - 1) >> i->sy);
    if (!ok)
        abort();
    /* the same header from the parser alone, on the first line after the magic */
    const uint8_t *nl = memchr(data, '\n', size);
    mv_info alone, back;
    rs_err err = {0};
    if (!nl || !mv_y4m_parse_header((const char *)data + 10, (size_t)(nl - data) - 10, &alone, &err) ||
        !same_header(i, &alone))
        abort();
    /* written back with the tags kept, it reads as the same */
    char hdr[256];
    int n = snprintf(hdr, sizeof hdr, "W%d H%d F%d:%d Ip A%d:%d C%s XCOLORRANGE=%s%s", i->w, i->h, i->fps_num,
                     i->fps_den, i->sar_num, i->sar_den, i->pixfmt, i->full_range ? "FULL" : "LIMITED",
                     i->matrix_guessed ? "" : i->matrix == MV_BT709 ? " XCOLORMATRIX=BT709" : " XCOLORMATRIX=BT601");
    if (n <= 0 || (size_t)n >= sizeof hdr || !mv_y4m_parse_header(hdr, (size_t)n, &back, &err) ||
        !same_header(i, &back))
        abort();
}

static void read_frames(mv_src *s, const char *path)
{
    size_t bytes = mv_frame_bytes(&s->info);
    if (bytes > FRAME_BYTES_MAX) /* -max_len keeps such a frame from ever being whole */
        return;
    uint8_t *frame = malloc(bytes);
    rs_err err = {0};
    int r = 1;
    for (int k = 0; k < FRAMES_MAX && r == 1; k++)
        r = s->read(s, frame, &err);
    if (r < 0) {
        if (strncmp(err.msg, path, strlen(path)) != 0 ||
            (err.code != MV_ERR_FORMAT && err.code != MV_ERR_TRUNCATED && err.code != MV_ERR_OPEN))
            abort();
        rs_err again = {0};
        if (s->read(s, frame, &again) != -1 || again.code != err.code || strcmp(again.msg, err.msg) != 0)
            abort(); /* errors are sticky */
    }
    free(frame);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int fd = -1;
    static char path[64];
    if (fd < 0) {
        fd = memfd_create("fuzz.y4m", 0);
        if (fd < 0)
            abort();
        snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    }
    if (ftruncate(fd, 0) != 0 || (size && pwrite(fd, data, size, 0) != (ssize_t)size))
        abort();
    rs_err err = {0};
    mv_src *s = mv_open(path, &err);
    bool y4m = size >= 10 && !memcmp(data, "YUV4MPEG2 ", 10);
    if (!s) {
        int want = size == 0 ? MV_ERR_FORMAT : y4m ? err.code : MV_ERR_UNSUPPORTED;
        if (err.code != want || strncmp(err.msg, path, strlen(path)) != 0 ||
            (y4m && err.code != MV_ERR_FORMAT && err.code != MV_ERR_UNSUPPORTED && err.code != MV_ERR_NOMEM))
            abort();
        return 0;
    }
    if (!y4m)
        abort(); /* no other reader in this build */
    check_header(&s->info, data, size);
    read_frames(s, path);
    mv_close(s);
    return 0;
}
