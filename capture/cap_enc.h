/* Encoder choice for the FFmpeg sink (cap_sink_ffmpeg.c): codec, rate
 * control, preset, chroma and hardware, chosen once per render before
 * anything is drawn (cap_sink_encoder), and a round trip of frames held in
 * memory for `ringside bench encode` (cap_enc_trial).
 *
 * Which encoder: for the codec asked for, the hardware encoders in the
 * order NVENC, VAAPI (when --hw allows and their device node exists), then
 * the first software encoder of this FFmpeg that takes the chroma asked for:
 *   h264  h264_nvenc  h264_vaapi  libx264
 *   hevc  hevc_nvenc  hevc_vaapi  libx265
 *   vp9               vp9_vaapi   libvpx-vp9
 *   av1   av1_nvenc   av1_vaapi   libsvtav1, libaom-av1
 * A hardware encoder is used only when it opens with the very settings of
 * the render (a probe at the output size), so a driver that is installed
 * but cannot run falls back before the first frame, not in the middle. */
#ifndef CAP_ENC_H
#define CAP_ENC_H

#include <stdbool.h>
#include <stdint.h>

#include "../runtime/util/rs_err.h"

typedef enum cap_codec { CAP_CODEC_DEFAULT, CAP_CODEC_H264, CAP_CODEC_HEVC, CAP_CODEC_VP9, CAP_CODEC_AV1 } cap_codec;
typedef enum cap_hw { CAP_HW_AUTO, CAP_HW_OFF, CAP_HW_NVENC, CAP_HW_VAAPI } cap_hw;
typedef enum cap_chroma { CAP_CHROMA_420, CAP_CHROMA_444 } cap_chroma;

#define CAP_ENC_PRESET_MAX 32

/* Zero means default for every field: the container's codec (mp4, mkv:
 * h264; webm: vp9), the encoder's default CRF and preset (cap_enc.c's
 * table, chosen from docs/capture.md's measurements), hardware if it works,
 * 4:2:0. */
typedef struct cap_enc {
    cap_codec codec;
    int crf;                          /* constant quality, 1..the encoder's max; 0: default */
    int64_t bitrate;                  /* bits/s, average; instead of crf (both: refused) */
    char preset[CAP_ENC_PRESET_MAX];  /* the encoder's own name for its speed/quality trade */
    cap_hw hw;
    cap_chroma chroma;
} cap_enc;

bool cap_codec_parse(const char *s, cap_codec *out);   /* h264 hevc vp9 av1 */
const char *cap_codec_name(cap_codec c);               /* "h264"...; the container's default: "default" */
bool cap_hw_parse(const char *s, cap_hw *out);         /* auto off nvenc vaapi */
bool cap_chroma_parse(const char *s, cap_chroma *out); /* yuv420p yuv444p */
/* "4M", "800k", "2500000" -> bits/s; false when malformed or outside 10k..1G */
bool cap_bitrate_parse(const char *s, int64_t *out);

struct cap_sink;

/* Checks enc against the sink's output (its container takes the codec;
 * the encoder takes the preset, CRF and chroma) and picks the encoder,
 * probing hardware; the sink remembers both (s->enc, s->enc_name) and,
 * for 4:4:4, asks the capture for RGBA frames (s->fmt).  When --hw auto
 * fell back from a hardware encoder whose device exists, s->enc_note says
 * which one was tried, why it failed, and what is used instead (one line,
 * no newline); otherwise it is empty.  Sinks that are not video files
 * (y4m, images, null:) take only the zero enc. */
bool cap_sink_encoder(struct cap_sink *s, const cap_enc *enc, rs_err *err);

/* bench encode: one encoder over frames held in memory. */
typedef struct cap_enc_trial {
    char encoder[32];     /* the encoder used */
    char preset[CAP_ENC_PRESET_MAX];
    int crf;
    uint64_t bytes;       /* all packets */
    double encode_s;      /* send + receive, flush included */
} cap_enc_trial;

/* Encodes n I420 frames of w x h (BT.709 limited, as the capture makes
 * them), decodes the packets again with libavcodec into `decoded` (n I420
 * frames) and fills t.  Software encoders only (enc->hw is ignored). */
bool cap_enc_trial_run(const cap_enc *enc, int w, int h, const uint8_t *i420, int n, uint8_t *decoded,
                       cap_enc_trial *t, rs_err *err);
/* The software encoder this FFmpeg would use for codec c at w x h (4:2:0), or NULL. */
const char *cap_enc_software(cap_codec c, int w, int h);

#endif
