/* Sink registry: the output's extension picks the sink. */
#include <stdio.h>
#include <string.h>

#include "cap_out.h"
#include "cap_sink.h"

size_t cap_frame_bytes(cap_pixfmt fmt, int w, int h)
{
    return fmt == CAP_RGBA ? (size_t)w * h * 4 : (size_t)w * h + 2 * ((size_t)(w / 2) * (h / 2));
}

static const char *ext_of(const char *path)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    return dot && (!slash || dot > slash) ? dot : "";
}

#ifdef RS_HAVE_FFMPEG
bool cap_ffmpeg_check(const char *path, const char *ext, rs_err *err);
extern const cap_sink_ops cap_sink_ffmpeg;
#endif

bool cap_images_pattern_ok(const char *path, const char **ext);
extern const cap_sink_ops cap_sink_images;

const char *cap_sink_formats(void)
{
#if defined(RS_HAVE_FFMPEG) && defined(RS_HAVE_OIIO)
    return ".y4m, .mp4, .mkv (H.264), .webm (VP9), name%06d.png|.exr|.tif";
#elif defined(RS_HAVE_FFMPEG)
    return ".y4m, .mp4, .mkv (H.264), .webm (VP9) (no OpenImageIO: no image sequences)";
#elif defined(RS_HAVE_OIIO)
    return ".y4m, name%06d.png|.exr|.tif (no FFmpeg: no .mp4/.mkv/.webm)";
#else
    return ".y4m (this build has neither FFmpeg nor OpenImageIO)";
#endif
}

const char *cap_error_text(int code)
{
    static const char *const text[] = {
#define X(id, t) t,
        CAP_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_CAP, text, (int)(sizeof text / sizeof text[0]));
}

const char *cap_error_name(int code)
{
    static const char *const name[] = {
#define X(id, t) #id,
        CAP_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_CAP, name, (int)(sizeof name / sizeof name[0]));
}

bool cap_sink_for(const char *path, int w, int h, cap_sink *s, rs_err *err)
{
    memset(s, 0, sizeof *s);
    snprintf(s->path, sizeof s->path, "%s", path);
    s->w = w;
    s->h = h;
    s->fmt = CAP_I420;
    const char *ext = ext_of(path);
    const char *iext;
    if (strchr(path, '%')) {
        if (!cap_images_pattern_ok(path, &iext))
            return rs_fail(err, CAP_ERR_OUTPUT, "%s: an image sequence needs one %%d or %%0Nd (two digits at most) in the file name and .png, .exr or .tif (e.g. frame%%06d.png)",
                           path);
#ifdef RS_HAVE_OIIO
        s->ops = &cap_sink_images;
        s->fmt = CAP_RGBA;
        return true;
#else
        return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this build has no OpenImageIO, so no image sequences (use .y4m)", path);
#endif
    }
    if (!strcmp(path, "null:")) {
        s->ops = &cap_sink_null;
        return true;
    }
    if (!strcmp(ext, ".y4m") || cap_out_is_stream(path)) { /* streams get Y4M, whatever their name */
        s->ops = &cap_sink_y4m;
        return true;
    }
    if (!strcmp(ext, ".mp4") || !strcmp(ext, ".mkv") || !strcmp(ext, ".webm")) {
#ifdef RS_HAVE_FFMPEG
        s->ops = &cap_sink_ffmpeg;
        return cap_ffmpeg_check(path, ext, err);
#else
        return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this build has no FFmpeg libraries, so no %s output (use .y4m)", path, ext);
#endif
    }
    return rs_fail(err, CAP_ERR_OUTPUT, "%s: unknown output type '%s' (this build writes %s)", path, ext, cap_sink_formats());
}
