/* FFmpeg sink: H.264 (libx264) in .mp4 / .mkv, VP9 (libvpx) in .webm,
 * through libavformat/libavcodec.  Frames arrive as I420 (BT.709, limited
 * range, chroma at the centre) and are tagged as such.  Timing is exact:
 * time base 1/60, pts = frame index, every packet lasts one frame, so the
 * duration is frames / 60 s.
 *
 * A segment (s->segment, cap_seg.h) differs in two things only, so that
 * every segment of one video has the same codec parameters: pts = tick
 * (index_base + index), and the GOP is closed by flag as well as by
 * x264's default.  Its first frame is a keyframe because every encoder
 * starts with one.  With x264's B-frames (delay D = 2 at veryfast) the
 * dts of the k-th packet is A + k - D: pts are consecutive, so x264's dts
 * (the pts D packets earlier in presentation order) run on across
 * segment boundaries without a gap or a repeat. */
#ifdef RS_HAVE_FFMPEG /* configure.sh found libavformat; otherwise this file is empty */
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cap_out.h"
#include "cap_sink.h"

typedef struct ff_impl {
    AVFormatContext *fmt;
    AVCodecContext *enc;
    AVStream *st;
    AVFrame *frame;
    AVPacket *pkt;
    char part[1100];
    bool stream; /* "-" (fd 1), a device or a pipe: written in place, no .part, no rename */
} ff_impl;

static const char *container(const char *ext)
{
    return !strcmp(ext, ".mkv") ? "matroska" : !strcmp(ext, ".webm") ? "webm" : !strcmp(ext, ".nut") ? "nut" : "mp4";
}

static const char *encoder_name(const char *ext)
{
    return !strcmp(ext, ".webm") ? "libvpx-vp9" : "libx264";
}

static const char *ext_of(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot ? dot : "";
}

static int fail_av(rs_err *err, int id, const char *path, const char *what, int code)
{
    char msg[AV_ERROR_MAX_STRING_SIZE] = "";
    av_strerror(code, msg, sizeof msg);
    return rs_fail(err, id, "%s: %s: %s", path, what, msg);
}

bool cap_ffmpeg_check(const char *path, const char *ext, rs_err *err)
{
    av_log_set_level(AV_LOG_ERROR); /* encoder statistics are noise on our stderr */
    if (!avcodec_find_encoder_by_name(encoder_name(ext)))
        return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this FFmpeg has no %s encoder for %s output (use .y4m, or an FFmpeg built with it)",
                       path, encoder_name(ext), ext);
    if (!av_guess_format(container(ext), NULL, NULL))
        return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this FFmpeg has no %s muxer", path, container(ext));
    return true;
}

static bool drain(cap_sink *s, ff_impl *f, rs_err *err)
{
    for (;;) {
        int r = avcodec_receive_packet(f->enc, f->pkt);
        if (r == AVERROR(EAGAIN) || r == AVERROR_EOF)
            return true;
        if (r < 0)
            return fail_av(err, CAP_ERR_ENCODER, s->path, "encoder", r);
        f->pkt->duration = 1; /* one frame, in the encoder's 1/60 */
        av_packet_rescale_ts(f->pkt, f->enc->time_base, f->st->time_base);
        f->pkt->stream_index = f->st->index;
        r = av_interleaved_write_frame(f->fmt, f->pkt); /* takes the packet's reference */
        if (r < 0)
            return fail_av(err, CAP_ERR_WRITE, s->path, "write failed", r);
    }
}

static bool ff_close(cap_sink *s, bool ok, rs_err *err);

static bool ff_open(cap_sink *s, rs_err *err)
{
    ff_impl *f = calloc(1, sizeof *f);
    if (!f)
        return rs_fail(err, CAP_ERR_NOMEM, "out of memory");
    s->impl = f;
    const char *ext = s->ext[0] ? s->ext : ext_of(s->path);
    f->stream = cap_out_is_stream(s->path);
    snprintf(f->part, sizeof f->part, !strcmp(s->path, "-") ? "pipe:1" : f->stream ? "%s" : "%s.part", s->path);
    const AVCodec *codec = avcodec_find_encoder_by_name(encoder_name(ext));
    int r = avformat_alloc_output_context2(&f->fmt, NULL, container(ext), f->part);
    if (r < 0 || !codec) {
        fail_av(err, CAP_ERR_ENCODER, s->path, "cannot set up the container", r < 0 ? r : AVERROR_ENCODER_NOT_FOUND);
        goto fail;
    }
    f->st = avformat_new_stream(f->fmt, NULL);
    f->enc = avcodec_alloc_context3(codec);
    f->frame = av_frame_alloc();
    f->pkt = av_packet_alloc();
    if (!f->st || !f->enc || !f->frame || !f->pkt) {
        rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", s->path);
        goto fail;
    }
    AVCodecContext *e = f->enc;
    e->width = s->w;
    e->height = s->h;
    e->time_base = (AVRational){1, 60};
    e->framerate = (AVRational){60, 1};
    e->pix_fmt = AV_PIX_FMT_YUV420P;
    e->gop_size = 120;
    e->color_range = AVCOL_RANGE_MPEG;
    e->colorspace = AVCOL_SPC_BT709;
    e->color_primaries = AVCOL_PRI_BT709;
    e->color_trc = AVCOL_TRC_BT709;
    e->chroma_sample_location = AVCHROMA_LOC_CENTER;
    if (s->segment)
        e->flags |= AV_CODEC_FLAG_CLOSED_GOP;
    if (!strcmp(codec->name, "libx264")) {
        av_opt_set(e->priv_data, "preset", "veryfast", 0);
        av_opt_set(e->priv_data, "crf", "20", 0);
    } else {
        av_opt_set(e->priv_data, "deadline", "realtime", 0);
        av_opt_set(e->priv_data, "cpu-used", "8", 0);
        av_opt_set(e->priv_data, "crf", "32", 0);
        e->bit_rate = 0;
    }
    if (f->fmt->oformat->flags & AVFMT_GLOBALHEADER)
        e->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    if ((r = avcodec_open2(e, codec, NULL)) < 0) {
        fail_av(err, CAP_ERR_ENCODER, s->path, "cannot open the encoder", r);
        goto fail;
    }
    avcodec_parameters_from_context(f->st->codecpar, e);
    f->st->time_base = e->time_base;
    f->st->avg_frame_rate = e->framerate;
    if ((r = avio_open(&f->fmt->pb, f->part, AVIO_FLAG_WRITE)) < 0) {
        fail_av(err, CAP_ERR_CREATE, f->part, "cannot create", r);
        goto fail;
    }
    AVDictionary *mux = NULL;
    if (s->segment && !strcmp(ext, ".mp4"))
        /* a segment from tick A starts with an empty edit of A ticks; in the
         * default 1/1000 movie time scale that is rounded (68 ticks read
         * back as 67.96), in a multiple of 60 it is exact */
        av_dict_set(&mux, "movie_timescale", "15360", 0);
    r = avformat_write_header(f->fmt, &mux);
    av_dict_free(&mux);
    if (r < 0) {
        fail_av(err, CAP_ERR_WRITE, s->path, "cannot write the header", r);
        goto fail;
    }
    f->frame->format = e->pix_fmt;
    f->frame->width = s->w;
    f->frame->height = s->h;
    if ((r = av_frame_get_buffer(f->frame, 0)) < 0) {
        fail_av(err, CAP_ERR_NOMEM, s->path, "frame buffer", r);
        goto fail;
    }
    return true;
fail:
    ff_close(s, false, NULL);
    return false;
}

static bool ff_write(cap_sink *s, const uint8_t *frame, uint64_t index, rs_err *err)
{
    ff_impl *f = s->impl;
    int r = av_frame_make_writable(f->frame);
    if (r < 0)
        return fail_av(err, CAP_ERR_NOMEM, s->path, "frame buffer", r);
    const uint8_t *plane = frame;
    for (int p = 0; p < 3; p++) {
        int pw = p ? s->w / 2 : s->w, ph = p ? s->h / 2 : s->h;
        for (int y = 0; y < ph; y++)
            memcpy(f->frame->data[p] + (size_t)y * f->frame->linesize[p], plane + (size_t)y * pw, (size_t)pw);
        plane += (size_t)pw * ph;
    }
    f->frame->pts = (int64_t)index + (s->segment ? (int64_t)s->index_base : 0);
    if ((r = avcodec_send_frame(f->enc, f->frame)) < 0) {
        char what[64];
        snprintf(what, sizeof what, "encoding frame %llu", (unsigned long long)index);
        return fail_av(err, CAP_ERR_ENCODER, s->path, what, r);
    }
    return drain(s, f, err);
}

static bool ff_close(cap_sink *s, bool ok, rs_err *err)
{
    ff_impl *f = s->impl;
    if (!f)
        return !ok;
    bool good = ok;
    if (good) {
        int r = avcodec_send_frame(f->enc, NULL); /* flush delayed frames */
        if (r < 0 && r != AVERROR_EOF)
            good = fail_av(err, CAP_ERR_ENCODER, s->path, "flushing the encoder", r);
        else
            good = drain(s, f, err);
        if (good && (r = av_write_trailer(f->fmt)) < 0)
            good = fail_av(err, CAP_ERR_WRITE, s->path, "write failed", r);
    }
    if (f->fmt && f->fmt->pb) {
        int perr = f->fmt->pb->error;
        avio_closep(&f->fmt->pb);
        if (good && perr < 0)
            good = fail_av(err, CAP_ERR_WRITE, s->path, "write failed", perr);
    }
    if (good && !f->stream && rename(f->part, s->path) != 0)
        good = rs_fail(err, CAP_ERR_WRITE, "%s: cannot rename %s into place", s->path, f->part);
    if (!good && !f->stream)
        unlink(f->part);
    av_packet_free(&f->pkt);
    av_frame_free(&f->frame);
    avcodec_free_context(&f->enc);
    avformat_free_context(f->fmt);
    free(f);
    s->impl = NULL;
    return good;
}

const cap_sink_ops cap_sink_ffmpeg = {"ffmpeg", ff_open, ff_write, ff_close};

#else
typedef int cap_sink_ffmpeg_not_built; /* ISO C wants something in a file */
#endif
