/* The soundtrack of a video: which codec a container gets, its bitrate,
 * and the audio encoder the FFmpeg sink drives beside the video one
 * (cap_enc_local.h: cap_aenc).
 *
 *   .mp4 .mkv .nut   AAC, FFmpeg's native encoder, default 192 kb/s
 *   .webm            Opus (libopus), default 128 kb/s
 *
 * DESIGN
 * - The track is a pure function of the replay, so the sink reads it as
 *   it goes (cap_audio_read_fn: the match mixed on demand, never held
 *   whole) and needs no queue between threads: after video frame i it
 *   encodes the track up to sample frame (i + 1) * 800, on the writer
 *   thread, in the encoder's own frame size (1024 AAC, 960 Opus).  `sent`
 *   counts the frames read; whole encoder frames only, so the samples
 *   that do not fill one stay unread until the next video frame; the last
 *   partial frame goes out short at close, and the encoder pads it.
 * - Priming: both encoders start with a delay (AAC 1024 samples, Opus
 *   312) and say so (initial_padding): their first packet's pts lies that
 *   far below zero.  MP4 trims it exactly with an edit list.  Matroska,
 *   WebM and NUT cannot start one stream before another: libavformat
 *   shifts every stream instead (WebM's Opus with its CodecDelay rounded
 *   to the millisecond put the picture 7 ms after the sound, measured).
 *   So there the encoder is fed from sample `skip` = its delay, its
 *   first packet lands at pts 0, no delay is declared, and the decoder's
 *   warm-up output stands in for the track's first 21 ms (AAC) or 6.5 ms
 *   (Opus): every later sample plays at exactly its time.
 * - The track's sample frame k is at k / 48000 s and video frame i at
 *   i / 60 s: one clock, no resampling, no drift. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "cap_seg.h"
#include "cap_sink.h"
#include "../runtime/util/rs_progress.h"

#define AAC_DEFAULT 192000
#define OPUS_DEFAULT 128000

static const char *ext_of(const cap_sink *s)
{
    const char *slash = strrchr(s->path, '/'), *dot = strrchr(s->path, '.');
    return s->ext[0] ? s->ext : dot && (!slash || dot > slash) ? dot : "";
}

#ifdef RS_HAVE_FFMPEG
extern const cap_sink_ops cap_sink_ffmpeg;
#endif

const char *cap_sink_audio_codec(const cap_sink *s)
{
#ifdef RS_HAVE_FFMPEG
    if (s->ops != &cap_sink_ffmpeg || s->segment)
        return NULL;
    const char *ext = ext_of(s);
    if (!strcasecmp(ext, ".webm"))
        return "opus";
    if (!strcasecmp(ext, ".mp4") || !strcasecmp(ext, ".mkv") || !strcasecmp(ext, ".nut"))
        return "aac";
#else
    (void)s;
#endif
    return NULL;
}

#ifdef RS_HAVE_FFMPEG
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>

#include "cap_enc_local.h"

/* The encoder of each codec, and the bitrates it takes (stereo, 48 kHz). */
static const struct {
    const char *codec, *encoder, *shown;
    int64_t lo, hi, def;
} acodecs[] = {
    {"aac", "aac", "AAC", 32000, 512000, AAC_DEFAULT},
    {"opus", "libopus", "Opus", 16000, 510000, OPUS_DEFAULT},
};

bool cap_sink_audio(cap_sink *s, cap_audio_read_fn read, void *u, size_t frames, int64_t bitrate, rs_err *err)
{
    const char *codec = cap_sink_audio_codec(s);
    if (!codec)
        return rs_fail(err, CAP_ERR_ENC_SETTING, "%s: %s carries no audio (.mp4, .mkv, .nut and .webm do; --wav writes the track beside any output)",
                       s->path, s->segment ? "a segment" : "this output");
    for (size_t i = 0; i < sizeof acodecs / sizeof acodecs[0]; i++) {
        if (strcmp(acodecs[i].codec, codec))
            continue;
        if (!avcodec_find_encoder_by_name(acodecs[i].encoder))
            return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this FFmpeg has no %s encoder for the %s audio (use --audio off)", s->path,
                           acodecs[i].encoder, codec);
        if (bitrate && (bitrate < acodecs[i].lo || bitrate > acodecs[i].hi))
            return rs_fail(err, CAP_ERR_ENC_SETTING, "%s: --audio-bitrate %lldk: %s takes %lldk..%lldk", s->path,
                           (long long)(bitrate / 1000), acodecs[i].shown, (long long)(acodecs[i].lo / 1000), (long long)(acodecs[i].hi / 1000));
        s->audio = read;
        s->audio_u = u;
        s->audio_frames = frames;
        s->audio_bitrate = bitrate ? bitrate : acodecs[i].def;
        snprintf(s->audio_codec, sizeof s->audio_codec, "%s", codec);
        return true;
    }
    return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: no %s encoder", s->path, codec);
}

static int fail_av(rs_err *err, int id, const char *path, const char *what, int code)
{
    char msg[AV_ERROR_MAX_STRING_SIZE] = "";
    av_strerror(code, msg, sizeof msg);
    return rs_fail(err, id, "%s: %s: %s", path, what, msg);
}

bool cap_aenc_open(cap_aenc *a, const cap_sink *s, AVFormatContext *fmt, rs_err *err)
{
    *a = (cap_aenc){.frames = s->audio_frames};
    const char *name = !strcmp(s->audio_codec, "opus") ? "libopus" : "aac";
    const AVCodec *codec = avcodec_find_encoder_by_name(name);
    if (!codec)
        return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this FFmpeg has no %s encoder", s->path, name);
    if (!(a->ctx = avcodec_alloc_context3(codec)) || !(a->frame = av_frame_alloc()) || !(a->pkt = av_packet_alloc()) ||
        !(a->st = avformat_new_stream(fmt, NULL)))
        return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", s->path);
    AVCodecContext *c = a->ctx;
    /* the encoder's own layout: planar float for AAC, interleaved float for libopus */
    c->sample_fmt = AV_SAMPLE_FMT_FLTP;
    for (const enum AVSampleFormat *f = codec->sample_fmts; f && *f != AV_SAMPLE_FMT_NONE; f++)
        if (*f == AV_SAMPLE_FMT_FLT || *f == AV_SAMPLE_FMT_FLTP) {
            c->sample_fmt = *f;
            break;
        }
    c->sample_rate = 48000;
    av_channel_layout_default(&c->ch_layout, 2);
    c->time_base = (AVRational){1, 48000};
    c->bit_rate = s->audio_bitrate;
    if (fmt->oformat->flags & AVFMT_GLOBALHEADER)
        c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    AVDictionary *o = NULL;
    if (s->audio_fast && !strcmp(name, "aac"))
        av_dict_set(&o, "aac_coder", "fast", 0);
    int r = avcodec_open2(c, codec, &o);
    av_dict_free(&o);
    if (r < 0)
        return fail_av(err, CAP_ERR_ENCODER, s->path, "cannot open the audio encoder", r);
    avcodec_parameters_from_context(a->st->codecpar, c);
    a->st->time_base = c->time_base;
    /* MP4 trims the priming exactly (an edit list); elsewhere the priming
     * stands in for the track's first samples (the DESIGN note above) */
    if (strcmp(fmt->oformat->name, "mp4")) {
        a->skip = (size_t)c->initial_padding;
        a->st->codecpar->initial_padding = 0; /* no CodecDelay: nothing to shift */
        AVCodecParameters *par = a->st->codecpar;
        if (par->extradata_size >= 12 && !memcmp(par->extradata, "OpusHead", 8))
            par->extradata[10] = par->extradata[11] = 0; /* the header's pre-skip, likewise */
    }
    a->chunk = c->frame_size > 0 ? (size_t)c->frame_size : 1024;
    if (!(a->buf = malloc(a->chunk * 2 * sizeof *a->buf)))
        return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", s->path);
    /* the priming's stand-in: the track's first frames, read and dropped */
    size_t skip = a->skip < a->frames ? a->skip : a->frames;
    while (a->sent < skip) {
        size_t n = skip - a->sent < a->chunk ? skip - a->sent : a->chunk;
        if (!s->audio(s->audio_u, a->buf, n, err))
            return false;
        a->sent += n;
    }
    a->frame->format = c->sample_fmt;
    a->frame->nb_samples = (int)a->chunk;
    a->frame->sample_rate = c->sample_rate;
    if ((r = av_channel_layout_copy(&a->frame->ch_layout, &c->ch_layout)) < 0 || (r = av_frame_get_buffer(a->frame, 0)) < 0)
        return fail_av(err, CAP_ERR_NOMEM, s->path, "audio frame", r);
    return true;
}

/* a packet kept for later (cap_atrack_encode) */
static bool keep(cap_atrack *t, AVPacket *pkt)
{
    if (t->n == t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 1024;
        AVPacket **p = realloc(t->pkt, cap * sizeof *p);
        if (!p)
            return false;
        t->pkt = p, t->cap = cap;
    }
    if (!(t->pkt[t->n] = av_packet_alloc()))
        return false;
    av_packet_move_ref(t->pkt[t->n++], pkt);
    return true;
}

static bool drain(cap_aenc *a, const cap_sink *s, AVFormatContext *fmt, rs_err *err)
{
    for (;;) {
        int r = avcodec_receive_packet(a->ctx, a->pkt);
        if (r == AVERROR(EAGAIN) || r == AVERROR_EOF)
            return true;
        if (r < 0)
            return fail_av(err, CAP_ERR_ENCODER, s->path, "audio encoder", r);
        av_packet_rescale_ts(a->pkt, a->ctx->time_base, a->st->time_base);
        a->pkt->stream_index = a->st->index;
        if (a->put) {
            bool ok = a->put(a->put_u, a->pkt, err);
            av_packet_unref(a->pkt);
            if (!ok)
                return false;
        } else if (a->keep) {
            if (!keep(a->keep, a->pkt))
                return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory for the encoded track", s->path);
        } else if ((r = av_interleaved_write_frame(fmt, a->pkt)) < 0) {
            return fail_av(err, CAP_ERR_WRITE, s->path, "write failed", r);
        }
    }
}

/* n frames of the track from a->sent, as one encoder frame */
static bool send(cap_aenc *a, const cap_sink *s, AVFormatContext *fmt, size_t n, rs_err *err)
{
    int r = av_frame_make_writable(a->frame);
    if (r < 0)
        return fail_av(err, CAP_ERR_NOMEM, s->path, "audio frame", r);
    const float *src = a->buf;
    if (!s->audio(s->audio_u, a->buf, n, err))
        return false;
    if (a->frame->format == AV_SAMPLE_FMT_FLTP) {
        float *l = (float *)a->frame->data[0], *rr = (float *)a->frame->data[1];
        for (size_t k = 0; k < n; k++)
            l[k] = src[2 * k], rr[k] = src[2 * k + 1];
    } else {
        memcpy(a->frame->data[0], src, n * 2 * sizeof(float));
    }
    a->frame->nb_samples = (int)n;
    a->frame->pts = (int64_t)a->sent; /* minus the encoder's priming: the first packet's pts is skip - initial_padding */
    a->sent += n;
    if ((r = avcodec_send_frame(a->ctx, a->frame)) < 0)
        return fail_av(err, CAP_ERR_ENCODER, s->path, "encoding audio", r);
    return drain(a, s, fmt, err);
}

bool cap_aenc_feed(cap_aenc *a, const cap_sink *s, AVFormatContext *fmt, size_t upto, rs_err *err)
{
    if (upto > a->frames)
        upto = a->frames;
    while (a->sent + a->chunk <= upto)
        if (!send(a, s, fmt, a->chunk, err))
            return false;
    return true;
}

bool cap_aenc_finish(cap_aenc *a, const cap_sink *s, AVFormatContext *fmt, rs_err *err)
{
    if (!cap_aenc_feed(a, s, fmt, a->frames, err))
        return false;
    if (a->sent < a->frames && !send(a, s, fmt, a->frames - a->sent, err)) /* the last, short frame */
        return false;
    int r = avcodec_send_frame(a->ctx, NULL);
    if (r < 0 && r != AVERROR_EOF)
        return fail_av(err, CAP_ERR_ENCODER, s->path, "flushing the audio encoder", r);
    return drain(a, s, fmt, err);
}

void cap_aenc_close(cap_aenc *a)
{
    free(a->buf);
    a->buf = NULL;
    av_packet_free(&a->pkt);
    av_frame_free(&a->frame);
    avcodec_free_context(&a->ctx);
}

cap_atrack *cap_atrack_encode(const cap_sink *audio, const char *out, rs_err *err)
{
    /* the container the packets are for, without a file: its flags and
     * name are what cap_aenc_open asks of it */
    const char *ext = cap_seg_format_of(out);
    AVFormatContext *fmt = NULL;
    cap_atrack *t = calloc(1, sizeof *t);
    if (!t || !ext || avformat_alloc_output_context2(&fmt, NULL, !strcmp(ext, "mkv") ? "matroska" : ext, NULL) < 0) {
        free(t);
        rs_fail(err, !t ? CAP_ERR_NOMEM : CAP_ERR_OUTPUT, "%s: %s", out, !t ? "out of memory" : "no container for the track");
        return NULL;
    }
    double t0 = rs_now();
    cap_av_log_level();
    cap_aenc a = {0};
    bool ok = cap_aenc_open(&a, audio, fmt, err);
    a.keep = t;
    ok = ok && cap_aenc_finish(&a, audio, fmt, err);
    if (ok && (!(t->par = avcodec_parameters_alloc()) || avcodec_parameters_copy(t->par, a.st->codecpar) < 0))
        ok = rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", out);
    if (ok)
        t->tb = a.st->time_base;
    cap_aenc_close(&a);
    avformat_free_context(fmt);
    t->secs = rs_now() - t0;
    if (!ok) {
        cap_atrack_free(t);
        return NULL;
    }
    return t;
}

double cap_atrack_secs(const cap_atrack *t)
{
    return t ? t->secs : 0;
}

void cap_atrack_free(cap_atrack *t)
{
    if (!t)
        return;
    for (size_t i = 0; i < t->n; i++)
        av_packet_free(&t->pkt[i]);
    free(t->pkt);
    avcodec_parameters_free(&t->par);
    free(t);
}

#else

cap_atrack *cap_atrack_encode(const cap_sink *audio, const char *out, rs_err *err)
{
    (void)audio;
    rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this build has no FFmpeg libraries, so no audio stream", out);
    return NULL;
}

double cap_atrack_secs(const cap_atrack *t)
{
    (void)t;
    return 0;
}

void cap_atrack_free(cap_atrack *t)
{
    (void)t;
}

bool cap_sink_audio(cap_sink *s, cap_audio_read_fn read, void *u, size_t frames, int64_t bitrate, rs_err *err)
{
    (void)read, (void)u, (void)frames, (void)bitrate;
    return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this build has no FFmpeg libraries, so no audio stream (--wav writes the track)",
                   s->path);
}
#endif
