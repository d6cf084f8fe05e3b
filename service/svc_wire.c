/* svc_wire: the strict grammar of HTTP/1.1 request framing (RFC 9112),
 * checked byte by byte as a connection's bytes arrive (svc_wire.h).
 *
 * DESIGN: a state machine with no buffer beyond a few bytes of a header's
 * name and value, so any split of the same bytes gives the same verdict
 * and memory does not grow with the request.  Bodies are skipped by their
 * length; only the framing around them is read (chunk sizes, the CRLF after
 * each chunk, trailers).  What it refuses, and why it is not left to
 * libmicrohttpd 0.9.75 (docs/service.md, "Malformed requests"):
 *   - a raw control byte in the request line or a header: libmicrohttpd
 *     keeps a NUL in the target and the code after it reads up to the NUL,
 *     so "GET /jobs/1<NUL>/video" was served as "/jobs/1";
 *   - a target that is not a path or "*", a space inside it (libmicrohttpd's
 *     strict mode closes the connection without an answer), a version
 *     other than HTTP/1.0 and 1.1 (1.2 to 1.9 pass as 1.1 there: 505 here);
 *   - a line ending in a bare LF or CR, obsolete line folding, whitespace
 *     before a header's colon;
 *   - Content-Length that is not a number, two of them, or one beside
 *     Transfer-Encoding: chunked (a request-smuggling shape);
 *   - a Transfer-Encoding other than chunked (501, as the gate answers);
 *   - a chunk size that is not 1 to 16 hex digits (400) or that takes the
 *     body past max_body (413, as soon as its digits say so: libmicrohttpd
 *     waits for a 2^64-byte chunk until the connection's deadline). */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "svc_wire.h"

enum {
    W_START,    /* before a request line (empty lines allowed) */
    W_START_LF, /* an empty line's LF */
    W_METHOD,
    W_TARGET0, /* the target's first byte */
    W_TARGET,
    W_STAR, /* after a target of "*" */
    W_VERSION,
    W_RL_LF,   /* the request line's LF */
    W_HSTART,  /* a header line's first byte, or the head's end */
    W_HNAME,
    W_HVALUE,
    W_HVAL_LF,
    W_HEND_LF, /* the LF of the empty line that ends the head (or the trailers) */
    W_BODY,    /* Content-Length bytes */
    W_CSIZE,
    W_CEXT, /* a chunk extension, up to its CR */
    W_CSIZE_LF,
    W_CDATA,
    W_CDATA_CR,
    W_CDATA_LF,
    W_REFUSED,
};

enum { METHOD_MAX = 32 };

static bool is_ctl(unsigned b)
{
    return b < 0x20 || b == 0x7f;
}

/* RFC 9110 tchar */
static bool is_tchar(unsigned b)
{
    return (b >= 'a' && b <= 'z') || (b >= 'A' && b <= 'Z') || (b >= '0' && b <= '9') ||
           (b && strchr("!#$%&'*+-.^_`|~", (int)b));
}

static int hex_value(unsigned b)
{
    return b >= '0' && b <= '9' ? (int)(b - '0')
           : b >= 'a' && b <= 'f' ? (int)(b - 'a' + 10)
           : b >= 'A' && b <= 'F' ? (int)(b - 'A' + 10)
                                  : -1;
}

static void refuse(svc_wire *w, int status, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void refuse(svc_wire *w, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->why, sizeof w->why, fmt, ap);
    va_end(ap);
    w->status = status;
    w->st = W_REFUSED;
}

static void refuse_ctl(svc_wire *w, unsigned b, const char *where)
{
    if (b == '\n')
        refuse(w, 400, "a line ends in LF without CR (%s)", where);
    else if (b == '\r')
        refuse(w, 400, "a CR that does not end a line (%s)", where);
    else
        refuse(w, 400, "a raw control byte 0x%02x in %s", b, where);
}

void svc_wire_init(svc_wire *w, uint64_t max_body)
{
    memset(w, 0, sizeof *w);
    w->max_body = max_body;
}

const char *svc_wire_phrase(int status)
{
    switch (status) {
    case 400: return "Bad Request";
    case 413: return "Content Too Large";
    case 501: return "Not Implemented";
    case 505: return "HTTP Version Not Supported";
    default: return "Error";
    }
}

static void request_done(svc_wire *w)
{
    uint32_t n = w->requests + 1;
    uint64_t max = w->max_body;
    svc_wire_init(w, max);
    w->requests = n;
}

/* A header line is whole (name and value, the value's trailing whitespace
 * still counted in vlen). */
static void header_done(svc_wire *w)
{
    if (w->trailer)
        return; /* trailers do not frame anything */
    size_t n = w->vlen;
    if (n <= sizeof w->val)
        while (n && (w->val[n - 1] == ' ' || w->val[n - 1] == '\t'))
            n--;
    bool whole = n < sizeof w->val; /* the value fits (room for the message's NUL) */
    if (!strcmp(w->name, "content-length")) {
        uint64_t v = 0;
        bool ok = whole && n >= 1 && n <= 19;
        for (size_t i = 0; ok && i < n; i++) {
            ok = w->val[i] >= '0' && w->val[i] <= '9';
            v = v * 10 + (uint64_t)(w->val[i] - '0');
        }
        if (!ok)
            refuse(w, 400, "Content-Length '%.*s%s' is not a number of bytes", (int)(whole ? n : sizeof w->val - 1),
                   w->val, whole ? "" : "...");
        else if (w->has_cl)
            refuse(w, 400, "two Content-Length headers");
        w->has_cl = true;
        w->cl = v;
    } else if (!strcmp(w->name, "transfer-encoding")) {
        bool chunked = whole && n == 7 && !memcmp(w->val, "chunked", 7);
        if (w->chunked || w->te_other || !chunked) {
            w->te_other = true;
            if (!w->status)
                refuse(w, 501, "Transfer-Encoding '%.*s%s': only chunked is understood",
                       (int)(whole ? n : sizeof w->val - 1), w->val, whole ? "" : "...");
        }
        w->chunked = chunked;
    }
}

/* The empty line after the headers: how the body is framed. */
static void head_done(svc_wire *w)
{
    if (w->chunked && w->has_cl)
        refuse(w, 400, "both Content-Length and Transfer-Encoding: chunked");
    else if (w->chunked)
        w->st = W_CSIZE, w->num = 0, w->ndig = 0;
    else if (w->has_cl && w->cl > 0)
        w->st = W_BODY, w->left = w->cl;
    else
        request_done(w);
}

static const char *const NOT_A_REQUEST_LINE =
    "the request line is not METHOD TARGET HTTP/x.y (a space inside the target, or a malformed version)";

/* the request line, and the empty lines before it */
static void step_line(svc_wire *w, unsigned b)
{
    switch (w->st) {
    case W_START:
        if (b == '\r')
            w->st = W_START_LF;
        else if (is_tchar(b))
            w->st = W_METHOD, w->pos = 1;
        else if (is_ctl(b))
            refuse_ctl(w, b, "the request line");
        else
            refuse(w, 400, "the request line does not begin with a method");
        break;
    case W_START_LF:
        if (b == '\n')
            w->st = W_START; /* RFC 9112 2.2: an empty line before a request is ignored */
        else
            refuse_ctl(w, '\r', "an empty line before the request");
        break;
    case W_METHOD:
        if (b == ' ')
            w->st = W_TARGET0;
        else if (!is_tchar(b))
            is_ctl(b) ? refuse_ctl(w, b, "the request line") : refuse(w, 400, "the method is not a token");
        else if (++w->pos > METHOD_MAX)
            refuse(w, 400, "a method longer than %d bytes", METHOD_MAX);
        break;
    case W_TARGET0:
        if (b == '/')
            w->st = W_TARGET;
        else if (b == '*')
            w->st = W_STAR;
        else if (b == ' ')
            refuse(w, 400, "%s", NOT_A_REQUEST_LINE);
        else if (is_ctl(b))
            refuse_ctl(w, b, "the request target");
        else
            refuse(w, 400, "the request target is not a path beginning with / (origin form) or *");
        break;
    case W_TARGET:
        if (b == ' ')
            w->st = W_VERSION, w->pos = 0;
        else if (b == '\r' || b == '\n')
            refuse(w, 400, "the request line has no HTTP version");
        else if (is_ctl(b))
            refuse_ctl(w, b, "the request target");
        break;
    case W_STAR:
        if (b == ' ')
            w->st = W_VERSION, w->pos = 0;
        else
            refuse(w, 400, "the request target is not a path beginning with / (origin form) or *");
        break;
    case W_VERSION:
        if (w->pos == 8) {
            if (b != '\r')
                is_ctl(b) ? refuse_ctl(w, b, "the request line") : refuse(w, 400, "%s", NOT_A_REQUEST_LINE);
            else if (w->vers[5] != '1' || (w->vers[7] != '0' && w->vers[7] != '1'))
                refuse(w, 505, "HTTP/%c.%c is not supported: HTTP/1.1 and HTTP/1.0 are", w->vers[5], w->vers[7]);
            else
                w->st = W_RL_LF;
            break;
        }
        {
            int i = w->pos;
            bool ok = i < 5 ? b == (unsigned char)"HTTP/"[i] : i == 6 ? b == '.' : b >= '0' && b <= '9';
            if (!ok)
                is_ctl(b) && b != '\r' && b != '\n' ? refuse_ctl(w, b, "the request line")
                                                    : refuse(w, 400, "%s", NOT_A_REQUEST_LINE);
            w->vers[i] = (uint8_t)b;
            w->pos++;
        }
        break;
    case W_RL_LF:
        if (b == '\n')
            w->st = W_HSTART;
        else
            refuse_ctl(w, '\r', "the request line");
        break;
    default:
        break;
    }
}

/* header lines, and the trailer lines after the last chunk */
static void step_headers(svc_wire *w, unsigned b)
{
    switch (w->st) {
    case W_HSTART:
        if (b == '\r')
            w->st = W_HEND_LF;
        else if (b == ' ' || b == '\t')
            refuse(w, 400, "a header line begins with whitespace (obsolete line folding)");
        else if (b == ':')
            refuse(w, 400, "a header line with an empty name");
        else if (is_tchar(b)) {
            w->st = W_HNAME;
            w->name[0] = (char)(b >= 'A' && b <= 'Z' ? b + 32 : b);
            w->name[1] = 0;
            w->pos = 1;
        } else
            is_ctl(b) ? refuse_ctl(w, b, "a header") : refuse(w, 400, "a header name is not a token");
        break;
    case W_HNAME:
        if (b == ':') {
            w->st = W_HVALUE;
            w->vlen = 0;
        } else if (b == ' ' || b == '\t')
            refuse(w, 400, "whitespace between a header's name and its colon");
        else if (!is_tchar(b))
            is_ctl(b) ? refuse_ctl(w, b, "a header") : refuse(w, 400, "a header name is not a token");
        else if (w->pos < sizeof w->name - 1) {
            w->name[w->pos++] = (char)(b >= 'A' && b <= 'Z' ? b + 32 : b);
            w->name[w->pos] = 0;
        } else
            w->name[0] = '-'; /* too long to be a name this check reads */
        break;
    case W_HVALUE:
        if (b == '\r')
            w->st = W_HVAL_LF;
        else if (is_ctl(b) && b != '\t')
            refuse_ctl(w, b, "a header value");
        else if (w->vlen == 0 && (b == ' ' || b == '\t'))
            ; /* leading whitespace */
        else {
            if (w->vlen < sizeof w->val)
                w->val[w->vlen] = (char)(b >= 'A' && b <= 'Z' ? b + 32 : b);
            if (w->vlen < 255)
                w->vlen++;
        }
        break;
    case W_HVAL_LF:
        if (b != '\n')
            refuse_ctl(w, '\r', "a header value");
        else {
            w->st = W_HSTART;
            header_done(w);
        }
        break;
    case W_HEND_LF:
        if (b != '\n')
            refuse_ctl(w, '\r', "the end of the header lines");
        else if (w->trailer)
            request_done(w);
        else
            head_done(w);
        break;
    default:
        break;
    }
}

/* a chunked body's framing: sizes, extensions, the CRLF after the data */
static void step_chunks(svc_wire *w, unsigned b)
{
    switch (w->st) {
    case W_CSIZE: {
        int v = hex_value(b);
        if (v >= 0) {
            if (++w->ndig > 16) {
                refuse(w, 400, "a chunk size longer than 16 hex digits");
                break;
            }
            w->num = w->num * 16 + (uint64_t)v;
            if (w->max_body && w->num > w->max_body - w->body)
                refuse(w, 413, "the upload's chunks declare more than the limit of %llu bytes (max_upload)",
                       (unsigned long long)w->max_body);
        } else if (w->ndig == 0)
            refuse(w, 400, "a chunk size that is not hexadecimal");
        else if (b == '\r')
            w->st = W_CSIZE_LF;
        else if (b == ';' || b == ' ' || b == '\t')
            w->st = W_CEXT;
        else
            refuse(w, 400, "a chunk size that is not hexadecimal");
        break;
    }
    case W_CEXT:
        if (b == '\r')
            w->st = W_CSIZE_LF;
        else if (is_ctl(b) && b != '\t')
            refuse_ctl(w, b, "a chunk extension");
        break;
    case W_CSIZE_LF:
        if (b != '\n')
            refuse_ctl(w, '\r', "a chunk size line");
        else if (w->num == 0)
            w->st = W_HSTART, w->trailer = true;
        else
            w->st = W_CDATA, w->left = w->num, w->body += w->num;
        break;
    case W_CDATA_CR:
        if (b == '\r')
            w->st = W_CDATA_LF;
        else
            refuse(w, 400, "a chunk's data is longer than its size");
        break;
    case W_CDATA_LF:
        if (b == '\n')
            w->st = W_CSIZE, w->num = 0, w->ndig = 0;
        else
            refuse_ctl(w, '\r', "the end of a chunk");
        break;
    default:
        break;
    }
}

static void step(svc_wire *w, unsigned b)
{
    if (w->st < W_HSTART)
        step_line(w, b);
    else if (w->st < W_BODY)
        step_headers(w, b);
    else
        step_chunks(w, b);
}

int svc_wire_feed(svc_wire *w, const void *bytes, size_t n)
{
    const unsigned char *p = bytes, *end = p + n;
    while (p < end && !w->status) {
        if (w->st == W_BODY || w->st == W_CDATA) {
            size_t take = (size_t)(end - p) < w->left ? (size_t)(end - p) : (size_t)w->left;
            p += take;
            w->left -= take;
            if (w->left == 0) {
                if (w->st == W_BODY)
                    request_done(w);
                else
                    w->st = W_CDATA_CR;
            }
            continue;
        }
        step(w, *p++);
    }
    return w->status;
}
