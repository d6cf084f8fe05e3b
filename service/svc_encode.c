/* A job's encoder options: checked at upload against the operator's bounds
 * (settings codecs, min_crf, max_bitrate, presets) and the encoder itself,
 * kept with the job as one canonical string ("codec=hevc crf=24"), and
 * turned back into render options for each of the job's renders.
 *
 * DESIGN: the string, not one column per option, so the queue's schema
 * does not change each time the render gains an encoder option; only
 * svc_encode_check writes it, so svc_encode_argv can trust its keys. */
#include "svc_encode.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../capture/cap.h"
#include "../capture/cap_enc.h"
#include "../capture/cap_sink.h"
#include "../runtime/render/r_quality.h"
#include "svc_local.h"

/* A whole decimal number, sign allowed ("-3", "12"). */
static bool number(const char *s, size_t n, long *v)
{
    char buf[24], *end;
    if (!n || n >= sizeof buf)
        return false;
    memcpy(buf, s, n);
    buf[n] = 0;
    *v = strtol(buf, &end, 10);
    return *end == 0 && end != buf;
}

/* Is word in the comma-separated list?  An item A..B takes the numbers
 * from A to B (the numbered presets: "4..13").  "" or "*": everything. */
static bool listed(const char *list, const char *word)
{
    if (!list[0] || !strcmp(list, "*"))
        return true;
    size_t n = strlen(word);
    long w = 0, lo, hi;
    bool numeric = number(word, n, &w);
    for (const char *p = list; *p;) {
        while (*p == ' ' || *p == ',')
            p++;
        size_t k = strcspn(p, ", ");
        const char *dots = strstr(p, "..");
        if (dots && dots < p + k) {
            if (numeric && number(p, (size_t)(dots - p), &lo) && number(dots + 2, (size_t)(p + k - dots - 2), &hi) &&
                w >= lo && w <= hi)
                return true;
        } else if (k == n && !strncmp(p, word, n)) {
            return true;
        }
        p += k;
    }
    return false;
}

static bool word_ok(const char *s)
{
    if (!s[0] || strlen(s) >= CAP_ENC_PRESET_MAX)
        return false;
    for (const char *p = s; *p; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '-'))
            return false;
    return true;
}

static void put(char *out, size_t n, const char *key, const char *value)
{
    size_t len = strlen(out);
    snprintf(out + len, n - len, "%s%s=%s", len ? " " : "", key, value);
}

bool svc_encode_check(const svc_config *cfg, const svc_encode_req *q, const char *format, int w, int h, char *out,
                      size_t n, rs_err *err)
{
    out[0] = 0;
    cap_enc e = {.hw = CAP_HW_OFF}; /* the check never opens hardware: renders choose it on their own machine */
    if (q->codec && q->codec[0]) {
        if (!cap_codec_parse(q->codec, &e.codec))
            return rs_fail(err, SVC_ERR_BAD_PARAM, "codec '%s': expected h264, hevc, vp9 or av1", q->codec);
        if (!listed(cfg->codecs, q->codec))
            return rs_fail(err, SVC_ERR_BAD_PARAM, "codec %s: this service encodes %s (setting codecs)", q->codec,
                           cfg->codecs);
        put(out, n, "codec", q->codec);
    }
    if (q->crf && q->crf[0]) {
        char *end;
        long v = strtol(q->crf, &end, 10);
        if (*end || end == q->crf || v < 1 || v > 63)
            return rs_fail(err, SVC_ERR_BAD_PARAM, "crf '%s': expected a number from 1 to 63", q->crf);
        if (v < cfg->min_crf)
            return rs_fail(err, SVC_ERR_BAD_PARAM, "crf %ld: this service's best quality is crf %d (setting min_crf)", v,
                           cfg->min_crf);
        e.crf = (int)v;
        put(out, n, "crf", q->crf);
    }
    if (q->bitrate && q->bitrate[0]) {
        if (!cap_bitrate_parse(q->bitrate, &e.bitrate))
            return rs_fail(err, SVC_ERR_BAD_PARAM, "bitrate '%s': expected bits a second such as 4M or 800k", q->bitrate);
        if (e.bitrate > (int64_t)cfg->max_bitrate * 1000)
            return rs_fail(err, SVC_ERR_BAD_PARAM, "bitrate %s: over this service's %d kbit/s (setting max_bitrate)",
                           q->bitrate, cfg->max_bitrate);
        put(out, n, "bitrate", q->bitrate);
    }
    if (q->preset && q->preset[0]) {
        if (!word_ok(q->preset))
            return rs_fail(err, SVC_ERR_BAD_PARAM, "preset '%s': expected a name such as veryfast or a number", q->preset);
        if (!listed(cfg->presets, q->preset))
            return rs_fail(err, SVC_ERR_BAD_PARAM, "preset %s: this service allows %s (setting presets)", q->preset,
                           cfg->presets);
        snprintf(e.preset, sizeof e.preset, "%s", q->preset);
        put(out, n, "preset", q->preset);
    }
    if (q->pix_fmt && q->pix_fmt[0]) {
        if (!cap_chroma_parse(q->pix_fmt, &e.chroma))
            return rs_fail(err, SVC_ERR_BAD_PARAM, "pix_fmt '%s': expected yuv420p or yuv444p", q->pix_fmt);
        put(out, n, "pix_fmt", q->pix_fmt);
    }
    if (q->audio && q->audio[0]) {
        if (strcmp(q->audio, "on") && strcmp(q->audio, "off"))
            return rs_fail(err, SVC_ERR_BAD_PARAM, "audio '%s': expected on or off", q->audio);
        if (!strcmp(q->audio, "off"))
            put(out, n, "audio", "off"); /* render --audio off; the join gets no --replay */
    }
    const char *quality = q->quality && q->quality[0] ? q->quality : cfg->quality;
    if (!r_preset_named(quality))
        return rs_fail(err, SVC_ERR_BAD_PARAM, "quality '%s': expected %s", quality, r_preset_list());
    if (!out[0]) {
        put(out, n, "quality", quality);
        return strlen(out) + 1 < n || rs_fail(err, SVC_ERR_BAD_PARAM, "the options are too long together");
    }
    /* the encoder's own word on the rest (container, preset names, CRF range) */
    char path[32];
    snprintf(path, sizeof path, "job.%s", format);
    cap_sink s;
    if (!cap_sink_for(path, w, h, &s, err) || !cap_sink_encoder(&s, &e, err)) {
        const char *msg = err ? strstr(err->msg, ": ") : NULL;
        return rs_fail(err, SVC_ERR_BAD_PARAM, "%s", msg ? msg + 2 : "the encoder refuses these options");
    }
    put(out, n, "quality", quality);
    return strlen(out) + 1 < n || rs_fail(err, SVC_ERR_BAD_PARAM, "the options are too long together");
}

int svc_encode_argv(const char *encode, char opt[][24], char val[][CAP_ENC_PRESET_MAX], int max)
{
    int k = 0;
    for (const char *p = encode; *p && k < max;) {
        while (*p == ' ')
            p++;
        size_t len = strcspn(p, " "), eq = strcspn(p, "=");
        if (!len)
            break;
        if (eq < len && eq + 3 < 24 && len - eq - 1 < CAP_ENC_PRESET_MAX) {
            snprintf(opt[k], 24, "--%.*s", (int)eq, p);
            for (char *c = opt[k]; *c; c++)
                if (*c == '_')
                    *c = '-'; /* pix_fmt -> --pix-fmt */
            snprintf(val[k], CAP_ENC_PRESET_MAX, "%.*s", (int)(len - eq - 1), p + eq + 1);
            k++;
        }
        p += len;
    }
    return k;
}

void svc_encode_get(const char *encode, const char *key, char *out, size_t n)
{
    out[0] = 0;
    size_t kl = strlen(key);
    for (const char *p = encode; *p;) {
        while (*p == ' ')
            p++;
        size_t len = strcspn(p, " ");
        if (len > kl && !strncmp(p, key, kl) && p[kl] == '=') {
            snprintf(out, n, "%.*s", (int)(len - kl - 1), p + kl + 1);
            return;
        }
        p += len;
    }
}

bool svc_encode_streamable(const char *format, const char *encode)
{
    char codec[16];
    svc_encode_get(encode, "codec", codec, sizeof codec);
    return (!strcmp(format, "mp4") || !strcmp(format, "mkv")) && (!codec[0] || !strcmp(codec, "h264") || !strcmp(codec, "hevc"));
}
