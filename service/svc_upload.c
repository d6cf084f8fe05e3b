/* svc_upload: an upload on its way to becoming a job (svc_upload.h). */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "svc_encode.h"
#include "svc_local.h"
#include "svc_upload.h"
#include "../capture/cap.h"
#include "../runtime/replay/rp.h"

/* --- the body and the parameters --- */

bool svc_upload_append(svc_upload *u, const void *data, size_t n)
{
    /* libmicrohttpd can open a file part with an empty piece: with
     * no body yet, body + len would be arithmetic on NULL */
    if (u->too_large || u->oom || n == 0)
        return true;
    if (u->len + n > (size_t)u->limit) {
        u->too_large = true;
        free(u->body);
        u->body = NULL;
        u->len = u->cap = 0;
        return true;
    }
    if (u->len + n > u->cap) {
        size_t nc = u->cap ? u->cap * 2 : 16384;
        while (nc < u->len + n)
            nc *= 2;
        uint8_t *p = realloc(u->body, nc);
        if (!p) {
            u->oom = true;
            return false;
        }
        u->body = p;
        u->cap = nc;
    }
    memcpy(u->body + u->len, data, n);
    u->len += n;
    return true;
}

void svc_upload_name(svc_upload *u, const char *name)
{
    if (!name || !*name)
        return;
    const char *slash = strrchr(name, '/');
    name = slash ? slash + 1 : name;
    size_t k = 0;
    for (const char *p = name; *p && k < sizeof u->name - 1; p++)
        u->name[k++] = (unsigned char)*p < 0x20 || *p == 0x7f ? '_' : *p;
    u->name[k] = 0;
}

/* The slot of parameter key in p, and its room; NULL for no parameter. */
static char *param_slot(svc_job_params *p, const char *key, size_t *room)
{
    static const struct {
        const char *key;
        size_t off, room;
    } slots[] = {
#define X(name, n) {#name, offsetof(svc_job_params, name), n},
        SVC_JOB_PARAMS(X)
#undef X
    };
    for (size_t i = 0; i < sizeof slots / sizeof *slots; i++)
        if (!strcmp(key, slots[i].key)) {
            *room = slots[i].room;
            return (char *)p + slots[i].off;
        }
    return NULL;
}

bool svc_upload_field(svc_upload *u, const char *key, const char *filename, const char *data, uint64_t off,
                      size_t size)
{
    if (!key) /* a part without a name: nothing we asked for */
        return true;
    if (!strcmp(key, "replay") || !strcmp(key, "file")) {
        if (off == 0 && filename)
            svc_upload_name(u, filename);
        return svc_upload_append(u, data, size);
    }
    size_t room = 0;
    char *dst = param_slot(&u->p, key, &room);
    if (dst && off + size < room) {
        memcpy(dst + off, data, size);
        dst[off + size] = 0;
    } else if (dst) {
        dst[0] = 0; /* too long: the pieces before this one go too, however the value was cut */
    }
    return true;
}

bool svc_upload_param(svc_upload *u, const char *key, const char *value, rs_err *err)
{
    size_t room = 0;
    char *dst = param_slot(&u->p, key, &room);
    if (!dst || dst[0] || !value)
        return true;
    if (strlen(value) >= room)
        return rs_fail(err, SVC_ERR_BAD_PARAM, "%s: at most %zu characters", key, room - 1);
    snprintf(dst, room, "%s", value);
    return true;
}

void svc_upload_free(svc_upload *u)
{
    free(u->body);
    u->body = NULL;
    u->len = u->cap = 0;
}

/* --- the job it asks for --- */

/* ?size=WxH against the operator's bounds (and a fixed render_size). */
static bool job_size(const svc_config *cfg, const char *size, svc_job *j, rs_err *err)
{
    long w, h;
    char x, extra;
    if (sscanf(size, "%ld%c%ld%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X'))
        return rs_fail(err, SVC_ERR_BAD_PARAM, "size '%s': expected WxH, such as 640x360", size);
    if (w < 16 || h < 16 || w > cfg->max_width || h > cfg->max_height || (w | h) & 1)
        return rs_fail(err, SVC_ERR_BAD_PARAM, "size %ldx%ld: each side must be even, at least 16 and at most %dx%d", w,
                       h, cfg->max_width, cfg->max_height);
    j->width = (int)w, j->height = (int)h;
    rs_err serr = {0};
    if (cfg->render_width &&
        !cap_check_sizes_for(CAP_I420, cfg->render_width, cfg->render_height, j->width, j->height, &serr))
        return rs_fail(err, SVC_ERR_BAD_PARAM, "size %s: %s", size, serr.msg);
    return true;
}

bool svc_upload_job(const svc_config *cfg, svc_upload *u, svc_job *j, rs_err *err)
{
    *j = (svc_job){0};
    snprintf(j->name, sizeof j->name, "%s", u->name[0] ? u->name : "upload.rsr");
    j->width = cfg->width;
    j->height = cfg->height;
    snprintf(j->format, sizeof j->format, "%s", cfg->format);
    const svc_job_params *p = &u->p;
    if (p->size[0] && !job_size(cfg, p->size, j, err))
        return false;
    if (p->format[0]) {
        if (strcmp(p->format, "mp4") && strcmp(p->format, "webm") && strcmp(p->format, "mkv"))
            return rs_fail(err, SVC_ERR_BAD_PARAM, "format '%s': expected mp4, webm or mkv", p->format);
        snprintf(j->format, sizeof j->format, "%s", p->format);
    }
    svc_encode_req eq = {p->codec, p->crf, p->bitrate, p->preset, p->pix_fmt, p->audio, p->quality};
    if (!svc_encode_check(cfg, &eq, j->format, j->width, j->height, j->encode, sizeof j->encode, err))
        return false;
    if (!svc_check_upload(cfg, u->body, u->len, j->name, j, err))
        return false;
    j->replay = u->body;
    j->replay_len = u->len;
    j->segment_ticks = cfg->segment_seconds * 60; /* the store splits it if it is longer */
    j->first_segment_ticks = cfg->first_segment_seconds * 60;
    return true;
}

/* --- the replay's checks --- */

/* The replay plays back as recorded: the same game rules, and every
 * checkpoint and the final hash reproduced by re-simulating it (what
 * `ringside replay verify` does; about 15 million ticks/s, so a 30-minute
 * replay costs a few hundredths of a second of the request's thread). */
static bool verify_upload(const rp_replay *rp, const char *name, rs_err *err)
{
    rs_err verr = {0};
    if (!rp_check_game(rp, name, &verr))
        return rs_fail(err, SVC_ERR_GAME_VERSION, "%s", verr.msg);
    rp_verify_result res;
    if (!rp_verify(rp, NULL, NULL, NULL, &res, &verr))
        return rs_fail(err, SVC_ERR_REPLAY, "%s: %s", name, verr.msg);
    if (res.header_mismatch)
        return rs_fail(err, SVC_ERR_DESYNC,
                       "%s: the header says winner %d, rounds %d-%d, but the simulation gives winner %d, rounds %d-%d",
                       name, rp->winner, rp->rounds[0], rp->rounds[1], res.winner, res.rounds[0], res.rounds[1]);
    if (!res.ok) {
        char what[400];
        rp_desync_text(&res, what, sizeof what);
        return rs_fail(err, SVC_ERR_DESYNC, "%s: %s", name, what);
    }
    return true;
}

static bool too_long(const svc_config *cfg, const char *name, uint64_t ticks, rs_err *err)
{
    return rs_fail(err, SVC_ERR_TOO_LONG, "%s: the replay lasts %llu s; this service renders at most %d s (max_seconds)",
                   name, (unsigned long long)((ticks + 59) / 60), cfg->max_seconds);
}

/* DESIGN: cheapest first.  Size, then the declared length (before decoding,
 * which allocates 2 bytes a tick), then the parse, then the re-simulation:
 * an oversized or overlong upload costs no simulation, and a desynced or
 * foreign replay is refused here instead of after minutes of rendering. */
bool svc_check_upload(const svc_config *cfg, const uint8_t *data, size_t len, const char *name, svc_job *j,
                      rs_err *err)
{
    if (len == 0)
        return rs_fail(err, SVC_ERR_EMPTY, "empty upload: send the replay file (.rsr) as the request body");
    if (len > (size_t)cfg->max_upload)
        return rs_fail(err, SVC_ERR_TOO_LARGE, "%s: %zu bytes is over the upload limit of %ld bytes", name, len,
                       cfg->max_upload);
    /* a small file can declare days of run-length coded play, and decoding
     * it would allocate 2 bytes a tick: its declared length first */
    uint64_t ticks = 0;
    if (rp_peek_ticks(data, len, &ticks) && ticks > (uint64_t)cfg->max_seconds * 60 && ticks <= RP_MAX_TICKS)
        return too_long(cfg, name, ticks, err);
    rp_replay rp = {0};
    rs_err perr = {0};
    if (!rp_decode(data, len, name, &rp, &perr))
        return rs_fail(err, SVC_ERR_REPLAY, "%s", perr.msg);
    j->frames_total = (int64_t)rp.ticks;
    j->stage = rp.stage;
    j->kind[0] = rp.kind[0], j->kind[1] = rp.kind[1];
    j->winner = rp.winner;
    j->rounds[0] = rp.rounds[0], j->rounds[1] = rp.rounds[1];
    bool ok = true;
    if (j->frames_total == 0)
        ok = rs_fail(err, SVC_ERR_REPLAY, "%s: the replay has no ticks: nothing to render", name);
    else if (j->frames_total > (int64_t)cfg->max_seconds * 60) /* one job must not hold a worker for days */
        ok = too_long(cfg, name, (uint64_t)j->frames_total, err);
    else
        ok = verify_upload(&rp, name, err);
    rp_free(&rp);
    return ok;
}

/* --- quotas --- */

int svc_upload_quota(svc_store *s, const svc_token *t, const svc_job *j, char *msg, size_t n, int64_t *retry,
                     rs_err *err)
{
    if (t->max_queued == 0 && t->seconds_per_hour == 0)
        return 1;
    svc_usage u;
    if (!s->ops->token_usage(s, t->id, &u, err))
        return -1;
    if (t->max_queued > 0 && u.active >= t->max_queued) {
        *retry = 30; /* jobs end at render speed: look again in a while */
        snprintf(msg, n, "token '%s' has %" PRId64 " jobs queued or running, its quota (max_queued %d)", t->name,
                 u.active, t->max_queued);
        return 0;
    }
    int64_t limit = (int64_t)t->seconds_per_hour * 60; /* in ticks, as frames_total */
    if (t->seconds_per_hour > 0 && u.hour_frames + j->frames_total > limit) {
        /* the oldest job of the hour leaves the window first */
        *retry = u.oldest ? u.oldest + 3600 - u.now : 3600;
        if (*retry < 1)
            *retry = 1;
        snprintf(msg, n,
                 "token '%s' submitted %" PRId64 " s of game time in the last hour; this replay's %" PRId64
                 " s would pass its quota (seconds_per_hour %d)",
                 t->name, u.hour_frames / 60, (j->frames_total + 59) / 60, t->seconds_per_hour);
        return 0;
    }
    return 1;
}
