/* Sink registry: the output's extension picks the sink. */
#include <stdio.h>
#include <string.h>

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

const char *cap_sink_formats(void)
{
#ifdef RS_HAVE_FFMPEG
    return ".y4m, .mp4, .mkv (H.264), .webm (VP9)";
#else
    return ".y4m (this build has no FFmpeg: no .mp4/.mkv/.webm)";
#endif
}

bool cap_sink_for(const char *path, int w, int h, cap_sink *s, rs_err *err)
{
    memset(s, 0, sizeof *s);
    snprintf(s->path, sizeof s->path, "%s", path);
    s->w = w;
    s->h = h;
    s->fmt = CAP_I420;
    const char *ext = ext_of(path);
    if (!strcmp(path, "null:")) {
        s->ops = &cap_sink_null;
        return true;
    }
    if (!strcmp(ext, ".y4m") || !strncmp(path, "/dev/", 5)) {
        s->ops = &cap_sink_y4m;
        return true;
    }
    if (!strcmp(ext, ".mp4") || !strcmp(ext, ".mkv") || !strcmp(ext, ".webm")) {
#ifdef RS_HAVE_FFMPEG
        s->ops = &cap_sink_ffmpeg;
        return cap_ffmpeg_check(path, ext, err);
#else
        return rs_fail(err, 1, "%s: this build has no FFmpeg libraries, so no %s output (use .y4m)", path, ext);
#endif
    }
    return rs_fail(err, 1, "%s: unknown output type '%s' (this build writes %s)", path, ext, cap_sink_formats());
}
