/* svc_http_guard: the network's guards: connections, their deadlines, the
 * upload budget, the raw 413 of an oversized upload.
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
 * fd that has been reused.
 *
 * The raw bytes of every watched connection pass through here too
 * (svc_http_recv.c): svc_wire checks them as they arrive, and a request it
 * refuses is answered by the guard itself, then the connection lingers.
 *
 * DESIGN (refusals and lingering): a refusal is written to the socket
 * whole, with Connection: close, only when libmicrohttpd is not writing on
 * it: the refused request is the one it is reading and no response is
 * queued (else it waits for on_completed of the request before it).  Then
 * libmicrohttpd's reads fail and it closes its descriptor, but the socket
 * lives on in a dup() that a lingering thread reads and discards, for at
 * most LINGER_TIME seconds, LINGER_IDLE without a byte, LINGER_BYTES: a
 * client still sending its body reads the answer instead of a reset (the
 * kernel answers a close with unread bytes with RST, which can overtake
 * the response; nginx's lingering_close does the same). */
#include <errno.h>
#include <inttypes.h>
#include <netdb.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <stdatomic.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#if defined(RS_HAVE_MHD)
#include "svc_http_local.h"
#include "svc_http_recv.h"
#include "svc_log.h"

static const char *const cut_name[NET_NCUTS] = {"header_timeout", "min_body_rate", "max_upload", "malformed"};

enum {
    WIRE_FDS = 1 << 16, /* descriptors watched: 0 .. WIRE_FDS - 1 */
    LINGER_MAX = 512,   /* connections lingering at once; more are closed at once */
};
static const double LINGER_TIME = 10, LINGER_IDLE = 2;
static const uint64_t LINGER_BYTES = 64u << 20;

struct net_linger {
    net_linger *prev, *next;
    int fd;
    double start, last;
    uint64_t bytes;
};

/* the watched connections by descriptor, for recv(): set when
 * libmicrohttpd opens one, cleared before it closes it */
static _Atomic(net_conn *) wire_fd[WIRE_FDS];

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec / 1e9;
}

net_conn *http_guard_conn(struct MHD_Connection *c)
{
    const union MHD_ConnectionInfo *ci = MHD_get_connection_info(c, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
    return ci ? ci->socket_context : NULL;
}

void http_guard_phase(svc_net *n, struct MHD_Connection *c, int phase)
{
    net_conn *nc = http_guard_conn(c);
    if (!nc)
        return;
    pthread_mutex_lock(&n->mu);
    nc->phase = phase;
    nc->since = now_s();
    nc->body = 0;
    pthread_mutex_unlock(&n->mu);
}

void http_guard_body(svc_net *n, struct MHD_Connection *c, size_t bytes)
{
    net_conn *nc = http_guard_conn(c);
    if (!nc)
        return;
    pthread_mutex_lock(&n->mu);
    nc->body += bytes;
    pthread_mutex_unlock(&n->mu);
}

void http_guard_notify(void *cls, struct MHD_Connection *c, void **socket_context,
                       enum MHD_ConnectionNotificationCode code)
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
        if (nc->fd >= 0 && nc->fd < WIRE_FDS)
            atomic_store(&wire_fd[nc->fd], NULL);
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
    nc->net = n;
    svc_wire_init(&nc->w, (uint64_t)n->d->cfg.max_upload);
    if (nc->fd >= 0 && nc->fd < WIRE_FDS)
        atomic_store(&wire_fd[nc->fd], nc);
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

void http_guard_metrics(svc_net *n, svc_buf *b)
{
    pthread_mutex_lock(&n->mu);
    long open = n->open, reserved = n->reserved, lingering = n->lingering;
    uint64_t cuts[NET_NCUTS];
    memcpy(cuts, n->cuts, sizeof cuts);
    pthread_mutex_unlock(&n->mu);
    svc_buf_printf(b, "# HELP ringside_http_connections HTTP connections open now.\n"
                      "# TYPE ringside_http_connections gauge\nringside_http_connections %ld\n"
                      "# HELP ringside_http_upload_bytes_reserved Bytes of upload_memory held by uploads in progress.\n"
                      "# TYPE ringside_http_upload_bytes_reserved gauge\nringside_http_upload_bytes_reserved %ld\n"
                      "# HELP ringside_http_connections_lingering Refused connections read to their end before they close.\n"
                      "# TYPE ringside_http_connections_lingering gauge\nringside_http_connections_lingering %ld\n"
                      "# HELP ringside_http_connections_cut_total Connections ended by the daemon, by reason.\n"
                      "# TYPE ringside_http_connections_cut_total counter\n",
                   open, reserved, lingering);
    for (int i = 0; i < NET_NCUTS; i++)
        svc_buf_printf(b, "ringside_http_connections_cut_total{reason=\"%s\"} %" PRIu64 "\n", cut_name[i], cuts[i]);
}

/* An upload's room in upload_memory, reserved before its body is read. */
bool http_guard_reserve(svc_net *n, req *q, long bytes)
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

void http_guard_release(svc_net *n, req *q)
{
    if (!q->reserved)
        return;
    pthread_mutex_lock(&n->mu);
    n->reserved -= q->reserved;
    q->reserved = 0;
    pthread_mutex_unlock(&n->mu);
}

/* Hands fd to the lingering thread (or closes it: too many linger). */
static void linger_add(svc_net *n, int fd)
{
    net_linger *l = NULL;
    pthread_mutex_lock(&n->mu);
    if (n->linger_ep >= 0 && n->lingering < LINGER_MAX && (l = calloc(1, sizeof *l))) {
        l->fd = fd;
        l->start = l->last = now_s();
        struct epoll_event ev = {.events = EPOLLIN | EPOLLRDHUP, .data.ptr = l};
        if (epoll_ctl(n->linger_ep, EPOLL_CTL_ADD, fd, &ev) == 0) {
            l->next = n->lingers;
            if (n->lingers)
                n->lingers->prev = l;
            n->lingers = l;
            n->lingering++;
        } else {
            free(l);
            l = NULL;
        }
    }
    if (!l)
        n->linger_full++;
    pthread_mutex_unlock(&n->mu);
    if (!l)
        close(fd);
}

/* The guard's own answer to a request it refuses (a JSON error, as
 * http_error gives), then the connection closed with a lingering close.
 * Called by the connection's libmicrohttpd thread when nothing else is
 * being written on it. */
static void conn_answer(net_conn *nc, int status, const char *why)
{
    svc_net *n = nc->net;
    svc_buf b = {0};
    svc_json_error(&b, why);
    char head[256];
    int hn = snprintf(head, sizeof head,
                      "HTTP/1.1 %d %s\r\nContent-Type: application/json\r\nCache-Control: no-store\r\n"
                      "Content-Length: %zu\r\nConnection: close\r\n\r\n",
                      status, svc_wire_phrase(status), b.len);
    if (!b.oom) {
        send(nc->fd, head, (size_t)hn, MSG_NOSIGNAL | MSG_DONTWAIT | MSG_MORE);
        send(nc->fd, b.p, b.len, MSG_NOSIGNAL | MSG_DONTWAIT);
    }
    svc_buf_free(&b);
    int fd = dup(nc->fd);
    if (fd >= 0) {
        shutdown(fd, SHUT_WR);
        linger_add(n, fd);
    }
    nc->refused = true;
    pthread_mutex_lock(&n->mu);
    nc->cut = true;
    n->cuts[status == 413 ? CUT_MAX_UPLOAD : CUT_MALFORMED]++;
    pthread_mutex_unlock(&n->mu);
    svc_log(SVC_LOG_INFO, -1, "http: request from %s refused (%d): %s; connection closed", nc->ip, status, why);
}

/* DESIGN: libmicrohttpd 0.9.75 queues no response while a body is arriving
 * (MHD_queue_response accepts one only right after the headers or after the
 * whole request), so an upload that passes max_upload would be read to its
 * end, however long, before it could be answered.  Instead the guard
 * answers 413 itself and MHD_NO makes libmicrohttpd close its descriptor.
 * (A chunked upload is mostly refused earlier, at the chunk size that
 * passes max_upload: svc_wire.) */
enum MHD_Result http_guard_cut_oversize(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    http_count_rejected(d);
    char msg[160];
    snprintf(msg, sizeof msg, "the upload is over the limit of %ld bytes (max_upload)", d->cfg.max_upload);
    net_conn *nc = http_guard_conn(c);
    if (nc && !nc->refused)
        conn_answer(nc, 413, msg);
    q->up.too_large = true;
    return MHD_NO;
}

/* svc_http_recv.c's two questions (svc_http_recv.h) */
bool http_recv_refused(int fd)
{
    net_conn *nc = fd >= 0 && fd < WIRE_FDS ? atomic_load(&wire_fd[fd]) : NULL;
    return nc && nc->refused;
}

/* The refusal waits while libmicrohttpd is on an earlier request of the
 * connection (pipelined) or writing a response. */
static bool act_on_refusal(net_conn *nc)
{
    if (nc->refused || !nc->w.status)
        return !nc->refused;
    if (nc->w.requests != nc->done || nc->answering) {
        nc->pending = true;
        return true;
    }
    if (nc->w.status == 413)
        http_count_rejected(nc->net->d);
    conn_answer(nc, nc->w.status, nc->w.why);
    return false;
}

bool http_recv_seen(int fd, const void *buf, size_t n)
{
    net_conn *nc = fd >= 0 && fd < WIRE_FDS ? atomic_load(&wire_fd[fd]) : NULL;
    if (!nc || nc->refused)
        return true;
    if (!nc->w.status)
        svc_wire_feed(&nc->w, buf, n);
    return act_on_refusal(nc);
}

void http_guard_answering(struct MHD_Connection *c)
{
    net_conn *nc = http_guard_conn(c);
    if (nc)
        nc->answering = true;
}

void http_guard_completed(struct MHD_Connection *c)
{
    net_conn *nc = http_guard_conn(c);
    if (!nc)
        return;
    nc->done++;
    nc->answering = false;
    if (nc->pending)
        act_on_refusal(nc);
}

bool http_guard_refused(struct MHD_Connection *c)
{
    net_conn *nc = http_guard_conn(c);
    return nc && nc->refused;
}

static void linger_end(svc_net *n, net_linger *l)
{
    epoll_ctl(n->linger_ep, EPOLL_CTL_DEL, l->fd, NULL);
    close(l->fd);
    if (l->prev)
        l->prev->next = l->next;
    else
        n->lingers = l->next;
    if (l->next)
        l->next->prev = l->prev;
    n->lingering--;
    free(l);
}

/* Reads what refused clients still send, and closes each when it stops,
 * or at its deadline. */
static void *lingerer(void *arg)
{
    svc_net *n = arg;
    enum { SINK = 64 * 1024 };
    char *sink = malloc(SINK); /* what is read is thrown away */
    struct epoll_event ev[64];
    pthread_mutex_lock(&n->mu);
    while (!n->stop) {
        pthread_mutex_unlock(&n->mu);
        int k = epoll_wait(n->linger_ep, ev, 64, 250);
        pthread_mutex_lock(&n->mu);
        double t = now_s();
        for (int i = 0; i < k; i++) {
            net_linger *l = ev[i].data.ptr;
            /* a bounded read per wake: a fast sender must neither pass
             * LINGER_BYTES inside this loop nor starve the others (the
             * epoll is level-triggered: what is left wakes it again) */
            ssize_t r = -1;
            uint64_t woke = l->bytes;
            while (sink && l->bytes <= LINGER_BYTES && l->bytes - woke < (1u << 20) &&
                   (r = read(l->fd, sink, SINK)) > 0)
                l->bytes += (uint64_t)r;
            l->last = t;
            if (r == 0 || (r < 0 && errno != EAGAIN && errno != EWOULDBLOCK) || l->bytes > LINGER_BYTES)
                linger_end(n, l);
        }
        for (net_linger *l = n->lingers, *next; l; l = next) {
            next = l->next;
            if (t - l->start > LINGER_TIME || t - l->last > LINGER_IDLE)
                linger_end(n, l);
        }
    }
    while (n->lingers)
        linger_end(n, n->lingers);
    pthread_mutex_unlock(&n->mu);
    free(sink);
    return NULL;
}

/* The connections the fd limit allows: the soft RLIMIT_NOFILE is raised
 * toward the hard one; what is still short lowers the limit, with a word. */
unsigned http_guard_connection_limit(const svc_config *cfg)
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

svc_net *http_guard_new(svc_daemon *d)
{
    svc_net *n = calloc(1, sizeof *n);
    if (!n)
        return NULL;
    n->d = d;
    n->linger_ep = -1;
    pthread_mutex_init(&n->mu, NULL);
    pthread_condattr_t ca;
    pthread_condattr_init(&ca);
    pthread_cond_init(&n->wake, &ca);
    pthread_condattr_destroy(&ca);
    if (d->cfg.allowed_hosts[0])
        snprintf(n->hosts, sizeof n->hosts, "%s", d->cfg.allowed_hosts);
    else
        http_gate_default_hosts(n);
    return n;
}

void http_guard_free(svc_net *n)
{
    if (!n)
        return;
    pthread_mutex_lock(&n->mu);
    n->stop = true;
    pthread_cond_signal(&n->wake);
    pthread_mutex_unlock(&n->mu);
    if (n->reaper_started)
        pthread_join(n->reaper, NULL);
    if (n->linger_started)
        pthread_join(n->linger_thread, NULL);
    if (n->linger_ep >= 0)
        close(n->linger_ep);
    pthread_cond_destroy(&n->wake);
    pthread_mutex_destroy(&n->mu);
    free(n);
}

bool http_guard_start(svc_net *n)
{
    n->reaper_started = pthread_create(&n->reaper, NULL, reaper, n) == 0;
    if (!http_recv_hooked())
        svc_log(SVC_LOG_WARN, -1, "http: the raw request bytes are not checked (recv() is not this program's: "
                                  "a static link?); libmicrohttpd's own checks apply");
    if ((n->linger_ep = epoll_create1(EPOLL_CLOEXEC)) >= 0)
        n->linger_started = pthread_create(&n->linger_thread, NULL, lingerer, n) == 0;
    if (!n->linger_started && n->linger_ep >= 0) {
        close(n->linger_ep);
        n->linger_ep = -1;
    }
    if (!n->linger_started)
        svc_log(SVC_LOG_WARN, -1, "http: no lingering close: refused connections close at once");
    return n->reaper_started;
}

#endif
