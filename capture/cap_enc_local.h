/* The encoder as the FFmpeg sink drives it (capture-private; cap_enc.h is
 * the public face).  One struct for software, NVENC and VAAPI, so that the
 * sink's muxing code does not know which it has: open, send frames, read
 * packets from ctx, close. */
#ifndef CAP_ENC_LOCAL_H
#define CAP_ENC_LOCAL_H

#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>

#include "cap_sink.h"

typedef struct cap_encoder {
    AVCodecContext *ctx;
    AVFrame *frame;      /* filled from the capture's frame: yuv420p, yuv444p, or nv12 to upload */
    AVFrame *hw;         /* VAAPI: the surface the frame is uploaded to; NULL otherwise */
    AVBufferRef *device; /* VAAPI device; NULL otherwise */
} cap_encoder;

/* Opens s->enc_name with s->enc's settings at s's size (a segment gets a
 * closed GOP).  global_header: the container wants the parameter sets in
 * the stream header (mp4, mkv).  Messages name path. */
bool cap_encoder_open(cap_encoder *x, const cap_sink *s, bool global_header, rs_err *err);
/* One capture frame (s->fmt: I420, or RGBA for 4:4:4) with timestamp pts. */
bool cap_encoder_send(cap_encoder *x, const cap_sink *s, const uint8_t *frame, int64_t pts, rs_err *err);
void cap_encoder_close(cap_encoder *x);

/* The audio encoder beside it (cap_audio.c): the sink's borrowed track
 * (s->audio), encoded in the encoder's frame size as the video goes. */
typedef struct cap_aenc {
    AVCodecContext *ctx;
    AVStream *st;
    AVFrame *frame;
    AVPacket *pkt;
    float *buf;         /* one encoder frame of the track, as read (stereo interleaved) */
    size_t frames;      /* the track's length in sample frames */
    size_t sent;        /* frames read from the track (the priming's stand-in, then encoded) */
    size_t chunk;       /* the encoder's frame size */
    size_t skip;        /* frames of the track's start that stand in for the priming (AAC in MKV, NUT) */
    struct cap_atrack *keep; /* set: packets are kept there (cap_atrack_encode), not written */
    /* set: each packet (in st's time base) goes to put instead (cap_hls.c's
     * track parts); put takes the packet's reference or leaves it */
    bool (*put)(void *u, AVPacket *pkt, rs_err *err);
    void *put_u;
} cap_aenc;

/* A track encoded ahead of its container (cap_seg.h): the stream's
 * parameters and time base as cap_aenc_open set them for the container,
 * and every packet, in that time base. */
struct cap_atrack {
    AVCodecParameters *par;
    AVRational tb;
    AVPacket **pkt;
    size_t n, cap;
    size_t next; /* the next packet to write (cap_join.c) */
    double secs; /* how long the encoding took */
};

/* Adds the audio stream to fmt (before its header is written). */
bool cap_aenc_open(cap_aenc *a, const cap_sink *s, AVFormatContext *fmt, rs_err *err);
/* Encodes the track up to sample frame upto (whole encoder frames only). */
bool cap_aenc_feed(cap_aenc *a, const cap_sink *s, AVFormatContext *fmt, size_t upto, rs_err *err);
/* The rest, the last short frame, and the encoder's delayed packets. */
bool cap_aenc_finish(cap_aenc *a, const cap_sink *s, AVFormatContext *fmt, rs_err *err);
void cap_aenc_close(cap_aenc *a);

/* FFmpeg's own log at the process's level (rs_log.h): errors, or its
 * statistics too with -v, nothing with --loglevel quiet. */
void cap_av_log_level(void);

#endif
