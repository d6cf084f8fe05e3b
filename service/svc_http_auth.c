/* svc_http_auth: the request phase that decides who asks. */
#include <string.h>

#if defined(RS_HAVE_MHD)
#include "svc_http_local.h"
#include "svc_log.h"

/* Who asks (docs/service.md, "Tokens").  Every route but the dashboard
 * and /healthz needs a valid token once any token exists or the daemon
 * listens beyond loopback (the route table's open column says which are
 * open).  Called at a request's first call, before any
 * body is read, so a refused upload costs no memory.  Nothing is cached:
 * the token is looked up on every request, so a revoked one stops working
 * at its next request.  true: go on (q->tok, q->all say who); false:
 * answered (401, 503), *ret what to return. */
bool http_auth(svc_daemon *d, struct MHD_Connection *c, req *q, enum MHD_Result *ret)
{
    if (q->m.open)
        return true;
    static const http_header bearer = {"WWW-Authenticate", "Bearer"},
                             invalid = {"WWW-Authenticate", "Bearer error=\"invalid_token\""};
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
        *ret = active < 0 ? http_store_error(c, &err)
                          : http_error(c, SVC_ERR_AUTH, &bearer, NULL,
                                       "this service needs an API token: send 'Authorization: Bearer TOKEN' "
                                       "('ringside serve token add NAME' makes one)");
        return false;
    }
    size_t n = 0;
    const char *tok = svc_bearer(h, &n);
    if (!tok || n == 0 || n > SVC_TOKEN_LEN) {
        *ret = http_error(c, SVC_ERR_AUTH, &invalid, NULL, "%s",
                          tok ? "not a token of this service" : "Authorization: expected 'Bearer TOKEN'");
        return false;
    }
    char text[SVC_TOKEN_LEN + 1], hash[SVC_TOKEN_HASH_LEN];
    memcpy(text, tok, n);
    text[n] = 0;
    svc_token_hash(text, hash);
    int r = d->http_store->ops->token_find(d->http_store, hash, &q->tok, &err);
    if (r < 0) {
        *ret = http_store_error(c, &err);
        return false;
    }
    if (r == 0 || q->tok.revoked) {
        bool revoked = r == 1;
        if (revoked)
            svc_log(SVC_LOG_INFO, -1, "refused a request with token '%s' (revoked)", q->tok.name);
        *ret = http_error(c, SVC_ERR_AUTH, &invalid, NULL, revoked ? "token '%s' was revoked" : "%sunknown token",
                          revoked ? q->tok.name : "");
        memset(&q->tok, 0, sizeof q->tok);
        return false;
    }
    q->done = false;
    q->all = q->tok.is_operator;
    return true;
}

#endif
