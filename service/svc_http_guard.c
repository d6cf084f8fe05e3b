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
 * fd that has been reused. */
#include <inttypes.h>
#include <netdb.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <time.h>

#if defined(RS_HAVE_MHD)
#include "svc_http_local.h"
#include "svc_log.h"

static const char *const cut_name[NET_NCUTS] = {"header_timeout", "min_body_rate", "max_upload"};

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

void http_guard_metrics(svc_net *n, svc_buf *b)
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

/* DESIGN: libmicrohttpd 0.9.75 queues no response while a body is arriving
 * (MHD_queue_response accepts one only right after the headers or after the
 * whole request), so an upload that passes max_upload would be read to its
 * end, however long, before it could be answered.  Instead the 413 is
 * written to the socket here, whole, with Connection: close, and MHD_NO
 * makes libmicrohttpd close the connection: nothing more is read. */
enum MHD_Result http_guard_cut_oversize(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    http_count_rejected(d);
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
    net_conn *nc = http_guard_conn(c);
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
    q->up.too_large = true;
    return MHD_NO;
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

bool http_guard_start(svc_net *n)
{
    n->reaper_started = pthread_create(&n->reaper, NULL, reaper, n) == 0;
    return n->reaper_started;
}

#endif
