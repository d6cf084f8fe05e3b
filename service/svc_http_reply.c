/* svc_http_reply: every answer of the HTTP layer leaves through here (the
 * CORS headers of its connection added), the one error answer, files with
 * Range; and the one place where an error id becomes an HTTP status. */
#include <ctype.h>
#include <errno.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "svc_local.h"

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

/* "bytes=A-B", "bytes=A-", "bytes=-N" (RFC 9110, one range only). */
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
#include "svc_http_local.h"
#include "svc_log.h"

enum MHD_Result http_queue(struct MHD_Connection *c, unsigned status, struct MHD_Response *r)
{
    net_conn *nc = http_guard_conn(c);
    if (nc && nc->cors[0]) {
        MHD_add_response_header(r, "Access-Control-Allow-Origin", nc->cors);
        MHD_add_response_header(r, "Access-Control-Expose-Headers", "Location, Retry-After");
    }
    if (nc && nc->vary)
        MHD_add_response_header(r, "Vary", "Origin");
    enum MHD_Result ret = MHD_queue_response(c, status, r);
    if (ret == MHD_YES)
        http_guard_answering(c);
    return ret;
}

/* A body answer, never cached; h one more header (NULL: none). */
static enum MHD_Result send_body(struct MHD_Connection *c, unsigned status, const char *type, const char *body,
                                 size_t n, const http_header *h)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(n, (void *)body, MHD_RESPMEM_MUST_COPY);
    if (!r)
        return MHD_NO;
    MHD_add_response_header(r, "Content-Type", type);
    MHD_add_response_header(r, "Cache-Control", "no-store");
    if (h)
        MHD_add_response_header(r, h->name, h->value);
    enum MHD_Result ret = http_queue(c, status, r);
    MHD_destroy_response(r);
    return ret;
}

enum MHD_Result http_reply(struct MHD_Connection *c, unsigned status, const char *type, const char *body, size_t n)
{
    return send_body(c, status, type, body, n, NULL);
}

enum MHD_Result http_reply_json(struct MHD_Connection *c, unsigned status, svc_buf *b)
{
    enum MHD_Result r = b->oom ? MHD_NO : http_reply(c, status, "application/json", b->p ? b->p : "", b->len);
    svc_buf_free(b);
    return r;
}

enum MHD_Result http_error(struct MHD_Connection *c, int id, const http_header *h, const char *log, const char *fmt,
                           ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    unsigned status = svc_http_status(id);
    if (log)
        svc_log(SVC_LOG_INFO, -1, "%s (%u): %s", log, status, msg);
    svc_buf b = {0};
    svc_json_error(&b, msg);
    enum MHD_Result r = b.oom ? MHD_NO : send_body(c, status, "application/json", b.p, b.len, h);
    svc_buf_free(&b);
    return r;
}

enum MHD_Result http_store_error(struct MHD_Connection *c, const rs_err *err)
{
    return http_error(c, err->code, NULL, NULL, "the queue is unavailable: %s", err->msg);
}

enum MHD_Result http_preflight(struct MHD_Connection *c)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(0, "", MHD_RESPMEM_PERSISTENT);
    if (!r)
        return MHD_NO;
    MHD_add_response_header(r, "Access-Control-Allow-Methods", "GET, POST, DELETE");
    MHD_add_response_header(r, "Access-Control-Allow-Headers", "Authorization, Content-Type");
    MHD_add_response_header(r, "Access-Control-Max-Age", "600");
    enum MHD_Result ret = http_queue(c, 204, r);
    MHD_destroy_response(r);
    return ret;
}

/* 416 with the size the range missed. */
static enum MHD_Result unsatisfiable(struct MHD_Connection *c, uint64_t len)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(0, "", MHD_RESPMEM_PERSISTENT);
    if (!r)
        return MHD_NO;
    char cr[64];
    snprintf(cr, sizeof cr, "bytes */%" PRIu64, len);
    MHD_add_response_header(r, "Content-Range", cr);
    enum MHD_Result ret = http_queue(c, svc_http_status(SVC_ERR_RANGE), r);
    MHD_destroy_response(r);
    return ret;
}

enum MHD_Result http_send_file(struct MHD_Connection *c, int fd, uint64_t len, const http_file *f)
{
    uint64_t first = 0, last = len ? len - 1 : 0;
    int rr = f->range ? svc_parse_range(f->range, len, &first, &last) : 0;
    if (rr < 0) {
        close(fd);
        return unsatisfiable(c, len);
    }
    uint64_t n = rr > 0 ? last - first + 1 : len;
    struct MHD_Response *r = MHD_create_response_from_fd_at_offset64(n, fd, rr > 0 ? first : 0);
    if (!r) {
        close(fd);
        return MHD_NO;
    }
    MHD_add_response_header(r, "Content-Type", f->type);
    if (f->cache)
        MHD_add_response_header(r, "Cache-Control", f->cache);
    if (f->ranges)
        MHD_add_response_header(r, "Accept-Ranges", "bytes");
    if (f->disposition)
        MHD_add_response_header(r, "Content-Disposition", f->disposition);
    if (rr > 0) {
        char cr[96];
        snprintf(cr, sizeof cr, "bytes %" PRIu64 "-%" PRIu64 "/%" PRIu64, first, last, len);
        MHD_add_response_header(r, "Content-Range", cr);
    }
    enum MHD_Result ret = http_queue(c, rr > 0 ? 206 : 200, r);
    MHD_destroy_response(r);
    return ret;
}

#endif
