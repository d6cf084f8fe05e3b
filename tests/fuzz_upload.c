/* libFuzzer target for an upload's way to a job (POST /jobs): the query
 * string and the multipart form as libmicrohttpd parses them, the pieces
 * of each field as svc_upload.c puts them together, and the job
 * svc_upload_job makes of the parameters and the replay.  `make fuzz`
 * builds it; seeds in tests/fuzz/upload/.
 *
 * An input is "QUERY\nCONTENT-TYPE\nBODY" (CR, LF and NUL left out of the
 * first two).  It goes as one POST /jobs?QUERY request over a socketpair
 * to a libmicrohttpd daemon in this process (no listening socket, run from
 * this thread), whose handler does what svc_http.c's does: a multipart
 * body through a post processor into svc_upload_field, any other body
 * whole, then http_upload_query and svc_upload_job.  The body also goes to
 * a second post processor in pieces of 1 to 64 bytes (the body's first
 * byte picks the size), as a connection's bytes may arrive: the upload it
 * makes must be the same.  A job made must be within the settings' bounds
 * (size, format, length) with a safe file name; a refusal must carry one
 * of the service's or the replay's error ids. */
#define _GNU_SOURCE
#include <netinet/in.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "../runtime/replay/rp.h"
#include "../service/svc_http_local.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct one {
    const uint8_t *body;
    size_t len, piece;
    bool started, finished;
    struct MHD_PostProcessor *pp[2];
    svc_upload up[2]; /* [0]: the body as libmicrohttpd hands it over; [1]: in pieces */
} one;

static svc_config cfg;
static struct MHD_Daemon *mhd;
static one *current; /* the input's request: one at a time, on this thread */

static enum MHD_Result field(void *cls, enum MHD_ValueKind kind, const char *key, const char *filename,
                             const char *content_type, const char *transfer_encoding, const char *data, uint64_t off,
                             size_t size)
{
    (void)kind, (void)content_type, (void)transfer_encoding;
    return svc_upload_field(cls, key, filename, data, off, size) ? MHD_YES : MHD_NO;
}

static void feed(one *o, int k, const char *data, size_t n)
{
    svc_upload *u = &o->up[k];
    if (!o->pp[k])
        svc_upload_append(u, data, n);
    else if (!u->bad && MHD_post_process(o->pp[k], data, n) != MHD_YES && !u->oom && !u->too_large)
        u->bad = "malformed multipart/form-data body";
}

static bool same_upload(const svc_upload *a, const svc_upload *b)
{
    bool same = a->len == b->len && (!a->len || !memcmp(a->body, b->body, a->len)) && a->too_large == b->too_large &&
                !a->bad == !b->bad && !strcmp(a->name, b->name);
#define X(name, room) same = same && !strcmp(a->p.name, b->p.name);
    SVC_JOB_PARAMS(X)
#undef X
    return same;
}

static void check_job(svc_upload *u)
{
    svc_job j;
    rs_err err = {0};
    if (!svc_upload_job(&cfg, u, &j, &err)) {
        rs_err_module m = RS_ERR_MODULE(err.code);
        if (!err.msg[0] || (m != RS_ERR_MOD_SVC && m != RS_ERR_MOD_RP && m != RS_ERR_MOD_CAP))
            abort();
        return;
    }
    bool ok = j.width >= 16 && j.height >= 16 && j.width <= cfg.max_width && j.height <= cfg.max_height &&
              !((j.width | j.height) & 1) &&
              (!strcmp(j.format, "mp4") || !strcmp(j.format, "webm") || !strcmp(j.format, "mkv")) &&
              j.frames_total >= 1 && j.frames_total <= (int64_t)cfg.max_seconds * 60 && j.replay == u->body &&
              j.replay_len == u->len && j.name[0] && !strchr(j.name, '/') && strlen(j.encode) < sizeof j.encode;
    for (const char *p = j.name; ok && *p; p++)
        ok = (unsigned char)*p >= 0x20 && *p != 0x7f;
    if (!ok)
        abort();
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *c, const char *url, const char *method,
                                  const char *version, const char *upload, size_t *upload_size, void **con_cls)
{
    (void)cls, (void)url, (void)method, (void)version;
    one *o = current;
    if (!o->started) { /* the headers: a post processor per upload for a form, as admit_body makes it */
        o->started = true;
        *con_cls = o;
        const char *ct = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Content-Type");
        for (int k = 0; k < 2; k++) {
            o->up[k].limit = cfg.max_upload;
            if (ct && strcasestr(ct, "multipart/form-data")) {
                o->pp[k] = MHD_create_post_processor(c, 32 * 1024, field, &o->up[k]);
                if (!o->pp[k])
                    o->up[k].bad = "malformed multipart/form-data request (no boundary?)";
            }
        }
        /* the second upload gets the whole body now, in pieces */
        for (size_t i = 0; i < o->len; i += o->piece)
            feed(o, 1, (const char *)o->body + i, o->len - i < o->piece ? o->len - i : o->piece);
        return MHD_YES;
    }
    if (*upload_size) {
        feed(o, 0, upload, *upload_size);
        *upload_size = 0;
        return MHD_YES;
    }
    if (o->finished)
        return MHD_YES;
    o->finished = true;
    rs_err e0 = {0}, e1 = {0};
    bool q0 = http_upload_query(c, &o->up[0], &e0), q1 = http_upload_query(c, &o->up[1], &e1);
    if (q0 != q1 || !same_upload(&o->up[0], &o->up[1]))
        abort(); /* the pieces a body arrives in changed what was uploaded */
    if (q0 && !o->up[0].bad && !o->up[0].too_large && !o->up[0].oom)
        check_job(&o->up[0]);
    struct MHD_Response *r = MHD_create_response_from_buffer(0, "", MHD_RESPMEM_PERSISTENT);
    enum MHD_Result ret = MHD_queue_response(c, 200, r);
    MHD_destroy_response(r);
    return ret;
}

/* The header text from the input: no CR, LF or NUL (they would make another request). */
static size_t header_text(const uint8_t *p, size_t n, char *out, size_t room)
{
    size_t k = 0;
    for (size_t i = 0; i < n && k + 1 < room; i++)
        if (p[i] != '\r' && p[i] != '\n' && p[i] != 0)
            out[k++] = (char)p[i];
    out[k] = 0;
    return k;
}

static void request(one *o, const char *query, const char *type)
{
    int sv[2];
    if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) != 0)
        abort();
    size_t cap = 1024 + strlen(query) + strlen(type) + o->len;
    char *text = malloc(cap);
    size_t n = (size_t)snprintf(text, cap,
                                "POST /jobs%s%s HTTP/1.1\r\nHost: localhost\r\nContent-Type: %s\r\n"
                                "Content-Length: %zu\r\nConnection: close\r\n\r\n",
                                query[0] ? "?" : "", query, type, o->len);
    memcpy(text + n, o->body, o->len);
    n += o->len;
    struct sockaddr_in peer = {.sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    if (MHD_add_connection(mhd, sv[1], (struct sockaddr *)&peer, sizeof peer) != MHD_YES)
        abort();
    size_t sent = 0;
    char sink[4096];
    /* libmicrohttpd reads, answers and closes its end; this end writes the
     * request as it is taken and drains the answer until then */
    for (int round = 0; round < 100000; round++) {
        if (sent < n) {
            ssize_t w = send(sv[0], text + sent, n - sent, MSG_DONTWAIT | MSG_NOSIGNAL);
            sent += w > 0 ? (size_t)w : 0;
            if (sent == n)
                shutdown(sv[0], SHUT_WR);
        }
        MHD_run(mhd);
        ssize_t r = recv(sv[0], sink, sizeof sink, MSG_DONTWAIT);
        if (r == 0)
            break; /* closed: the request is over */
    }
    close(sv[0]);
    free(text);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!mhd) {
        svc_config_defaults(&cfg);
        mhd = MHD_start_daemon(MHD_USE_NO_LISTEN_SOCKET, 0, NULL, NULL, on_request, NULL, MHD_OPTION_END);
        if (!mhd)
            abort();
    }
    const uint8_t *nl1 = memchr(data, '\n', size), *nl2 = nl1 ? memchr(nl1 + 1, '\n', size - (size_t)(nl1 + 1 - data)) : NULL;
    if (!nl2)
        return 0;
    char query[1024], type[512];
    header_text(data, (size_t)(nl1 - data), query, sizeof query);
    header_text(nl1 + 1, (size_t)(nl2 - nl1 - 1), type, sizeof type);
    one o = {.body = nl2 + 1, .len = size - (size_t)(nl2 + 1 - data)};
    o.piece = 1 + (o.len ? o.body[0] % 64 : 0);
    current = &o;
    request(&o, query, type);
    current = NULL;
    for (int k = 0; k < 2; k++) {
        if (o.pp[k])
            MHD_destroy_post_processor(o.pp[k]);
        svc_upload_free(&o.up[k]);
    }
    return 0;
}
