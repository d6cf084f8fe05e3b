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
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "svc_auth.h"
#include "svc_encode.h"
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
#define X(id, status, t) t,
        SVC_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_SVC, text, (int)(sizeof text / sizeof text[0]));
}

unsigned svc_http_status(int code)
{
    switch (code) {
#define X(id, status, t)                                                                                               \
    case SVC_ERR_##id:                                                                                                 \
        return status;
        SVC_ERRORS(X)
#undef X
    }
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
    j->stage = rp.stage;
    j->kind[0] = rp.kind[0], j->kind[1] = rp.kind[1];
    j->winner = rp.winner;
    j->rounds[0] = rp.rounds[0], j->rounds[1] = rp.rounds[1];
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
#include <netdb.h>
#include <pthread.h>
#include <sys/socket.h>
#include <time.h>

/* --- the network's guards: connections, their deadlines, the upload budget ---
 *
 * DESIGN: libmicrohttpd's own timeout is an idle timeout (any byte resets
 * it), so a client trickling a header line every few seconds holds its
 * connection forever.  Every connection is recorded here when libmicrohttpd
 * opens it (MHD_OPTION_NOTIFY_CONNECTION) with the phase it is in; a reaper
 * thread looks at them once a second and shuts down (never closes: the fd is
 * libmicrohttpd's) a connection whose headers took longer than
 * header_timeout or whose upload averages less than min_body_rate.  The
 * table's mutex is held across shutdown(), and libmicrohttpd reports a
 * connection closed before it closes the fd, so the reaper never touches an
 * fd that has been reused. */
enum { NET_HEADERS, NET_BODY, NET_ANSWER }; /* a connection's phase */
enum { CUT_HEADER_TIMEOUT, CUT_BODY_RATE, CUT_MAX_UPLOAD, NET_NCUTS };
static const char *const cut_name[NET_NCUTS] = {"header_timeout", "min_body_rate", "max_upload"};

typedef struct net_conn {
    struct net_conn *prev, *next;
    int fd;
    char ip[64];
    int phase;
    double since;   /* when the phase began (monotonic seconds) */
    uint64_t body;  /* bytes of the request body read in this phase */
    bool cut;       /* shut down by the reaper */
    char cors[256]; /* the Origin to answer with CORS headers ("" none) */
    bool vary;      /* answers depend on Origin (cors_origins is set) */
} net_conn;

struct svc_net {
    svc_daemon *d;
    pthread_mutex_t mu; /* guards everything below */
    net_conn *conns;
    long open;
    uint64_t cuts[NET_NCUTS];
    long reserved;      /* upload bytes promised to requests in progress */
    bool stop;
    pthread_cond_t wake;
    pthread_t reaper;
    bool reaper_started;
    char hosts[1024];   /* accepted Host names, comma-separated, lower case */
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec / 1e9;
}

static net_conn *conn_of(struct MHD_Connection *c)
{
    const union MHD_ConnectionInfo *ci = MHD_get_connection_info(c, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    return ci ? ci->socket_context : NULL;
}

/* A connection enters a phase: its deadline starts over. */
static void conn_phase(svc_net *n, struct MHD_Connection *c, int phase)
{
    net_conn *nc = conn_of(c);
    if (!nc)
        return;
    pthread_mutex_lock(&n->mu);
    nc->phase = phase;
    nc->since = now_s();
    nc->body = 0;
    pthread_mutex_unlock(&n->mu);
}

/* Body bytes read: what min_body_rate is measured on. */
static void conn_body(svc_net *n, struct MHD_Connection *c, size_t bytes)
{
    net_conn *nc = conn_of(c);
    if (!nc)
        return;
    pthread_mutex_lock(&n->mu);
    nc->body += bytes;
    pthread_mutex_unlock(&n->mu);
}

static void on_connection(void *cls, struct MHD_Connection *c, void **socket_context, enum MHD_ConnectionNotificationCode code)
{
    svc_net *n = cls;
    net_conn *nc = *socket_context;
    if (code == MHD_CONNECTION_NOTIFY_CLOSED) {
        if (!nc)
            return;
        pthread_mutex_lock(&n->mu);
        if (nc->prev)
            nc->prev->next = nc->next;
        else
            n->conns = nc->next;
        if (nc->next)
            nc->next->prev = nc->prev;
        n->open--;
        pthread_mutex_unlock(&n->mu);
        free(nc);
        *socket_context = NULL;
        return;
    }
    const union MHD_ConnectionInfo *fd = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
    if (!fd || !(nc = calloc(1, sizeof *nc)))
        return; /* not watched: libmicrohttpd's idle timeout still applies */
    nc->fd = fd->connect_fd;
    const union MHD_ConnectionInfo *ad = MHD_get_connection_info(c, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
    if (!ad || getnameinfo(ad->client_addr, ad->client_addr->sa_family == AF_INET6 ? sizeof(struct sockaddr_in6)
                                                                                   : sizeof(struct sockaddr_in),
                           nc->ip, sizeof nc->ip, NULL, 0, NI_NUMERICHOST) != 0)
        snprintf(nc->ip, sizeof nc->ip, "?");
    nc->phase = NET_HEADERS;
    nc->since = now_s();
    pthread_mutex_lock(&n->mu);
    nc->next = n->conns;
    if (n->conns)
        n->conns->prev = nc;
    n->conns = nc;
    n->open++;
    pthread_mutex_unlock(&n->mu);
    *socket_context = nc;
}

/* Ends a connection for a reason (the table's mutex held): the peer sees
 * the connection end; libmicrohttpd sees an error on it and closes it. */
static void conn_cut(svc_net *n, net_conn *nc, int why, double age)
{
    shutdown(nc->fd, SHUT_RDWR);
    nc->cut = true;
    n->cuts[why]++;
    svc_log(SVC_LOG_DEBUG, -1, "http: connection from %s cut after %.1f s: %s (%" PRIu64 " body bytes)", nc->ip, age,
            cut_name[why], nc->body);
}

static void *reaper(void *arg)
{
    svc_net *n = arg;
    const svc_config *cfg = &n->d->cfg;
    pthread_mutex_lock(&n->mu);
    while (!n->stop) {
        double t = now_s();
        for (net_conn *nc = n->conns; nc; nc = nc->next) {
            double age = t - nc->since;
            if (nc->cut || age <= cfg->header_timeout)
                continue;
            if (nc->phase == NET_HEADERS)
                conn_cut(n, nc, CUT_HEADER_TIMEOUT, age);
            else if (nc->phase == NET_BODY && (double)nc->body < (double)cfg->min_body_rate * age)
                conn_cut(n, nc, CUT_BODY_RATE, age);
        }
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_sec += 1;
        pthread_cond_timedwait(&n->wake, &n->mu, &until);
    }
    pthread_mutex_unlock(&n->mu);
    return NULL;
}

/* Every answer goes out through here: the CORS headers of the request's
 * connection are added to it. */
static enum MHD_Result queue(struct MHD_Connection *c, unsigned status, struct MHD_Response *r)
{
    net_conn *nc = conn_of(c);
    if (nc && nc->cors[0]) {
        MHD_add_response_header(r, "Access-Control-Allow-Origin", nc->cors);
        MHD_add_response_header(r, "Access-Control-Expose-Headers", "Location, Retry-After");
    }
    if (nc && nc->vary)
        MHD_add_response_header(r, "Vary", "Origin");
    return MHD_queue_response(c, status, r);
}

static void net_metrics(svc_net *n, svc_buf *b)
{
    pthread_mutex_lock(&n->mu);
    long open = n->open, reserved = n->reserved;
    uint64_t cuts[NET_NCUTS];
    memcpy(cuts, n->cuts, sizeof cuts);
    pthread_mutex_unlock(&n->mu);
    svc_buf_printf(b, "# HELP ringside_http_connections HTTP connections open now.\n"
                      "# TYPE ringside_http_connections gauge\nringside_http_connections %ld\n"
                      "# HELP ringside_http_upload_bytes_reserved Bytes of upload_memory held by uploads in progress.\n"
                      "# TYPE ringside_http_upload_bytes_reserved gauge\nringside_http_upload_bytes_reserved %ld\n"
                      "# HELP ringside_http_connections_cut_total Connections ended by the daemon, by reason.\n"
                      "# TYPE ringside_http_connections_cut_total counter\n",
                   open, reserved);
    for (int i = 0; i < NET_NCUTS; i++)
        svc_buf_printf(b, "ringside_http_connections_cut_total{reason=\"%s\"} %" PRIu64 "\n", cut_name[i], cuts[i]);
}

typedef struct req {
    bool started;       /* the first call (headers only) is over */
    bool post_jobs;
    bool done;          /* a response was queued early (413, 503) */
    uint64_t received;  /* body bytes read */
    long reserved;      /* bytes of upload_memory held for it */
    struct MHD_PostProcessor *pp;
    uint8_t *body;
    size_t len, cap;
    bool too_large, oom;
    const char *bad; /* a malformed body: answered 400 once it is read */
    char name[SVC_NAME_MAX];
    char size[32], format[16];
    char codec[16], crf[8], bitrate[16], preset[CAP_ENC_PRESET_MAX], pix_fmt[16], audio[8], quality[16]; /* svc_encode.c */
    /* who asks (authorize): tok.id 0 without a token; all: sees every job
     * (an operator token, or loopback with no tokens at all) */
    svc_token tok;
    bool all;
} req;

static enum MHD_Result reply(struct MHD_Connection *c, unsigned status, const char *type, const char *body, size_t n)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(n, (void *)body, MHD_RESPMEM_MUST_COPY);
    if (!r)
        return MHD_NO;
    MHD_add_response_header(r, "Content-Type", type);
    MHD_add_response_header(r, "Cache-Control", "no-store");
    enum MHD_Result ret = queue(c, status, r);
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

/* An error answer with one more header (header NULL: none): 401's
 * WWW-Authenticate, 429's Retry-After, 503's Retry-After. */
static enum MHD_Result send_error(struct MHD_Connection *c, int id, const char *header, const char *value,
                                  const char *msg)
{
    svc_buf b = {0};
    svc_json_error(&b, msg);
    struct MHD_Response *r = b.oom ? NULL : MHD_create_response_from_buffer(b.len, b.p, MHD_RESPMEM_MUST_COPY);
    svc_buf_free(&b);
    if (!r)
        return MHD_NO;
    MHD_add_response_header(r, "Content-Type", "application/json");
    MHD_add_response_header(r, "Cache-Control", "no-store");
    if (header)
        MHD_add_response_header(r, header, value);
    enum MHD_Result ret = queue(c, svc_http_status(id), r);
    MHD_destroy_response(r);
    return ret;
}

static enum MHD_Result reply_error_header(struct MHD_Connection *c, int id, const char *header, const char *value,
                                          const char *fmt, ...) RS_PRINTF(5, 6);
static enum MHD_Result reply_error_header(struct MHD_Connection *c, int id, const char *header, const char *value,
                                          const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return send_error(c, id, header, value, msg);
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
    struct {
        const char *key;
        char *dst;
        size_t room;
    } const fields[] = {{"size", q->size, sizeof q->size},       {"format", q->format, sizeof q->format},
                        {"codec", q->codec, sizeof q->codec},    {"crf", q->crf, sizeof q->crf},
                        {"bitrate", q->bitrate, sizeof q->bitrate}, {"preset", q->preset, sizeof q->preset},
                        {"pix_fmt", q->pix_fmt, sizeof q->pix_fmt}, {"audio", q->audio, sizeof q->audio},
                        {"quality", q->quality, sizeof q->quality}};
    char *dst = NULL;
    size_t room = 0;
    for (size_t i = 0; i < sizeof fields / sizeof *fields; i++)
        if (!strcmp(key, fields[i].key))
            dst = fields[i].dst, room = fields[i].room;
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
    bool bad_uri; /* a control character in the raw path or query */
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

/* A token's quotas against job j (frames_total known).  1: within them;
 * 0: over one (msg says which, *retry the seconds until trying again may
 * work); -1: the queue failed (err). */
static int check_quota(svc_daemon *d, const svc_token *t, const svc_job *j, char *msg, size_t n, int64_t *retry,
                       rs_err *err)
{
    if (t->max_queued == 0 && t->seconds_per_hour == 0)
        return 1;
    svc_usage u;
    if (!d->http_store->ops->token_usage(d->http_store, t->id, &u, err))
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

/* Quota check and submit under one lock, so two uploads of one token at
 * once cannot both pass the same last slot (on one daemon; several
 * daemons of a PostgreSQL queue can each let one through). */
static pthread_mutex_t submit_mu = PTHREAD_MUTEX_INITIALIZER;

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
    struct {
        const char *key;
        char *dst;
        size_t room;
    } const enc_args[] = {{"codec", q->codec, sizeof q->codec},
                          {"crf", q->crf, sizeof q->crf},
                          {"bitrate", q->bitrate, sizeof q->bitrate},
                          {"preset", q->preset, sizeof q->preset},
                          {"pix_fmt", q->pix_fmt, sizeof q->pix_fmt},
                          {"audio", q->audio, sizeof q->audio},
                          {"quality", q->quality, sizeof q->quality}};
    for (size_t i = 0; i < sizeof enc_args / sizeof *enc_args; i++)
        if (!enc_args[i].dst[0] && (v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, enc_args[i].key))) {
            if (strlen(v) >= enc_args[i].room)
                return reject(d, c, SVC_ERR_BAD_PARAM, "%s: at most %zu characters", enc_args[i].key, enc_args[i].room - 1);
            snprintf(enc_args[i].dst, enc_args[i].room, "%s", v);
        }
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
        if (d->cfg.render_width &&
            !cap_check_sizes_for(CAP_I420, d->cfg.render_width, d->cfg.render_height, j.width, j.height, &serr))
            return reject(d, c, SVC_ERR_BAD_PARAM, "size %s: %s", q->size, serr.msg);
    }
    if (q->format[0]) {
        if (strcmp(q->format, "mp4") && strcmp(q->format, "webm") && strcmp(q->format, "mkv"))
            return reject(d, c, SVC_ERR_BAD_PARAM, "format '%s': expected mp4, webm or mkv", q->format);
        snprintf(j.format, sizeof j.format, "%s", q->format);
    }
    rs_err err = {0};
    svc_encode_req eq = {q->codec, q->crf, q->bitrate, q->preset, q->pix_fmt, q->audio, q->quality};
    if (!svc_encode_check(&d->cfg, &eq, j.format, j.width, j.height, j.encode, sizeof j.encode, &err))
        return reject(d, c, err.code, "%s", err.msg);
    if (!svc_check_upload(&d->cfg, q->body, q->len, j.name, &j, &err))
        return reject(d, c, err.code, "%s", err.msg);
    j.replay = q->body;
    j.replay_len = q->len;
    j.segment_ticks = d->cfg.segment_seconds * 60; /* the store splits it if it is longer */
    j.token_id = q->tok.id;
    char over[512];
    int64_t retry = 0;
    pthread_mutex_lock(&submit_mu);
    int quota = q->tok.id ? check_quota(d, &q->tok, &j, over, sizeof over, &retry, &err) : 1;
    bool queued = quota == 1 && d->http_store->ops->submit(d->http_store, &j, &err);
    pthread_mutex_unlock(&submit_mu);
    if (quota == 0) {
        char ra[32];
        snprintf(ra, sizeof ra, "%" PRId64, retry);
        svc_log(SVC_LOG_INFO, -1, "upload refused (429): %s", over);
        return reply_error_header(c, SVC_ERR_QUOTA, "Retry-After", ra, "%s; try again in %" PRId64 " s", over, retry);
    }
    if (!queued) {
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
    enum MHD_Result ret = queue(c, 201, r);
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

/* DESIGN (queue position and ETA of a queued job): the claim hands out
 * units of the oldest job first (svc_store.h), so a queued job's position
 * is 1 + the queued jobs older than it.  Its ETA is the frames still to
 * render up to and including it (the running jobs' remainders, the older
 * queued jobs' totals, its own) over the queue's throughput: the recent
 * render speed (frames over wall seconds of the last QUEUE_SPEED_JOBS done
 * jobs, as the queue recorded them, so a split job's parallel segments
 * count) times this daemon's workers.  Another daemon on a PostgreSQL
 * queue is not counted, so the estimate errs long there; before any job
 * is done there is no speed and the ETA is null.  A running job keeps its
 * own: its remaining frames over its live fps.  At most QUEUE_SCAN jobs of
 * the queue are looked at; one further back shows no position. */
#define QUEUE_SPEED_JOBS 20
#define QUEUE_SCAN 10000

typedef struct queue_view {
    svc_pending *p;
    int n;
    double speed; /* frames per second of one worker, recently; 0: unknown */
} queue_view;

/* Loads the queue order when one of jobs[0..n-1] is queued (else nothing
 * to look up).  False: the queue failed (err). */
static bool queue_load(svc_daemon *d, const svc_job *jobs, int n, queue_view *qv, rs_err *err)
{
    memset(qv, 0, sizeof *qv);
    bool any = false;
    for (int i = 0; i < n; i++)
        any |= jobs[i].state == SVC_QUEUED;
    if (!any)
        return true;
    if (!(qv->p = calloc(QUEUE_SCAN, sizeof *qv->p)))
        return rs_fail(err, SVC_ERR_NOMEM, "out of memory");
    qv->n = d->http_store->ops->pending(d->http_store, qv->p, QUEUE_SCAN, err);
    return qv->n >= 0 && d->http_store->ops->speed(d->http_store, QUEUE_SPEED_JOBS, &qv->speed, err);
}

/* What the API shows of job j beyond its row. */
static void job_view(svc_daemon *d, const queue_view *qv, const svc_job *j, svc_job_view *v)
{
    *v = (svc_job_view){.eta_s = -1, .bytes = -1};
    char path[1100];
    struct stat st;
    if (j->state == SVC_DONE && !j->expired) {
        snprintf(path, sizeof path, "%s/%" PRId64 ".%s", d->cfg.output, j->id, j->format);
        if (stat(path, &st) == 0 && S_ISREG(st.st_mode))
            v->bytes = (int64_t)st.st_size;
        snprintf(path, sizeof path, "%s/%" PRId64 ".png", d->cfg.output, j->id);
        v->poster = stat(path, &st) == 0 && S_ISREG(st.st_mode);
    }
    if (j->state != SVC_QUEUED)
        return;
    int64_t frames = 0, ahead = 0;
    for (int i = 0; i < qv->n; i++) {
        frames += qv->p[i].frames_left;
        if (qv->p[i].id == j->id) {
            v->queue_position = ahead + 1;
            if (qv->speed > 0)
                v->eta_s = (double)frames / (qv->speed * d->cfg.workers);
            break;
        }
        ahead += qv->p[i].state == SVC_QUEUED;
    }
}

/* A token sees its own jobs only (an operator's, or no token on an open
 * loopback daemon: every job); another's answers 404, as a missing one. */
static bool may_see(const req *q, const svc_job *j)
{
    return q->all || (q->tok.id != 0 && j->token_id == q->tok.id);
}

/* Job id as q may see it: false with the answer in *ret (503 when the
 * queue is down, 404 for a missing job or another token's). */
static bool get_visible(svc_daemon *d, struct MHD_Connection *c, const req *q, int64_t id, svc_job *j,
                        enum MHD_Result *ret)
{
    rs_err err = {0};
    int r = d->http_store->ops->get(d->http_store, id, j, &err);
    if (r < 0)
        *ret = reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    else if (r == 0 || !may_see(q, j))
        *ret = reply_error(c, SVC_ERR_NOT_FOUND, "no job %" PRId64, id);
    return r == 1 && may_see(q, j);
}

static enum MHD_Result do_get_job(svc_daemon *d, struct MHD_Connection *c, const req *q, int64_t id)
{
    svc_job j;
    enum MHD_Result answer;
    if (!get_visible(d, c, q, id, &j, &answer))
        return answer;
    /* a split job shows its segments: who rendered each, how often */
    svc_unit *units = NULL;
    int n = 0;
    rs_err err = {0};
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
    queue_view qv;
    svc_job_view v;
    if (!queue_load(d, &j, 1, &qv, &err)) {
        free(units);
        free(qv.p);
        return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    }
    job_view(d, &qv, &j, &v);
    free(qv.p);
    svc_buf b = {0};
    svc_json_job(&b, &j, d->cfg.max_attempts, units, n, &v);
    svc_buf_add(&b, "\n", 1);
    free(units);
    return reply_json(c, 200, &b);
}

static enum MHD_Result do_list(svc_daemon *d, struct MHD_Connection *c, const req *q)
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
    int n = d->http_store->ops->list(d->http_store, q->all ? 0 : q->tok.id, before, (int)limit, jobs, &err);
    if (n < 0) {
        free(jobs);
        return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    }
    queue_view qv;
    if (!queue_load(d, jobs, n, &qv, &err)) {
        free(jobs);
        free(qv.p);
        return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    }
    svc_buf b = {0};
    svc_buf_add(&b, "{\"jobs\":[", 9);
    for (int i = 0; i < n; i++) {
        overlay_live(d, &jobs[i], NULL, 0);
        if (i)
            svc_buf_add(&b, ",", 1);
        svc_job_view jv;
        job_view(d, &qv, &jobs[i], &jv);
        svc_json_job(&b, &jobs[i], d->cfg.max_attempts, NULL, 0, &jv);
    }
    free(qv.p);
    if (n == limit && n > 0)
        svc_buf_printf(&b, "],\"next\":\"/jobs?before=%" PRId64 "&limit=%ld\"}\n", jobs[n - 1].id, limit);
    else
        svc_buf_add(&b, "],\"next\":null}\n", 15);
    free(jobs);
    return reply_json(c, 200, &b);
}

/* DELETE of a job that is over: its files, then its row (a crash between
 * leaves a row whose video answers 410, and a second DELETE finishes). */
static enum MHD_Result do_delete_finished(svc_daemon *d, struct MHD_Connection *c, int64_t id)
{
    svc_job j;
    rs_err err = {0};
    int r = d->http_store->ops->get(d->http_store, id, &j, &err);
    int files = r == 1 ? svc_remove_job_outputs(&d->cfg, id, j.format) : 0;
    if (r == 1)
        r = d->http_store->ops->remove(d->http_store, id, &err);
    if (r < 0)
        return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    if (r == 0)
        return reply_error(c, SVC_ERR_NOT_FOUND, "no job %" PRId64, id);
    if (r == 2) /* the store's own check: an over job never runs again */
        return reply_error(c, SVC_ERR_CONFLICT, "job %" PRId64 " is not over", id);
    svc_log(SVC_LOG_INFO, id, "deleted by a client (%s, %d file%s removed)", svc_state_name(j.state), files,
            files == 1 ? "" : "s");
    char body[128];
    snprintf(body, sizeof body, "{\"id\":%" PRId64 ",\"deleted\":true,\"state\":\"%s\",\"files_removed\":%d}\n", id,
             svc_state_name(j.state), files);
    return reply(c, 200, "application/json", body, strlen(body));
}

static enum MHD_Result do_cancel(svc_daemon *d, struct MHD_Connection *c, const req *q, int64_t id)
{
    rs_err err = {0};
    svc_job mine;
    int r = d->http_store->ops->get(d->http_store, id, &mine, &err);
    if (r == 1 && !may_see(q, &mine))
        r = 0;
    if (r == 1)
        r = d->http_store->ops->cancel(d->http_store, id, &err);
    if (r < 0)
        return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    if (r == 0)
        return reply_error(c, SVC_ERR_NOT_FOUND, "no job %" PRId64, id);
    if (r == 2)
        return do_delete_finished(d, c, id);
    if (q->tok.id)
        svc_log(SVC_LOG_INFO, id, "cancelled by a client (token '%s')", q->tok.name);
    else
        svc_log(SVC_LOG_INFO, id, "cancelled by a client");
    return do_get_job(d, c, q, id);
}

static enum MHD_Result do_file(svc_daemon *d, struct MHD_Connection *c, const req *q, int64_t id, bool video)
{
    svc_job j;
    enum MHD_Result answer;
    if (!get_visible(d, c, q, id, &j, &answer))
        return answer;
    if (j.state != SVC_DONE)
        return reply_error(c, SVC_ERR_NOT_FOUND, "job %" PRId64 " is %s: its %s exists once it is done", id, svc_state_name(j.state),
                           video ? "video" : "hash list");
    if (j.expired)
        return reply_error(c, SVC_ERR_GONE, "job %" PRId64 "'s %s was removed by retention (kept %ld s after it finished)",
                           id, video ? "video" : "hash list", d->cfg.retention);
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
        enum MHD_Result ret = queue(c, svc_http_status(SVC_ERR_RANGE), resp);
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
    enum MHD_Result ret = queue(c, rr > 0 ? 206 : 200, resp);
    MHD_destroy_response(resp);
    return ret;
}

/* The job's poster (render --poster), once its render put it in place. */
static enum MHD_Result do_poster(svc_daemon *d, struct MHD_Connection *c, const req *q, int64_t id)
{
    svc_job j;
    enum MHD_Result answer;
    if (!get_visible(d, c, q, id, &j, &answer))
        return answer;
    if (j.expired)
        return reply_error(c, SVC_ERR_GONE, "job %" PRId64 "'s poster was removed by retention", id);
    char path[1100];
    svc_job_file(&d->cfg, id, "png", path, sizeof path);
    int fd = j.state == SVC_DONE ? open(path, O_RDONLY | O_CLOEXEC) : -1;
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        if (fd >= 0)
            close(fd);
        return reply_error(c, SVC_ERR_NOT_FOUND, "job %" PRId64 " is %s and has no poster%s", id, svc_state_name(j.state),
                           j.state == SVC_DONE ? "" : " yet: it comes with the video");
    }
    struct MHD_Response *resp = MHD_create_response_from_fd64((uint64_t)st.st_size, fd);
    if (!resp) {
        close(fd);
        return MHD_NO;
    }
    MHD_add_response_header(resp, "Content-Type", "image/png");
    MHD_add_response_header(resp, "Cache-Control", "private, max-age=3600");
    enum MHD_Result ret = queue(c, 200, resp);
    MHD_destroy_response(resp);
    return ret;
}

/* The job's render log: each ended unit attempt's last lines (OUTPUT/N.log),
 * then what the units running here have said so far. */
static enum MHD_Result do_log(svc_daemon *d, struct MHD_Connection *c, const req *q, int64_t id)
{
    svc_job j;
    enum MHD_Result answer;
    if (!get_visible(d, c, q, id, &j, &answer))
        return answer;
    char path[1100];
    svc_job_file(&d->cfg, id, "log", path, sizeof path);
    size_t len = 0;
    rs_err ferr = {0};
    char *text = rs_read_file(path, 4 << 20, &len, &ferr);
    svc_buf b = {0};
    if (text)
        svc_buf_add(&b, text, len);
    free(text);
    pthread_mutex_lock(&d->mu);
    for (int i = 0; i < d->cfg.workers; i++) {
        const svc_live *l = &d->live[i];
        if (l->job != id)
            continue;
        svc_unit u = {.kind = l->kind, .index = l->index};
        char cx[96];
        svc_unit_context(cx, sizeof cx, &u);
        svc_buf_printf(&b, "== %s%s, running in process %d (%" PRId64 " of %" PRId64 " frames) ==\n%s", cx,
                       l->kind == SVC_UNIT_JOIN ? "join" : "render", (int)l->pid, l->done, l->total, l->log);
    }
    pthread_mutex_unlock(&d->mu);
    if (b.oom) {
        svc_buf_free(&b);
        return MHD_NO;
    }
    enum MHD_Result ret = reply(c, 200, "text/plain; charset=utf-8", b.p ? b.p : "", b.len);
    svc_buf_free(&b);
    return ret;
}

/* A failed job back into the queue, its attempts reset (svc_store.h, retry). */
static enum MHD_Result do_retry(svc_daemon *d, struct MHD_Connection *c, const req *q, int64_t id)
{
    svc_job j;
    rs_err err = {0};
    int r = d->http_store->ops->get(d->http_store, id, &j, &err);
    if (r == 1 && !may_see(q, &j))
        r = 0;
    if (r == 1)
        r = d->http_store->ops->retry(d->http_store, id, &err);
    if (r < 0)
        return reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
    if (r == 0)
        return reply_error(c, SVC_ERR_NOT_FOUND, "no job %" PRId64, id);
    if (r == 2)
        return reply_error(c, SVC_ERR_CONFLICT, "job %" PRId64 " is %s: only a failed job can be retried", id,
                           svc_state_name(j.state));
    svc_log(SVC_LOG_INFO, id, "re-queued by a client%s%s%s (it had failed: %s)", q->tok.id ? " (token '" : "",
            q->tok.id ? q->tok.name : "", q->tok.id ? "')" : "", j.error);
    return do_get_job(d, c, q, id);
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
    /* what the dashboard's upload form offers: the default and the bounds (a fixed
     * render_size bounds the sizes too: downscale only) */
    int mw = d->cfg.max_width, mh = d->cfg.max_height;
    if (d->cfg.render_width && (d->cfg.render_width < mw || d->cfg.render_height < mh))
        mw = d->cfg.render_width < mw ? d->cfg.render_width : mw, mh = d->cfg.render_height < mh ? d->cfg.render_height : mh;
    svc_buf_printf(&b, ",\"default_size\":\"%dx%d\",\"max_size\":\"%dx%d\",\"default_format\":\"%s\",\"default_quality\":\"%s\"",
                   d->cfg.width, d->cfg.height, mw, mh, d->cfg.format, d->cfg.quality);
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
    net_metrics(d->net, &b);
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

static enum MHD_Result route(svc_daemon *d, struct MHD_Connection *c, const req *q, const char *url, const char *method)
{
    bool get = !strcmp(method, "GET") || !strcmp(method, "HEAD");
    if (!strcmp(url, "/") || !strcmp(url, "/index.html"))
        return get ? do_dashboard(d, c) : reply_error(c, SVC_ERR_METHOD, "%s /: only GET", method);
    if (!strcmp(url, "/healthz"))
        return get ? do_health(d, c) : reply_error(c, SVC_ERR_METHOD, "%s %s: only GET", method, url);
    if (!strcmp(url, "/metrics"))
        return get ? do_metrics(d, c) : reply_error(c, SVC_ERR_METHOD, "%s %s: only GET", method, url);
    if (!strcmp(url, "/jobs") || !strcmp(url, "/jobs/"))
        return get ? do_list(d, c, q) : reply_error(c, SVC_ERR_METHOD, "%s /jobs: expected GET or POST", method);
    if (!strncmp(url, "/jobs/", 6)) {
        const char *p = url + 6, *slash = strchr(p, '/');
        size_t n = slash ? (size_t)(slash - p) : strlen(p);
        int64_t id;
        if (!parse_id(p, n, &id))
            return reply_error(c, SVC_ERR_NOT_FOUND, "%s: not a job id", url);
        if (!slash) {
            if (get)
                return do_get_job(d, c, q, id);
            if (!strcmp(method, "DELETE"))
                return do_cancel(d, c, q, id);
            return reply_error(c, SVC_ERR_METHOD, "%s %s: expected GET or DELETE", method, url);
        }
        if (!strcmp(slash, "/video") || !strcmp(slash, "/hashes"))
            return get ? do_file(d, c, q, id, slash[1] == 'v') : reply_error(c, SVC_ERR_METHOD, "%s %s: only GET", method, url);
        if (!strcmp(slash, "/poster"))
            return get ? do_poster(d, c, q, id) : reply_error(c, SVC_ERR_METHOD, "%s %s: only GET", method, url);
        if (!strcmp(slash, "/log"))
            return get ? do_log(d, c, q, id) : reply_error(c, SVC_ERR_METHOD, "%s %s: only GET", method, url);
        if (!strcmp(slash, "/retry"))
            return !strcmp(method, "POST") ? do_retry(d, c, q, id)
                                           : reply_error(c, SVC_ERR_METHOD, "%s %s: only POST", method, url);
    }
    return reply_error(c, SVC_ERR_NOT_FOUND, "%s: no such resource (see /jobs, /healthz, /metrics)", url);
}

/* Who asks (docs/service.md, "Tokens").  Every route but the dashboard
 * and /healthz needs a valid token once any token exists or the daemon
 * listens beyond loopback.  Called at a request's first call, before any
 * body is read, so a refused upload costs no memory.  Nothing is cached:
 * the token is looked up on every request, so a revoked one stops working
 * at its next request.  true: go on (q->tok, q->all say who); false:
 * answered (401, 503), *ret what to return. */
static bool authorize(svc_daemon *d, struct MHD_Connection *c, const char *url, req *q, enum MHD_Result *ret)
{
    if (!strcmp(url, "/") || !strcmp(url, "/index.html") || !strcmp(url, "/healthz"))
        return true;
    const char *h = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Authorization");
    rs_err err = {0};
    q->done = true;
    if (!h) {
        int64_t active = svc_listen_is_loopback(d->cfg.listen) ? d->http_store->ops->token_active(d->http_store, &err) : 1;
        if (active == 0) {
            q->done = false;
            q->all = true; /* loopback, no tokens: the convenience of a local daemon */
            return true;
        }
        *ret = active < 0 ? reply_error(c, err.code, "the queue is unavailable: %s", err.msg)
                          : reply_error_header(c, SVC_ERR_AUTH, "WWW-Authenticate", "Bearer",
                                               "this service needs an API token: send 'Authorization: Bearer TOKEN' "
                                               "('ringside serve token add NAME' makes one)");
        return false;
    }
    size_t n = 0;
    const char *tok = svc_bearer(h, &n);
    if (!tok || n == 0 || n > SVC_TOKEN_LEN) {
        *ret = reply_error_header(c, SVC_ERR_AUTH, "WWW-Authenticate", "Bearer error=\"invalid_token\"",
                                  tok ? "not a token of this service" : "Authorization: expected 'Bearer TOKEN'");
        return false;
    }
    char text[SVC_TOKEN_LEN + 1], hash[SVC_TOKEN_HASH_LEN];
    memcpy(text, tok, n);
    text[n] = 0;
    svc_token_hash(text, hash);
    int r = d->http_store->ops->token_find(d->http_store, hash, &q->tok, &err);
    if (r < 0) {
        *ret = reply_error(c, err.code, "the queue is unavailable: %s", err.msg);
        return false;
    }
    if (r == 0 || q->tok.revoked) {
        bool revoked = r == 1;
        if (revoked)
            svc_log(SVC_LOG_INFO, -1, "refused a request with token '%s' (revoked)", q->tok.name);
        *ret = reply_error_header(c, SVC_ERR_AUTH, "WWW-Authenticate", "Bearer error=\"invalid_token\"",
                                  revoked ? "token '%s' was revoked" : "%sunknown token", revoked ? q->tok.name : "");
        memset(&q->tok, 0, sizeof q->tok);
        return false;
    }
    q->done = false;
    q->all = q->tok.is_operator;
    return true;
}


/* --- the gate: what every request must pass before it is routed --- */

/* A refusal at the gate, logged, with an optional extra header. */
static enum MHD_Result refuse(struct MHD_Connection *c, int id, const char *header, const char *value, const char *fmt,
                              ...) RS_PRINTF(5, 6);
static enum MHD_Result refuse(struct MHD_Connection *c, int id, const char *header, const char *value, const char *fmt,
                              ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    svc_log(SVC_LOG_INFO, -1, "request refused (%u): %s", svc_http_status(id), msg);
    return send_error(c, id, header, value, msg);
}

/* The host of a Host header or an allowed_hosts entry, lower case, without
 * its port or IPv6 brackets ("[::1]:8080" -> "::1"); false if empty or too long. */
static bool host_part(const char *in, size_t in_len, char *out, size_t n)
{
    const char *s = in;
    size_t len = in_len;
    if (len && *s == '[') {
        const char *e = memchr(s, ']', len);
        if (!e)
            return false;
        s++;
        len = (size_t)(e - s);
    } else {
        const char *colon = memchr(s, ':', len);
        if (colon && !memchr(colon + 1, ':', len - (size_t)(colon + 1 - s))) /* host:port, not a bare IPv6 */
            len = (size_t)(colon - s);
    }
    if (len == 0 || len >= n)
        return false;
    for (size_t i = 0; i < len; i++)
        out[i] = (char)tolower((unsigned char)s[i]);
    out[len] = 0;
    return true;
}

/* Whether NAME is one of the comma-separated items of LIST (spaces around
 * items ignored, case-insensitive). */
static bool in_list(const char *list, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = list; *p;) {
        while (*p == ' ' || *p == ',')
            p++;
        const char *e = p;
        while (*e && *e != ',')
            e++;
        const char *t = e;
        while (t > p && t[-1] == ' ')
            t--;
        if ((size_t)(t - p) == n && n && !strncasecmp(p, name, n))
            return true;
        p = e;
    }
    return false;
}

/* The Host names accepted when allowed_hosts is empty: the listen host,
 * the loopback names and, listening on every address, this machine's name. */
static void default_hosts(svc_net *n)
{
    char lh[128] = "";
    const char *listen = n->d->cfg.listen, *colon = strrchr(listen, ':');
    host_part(listen, colon ? (size_t)(colon - listen) : strlen(listen), lh, sizeof lh);
    bool any = !lh[0] || !strcmp(lh, "0.0.0.0") || !strcmp(lh, "::");
    char me[256] = "";
    if (any && gethostname(me, sizeof me - 1) != 0)
        me[0] = 0;
    snprintf(n->hosts, sizeof n->hosts, "localhost,127.0.0.1,::1%s%s%s%s", any ? "" : ",", any ? "" : lh,
             me[0] ? "," : "", me);
}

static bool host_allowed(svc_net *n, const char *host)
{
    if (!strcmp(n->hosts, "*"))
        return true;
    char h[256];
    if (!host_part(host, strlen(host), h, sizeof h))
        return false;
    for (const char *p = n->hosts; *p;) { /* entries may carry ports or brackets too */
        while (*p == ' ' || *p == ',')
            p++;
        const char *e = p + strcspn(p, ",");
        char item[256];
        if (host_part(p, (size_t)(e - p), item, sizeof item) && !strcmp(item, h))
            return true;
        p = e;
    }
    return false;
}

static bool state_changing(const char *method)
{
    return !strcmp(method, "POST") || !strcmp(method, "DELETE") || !strcmp(method, "PUT") || !strcmp(method, "PATCH");
}

/* The query parameters each resource takes; any other is refused. */
static const struct {
    const char *method, *path, *params;
} query_params[] = {
    {"POST", "/jobs", "size,format,name,codec,crf,bitrate,preset,pix_fmt,audio,quality"},
    {"GET", "/jobs", "limit,before"},
    {"HEAD", "/jobs", "limit,before"},
};

typedef struct unknown_params {
    const char *allowed;
    char names[256];
} unknown_params;

static enum MHD_Result note_param(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    (void)kind, (void)value;
    unknown_params *u = cls;
    if (in_list(u->allowed, key))
        return MHD_YES;
    size_t k = strlen(u->names);
    snprintf(u->names + k, sizeof u->names - k, "%s%s", k ? ", " : "", key);
    return MHD_YES;
}

static enum MHD_Result note_spaced_name(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    (void)kind, (void)value;
    if (!strpbrk(key, " \t"))
        return MHD_YES;
    *(const char **)cls = key;
    return MHD_NO;
}

/* The CORS preflight of a listed origin. */
static enum MHD_Result preflight(struct MHD_Connection *c)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(0, "", MHD_RESPMEM_PERSISTENT);
    if (!r)
        return MHD_NO;
    MHD_add_response_header(r, "Access-Control-Allow-Methods", "GET, POST, DELETE");
    MHD_add_response_header(r, "Access-Control-Allow-Headers", "Authorization, Content-Type");
    MHD_add_response_header(r, "Access-Control-Max-Age", "600");
    enum MHD_Result ret = queue(c, 204, r);
    MHD_destroy_response(r);
    return ret;
}

/* Origin: a state-changing request from a foreign page is refused; a listed
 * origin gets the CORS headers (noted on the connection for queue()). */
static bool gate_origin(svc_daemon *d, struct MHD_Connection *c, const char *method, enum MHD_Result *ret)
{
    net_conn *nc = conn_of(c);
    if (nc) {
        nc->cors[0] = 0;
        nc->vary = d->cfg.cors_origins[0] != 0;
    }
    const char *origin = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Origin");
    if (!origin)
        return true;
    bool listed = in_list(d->cfg.cors_origins, origin);
    if (listed && nc)
        snprintf(nc->cors, sizeof nc->cors, "%s", origin);
    const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Host");
    bool own = host && !strncasecmp(origin, "http://", 7) && !strcasecmp(origin + 7, host);
    if (listed && !strcmp(method, "OPTIONS") &&
        MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Access-Control-Request-Method")) {
        *ret = preflight(c);
        return false;
    }
    if (state_changing(method) && !own && !listed) {
        *ret = refuse(c, SVC_ERR_ORIGIN, NULL, NULL,
                      "%s from Origin %s refused: not this server's own origin, nor one of cors_origins", method, origin);
        return false;
    }
    return true;
}

/* Every check a request passes before it is routed or its body is read:
 * false with *ret the answer when it is refused. */
static bool gate_request(svc_daemon *d, struct MHD_Connection *c, conn_ctx *cx, const char *url, const char *method,
                         enum MHD_Result *ret)
{
    if (cx->bad_uri) {
        *ret = refuse(c, SVC_ERR_BAD_REQUEST, NULL, NULL, "a control character (raw or %%-encoded) in the path or query");
        return false;
    }
    const char *spaced = NULL;
    MHD_get_connection_values(c, MHD_HEADER_KIND, note_spaced_name, &spaced);
    if (spaced) {
        *ret = refuse(c, SVC_ERR_BAD_REQUEST, NULL, NULL, "header '%.64s': whitespace before the colon", spaced);
        return false;
    }
    const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Host");
    if (host && !host_allowed(d->net, host)) {
        *ret = refuse(c, SVC_ERR_HOST, NULL, NULL, "Host '%.200s' is not served here (see the allowed_hosts setting)", host);
        return false;
    }
    const char *te = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Transfer-Encoding");
    if (te && strcasecmp(te, "chunked") && strcasecmp(te, "identity")) {
        *ret = refuse(c, SVC_ERR_CODING, NULL, NULL, "Transfer-Encoding '%.100s': only chunked is understood", te);
        return false;
    }
    if (!gate_origin(d, c, method, ret))
        return false;
    unknown_params u = {.allowed = ""};
    for (size_t i = 0; i < sizeof query_params / sizeof query_params[0]; i++)
        if (!strcmp(method, query_params[i].method) && (!strcmp(url, query_params[i].path) ||
                                                        (!strncmp(url, query_params[i].path, strlen(query_params[i].path)) &&
                                                         !strcmp(url + strlen(query_params[i].path), "/"))))
            u.allowed = query_params[i].params;
    MHD_get_connection_values(c, MHD_GET_ARGUMENT_KIND, note_param, &u);
    if (u.names[0]) {
        *ret = refuse(c, SVC_ERR_BAD_PARAM, NULL, NULL, "unknown query parameter %s for %s %s (it takes: %s)", u.names, method,
                      url, u.allowed[0] ? u.allowed : "none");
        return false;
    }
    return true;
}

/* Runs before the URI is decoded: control characters, raw or %-encoded,
 * are noted here and refused by the gate.  Its answer is the request's
 * context (*con_cls of on_request). */
static void *on_uri(void *cls, const char *uri, struct MHD_Connection *c)
{
    (void)cls, (void)c;
    conn_ctx *cx = calloc(1, sizeof *cx);
    if (!cx)
        return NULL;
    for (const unsigned char *p = (const unsigned char *)uri; *p; p++) {
        if (*p < 0x20 || *p == 0x7f)
            cx->bad_uri = true;
        if (*p == '%' && isxdigit(p[1]) && isxdigit(p[2])) {
            unsigned v = (unsigned)strtoul((char[]){(char)p[1], (char)p[2], 0}, NULL, 16);
            cx->bad_uri |= v < 0x20 || v == 0x7f;
        }
    }
    return cx;
}

/* An upload's room in upload_memory, reserved before its body is read. */
static bool reserve_upload(svc_net *n, req *q, long bytes)
{
    pthread_mutex_lock(&n->mu);
    bool ok = n->reserved + bytes <= n->d->cfg.upload_memory;
    if (ok) {
        n->reserved += bytes;
        q->reserved = bytes;
    }
    pthread_mutex_unlock(&n->mu);
    return ok;
}

/* DESIGN: libmicrohttpd 0.9.75 queues no response while a body is arriving
 * (MHD_queue_response accepts one only right after the headers or after the
 * whole request), so an upload that passes max_upload would be read to its
 * end, however long, before it could be answered.  Instead the 413 is
 * written to the socket here, whole, with Connection: close, and MHD_NO
 * makes libmicrohttpd close the connection: nothing more is read. */
static enum MHD_Result cut_oversize(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    pthread_mutex_lock(&d->mu);
    d->uploads_rejected++;
    pthread_mutex_unlock(&d->mu);
    svc_log(SVC_LOG_INFO, -1, "upload refused (413): more than max_upload %ld bytes sent; connection closed",
            d->cfg.max_upload);
    svc_buf b = {0};
    char msg[160];
    snprintf(msg, sizeof msg, "the upload is over the limit of %ld bytes (max_upload)", d->cfg.max_upload);
    svc_json_error(&b, msg);
    char head[256];
    int hn = snprintf(head, sizeof head,
                      "HTTP/1.1 413 Content Too Large\r\nContent-Type: application/json\r\nCache-Control: no-store\r\n"
                      "Content-Length: %zu\r\nConnection: close\r\n\r\n",
                      b.len);
    net_conn *nc = conn_of(c);
    if (nc && !b.oom) {
        pthread_mutex_lock(&d->net->mu);
        nc->cut = true;
        d->net->cuts[CUT_MAX_UPLOAD]++;
        pthread_mutex_unlock(&d->net->mu);
        send(nc->fd, head, (size_t)hn, MSG_NOSIGNAL | MSG_DONTWAIT | MSG_MORE);
        send(nc->fd, b.p, b.len, MSG_NOSIGNAL | MSG_DONTWAIT);
        shutdown(nc->fd, SHUT_WR);
    }
    svc_buf_free(&b);
    q->too_large = true;
    return MHD_NO;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *c, const char *url, const char *method,
                                  const char *version, const char *upload, size_t *upload_size, void **con_cls)
{
    (void)version;
    svc_daemon *d = cls;
    conn_ctx *cx = *con_cls; /* made by on_uri */
    if (!cx)
        return MHD_NO;
    if (!cx->q.started) {
        req *q = &cx->q;
        q->started = true;
        conn_phase(d->net, c, NET_BODY);
        enum MHD_Result refused;
        /* the request's form first (Host, Origin, strict HTTP), then who asks */
        if (!gate_request(d, c, cx, url, method, &refused) || !authorize(d, c, url, q, &refused)) {
            q->done = true;
            return refused;
        }
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
        long want = cl ? (long)strtoull(cl, NULL, 10)
                       : MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Transfer-Encoding") ? d->cfg.max_upload : 0;
        if (want > 0 && !reserve_upload(d->net, q, want)) {
            q->done = true;
            return refuse(c, SVC_ERR_BUSY, "Retry-After", "5",
                          "uploads in progress hold upload_memory (%ld bytes): try again in a few seconds",
                          d->cfg.upload_memory);
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
        q->received += *upload_size;
        if (q->received > (uint64_t)d->cfg.max_upload)
            return cut_oversize(d, c, q);
        conn_body(d->net, c, *upload_size);
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
    conn_phase(d->net, c, NET_ANSWER);
    if (q->post_jobs)
        return do_submit(d, c, q);
    return route(d, c, q, url, method);
}

static void on_completed(void *cls, struct MHD_Connection *c, void **con_cls, enum MHD_RequestTerminationCode toe)
{
    (void)toe;
    svc_daemon *d = cls;
    conn_phase(d->net, c, NET_HEADERS); /* a keep-alive connection's next request */
    conn_ctx *cx = *con_cls;
    if (!cx)
        return;
    if (cx->q.reserved) {
        pthread_mutex_lock(&d->net->mu);
        d->net->reserved -= cx->q.reserved;
        pthread_mutex_unlock(&d->net->mu);
    }
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

/* The connections the fd limit allows: the soft RLIMIT_NOFILE is raised
 * toward the hard one; what is still short lowers the limit, with a word. */
static unsigned connection_limit(const svc_config *cfg)
{
    enum { RESERVE = 128 }; /* the queue, logs, render pipes, the listen socket */
    rlim_t want = (rlim_t)cfg->max_connections + RESERVE;
    struct rlimit rl;
    if (getrlimit(RLIMIT_NOFILE, &rl) != 0)
        return (unsigned)cfg->max_connections;
    if (rl.rlim_cur < want && rl.rlim_cur < rl.rlim_max) {
        rl.rlim_cur = rl.rlim_max == RLIM_INFINITY || rl.rlim_max > want ? want : rl.rlim_max;
        setrlimit(RLIMIT_NOFILE, &rl);
        getrlimit(RLIMIT_NOFILE, &rl);
    }
    if (rl.rlim_cur >= want)
        return (unsigned)cfg->max_connections;
    unsigned n = rl.rlim_cur > RESERVE + 16 ? (unsigned)(rl.rlim_cur - RESERVE) : 16;
    svc_log(SVC_LOG_WARN, -1, "max_connections %d lowered to %u: the open-file limit is %llu (raise `ulimit -n`)",
            cfg->max_connections, n, (unsigned long long)rl.rlim_cur);
    return n;
}

static svc_net *net_new(svc_daemon *d)
{
    svc_net *n = calloc(1, sizeof *n);
    if (!n)
        return NULL;
    n->d = d;
    pthread_mutex_init(&n->mu, NULL);
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_cond_init(&n->wake, &ca);
    pthread_condattr_destroy(&ca);
    if (d->cfg.allowed_hosts[0])
        snprintf(n->hosts, sizeof n->hosts, "%s", d->cfg.allowed_hosts);
    else
        default_hosts(n);
    return n;
}

static void net_free(svc_net *n)
{
    if (!n)
        return;
    if (n->reaper_started) {
        pthread_mutex_lock(&n->mu);
        n->stop = true;
        pthread_cond_signal(&n->wake);
        pthread_mutex_unlock(&n->mu);
        pthread_join(n->reaper, NULL);
    }
    pthread_cond_destroy(&n->wake);
    pthread_mutex_destroy(&n->mu);
    free(n);
}

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
        rs_fail(err, SVC_ERR_LISTEN, "listen %s: %s", d->cfg.listen, gai_strerror(gr));
        return NULL;
    }
    if (!(d->net = net_new(d))) {
        freeaddrinfo(ai);
        rs_fail(err, SVC_ERR_NOMEM, "out of memory starting the HTTP server");
        return NULL;
    }
    /* epoll: no FD_SETSIZE limit, and thousands of idle connections cost
     * nothing per wake-up; each of the pool's threads has its own */
    unsigned flags = MHD_USE_EPOLL_INTERNAL_THREAD | MHD_USE_ERROR_LOG;
    if (ai->ai_family == AF_INET6)
        flags |= MHD_USE_IPv6;
    /* strict: HTTP/1.1 without Host and spaces in the request line are
     * answered 400 by libmicrohttpd itself */
    struct MHD_Daemon *mhd = MHD_start_daemon(
        flags, 0, NULL, NULL, on_request, d, MHD_OPTION_EXTERNAL_LOGGER, on_mhd_log, d, MHD_OPTION_SOCK_ADDR,
        ai->ai_addr, MHD_OPTION_THREAD_POOL_SIZE, 4u, MHD_OPTION_NOTIFY_COMPLETED, on_completed, d,
        MHD_OPTION_NOTIFY_CONNECTION, on_connection, d->net, MHD_OPTION_URI_LOG_CALLBACK, on_uri, d,
        MHD_OPTION_STRICT_FOR_CLIENT, 1, MHD_OPTION_CONNECTION_TIMEOUT, 60u, MHD_OPTION_CONNECTION_LIMIT,
        connection_limit(&d->cfg), MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)d->cfg.max_connections_per_ip,
        MHD_OPTION_END);
    freeaddrinfo(ai);
    if (!mhd) {
        net_free(d->net);
        d->net = NULL;
        rs_fail(err, SVC_ERR_LISTEN, "cannot listen on %s (in use, or not an address of this machine?)", d->cfg.listen);
        return NULL;
    }
    if (pthread_create(&d->net->reaper, NULL, reaper, d->net) == 0)
        d->net->reaper_started = true;
    else
        svc_log(SVC_LOG_WARN, -1, "no connection reaper thread: header_timeout and min_body_rate are not enforced");
    const union MHD_DaemonInfo *info = MHD_get_daemon_info(mhd, MHD_DAEMON_INFO_BIND_PORT);
    d->port = info ? info->port : 0;
    return mhd;
}

void svc_http_stop(svc_daemon *d, struct MHD_Daemon *h)
{
    if (h)
        MHD_stop_daemon(h); /* reports every connection closed first */
    net_free(d->net);
    d->net = NULL;
}

#else /* !RS_HAVE_MHD */

struct MHD_Daemon *svc_http_start(svc_daemon *d, rs_err *err)
{
    (void)d;
    rs_fail(err, SVC_ERR_NO_HTTP, "this ringside was built without libmicrohttpd (install libmicrohttpd-dev and rebuild)");
    return NULL;
}

void svc_http_stop(svc_daemon *d, struct MHD_Daemon *h)
{
    (void)d, (void)h;
}

#endif
