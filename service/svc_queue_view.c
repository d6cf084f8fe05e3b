/* svc_queue_view: what the API shows of a job beyond its queue row: the
 * live numbers of a render running here, the queue position, the ETA, the
 * size of its video and whether it has a poster (svc_queue_view.h). */
#include <inttypes.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "svc_encode.h"
#include "svc_queue_view.h"

/* DESIGN (queue position and ETA of a queued job): the claim hands out
 * units of the oldest job first (svc_store.h), so a queued job's position
 * is 1 + the queued jobs older than it.  Its ETA is the frames still to
 * render up to and including it (the running jobs' remainders, the older
 * queued jobs' totals, its own) over the queue's throughput: the recent
 * render speed (frames over wall seconds of the last QUEUE_SPEED_JOBS done
 * jobs, as the queue recorded them, so a split job's parallel segments
 * count) times this daemon's workers.  Another daemon on a PostgreSQL
 * queue is not counted, so the estimate errs long there; before any job
 * is done there is no speed and the ETA is null.  A running job keeps its
 * own: its remaining frames over its live fps.  At most QUEUE_SCAN jobs of
 * the queue are looked at; one further back shows no position. */
#define QUEUE_SPEED_JOBS 20
#define QUEUE_SCAN 10000

/* A running job's live numbers come from the daemon that runs it (when
 * that is us): fresher than the last heartbeat.  A whole job's are the
 * render's own; a split job's row sums its units as of their heartbeats,
 * so what our renders did since theirs is added. */
void svc_view_live(svc_daemon *d, svc_job *j, svc_unit *units, int n)
{
    if (j->state != SVC_RUNNING)
        return;
    pthread_mutex_lock(&d->mu);
    for (int i = 0; i < d->cfg.workers; i++) {
        const svc_live *l = &d->live[i];
        if (l->job != j->id)
            continue;
        if (l->kind == SVC_UNIT_WHOLE) {
            j->frames_done = l->done;
            j->frames_total = l->total;
            j->fps = l->fps;
            continue;
        }
        if (l->kind == SVC_UNIT_SEGMENT) {
            j->frames_done += l->done - l->beat_done;
            j->fps += l->fps - l->beat_fps;
        }
        for (int k = 0; k < n; k++)
            if (units[k].kind == l->kind && units[k].index == l->index && units[k].state == SVC_RUNNING) {
                units[k].frames_done = l->done;
                units[k].fps = l->fps;
            }
    }
    pthread_mutex_unlock(&d->mu);
    if (j->frames_done > j->frames_total)
        j->frames_done = j->frames_total;
    if (j->frames_done < 0)
        j->frames_done = 0;
    if (j->fps < 0)
        j->fps = 0;
}

bool svc_view_queue(svc_daemon *d, const svc_job *jobs, int n, svc_queue_view *qv, rs_err *err)
{
    memset(qv, 0, sizeof *qv);
    bool any = false;
    for (int i = 0; i < n; i++)
        any |= jobs[i].state == SVC_QUEUED;
    if (!any)
        return true;
    if (!(qv->p = calloc(QUEUE_SCAN, sizeof *qv->p)))
        return rs_fail(err, SVC_ERR_NOMEM, "out of memory");
    qv->n = d->http_store->ops->pending(d->http_store, qv->p, QUEUE_SCAN, err);
    return qv->n >= 0 && d->http_store->ops->speed(d->http_store, QUEUE_SPEED_JOBS, &qv->speed, err);
}

/* How much of the match a job's live stream lists, as the queue knows it:
 * a running split job's done units from tick 0 up to the first that is not
 * (the units svc_http_stream.c lists, once their indexes read back there);
 * a whole job's pieces come when it is done.  < 0: no stream. */
static double stream_seconds(svc_daemon *d, const svc_job *j, const svc_unit *units, int n)
{
    if (j->expired || !svc_encode_streamable(j->format, j->encode))
        return -1;
    if (j->state == SVC_DONE)
        return (double)j->frames_total / 60.0;
    if (j->state != SVC_RUNNING || j->segments <= 0)
        return j->state == SVC_QUEUED || j->state == SVC_RUNNING ? 0 : -1;
    svc_unit *own = NULL;
    if (!units) {
        rs_err err = {0};
        if (!(own = calloc((size_t)j->segments + 1, sizeof *own)))
            return 0;
        n = d->http_store->ops->units(d->http_store, j->id, own, j->segments + 1, &err);
        units = own;
    }
    int64_t end = 0;
    for (int i = 0; i < n; i++) {
        if (units[i].kind == SVC_UNIT_JOIN)
            continue;
        if (units[i].first_tick != end || (units[i].state != SVC_DONE && units[i].renders == 0))
            break;
        end = units[i].end_tick;
    }
    free(own);
    return (double)end / 60.0;
}

void svc_view_job(svc_daemon *d, const svc_queue_view *qv, const svc_job *j, const svc_unit *units, int n,
                  svc_job_view *v)
{
    *v = (svc_job_view){.eta_s = -1, .bytes = -1};
    v->stream_s = stream_seconds(d, j, units, n);
    char path[1100];
    struct stat st;
    if (j->state == SVC_DONE && !j->expired) {
        svc_job_file(&d->cfg, j->id, j->format, path, sizeof path);
        if (stat(path, &st) == 0 && S_ISREG(st.st_mode))
            v->bytes = (int64_t)st.st_size;
        svc_job_file(&d->cfg, j->id, "png", path, sizeof path);
        v->poster = stat(path, &st) == 0 && S_ISREG(st.st_mode);
    }
    if (j->state != SVC_QUEUED)
        return;
    int64_t frames = 0, ahead = 0;
    for (int i = 0; i < qv->n; i++) {
        frames += qv->p[i].frames_left;
        if (qv->p[i].id == j->id) {
            v->queue_position = ahead + 1;
            if (qv->speed > 0)
                v->eta_s = (double)frames / (qv->speed * d->cfg.workers);
            break;
        }
        ahead += qv->p[i].state == SVC_QUEUED;
    }
}

void svc_view_free(svc_queue_view *qv)
{
    free(qv->p);
    qv->p = NULL;
}
