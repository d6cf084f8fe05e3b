/* svc_auth: API tokens (svc_auth.h), and `ringside serve token` (svc.h).
 *
 * DESIGN: a token is 32 bytes from getrandom(2), shown once as text; the
 * queue keeps only SHA-256 of that text, so a copy of the database lets
 * nobody in.  A plain unsalted hash is enough here: the secret has 256
 * bits of entropy, nothing to guess from a list.  SHA-256 is our own
 * (below, checked against FIPS 180-4's examples in tests/test_svc.c): the
 * binary links no crypto library, and one is not worth adding for 80
 * lines. */
#define _DEFAULT_SOURCE /* getrandom */
#include <arpa/inet.h>
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <stdlib.h>
#include <sys/random.h>
#include <time.h>

#include "svc.h"
#include "svc_auth.h"
#include "svc_local.h"
#include "svc_store.h"
#include "../runtime/util/rs_file.h"

/* --- SHA-256 --- */

static const uint32_t K[64] = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2,
};

static uint32_t ror(uint32_t x, int n)
{
    return x >> n | x << (32 - n);
}

/* One 64-byte block into the state h. */
static void sha256_block(uint32_t h[8], const uint8_t *p)
{
    uint32_t w[64], v[8];
    for (int i = 0; i < 16; i++)
        w[i] = (uint32_t)p[4 * i] << 24 | (uint32_t)p[4 * i + 1] << 16 | (uint32_t)p[4 * i + 2] << 8 | p[4 * i + 3];
    for (int i = 16; i < 64; i++) {
        uint32_t s0 = ror(w[i - 15], 7) ^ ror(w[i - 15], 18) ^ w[i - 15] >> 3;
        uint32_t s1 = ror(w[i - 2], 17) ^ ror(w[i - 2], 19) ^ w[i - 2] >> 10;
        w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    memcpy(v, h, sizeof v);
    for (int i = 0; i < 64; i++) {
        uint32_t t1 = v[7] + (ror(v[4], 6) ^ ror(v[4], 11) ^ ror(v[4], 25)) + ((v[4] & v[5]) ^ (~v[4] & v[6])) + K[i] + w[i];
        uint32_t t2 = (ror(v[0], 2) ^ ror(v[0], 13) ^ ror(v[0], 22)) + ((v[0] & v[1]) ^ (v[0] & v[2]) ^ (v[1] & v[2]));
        memmove(v + 1, v, 7 * sizeof v[0]);
        v[4] += t1;
        v[0] = t1 + t2;
    }
    for (int i = 0; i < 8; i++)
        h[i] += v[i];
}

void svc_sha256(const void *data, size_t n, uint8_t out[32])
{
    uint32_t h[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
    const uint8_t *p = data;
    size_t left = n;
    for (; left >= 64; p += 64, left -= 64)
        sha256_block(h, p);
    /* the tail, 0x80, zeros, and the length in bits (big-endian) */
    uint8_t last[128] = {0};
    memcpy(last, p, left);
    last[left] = 0x80;
    size_t blocks = left + 9 > 64 ? 2 : 1;
    uint64_t bits = (uint64_t)n * 8;
    for (int i = 0; i < 8; i++)
        last[blocks * 64 - 1 - i] = (uint8_t)(bits >> (8 * i));
    for (size_t b = 0; b < blocks; b++)
        sha256_block(h, last + 64 * b);
    for (int i = 0; i < 8; i++)
        for (int k = 0; k < 4; k++)
            out[4 * i + k] = (uint8_t)(h[i] >> (24 - 8 * k));
}

/* --- tokens --- */

bool svc_token_make(char *out, rs_err *err)
{
    static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
    uint8_t r[33] = {0}; /* 32 random bytes; the 33rd pads the last group */
    size_t got = 0;
    while (got < 32) {
        ssize_t n = getrandom(r + got, 32 - got, 0);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return rs_fail(err, SVC_ERR_SYSTEM, "cannot make a token: getrandom: %s", strerror(errno));
        got += (size_t)n;
    }
    size_t k = strlen(SVC_TOKEN_PREFIX);
    memcpy(out, SVC_TOKEN_PREFIX, k);
    for (int i = 0; i < 33; i += 3) {
        uint32_t v = (uint32_t)r[i] << 16 | (uint32_t)r[i + 1] << 8 | r[i + 2];
        for (int s = 18; s >= 0 && k < SVC_TOKEN_LEN; s -= 6)
            out[k++] = b64[v >> s & 63];
    }
    out[k] = 0;
    return true;
}

void svc_token_hash(const char *token, char hex[SVC_TOKEN_HASH_LEN])
{
    uint8_t h[32];
    svc_sha256(token, strlen(token), h);
    for (int i = 0; i < 32; i++)
        snprintf(hex + 2 * i, 3, "%02x", h[i]);
}

const char *svc_bearer(const char *authorization, size_t *len)
{
    if (!authorization)
        return NULL;
    const char *p = authorization;
    while (*p == ' ' || *p == '\t')
        p++;
    if (strncasecmp(p, "Bearer", 6) != 0 || (p[6] != ' ' && p[6] != '\t'))
        return NULL;
    p += 6;
    while (*p == ' ' || *p == '\t')
        p++;
    size_t n = strlen(p);
    while (n && (p[n - 1] == ' ' || p[n - 1] == '\t'))
        n--;
    *len = n;
    return p;
}

bool svc_listen_is_loopback(const char *listen)
{
    char host[128];
    snprintf(host, sizeof host, "%s", listen);
    char *colon = strrchr(host, ':');
    if (colon)
        *colon = 0;
    if (!strcmp(host, "[::1]") || !strcmp(host, "::1") || !strcasecmp(host, "localhost"))
        return true;
    /* 127.0.0.0/8, as four plain decimal numbers (inet_pton's form): the
     * daemon binds with getaddrinfo, which reads "0127.0.0.1" as octal, so
     * 87.0.0.1; anything but the plain form is not taken for loopback */
    struct in_addr a;
    return inet_pton(AF_INET, host, &a) == 1 && (ntohl(a.s_addr) >> 24) == 127;
}

/* --- `ringside serve token` --- */

/* The queue of cfg, made if it is new (a token may come before the first
 * start).  An SQLite queue is not locked: WAL lets this run beside its
 * daemon. */
static svc_store *open_queue(const svc_config *cfg, rs_err *err)
{
    bool pg = !strncmp(cfg->queue, "postgres://", 11) || !strncmp(cfg->queue, "postgresql://", 13);
    const char *db = !strncmp(cfg->queue, "sqlite:", 7) ? cfg->queue + 7 : cfg->queue;
    if (!pg && *db && !rs_mkdirs_for(db, err))
        return NULL;
    return svc_store_open(cfg->queue, cfg->lease, err);
}

/* Names people read in logs and lists: 1..64 of letters, digits, . _ - @,
 * not all digits (revoke takes an id too). */
static bool name_ok(const char *name, rs_err *err)
{
    size_t n = strlen(name);
    bool digits = true;
    for (const char *p = name; *p; p++) {
        if (!isalnum((unsigned char)*p) && !strchr("._-@", *p))
            return rs_fail(err, SVC_TOKEN_USAGE, "name '%s': use letters, digits and . _ - @ only", name);
        digits = digits && isdigit((unsigned char)*p);
    }
    if (n == 0 || n > 64)
        return rs_fail(err, SVC_TOKEN_USAGE, "name '%s': 1 to 64 characters", name);
    if (digits)
        return rs_fail(err, SVC_TOKEN_USAGE, "name '%s': not only digits (revoke takes an id as well as a name)", name);
    return true;
}

bool svc_token_add(const svc_config *cfg, const char *name, bool is_operator, int max_queued, int seconds_per_hour,
                   rs_err *err)
{
    if (!name_ok(name, err))
        return false;
    char token[SVC_TOKEN_LEN + 1], hash[SVC_TOKEN_HASH_LEN];
    if (!svc_token_make(token, err))
        return false;
    svc_token_hash(token, hash);
    svc_store *s = open_queue(cfg, err);
    if (!s)
        return false;
    svc_token t = {.is_operator = is_operator, .max_queued = max_queued, .seconds_per_hour = seconds_per_hour};
    snprintf(t.name, sizeof t.name, "%s", name);
    int r = s->ops->token_add(s, &t, hash, err);
    s->ops->close(s);
    if (r == 0)
        return rs_fail(err, SVC_ERR_TOKEN_EXISTS, "a token named '%s' exists already (revoked ones keep their names)", name);
    if (r < 0)
        return false;
    printf("%s\n", token);
    fflush(stdout);
    fprintf(stderr, "ringside serve token: added token %lld '%s'%s; it is shown this once and cannot be shown again\n",
            (long long)t.id, name, is_operator ? " (operator)" : "");
    return true;
}

static void put_time(char *out, size_t n, int64_t t)
{
    time_t tt = (time_t)t;
    struct tm tm;
    if (t == 0 || !gmtime_r(&tt, &tm) || !strftime(out, n, "%Y-%m-%dT%H:%MZ", &tm))
        snprintf(out, n, "-");
}

bool svc_token_list(const svc_config *cfg, rs_err *err)
{
    svc_store *s = open_queue(cfg, err);
    if (!s)
        return false;
    enum { MAX = 10000 };
    svc_token *t = calloc(MAX, sizeof *t);
    int n = t ? s->ops->token_list(s, t, MAX, err) : -1;
    s->ops->close(s);
    if (!t)
        return rs_fail(err, SVC_ERR_NOMEM, "out of memory");
    if (n < 0) {
        free(t);
        return false;
    }
    printf("%-5s %-24s %-8s %-10s %-8s %-17s %-17s %s\n", "ID", "NAME", "OPERATOR", "MAX_QUEUED", "SEC/HOUR", "CREATED",
           "REVOKED", "LAST_USED");
    for (int i = 0; i < n; i++) {
        char created[32], revoked[32], used[32];
        put_time(created, sizeof created, t[i].created);
        put_time(revoked, sizeof revoked, t[i].revoked);
        put_time(used, sizeof used, t[i].last_used);
        printf("%-5lld %-24s %-8s %-10d %-8d %-17s %-17s %s\n", (long long)t[i].id, t[i].name,
               t[i].is_operator ? "yes" : "no", t[i].max_queued, t[i].seconds_per_hour, created, revoked, used);
    }
    free(t);
    return true;
}

bool svc_token_revoke(const svc_config *cfg, const char *which, rs_err *err)
{
    svc_store *s = open_queue(cfg, err);
    if (!s)
        return false;
    svc_token t;
    int r = s->ops->token_revoke(s, which, &t, err);
    s->ops->close(s);
    if (r < 0)
        return false;
    if (r == 0)
        return rs_fail(err, SVC_ERR_TOKEN_UNKNOWN, "no token named '%s' or with that id ('ringside serve token list' shows them)", which);
    fprintf(stderr, "ringside serve token: token %lld '%s' %s\n", (long long)t.id, t.name,
            r == 2 ? "was revoked already" : "revoked: it stops working at its next request");
    return true;
}
