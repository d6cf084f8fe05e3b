/* svc_json: a small JSON writer into a growing buffer (the API's replies),
 * and the job object every endpoint shares. */
#ifndef SVC_JSON_H
#define SVC_JSON_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "../runtime/util/rs_err.h"
#include "svc_store.h"

typedef struct svc_buf {
    char *p;
    size_t len, cap;
    bool oom; /* an allocation failed: the buffer is incomplete */
} svc_buf;

void svc_buf_free(svc_buf *b);
void svc_buf_add(svc_buf *b, const char *s, size_t n);
void svc_buf_printf(svc_buf *b, const char *fmt, ...) RS_PRINTF(2, 3);
/* A JSON string literal: quotes, escapes, control characters as \u00XX;
 * invalid UTF-8 bytes become U+FFFD so the output is always valid JSON. */
void svc_json_str(svc_buf *b, const char *s);
/* The job object of GET /jobs/N.  max_attempts comes from the config;
 * lost_leases only when its daemon was lost; a done job has video and
 * hashes URLs, or "expired": true once retention removed them.  A
 * split job adds segment_seconds and segment_count, and with its units
 * (n > 0; GET /jobs/N, not the list) "segments" (each segment's ticks,
 * state, attempts, renders, frames and worker) and "join". */
void svc_json_job(svc_buf *b, const svc_job *j, int max_attempts, const svc_unit *units, int n);
/* {"error":"msg"} */
void svc_json_error(svc_buf *b, const char *msg);

#endif
