/* svc_http_events: GET /jobs/events, the job list's changes pushed as
 * Server-Sent Events (docs/service.md, "Events").
 *
 *   event: jobs    the page of jobs as GET /jobs?limit&before answers it:
 *                  first, and again whenever a job enters or leaves the page
 *   event: job     one job of the page whose object changed (progress,
 *                  state, queue place, stream), as in the list
 *   event: end     the stream ends: why (a revoked token, the daemon stopping)
 *   ": ping"       a comment after 15 s of silence, so a dead client is noticed
 *
 * DESIGN: a stream is a libmicrohttpd response read through a callback
 * that hands over what is queued and, when nothing is, suspends its
 * connection (the pool's threads never wait on a stream).  One thread
 * looks at the queue every EVENTS_TICK_MS (at once when poked by an upload
 * or a cancel here), makes each stream's page, and queues the objects that
 * differ from what that stream last sent (FNV-1a of the object's text),
 * resuming its connection.  Streams of the same page and token share one
 * look.  Looking at the queue rather than being told by the workers is
 * what lets any daemon of a PostgreSQL queue push what the others do, and
 * it costs what one dashboard's polling cost, without the requests; a
 * round that takes long makes the next wait twice its time, so streams of
 * many different pages cannot take more than a third of a core.
 * Streams are freed only by the thread: the response's free callback
 * marks its stream gone, so the thread never resumes a closed
 * connection. */
#include <inttypes.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "svc.h"

#if defined(RS_HAVE_MHD)
#include "svc_http_local.h"
#include "svc_log.h"
#include "../runtime/util/rs_hash.h"
#include "../runtime/util/rs_progress.h"

#define EVENTS_TICK_MS 500
#define EVENTS_PING_S 15.0
#define EVENTS_TOKEN_CHECK_S 5.0 /* how soon a revoked token's stream ends */
#define EVENTS_MAX 64            /* streams open at once */
#define EVENTS_OUT_MAX (4 << 20) /* bytes queued for a client that reads nothing: it is cut */

typedef struct ev_stream {
    struct ev_stream *next;
    svc_events *hub;
    struct MHD_Connection *c;
    /* what it shows: fixed at the request */
    int64_t token_id; /* 0: every job */
    bool token_less;  /* an open loopback daemon's (it ends once a token exists) */
    int64_t before;
    long limit;
    /* what the client was sent (the thread's alone) */
    int64_t *ids;
    uint64_t *hash;
    int n;
    bool listed;
    double last_out; /* monotonic seconds of the last bytes queued */
    /* under the hub's lock */
    svc_buf out;
    size_t off;      /* of out, handed to libmicrohttpd */
    bool suspended;  /* its connection is suspended: resume it for new bytes */
    bool ending;     /* send out, then end */
    bool gone;       /* its response was freed: the thread frees it */
} ev_stream;

struct svc_events {
    svc_daemon *d;
    pthread_mutex_t mu;
    pthread_cond_t wake;
    ev_stream *streams;
    int open;
    bool stop, poked;
    pthread_t thread;
    uint64_t sent, cut; /* events sent; streams cut for not reading */
};

static void stream_free(ev_stream *s)
{
    svc_buf_free(&s->out);
    free(s->ids);
    free(s->hash);
    free(s);
}

/* An absolute CLOCK_REALTIME time ns from now, for pthread_cond_timedwait. */
static struct timespec deadline_in(long ns)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    ts.tv_sec += ns / 1000000000L;
    ts.tv_nsec += ns % 1000000000L;
    ts.tv_sec += ts.tv_nsec / 1000000000L;
    ts.tv_nsec %= 1000000000L;
    return ts;
}

/* --- the connection's side (libmicrohttpd's threads) --- */

/* What is queued, else the end, else suspend until the thread resumes it. */
static ssize_t ev_read(void *cls, uint64_t pos, char *buf, size_t max)
{
    (void)pos;
    ev_stream *s = cls;
    pthread_mutex_lock(&s->hub->mu);
    ssize_t n = 0;
    if (s->off < s->out.len) {
        size_t k = s->out.len - s->off < max ? s->out.len - s->off : max;
        memcpy(buf, s->out.p + s->off, k);
        s->off += k;
        if (s->off == s->out.len)
            s->out.len = s->off = 0;
        n = (ssize_t)k;
    } else if (s->ending)
        n = MHD_CONTENT_READER_END_OF_STREAM;
    else {
        /* the lock orders this against the thread's resume: bytes queued
         * after this point find the stream suspended and resume it */
        s->suspended = true;
        MHD_suspend_connection(s->c);
    }
    pthread_mutex_unlock(&s->hub->mu);
    return n;
}

static void ev_free(void *cls)
{
    ev_stream *s = cls;
    pthread_mutex_lock(&s->hub->mu);
    s->gone = true;
    s->suspended = false;
    pthread_cond_signal(&s->hub->wake);
    pthread_mutex_unlock(&s->hub->mu);
}

/* Under the lock: bytes for s, its connection resumed if it waits for them. */
static void ev_queue(svc_events *e, ev_stream *s, const char *p, size_t n)
{
    if (s->gone || s->ending)
        return;
    if (s->out.len - s->off + n > EVENTS_OUT_MAX) { /* a client that reads nothing */
        s->out.len = s->off = 0;
        static const char cut[] = "event: end\ndata: {\"reason\":\"the client reads too slowly\"}\n\n";
        svc_buf_add(&s->out, cut, sizeof cut - 1);
        s->ending = true;
        e->cut++;
    } else
        svc_buf_add(&s->out, p, n);
    if (s->suspended) {
        s->suspended = false;
        MHD_resume_connection(s->c);
    }
}

static void ev_end(svc_events *e, ev_stream *s, const char *why)
{
    char line[256];
    int n = snprintf(line, sizeof line, "event: end\ndata: {\"reason\":\"%s\"}\n\n", why);
    ev_queue(e, s, line, (size_t)n); /* resumes the connection when it waits */
    s->ending = true;
}

enum MHD_Result http_events(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    long limit;
    int64_t before;
    enum MHD_Result ret;
    if (!http_list_params(c, 20 /* the dashboard's page */, &limit, &before, &ret))
        return ret;
    static const http_header again = {"Retry-After", "5"};
    svc_events *e = d->events;
    if (!e)
        return http_error(c, SVC_ERR_STREAMS, &again, NULL, "this daemon has no event thread");
    ev_stream *s = calloc(1, sizeof *s);
    if (!s || !(s->ids = calloc((size_t)limit, sizeof *s->ids)) || !(s->hash = calloc((size_t)limit, sizeof *s->hash))) {
        if (s)
            stream_free(s);
        return http_error(c, SVC_ERR_NOMEM, NULL, NULL, "out of memory");
    }
    *s = (ev_stream){.hub = e, .c = c, .token_id = q->all ? 0 : q->tok.id, .token_less = q->all && q->tok.id == 0,
                     .before = before, .limit = limit, .ids = s->ids, .hash = s->hash, .last_out = rs_now()};
    static const char hello[] = "retry: 2000\n\n";
    svc_buf_add(&s->out, hello, sizeof hello - 1);
    pthread_mutex_lock(&e->mu);
    bool full = e->open >= EVENTS_MAX || e->stop;
    if (!full) {
        s->next = e->streams;
        e->streams = s;
        e->open++;
        e->poked = true;
        pthread_cond_signal(&e->wake);
    }
    pthread_mutex_unlock(&e->mu);
    if (full) {
        stream_free(s);
        return http_error(c, SVC_ERR_STREAMS, &again, NULL, "%d event streams are open, the most this daemon keeps",
                          EVENTS_MAX);
    }
    /* from here the stream belongs to the thread: ev_free marks it gone */
    struct MHD_Response *r = MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 4096, ev_read, s, ev_free);
    if (!r) {
        ev_free(s);
        return http_error(c, SVC_ERR_NOMEM, NULL, NULL, "out of memory");
    }
    MHD_add_response_header(r, "Content-Type", "text/event-stream; charset=utf-8");
    MHD_add_response_header(r, "Cache-Control", "no-store");
    MHD_add_response_header(r, "X-Accel-Buffering", "no"); /* a proxy in front (nginx) passes each event on at once */
    ret = http_queue(c, 200, r);
    MHD_destroy_response(r);
    return ret;
}

/* --- the thread --- */

/* One look at a page, shared by the streams that show it. */
typedef struct ev_look {
    int64_t token_id, before;
    long limit;
    bool ok;
    http_jobs_page p;
    uint64_t *hash;
    rs_err err;
} ev_look;

static void look_free(ev_look *l)
{
    http_jobs_page_free(&l->p);
    free(l->hash);
}

static void look(svc_daemon *d, ev_look *l)
{
    l->ok = http_jobs_page_make(d, l->token_id, l->before, l->limit, &l->p, &l->err);
    if (l->ok && !(l->hash = calloc((size_t)l->p.n + 1, sizeof *l->hash))) {
        http_jobs_page_free(&l->p);
        l->ok = false;
        rs_fail(&l->err, SVC_ERR_NOMEM, "out of memory");
    }
    for (int i = 0; l->ok && i < l->p.n; i++)
        l->hash[i] = rs_fnv1a64(l->p.b.p + l->p.at[i], l->p.at[i + 1] - l->p.at[i]);
}

/* What stream s is sent of look l, appended to out: the whole page when
 * its jobs are not the ones s has, else the objects that changed. */
static void diff(ev_stream *s, const ev_look *l, svc_buf *out, uint64_t *events)
{
    bool same = s->listed && s->n == l->p.n;
    for (int i = 0; same && i < l->p.n; i++)
        same = s->ids[i] == l->p.ids[i];
    if (!same) {
        svc_buf_add(out, "event: jobs\ndata: ", 18);
        svc_buf_add(out, l->p.b.p, l->p.b.len);
        svc_buf_add(out, "\n\n", 2);
        (*events)++;
    } else
        for (int i = 0; i < l->p.n; i++)
            if (s->hash[i] != l->hash[i]) {
                svc_buf_add(out, "event: job\ndata: ", 17);
                svc_buf_add(out, l->p.b.p + l->p.at[i], l->p.at[i + 1] - l->p.at[i]);
                svc_buf_add(out, "\n\n", 2);
                (*events)++;
            }
    memcpy(s->ids, l->p.ids, (size_t)l->p.n * sizeof *s->ids);
    memcpy(s->hash, l->hash, (size_t)l->p.n * sizeof *s->hash);
    s->n = l->p.n;
    s->listed = true;
}

/* Whether the token of s still may look (checked every EVENTS_TOKEN_CHECK_S):
 * a revoked token's stream ends, and so does an open daemon's once a token
 * exists.  tokens[0..nt-1]: the queue's tokens (nt < 0: not known). */
static const char *refused(const ev_stream *s, const svc_token *tokens, int nt, int64_t active)
{
    if (s->token_less)
        return active > 0 ? "this service needs an API token now" : NULL;
    if (s->token_id == 0 || nt < 0)
        return NULL;
    for (int i = 0; i < nt; i++)
        if (tokens[i].id == s->token_id)
            return tokens[i].revoked ? "the token was revoked" : NULL;
    return "the token was removed";
}

/* The streams the thread serves this round, with the lock held: the gone
 * ones freed; the others' pointers stay valid until the thread frees them. */
static int gather(svc_events *e, ev_stream ***list)
{
    for (ev_stream **pp = &e->streams; *pp;) {
        ev_stream *s = *pp;
        if (s->gone) {
            *pp = s->next;
            e->open--;
            stream_free(s);
        } else
            pp = &s->next;
    }
    free(*list);
    *list = calloc((size_t)e->open + 1, sizeof **list);
    int n = 0;
    for (ev_stream *s = e->streams; s && *list; s = s->next)
        if (!s->ending)
            (*list)[n++] = s;
    return n;
}

static void one_round(svc_events *e, ev_stream **list, int n, bool check_tokens)
{
    svc_daemon *d = e->d;
    svc_token tokens[256];
    int nt = -1;
    int64_t active = 0;
    if (check_tokens) {
        rs_err err = {0};
        nt = d->http_store->ops->token_list(d->http_store, tokens, 256, &err);
        active = nt > 0 ? nt : d->http_store->ops->token_active(d->http_store, &err);
        if (nt >= 256)
            nt = -1; /* more than fit: not judged this round */
    }
    ev_look *looks = calloc((size_t)n + 1, sizeof *looks);
    svc_buf *outs = calloc((size_t)n + 1, sizeof *outs);
    const char **why = calloc((size_t)n + 1, sizeof *why);
    if (!looks || !outs || !why) {
        free(looks), free(outs), free(why);
        return;
    }
    int nl = 0;
    uint64_t events = 0;
    double t = rs_now();
    for (int i = 0; i < n; i++) {
        ev_stream *s = list[i];
        if (check_tokens && (why[i] = refused(s, tokens, nt, active)))
            continue;
        int k = 0;
        while (k < nl && !(looks[k].token_id == s->token_id && looks[k].before == s->before && looks[k].limit == s->limit))
            k++;
        if (k == nl) {
            looks[nl] = (ev_look){.token_id = s->token_id, .before = s->before, .limit = s->limit};
            look(d, &looks[nl++]);
        }
        if (looks[k].ok)
            diff(s, &looks[k], &outs[i], &events);
        if (outs[i].len == 0 && t - s->last_out >= EVENTS_PING_S)
            svc_buf_add(&outs[i], ": ping\n\n", 8);
        if (outs[i].len)
            s->last_out = t;
    }
    for (int k = 0; k < nl; k++)
        if (!looks[k].ok)
            svc_log(SVC_LOG_WARN, -1, "event streams: %s", looks[k].err.msg);
    pthread_mutex_lock(&e->mu);
    for (int i = 0; i < n; i++) {
        if (why[i])
            ev_end(e, list[i], why[i]);
        else if (outs[i].len)
            ev_queue(e, list[i], outs[i].p, outs[i].len);
        svc_buf_free(&outs[i]);
    }
    e->sent += events;
    pthread_mutex_unlock(&e->mu);
    for (int k = 0; k < nl; k++)
        look_free(&looks[k]);
    free(looks), free(outs), free(why);
}

static void *events_main(void *arg)
{
    svc_events *e = arg;
    ev_stream **list = NULL;
    double checked = 0, spent = 0; /* seconds the last round took */
    pthread_mutex_lock(&e->mu);
    while (!e->stop) {
        if (!e->streams) {
            pthread_cond_wait(&e->wake, &e->mu);
            continue;
        }
        if (!e->poked) {
            /* a round that took long (many pages, a slow queue) waits
             * twice as long: the thread keeps to a third of a core */
            long wait_ns = EVENTS_TICK_MS * 1000000L;
            if (spent * 2e9 > (double)wait_ns)
                wait_ns = spent * 2e9 > 10e9 ? 10000000000L : (long)(spent * 2e9);
            struct timespec ts = deadline_in(wait_ns);
            pthread_cond_timedwait(&e->wake, &e->mu, &ts);
            if (e->stop)
                break;
        }
        e->poked = false;
        int n = gather(e, &list);
        pthread_mutex_unlock(&e->mu);
        double t = rs_now();
        bool check = t - checked >= EVENTS_TOKEN_CHECK_S;
        if (check)
            checked = t;
        if (n > 0)
            one_round(e, list, n, check);
        spent = rs_now() - t;
        pthread_mutex_lock(&e->mu);
    }
    pthread_mutex_unlock(&e->mu);
    free(list);
    return NULL;
}

bool http_events_start(svc_daemon *d)
{
    svc_events *e = calloc(1, sizeof *e);
    if (!e)
        return false;
    e->d = d;
    pthread_mutex_init(&e->mu, NULL);
    pthread_cond_init(&e->wake, NULL);
    if (pthread_create(&e->thread, NULL, events_main, e) != 0) {
        pthread_mutex_destroy(&e->mu);
        pthread_cond_destroy(&e->wake);
        free(e);
        return false;
    }
    d->events = e;
    return true;
}

void http_events_end(svc_daemon *d)
{
    svc_events *e = d->events;
    if (!e)
        return;
    pthread_mutex_lock(&e->mu);
    e->stop = true;
    for (ev_stream *s = e->streams; s; s = s->next)
        if (!s->gone && !s->ending)
            ev_end(e, s, "the daemon is stopping");
    pthread_cond_signal(&e->wake);
    pthread_mutex_unlock(&e->mu);
    pthread_join(e->thread, NULL);
    /* libmicrohttpd's stop closes connections without sending what waits:
     * give the streams up to a second to send their end and close */
    double until = rs_now() + 1.0;
    pthread_mutex_lock(&e->mu);
    for (;;) {
        bool open = false;
        for (ev_stream *s = e->streams; s && !open; s = s->next)
            open = !s->gone;
        if (!open || rs_now() >= until)
            break;
        struct timespec ts = deadline_in(50000000L);
        pthread_cond_timedwait(&e->wake, &e->mu, &ts);
    }
    pthread_mutex_unlock(&e->mu);
}

/* After libmicrohttpd stopped (every response freed): the memory. */
void http_events_free(svc_daemon *d)
{
    svc_events *e = d->events;
    if (!e)
        return;
    while (e->streams) {
        ev_stream *s = e->streams;
        e->streams = s->next;
        stream_free(s);
    }
    pthread_mutex_destroy(&e->mu);
    pthread_cond_destroy(&e->wake);
    free(e);
    d->events = NULL;
}

void http_events_poke(svc_daemon *d)
{
    svc_events *e = d->events;
    if (!e)
        return;
    pthread_mutex_lock(&e->mu);
    e->poked = true;
    pthread_cond_signal(&e->wake);
    pthread_mutex_unlock(&e->mu);
}

void http_events_metrics(svc_daemon *d, svc_buf *b)
{
    svc_events *e = d->events;
    int open = 0;
    uint64_t sent = 0, cut = 0;
    if (e) {
        pthread_mutex_lock(&e->mu);
        for (ev_stream *s = e->streams; s; s = s->next)
            open += !s->gone;
        sent = e->sent;
        cut = e->cut;
        pthread_mutex_unlock(&e->mu);
    }
    svc_buf_printf(b,
                   "# HELP ringside_event_streams GET /jobs/events streams open.\n# TYPE ringside_event_streams gauge\n"
                   "ringside_event_streams %d\n"
                   "# HELP ringside_events_sent_total Events sent on GET /jobs/events streams.\n"
                   "# TYPE ringside_events_sent_total counter\nringside_events_sent_total %" PRIu64 "\n"
                   "# HELP ringside_event_streams_cut_total Event streams ended because the client read nothing.\n"
                   "# TYPE ringside_event_streams_cut_total counter\nringside_event_streams_cut_total %" PRIu64 "\n",
                   open, sent, cut);
}

#endif
