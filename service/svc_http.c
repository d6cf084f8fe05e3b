/* svc_http: the HTTP API and dashboard of `ringside serve` (libmicrohttpd).
 *
 * DESIGN: libmicrohttpd runs a small pool of threads; each request is
 * answered from the request's own context (struct req) and the daemon's
 * HTTP store handle, which locks itself.  Live numbers of running renders
 * come from svc_daemon.live under its mutex; nothing here touches a worker
 * or a child process.  Uploads are read into memory up to max_upload (the
 * replay format is small: a 20-minute match is a few tens of KiB) and
 * checked by the replay parser before the job is committed; the job id
 * goes back only after the commit. */
#define _GNU_SOURCE /* strcasestr */
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "svc_json.h"
#include "svc_local.h"
#include "svc_log.h"
#include "../capture/cap.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_version.h"

/* --- error ids, upload checks and Range parsing: plain functions, unit-tested --- */

const char *svc_error_text(int code)
{
    static const char *const text[] = {
#define X(id, t) t,
        SVC_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_SVC, text, (int)(sizeof text / sizeof text[0]));
}

/* The one place where an error becomes an HTTP status. */
static const struct {
    int id;
    unsigned short status;
} http_status[] = {
    {SVC_ERR_EMPTY, 400},     {SVC_ERR_TOO_LARGE, 413}, {SVC_ERR_TOO_LONG, 400}, {SVC_ERR_REPLAY, 400},
    {SVC_ERR_BAD_BODY, 400},  {SVC_ERR_BAD_PARAM, 400}, {SVC_ERR_NOT_FOUND, 404}, {SVC_ERR_CONFLICT, 409},
    {SVC_ERR_GONE, 410},      {SVC_ERR_RANGE, 416},     {SVC_ERR_METHOD, 405},   {SVC_ERR_DRAINING, 503},
    {SVC_ERR_NOMEM, 500},
    {SVC_ERR_DESYNC, 400},    {SVC_ERR_GAME_VERSION, 400},
};

unsigned svc_http_status(int code)
{
    for (size_t i = 0; i < sizeof http_status / sizeof http_status[0]; i++)
        if (http_status[i].id == code)
            return http_status[i].status;
    return RS_ERR_MODULE(code) == RS_ERR_MOD_SVC_STORE ? 503 : 500;
}

/* The replay plays back as recorded: the same game rules, and every
 * checkpoint and the final hash reproduced by re-simulating it (what
 * `ringside replay verify` does; about 15 million ticks/s, so a 30-minute
 * replay costs a few hundredths of a second of this request's thread). */
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
    if (!res.ok)
        return rs_fail(err, SVC_ERR_DESYNC,
                       "%s: desync at tick %" PRIu64 ": state hash %016" PRIx64 ", recorded %016" PRIx64
                       " (last matching checkpoint: tick %" PRIu64 "; the inputs diverge in ticks %" PRIu64 "..%" PRIu64 ")",
                       name, res.desync_tick, res.got, res.want, res.last_good_tick, res.last_good_tick + 1,
                       res.desync_tick);
    return true;
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
        return rs_fail(err, SVC_ERR_TOO_LARGE, "%s: %zu bytes is over the upload limit of %ld bytes", name, len, cfg->max_upload);
    /* the tick count (byte 20) first: a small file can declare days of
     * run-length coded play, and decoding it would allocate 2 bytes a tick */
    if (len >= 28 && !memcmp(data, RP_MAGIC, 4)) {
        uint64_t ticks = 0;
        for (int k = 0; k < 8; k++)
            ticks |= (uint64_t)data[20 + k] << (8 * k);
        if (ticks > (uint64_t)cfg->max_seconds * 60 && ticks <= RP_MAX_TICKS)
            return rs_fail(err, SVC_ERR_TOO_LONG, "%s: the replay lasts %llu s; this service renders at most %d s (max_seconds)",
                           name, (unsigned long long)((ticks + 59) / 60), cfg->max_seconds);
    }
    rp_replay rp = {0};
    rs_err perr = {0};
    if (!rp_decode(data, len, name, &rp, &perr))
        return rs_fail(err, SVC_ERR_REPLAY, "%s", perr.msg);
    j->frames_total = (int64_t)rp.ticks;
    bool ok = true;
    if (j->frames_total == 0)
        ok = rs_fail(err, SVC_ERR_REPLAY, "%s: the replay has no ticks: nothing to render", name);
    /* a small file can describe days of play (inputs are run-length coded):
     * one job must not hold a worker for that long */
    else if (j->frames_total > (int64_t)cfg->max_seconds * 60)
        ok = rs_fail(err, SVC_ERR_TOO_LONG, "%s: the replay lasts %lld s; this service renders at most %d s (max_seconds)",
                     name, (long long)((j->frames_total + 59) / 60), cfg->max_seconds);
    else
        ok = verify_upload(&rp, name, err);
    rp_free(&rp);
    return ok;
}

int svc_parse_range(const char *h, uint64_t len, uint64_t *first, uint64_t *last)
{
    if (!h || strncmp(h, "bytes=", 6) != 0)
        return 0;
    const char *p = h + 6;
    if (strchr(p, ','))
        return 0; /* several ranges: allowed to answer with the whole file */
    char *end;
    if (*p == '-') { /* the last N bytes */
        if (!isdigit((unsigned char)p[1]))
            return 0;
        errno = 0;
        unsigned long long n = strtoull(p + 1, &end, 10);
        if (errno || *end || n == 0)
            return n == 0 && !errno && !*end ? -1 : 0;
        if (len == 0)
            return -1;
        *first = n >= len ? 0 : len - n;
        *last = len - 1;
        return 1;
    }
    if (!isdigit((unsigned char)*p))
        return 0;
    errno = 0;
    unsigned long long a = strtoull(p, &end, 10);
    if (errno || *end != '-')
        return 0;
    p = end + 1;
    unsigned long long b = len ? len - 1 : 0;
    if (*p) {
        if (!isdigit((unsigned char)*p))
            return 0;
        b = strtoull(p, &end, 10);
        if (errno || *end || b < a)
            return 0;
    }
    if (a >= len)
        return -1;
    *first = a;
    *last = b >= len ? len - 1 : b;
    return 1;
}

#if defined(RS_HAVE_MHD)
#include <microhttpd.h>

typedef struct req {
    bool post_jobs;
    bool done;          /* a response was queued early (413, 503) */
    struct MHD_PostProcessor *pp;
    uint8_t *body;
    size_t len, cap;
    bool too_large, oom;
    const char *bad; /* a malformed body: answered 400 once it is read */
    char name[SVC_NAME_MAX];
    char size[32], format[16];
} req;

static enum MHD_Result reply(struct MHD_Connection *c, unsigned status, const char *type, const char *body, size_t n)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(n, (void *)body, MHD_RESPMEM_MUST_COPY);
    if (!r)
        return MHD_NO;
    MHD_add_response_header(r, "Content-Type", type);
    MHD_add_response_header(r, "Cache-Control", "no-store");
    enum MHD_Result ret = MHD_queue_response(c, status, r);
    MHD_destroy_response(r);
    return ret;
}

static enum MHD_Result reply_json(struct MHD_Connection *c, unsigned status, svc_buf *b)
{
    if (b->oom) {
        svc_buf_free(b);
        return MHD_NO;
    }
    enum MHD_Result r = reply(c, status, "application/json", b->p ? b->p : "", b->len);
    svc_buf_free(b);
    return r;
}

/* An error answer: the status comes from the error id (svc_http_status). */
static enum MHD_Result reply_error(struct MHD_Connection *c, int id, const char *fmt, ...) RS_PRINTF(3, 4);
static enum MHD_Result reply_error(struct MHD_Connection *c, int id, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    svc_buf b = {0};
    svc_json_error(&b, msg);
    return reply_json(c, svc_http_status(id), &b);
}

static bool append(req *q, const char *data, size_t n, long limit)
{
    if (q->too_large || q->oom)
        return true;
    if (q->len + n > (size_t)limit) {
        q->too_large = true;
        free(q->body);
        q->body = NULL;
        q->len = q->cap = 0;
        return true;
    }
    if (q->len + n > q->cap) {
        size_t nc = q->cap ? q->cap * 2 : 16384;
        while (nc < q->len + n)
            nc *= 2;
        uint8_t *p = realloc(q->body, nc);
        if (!p) {
            q->oom = true;
            return false;
        }
        q->body = p;
        q->cap = nc;
    }
    memcpy(q->body + q->len, data, n);
    q->len += n;
    return true;
}

static void set_name(req *q, const char *name)
{
    if (!name || !*name)
        return;
    const char *slash = strrchr(name, '/');
    name = slash ? slash + 1 : name;
    size_t k = 0;
    for (const char *p = name; *p && k < sizeof q->name - 1; p++)
        q->name[k++] = (unsigned char)*p < 0x20 || *p == 0x7f ? '_' : *p;
    q->name[k] = 0;
}

static enum MHD_Result post_field(void *cls, enum MHD_ValueKind kind, const char *key, const char *filename,
                                  const char *content_type, const char *transfer_encoding, const char *data,
                                  uint64_t off, size_t size)
{
    (void)kind, (void)content_type, (void)transfer_encoding;
    svc_daemon *d = ((void **)cls)[0];
    req *q = ((void **)cls)[1];
    if (!key) /* a part without a name: nothing we asked for */
        return MHD_YES;
    if (!strcmp(key, "replay") || !strcmp(key, "file")) {
        if (off == 0 && filename)
            set_name(q, filename);
        return append(q, data, size, d->cfg.max_upload) ? MHD_YES : MHD_NO;
    }
    char *dst = !strcmp(key, "size") ? q->size : !strcmp(key, "format") ? q->format : NULL;
    size_t room = !strcmp(key, "size") ? sizeof q->size : sizeof q->format;
    if (dst && off + size < room) {
        memcpy(dst + off, data, size);
        dst[off + size] = 0;
    }
    return MHD_YES;
}

/* The post processor's callback context: the daemon and the request. */
typedef struct pp_ctx {
    void *pair[2];
} pp_ctx;

typedef struct conn_ctx {
    req q;
    pp_ctx pc;
} conn_ctx;

static bool parse_id(const char *s, size_t n, int64_t *id)
{
    if (n == 0 || n > 18)
        return false;
    int64_t v = 0;
    for (size_t i = 0; i < n; i++) {
        if (!isdigit((unsigned char)s[i]))
            return false;
        v = v * 10 + (s[i] - '0');
    }
    *id = v;
    return v > 0;
}

/* A refused upload: counted for /metrics, logged, answered. */
static enum MHD_Result reject(svc_daemon *d, struct MHD_Connection *c, int id, const char *fmt, ...) RS_PRINTF(4, 5);
static enum MHD_Result reject(svc_daemon *d, struct MHD_Connection *c, int id, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    pthread_mutex_lock(&d->mu);
    d->uploads_rejected++;
    pthread_mutex_unlock(&d->mu);
    svc_log(SVC_LOG_INFO, -1, "upload refused (%u): %s", svc_http_status(id), msg);
    return reply_error(c, id, "%s", msg);
}

static enum MHD_Result do_submit(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    if (q->oom)
        return reply_error(c, SVC_ERR_NOMEM, "out of memory reading the upload");
    if (q->bad)
        return reject(d, c, SVC_ERR_BAD_BODY, "%s", q->bad);
    if (q->too_large)
        return reject(d, c, SVC_ERR_TOO_LARGE, "the upload is over the limit of %ld bytes (max_upload)", d->cfg.max_upload);
    const char *v;
    if (!q->size[0] && (v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "size")))
        snprintf(q->size, sizeof q->size, "%s", v);
    if (!q->format[0] && (v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "format")))
        snprintf(q->format, sizeof q->format, "%s", v);
    if (!q->name[0]) {
        set_name(q, MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "name"));
        if (!q->name[0])
            set_name(q, MHD_lookup_connection_value(c, MHD_HEADER_KIND, "X-Filename"));
        if (!q->name[0])
            snprintf(q->name, sizeof q->name, "upload.rsr");
    }
    svc_job j = {0};
    snprintf(j.name, sizeof j.name, "%s", q->name);
    j.width = d->cfg.width;
    j.height = d->cfg.height;
    snprintf(j.format, sizeof j.format, "%s", d->cfg.format);
    if (q->size[0]) {
        long w, h;
        char x, extra;
        if (sscanf(q->size, "%ld%c%ld%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X'))
            return reject(d, c, SVC_ERR_BAD_PARAM, "size '%s': expected WxH, such as 640x360", q->size);
        if (w < 16 || h < 16 || w > d->cfg.max_width || h > d->cfg.max_height || (w | h) & 1)
            return reject(d, c, SVC_ERR_BAD_PARAM, "size %ldx%ld: each side must be even, at least 16 and at most %dx%d", w, h,
                               d->cfg.max_width, d->cfg.max_height);
        j.width = (int)w, j.height = (int)h;
        rs_err serr = {0};
        if (!cap_check_sizes_for(CAP_I420, d->cfg.render_width, d->cfg.render_height, j.width, j.height, &serr))
            return reject(d, c, SVC_ERR_BAD_PARAM, "size %s: %s", q->size, serr.msg);
    }
    if (q->format[0]) {
        if (strcmp(q->format, "mp4") && strcmp(q->format, "webm") && strcmp(q->format, "mkv"))
            return reject(d, c, SVC_ERR_BAD_PARAM, "format '%s': expected mp4, webm or mkv", q->format);
        snprintf(j.format, sizeof j.format, "%s", q->format);
    }
    rs_err err = {0};
    if (!svc_check_upload(&d->cfg, q->body, q->len, j.name, &j, &err))
        return reject(d, c, err.code, "%s", err.msg);
    j.replay = q->body;
    j.replay_len = q->len;
    j.segment_ticks = d->cfg.segment_seconds * 60; /* the store splits it if it is longer */
    if (!d->http_store->ops->submit(d->http_store, &j, &err)) {
        svc_log(SVC_LOG_ERROR, -1, "could not queue an upload: %s", err.msg);
        return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    }
    if (j.segments > 0)
        svc_log(SVC_LOG_INFO, j.id, "queued %s (%zu bytes, %" PRId64 " frames, %dx%d %s) as %d segments of %d s",
                j.name, q->len, j.frames_total, j.width, j.height, j.format, j.segments, d->cfg.segment_seconds);
    else
        svc_log(SVC_LOG_INFO, j.id, "queued %s (%zu bytes, %" PRId64 " frames, %dx%d %s)", j.name, q->len,
                j.frames_total, j.width, j.height, j.format);
    svc_buf b = {0};
    svc_buf_printf(&b, "{\"id\":%" PRId64 ",\"state\":\"queued\",\"url\":\"/jobs/%" PRId64 "\",\"frames_total\":%" PRId64
                       "}\n",
                   j.id, j.id, j.frames_total);
    struct MHD_Response *r = MHD_create_response_from_buffer(b.len, b.p, MHD_RESPMEM_MUST_COPY);
    svc_buf_free(&b);
    if (!r)
        return MHD_NO;
    char loc[64];
    snprintf(loc, sizeof loc, "/jobs/%" PRId64, j.id);
    MHD_add_response_header(r, "Content-Type", "application/json");
    MHD_add_response_header(r, "Location", loc);
    enum MHD_Result ret = MHD_queue_response(c, 201, r);
    MHD_destroy_response(r);
    return ret;
}

/* A running job's live numbers come from the daemon that runs it (when
 * that is us): fresher than the last heartbeat.  A whole job's are the
 * render's own; a split job's row sums its units as of their heartbeats,
 * so what our renders did since theirs is added. */
static void overlay_live(svc_daemon *d, svc_job *j, svc_unit *units, int n)
{
    if (j->state != SVC_RUNNING)
        return;
    pthread_mutex_lock(&d->mu);
    for (int i = 0; i < d->cfg.workers; i++) {
        const svc_live *l = &d->live[i];
        if (l->job != j->id)
            continue;
        if (l->kind == SVC_UNIT_WHOLE) {
            j->frames_done = l->done;
            j->frames_total = l->total;
            j->fps = l->fps;
            continue;
        }
        if (l->kind == SVC_UNIT_SEGMENT) {
            j->frames_done += l->done - l->beat_done;
            j->fps += l->fps - l->beat_fps;
        }
        for (int k = 0; k < n; k++)
            if (units[k].kind == l->kind && units[k].index == l->index && units[k].state == SVC_RUNNING) {
                units[k].frames_done = l->done;
                units[k].fps = l->fps;
            }
    }
    pthread_mutex_unlock(&d->mu);
    if (j->frames_done > j->frames_total)
        j->frames_done = j->frames_total;
    if (j->frames_done < 0)
        j->frames_done = 0;
    if (j->fps < 0)
        j->fps = 0;
}

static enum MHD_Result do_get_job(svc_daemon *d, struct MHD_Connection *c, int64_t id)
{
    svc_job j;
    rs_err err = {0};
    int r = d->http_store->ops->get(d->http_store, id, &j, &err);
    if (r < 0)
        return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    if (r == 0)
        return reply_error(c, SVC_ERR_NOT_FOUND, "no job %" PRId64, id);
    /* a split job shows its segments: who rendered each, how often */
    svc_unit *units = NULL;
    int n = 0;
    if (j.segments > 0) {
        units = calloc((size_t)j.segments + 1, sizeof *units);
        if (!units)
            return reply_error(c, SVC_ERR_NOMEM, "out of memory");
        n = d->http_store->ops->units(d->http_store, id, units, j.segments + 1, &err);
        if (n < 0) {
            free(units);
            return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
        }
    }
    overlay_live(d, &j, units, n);
    svc_buf b = {0};
    svc_json_job(&b, &j, d->cfg.max_attempts, units, n);
    svc_buf_add(&b, "\n", 1);
    free(units);
    return reply_json(c, 200, &b);
}

static enum MHD_Result do_list(svc_daemon *d, struct MHD_Connection *c)
{
    long limit = 50;
    int64_t before = 0, lim;
    const char *v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "limit");
    if (v && (!parse_id(v, strlen(v), &lim) || lim > 500))
        return reply_error(c, SVC_ERR_BAD_PARAM, "limit '%s': expected 1..500", v);
    if (v)
        limit = (long)lim;
    v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "before");
    if (v && !parse_id(v, strlen(v), &before))
        return reply_error(c, SVC_ERR_BAD_PARAM, "before '%s': expected a job id", v);
    svc_job *jobs = calloc((size_t)limit, sizeof *jobs);
    if (!jobs)
        return reply_error(c, SVC_ERR_NOMEM, "out of memory");
    rs_err err = {0};
    int n = d->http_store->ops->list(d->http_store, before, (int)limit, jobs, &err);
    if (n < 0) {
        free(jobs);
        return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    }
    svc_buf b = {0};
    svc_buf_add(&b, "{\"jobs\":[", 9);
    for (int i = 0; i < n; i++) {
        overlay_live(d, &jobs[i], NULL, 0);
        if (i)
            svc_buf_add(&b, ",", 1);
        svc_json_job(&b, &jobs[i], d->cfg.max_attempts, NULL, 0);
    }
    if (n == limit && n > 0)
        svc_buf_printf(&b, "],\"next\":\"/jobs?before=%" PRId64 "&limit=%ld\"}\n", jobs[n - 1].id, limit);
    else
        svc_buf_add(&b, "],\"next\":null}\n", 15);
    free(jobs);
    return reply_json(c, 200, &b);
}

static enum MHD_Result do_cancel(svc_daemon *d, struct MHD_Connection *c, int64_t id)
{
    rs_err err = {0};
    int r = d->http_store->ops->cancel(d->http_store, id, &err);
    if (r < 0)
        return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    if (r == 0)
        return reply_error(c, SVC_ERR_NOT_FOUND, "no job %" PRId64, id);
    if (r == 2) {
        svc_job j;
        const char *st = d->http_store->ops->get(d->http_store, id, &j, &err) == 1 ? svc_state_name(j.state) : "over";
        return reply_error(c, SVC_ERR_CONFLICT, "job %" PRId64 " is already %s", id, st);
    }
    svc_log(SVC_LOG_INFO, id, "cancelled by a client");
    return do_get_job(d, c, id);
}

static enum MHD_Result do_file(svc_daemon *d, struct MHD_Connection *c, int64_t id, bool video)
{
    svc_job j;
    rs_err err = {0};
    int r = d->http_store->ops->get(d->http_store, id, &j, &err);
    if (r < 0)
        return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    if (r == 0)
        return reply_error(c, SVC_ERR_NOT_FOUND, "no job %" PRId64, id);
    if (j.state != SVC_DONE)
        return reply_error(c, SVC_ERR_NOT_FOUND, "job %" PRId64 " is %s: its %s exists once it is done", id, svc_state_name(j.state),
                           video ? "video" : "hash list");
    char path[1100];
    if (video)
        snprintf(path, sizeof path, "%s/%" PRId64 ".%s", d->cfg.output, id, j.format);
    else
        snprintf(path, sizeof path, "%s/%" PRId64 ".hashes", d->cfg.output, id);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        int e = fd >= 0 && S_ISREG(st.st_mode) ? errno : fd < 0 ? errno : EISDIR;
        if (fd >= 0)
            close(fd);
        svc_log(SVC_LOG_WARN, id, "%s: %s (a shared output directory not mounted here?)", path, strerror(e));
        return reply_error(c, SVC_ERR_GONE, "job %" PRId64 " is done but %s is missing on this server", id, path);
    }
    uint64_t len = (uint64_t)st.st_size, first = 0, last = len ? len - 1 : 0;
    int rr = video ? svc_parse_range(MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Range"), len, &first, &last) : 0;
    if (rr < 0) {
        close(fd);
        struct MHD_Response *resp = MHD_create_response_from_buffer(0, "", MHD_RESPMEM_PERSISTENT);
        char cr[64];
        snprintf(cr, sizeof cr, "bytes */%" PRIu64, len);
        MHD_add_response_header(resp, "Content-Range", cr);
        enum MHD_Result ret = MHD_queue_response(c, svc_http_status(SVC_ERR_RANGE), resp);
        MHD_destroy_response(resp);
        return ret;
    }
    uint64_t n = rr > 0 ? last - first + 1 : len;
    struct MHD_Response *resp = MHD_create_response_from_fd_at_offset64(n, fd, rr > 0 ? first : 0);
    if (!resp) {
        close(fd);
        return MHD_NO;
    }
    static const char *const types[][2] = {{"mp4", "video/mp4"}, {"webm", "video/webm"}, {"mkv", "video/x-matroska"}};
    const char *type = "text/plain; charset=utf-8";
    for (int i = 0; video && i < 3; i++)
        if (!strcmp(j.format, types[i][0]))
            type = types[i][1];
    MHD_add_response_header(resp, "Content-Type", type);
    MHD_add_response_header(resp, "Accept-Ranges", "bytes");
    char disp[200];
    snprintf(disp, sizeof disp, "inline; filename=\"ringside-job%" PRId64 ".%s\"", id, video ? j.format : "hashes");
    MHD_add_response_header(resp, "Content-Disposition", disp);
    if (rr > 0) {
        char cr[96];
        snprintf(cr, sizeof cr, "bytes %" PRIu64 "-%" PRIu64 "/%" PRIu64, first, last, len);
        MHD_add_response_header(resp, "Content-Range", cr);
    }
    enum MHD_Result ret = MHD_queue_response(c, rr > 0 ? 206 : 200, resp);
    MHD_destroy_response(resp);
    return ret;
}

static enum MHD_Result do_health(svc_daemon *d, struct MHD_Connection *c)
{
    int64_t counts[SVC_NSTATES];
    rs_err err = {0};
    bool ok = d->http_store->ops->counts(d->http_store, counts, &err);
    int busy = 0;
    pthread_mutex_lock(&d->mu);
    for (int i = 0; i < d->cfg.workers; i++)
        busy += d->live[i].job != 0;
    bool draining = d->draining;
    pthread_mutex_unlock(&d->mu);
    svc_buf b = {0};
    svc_buf_printf(&b, "{\"ok\":%s,\"queue\":\"%s\",\"workers\":%d,\"busy\":%d,\"draining\":%s,\"version\":\"%s\"",
                   ok ? "true" : "false", d->http_store->ops->name, d->cfg.workers, busy, draining ? "true" : "false",
                   RS_VERSION);
    if (ok)
        svc_buf_printf(&b, ",\"queued\":%" PRId64 ",\"running\":%" PRId64 "}\n", counts[SVC_QUEUED], counts[SVC_RUNNING]);
    else {
        svc_buf_add(&b, ",\"error\":", 9);
        svc_json_str(&b, err.msg);
        svc_buf_add(&b, "}\n", 2);
    }
    return reply_json(c, ok ? 200 : svc_http_status(err.code), &b);
}

static enum MHD_Result do_metrics(svc_daemon *d, struct MHD_Connection *c)
{
    int64_t counts[SVC_NSTATES];
    rs_err err = {0};
    if (!d->http_store->ops->counts(d->http_store, counts, &err))
        return reply(c, svc_http_status(err.code), "text/plain", err.msg, strlen(err.msg));
    svc_buf b = {0};
    svc_buf_printf(&b, "# HELP ringside_queue_depth Jobs waiting for a worker.\n# TYPE ringside_queue_depth gauge\n"
                       "ringside_queue_depth %" PRId64 "\n",
                   counts[SVC_QUEUED]);
    svc_buf_printf(&b, "# HELP ringside_jobs Jobs in the queue by state (every daemon of the queue).\n"
                       "# TYPE ringside_jobs gauge\n");
    for (int s = 0; s < SVC_NSTATES; s++)
        svc_buf_printf(&b, "ringside_jobs{state=\"%s\"} %" PRId64 "\n", svc_state_name(s), counts[s]);
    double fps = 0;
    int busy = 0;
    pthread_mutex_lock(&d->mu);
    for (int i = 0; i < d->cfg.workers; i++)
        if (d->live[i].job) {
            busy++;
            fps += d->live[i].kind == SVC_UNIT_JOIN ? 0 : d->live[i].fps;
        }
    uint64_t frames = d->frames_rendered, done = d->jobs_done, failed = d->jobs_failed, retried = d->jobs_retried;
    uint64_t crashes = d->worker_crashes, wd = d->watchdog_kills, rejected = d->uploads_rejected;
    pthread_mutex_unlock(&d->mu);
    svc_buf_printf(&b,
                   "# HELP ringside_frames_rendered_total Frames rendered by this daemon's workers.\n"
                   "# TYPE ringside_frames_rendered_total counter\nringside_frames_rendered_total %" PRIu64 "\n"
                   "# HELP ringside_render_fps Frames per second of this daemon's running renders, summed.\n"
                   "# TYPE ringside_render_fps gauge\nringside_render_fps %.2f\n"
                   "# HELP ringside_workers Render processes this daemon may run.\n"
                   "# TYPE ringside_workers gauge\nringside_workers %d\n"
                   "# HELP ringside_workers_busy Render processes running now.\n"
                   "# TYPE ringside_workers_busy gauge\nringside_workers_busy %d\n"
                   "# HELP ringside_jobs_finished_total Jobs this daemon finished, by result.\n"
                   "# TYPE ringside_jobs_finished_total counter\n"
                   "ringside_jobs_finished_total{result=\"done\"} %" PRIu64 "\n"
                   "ringside_jobs_finished_total{result=\"failed\"} %" PRIu64 "\n"
                   "# HELP ringside_jobs_retried_total Attempts that failed and were re-queued.\n"
                   "# TYPE ringside_jobs_retried_total counter\nringside_jobs_retried_total %" PRIu64 "\n"
                   "# HELP ringside_worker_failures_total Render processes that crashed, failed or were killed.\n"
                   "# TYPE ringside_worker_failures_total counter\nringside_worker_failures_total %" PRIu64 "\n"
                   "# HELP ringside_watchdog_kills_total Renders killed for making no progress.\n"
                   "# TYPE ringside_watchdog_kills_total counter\nringside_watchdog_kills_total %" PRIu64 "\n"
                   "# HELP ringside_uploads_rejected_total Uploads refused (bad, too large).\n"
                   "# TYPE ringside_uploads_rejected_total counter\nringside_uploads_rejected_total %" PRIu64 "\n",
                   frames, fps, d->cfg.workers, busy, done, failed, retried, crashes, wd, rejected);
    if (b.oom)
        return MHD_NO;
    enum MHD_Result r = reply(c, 200, "text/plain; version=0.0.4", b.p, b.len);
    svc_buf_free(&b);
    return r;
}

static enum MHD_Result do_dashboard(svc_daemon *d, struct MHD_Connection *c)
{
    rs_err err = {0};
    size_t len;
    char *html = d->dashboard[0] ? rs_read_file(d->dashboard, 1 << 20, &len, &err) : NULL;
    if (!html) {
        const char *msg = "<!doctype html><title>ringside</title><p>The dashboard page (service/dashboard.html) "
                          "was not found; the API is at /jobs, /healthz and /metrics.";
        return reply(c, 200, "text/html; charset=utf-8", msg, strlen(msg));
    }
    enum MHD_Result r = reply(c, 200, "text/html; charset=utf-8", html, len);
    free(html);
    return r;
}

static enum MHD_Result route(svc_daemon *d, struct MHD_Connection *c, const char *url, const char *method)
{
    bool get = !strcmp(method, "GET") || !strcmp(method, "HEAD");
    if (!strcmp(url, "/") || !strcmp(url, "/index.html"))
        return get ? do_dashboard(d, c) : reply_error(c, SVC_ERR_METHOD, "%s /: only GET", method);
    if (!strcmp(url, "/healthz"))
        return get ? do_health(d, c) : reply_error(c, SVC_ERR_METHOD, "%s %s: only GET", method, url);
    if (!strcmp(url, "/metrics"))
        return get ? do_metrics(d, c) : reply_error(c, SVC_ERR_METHOD, "%s %s: only GET", method, url);
    if (!strcmp(url, "/jobs") || !strcmp(url, "/jobs/"))
        return get ? do_list(d, c) : reply_error(c, SVC_ERR_METHOD, "%s /jobs: expected GET or POST", method);
    if (!strncmp(url, "/jobs/", 6)) {
        const char *p = url + 6, *slash = strchr(p, '/');
        size_t n = slash ? (size_t)(slash - p) : strlen(p);
        int64_t id;
        if (!parse_id(p, n, &id))
            return reply_error(c, SVC_ERR_NOT_FOUND, "%s: not a job id", url);
        if (!slash) {
            if (get)
                return do_get_job(d, c, id);
            if (!strcmp(method, "DELETE"))
                return do_cancel(d, c, id);
            return reply_error(c, SVC_ERR_METHOD, "%s %s: expected GET or DELETE", method, url);
        }
        if (!strcmp(slash, "/video") || !strcmp(slash, "/hashes"))
            return get ? do_file(d, c, id, slash[1] == 'v') : reply_error(c, SVC_ERR_METHOD, "%s %s: only GET", method, url);
    }
    return reply_error(c, SVC_ERR_NOT_FOUND, "%s: no such resource (see /jobs, /healthz, /metrics)", url);
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *c, const char *url, const char *method,
                                  const char *version, const char *upload, size_t *upload_size, void **con_cls)
{
    (void)version;
    svc_daemon *d = cls;
    conn_ctx *cx = *con_cls;
    if (!cx) {
        cx = calloc(1, sizeof *cx);
        if (!cx)
            return MHD_NO;
        *con_cls = cx;
        req *q = &cx->q;
        if (strcmp(method, "POST") != 0 || (strcmp(url, "/jobs") != 0 && strcmp(url, "/jobs/") != 0))
            return MHD_YES; /* answered below, once any body is read */
        q->post_jobs = true;
        pthread_mutex_lock(&d->mu);
        bool draining = d->draining;
        pthread_mutex_unlock(&d->mu);
        if (draining) {
            q->done = true;
            return reply_error(c, SVC_ERR_DRAINING, "the daemon is shutting down: not accepting jobs");
        }
        const char *cl = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Content-Length");
        if (cl && strtoull(cl, NULL, 10) > (unsigned long long)d->cfg.max_upload) {
            q->done = true;
            pthread_mutex_lock(&d->mu);
            d->uploads_rejected++;
            pthread_mutex_unlock(&d->mu);
            svc_log(SVC_LOG_INFO, -1, "upload refused (413): Content-Length %s is over max_upload %ld", cl,
                    d->cfg.max_upload);
            return reply_error(c, SVC_ERR_TOO_LARGE, "the upload (%s bytes) is over the limit of %ld bytes (max_upload)", cl,
                               d->cfg.max_upload);
        }
        const char *ct = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Content-Type");
        if (ct && strcasestr(ct, "multipart/form-data")) {
            cx->pc.pair[0] = d;
            cx->pc.pair[1] = q;
            q->pp = MHD_create_post_processor(c, 32 * 1024, post_field, cx->pc.pair);
            if (!q->pp)
                q->bad = "malformed multipart/form-data request (no boundary?)";
        }
        return MHD_YES;
    }
    req *q = &cx->q;
    if (*upload_size) {
        if (!q->done) {
            if (!q->post_jobs)
                ; /* a body nobody asked for: ignored */
            else if (q->pp) {
                /* libmicrohttpd takes no response while a body is still
                 * arriving: remember, read the rest, answer at the end */
                if (!q->bad && MHD_post_process(q->pp, upload, *upload_size) != MHD_YES && !q->oom && !q->too_large)
                    q->bad = "malformed multipart/form-data body";
            } else if (!append(q, upload, *upload_size, d->cfg.max_upload))
                q->oom = true;
        }
        *upload_size = 0;
        return MHD_YES;
    }
    if (q->done)
        return MHD_YES;
    q->done = true;
    if (q->post_jobs)
        return do_submit(d, c, q);
    return route(d, c, url, method);
}

static void on_completed(void *cls, struct MHD_Connection *c, void **con_cls, enum MHD_RequestTerminationCode toe)
{
    (void)cls, (void)c, (void)toe;
    conn_ctx *cx = *con_cls;
    if (!cx)
        return;
    if (cx->q.pp)
        MHD_destroy_post_processor(cx->q.pp);
    free(cx->q.body);
    free(cx);
    *con_cls = NULL;
}

static void on_mhd_log(void *cls, const char *fmt, va_list ap)
{
    (void)cls;
    char msg[512];
    vsnprintf(msg, sizeof msg, fmt, ap);
    size_t n = strlen(msg);
    while (n && (msg[n - 1] == '\n' || msg[n - 1] == '\r'))
        msg[--n] = 0;
    svc_log(SVC_LOG_DEBUG, -1, "http: %s", msg);
}

#include <netdb.h>
#include <sys/socket.h>

struct MHD_Daemon *svc_http_start(svc_daemon *d, rs_err *err)
{
    char host[128];
    snprintf(host, sizeof host, "%s", d->cfg.listen);
    char *colon = strrchr(host, ':');
    *colon = 0;
    const char *port = colon + 1;
    char *h = host;
    if (h[0] == '[' && h[strlen(h) - 1] == ']') { /* [::1]:8080 */
        h[strlen(h) - 1] = 0;
        h++;
    }
    struct addrinfo hints = {.ai_family = AF_UNSPEC, .ai_socktype = SOCK_STREAM, .ai_flags = AI_NUMERICSERV | AI_PASSIVE};
    struct addrinfo *ai = NULL;
    int gr = getaddrinfo(*h ? h : NULL, port, &hints, &ai);
    if (gr != 0) {
        rs_fail(err, 1, "listen %s: %s", d->cfg.listen, gai_strerror(gr));
        return NULL;
    }
    unsigned flags = MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_ERROR_LOG;
    if (ai->ai_family == AF_INET6)
        flags |= MHD_USE_IPv6;
    flags |= MHD_USE_AUTO; /* epoll on Linux: no FD_SETSIZE limit */
    struct MHD_Daemon *mhd = MHD_start_daemon(
        flags, 0, NULL, NULL, on_request, d, MHD_OPTION_EXTERNAL_LOGGER, on_mhd_log, d, MHD_OPTION_SOCK_ADDR,
        ai->ai_addr, MHD_OPTION_THREAD_POOL_SIZE, 4u, MHD_OPTION_NOTIFY_COMPLETED, on_completed, d,
        MHD_OPTION_CONNECTION_TIMEOUT, 60u, MHD_OPTION_CONNECTION_LIMIT, 256u, MHD_OPTION_END);
    freeaddrinfo(ai);
    if (!mhd) {
        rs_fail(err, 1, "cannot listen on %s (in use, or not an address of this machine?)", d->cfg.listen);
        return NULL;
    }
    const union MHD_DaemonInfo *info = MHD_get_daemon_info(mhd, MHD_DAEMON_INFO_BIND_PORT);
    d->port = info ? info->port : 0;
    return mhd;
}

void svc_http_stop(struct MHD_Daemon *h)
{
    if (h)
        MHD_stop_daemon(h);
}

#else /* !RS_HAVE_MHD */

struct MHD_Daemon *svc_http_start(svc_daemon *d, rs_err *err)
{
    (void)d;
    rs_fail(err, 1, "this ringside was built without libmicrohttpd (install libmicrohttpd-dev and rebuild)");
    return NULL;
}

void svc_http_stop(struct MHD_Daemon *h)
{
    (void)h;
}

#endif
