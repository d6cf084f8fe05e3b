/* Sink registry: the output's extension (any case) or --format picks the sink. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

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
    return ".y4m, .mp4, .mkv, .nut (H.264 unless --codec), .webm (VP9 unless --codec), name%06d.png|.exr|.tif";
#elif defined(RS_HAVE_FFMPEG)
    return ".y4m, .mp4, .mkv, .nut (H.264 unless --codec), .webm (VP9 unless --codec) (no OpenImageIO: no image sequences)";
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

/* The extension, lower case, into out ("" when there is none). */
static void lower_ext(const char *path, char *out, size_t n)
{
    snprintf(out, n, "%s", ext_of(path));
    for (char *c = out; *c; c++)
        if (*c >= 'A' && *c <= 'Z')
            *c = (char)(*c - 'A' + 'a');
}

static bool is_image_ext(const char *ext)
{
    return !strcmp(ext, ".png") || !strcmp(ext, ".exr") || !strcmp(ext, ".tif") || !strcmp(ext, ".tiff");
}

bool cap_sink_for(const char *path, int w, int h, cap_sink *s, rs_err *err)
{
    return cap_sink_for_format(path, NULL, w, h, s, err);
}

bool cap_sink_for_format(const char *path, const char *format, int w, int h, cap_sink *s, rs_err *err)
{
    memset(s, 0, sizeof *s);
    snprintf(s->path, sizeof s->path, "%s", path);
    s->w = w;
    s->h = h;
    s->fmt = CAP_I420;
    char ext[16];
    lower_ext(path, ext, sizeof ext);
    const char *iext;
    if (strchr(path, '%')) {
        if (format)
            return rs_fail(err, CAP_ERR_OUTPUT, "%s: --format %s: an image sequence takes its type from the extension", path, format);
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
    bool stream = cap_out_is_stream(path);
    if (format) {
        if (strcmp(format, "y4m") && strcmp(format, "nut") && strcmp(format, "mkv") && strcmp(format, "mp4") &&
            strcmp(format, "webm"))
            return rs_fail(err, CAP_ERR_OUTPUT, "%s: --format '%s': expected y4m, nut, mkv, mp4 or webm", path, format);
        snprintf(ext, sizeof ext, ".%s", format);
    } else if (stream) { /* streams get Y4M, whatever their name */
        snprintf(ext, sizeof ext, ".y4m");
    } else if (is_image_ext(ext)) {
        int stem = (int)(strlen(path) - strlen(ext));
        return rs_fail(err, CAP_ERR_OUTPUT, "%s: a single image name; use a pattern such as %.*s%%06d%s", path, stem, path,
                       ext_of(path));
    }
    snprintf(s->ext, sizeof s->ext, "%s", ext);
    if (!strcmp(ext, ".y4m")) {
        s->ops = &cap_sink_y4m;
        return true;
    }
    if (!strcmp(ext, ".mp4") || !strcmp(ext, ".mkv") || !strcmp(ext, ".webm") || !strcmp(ext, ".nut")) {
        /* DESIGN: MP4 puts its index after the media and seeks back to it;
         * a pipe cannot seek, so refuse rather than write a broken file */
        struct stat st;
        if (!strcmp(ext, ".mp4") && stream && (!strcmp(path, "-") || (stat(path, &st) == 0 && !S_ISCHR(st.st_mode))))
            return rs_fail(err, CAP_ERR_OUTPUT, "%s: MP4 cannot be written to a pipe (its index goes last); use --format mkv", path);
#ifdef RS_HAVE_FFMPEG
        s->ops = &cap_sink_ffmpeg;
        return cap_ffmpeg_check(path, ext, err);
#else
        return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this build has no FFmpeg libraries, so no %s output (use .y4m)", path, ext);
#endif
    }
    return rs_fail(err, CAP_ERR_OUTPUT, "%s: unknown output type '%s' (this build writes %s)", path, ext_of(path), cap_sink_formats());
}
