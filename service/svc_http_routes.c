/* svc_http_routes: the one route table of the HTTP API.  Routing, the
 * routes open without a token (the auth phase) and the query parameters a
 * route takes (the gate) all read it; to add a route, add its row and
 * write its handler (docs/architecture.md, "The service's HTTP layer"). */
#include <ctype.h>
#include <stdio.h>
#include <string.h>

#include "svc.h"

#if defined(RS_HAVE_MHD)
#include "svc_http_local.h"

/* The methods, the paths and what each takes; the order of rows is the
 * order of the "expected GET or POST" lists of a 405. */
static const svc_route routes[] = {
    /* method   path                 handler         open   body   query parameters */
    {"GET",    "/",                  http_dashboard, true,  false, ""},
    {"GET",    "/index.html",        http_dashboard, true,  false, ""},
    {"GET",    "/healthz",           http_health,    true,  false, ""},
    {"GET",    "/hls.js",            http_hls_js,    true,  false, ""},
    {"GET",    "/metrics",           http_metrics,   false, false, ""},
    {"GET",    "/jobs",              http_list,      false, false, "limit,before"},
    {"POST",   "/jobs",              http_submit,    false, true,  SVC_JOB_PARAM_LIST},
    {"GET",    "/jobs/events",       http_events,    false, false, "limit,before"},
    {"GET",    "/jobs/:id",          http_job,       false, false, ""},
    {"DELETE", "/jobs/:id",          http_cancel,    false, false, ""},
    {"GET",    "/jobs/:id/video",    http_video,     false, false, ""},
    {"GET",    "/jobs/:id/hashes",   http_hashes,    false, false, ""},
    {"GET",    "/jobs/:id/poster",   http_poster,    false, false, ""},
    {"GET",    "/jobs/:id/log",      http_log,       false, false, ""},
    {"GET",    "/jobs/:id/stream.m3u8", http_stream, false, false, ""},
    {"GET",    "/jobs/:id/stream/:ts", http_piece,   false, false, ""},
    {"POST",   "/jobs/:id/retry",    http_retry,     false, false, ""},
};

bool http_parse_id(const char *s, size_t n, int64_t *id)
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

/* A path other rows' paths go on from ("/jobs" of "/jobs/:id"). */
static bool collection(const char *path)
{
    size_t n = strlen(path);
    for (size_t i = 0; i < sizeof routes / sizeof *routes; i++)
        if (n > 1 && !strncmp(routes[i].path, path, n) && routes[i].path[n] == '/')
            return true;
    return false;
}

/* "TICK.ts": a stream piece's name, TICK 1 to 12 digits, no leading zero */
static bool parse_piece(const char *s, size_t n, int64_t *tick)
{
    size_t d = 0;
    int64_t v = 0;
    while (d < n && d < 13 && isdigit((unsigned char)s[d]))
        v = v * 10 + (s[d++] - '0');
    if (d == 0 || d > 12 || (s[0] == '0' && d > 1) || n != d + 3 || strncmp(s + d, ".ts", 3) != 0)
        return false;
    *tick = v;
    return true;
}

/* Whether url is pattern: segment by segment, ":id" a job id (*bad_id when
 * everything else fits but it is not one), ":ts" a piece's name (*tick).
 * A collection also answers with one trailing slash ("/jobs/"). */
static bool path_is(const char *pattern, const char *url, int64_t *id, int64_t *tick, bool *bad_id)
{
    const char *p = pattern, *u = url;
    bool id_ok = true;
    while (*p && *u) {
        if (!strncmp(p, ":id", 3)) {
            size_t n = strcspn(u, "/");
            id_ok = http_parse_id(u, n, id);
            p += 3, u += n;
        } else if (!strncmp(p, ":ts", 3)) {
            size_t n = strcspn(u, "/");
            if (!parse_piece(u, n, tick))
                return false;
            p += 3, u += n;
        } else if (*p++ != *u++)
            return false;
    }
    bool fits = !*p && (!*u || (!strcmp(u, "/") && collection(pattern)));
    if (fits && !id_ok)
        *bad_id = true;
    return fits && id_ok;
}

static bool method_is(const char *row, const char *method)
{
    return !strcmp(row, method) || (!strcmp(row, "GET") && !strcmp(method, "HEAD"));
}

void svc_route_match(const char *url, const char *method, svc_match *m)
{
    *m = (svc_match){0};
    for (size_t i = 0; i < sizeof routes / sizeof *routes; i++) {
        int64_t id = 0, tick = -1;
        if (!path_is(routes[i].path, url, &id, &tick, &m->bad_id))
            continue;
        m->tick = tick;
        size_t k = strlen(m->methods);
        snprintf(m->methods + k, sizeof m->methods - k, "%s%s", k ? " or " : "", routes[i].method);
        m->known = true;
        m->open |= routes[i].open;
        m->id = id;
        if (!m->route && method_is(routes[i].method, method))
            m->route = &routes[i];
    }
}

enum MHD_Result svc_route_dispatch(svc_daemon *d, struct MHD_Connection *c, req *q, const char *url,
                                   const char *method)
{
    const svc_match *m = &q->m;
    if (m->route)
        return m->route->fn(d, c, q);
    if (m->known)
        return http_error(c, SVC_ERR_METHOD, NULL, NULL, "%s %s: %s %s", method, url,
                          strchr(m->methods, ' ') ? "expected" : "only", m->methods);
    if (m->bad_id)
        return http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL, "%s: not a job id", url);
    return http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL, "%s: no such resource (see /jobs, /healthz, /metrics)", url);
}

bool svc_routes_print(FILE *out)
{
    fprintf(out, "%-7s %-22s %-6s %-5s %s\n", "METHOD", "PATH", "TOKEN", "BODY", "QUERY");
    for (size_t i = 0; i < sizeof routes / sizeof *routes; i++)
        fprintf(out, "%-7s %-22s %-6s %-5s %s\n", routes[i].method, routes[i].path, routes[i].open ? "no" : "yes",
                routes[i].body ? "yes" : "no", routes[i].params[0] ? routes[i].params : "-");
    return true;
}

#else

bool svc_routes_print(FILE *out)
{
    (void)out;
    return false;
}

#endif
