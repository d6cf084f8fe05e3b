/* svc_queue_view: what the API shows of a job beyond its queue row (the
 * DESIGN note in svc_queue_view.c says how the position and ETA are
 * estimated).  Private to service/. */
#ifndef SVC_QUEUE_VIEW_H
#define SVC_QUEUE_VIEW_H

#include "svc_json.h"
#include "svc_local.h"

typedef struct svc_queue_view {
    svc_pending *p;
    int n;
    double speed; /* frames per second of one worker, recently; 0: unknown */
} svc_queue_view;

/* A running job's live numbers from the render running it here, when one
 * does (units: its segments, n of them, or NULL). */
void svc_view_live(svc_daemon *d, svc_job *j, svc_unit *units, int n);
/* Loads the queue order when one of jobs[0..n-1] is queued (else nothing
 * to look up).  False: the queue failed (err).  Free with svc_view_free
 * either way. */
bool svc_view_queue(svc_daemon *d, const svc_job *jobs, int n, svc_queue_view *qv, rs_err *err);
void svc_view_free(svc_queue_view *qv);
/* What the API shows of job j beyond its row (units: its units when the
 * caller has them, n of them; NULL: looked up when needed). */
void svc_view_job(svc_daemon *d, const svc_queue_view *qv, const svc_job *j, const svc_unit *units, int n,
                  svc_job_view *v);

#endif
