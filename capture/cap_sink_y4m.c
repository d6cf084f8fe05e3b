/* YUV4MPEG2: the dependency-free video sink.  Every player and FFmpeg read
 * it; it is raw, so it is as big as the frames. */
#include <stdlib.h>
#include <string.h>

#include "cap_out.h"
#include "cap_sink.h"

static bool y4m_open(cap_sink *s, rs_err *err)
{
    cap_out *o = calloc(1, sizeof *o);
    if (!o)
        return rs_fail(err, CAP_ERR_NOMEM, "out of memory");
    if (!cap_out_open(o, s->path, err)) {
        free(o);
        return false;
    }
    s->impl = o;
    char hdr[128];
    int n = snprintf(hdr, sizeof hdr, "YUV4MPEG2 W%d H%d F60:1 Ip A1:1 C420jpeg XCOLORRANGE=LIMITED\n", s->w, s->h);
    return cap_out_write(o, hdr, (size_t)n, err);
}

static bool y4m_write(cap_sink *s, const uint8_t *frame, uint64_t index, rs_err *err)
{
    (void)index;
    cap_out *o = s->impl;
    return cap_out_write(o, "FRAME\n", 6, err) && cap_out_write(o, frame, cap_frame_bytes(CAP_I420, s->w, s->h), err);
}

static bool y4m_close(cap_sink *s, bool ok, rs_err *err)
{
    cap_out *o = s->impl;
    if (!o)
        return !ok;
    bool r = cap_out_close(o, ok, err);
    free(o);
    s->impl = NULL;
    return r;
}

const cap_sink_ops cap_sink_y4m = {"y4m", y4m_open, y4m_write, y4m_close};

static bool null_open(cap_sink *s, rs_err *err)
{
    (void)s, (void)err;
    return true;
}
static bool null_write(cap_sink *s, const uint8_t *frame, uint64_t index, rs_err *err)
{
    (void)s, (void)frame, (void)index, (void)err;
    return true;
}
static bool null_close(cap_sink *s, bool ok, rs_err *err)
{
    (void)s, (void)err;
    return ok;
}
const cap_sink_ops cap_sink_null = {"null", null_open, null_write, null_close};
