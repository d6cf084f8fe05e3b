/* svc_http_gate: what every request must pass before anyone asks who sent
 * it: no control characters in its path or query, header names without
 * whitespace, a Host this daemon serves, a transfer coding it understands,
 * an Origin allowed to change state (and CORS for listed ones), and only
 * the query parameters its route takes (the route table's params). */
#define _GNU_SOURCE
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#if defined(RS_HAVE_MHD)
#include "svc_http_local.h"

#define REFUSED "request refused" /* the log's word for a refusal here */

bool http_host_part(const char *in, size_t in_len, char *out, size_t n)
{
    const char *s = in;
    size_t len = in_len;
    if (len && *s == '[') {
        const char *e = memchr(s, ']', len);
        /* after the bracket only a port: "[::1].evil" is no IPv6 host */
        if (!e || (e + 1 < in + in_len && e[1] != ':'))
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

bool http_in_list(const char *list, const char *name)
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
void http_gate_default_hosts(svc_net *n)
{
    char lh[128] = "";
    const char *listen = n->d->cfg.listen, *colon = strrchr(listen, ':');
    http_host_part(listen, colon ? (size_t)(colon - listen) : strlen(listen), lh, sizeof lh);
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
    if (!http_host_part(host, strlen(host), h, sizeof h))
        return false;
    for (const char *p = n->hosts; *p;) { /* entries may carry ports or brackets too */
        while (*p == ' ' || *p == ',')
            p++;
        const char *e = p + strcspn(p, ",");
        char item[256];
        if (http_host_part(p, (size_t)(e - p), item, sizeof item) && !strcmp(item, h))
            return true;
        p = e;
    }
    return false;
}

static bool state_changing(const char *method)
{
    return !strcmp(method, "POST") || !strcmp(method, "DELETE") || !strcmp(method, "PUT") || !strcmp(method, "PATCH");
}

/* Query parameters not in allowed, noted as "a, b" for the refusal. */
typedef struct unknown_params {
    const char *allowed;
    char names[256];
} unknown_params;

static enum MHD_Result note_param(void *cls, enum MHD_ValueKind kind, const char *key, const char *value)
{
    (void)kind, (void)value;
    unknown_params *u = cls;
    if (http_in_list(u->allowed, key))
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

/* Origin: a state-changing request from a foreign page is refused; a listed
 * origin gets the CORS headers (noted on the connection for http_queue()). */
static bool gate_origin(svc_daemon *d, struct MHD_Connection *c, const char *method, enum MHD_Result *ret)
{
    net_conn *nc = http_guard_conn(c);
    if (nc) {
        nc->cors[0] = 0;
        nc->vary = d->cfg.cors_origins[0] != 0;
    }
    const char *origin = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Origin");
    if (!origin)
        return true;
    bool listed = http_in_list(d->cfg.cors_origins, origin);
    if (listed && nc)
        snprintf(nc->cors, sizeof nc->cors, "%s", origin);
    const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Host");
    bool own = host && !strncasecmp(origin, "http://", 7) && !strcasecmp(origin + 7, host);
    if (listed && !strcmp(method, "OPTIONS") &&
        MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Access-Control-Request-Method")) {
        *ret = http_preflight(c);
        return false;
    }
    if (state_changing(method) && !own && !listed) {
        *ret = http_error(c, SVC_ERR_ORIGIN, NULL, REFUSED,
                          "%s from Origin %s refused: not this server's own origin, nor one of cors_origins", method,
                          origin);
        return false;
    }
    return true;
}

/* The checks in order: false with *ret the answer when one refuses. */
bool http_gate(svc_daemon *d, struct MHD_Connection *c, req *q, const char *url, const char *method,
               enum MHD_Result *ret)
{
    if (q->bad_uri) {
        *ret = http_error(c, SVC_ERR_BAD_REQUEST, NULL, REFUSED,
                          "a control character (raw or %%-encoded) in the path or query");
        return false;
    }
    const char *spaced = NULL;
    MHD_get_connection_values(c, MHD_HEADER_KIND, note_spaced_name, &spaced);
    if (spaced) {
        *ret = http_error(c, SVC_ERR_BAD_REQUEST, NULL, REFUSED, "header '%.64s': whitespace before the colon", spaced);
        return false;
    }
    const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Host");
    if (host && !host_allowed(d->net, host)) {
        *ret = http_error(c, SVC_ERR_HOST, NULL, REFUSED,
                          "Host '%.200s' is not served here (see the allowed_hosts setting)", host);
        return false;
    }
    const char *te = MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Transfer-Encoding");
    if (te && strcasecmp(te, "chunked") && strcasecmp(te, "identity")) {
        *ret = http_error(c, SVC_ERR_CODING, NULL, REFUSED, "Transfer-Encoding '%.100s': only chunked is understood",
                          te);
        return false;
    }
    if (!gate_origin(d, c, method, ret))
        return false;
    unknown_params u = {.allowed = q->m.route ? q->m.route->params : ""};
    MHD_get_connection_values(c, MHD_GET_ARGUMENT_KIND, note_param, &u);
    if (u.names[0]) {
        *ret = http_error(c, SVC_ERR_BAD_PARAM, NULL, REFUSED, "unknown query parameter %s for %s %s (it takes: %s)",
                          u.names, method, url, u.allowed[0] ? u.allowed : "none");
        return false;
    }
    return true;
}

/* Runs before the URI is decoded: control characters, raw or %-encoded,
 * are noted here and refused by the gate.  Its answer is the request's
 * context (*con_cls of on_request). */
void *http_gate_uri(void *cls, const char *uri, struct MHD_Connection *c)
{
    (void)c;
    req *q = calloc(1, sizeof *q);
    if (!q)
        return NULL;
    q->d = cls;
    q->up.limit = q->d->cfg.max_upload;
    q->bad_uri = http_uri_bad(uri);
    return q;
}

bool http_uri_bad(const char *uri)
{
    bool bad = false;
    for (const unsigned char *p = (const unsigned char *)uri; *p; p++) {
        if (*p < 0x20 || *p == 0x7f)
            bad = true;
        if (*p == '%' && isxdigit(p[1]) && isxdigit(p[2])) {
            unsigned v = (unsigned)strtoul((char[]){(char)p[1], (char)p[2], 0}, NULL, 16);
            bad |= v < 0x20 || v == 0x7f;
        }
    }
    return bad;
}

#endif
