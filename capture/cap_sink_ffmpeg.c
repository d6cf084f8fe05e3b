/* FFmpeg sink: H.264, HEVC, VP9 or AV1 (cap_enc.h picks the encoder and
 * its settings) in .mp4 / .mkv / .webm, through libavformat/libavcodec.
 * Frames arrive as I420 (BT.709, limited range, chroma at the centre), or
 * as RGBA for 4:4:4 (converted by cap_enc.c), and are tagged as such.
 * Timing is exact: time base 1/60, pts = frame index, every packet lasts
 * one frame, so the duration is frames / 60 s.
 *
 * Web-ready MP4: the index (moov) is moved before the media data
 * (faststart) when the file is complete, so a browser plays it while it
 * downloads; HEVC is tagged hvc1, the tag Apple's players require.  The
 * metadata (s->meta: title, stage, players, winner, ringside_version) is
 * written in every container; MP4 needs use_metadata_tags for keys beyond
 * iTunes' fixed set, so there all of them go in the mdta form.
 *
 * A segment (s->segment, cap_seg.h) differs in three things, so that
 * every segment of one video has the same codec parameters: pts = tick
 * (index_base + index), the GOP is closed by flag as well as by x264's
 * default, and no faststart (join writes the index once for the whole).
 * Its first frame is a keyframe because every encoder starts with one.
 * With x264's B-frames (delay D = 2 at veryfast) the dts of the k-th
 * packet is A + k - D: pts are consecutive, so x264's dts (the pts D
 * packets earlier in presentation order) run on across segment
 * boundaries without a gap or a repeat.
 *
 * Sound (s->audio, cap_sink_audio): a second stream, AAC or Opus, encoded
 * by cap_audio.c after each video frame up to that frame's end, and
 * flushed before the trailer.  Segments never have one (join adds it). */
#ifdef RS_HAVE_FFMPEG /* configure.sh found libavformat; otherwise this file is empty */
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cap_enc_local.h"
#include "cap_out.h"
#include "cap_sink.h"
#include "../runtime/util/rs_log.h"

typedef struct ff_impl {
    AVFormatContext *fmt;
    cap_encoder x;
    AVStream *st;
    AVPacket *pkt;
    cap_aenc a; /* a.ctx NULL: no audio */
    char part[1100];
    bool stream; /* "-" (fd 1), a device or a pipe: written in place, no .part, no rename */
} ff_impl;

static const char *container(const char *ext)
{
    return !strcmp(ext, ".mkv") ? "matroska" : !strcmp(ext, ".webm") ? "webm" : !strcmp(ext, ".nut") ? "nut" : "mp4";
}

static const char *ext_of(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot ? dot : "";
}

static int fail_av(rs_err *err, int id, const char *path, const char *what, int code)
{
    if (code == AVERROR(EPIPE))
        return rs_fail(err, CAP_ERR_PIPE_CLOSED, "%s: the reader closed the pipe", cap_out_name(path));
    char msg[AV_ERROR_MAX_STRING_SIZE] = "";
    av_strerror(code, msg, sizeof msg);
    return rs_fail(err, id, "%s: %s: %s", path, what, msg);
}

void cap_av_log_level(void)
{
    /* encoder statistics are noise on our stderr, unless -v asks for them */
    av_log_set_level(rs_log_on(RS_LOG_DEBUG) ? AV_LOG_INFO : rs_log_on(RS_LOG_ERROR) ? AV_LOG_ERROR : AV_LOG_QUIET);
}

bool cap_ffmpeg_check(const char *path, const char *ext, rs_err *err)
{
    cap_av_log_level();
    /* the encoder is cap_sink_encoder's to find: the codec asked for may not be the container's default */
    if (!av_guess_format(container(ext), NULL, NULL))
        return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this FFmpeg has no %s muxer", path, container(ext));
    return true;
}

static bool drain(cap_sink *s, ff_impl *f, rs_err *err)
{
    for (;;) {
        int r = avcodec_receive_packet(f->x.ctx, f->pkt);
        if (r == AVERROR(EAGAIN) || r == AVERROR_EOF)
            return true;
        if (r < 0)
            return fail_av(err, CAP_ERR_ENCODER, s->path, "encoder", r);
        f->pkt->duration = 1; /* one frame, in the encoder's 1/60 */
        av_packet_rescale_ts(f->pkt, f->x.ctx->time_base, f->st->time_base);
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
    bool mp4 = !strcmp(container(ext), "mp4");
    f->stream = cap_out_is_stream(s->path);
    snprintf(f->part, sizeof f->part, !strcmp(s->path, "-") ? "pipe:1" : f->stream ? "%s" : "%s.part", s->path);
    /* callers that set no encoder get the defaults (and hardware, if it works) */
    if (!s->enc_name[0] && !cap_sink_encoder(s, &s->enc, err))
        goto fail;
    int r = avformat_alloc_output_context2(&f->fmt, NULL, container(ext), f->part);
    if (r < 0) {
        fail_av(err, CAP_ERR_ENCODER, s->path, "cannot set up the container", r);
        goto fail;
    }
    f->st = avformat_new_stream(f->fmt, NULL);
    f->pkt = av_packet_alloc();
    if (!f->st || !f->pkt) {
        rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", s->path);
        goto fail;
    }
    if (!cap_encoder_open(&f->x, s, f->fmt->oformat->flags & AVFMT_GLOBALHEADER, err))
        goto fail;
    AVCodecContext *e = f->x.ctx;
    avcodec_parameters_from_context(f->st->codecpar, e);
    if (mp4 && e->codec_id == AV_CODEC_ID_HEVC)
        f->st->codecpar->codec_tag = MKTAG('h', 'v', 'c', '1'); /* not hev1: Safari and QuickTime play only hvc1 */
    f->st->time_base = e->time_base;
    f->st->avg_frame_rate = e->framerate;
    if (s->audio && !cap_aenc_open(&f->a, s, f->fmt, err))
        goto fail;
    for (int i = 0; i < s->n_meta; i++)
        av_dict_set(&f->fmt->metadata, s->meta[i].key, s->meta[i].value, 0);
    if ((r = avio_open(&f->fmt->pb, f->part, AVIO_FLAG_WRITE)) < 0) {
        char what[1200];
        snprintf(what, sizeof what, "cannot create (as %s)", f->part);
        fail_av(err, CAP_ERR_CREATE, s->path, what, r);
        goto fail;
    }
    AVDictionary *mux = NULL;
    if (mp4)
        av_dict_set(&mux, "movflags", s->segment ? "+use_metadata_tags" : "+faststart+use_metadata_tags", 0);
    if (s->segment && mp4)
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
    return true;
fail:
    ff_close(s, false, NULL);
    return false;
}

static bool ff_write(cap_sink *s, const uint8_t *frame, uint64_t index, rs_err *err)
{
    ff_impl *f = s->impl;
    int64_t pts = (int64_t)index + (s->segment ? (int64_t)s->index_base : 0);
    /* then the sound up to the end of this frame: 800 sample frames a tick */
    return cap_encoder_send(&f->x, s, frame, pts, err) && drain(s, f, err) &&
           (!f->a.ctx || cap_aenc_feed(&f->a, s, f->fmt, (size_t)(index + 1) * 800, err));
}

static bool ff_close(cap_sink *s, bool ok, rs_err *err)
{
    ff_impl *f = s->impl;
    if (!f)
        return !ok;
    bool good = ok;
    if (good) {
        int r = avcodec_send_frame(f->x.ctx, NULL); /* flush delayed frames */
        if (r < 0 && r != AVERROR_EOF)
            good = fail_av(err, CAP_ERR_ENCODER, s->path, "flushing the encoder", r);
        else
            good = drain(s, f, err);
        if (good && f->a.ctx)
            good = cap_aenc_finish(&f->a, s, f->fmt, err);
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
    cap_encoder_close(&f->x);
    cap_aenc_close(&f->a);
    avformat_free_context(f->fmt);
    free(f);
    s->impl = NULL;
    return good;
}

const cap_sink_ops cap_sink_ffmpeg = {"ffmpeg", ff_open, ff_write, ff_close};

#else
typedef int cap_sink_ffmpeg_not_built; /* ISO C wants something in a file */
#endif
