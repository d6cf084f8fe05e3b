/* Encoder choice and set-up for the FFmpeg sink: the table of encoders,
 * the checks of --codec/--crf/--bitrate/--preset/--pix-fmt/--hw against
 * the container and the encoder, the hardware probe, filling frames, and
 * the in-memory round trip of `bench encode`.  cap_enc.h has the contract.
 *
 * DESIGN
 * - Presets are the encoder's own names, checked through its AVOptions:
 *   an option with named constants (NVENC's p1..p7) takes those, an
 *   integer one (SVT-AV1's preset, libvpx's cpu-used) its range; x264 and
 *   x265 take a plain string their library checks only when it opens, so
 *   their names are listed here (the libraries' own lists, which have not
 *   changed in years).
 * - CRF goes to each encoder's constant-quality knob: crf (x264, x265,
 *   libvpx, SVT-AV1, libaom), cq with VBR (NVENC), the QP of CQP (VAAPI).
 * - 4:4:4 frames come from the capture as RGBA and are converted here with
 *   the coefficients of cap_cpu_rgba_to_i420 (BT.709, limited range), so
 *   4:2:0 and 4:4:4 renders agree wherever chroma is flat.
 * - A hardware encoder is probed by opening it with the render's settings
 *   (and freeing it again): an NVENC in FFmpeg without a driver, or a
 *   VAAPI node whose driver lacks the codec, fails there, before a frame
 *   is drawn.  The probe's libav messages are caught, not printed: the
 *   reason goes into the one note line (s->enc_note).  Probing runs on the
 *   thread that calls cap_sink_encoder, before the writer thread exists,
 *   because the libav log callback is process-wide.
 * - A segment (--segment) does not try hardware unless asked by name: the
 *   segments of one job may run on different machines, and join needs one
 *   encoder's parameter sets in all of them. */
#include "cap_enc.h"

#include <ctype.h>
#include <glob.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

#include "cap_sink.h"

const char *const cap_meta_keys[] = {"title", "stage", "players", "winner", "ringside_version", NULL};

static const char *const codec_names[] = {"default", "h264", "hevc", "vp9", "av1"};

bool cap_codec_parse(const char *s, cap_codec *out)
{
    for (int i = 1; i < 5; i++)
        if (!strcmp(s, codec_names[i])) {
            *out = (cap_codec)i;
            return true;
        }
    return false;
}

const char *cap_codec_name(cap_codec c)
{
    return (unsigned)c < 5 ? codec_names[c] : "?";
}

bool cap_hw_parse(const char *s, cap_hw *out)
{
    static const char *const names[] = {"auto", "off", "nvenc", "vaapi"};
    for (int i = 0; i < 4; i++)
        if (!strcmp(s, names[i])) {
            *out = (cap_hw)i;
            return true;
        }
    return false;
}

bool cap_chroma_parse(const char *s, cap_chroma *out)
{
    if (!strcmp(s, "yuv420p"))
        *out = CAP_CHROMA_420;
    else if (!strcmp(s, "yuv444p"))
        *out = CAP_CHROMA_444;
    else
        return false;
    return true;
}

bool cap_bitrate_parse(const char *s, int64_t *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || !isdigit((unsigned char)s[0]))
        return false;
    if (*end == 'k' || *end == 'K')
        v *= 1e3, end++;
    else if (*end == 'm' || *end == 'M')
        v *= 1e6, end++;
    if (*end || v < 1e4 || v > 1e9)
        return false;
    *out = (int64_t)v;
    return true;
}

void cap_sink_meta(cap_sink *s, const char *key, const char *value)
{
    if (!value || !value[0] || s->n_meta >= CAP_META_MAX)
        return;
    cap_meta *m = &s->meta[s->n_meta++];
    snprintf(m->key, sizeof m->key, "%s", key);
    snprintf(m->value, sizeof m->value, "%s", value);
}

static bool enc_is_zero(const cap_enc *e)
{
    static const cap_enc zero;
    return !memcmp(e, &zero, sizeof zero);
}

#ifdef RS_HAVE_FFMPEG
#include <libavutil/hwcontext.h>
#include <libavutil/opt.h>
#include <libavutil/pixdesc.h>

#include "cap_enc_local.h"

extern const cap_sink_ops cap_sink_ffmpeg;

static const char *const x26x_presets[] = {"ultrafast", "superfast", "veryfast", "faster",   "fast",
                                           "medium",    "slow",      "slower",   "veryslow", "placebo", NULL};

/* One encoder.  Rows of a codec in the order they are tried. */
typedef struct enc_row {
    cap_codec codec;
    const char *name;
    cap_hw hw;                        /* CAP_HW_OFF: software */
    const char *preset_opt;           /* the AVOption --preset sets; NULL: none */
    const char *const *preset_names;  /* for a string option: the names it takes */
    const char *preset_default;
    int crf_default, crf_max;
    int min_side;                     /* smallest width and height it encodes; 0: any */
} enc_row;

/* Defaults: docs/capture.md, "Encoders", has the measurements they come from. */
static const enc_row rows[] = {
    {CAP_CODEC_H264, "h264_nvenc", CAP_HW_NVENC, "preset", NULL, "p4", 23, 51, 0},
    {CAP_CODEC_H264, "h264_vaapi", CAP_HW_VAAPI, NULL, NULL, NULL, 23, 51, 0},
    {CAP_CODEC_H264, "libx264", CAP_HW_OFF, "preset", x26x_presets, "veryfast", 20, 51, 0},
    {CAP_CODEC_HEVC, "hevc_nvenc", CAP_HW_NVENC, "preset", NULL, "p4", 25, 51, 0},
    {CAP_CODEC_HEVC, "hevc_vaapi", CAP_HW_VAAPI, NULL, NULL, NULL, 25, 51, 0},
    {CAP_CODEC_HEVC, "libx265", CAP_HW_OFF, "preset", x26x_presets, "superfast", 20, 51, 0},
    {CAP_CODEC_VP9, "vp9_vaapi", CAP_HW_VAAPI, NULL, NULL, NULL, 100, 255, 0},
    {CAP_CODEC_VP9, "libvpx-vp9", CAP_HW_OFF, "cpu-used", NULL, "8", 32, 63, 0},
    {CAP_CODEC_AV1, "av1_nvenc", CAP_HW_NVENC, "preset", NULL, "p4", 30, 51, 0},
    {CAP_CODEC_AV1, "av1_vaapi", CAP_HW_VAAPI, NULL, NULL, NULL, 100, 255, 0},
    {CAP_CODEC_AV1, "libsvtav1", CAP_HW_OFF, "preset", NULL, "10", 35, 63, 64},
    {CAP_CODEC_AV1, "libaom-av1", CAP_HW_OFF, "cpu-used", NULL, "8", 32, 63, 0},
};
#define NROWS ((int)(sizeof rows / sizeof rows[0]))

static const enc_row *row_named(const char *name)
{
    for (int i = 0; i < NROWS; i++)
        if (!strcmp(rows[i].name, name))
            return &rows[i];
    return NULL;
}

static const char *hw_name(cap_hw hw)
{
    return hw == CAP_HW_NVENC ? "NVENC" : "VAAPI";
}

static enum AVPixelFormat sw_pix(const cap_enc *e)
{
    return e->chroma == CAP_CHROMA_444 ? AV_PIX_FMT_YUV444P : AV_PIX_FMT_YUV420P;
}

static bool takes_pix(const AVCodec *c, enum AVPixelFormat want)
{
    if (!c->pix_fmts)
        return true;
    for (const enum AVPixelFormat *p = c->pix_fmts; *p != AV_PIX_FMT_NONE; p++)
        if (*p == want)
            return true;
    return false;
}

/* The software encoder for e at w x h: the first of its codec's rows that this FFmpeg has and that takes the
 * chroma and the size (SVT-AV1 needs 64x64; libaom-av1 takes smaller). */
static const enc_row *soft_row(const cap_enc *e, int w, int h)
{
    for (int i = 0; i < NROWS; i++) {
        const AVCodec *c = avcodec_find_encoder_by_name(rows[i].name);
        if (rows[i].codec == e->codec && rows[i].hw == CAP_HW_OFF && c && takes_pix(c, sw_pix(e)) &&
            w >= rows[i].min_side && h >= rows[i].min_side)
            return &rows[i];
    }
    return NULL;
}

/* The container's name for libavformat and whether it holds the codec. */
static const char *container_of(const cap_sink *s)
{
    /* the sink's container (from --format or the name, any case), else the name's */
    const char *dot = s->ext[0] ? s->ext : strrchr(s->path, '.');
    if (dot && !strcasecmp(dot, ".mkv"))
        return "matroska";
    if (dot && !strcasecmp(dot, ".webm"))
        return "webm";
    if (dot && !strcasecmp(dot, ".nut"))
        return "nut";
    return "mp4";
}

static bool container_takes(const char *fmt, cap_codec c)
{
    if (!strcmp(fmt, "mp4"))
        return c != CAP_CODEC_VP9; /* FFmpeg writes VP9 in MP4, but browsers and players expect WebM or MKV */
    if (!strcmp(fmt, "webm"))
        return c == CAP_CODEC_VP9 || c == CAP_CODEC_AV1;
    return true;
}

/* Is name one of row's presets?  Fills `choices` with them for the message. */
static bool preset_ok(const enc_row *row, const AVCodec *codec, const char *name, char *choices, size_t n)
{
    choices[0] = 0;
    if (!row->preset_opt) {
        snprintf(choices, n, "none: %s has no presets", row->name);
        return false;
    }
    if (row->preset_names) {
        bool found = false;
        size_t len = 0;
        for (int i = 0; row->preset_names[i]; i++) {
            found |= !strcmp(name, row->preset_names[i]);
            len += (size_t)snprintf(choices + len, len < n ? n - len : 0, "%s%s", i ? ", " : "", row->preset_names[i]);
        }
        return found;
    }
    void *cls = (void *)&codec->priv_class; /* a "fake object": the class alone (av_opt_find's AV_OPT_SEARCH_FAKE_OBJ) */
    const AVOption *o = codec->priv_class ? av_opt_find(cls, row->preset_opt, NULL, 0, AV_OPT_SEARCH_FAKE_OBJ) : NULL;
    if (!o) {
        snprintf(choices, n, "none: this FFmpeg's %s has no %s option", row->name, row->preset_opt);
        return false;
    }
    if (o->unit) {
        bool found = false;
        size_t len = 0;
        for (const AVOption *c = NULL; (c = av_opt_next(cls, c));)
            if (c->type == AV_OPT_TYPE_CONST && c->unit && !strcmp(c->unit, o->unit)) {
                found |= !strcmp(name, c->name);
                len += (size_t)snprintf(choices + len, len < n ? n - len : 0, "%s%s", len ? ", " : "", c->name);
            }
        return found;
    }
    /* an integer: the range the option allows (SVT-AV1's -1 and libvpx's negatives mean "the library's own
     * choice" and "realtime variants"; offered as they are) */
    snprintf(choices, n, "%.0f..%.0f", o->min, o->max);
    char *end;
    long v = strtol(name, &end, 10);
    return *name && !*end && v >= o->min && v <= o->max;
}

/* Can row encode enc?  why: the reason it cannot. */
static bool row_takes(const enc_row *row, const cap_enc *enc, char *why, size_t n)
{
    const AVCodec *codec = avcodec_find_encoder_by_name(row->name);
    char choices[400];
    if (!codec)
        snprintf(why, n, "this FFmpeg has no %s", row->name);
    else if (row->hw == CAP_HW_VAAPI && enc->chroma == CAP_CHROMA_444)
        snprintf(why, n, "%s encodes 4:2:0 only", row->name);
    else if (row->hw == CAP_HW_OFF && !takes_pix(codec, sw_pix(enc)))
        snprintf(why, n, "%s does not take %s", row->name, av_get_pix_fmt_name(sw_pix(enc)));
    else if (enc->preset[0] && !preset_ok(row, codec, enc->preset, choices, sizeof choices))
        snprintf(why, n, "--preset '%s' is not one of %s's presets (%s)", enc->preset, row->name, choices);
    else if (enc->crf > row->crf_max)
        snprintf(why, n, "--crf %d: %s takes 1..%d", enc->crf, row->name, row->crf_max);
    else
        return true;
    return false;
}

static bool node_exists(cap_hw hw, char *node, size_t n)
{
    if (hw == CAP_HW_NVENC) {
        snprintf(node, n, "/dev/nvidia0");
        return access(node, F_OK) == 0;
    }
    glob_t g;
    bool found = glob("/dev/dri/renderD*", 0, NULL, &g) == 0 && g.gl_pathc > 0;
    snprintf(node, n, "%s", found ? g.gl_pathv[0] : "/dev/dri/renderD*");
    if (found || g.gl_pathv)
        globfree(&g);
    return found;
}

/* The probe's libav messages, kept for the note instead of printed. */
static char probe_msg[200];

static void probe_log(void *avcl, int level, const char *fmt, va_list vl)
{
    (void)avcl;
    if (level > AV_LOG_ERROR)
        return;
    char line[200];
    vsnprintf(line, sizeof line, fmt, vl);
    line[strcspn(line, "\n")] = 0;
    if (line[0])
        snprintf(probe_msg, sizeof probe_msg, "%s", line);
}

static bool probe(cap_sink *s, const enc_row *row, char *why, size_t n)
{
    cap_encoder x = {0};
    rs_err e = {0};
    snprintf(s->enc_name, sizeof s->enc_name, "%s", row->name);
    probe_msg[0] = 0;
    av_log_set_callback(probe_log);
    bool ok = cap_encoder_open(&x, s, true, &e);
    av_log_set_callback(av_log_default_callback);
    cap_encoder_close(&x);
    if (!ok)
        snprintf(why, n, "%s%s%s", e.msg, probe_msg[0] ? ": " : "", probe_msg);
    s->enc_name[0] = 0;
    return ok;
}

static void append(char *buf, size_t n, const char *text)
{
    size_t len = strlen(buf);
    snprintf(buf + len, n - len, "%s%s", len ? ", " : "", text);
}

bool cap_sink_encoder(cap_sink *s, const cap_enc *enc, rs_err *err)
{
    s->enc_note[0] = s->enc_name[0] = 0;
    if (s->ops != &cap_sink_ffmpeg) {
        if (!enc_is_zero(enc))
            return rs_fail(err, CAP_ERR_ENC_SETTING,
                           "%s: --codec, --crf, --bitrate, --preset, --pix-fmt and --hw apply to .mp4, .mkv and .webm outputs",
                           s->path);
        return true;
    }
    const char *fmt = container_of(s);
    cap_enc e = *enc;
    if (!e.codec)
        e.codec = !strcmp(fmt, "webm") ? CAP_CODEC_VP9 : CAP_CODEC_H264;
    if (!container_takes(fmt, e.codec))
        return rs_fail(err, CAP_ERR_ENC_SETTING, "%s: %s does not hold %s (%s)", s->path, !strcmp(fmt, "webm") ? "WebM" : "MP4",
                       cap_codec_name(e.codec),
                       !strcmp(fmt, "webm") ? "WebM takes vp9 or av1; use .mp4 or .mkv" : "MP4 takes h264, hevc or av1; use .webm or .mkv");
    if (s->segment && e.hw == CAP_HW_AUTO)
        e.hw = CAP_HW_OFF; /* segments of one video may be rendered on machines with and without a GPU: they must
                            * all get the same encoder, or join cannot stream-copy them (--hw nvenc still asks) */
    if (e.crf && e.bitrate)
        return rs_fail(err, CAP_ERR_ENC_SETTING, "%s: --crf and --bitrate exclude each other (constant quality or an average rate)",
                       s->path);
    s->enc = e;
    s->fmt = e.chroma == CAP_CHROMA_444 ? CAP_RGBA : CAP_I420; /* 4:4:4: converted in cap_encoder_send */
    char why[600];
    if (e.hw == CAP_HW_NVENC || e.hw == CAP_HW_VAAPI) {
        const enc_row *row = NULL;
        for (int i = 0; i < NROWS && !row; i++)
            if (rows[i].codec == e.codec && rows[i].hw == e.hw)
                row = &rows[i];
        char node[64];
        if (!row)
            return rs_fail(err, CAP_ERR_ENC_HW, "%s: --hw %s: %s has no %s encoder (use --hw auto or off)", s->path,
                           e.hw == CAP_HW_NVENC ? "nvenc" : "vaapi", hw_name(e.hw), cap_codec_name(e.codec));
        if (!node_exists(e.hw, node, sizeof node))
            return rs_fail(err, CAP_ERR_ENC_HW, "%s: --hw %s: no device %s (%s); use --hw auto or off", s->path,
                           e.hw == CAP_HW_NVENC ? "nvenc" : "vaapi", node,
                           e.hw == CAP_HW_NVENC ? "no NVIDIA driver loaded" : "no DRM render node");
        if (!row_takes(row, &e, why, sizeof why) || !probe(s, row, why, sizeof why))
            return rs_fail(err, CAP_ERR_ENC_HW, "%s: --hw %s: %s", s->path, e.hw == CAP_HW_NVENC ? "nvenc" : "vaapi", why);
        snprintf(s->enc_name, sizeof s->enc_name, "%s", row->name);
        return true;
    }
    const enc_row *soft = soft_row(&e, s->w, s->h);
    if (!soft)
        return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this FFmpeg has no software %s encoder for %s at %dx%d", s->path,
                       cap_codec_name(e.codec), av_get_pix_fmt_name(sw_pix(&e)), s->w, s->h);
    if (!row_takes(soft, &e, why, sizeof why))
        return rs_fail(err, CAP_ERR_ENC_SETTING, "%s: %s", s->path, why);
    char tried[sizeof s->enc_note] = "";
    for (int i = 0; e.hw == CAP_HW_AUTO && i < NROWS; i++) {
        char node[64];
        const enc_row *row = &rows[i];
        if (row->codec != e.codec || row->hw == CAP_HW_OFF || !node_exists(row->hw, node, sizeof node))
            continue; /* no device, nothing to say */
        if (row_takes(row, &e, why, sizeof why) && probe(s, row, why, sizeof why)) {
            snprintf(s->enc_name, sizeof s->enc_name, "%s", row->name);
            if (tried[0])
                snprintf(s->enc_note, sizeof s->enc_note, "hardware encoder %s failed; using %s", tried, row->name);
            return true;
        }
        char one[700];
        snprintf(one, sizeof one, "%s (%s)", row->name, why);
        append(tried, sizeof tried, one);
    }
    if (tried[0])
        snprintf(s->enc_note, sizeof s->enc_note, "hardware encoder %s failed; using %s", tried, soft->name);
    snprintf(s->enc_name, sizeof s->enc_name, "%s", soft->name);
    return true;
}

const char *cap_enc_software(cap_codec c, int w, int h)
{
    const enc_row *row = soft_row(&(cap_enc){.codec = c}, w, h);
    return row ? row->name : NULL;
}

/* --- the encoder itself --- */

static int fail_av(rs_err *err, int id, const char *path, const char *what, int code)
{
    char msg[AV_ERROR_MAX_STRING_SIZE] = "";
    av_strerror(code, msg, sizeof msg);
    return rs_fail(err, id, "%s: %s: %s", path, what, msg);
}

/* Rate control and speed, in each encoder's own options. */
static void set_rate(AVCodecContext *c, const enc_row *row, const cap_enc *e)
{
    void *p = c->priv_data;
    int crf = e->bitrate ? 0 : e->crf ? e->crf : row->crf_default;
    const char *preset = e->preset[0] ? e->preset : row->preset_default;
    char num[16];
    snprintf(num, sizeof num, "%d", crf);
    c->bit_rate = e->bitrate;
    if (preset)
        av_opt_set(p, row->preset_opt, preset, 0);
    if (row->hw == CAP_HW_NVENC) {
        av_opt_set(p, "rc", "vbr", 0);
        if (crf)
            av_opt_set(p, "cq", num, 0);
    } else if (row->hw == CAP_HW_VAAPI) {
        av_opt_set(p, "rc_mode", crf ? "CQP" : "VBR", 0);
        c->global_quality = crf;
    } else if (crf) {
        av_opt_set(p, "crf", num, 0);
    }
    if (!strcmp(row->name, "libvpx-vp9"))
        /* libvpx's speed: realtime from cpu-used 5 up (the old fixed setting was realtime, 8), good below */
        av_opt_set(p, "deadline", atoi(preset) >= 5 ? "realtime" : "good", 0);
    if (!strcmp(row->name, "libx265"))
        av_opt_set(p, "x265-params", "log-level=error", 0); /* x265 prints its banner past av_log */
    if (!strcmp(row->name, "libsvtav1"))
        setenv("SVT_LOG", "1", 0); /* SVT-AV1's own log, errors only; read when the encoder starts */
}

bool cap_encoder_open(cap_encoder *x, const cap_sink *s, bool global_header, rs_err *err)
{
    const enc_row *row = row_named(s->enc_name);
    const AVCodec *codec = row ? avcodec_find_encoder_by_name(row->name) : NULL;
    if (!codec)
        return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this FFmpeg has no encoder '%s'", s->path, s->enc_name);
    int r = 0;
    if (!(x->ctx = avcodec_alloc_context3(codec)) || !(x->frame = av_frame_alloc()))
        return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", s->path);
    AVCodecContext *c = x->ctx;
    c->width = s->w;
    c->height = s->h;
    c->time_base = (AVRational){1, 60};
    c->framerate = (AVRational){60, 1};
    c->pix_fmt = sw_pix(&s->enc);
    c->gop_size = 120;
    c->color_range = AVCOL_RANGE_MPEG;
    c->colorspace = AVCOL_SPC_BT709;
    c->color_primaries = AVCOL_PRI_BT709;
    c->color_trc = AVCOL_TRC_BT709;
    c->chroma_sample_location = s->enc.chroma == CAP_CHROMA_444 ? AVCHROMA_LOC_UNSPECIFIED : AVCHROMA_LOC_CENTER;
    if (s->segment || s->closed_gop)
        c->flags |= AV_CODEC_FLAG_CLOSED_GOP;
    if (global_header)
        c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    set_rate(c, row, &s->enc);
    x->frame->format = c->pix_fmt;
    if (row->hw == CAP_HW_VAAPI) {
        char node[64];
        node_exists(CAP_HW_VAAPI, node, sizeof node);
        if ((r = av_hwdevice_ctx_create(&x->device, AV_HWDEVICE_TYPE_VAAPI, node, NULL, 0)) < 0)
            return fail_av(err, CAP_ERR_ENC_HW, s->path, node, r);
        AVBufferRef *frames = av_hwframe_ctx_alloc(x->device);
        if (!frames)
            return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", s->path);
        AVHWFramesContext *fc = (AVHWFramesContext *)frames->data;
        fc->format = AV_PIX_FMT_VAAPI;
        fc->sw_format = AV_PIX_FMT_NV12;
        fc->width = s->w;
        fc->height = s->h;
        fc->initial_pool_size = 8;
        if ((r = av_hwframe_ctx_init(frames)) < 0) {
            av_buffer_unref(&frames);
            return fail_av(err, CAP_ERR_ENC_HW, s->path, "VAAPI surfaces", r);
        }
        c->pix_fmt = AV_PIX_FMT_VAAPI;
        c->hw_frames_ctx = frames; /* the context owns it now */
        x->frame->format = AV_PIX_FMT_NV12;
        if (!(x->hw = av_frame_alloc()))
            return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", s->path);
    }
    if ((r = avcodec_open2(c, codec, NULL)) < 0)
        return fail_av(err, row->hw != CAP_HW_OFF ? CAP_ERR_ENC_HW : CAP_ERR_ENCODER, s->path, "cannot open the encoder", r);
    x->frame->width = s->w;
    x->frame->height = s->h;
    if ((r = av_frame_get_buffer(x->frame, 0)) < 0)
        return fail_av(err, CAP_ERR_NOMEM, s->path, "frame buffer", r);
    return true;
}

static uint8_t u8(double v)
{
    long r = lround(v);
    return (uint8_t)(r < 0 ? 0 : r > 255 ? 255 : r);
}

/* RGBA (top-down) -> 4:4:4 planes, BT.709 limited range: cap_cpu_rgba_to_i420 without the 2x2 average. */
static void rgba_to_444(const uint8_t *rgba, int w, int h, AVFrame *f)
{
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const uint8_t *p = rgba + ((size_t)y * w + x) * 4;
            double r = p[0] / 255.0, g = p[1] / 255.0, b = p[2] / 255.0;
            double l = 0.2126 * r + 0.7152 * g + 0.0722 * b;
            f->data[0][(size_t)y * f->linesize[0] + x] = u8(16 + 219 * l);
            f->data[1][(size_t)y * f->linesize[1] + x] = u8(128 + 224 * (b - l) / 1.8556);
            f->data[2][(size_t)y * f->linesize[2] + x] = u8(128 + 224 * (r - l) / 1.5748);
        }
}

static void i420_to_frame(const uint8_t *frame, int w, int h, AVFrame *f)
{
    const uint8_t *y = frame, *cb = frame + (size_t)w * h, *cr = cb + (size_t)(w / 2) * (h / 2);
    for (int row = 0; row < h; row++)
        memcpy(f->data[0] + (size_t)row * f->linesize[0], y + (size_t)row * w, (size_t)w);
    for (int row = 0; row < h / 2; row++) {
        const uint8_t *u = cb + (size_t)row * (w / 2), *v = cr + (size_t)row * (w / 2);
        if (f->format == AV_PIX_FMT_NV12) {
            uint8_t *uv = f->data[1] + (size_t)row * f->linesize[1];
            for (int k = 0; k < w / 2; k++)
                uv[2 * k] = u[k], uv[2 * k + 1] = v[k];
        } else {
            memcpy(f->data[1] + (size_t)row * f->linesize[1], u, (size_t)w / 2);
            memcpy(f->data[2] + (size_t)row * f->linesize[2], v, (size_t)w / 2);
        }
    }
}

bool cap_encoder_send(cap_encoder *x, const cap_sink *s, const uint8_t *frame, int64_t pts, rs_err *err)
{
    int r = av_frame_make_writable(x->frame);
    if (r < 0)
        return fail_av(err, CAP_ERR_NOMEM, s->path, "frame buffer", r);
    if (s->fmt == CAP_RGBA)
        rgba_to_444(frame, s->w, s->h, x->frame);
    else
        i420_to_frame(frame, s->w, s->h, x->frame);
    AVFrame *send = x->frame;
    if (x->hw) {
        av_frame_unref(x->hw);
        if ((r = av_hwframe_get_buffer(x->ctx->hw_frames_ctx, x->hw, 0)) < 0 ||
            (r = av_hwframe_transfer_data(x->hw, x->frame, 0)) < 0)
            return fail_av(err, CAP_ERR_ENCODER, s->path, "uploading to VAAPI", r);
        send = x->hw;
    }
    send->pts = pts;
    if ((r = avcodec_send_frame(x->ctx, send)) < 0) {
        char what[64];
        snprintf(what, sizeof what, "encoding frame %lld", (long long)pts);
        return fail_av(err, CAP_ERR_ENCODER, s->path, what, r);
    }
    return true;
}

void cap_encoder_close(cap_encoder *x)
{
    av_frame_free(&x->hw);
    av_frame_free(&x->frame);
    avcodec_free_context(&x->ctx);
    av_buffer_unref(&x->device);
}

/* --- bench encode: encode, decode back --- */

static bool decode_into(AVCodecContext *d, AVPacket *pkt, AVFrame *f, uint8_t *out, int w, int h, int n, int *got,
                        rs_err *err)
{
    int r = avcodec_send_packet(d, pkt);
    if (r < 0 && r != AVERROR_EOF)
        return fail_av(err, CAP_ERR_ENCODER, "bench encode", "decoding", r);
    while ((r = avcodec_receive_frame(d, f)) >= 0) {
        if (*got < n && f->format == AV_PIX_FMT_YUV420P && f->width == w && f->height == h) {
            uint8_t *dst = out + (size_t)*got * cap_frame_bytes(CAP_I420, w, h);
            for (int p = 0; p < 3; p++) {
                int pw = p ? w / 2 : w, ph = p ? h / 2 : h;
                for (int y = 0; y < ph; y++)
                    memcpy(dst + (size_t)y * pw, f->data[p] + (size_t)y * f->linesize[p], (size_t)pw);
                dst += (size_t)pw * ph;
            }
        }
        (*got)++;
        av_frame_unref(f);
    }
    return r == AVERROR(EAGAIN) || r == AVERROR_EOF ? true : fail_av(err, CAP_ERR_ENCODER, "bench encode", "decoding", r);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec / 1e9;
}

bool cap_enc_trial_run(const cap_enc *enc, int w, int h, const uint8_t *i420, int n, uint8_t *decoded,
                       cap_enc_trial *t, rs_err *err)
{
    cap_sink s = {.w = w, .h = h, .fmt = CAP_I420, .enc = *enc};
    snprintf(s.path, sizeof s.path, "bench encode");
    s.enc.hw = CAP_HW_OFF;
    s.enc.chroma = CAP_CHROMA_420;
    const char *name = cap_enc_software(enc->codec, w, h);
    const enc_row *row = name ? row_named(name) : NULL;
    char why[600];
    memset(t, 0, sizeof *t);
    if (!row)
        return rs_fail(err, CAP_ERR_NOT_BUILT, "no software %s encoder in this FFmpeg", cap_codec_name(enc->codec));
    if (!row_takes(row, &s.enc, why, sizeof why))
        return rs_fail(err, CAP_ERR_ENC_SETTING, "%s", why);
    snprintf(s.enc_name, sizeof s.enc_name, "%s", name);
    snprintf(t->encoder, sizeof t->encoder, "%s", name);
    snprintf(t->preset, sizeof t->preset, "%s", enc->preset[0] ? enc->preset : row->preset_default);
    t->crf = enc->crf ? enc->crf : row->crf_default;
    cap_av_log_level();
    cap_encoder x = {0};
    AVCodecContext *d = NULL;
    AVPacket *pkt = av_packet_alloc();
    AVFrame *f = av_frame_alloc();
    bool ok = false;
    int got = 0, r;
    size_t fb = cap_frame_bytes(CAP_I420, w, h);
    const AVCodec *dec;
    if (!pkt || !f) {
        rs_fail(err, CAP_ERR_NOMEM, "out of memory");
        goto done;
    }
    if (!cap_encoder_open(&x, &s, false, err))
        goto done;
    /* the decoder: FFmpeg's own where it has one (av1: libdav1d or libaom, whichever is there) */
    dec = avcodec_find_decoder(x.ctx->codec_id);
    if (!dec || !(d = avcodec_alloc_context3(dec)) || avcodec_open2(d, dec, NULL) < 0) {
        rs_fail(err, CAP_ERR_NOT_BUILT, "no %s decoder in this FFmpeg", cap_codec_name(enc->codec));
        goto done;
    }
    double t0 = now_s(), spent = 0;
    for (int i = 0; i <= n; i++) {
        if (i < n && !cap_encoder_send(&x, &s, i420 + (size_t)i * fb, i, err))
            goto done;
        if (i == n && (r = avcodec_send_frame(x.ctx, NULL)) < 0) {
            fail_av(err, CAP_ERR_ENCODER, s.path, "flushing", r);
            goto done;
        }
        while ((r = avcodec_receive_packet(x.ctx, pkt)) >= 0) {
            spent += now_s() - t0; /* decoding is not the encoder's time */
            t->bytes += (uint64_t)pkt->size;
            bool dok = decode_into(d, pkt, f, decoded, w, h, n, &got, err);
            av_packet_unref(pkt);
            if (!dok)
                goto done;
            t0 = now_s();
        }
        if (r != AVERROR(EAGAIN) && r != AVERROR_EOF) {
            fail_av(err, CAP_ERR_ENCODER, s.path, "encoding", r);
            goto done;
        }
    }
    t->encode_s = spent + now_s() - t0;
    if (!decode_into(d, NULL, f, decoded, w, h, n, &got, err))
        goto done;
    if (got != n) {
        rs_fail(err, CAP_ERR_ENCODER, "%s: %d frames in, %d decoded", name, n, got);
        goto done;
    }
    ok = true;
done:
    cap_encoder_close(&x);
    avcodec_free_context(&d);
    av_packet_free(&pkt);
    av_frame_free(&f);
    return ok;
}

#else /* no FFmpeg: only the zero settings, which no sink uses */

bool cap_sink_encoder(cap_sink *s, const cap_enc *enc, rs_err *err)
{
    s->enc_note[0] = s->enc_name[0] = 0;
    if (!enc_is_zero(enc))
        return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this build has no FFmpeg libraries, so no encoder settings", s->path);
    return true;
}

const char *cap_enc_software(cap_codec c, int w, int h)
{
    (void)c, (void)w, (void)h;
    return NULL;
}

bool cap_enc_trial_run(const cap_enc *enc, int w, int h, const uint8_t *i420, int n, uint8_t *decoded,
                       cap_enc_trial *t, rs_err *err)
{
    (void)enc, (void)w, (void)h, (void)i420, (void)n, (void)decoded, (void)t;
    return rs_fail(err, CAP_ERR_NOT_BUILT, "this build has no FFmpeg libraries");
}
#endif
