/* svc_auth: the API tokens of `ringside serve` (docs/service.md, "Tokens"):
 * making one, the hash that is all the queue keeps of it, reading one from
 * a request, and whether a listen address is loopback (which decides
 * whether a daemon without tokens may start at all).  Private to service/. */
#ifndef SVC_AUTH_H
#define SVC_AUTH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "../runtime/util/rs_err.h"

/* "rs_" and 43 base64url characters (32 random bytes), and the NUL. */
#define SVC_TOKEN_PREFIX "rs_"
#define SVC_TOKEN_LEN (3 + 43)
/* The hash as the queue stores it: 64 lowercase hex digits and the NUL. */
#define SVC_TOKEN_HASH_LEN 65

/* SHA-256 (FIPS 180-4) of n bytes. */
void svc_sha256(const void *data, size_t n, uint8_t out[32]);
/* A new token from getrandom(2) into out (SVC_TOKEN_LEN + 1 bytes). */
bool svc_token_make(char *out, rs_err *err);
/* hex SHA-256 of the token's text: what the queue looks it up by. */
void svc_token_hash(const char *token, char hex[SVC_TOKEN_HASH_LEN]);
/* The token of an Authorization header value ("Bearer TOKEN", the scheme
 * in any case, spaces around): a pointer into it and its length, or NULL
 * when the header is missing or names another scheme. */
const char *svc_bearer(const char *authorization, size_t *len);
/* true for 127.0.0.0/8 in plain dotted decimal, ::1, [::1] and localhost
 * (any port): the only addresses a daemon may listen on without a token. */
bool svc_listen_is_loopback(const char *listen);

#endif
