/* The encoder as the FFmpeg sink drives it (capture-private; cap_enc.h is
 * the public face).  One struct for software, NVENC and VAAPI, so that the
 * sink's muxing code does not know which it has: open, send frames, read
 * packets from ctx, close. */
#ifndef CAP_ENC_LOCAL_H
#define CAP_ENC_LOCAL_H

#include <libavcodec/avcodec.h>

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

#endif
