/* svc_wire: the bytes of HTTP/1.1 requests as they arrive on a connection,
 * checked before libmicrohttpd parses them (docs/service.md, "Malformed
 * requests").
 *
 * A connection's bytes are fed in the pieces recv() returned; the check
 * follows the framing (request line, header lines, a Content-Length or
 * chunked body, the next request) and stops at the first byte that breaks
 * the strict grammar: a raw control byte in the request line or a header,
 * a CR or LF where a line cannot end, a target that is not a path or "*",
 * an HTTP version other than 1.0 and 1.1, a chunk size that is not 1 to 16
 * hex digits or that would take the body past max_upload.  It answers the
 * status the request gets and a one-line reason.  Pure: no socket, no
 * allocation, the same verdict however the bytes are split. */
#ifndef SVC_WIRE_H
#define SVC_WIRE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct svc_wire {
    uint8_t st;           /* where in the request (svc_wire.c's W_ states) */
    bool trailer;         /* the header lines after the last chunk */
    bool chunked, has_cl; /* this request's framing */
    bool te_other;        /* a Transfer-Encoding other than chunked */
    uint8_t pos;          /* bytes into the method, the version or a header name */
    uint8_t vers[8];      /* the version as sent */
    char name[20];        /* the header's name, lower case (longer names are cut) */
    char val[24];         /* the start of its value, lower case, without leading whitespace */
    uint8_t vlen;         /* bytes of the value (saturates above sizeof val) */
    uint8_t ndig;         /* digits of the chunk size or Content-Length read */
    uint64_t num;         /* the chunk size or Content-Length being read */
    uint64_t cl;          /* the request's Content-Length */
    uint64_t left;        /* body bytes (or chunk bytes) still to come */
    uint64_t body;        /* body bytes declared so far by this request's chunks */
    uint64_t max_body;    /* max_upload: a chunk that passes it is refused (0: no limit) */
    uint32_t requests;    /* requests whose bytes have all come */
    int status;           /* 0 while the bytes are well formed; else 400, 413, 501 or 505 */
    char why[160];        /* the reason, for the answer and the log */
} svc_wire;

/* A new connection: max_body is the largest body accepted (0: any). */
void svc_wire_init(svc_wire *w, uint64_t max_body);
/* Feeds n bytes; the status (0: fine so far).  Once not 0, it stays. */
int svc_wire_feed(svc_wire *w, const void *bytes, size_t n);
/* The reason phrase of a status svc_wire_feed gives ("Bad Request"). */
const char *svc_wire_phrase(int status);

#endif
