/* A job's encoder options (codec, crf, bitrate, preset, pix_fmt, audio) and its
 * quality preset: checked
 * at upload, stored as one string, given to the job's renders. */
#ifndef SVC_ENCODE_H
#define SVC_ENCODE_H

#include <stdbool.h>
#include <stddef.h>

#include "../capture/cap_enc.h"
#include "../runtime/util/rs_err.h"
#include "svc_config.h"

/* What an upload asked for; NULL or "": not asked. */
typedef struct svc_encode_req {
    const char *codec, *crf, *bitrate, *preset, *pix_fmt;
    const char *audio; /* "on" (the default: not stored) or "off" */
    const char *quality; /* a preset name (r_quality.h); "": the setting quality.  Always stored,
                            so every segment of a job is drawn alike whatever the daemon's default */
} svc_encode_req;

/* Checks q against the settings and the encoder for a video of format
 * ("mp4"...) at w x h; fills out with the canonical string ("" when
 * nothing was asked).  The message (SVC_ERR_BAD_PARAM) names the
 * parameter and the bound. */
bool svc_encode_check(const svc_config *cfg, const svc_encode_req *q, const char *format, int w, int h, char *out,
                      size_t n, rs_err *err);
/* The render options of a stored string: opt[i] ("--codec") and val[i]
 * ("hevc"), at most max; returns how many. */
int svc_encode_argv(const char *encode, char opt[][24], char val[][CAP_ENC_PRESET_MAX], int max);
/* One key's value ("codec" -> "hevc"), "" when absent. */
void svc_encode_get(const char *encode, const char *key, char *out, size_t n);
/* Whether a job of this format and encoder string has a live stream:
 * MPEG-TS pieces carry H.264 or HEVC, so .mp4 or .mkv with h264 (their
 * default) or hevc (docs/service.md, "Watching while it renders"). */
bool svc_encode_streamable(const char *format, const char *encode);

#endif
