/* The FFmpeg reader: anything libavformat demuxes and libavcodec decodes
 * (H.264, VP9, AV1, MPEG-4, ...), delivered as packed 8-bit planes.
 *
 * Pixel formats: every YUV format whose components are planar or
 * semi-planar (NV12/NV21/P010 ...) at 8 to 16 bits, and gray.  8-bit planar
 * rows are copied; the rest go through one generic loop that reads each
 * component by its descriptor and rounds it to 8 bits.  RGB, paletted,
 * alpha and hardware formats are refused with the format's name.
 *
 * The matrix, range and chroma siting come from the stream's codec
 * parameters (a frame that changes size or format is an error); unspecified matrix -> guessed by size as
 * mpv does, unspecified range -> limited, unspecified siting -> left (the
 * MPEG-2/H.264 default). */
#include <stdlib.h>
#include <string.h>

#include "mv.h"

#ifndef RS_HAVE_FFMPEG

mv_src *mv_ffmpeg_open(const char *path, rs_err *err)
{
    rs_fail(err, MV_ERR_UNSUPPORTED, "%s: not a Y4M file, and this build has no FFmpeg to decode it", path);
    return NULL;
}

#else

#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/pixdesc.h>

typedef struct ff_src {
    mv_src base; /* first: (mv_src *) casts */
    AVFormatContext *fmt;
    AVCodecContext *dec;
    AVPacket *pkt;
    AVFrame *frame;
    int stream;
    int pix_fmt;
    const AVPixFmtDescriptor *desc;
    bool fast;     /* 8-bit planar: row copies */
    bool draining; /* the demuxer ended; the decoder is being flushed */
    bool ended;
    bool cut_short; /* the demuxer met the end of the file inside a packet */
    int bad_packets; /* consecutive packets the decoder refused */
} ff_src;

static const char *av_msg(int e, char *buf, size_t n)
{
    av_strerror(e, buf, n);
    return buf;
}

/* Formats we deliver: YUV or gray, no alpha, no palette, no RGB, no
 * hardware surface, 8..16 bits, chroma in 1 or 2 planes. */
static bool usable(const AVPixFmtDescriptor *d)
{
    if (!d || (d->flags & (AV_PIX_FMT_FLAG_RGB | AV_PIX_FMT_FLAG_PAL | AV_PIX_FMT_FLAG_HWACCEL |
                           AV_PIX_FMT_FLAG_ALPHA | AV_PIX_FMT_FLAG_BITSTREAM | AV_PIX_FMT_FLAG_FLOAT |
                           AV_PIX_FMT_FLAG_BAYER)))
        return false;
    if (d->nb_components != 1 && d->nb_components != 3)
        return false;
    if (d->log2_chroma_w > 2 || d->log2_chroma_h > 2)
        return false;
    for (int c = 0; c < d->nb_components; c++) {
        if (d->comp[c].depth < 8 || d->comp[c].depth > 16)
            return false;
        if (d->comp[c].step < 1 || d->comp[c].step > 4)
            return false;
    }
    return true;
}

static bool fast_path(const AVPixFmtDescriptor *d)
{
    for (int c = 0; c < d->nb_components; c++)
        if (d->comp[c].depth != 8 || d->comp[c].step != 1 || d->comp[c].plane != c || d->comp[c].offset)
            return false;
    return true;
}

static void set_colour(mv_info *i, int spc, int range, int loc, int pix_fmt)
{
    switch (spc) {
    case AVCOL_SPC_BT709:
        i->matrix = MV_BT709;
        i->matrix_guessed = false;
        break;
    case AVCOL_SPC_BT470BG:
    case AVCOL_SPC_SMPTE170M:
    case AVCOL_SPC_FCC:
        i->matrix = MV_BT601;
        i->matrix_guessed = false;
        break;
    default: /* unspecified, or a matrix we do not convert: guess */
        i->matrix = mv_guess_matrix(i->w, i->h);
        i->matrix_guessed = true;
        break;
    }
    i->full_range = range == AVCOL_RANGE_JPEG || pix_fmt == AV_PIX_FMT_YUVJ420P ||
                    pix_fmt == AV_PIX_FMT_YUVJ422P || pix_fmt == AV_PIX_FMT_YUVJ444P ||
                    pix_fmt == AV_PIX_FMT_YUVJ440P || pix_fmt == AV_PIX_FMT_YUVJ411P;
    switch (loc) {
    case AVCHROMA_LOC_CENTER: i->chroma_loc = MV_CHROMA_CENTER; break;
    case AVCHROMA_LOC_TOPLEFT: i->chroma_loc = MV_CHROMA_TOPLEFT; break;
    default: i->chroma_loc = MV_CHROMA_LEFT; break;
    }
}

/* One component, any layout, rounded to 8 bits. */
static void copy_generic(const AVFrame *f, const AVPixFmtDescriptor *d, int c, int w, int h, uint8_t *dst)
{
    const AVComponentDescriptor *cd = &d->comp[c];
    int depth = cd->depth, bytes = (depth + cd->shift > 8) ? 2 : 1;
    bool be = d->flags & AV_PIX_FMT_FLAG_BE;
    unsigned mask = (1u << depth) - 1, half = depth > 8 ? 1u << (depth - 9) : 0;
    for (int y = 0; y < h; y++) {
        const uint8_t *row = f->data[cd->plane] + (ptrdiff_t)y * f->linesize[cd->plane] + cd->offset;
        for (int x = 0; x < w; x++) {
            const uint8_t *p = row + (ptrdiff_t)x * cd->step;
            unsigned v = bytes == 1 ? p[0] : be ? (unsigned)p[0] << 8 | p[1] : (unsigned)p[1] << 8 | p[0];
            v = (v >> cd->shift) & mask;
            if (depth > 8) {
                v = (v + half) >> (depth - 8);
                if (v > 255)
                    v = 255;
            }
            dst[(size_t)y * w + x] = (uint8_t)v;
        }
    }
}

static bool deliver(ff_src *s, uint8_t *dst, rs_err *err)
{
    const mv_info *i = &s->base.info;
    AVFrame *f = s->frame;
    if (f->width != i->w || f->height != i->h || f->format != s->pix_fmt)
        return rs_fail(err, MV_ERR_UNSUPPORTED, "%s: frame %lld: size or format changed mid-stream (%dx%d %s, was %dx%d %s)",
                       s->base.path, (long long)s->base.index, f->width, f->height,
                       av_get_pix_fmt_name(f->format) ? av_get_pix_fmt_name(f->format) : "?", i->w, i->h, i->pixfmt);
    int pw[3] = {i->w, i->cw, i->cw}, ph[3] = {i->h, i->ch, i->ch};
    size_t off = 0;
    for (int c = 0; c < s->desc->nb_components; c++) {
        if (s->fast) {
            for (int y = 0; y < ph[c]; y++)
                memcpy(dst + off + (size_t)y * pw[c], f->data[c] + (ptrdiff_t)y * f->linesize[c], (size_t)pw[c]);
        } else {
            copy_generic(f, s->desc, c, pw[c], ph[c], dst + off);
        }
        off += (size_t)pw[c] * ph[c];
    }
    return true;
}

static int ff_read(mv_src *base, uint8_t *dst, rs_err *err)
{
    ff_src *s = (ff_src *)base;
    char m[128];
    if (s->ended)
        return 0;
    for (;;) {
        int r = avcodec_receive_frame(s->dec, s->frame);
        if (r == 0) {
            bool ok = deliver(s, dst, err);
            av_frame_unref(s->frame);
            if (!ok)
                return -1;
            base->index++;
            return 1;
        }
        if (r == AVERROR_EOF) {
            /* nb_frames counts packets (an edit list may hide some), so a
             * short count is no error; a file cut short is, and the demuxer
             * says so with an I/O error at the end of the file. */
            s->ended = true;
            if (s->cut_short) {
                rs_fail(err, MV_ERR_TRUNCATED, "%s: the file ends inside frame %lld (truncated)", base->path,
                        (long long)base->index);
                return -1;
            }
            return 0;
        }
        if (r != AVERROR(EAGAIN)) {
            rs_fail(err, MV_ERR_DECODE, "%s: frame %lld: decoding failed: %s", base->path, (long long)base->index,
                    av_msg(r, m, sizeof m));
            return -1;
        }
        if (s->draining) { /* EAGAIN while draining cannot happen; be safe */
            s->ended = true;
            return 0;
        }
        /* the decoder wants input */
        for (;;) {
            r = av_read_frame(s->fmt, s->pkt);
            if (r == AVERROR_EOF || (r == AVERROR(EIO) && s->fmt->pb && avio_feof(s->fmt->pb))) {
                s->cut_short = r != AVERROR_EOF;
                s->draining = true;
                avcodec_send_packet(s->dec, NULL);
                break;
            }
            if (r < 0) {
                rs_fail(err, MV_ERR_DECODE, "%s: frame %lld: reading failed: %s", base->path,
                        (long long)base->index, av_msg(r, m, sizeof m));
                return -1;
            }
            if (s->pkt->stream_index != s->stream) {
                av_packet_unref(s->pkt);
                continue;
            }
            r = avcodec_send_packet(s->dec, s->pkt);
            av_packet_unref(s->pkt);
            if (r == AVERROR_INVALIDDATA) {
                /* Damaged data: the decoder conceals what it can; give up
                 * when it refuses many packets in a row. */
                if (++s->bad_packets >= 25) {
                    rs_fail(err, MV_ERR_DECODE, "%s: frame %lld: %d damaged packets in a row (corrupt file?)",
                            base->path, (long long)base->index, s->bad_packets);
                    return -1;
                }
                continue;
            }
            if (r < 0 && r != AVERROR(EAGAIN)) {
                rs_fail(err, MV_ERR_DECODE, "%s: frame %lld: decoding failed: %s", base->path,
                        (long long)base->index, av_msg(r, m, sizeof m));
                return -1;
            }
            s->bad_packets = 0;
            break;
        }
    }
}

static void ff_close(mv_src *base)
{
    ff_src *s = (ff_src *)base;
    av_frame_free(&s->frame);
    av_packet_free(&s->pkt);
    avcodec_free_context(&s->dec);
    avformat_close_input(&s->fmt);
    free(s);
}

mv_src *mv_ffmpeg_open(const char *path, rs_err *err)
{
    char m[128];
    ff_src *s = calloc(1, sizeof *s);
    if (!s) {
        rs_fail(err, MV_ERR_NOMEM, "%s: out of memory", path);
        return NULL;
    }
    snprintf(s->base.path, sizeof s->base.path, "%s", path);
    s->base.read = ff_read;
    s->base.close = ff_close;
    av_log_set_level(AV_LOG_FATAL); /* our messages say what went wrong, once */
    int r = avformat_open_input(&s->fmt, path, NULL, NULL);
    if (r < 0) {
        rs_fail(err, r == AVERROR_INVALIDDATA ? MV_ERR_FORMAT : MV_ERR_OPEN, "%s: cannot open as a movie: %s", path,
                av_msg(r, m, sizeof m));
        goto fail;
    }
    if ((r = avformat_find_stream_info(s->fmt, NULL)) < 0) {
        rs_fail(err, MV_ERR_FORMAT, "%s: cannot read the stream layout: %s", path, av_msg(r, m, sizeof m));
        goto fail;
    }
    const AVCodec *codec = NULL;
    s->stream = av_find_best_stream(s->fmt, AVMEDIA_TYPE_VIDEO, -1, -1, &codec, 0);
    if (s->stream < 0 || !codec) {
        rs_fail(err, s->stream == AVERROR_DECODER_NOT_FOUND ? MV_ERR_UNSUPPORTED : MV_ERR_FORMAT,
                "%s: %s", path, s->stream == AVERROR_DECODER_NOT_FOUND ? "no decoder for its video codec" : "no video stream");
        goto fail;
    }
    AVStream *st = s->fmt->streams[s->stream];
    AVCodecParameters *cp = st->codecpar;
    s->dec = avcodec_alloc_context3(codec);
    s->pkt = av_packet_alloc();
    s->frame = av_frame_alloc();
    if (!s->dec || !s->pkt || !s->frame) {
        rs_fail(err, MV_ERR_NOMEM, "%s: out of memory", path);
        goto fail;
    }
    s->dec->thread_count = 0; /* as many as the machine has: HD H.264 must keep up with 60 Hz */
    if ((r = avcodec_parameters_to_context(s->dec, cp)) < 0 || (r = avcodec_open2(s->dec, codec, NULL)) < 0) {
        rs_fail(err, MV_ERR_UNSUPPORTED, "%s: cannot open the %s decoder: %s", path, codec->name, av_msg(r, m, sizeof m));
        goto fail;
    }
    s->pix_fmt = cp->format;
    s->desc = av_pix_fmt_desc_get(cp->format);
    if (!usable(s->desc)) {
        rs_fail(err, MV_ERR_UNSUPPORTED,
                "%s: pixel format %s is not played (YUV or gray, 8 to 16 bits, no alpha; convert with "
                "ffmpeg -pix_fmt yuv420p)", path, s->desc ? s->desc->name : "unknown");
        goto fail;
    }
    mv_info *i = &s->base.info;
    i->w = cp->width;
    i->h = cp->height;
    if (i->w < 1 || i->h < 1 || i->w > 16384 || i->h > 16384) {
        rs_fail(err, MV_ERR_FORMAT, "%s: bad frame size %dx%d", path, i->w, i->h);
        goto fail;
    }
    i->mono = s->desc->nb_components == 1;
    i->sx = s->desc->log2_chroma_w;
    i->sy = s->desc->log2_chroma_h;
    mv_info_planes(i);
    s->fast = fast_path(s->desc);
    set_colour(i, cp->color_space, cp->color_range, cp->chroma_location, cp->format);
    AVRational fr = av_guess_frame_rate(s->fmt, st, NULL);
    if (fr.num <= 0 || fr.den <= 0)
        fr = (AVRational){25, 1};
    av_reduce(&i->fps_num, &i->fps_den, fr.num, fr.den, 1 << 20);
    AVRational sar = av_guess_sample_aspect_ratio(s->fmt, st, NULL);
    i->sar_num = sar.num > 0 && sar.den > 0 ? sar.num : 1;
    i->sar_den = sar.num > 0 && sar.den > 0 ? sar.den : 1;
    i->frames = st->nb_frames > 0 ? st->nb_frames : -1;
    snprintf(i->codec, sizeof i->codec, "%s", codec->name);
    snprintf(i->pixfmt, sizeof i->pixfmt, "%s", s->desc->name);
    return &s->base;
fail:
    ff_close(&s->base);
    return NULL;
}

#endif
