/* Movie sources: picking a reader, and the facts every reader shares. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "mv.h"

const char *mv_error_text(int code)
{
    static const char *const text[] = {
#define X(id, t) t,
        MV_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_MV, text, (int)(sizeof text / sizeof text[0]));
}

void mv_info_planes(mv_info *i)
{
    if (i->mono) {
        i->cw = i->ch = 0;
        i->sx = i->sy = 0;
        return;
    }
    i->cw = (i->w + (1 << i->sx) - 1) >> i->sx;
    i->ch = (i->h + (1 << i->sy) - 1) >> i->sy;
}

int mv_guess_matrix(int w, int h)
{
    return (w >= 1280 || h > 576) ? MV_BT709 : MV_BT601;
}

mv_src *mv_open(const char *path, rs_err *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        rs_fail(err, MV_ERR_OPEN, "%s: %s", path, strerror(errno));
        return NULL;
    }
    char magic[10];
    size_t n = fread(magic, 1, sizeof magic, f);
    fclose(f);
    if (n == sizeof magic && !memcmp(magic, "YUV4MPEG2 ", sizeof magic))
        return mv_y4m_open(path, err);
    if (n == 0) {
        rs_fail(err, MV_ERR_FORMAT, "%s: empty file", path);
        return NULL;
    }
    return mv_ffmpeg_open(path, err);
}

void mv_close(mv_src *s)
{
    if (s)
        s->close(s);
}
