/* svc_http_jobs: the job API's handlers (the route table in
 * svc_http_routes.c says which path and method reach each): submit, list,
 * show, cancel or delete, retry, and a job's files: video, hashes, poster,
 * log.  Each answers from the queue (d->http_store, which locks itself)
 * and the live numbers of renders running here; nothing here touches a
 * worker or a child process. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#if defined(RS_HAVE_MHD)
#include "svc_http_local.h"
#include "svc_log.h"
#include "svc_queue_view.h"
#include "../runtime/util/rs_file.h"

#define REFUSED "upload refused" /* the log's word for a refused upload */

/* --- submit --- */

/* Quota check and submit under one lock, so two uploads of one token at
 * once cannot both pass the same last slot (on one daemon; several
 * daemons of a PostgreSQL queue can each let one through). */
static pthread_mutex_t submit_mu = PTHREAD_MUTEX_INITIALIZER;

/* 201 with the new job's id and where to follow it. */
static enum MHD_Result created(struct MHD_Connection *c, const svc_job *j)
{
    svc_buf b = {0};
    svc_buf_printf(&b, "{\"id\":%" PRId64 ",\"state\":\"queued\",\"url\":\"/jobs/%" PRId64 "\",\"frames_total\":%" PRId64
                       "}\n",
                   j->id, j->id, j->frames_total);
    struct MHD_Response *r = b.oom ? NULL : MHD_create_response_from_buffer(b.len, b.p, MHD_RESPMEM_MUST_COPY);
    svc_buf_free(&b);
    if (!r)
        return MHD_NO;
    char loc[64];
    snprintf(loc, sizeof loc, "/jobs/%" PRId64, j->id);
    MHD_add_response_header(r, "Content-Type", "application/json");
    MHD_add_response_header(r, "Location", loc);
    enum MHD_Result ret = http_queue(c, 201, r);
    MHD_destroy_response(r);
    return ret;
}

bool http_upload_query(struct MHD_Connection *c, svc_upload *u, rs_err *err)
{
    static const char *const keys[] = {
#define X(name, room) #name,
        SVC_JOB_PARAMS(X)
#undef X
    };
    for (size_t i = 0; i < sizeof keys / sizeof *keys; i++)
        if (!svc_upload_param(u, keys[i], MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, keys[i]), err))
            return false;
    if (!u->name[0])
        svc_upload_name(u, MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "name"));
    if (!u->name[0])
        svc_upload_name(u, MHD_lookup_connection_value(c, MHD_HEADER_KIND, "X-Filename"));
    return true;
}

enum MHD_Result http_submit(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    svc_upload *u = &q->up;
    if (u->oom)
        return http_error(c, SVC_ERR_NOMEM, NULL, NULL, "out of memory reading the upload");
    rs_err err = {0};
    svc_job j;
    if (u->bad)
        rs_fail(&err, SVC_ERR_BAD_BODY, "%s", u->bad);
    else if (u->too_large)
        rs_fail(&err, SVC_ERR_TOO_LARGE, "the upload is over the limit of %ld bytes (max_upload)", d->cfg.max_upload);
    if (err.code || !http_upload_query(c, u, &err) || !svc_upload_job(&d->cfg, u, &j, &err)) {
        http_count_rejected(d);
        return http_error(c, err.code, NULL, REFUSED, "%s", err.msg);
    }
    j.token_id = q->tok.id;
    char over[512];
    int64_t retry = 0;
    pthread_mutex_lock(&submit_mu);
    int quota = q->tok.id ? svc_upload_quota(d->http_store, &q->tok, &j, over, sizeof over, &retry, &err) : 1;
    bool queued = quota == 1 && d->http_store->ops->submit(d->http_store, &j, &err);
    pthread_mutex_unlock(&submit_mu);
    if (quota == 0) {
        char ra[32];
        snprintf(ra, sizeof ra, "%" PRId64, retry);
        return http_error(c, SVC_ERR_QUOTA, &(http_header){"Retry-After", ra}, REFUSED, "%s; try again in %" PRId64 " s",
                          over, retry);
    }
    if (!queued) {
        svc_log(SVC_LOG_ERROR, -1, "could not queue an upload: %s", err.msg);
        return http_store_error(c, &err);
    }
    http_events_poke(d);
    if (j.segments > 0)
        svc_log(SVC_LOG_INFO, j.id, "queued %s (%zu bytes, %" PRId64 " frames, %dx%d %s) as %d segments of %d s",
                j.name, u->len, j.frames_total, j.width, j.height, j.format, j.segments, d->cfg.segment_seconds);
    else
        svc_log(SVC_LOG_INFO, j.id, "queued %s (%zu bytes, %" PRId64 " frames, %dx%d %s)", j.name, u->len,
                j.frames_total, j.width, j.height, j.format);
    return created(c, &j);
}

/* --- one job, many jobs --- */

/* A token sees its own jobs only (an operator's, or no token on an open
 * loopback daemon: every job); another's answers 404, as a missing one. */
static bool may_see(const req *q, const svc_job *j)
{
    return q->all || (q->tok.id != 0 && j->token_id == q->tok.id);
}

bool http_job_visible(svc_daemon *d, struct MHD_Connection *c, const req *q, svc_job *j, enum MHD_Result *ret)
{
    rs_err err = {0};
    int r = d->http_store->ops->get(d->http_store, q->m.id, j, &err);
    if (r < 0)
        *ret = http_store_error(c, &err);
    else if (r == 0 || !may_see(q, j))
        *ret = http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL, "no job %" PRId64, q->m.id);
    return r == 1 && may_see(q, j);
}

enum MHD_Result http_job(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    svc_job j;
    enum MHD_Result answer;
    if (!http_job_visible(d, c, q, &j, &answer))
        return answer;
    /* a split job shows its segments: who rendered each, how often */
    svc_unit *units = NULL;
    int n = 0;
    rs_err err = {0};
    if (j.segments > 0) {
        units = calloc((size_t)j.segments + 1, sizeof *units);
        if (!units)
            return http_error(c, SVC_ERR_NOMEM, NULL, NULL, "out of memory");
        n = d->http_store->ops->units(d->http_store, q->m.id, units, j.segments + 1, &err);
    }
    svc_queue_view qv = {0};
    if (n < 0 || !svc_view_queue(d, &j, 1, &qv, &err)) {
        free(units);
        svc_view_free(&qv);
        return http_store_error(c, &err);
    }
    svc_view_live(d, &j, units, n);
    svc_job_view v;
    svc_view_job(d, &qv, &j, units, n, &v);
    svc_view_free(&qv);
    svc_buf b = {0};
    svc_json_job(&b, &j, d->cfg.max_attempts, units, n, &v);
    svc_buf_add(&b, "\n", 1);
    free(units);
    return http_reply_json(c, 200, &b);
}

/* ?limit= and ?before=: false with the answer when one is malformed. */
bool http_list_params(struct MHD_Connection *c, long default_limit, long *limit, int64_t *before, enum MHD_Result *ret)
{
    int64_t lim;
    const char *v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "limit");
    if (v && (!http_parse_id(v, strlen(v), &lim) || lim > 500)) {
        *ret = http_error(c, SVC_ERR_BAD_PARAM, NULL, NULL, "limit '%s': expected 1..500", v);
        return false;
    }
    *limit = v ? (long)lim : default_limit;
    v = MHD_lookup_connection_value(c, MHD_GET_ARGUMENT_KIND, "before");
    *before = 0;
    if (v && !http_parse_id(v, strlen(v), before)) {
        *ret = http_error(c, SVC_ERR_BAD_PARAM, NULL, NULL, "before '%s': expected a job id", v);
        return false;
    }
    return true;
}

void http_jobs_page_free(http_jobs_page *p)
{
    svc_buf_free(&p->b);
    free(p->ids);
    free(p->at);
    p->ids = NULL;
    p->at = NULL;
    p->n = 0;
}

bool http_jobs_page_make(svc_daemon *d, int64_t token_id, int64_t before, long limit, http_jobs_page *p, rs_err *err)
{
    memset(p, 0, sizeof *p);
    svc_job *jobs = calloc((size_t)limit, sizeof *jobs);
    p->ids = calloc((size_t)limit, sizeof *p->ids);
    p->at = calloc((size_t)limit + 1, sizeof *p->at);
    if (!jobs || !p->ids || !p->at) {
        free(jobs);
        http_jobs_page_free(p);
        return rs_fail(err, SVC_ERR_NOMEM, "out of memory");
    }
    int n = d->http_store->ops->list(d->http_store, token_id, before, (int)limit, jobs, err);
    svc_queue_view qv = {0};
    if (n < 0 || !svc_view_queue(d, jobs, n, &qv, err)) {
        free(jobs);
        svc_view_free(&qv);
        http_jobs_page_free(p);
        return false;
    }
    svc_buf_add(&p->b, "{\"jobs\":[", 9);
    for (int i = 0; i < n; i++) {
        svc_view_live(d, &jobs[i], NULL, 0);
        if (i)
            svc_buf_add(&p->b, ",", 1);
        svc_job_view jv;
        svc_view_job(d, &qv, &jobs[i], NULL, 0, &jv);
        p->ids[i] = jobs[i].id;
        p->at[i] = p->b.len;
        svc_json_job(&p->b, &jobs[i], d->cfg.max_attempts, NULL, 0, &jv);
        p->at[i + 1] = p->b.len;
    }
    p->n = n;
    svc_view_free(&qv);
    if (n == limit && n > 0)
        svc_buf_printf(&p->b, "],\"next\":\"/jobs?before=%" PRId64 "&limit=%ld\"}", jobs[n - 1].id, limit);
    else
        svc_buf_add(&p->b, "],\"next\":null}", 14);
    free(jobs);
    if (p->b.oom) {
        http_jobs_page_free(p);
        return rs_fail(err, SVC_ERR_NOMEM, "out of memory");
    }
    return true;
}

enum MHD_Result http_list(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    long limit;
    int64_t before;
    enum MHD_Result answer;
    if (!http_list_params(c, 50, &limit, &before, &answer))
        return answer;
    http_jobs_page p;
    rs_err err = {0};
    if (!http_jobs_page_make(d, q->all ? 0 : q->tok.id, before, limit, &p, &err))
        return err.code == SVC_ERR_NOMEM ? http_error(c, SVC_ERR_NOMEM, NULL, NULL, "out of memory")
                                         : http_store_error(c, &err);
    svc_buf b = p.b;
    p.b = (svc_buf){0};
    http_jobs_page_free(&p);
    svc_buf_add(&b, "\n", 1);
    return http_reply_json(c, 200, &b);
}

/* --- changing a job --- */

/* DELETE of a job that is over: its files, then its row (a crash between
 * leaves a row whose video answers 410, and a second DELETE finishes). */
static enum MHD_Result delete_finished(svc_daemon *d, struct MHD_Connection *c, int64_t id)
{
    svc_job j;
    rs_err err = {0};
    int r = d->http_store->ops->get(d->http_store, id, &j, &err);
    int files = r == 1 ? svc_remove_job_outputs(&d->cfg, id, j.format) : 0;
    if (r == 1)
        r = d->http_store->ops->remove(d->http_store, id, &err);
    if (r < 0)
        return http_store_error(c, &err);
    if (r == 0)
        return http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL, "no job %" PRId64, id);
    if (r == 2) /* the store's own check: an over job never runs again */
        return http_error(c, SVC_ERR_CONFLICT, NULL, NULL, "job %" PRId64 " is not over", id);
    http_events_poke(d);
    svc_log(SVC_LOG_INFO, id, "deleted by a client (%s, %d file%s removed)", svc_state_name(j.state), files,
            files == 1 ? "" : "s");
    char body[128];
    snprintf(body, sizeof body, "{\"id\":%" PRId64 ",\"deleted\":true,\"state\":\"%s\",\"files_removed\":%d}\n", id,
             svc_state_name(j.state), files);
    return http_reply(c, 200, "application/json", body, strlen(body));
}

/* A store call on a job q may see: its answer (-1 failed, 0 no such job,
 * 1 done, 2 the job's state refused it), with the job as it was in *j. */
static int on_visible(svc_daemon *d, const req *q, svc_job *j, int (*op)(svc_store *, int64_t, rs_err *), rs_err *err)
{
    int r = d->http_store->ops->get(d->http_store, q->m.id, j, err);
    if (r == 1 && !may_see(q, j))
        r = 0;
    if (r == 1 && (r = op(d->http_store, q->m.id, err)) == 1)
        http_events_poke(d); /* the event streams show it now */
    return r;
}

enum MHD_Result http_cancel(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    svc_job j;
    rs_err err = {0};
    int r = on_visible(d, q, &j, d->http_store->ops->cancel, &err);
    if (r < 0)
        return http_store_error(c, &err);
    if (r == 0)
        return http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL, "no job %" PRId64, q->m.id);
    if (r == 2)
        return delete_finished(d, c, q->m.id);
    if (q->tok.id)
        svc_log(SVC_LOG_INFO, q->m.id, "cancelled by a client (token '%s')", q->tok.name);
    else
        svc_log(SVC_LOG_INFO, q->m.id, "cancelled by a client");
    return http_job(d, c, q);
}

/* A failed job back into the queue, its attempts reset (svc_store.h, retry). */
enum MHD_Result http_retry(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    svc_job j;
    rs_err err = {0};
    int r = on_visible(d, q, &j, d->http_store->ops->retry, &err);
    if (r < 0)
        return http_store_error(c, &err);
    if (r == 0)
        return http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL, "no job %" PRId64, q->m.id);
    if (r == 2)
        return http_error(c, SVC_ERR_CONFLICT, NULL, NULL, "job %" PRId64 " is %s: only a failed job can be retried",
                          q->m.id, svc_state_name(j.state));
    svc_log(SVC_LOG_INFO, q->m.id, "re-queued by a client%s%s%s (it had failed: %s)", q->tok.id ? " (token '" : "",
            q->tok.id ? q->tok.name : "", q->tok.id ? "')" : "", j.error);
    return http_job(d, c, q);
}

/* --- a job's files --- */

/* The file path as a regular file, open; -1 with errno otherwise. */
static int open_regular(const char *path, uint64_t *len)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd >= 0 && fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
        *len = (uint64_t)st.st_size;
        return fd;
    }
    int e = fd < 0 ? errno : EISDIR;
    if (fd >= 0)
        close(fd);
    errno = e;
    return -1;
}

/* files = queue: a done job's file this machine lacks (another one made
 * it) is fetched from the queue into its place first (svc_keep.c). */
static void fetch_copy(svc_daemon *d, int64_t id, const char *name, const char *path)
{
    rs_err err = {0};
    if (svc_keep_on(&d->cfg) && svc_fetch(d->http_store, id, name, path, &err) < 0)
        svc_log(SVC_LOG_WARN, id, "%s", err.msg);
}

/* A done job's video or hash list (OUTPUT/N.FORMAT, OUTPUT/N.hashes). */
static enum MHD_Result send_output(svc_daemon *d, struct MHD_Connection *c, req *q, bool video)
{
    svc_job j;
    enum MHD_Result answer;
    if (!http_job_visible(d, c, q, &j, &answer))
        return answer;
    const char *what = video ? "video" : "hash list", *ext = video ? j.format : "hashes";
    if (j.state != SVC_DONE)
        return http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL, "job %" PRId64 " is %s: its %s exists once it is done",
                          q->m.id, svc_state_name(j.state), what);
    if (j.expired)
        return http_error(c, SVC_ERR_GONE, NULL, NULL,
                          "job %" PRId64 "'s %s was removed by retention (kept %ld s after it finished)", q->m.id, what,
                          d->cfg.retention);
    char path[1100], name[24];
    svc_job_file(&d->cfg, q->m.id, ext, path, sizeof path);
    snprintf(name, sizeof name, video ? "video.%s" : "%s", ext);
    fetch_copy(d, q->m.id, name, path);
    uint64_t len = 0;
    int fd = open_regular(path, &len);
    if (fd < 0) {
        svc_log(SVC_LOG_WARN, q->m.id, "%s: %s (%s)", path, strerror(errno),
                svc_keep_on(&d->cfg) ? "not in the queue either" : "a shared output directory not mounted here?");
        return http_error(c, SVC_ERR_GONE, NULL, NULL, "job %" PRId64 " is done but %s is missing on this server", q->m.id,
                          path);
    }
    static const char *const types[][2] = {{"mp4", "video/mp4"}, {"webm", "video/webm"}, {"mkv", "video/x-matroska"}};
    const char *type = "text/plain; charset=utf-8";
    for (int i = 0; video && i < 3; i++)
        if (!strcmp(j.format, types[i][0]))
            type = types[i][1];
    char disp[200];
    snprintf(disp, sizeof disp, "inline; filename=\"ringside-job%" PRId64 ".%s\"", q->m.id, ext);
    const char *range = video ? MHD_lookup_connection_value(c, MHD_HEADER_KIND, "Range") : NULL;
    return http_send_file(c, fd, len, &(http_file){.type = type, .range = range, .disposition = disp, .ranges = true});
}

enum MHD_Result http_video(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    return send_output(d, c, q, true);
}

enum MHD_Result http_hashes(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    return send_output(d, c, q, false);
}

/* The job's poster (render --poster), once its render put it in place. */
enum MHD_Result http_poster(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    svc_job j;
    enum MHD_Result answer;
    if (!http_job_visible(d, c, q, &j, &answer))
        return answer;
    if (j.expired)
        return http_error(c, SVC_ERR_GONE, NULL, NULL, "job %" PRId64 "'s poster was removed by retention", q->m.id);
    char path[1100];
    svc_job_file(&d->cfg, q->m.id, "png", path, sizeof path);
    if (j.state == SVC_DONE)
        fetch_copy(d, q->m.id, "poster.png", path);
    uint64_t len = 0;
    int fd = j.state == SVC_DONE ? open_regular(path, &len) : -1;
    if (fd < 0)
        return http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL, "job %" PRId64 " is %s and has no poster%s", q->m.id,
                          svc_state_name(j.state), j.state == SVC_DONE ? "" : " yet: it comes with the video");
    return http_send_file(c, fd, len, &(http_file){.type = "image/png", .cache = "private, max-age=3600"});
}

/* The job's render log: each ended unit attempt's last lines (OUTPUT/N.log),
 * then what the units running here have said so far. */
enum MHD_Result http_log(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    svc_job j;
    enum MHD_Result answer;
    if (!http_job_visible(d, c, q, &j, &answer))
        return answer;
    char path[1100];
    svc_job_file(&d->cfg, q->m.id, "log", path, sizeof path);
    size_t len = 0;
    rs_err ferr = {0};
    /* files = queue: the log is the queue's (every machine's units append
     * there), fetched afresh each time; this machine's copy only where
     * the queue could not take a block */
    char *text = NULL, *local;
    if (svc_keep_on(&d->cfg)) {
        static unsigned seq;
        char copy[1200];
        snprintf(copy, sizeof copy, "%s/work/log%" PRId64 "-%d-%u.txt", d->cfg.data, q->m.id, (int)getpid(),
                 __atomic_fetch_add(&seq, 1, __ATOMIC_RELAXED));
        int got = d->http_store->ops->file_get(d->http_store, q->m.id, "log", copy, &ferr);
        if (got < 0)
            svc_log(SVC_LOG_WARN, q->m.id, "the render log: %s", ferr.msg);
        if (got == 1) {
            text = rs_read_file(copy, 4 << 20, &len, &ferr);
            unlink(copy);
        }
    }
    svc_buf b = {0};
    if (text)
        svc_buf_add(&b, text, len);
    free(text);
    if ((local = rs_read_file(path, 4 << 20, &len, &ferr)))
        svc_buf_add(&b, local, len);
    free(local);
    pthread_mutex_lock(&d->mu);
    for (int i = 0; i < d->cfg.workers; i++) {
        const svc_live *l = &d->live[i];
        if (l->job != q->m.id)
            continue;
        svc_unit u = {.kind = l->kind, .index = l->index};
        char cx[96];
        svc_unit_context(cx, sizeof cx, &u);
        svc_buf_printf(&b, "== %s%s, running in process %d (%" PRId64 " of %" PRId64 " frames) ==\n%s", cx,
                       l->kind == SVC_UNIT_JOIN ? "join" : "render", (int)l->pid, l->done, l->total, l->log);
    }
    pthread_mutex_unlock(&d->mu);
    if (b.oom) {
        svc_buf_free(&b);
        return MHD_NO;
    }
    enum MHD_Result ret = http_reply(c, 200, "text/plain; charset=utf-8", b.p ? b.p : "", b.len);
    svc_buf_free(&b);
    return ret;
}

#endif
