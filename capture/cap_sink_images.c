/* Image sequences through OpenImageIO: name%06d.png, .exr or .tif, one
 * RGBA file per frame.  Each file is encoded in memory and written as
 * "<name>.part" with every write checked (rs_oiio_write), then renamed, so
 * no half-written image ever carries a final name; a failed render removes
 * the frames it wrote, so no partial sequence looks finished. */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "../runtime/util/rs_out.h"
#include "../runtime/util/rs_oiio.h"
#include "cap_sink.h"

typedef struct seq {
    char ext[8];
} seq;

/* Accepts exactly one %d / %0Nd conversion (N at most two digits) and no
 * other '%': the pattern is used as a printf format, so nothing else may
 * reach it. */
bool cap_images_pattern_ok(const char *path, const char **ext)
{
    const char *p = strchr(path, '%'), *slash = strrchr(path, '/');
    if (!p || strchr(p + 1, '%') || (slash && slash > p)) /* the number goes in the file name */
        return false;
    const char *q = p + 1;
    if (*q == '0')
        q++;
    int digits = 0;
    while (*q >= '0' && *q <= '9' && digits < 3)
        q++, digits++;
    if (*q != 'd' || digits > 2)
        return false;
    const char *dot = strrchr(path, '.');
    if (!dot || dot < q)
        return false;
    *ext = dot;
    return !strcasecmp(dot, ".png") || !strcasecmp(dot, ".exr") || !strcasecmp(dot, ".tif") || !strcasecmp(dot, ".tiff");
}

static void frame_path(const cap_sink *s, uint64_t index, char *out, size_t n)
{
    snprintf(out, n, s->path, (int)(index + s->index_base)); /* the pattern was checked by cap_images_pattern_ok */
}

static bool img_open(cap_sink *s, rs_err *err)
{
    seq *q = calloc(1, sizeof *q);
    const char *ext;
    if (!q)
        return rs_fail(err, CAP_ERR_NOMEM, "out of memory");
    if (!cap_images_pattern_ok(s->path, &ext)) {
        free(q);
        return rs_fail(err, CAP_ERR_OUTPUT, "%s: expected an image sequence pattern like name%%06d.png", s->path);
    }
    snprintf(q->ext, sizeof q->ext, "%s", ext);
    for (char *c = q->ext; *c; c++) /* F%04d.PNG is a PNG */
        if (*c >= 'A' && *c <= 'Z')
            *c = (char)(*c - 'A' + 'a');
    s->impl = q;
    rs_err oerr = {0};
    if (!rs_oiio_ready(&oerr)) /* OpenImageIO is loaded when first used: here, before any frame */
        return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: %s", s->path, oerr.msg);
    char first[1100];
    frame_path(s, 0, first, sizeof first);
    /* the folder must exist, as for every output kind (rs_out.h); whether
     * frames may be overwritten is the command's check, made before this */
    if (rs_out_check(first, true, err))
        return true;
    if (err)
        err->code = CAP_ERR_CREATE; /* rs_out's failure, as one of ours */
    return false;
}

static bool img_write(cap_sink *s, const uint8_t *frame, uint64_t index, rs_err *err)
{
    seq *q = s->impl;
    char path[1100], part[1120];
    frame_path(s, index, path, sizeof path);
    snprintf(part, sizeof part, "%s.part", path);
    if (!q)
        return rs_fail(err, CAP_ERR_ARG, "%s: the image sequence is not open", path);
    rs_err oerr = {0};
    if (!rs_oiio_write(part, q->ext, s->w, s->h, frame, &oerr)) {
        unlink(part);
        /* the frame's own name first, then the reason and the temporary it was written as */
        size_t k = strlen(part);
        bool named = !strncmp(oerr.msg, part, k) && !strncmp(oerr.msg + k, ": ", 2);
        return rs_fail(err, CAP_ERR_WRITE, "%s: cannot write frame %" PRIu64 ": %s (writing %s)", path, index,
                       named ? oerr.msg + k + 2 : oerr.msg, part);
    }
    if (rename(part, path) != 0) {
        int e = errno;
        unlink(part);
        return rs_fail(err, CAP_ERR_WRITE, "%s: cannot rename into place: %s", path, strerror(e));
    }
    s->frames = index + 1;
    return true;
}

static bool img_close(cap_sink *s, bool ok, rs_err *err)
{
    (void)err;
    free(s->impl);
    s->impl = NULL;
    if (!ok) /* a partial sequence must not look finished */
        for (uint64_t i = 0; i < s->frames; i++) {
            char path[1100];
            frame_path(s, i, path, sizeof path);
            unlink(path);
        }
    return ok;
}

const cap_sink_ops cap_sink_images = {"images", img_open, img_write, img_close};
