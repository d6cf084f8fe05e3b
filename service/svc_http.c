/* svc_http: the HTTP API and dashboard of `ringside serve` (libmicrohttpd):
 * the request's phases and the server's lifecycle.
 *
 * DESIGN: libmicrohttpd runs a small pool of threads and calls on_request
 * several times for one request: once with the headers, once per piece of
 * body, once at the end.  Every request passes the same phases in order
 * (svc_http_local.h lists the file of each): at the first call the route
 * is looked up in the one route table, then the gate checks the request's
 * form and auth who asks; a route that takes a body (an upload) is let in
 * within max_upload and upload_memory; at the last call the route's
 * handler answers.  A phase that refuses answers at once and the rest is
 * skipped.  Uploads are read into memory up to max_upload (a 20-minute
 * match is a few tens of KiB) and checked by the replay parser before the
 * job is committed; the job id goes back only after the commit. */
#define _GNU_SOURCE /* strcasestr */
#include <netdb.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>

#include "svc_local.h"

#if defined(RS_HAVE_MHD)
#include "svc_http_local.h"
#include "svc_log.h"

/* libmicrohttpd's multipart parser hands each piece of a form field here. */
static enum MHD_Result form_field(void *cls, enum MHD_ValueKind kind, const char *key, const char *filename,
                                  const char *content_type, const char *transfer_encoding, const char *data,
                                  uint64_t off, size_t size)
{
    (void)kind, (void)content_type, (void)transfer_encoding;
    req *q = cls;
    return svc_upload_field(&q->up, key, filename, data, off, size) ? MHD_YES : MHD_NO;
}

/* What a route that takes a body needs before the body comes: a daemon
 * taking jobs, a declared length within max_upload, room in upload_memory,
 * and a parser for a multipart form. */
static enum MHD_Result admit_body(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    pthread_mutex_lock(&d->mu);
    bool draining = d->draining;
    pthread_mutex_unlock(&d->mu);
    q->done = true;
    if (draining)
        return http_error(c, SVC_ERR_DRAINING, NULL, NULL, "the daemon is shutting down: not accepting jobs");
    const char *cl = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Content-Length");
    if (cl && strtoull(cl, NULL, 10) > (unsigned long long)d->cfg.max_upload) {
        http_count_rejected(d);
        return http_error(c, SVC_ERR_TOO_LARGE, NULL, "upload refused",
                          "the upload (%s bytes) is over the limit of %ld bytes (max_upload)", cl, d->cfg.max_upload);
    }
    long want = cl ? (long)strtoull(cl, NULL, 10)
                   : MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Transfer-Encoding") ? d->cfg.max_upload : 0;
    if (want > 0 && !http_guard_reserve(d->net, q, want))
        return http_error(c, SVC_ERR_BUSY, &(http_header){"Retry-After", "5"}, "request refused",
                          "uploads in progress hold upload_memory (%ld bytes): try again in a few seconds",
                          d->cfg.upload_memory);
    q->done = false;
    const char *ct = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Content-Type");
    if (ct && strcasestr(ct, "multipart/form-data")) {
        q->pp = MHD_create_post_processor(c, 32 * 1024, form_field, q);
        if (!q->pp)
            q->up.bad = "malformed multipart/form-data request (no boundary?)";
    }
    return MHD_YES;
}

/* The first call, headers only: the route, the gate, auth, and a body's admission. */
static enum MHD_Result begin(svc_daemon *d, struct MHD_Connection *c, req *q, const char *url, const char *method)
{
    q->started = true;
    http_guard_phase(d->net, c, NET_BODY);
    svc_route_match(url, method, &q->m);
    enum MHD_Result refused;
    /* the request's form first (Host, Origin, strict HTTP), then who asks */
    if (!http_gate(d, c, q, url, method, &refused) || !http_auth(d, c, q, &refused)) {
        q->done = true;
        return refused;
    }
    if (q->m.route && q->m.route->body)
        return admit_body(d, c, q);
    return MHD_YES; /* answered at the last call, once any body is read */
}

/* A piece of body.  libmicrohttpd takes no answer while a body is still
 * arriving: a malformed one is remembered and answered at the end. */
static enum MHD_Result body(svc_daemon *d, struct MHD_Connection *c, req *q, const char *data, size_t *n)
{
    q->received += *n;
    if (q->received > (uint64_t)d->cfg.max_upload)
        return http_guard_cut_oversize(d, c, q);
    http_guard_body(d->net, c, *n);
    if (!q->done && q->m.route && q->m.route->body) { /* a body nobody asked for is ignored */
        if (!q->pp)
            svc_upload_append(&q->up, data, *n);
        else if (!q->up.bad && MHD_post_process(q->pp, data, *n) != MHD_YES && !q->up.oom && !q->up.too_large)
            q->up.bad = "malformed multipart/form-data body";
    }
    *n = 0;
    return MHD_YES;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *c, const char *url, const char *method,
                                  const char *version, const char *upload, size_t *upload_size, void **con_cls)
{
    (void)version;
    svc_daemon *d = cls;
    req *q = *con_cls; /* made by http_gate_uri */
    if (!q || http_guard_refused(c)) /* the guard answered its raw bytes (svc_wire) */
        return MHD_NO;
    if (!q->started)
        return begin(d, c, q, url, method);
    if (*upload_size)
        return body(d, c, q, upload, upload_size);
    if (q->done)
        return MHD_YES;
    q->done = true;
    http_guard_phase(d->net, c, NET_ANSWER);
    return svc_route_dispatch(d, c, q, url, method);
}

static void on_completed(void *cls, struct MHD_Connection *c, void **con_cls, enum MHD_RequestTerminationCode toe)
{
    (void)toe;
    svc_daemon *d = cls;
    http_guard_phase(d->net, c, NET_HEADERS); /* a keep-alive connection's next request */
    http_guard_completed(c);
    req *q = *con_cls;
    if (!q)
        return;
    http_guard_release(d->net, q);
    if (q->pp)
        MHD_destroy_post_processor(q->pp);
    svc_upload_free(&q->up);
    free(q);
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
    if (!(d->net = http_guard_new(d))) {
        freeaddrinfo(ai);
        rs_fail(err, SVC_ERR_NOMEM, "out of memory starting the HTTP server");
        return NULL;
    }
    /* epoll: no FD_SETSIZE limit, and thousands of idle connections cost
     * nothing per wake-up; each of the pool's threads has its own */
    unsigned flags = MHD_USE_EPOLL_INTERNAL_THREAD | MHD_USE_ERROR_LOG | MHD_ALLOW_SUSPEND_RESUME;
    if (ai->ai_family == AF_INET6)
        flags |= MHD_USE_IPv6;
    /* strict: HTTP/1.1 without Host and spaces in the request line are
     * answered 400 by libmicrohttpd itself */
    struct MHD_Daemon *mhd = MHD_start_daemon(
        flags, 0, NULL, NULL, on_request, d, MHD_OPTION_EXTERNAL_LOGGER, on_mhd_log, d, MHD_OPTION_SOCK_ADDR,
        ai->ai_addr, MHD_OPTION_THREAD_POOL_SIZE, 4u, MHD_OPTION_NOTIFY_COMPLETED, on_completed, d,
        MHD_OPTION_NOTIFY_CONNECTION, http_guard_notify, d->net, MHD_OPTION_URI_LOG_CALLBACK, http_gate_uri, d,
        MHD_OPTION_STRICT_FOR_CLIENT, 1, MHD_OPTION_CONNECTION_TIMEOUT, 60u, MHD_OPTION_CONNECTION_LIMIT,
        http_guard_connection_limit(&d->cfg), MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)d->cfg.max_connections_per_ip,
        MHD_OPTION_END);
    freeaddrinfo(ai);
    if (!mhd) {
        http_guard_free(d->net);
        d->net = NULL;
        rs_fail(err, SVC_ERR_LISTEN, "cannot listen on %s (in use, or not an address of this machine?)", d->cfg.listen);
        return NULL;
    }
    if (!http_events_start(d))
        svc_log(SVC_LOG_WARN, -1, "no event thread: GET /jobs/events answers 503");
    if (!http_guard_start(d->net))
        svc_log(SVC_LOG_WARN, -1, "no connection reaper thread: header_timeout and min_body_rate are not enforced");
    const union MHD_DaemonInfo *info = MHD_get_daemon_info(mhd, MHD_DAEMON_INFO_BIND_PORT);
    d->port = info ? info->port : 0;
    return mhd;
}

void svc_http_stop(svc_daemon *d, struct MHD_Daemon *h)
{
    http_events_end(d); /* a suspended connection would keep libmicrohttpd from stopping */
    if (h)
        MHD_stop_daemon(h); /* reports every connection closed first */
    http_events_free(d);
    http_guard_free(d->net);
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
