/* svc_json: see svc_json.h. */
#include "svc_json.h"
#include "svc_encode.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../runtime/game/g_game.h"
#include "../runtime/replay/rp.h"

void svc_buf_free(svc_buf *b)
{
    free(b->p);
    memset(b, 0, sizeof *b);
}

static bool reserve(svc_buf *b, size_t n)
{
    if (b->oom)
        return false;
    if (b->len + n + 1 <= b->cap)
        return true;
    size_t cap = b->cap ? b->cap : 256;
    while (cap < b->len + n + 1)
        cap *= 2;
    char *p = realloc(b->p, cap);
    if (!p) {
        b->oom = true;
        return false;
    }
    b->p = p;
    b->cap = cap;
    return true;
}

void svc_buf_add(svc_buf *b, const char *s, size_t n)
{
    if (!reserve(b, n))
        return;
    memcpy(b->p + b->len, s, n);
    b->len += n;
    b->p[b->len] = 0;
}

void svc_buf_printf(svc_buf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0 || !reserve(b, (size_t)n))
        return;
    va_start(ap, fmt);
    vsnprintf(b->p + b->len, (size_t)n + 1, fmt, ap);
    va_end(ap);
    b->len += (size_t)n;
}

/* Length of a valid UTF-8 sequence at s (1..4), or 0. */
static int utf8_len(const unsigned char *s)
{
    if (s[0] < 0x80)
        return 1;
    int n = s[0] >= 0xf0 && s[0] <= 0xf4 ? 4 : s[0] >= 0xe0 && s[0] < 0xf0 ? 3 : s[0] >= 0xc2 && s[0] < 0xe0 ? 2 : 0;
    for (int i = 1; i < n; i++)
        if ((s[i] & 0xc0) != 0x80)
            return 0;
    if (n == 3 && ((s[0] == 0xe0 && s[1] < 0xa0) || (s[0] == 0xed && s[1] >= 0xa0)))
        return 0; /* overlong, or a UTF-16 surrogate */
    if (n == 4 && ((s[0] == 0xf0 && s[1] < 0x90) || (s[0] == 0xf4 && s[1] >= 0x90)))
        return 0;
    return n;
}

void svc_json_str(svc_buf *b, const char *str)
{
    const unsigned char *s = (const unsigned char *)(str ? str : "");
    svc_buf_add(b, "\"", 1);
    while (*s) {
        int n = utf8_len(s);
        if (n == 0) {
            svc_buf_add(b, "\\ufffd", 6);
            s++;
        } else if (n > 1) {
            svc_buf_add(b, (const char *)s, (size_t)n);
            s += n;
        } else {
            unsigned char c = *s++;
            if (c == '"' || c == '\\') {
                char e[2] = {'\\', (char)c};
                svc_buf_add(b, e, 2);
            } else if (c == '\n')
                svc_buf_add(b, "\\n", 2);
            else if (c < 0x20 || c == 0x7f)
                svc_buf_printf(b, "\\u%04x", c);
            else
                svc_buf_add(b, (const char *)&c, 1);
        }
    }
    svc_buf_add(b, "\"", 1);
}

static void json_time(svc_buf *b, const char *key, int64_t t)
{
    if (t <= 0) {
        svc_buf_printf(b, ",\"%s\":null", key);
        return;
    }
    time_t tt = (time_t)t;
    struct tm tm;
    char s[32];
    gmtime_r(&tt, &tm);
    strftime(s, sizeof s, "%Y-%m-%dT%H:%M:%SZ", &tm);
    svc_buf_printf(b, ",\"%s\":\"%s\"", key, s);
}

/* One unit: what it is, where it stands, who rendered it. */
static void json_unit(svc_buf *b, const svc_unit *u)
{
    svc_buf_printf(b, "{");
    if (u->kind == SVC_UNIT_SEGMENT)
        svc_buf_printf(b, "\"index\":%d,\"ticks\":[%lld,%lld],", u->index, (long long)u->first_tick,
                       (long long)u->end_tick);
    svc_buf_printf(b, "\"state\":\"%s\",\"attempts\":%d,\"renders\":%d,\"frames_done\":%lld,\"worker\":",
                   svc_state_name(u->state), u->attempts, u->renders, (long long)u->frames_done);
    const char *who = u->state == SVC_RUNNING ? u->owner : u->done_by;
    if (who[0])
        svc_json_str(b, who);
    else
        svc_buf_add(b, "null", 4);
    svc_buf_add(b, ",\"error\":", 9);
    if (u->error[0])
        svc_json_str(b, u->error);
    else
        svc_buf_add(b, "null", 4);
    svc_buf_add(b, "}", 1);
}

/* The codec the job asked for (svc_encode.c), else the one capture's
 * FFmpeg sink uses for the format (cap_enc.c). */
static void codec_of(const svc_job *j, char *out, size_t n)
{
    svc_encode_get(j->encode, "codec", out, n);
    if (!out[0])
        snprintf(out, n, "%s", !strcmp(j->format, "webm") ? "vp9" : "h264");
}

/* What the replay says (svc_job's header fields), null when not known. */
static void json_replay(svc_buf *b, const svc_job *j)
{
    static const char *const kinds[] = {"human", "cpu"};
    if (j->stage < 0 || j->stage >= G_STAGES) {
        svc_buf_printf(b, ",\"stage\":null,\"players\":null,\"winner\":null,\"rounds\":null");
        return;
    }
    svc_buf_add(b, ",\"stage\":", 9);
    svc_json_str(b, g_stages[j->stage].name);
    svc_buf_printf(b, ",\"players\":[\"%s\",\"%s\"]", kinds[j->kind[0] == RP_CPU], kinds[j->kind[1] == RP_CPU]);
    if (j->winner >= 0)
        svc_buf_printf(b, ",\"winner\":%d,\"rounds\":[%d,%d]", j->winner, j->rounds[0], j->rounds[1]);
    else
        svc_buf_printf(b, ",\"winner\":null,\"rounds\":null");
}

void svc_json_job(svc_buf *b, const svc_job *j, int max_attempts, const svc_unit *units, int n, const svc_job_view *v)
{
    svc_buf_printf(b, "{\"id\":%lld,\"state\":\"%s\",\"name\":", (long long)j->id, svc_state_name(j->state));
    svc_json_str(b, j->name);
    svc_buf_printf(b, ",\"size\":\"%dx%d\",\"format\":", j->width, j->height);
    svc_json_str(b, j->format);
    int64_t done = j->state == SVC_DONE ? j->frames_total : j->frames_done;
    double progress = j->frames_total > 0 ? (double)done / (double)j->frames_total : 0.0;
    svc_buf_printf(b, ",\"frames_done\":%lld,\"frames_total\":%lld,\"progress\":%.4f,\"fps\":%.2f", (long long)done,
                   (long long)j->frames_total, progress, j->state == SVC_RUNNING ? j->fps : 0.0);
    if (v && v->eta_s >= 0)
        svc_buf_printf(b, ",\"eta_s\":%.1f", v->eta_s);
    else if (j->state == SVC_RUNNING && j->fps > 0 && j->frames_total >= done)
        svc_buf_printf(b, ",\"eta_s\":%.1f", (double)(j->frames_total - done) / j->fps);
    else
        svc_buf_add(b, ",\"eta_s\":null", 13);
    if (v && v->queue_position > 0)
        svc_buf_printf(b, ",\"queue_position\":%lld", (long long)v->queue_position);
    else
        svc_buf_add(b, ",\"queue_position\":null", 22);
    json_replay(b, j);
    char codec[16];
    codec_of(j, codec, sizeof codec);
    char audio[8], quality[16];
    svc_encode_get(j->encode, "audio", audio, sizeof audio); /* stored only when off */
    svc_encode_get(j->encode, "quality", quality, sizeof quality); /* "" for a job queued before presets */
    svc_buf_printf(b, ",\"length_s\":%.2f,\"codec\":\"%s\",\"audio\":%s,\"encode\":", j->frames_total / 60.0, codec,
                   strcmp(audio, "off") ? "true" : "false");
    svc_json_str(b, j->encode);
    svc_buf_add(b, ",\"quality\":", 11);
    if (quality[0])
        svc_json_str(b, quality);
    else
        svc_buf_add(b, "null", 4);
    if (v && v->bytes >= 0)
        svc_buf_printf(b, ",\"bytes\":%lld", (long long)v->bytes);
    else
        svc_buf_add(b, ",\"bytes\":null", 13);
    if (j->state == SVC_DONE && j->started > 0 && j->finished >= j->started)
        svc_buf_printf(b, ",\"render_s\":%lld", (long long)(j->finished - j->started));
    else
        svc_buf_add(b, ",\"render_s\":null", 16);
    svc_buf_printf(b, ",\"attempts\":%d,\"max_attempts\":%d,", j->attempts, max_attempts);
    if (j->lost > 0) /* leases lost to daemon crashes: not attempts, shown when there were any */
        svc_buf_printf(b, "\"lost_leases\":%d,", j->lost);
    svc_buf_add(b, "\"error\":", 8);
    if (j->error[0])
        svc_json_str(b, j->error);
    else
        svc_buf_add(b, "null", 4);
    if (j->desync_tick >= 0)
        svc_buf_printf(b, ",\"desync_tick\":%lld", (long long)j->desync_tick);
    else
        svc_buf_add(b, ",\"desync_tick\":null", 19);
    if (j->state == SVC_RUNNING && j->owner[0]) {
        svc_buf_add(b, ",\"worker\":", 10);
        svc_json_str(b, j->owner);
    }
    json_time(b, "created", j->created);
    json_time(b, "started", j->started);
    json_time(b, "finished", j->finished);
    if (j->segments > 0) {
        svc_buf_printf(b, ",\"segment_seconds\":%g,\"segment_count\":%d", j->segment_ticks / 60.0, j->segments);
        int k = 0;
        for (int i = 0; i < n; i++)
            if (units[i].kind == SVC_UNIT_SEGMENT) {
                if (k++)
                    svc_buf_add(b, ",", 1);
                else
                    svc_buf_add(b, ",\"segments\":[", 13);
                json_unit(b, &units[i]);
            }
        if (k)
            svc_buf_add(b, "]", 1);
        for (int i = 0; i < n; i++)
            if (units[i].kind == SVC_UNIT_JOIN) {
                svc_buf_add(b, ",\"join\":", 8);
                json_unit(b, &units[i]);
            }
    }
    svc_buf_printf(b, ",\"url\":\"/jobs/%lld\"", (long long)j->id);
    if (j->expired)
        svc_buf_add(b, ",\"expired\":true", 15);
    else if (j->state == SVC_DONE)
        svc_buf_printf(b, ",\"video\":\"/jobs/%lld/video\",\"hashes\":\"/jobs/%lld/hashes\"", (long long)j->id,
                       (long long)j->id);
    if (v && v->poster && !j->expired)
        svc_buf_printf(b, ",\"poster\":\"/jobs/%lld/poster\"", (long long)j->id);
    svc_buf_printf(b, ",\"log\":\"/jobs/%lld/log\"", (long long)j->id);
    /* the live stream's playlist, from the first unit on (it lists nothing
     * until then), and how much of the match it lists */
    if (!j->expired && j->state != SVC_FAILED && j->state != SVC_CANCELLED && svc_encode_streamable(j->format, j->encode)) {
        svc_buf_printf(b, ",\"stream\":\"/jobs/%lld/stream.m3u8\"", (long long)j->id);
        if (v && v->stream_s >= 0)
            svc_buf_printf(b, ",\"stream_s\":%.2f", v->stream_s);
    }
    svc_buf_add(b, "}", 1);
}

void svc_json_error(svc_buf *b, const char *msg)
{
    svc_buf_add(b, "{\"error\":", 9);
    svc_json_str(b, msg);
    svc_buf_add(b, "}\n", 2);
}
