/* libFuzzer target for the HTTP layer's own parsers of request text
 * (service/svc_http_*.c, svc_auth.c, svc_json.c): `make fuzz` builds it,
 * seeds in tests/fuzz/http/.  The first byte picks the parser, the rest
 * (up to a NUL) is its text:
 *   0 Range     svc_parse_range against a file length (the next byte: 0..255,
 *               or with bit 3 of the first byte 8 bytes of any length),
 *               compared with a second, plainly written reading of RFC 9110's
 *               one-range grammar: the verdict and the range must agree;
 *   1 Bearer    svc_bearer: the token is what follows "Bearer" and blanks,
 *               without blanks at its ends, inside the header;
 *   2 Host      http_host_part into a buffer of the next byte's size: a lower
 *               case copy of the host, inside the buffer;
 *   3 lists     http_in_list (query parameter and CORS origin lists), list
 *               and name cut at the first newline, against a second reading;
 *   4 routes    svc_route_match and http_parse_id (the path's job id, ?limit=,
 *               ?before=): a matched route takes the method, an id is 1..18
 *               digits and its value;
 *   5 URI       http_uri_bad against a second reading: a control character,
 *               raw or %-encoded;
 *   6 JSON      svc_json_str (file names and messages from clients): valid
 *               JSON whose string is the input, each byte that is not well
 *               formed UTF-8 read as U+FFFD;
 *   7 listen    svc_listen_is_loopback: a numeric address it calls loopback is
 *               in 127.0.0.0/8 (what the daemon then binds). */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <ctype.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "../service/svc_http_local.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* digits only, value <= UINT64_MAX: the length, or -1 */
static int digits(const char *s, const char **end, uint64_t *v)
{
    const char *p = s;
    uint64_t x = 0;
    bool over = false;
    for (; *p >= '0' && *p <= '9'; p++) {
        unsigned d = (unsigned)(*p - '0');
        over |= x > (UINT64_MAX - d) / 10;
        x = x * 10 + d;
    }
    *end = p;
    *v = x;
    return p == s ? 0 : over ? -1 : (int)(p - s);
}

/* bytes=A-B, bytes=A-, bytes=-N; 1, 0 (ignored) or -1 (unsatisfiable) as svc_local.h says */
static int range_again(const char *h, uint64_t len, uint64_t *first, uint64_t *last)
{
    if (strncmp(h, "bytes=", 6) != 0 || strchr(h, ','))
        return 0;
    const char *p = h + 6, *e;
    uint64_t a, b;
    if (*p == '-') {
        if (digits(p + 1, &e, &a) <= 0 || *e)
            return 0;
        if (a == 0 || len == 0)
            return -1;
        *first = a >= len ? 0 : len - a;
        *last = len - 1;
        return 1;
    }
    if (digits(p, &e, &a) <= 0 || *e != '-')
        return 0;
    p = e + 1;
    b = UINT64_MAX;
    if (*p && (digits(p, &e, &b) <= 0 || *e || b < a))
        return 0;
    if (a >= len)
        return -1;
    *first = a;
    *last = b >= len ? len - 1 : b;
    return 1;
}

static void range(const char *h, uint64_t len)
{
    uint64_t f1 = 7, l1 = 7, f2 = 7, l2 = 7;
    int r1 = svc_parse_range(h, len, &f1, &l1), r2 = range_again(h, len, &f2, &l2);
    if (r1 != r2 || f1 != f2 || l1 != l2 || (r1 == 1 && !(f1 <= l1 && l1 < len)))
        abort();
}

static bool blank(char c)
{
    return c == ' ' || c == '\t';
}

static void bearer(const char *h)
{
    size_t n = 99;
    const char *tok = svc_bearer(h, &n), *end = h + strlen(h);
    if (!tok)
        return;
    const char *p = h;
    while (blank(*p))
        p++;
    bool ok = !strncasecmp(p, "bearer", 6) && blank(p[6]) && tok > p + 6 && tok <= end && n <= (size_t)(end - tok);
    for (const char *q = p + 6; ok && q < tok; q++)
        ok = blank(*q);
    ok = ok && (n == 0 || (!blank(tok[0]) && !blank(tok[n - 1])));
    for (const char *q = tok + n; ok && q < end; q++)
        ok = blank(*q);
    if (!ok)
        abort();
}

static void host(const char *in, size_t len, size_t room)
{
    char *out = malloc(room); /* exactly room bytes: writing past them is an ASan report */
    if (http_host_part(in, len, out, room)) {
        size_t k = strnlen(out, room);
        const char *from = len && in[0] == '[' ? in + 1 : in;
        if (k >= room)
            abort();
        for (size_t i = 0; i < k; i++)
            if (out[i] != (char)tolower((unsigned char)from[i]))
                abort();
    }
    free(out);
}

static void list(const char *text)
{
    const char *nl = strchr(text, '\n');
    if (!nl)
        return;
    char *items = strndup(text, (size_t)(nl - text)), *whole = strdup(items);
    const char *name = nl + 1;
    bool want = false;
    for (char *save = NULL, *item = strtok_r(items, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
        while (*item == ' ')
            item++;
        size_t k = strlen(item);
        while (k && item[k - 1] == ' ')
            k--;
        want |= k && k == strlen(name) && !strncasecmp(item, name, k);
    }
    if (http_in_list(whole, name) != want)
        abort();
    free(items);
    free(whole);
}

static void route(const char *text, uint8_t which)
{
    static const char *const methods[] = {"GET", "HEAD", "POST", "DELETE", "PUT", "OPTIONS", "get", ""};
    const char *method = methods[which % 8];
    svc_match m;
    svc_route_match(text, method, &m);
    if (m.route && (!m.known || (strcmp(m.route->method, method) && !(!strcmp(method, "HEAD") &&
                                                                         !strcmp(m.route->method, "GET")))))
        abort();
    if (m.known != (m.methods[0] != 0) || (m.route && strstr(m.route->path, ":id") && m.id <= 0))
        abort();
    int64_t id = -1;
    size_t n = strlen(text);
    if (http_parse_id(text, n, &id)) {
        int64_t v = 0;
        for (size_t i = 0; i < n; i++)
            v = v * 10 + (text[i] - '0');
        if (n < 1 || n > 18 || strspn(text, "0123456789") != n || v != id || id <= 0)
            abort();
    }
}

static void uri(const char *u)
{
    bool want = false;
    for (const char *p = u; *p; p++) {
        unsigned c = (unsigned char)*p;
        if (c == '%' && isxdigit((unsigned char)p[1]) && isxdigit((unsigned char)p[2])) {
            char hex[3] = {p[1], p[2], 0};
            unsigned v = (unsigned)strtoul(hex, NULL, 16);
            want |= v < 0x20 || v == 0x7f; /* p[1], p[2] are checked in their own turn */
        }
        want |= c < 0x20 || c == 0x7f;
    }
    if (http_uri_bad(u) != want)
        abort();
}

/* Code point of a well-formed UTF-8 sequence at s (its length in *n), or -1. */
static long utf8_at(const unsigned char *s, int *n)
{
    int len = s[0] < 0x80 ? 1 : (s[0] & 0xe0) == 0xc0 ? 2 : (s[0] & 0xf0) == 0xe0 ? 3 : (s[0] & 0xf8) == 0xf0 ? 4 : 0;
    if (!len)
        return -1;
    long cp = len == 1 ? s[0] : s[0] & (0x7f >> len);
    for (int i = 1; i < len; i++) {
        if ((s[i] & 0xc0) != 0x80)
            return -1;
        cp = cp << 6 | (s[i] & 0x3f);
    }
    static const long min[] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < min[len] || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff))
        return -1;
    *n = len;
    return cp;
}

static void put_utf8(char *out, size_t *o, long cp)
{
    if (cp < 0x80) {
        out[(*o)++] = (char)cp;
    } else if (cp < 0x800) {
        out[(*o)++] = (char)(0xc0 | cp >> 6);
        out[(*o)++] = (char)(0x80 | (cp & 0x3f));
    } else if (cp < 0x10000) {
        out[(*o)++] = (char)(0xe0 | cp >> 12);
        out[(*o)++] = (char)(0x80 | (cp >> 6 & 0x3f));
        out[(*o)++] = (char)(0x80 | (cp & 0x3f));
    } else {
        out[(*o)++] = (char)(0xf0 | cp >> 18);
        out[(*o)++] = (char)(0x80 | (cp >> 12 & 0x3f));
        out[(*o)++] = (char)(0x80 | (cp >> 6 & 0x3f));
        out[(*o)++] = (char)(0x80 | (cp & 0x3f));
    }
}

static void json(const char *s)
{
    size_t len = strlen(s), o = 0;
    char *want = malloc(3 * len + 1), *got = malloc(3 * len + 1);
    for (const unsigned char *p = (const unsigned char *)s; *p;) {
        int n = 1;
        long cp = utf8_at(p, &n);
        put_utf8(want, &o, cp < 0 ? 0xfffd : cp);
        p += n;
    }
    svc_buf b = {0};
    svc_json_str(&b, s);
    /* decode it as a strict JSON parser would: one string and nothing after it */
    const unsigned char *p = (const unsigned char *)b.p, *end = p + b.len;
    size_t g = 0;
    bool ok = !b.oom && b.len >= 2 && *p++ == '"';
    while (ok && p < end && *p != '"') {
        int n = 1;
        long cp;
        if (*p == '\\') {
            const char *esc = strchr("\"\\/bfnrt", p[1]);
            if (p + 1 < end && p[1] && esc) {
                put_utf8(got, &g, "\"\\/\b\f\n\r\t"[esc - "\"\\/bfnrt"]);
                p += 2;
                continue;
            }
            ok = p + 5 < end && p[1] == 'u' && isxdigit(p[2]) && isxdigit(p[3]) && isxdigit(p[4]) && isxdigit(p[5]);
            if (ok) {
                char hex[5] = {(char)p[2], (char)p[3], (char)p[4], (char)p[5], 0};
                cp = strtol(hex, NULL, 16);
                ok = cp < 0xd800 || cp > 0xdfff; /* the writer never needs a surrogate pair */
                put_utf8(got, &g, cp);
                p += 6;
            }
        } else {
            cp = utf8_at(p, &n);
            ok = cp >= 0x20 && p + n <= end;
            if (ok)
                put_utf8(got, &g, cp);
            p += n;
        }
    }
    ok = ok && p + 1 == end && *p == '"';
    if (!ok || g != o || memcmp(got, want, o) != 0)
        abort();
    svc_buf_free(&b);
    free(want);
    free(got);
}

static void listen_addr(const char *listen)
{
    if (!svc_listen_is_loopback(listen))
        return;
    char host[128];
    snprintf(host, sizeof host, "%s", listen);
    char *colon = strrchr(host, ':');
    if (colon)
        *colon = 0;
    struct in_addr a;
    if (strcasecmp(host, "localhost") && strcmp(host, "::1") && strcmp(host, "[::1]") && inet_aton(host, &a) &&
        (ntohl(a.s_addr) >> 24) != 127)
        abort(); /* a numeric address called loopback that is not */
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    uint8_t which = data[0];
    data++, size--;
    uint64_t len = 0;
    size_t head = which % 8 == 0 ? (which & 8 ? 8 : 1) : which % 8 == 2 || which % 8 == 4 ? 1 : 0;
    if (size < head)
        return 0;
    for (size_t i = 0; i < head; i++)
        len = len << 8 | data[i];
    data += head, size -= head;
    char *text = malloc(size + 1); /* the text as the parsers get it: a C string from libmicrohttpd */
    memcpy(text, data, size);
    text[size] = 0;
    switch (which % 8) {
    case 0: range(text, len); break;
    case 1: bearer(text); break;
    case 2: host(text, size, 1 + (size_t)len); break;
    case 3: list(text); break;
    case 4: route(text, (uint8_t)len); break;
    case 5: uri(text); break;
    case 6: json(text); break;
    case 7: listen_addr(text); break;
    }
    free(text);
    return 0;
}
