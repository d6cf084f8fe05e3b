/* svc_http_local.h: what the files of the HTTP layer share.  Private to
 * them (the rest of service/ sees svc_http_start/stop in svc_local.h).
 *
 * Before libmicrohttpd parses a byte, the guard checks it (svc_http_recv.c
 * hands it over, svc_wire.c is the grammar) and answers a refusal itself.
 * A request then passes fixed phases, in this order (svc_http.c runs them):
 *   1. gate      svc_http_gate.c   the request's form: control characters,
 *                                  header syntax, Host, transfer coding,
 *                                  Origin (CORS), the query parameters its
 *                                  route takes;
 *   2. auth      svc_http_auth.c   who asks: the token, unless the route is open;
 *   3. body      svc_upload.c      a route that takes a body reads it within
 *                                  the upload budget of the connection guard
 *                                  (svc_http_guard.c);
 *   4. dispatch  svc_http_routes.c the route table's handler
 *                                  (svc_http_jobs.c, svc_http_ops.c).
 * Every answer leaves through svc_http_reply.c.  docs/architecture.md,
 * "The service's HTTP layer", draws it and adds a route step by step. */
#ifndef SVC_HTTP_LOCAL_H
#define SVC_HTTP_LOCAL_H

#include <microhttpd.h>

#include "svc_auth.h"
#include "svc_json.h"
#include "svc_local.h"
#include "svc_upload.h"
#include "svc_wire.h"

typedef struct req req;
typedef enum MHD_Result (*svc_handler)(svc_daemon *d, struct MHD_Connection *c, req *q);

/* --- the route table (svc_http_routes.c) --- */

typedef struct svc_route {
    const char *method; /* a GET route answers HEAD too */
    const char *path;   /* a ":id" segment matches a job id, given to the handler in q->m.id */
    svc_handler fn;
    bool open;          /* answered without a token (docs/service.md, "Tokens") */
    bool body;          /* reads a request body (an upload) within the upload budget */
    const char *params; /* the query parameters it takes, comma-separated ("": none) */
} svc_route;

/* What the table says of one method and path. */
typedef struct svc_match {
    const svc_route *route; /* the row of this method and path; NULL: none */
    bool known;             /* some row has this path (a wrong method is 405, not 404) */
    bool open;              /* the path's rows are open */
    bool bad_id;            /* its ":id" segment is no job id */
    int64_t id;
    int64_t tick;           /* a ":ts" segment's tick ("120" of "120.ts"); -1: none */
    char methods[48];       /* the path's methods, "GET" or "GET or DELETE" */
} svc_match;

/* A job id: 1 to 18 digits, not 0. */
bool http_parse_id(const char *s, size_t n, int64_t *id);
void svc_route_match(const char *url, const char *method, svc_match *m);
/* Runs the matched route's handler, or answers 404 / 405. */
enum MHD_Result svc_route_dispatch(svc_daemon *d, struct MHD_Connection *c, req *q, const char *url,
                                   const char *method);

/* --- one request, from its first call to on_completed (svc_http.c) --- */

struct req {
    svc_daemon *d;
    bool bad_uri;      /* a control character in the raw path or query (the gate refuses it) */
    bool started;      /* the first call (headers only) is over */
    bool done;         /* answered before its body was read (refused, 413, 503) */
    svc_match m;       /* its route */
    uint64_t received; /* body bytes read */
    long reserved;     /* bytes of upload_memory held for it */
    struct MHD_PostProcessor *pp;
    svc_upload up;     /* the body of a route that takes one */
    svc_token tok;     /* who asks: tok.id 0 without a token */
    bool all;          /* sees every job: an operator token, or loopback with no tokens */
};

/* --- replies (svc_http_reply.c): every answer leaves through here --- */

typedef struct http_header {
    const char *name, *value;
} http_header;

/* Queues r with the CORS headers of the request's connection. */
enum MHD_Result http_queue(struct MHD_Connection *c, unsigned status, struct MHD_Response *r);
enum MHD_Result http_reply(struct MHD_Connection *c, unsigned status, const char *type, const char *body, size_t n);
/* b as application/json, freed. */
enum MHD_Result http_reply_json(struct MHD_Connection *c, unsigned status, svc_buf *b);
/* The one error answer: {"error": message}, the status of id's row of
 * SVC_ERRORS (svc_http_status), h one more header (NULL: none).  log, when
 * not NULL, names the refusal in the daemon's log: "LOG (STATUS): message". */
enum MHD_Result http_error(struct MHD_Connection *c, int id, const http_header *h, const char *log, const char *fmt,
                           ...) RS_PRINTF(5, 6);
/* "the queue is unavailable: ..." for a failed store call (503). */
enum MHD_Result http_store_error(struct MHD_Connection *c, const rs_err *err);
/* The CORS preflight of a listed origin. */
enum MHD_Result http_preflight(struct MHD_Connection *c);

typedef struct http_file {
    const char *type;
    const char *range;       /* the request's Range header (NULL: send it all) */
    const char *disposition; /* Content-Disposition (NULL: none) */
    const char *cache;       /* Cache-Control (NULL: none) */
    bool ranges;             /* Accept-Ranges: bytes */
} http_file;
/* Sends len bytes of fd (taken over: closed when sent, or now on failure),
 * 206 for a satisfiable Range, 416 for another. */
enum MHD_Result http_send_file(struct MHD_Connection *c, int fd, uint64_t len, const http_file *f);

/* --- the connection guard (svc_http_guard.c) --- */

enum { NET_HEADERS, NET_BODY, NET_ANSWER }; /* a connection's phase */
enum { CUT_HEADER_TIMEOUT, CUT_BODY_RATE, CUT_MAX_UPLOAD, CUT_MALFORMED, NET_NCUTS };

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
    struct svc_net *net;
    /* the raw bytes (svc_http_recv.c), checked by the MHD thread that reads them */
    svc_wire w;
    uint32_t done;  /* requests libmicrohttpd has finished on it (on_completed) */
    bool answering; /* a response is queued for the request in progress */
    bool pending;   /* w refused a request libmicrohttpd has not reached yet */
    bool refused;   /* answered by the guard: libmicrohttpd's reads fail, requests get MHD_NO */
} net_conn;

typedef struct net_linger net_linger;

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
    char hosts[1024];   /* accepted Host names, comma-separated, lower case (the gate's) */
    /* refused connections read to their end before they close (lingering) */
    int linger_ep;      /* epoll of their descriptors (-1: none) */
    net_linger *lingers;
    long lingering;
    uint64_t linger_full; /* closed at once: LINGER_MAX were lingering */
    pthread_t linger_thread;
    bool linger_started;
};

svc_net *http_guard_new(svc_daemon *d);
/* The reaper thread; false: none (deadlines not enforced). */
bool http_guard_start(svc_net *n);
void http_guard_free(svc_net *n);
/* libmicrohttpd's MHD_OPTION_NOTIFY_CONNECTION: records and forgets connections. */
void http_guard_notify(void *cls, struct MHD_Connection *c, void **socket_context,
                       enum MHD_ConnectionNotificationCode code);
/* The connection's record (NULL: not watched). */
net_conn *http_guard_conn(struct MHD_Connection *c);
/* A connection enters a phase: its deadline starts over. */
void http_guard_phase(svc_net *n, struct MHD_Connection *c, int phase);
/* Body bytes read: what min_body_rate is measured on. */
void http_guard_body(svc_net *n, struct MHD_Connection *c, size_t bytes);
/* An upload's room in upload_memory, before its body is read; released by on_completed. */
bool http_guard_reserve(svc_net *n, req *q, long bytes);
void http_guard_release(svc_net *n, req *q);
/* An upload past max_upload: a 413 written to the socket, the connection closed. */
enum MHD_Result http_guard_cut_oversize(svc_daemon *d, struct MHD_Connection *c, req *q);
/* A response is queued on c (http_queue); a request on c is finished (on_completed). */
void http_guard_answering(struct MHD_Connection *c);
void http_guard_completed(struct MHD_Connection *c);
/* Whether the guard has answered and refused c: every call on it is MHD_NO. */
bool http_guard_refused(struct MHD_Connection *c);
void http_guard_metrics(svc_net *n, svc_buf *b);
/* max_connections within the open-file limit (raised toward the hard one). */
unsigned http_guard_connection_limit(const svc_config *cfg);

/* --- phases (svc_http_gate.c, svc_http_auth.c) --- */

/* libmicrohttpd's URI log callback: makes the request's context (a req)
 * and notes control characters in the raw URI. */
void *http_gate_uri(void *cls, const char *uri, struct MHD_Connection *c);
/* The request's form: false with *ret the answer when it is refused. */
bool http_gate(svc_daemon *d, struct MHD_Connection *c, req *q, const char *url, const char *method,
               enum MHD_Result *ret);
/* The gate's parsers of request text (exposed for tests and fuzzing):
 * the host of a Host header or an allowed_hosts entry, lower case, without
 * its port or IPv6 brackets ("[::1]:8080" -> "::1"), false if empty or too
 * long; whether NAME is one of the comma-separated items of LIST (spaces
 * around items ignored, case-insensitive); whether a raw URI holds a
 * control character, raw or %-encoded. */
bool http_host_part(const char *in, size_t in_len, char *out, size_t n);
bool http_in_list(const char *list, const char *name);
bool http_uri_bad(const char *uri);
/* The Host names accepted when allowed_hosts is empty. */
void http_gate_default_hosts(svc_net *n);
/* Who asks: true to go on (q->tok, q->all say who); false answered (401, 503). */
bool http_auth(svc_daemon *d, struct MHD_Connection *c, req *q, enum MHD_Result *ret);

/* --- handlers (svc_http_jobs.c, svc_http_stream.c, svc_http_ops.c) --- */

/* The job of q->m.id as q may see it: false with the answer in *ret (503
 * when the queue is down, 404 for a missing job or another token's). */
bool http_job_visible(svc_daemon *d, struct MHD_Connection *c, const req *q, svc_job *j, enum MHD_Result *ret);

/* A page of the job list as GET /jobs answers it ({"jobs":[...],"next":...},
 * no newline) in b, job i's object at b.p[at[i]..at[i+1]-1] (id ids[i]);
 * token_id 0: every job. */
typedef struct http_jobs_page {
    svc_buf b;
    int n;
    int64_t *ids;
    size_t *at;
} http_jobs_page;
bool http_jobs_page_make(svc_daemon *d, int64_t token_id, int64_t before, long limit, http_jobs_page *p, rs_err *err);
void http_jobs_page_free(http_jobs_page *p);
/* ?limit= (1..500, else default_limit) and ?before= (a job id): false with the answer when one is malformed. */
bool http_list_params(struct MHD_Connection *c, long default_limit, long *limit, int64_t *before, enum MHD_Result *ret);

enum MHD_Result http_submit(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_list(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_job(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_cancel(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_video(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_hashes(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_poster(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_log(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_stream(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_piece(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_retry(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_health(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_metrics(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_dashboard(svc_daemon *d, struct MHD_Connection *c, req *q);
enum MHD_Result http_hls_js(svc_daemon *d, struct MHD_Connection *c, req *q);

/* --- the event stream (svc_http_events.c) --- */

/* GET /jobs/events: the jobs' changes as Server-Sent Events. */
enum MHD_Result http_events(svc_daemon *d, struct MHD_Connection *c, req *q);
/* Its thread; false: out of memory or no thread (the route answers 503). */
bool http_events_start(svc_daemon *d);
/* Ends every stream (resumed, so that libmicrohttpd can stop) and the
 * thread; http_events_free, after libmicrohttpd stopped, the memory. */
void http_events_end(svc_daemon *d);
void http_events_free(svc_daemon *d);
/* Something changed here (an upload, a cancel): the streams look now, not at their next tick. */
void http_events_poke(svc_daemon *d);
/* ringside_event_streams for /metrics. */
void http_events_metrics(svc_daemon *d, svc_buf *b);
/* An upload's job parameters the form left to the query string, and its
 * file name (the form's, else ?name=, else X-Filename); false
 * (SVC_ERR_BAD_PARAM) for a value longer than its room. */
bool http_upload_query(struct MHD_Connection *c, svc_upload *u, rs_err *err);
/* An upload refused: counted for /metrics (ringside_uploads_rejected_total). */
void http_count_rejected(svc_daemon *d);

#endif
