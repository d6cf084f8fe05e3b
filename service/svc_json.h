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
/* What the HTTP side adds to a job from outside its row (NULL: nothing
 * known; each field's "unknown" as given). */
typedef struct svc_job_view {
    int64_t queue_position; /* queued: 1 = next to be claimed; 0: not queued or unknown */
    double eta_s;           /* queued or running: seconds until done; < 0: unknown */
    int64_t bytes;          /* done: the video's size; < 0: not there */
    bool poster;            /* the poster image exists */
    double stream_s;        /* seconds of the match its live stream lists, as the queue knows it; < 0: no stream */
} svc_job_view;

/* The job object of GET /jobs/N.  max_attempts comes from the config;
 * lost_leases only when its daemon was lost; a done job has video and
 * hashes URLs, or "expired": true once retention removed them.  A
 * split job adds segment_seconds and segment_count, and with its units
 * (n > 0; GET /jobs/N, not the list) "segments" (each segment's ticks,
 * state, attempts, renders, frames and worker) and "join".
 * The replay's header (stage, players, winner, rounds) is null for a job
 * queued before it was kept; length_s is the replay's; codec the format's
 * encoder (h264, vp9); render_s a finished job's started..finished.  v
 * adds queue_position, eta_s (also for a queued job), bytes, poster and
 * stream_s (beside the stream's URL). */
void svc_json_job(svc_buf *b, const svc_job *j, int max_attempts, const svc_unit *units, int n, const svc_job_view *v);
/* {"error":"msg"} */
void svc_json_error(svc_buf *b, const char *msg);

#endif
