/* svc_store_sql_jobs: a job as a whole: submit (the job and its units),
 * the reads of jobs (get, list, units, the queue, counts, the recent
 * speed), and the changes to a whole job (cancel, retry, expire, remove).
 * The rules are svc_store.h's; svc_store_sql.c says how a change locks. */
#include <fcntl.h>
#include <inttypes.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "svc_store_sql_impl.h"

/* A nonce for the job's key: /dev/urandom, or the clock and pid. */
static void new_nonce(char *out, size_t n)
{
    uint8_t b[8] = {0};
    int fd = open("/dev/urandom", O_RDONLY | O_CLOEXEC);
    bool got = fd >= 0 && read(fd, b, sizeof b) == (ssize_t)sizeof b;
    if (fd >= 0)
        close(fd);
    if (!got) {
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        uint64_t v = (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 30) ^ ((uint64_t)getpid() << 12);
        memcpy(b, &v, sizeof b);
    }
    snprintf(out, n, "%02x%02x%02x%02x%02x%02x%02x%02x", b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]);
}

bool sq_submit(svc_store *bs, svc_job *j, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t seg = j->segment_ticks > 0 ? j->segment_ticks : 0;
    /* the plan (svc_plan_segments): whole, equal segments, or growing ones */
    int64_t n = svc_plan_segments(j->frames_total, seg, j->first_segment_ticks, NULL, 0);
    int64_t *ends = n > 0 ? malloc((size_t)n * sizeof *ends) : NULL;
    if (n > 0 && !ends)
        return rs_fail(err, SVC_STORE_ERR_NOMEM, "out of memory");
    if (n > 0)
        svc_plan_segments(j->frames_total, seg, j->first_segment_ticks, ends, (int)n);
    char nonce[24];
    new_nonce(nonce, sizeof nonce);
    int64_t now;
    pthread_mutex_lock(&s->mu);
    bool ok = sq_tx_begin(s, &now, err);
    if (!ok)
        goto out;
    int64_t id = 0;
    ok = sq_rows(s, "insert job",
                 "INSERT INTO jobs (state, name, width, height, format, frames_total, created, replay, segment_ticks,"
                 " segments, seg_key, token_id, stage, kind1, kind2, winner, rounds1, rounds2, encode)"
                 " VALUES (0, ?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17, ?18) RETURNING id",
                 ARGS(T(j->name), I(j->width), I(j->height), T(j->format), I(j->frames_total), I(now),
                      B(j->replay, j->replay_len), I(seg), I(n), T(nonce), I(j->token_id), I(j->stage), I(j->kind[0]),
                      I(j->kind[1]), I(j->winner), I(j->rounds[0]), I(j->rounds[1]), T(j->encode)),
                 sq_int_row, &id, 1, err) == 1;
    if (ok && n == 0)
        ok = run(s, "insert the job's unit",
                 "INSERT INTO units (job_id, idx, kind, first_tick, end_tick) VALUES (?1, 0, 0, 0, ?2)",
                 ARGS(I(id), I(j->frames_total)), NULL, err) >= 0;
    for (int64_t i = 0; ok && i < n; i++)
        ok = run(s, "insert a segment of the job",
                 "INSERT INTO units (job_id, idx, kind, first_tick, end_tick) VALUES (?1, ?2, 1, ?3, ?4)",
                 ARGS(I(id), I(i), I(i ? ends[i - 1] : 0), I(ends[i])), NULL, err) >= 0;
    if (ok && n > 0)
        ok = run(s, "insert the job's join",
                 "INSERT INTO units (job_id, idx, kind, first_tick, end_tick) VALUES (?1, ?2, 2, 0, ?3)",
                 ARGS(I(id), I(n), I(j->frames_total)), NULL, err) >= 0;
    if (sq_tx_end(s, ok, 1, err) == 1) {
        j->id = id;
        j->created = now;
        j->state = SVC_QUEUED;
        j->segment_ticks = (int)seg;
        j->segments = (int)n;
        snprintf(j->key, sizeof j->key, "job%" PRId64 "-%s", id, nonce);
    } else
        ok = false;
out:
    pthread_mutex_unlock(&s->mu);
    free(ends);
    return ok;
}

int sq_units(svc_store *bs, int64_t id, svc_unit *out, int max, rs_err *err)
{
    if (max <= 0)
        return 0;
    return sq_query(S(bs), "list the units", "SELECT " UNIT_COLS " FROM units WHERE job_id = ?1 ORDER BY idx LIMIT ?2",
                    ARGS(I(id), I(max)), sq_unit_row, out, max, err);
}

int sq_get(svc_store *bs, int64_t id, svc_job *out, rs_err *err)
{
    return sq_query(S(bs), "get", "SELECT " SQ_JOB_COLS ", " EXTRA_COLS " FROM jobs WHERE id = ?1", ARGS(I(id)),
                    sq_job_row, out, 1, err);
}

int sq_list(svc_store *bs, int64_t token_id, int64_t before, int limit, svc_job *out, rs_err *err)
{
    if (limit <= 0) /* PostgreSQL refuses a negative LIMIT */
        return 0;
    /* 0 means "from the newest"; a plain id < ?1 keeps the primary key usable */
    return sq_query(S(bs), "list",
                    "SELECT " SQ_JOB_COLS ", " EXTRA_COLS " FROM jobs WHERE id < ?1 AND (?3 = 0 OR token_id = ?3)"
                    " ORDER BY id DESC LIMIT ?2",
                    ARGS(I(before == 0 ? INT64_MAX : before), I(limit), I(token_id)), sq_job_row, out, limit, err);
}

/* A change to one job in one transaction, under the store's lock: the job
 * row locked, its state asked whether the change applies (allowed), then
 * change() run.  0: no such job; 2: its state refuses the change; 1: done;
 * -1: the queue failed (err).  cancel, remove and retry are this frame
 * around their own statements. */
static int job_change(svc_store *bs, int64_t id, bool (*allowed)(int state),
                      bool (*change)(sq_store *s, int64_t id, int64_t now, rs_err *err), rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1, state = 0;
    pthread_mutex_lock(&s->mu);
    if (sq_tx_begin(s, &now, err)) {
        int l = sq_lock_job(s, id, &state, NULL, err);
        bool applies = l > 0 && allowed(state), ok = l >= 0 && (!applies || change(s, id, now, err));
        rc = sq_tx_end(s, ok, l == 0 ? 0 : applies ? 1 : 2, err);
    }
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static bool is_live(int state)
{
    return state == SVC_QUEUED || state == SVC_RUNNING;
}

static bool is_over(int state)
{
    return !is_live(state);
}

static bool is_failed(int state)
{
    return state == SVC_FAILED;
}

static bool cancel_job(sq_store *s, int64_t id, int64_t now, rs_err *err)
{
    return run(s, "cancel", "UPDATE jobs SET state = 4, finished = ?2 WHERE id = ?1", ARGS(I(id), I(now)), NULL, err) >=
               0 &&
           sq_end_units(s, id, err) && sq_refresh(s, id, err);
}

int sq_cancel(svc_store *bs, int64_t id, rs_err *err)
{
    return job_change(bs, id, is_live, cancel_job, err);
}

int sq_expiring(svc_store *bs, int64_t age_s, const char *host, int64_t *out, int max, rs_err *err)
{
    if (max <= 0)
        return 0;
    char like[SVC_OWNER_MAX + 4];
    snprintf(like, sizeof like, host && host[0] ? "%s:%%" : "%%", host ? host : "");
    /* the WHOLE unit or the join made the video: its done_by names the host */
    return sq_query(S(bs), "find expired videos",
                    "SELECT j.id FROM jobs j WHERE j.state = 2 AND j.expired = 0 AND j.finished < @NOW - ?1"
                    " AND EXISTS (SELECT 1 FROM units u WHERE u.job_id = j.id AND u.kind <> 1 AND u.done_by LIKE ?2)"
                    " ORDER BY j.finished, j.id LIMIT ?3",
                    ARGS(I(age_s), T(like), I(max)), sq_int_row, out, max, err);
}

int sq_expire(svc_store *bs, int64_t id, rs_err *err)
{
    sq_store *s = S(bs);
    pthread_mutex_lock(&s->mu);
    int64_t n = run(s, "mark expired", "UPDATE jobs SET expired = 1 WHERE id = ?1 AND state = 2", ARGS(I(id)), NULL, err);
    pthread_mutex_unlock(&s->mu);
    return n < 0 ? -1 : n > 0;
}

static bool remove_job(sq_store *s, int64_t id, int64_t now, rs_err *err)
{
    (void)now;
    return run(s, "remove the units", "DELETE FROM units WHERE job_id = ?1", ARGS(I(id)), NULL, err) >= 0 &&
           run(s, "remove the stored files", "DELETE FROM job_files WHERE job_id = ?1", ARGS(I(id)), NULL, err) >= 0 &&
           run(s, "remove the job", "DELETE FROM jobs WHERE id = ?1", ARGS(I(id)), NULL, err) >= 0;
}

int sq_remove(svc_store *bs, int64_t id, rs_err *err)
{
    return job_change(bs, id, is_over, remove_job, err);
}

/* by_state[state] = count: row i is (state, count) */
static void count_row(void *dst, const sq_res *r, int i)
{
    int64_t *by_state = dst, k = v_int(r, i, 0);
    if (k >= 0 && k < SVC_NSTATES)
        by_state[k] = v_int(r, i, 1);
}

bool sq_counts(svc_store *bs, int64_t by_state[SVC_NSTATES], rs_err *err)
{
    memset(by_state, 0, sizeof(int64_t) * SVC_NSTATES);
    return sq_query(S(bs), "counts", "SELECT state, COUNT(*) FROM jobs GROUP BY state", NOARGS, count_row, by_state,
                    INT32_MAX, err) >= 0;
}

static bool retry_job(sq_store *s, int64_t id, int64_t now, rs_err *err)
{
    (void)now;
    return run(s, "re-queue the units",
               "UPDATE units SET state = 0, attempts = 0, lost = 0, error = '', owner = '', claimed_until = 0,"
               " frames_done = 0, fps = 0, started = 0, finished = 0, done_by = '', done_attempt = 0"
               " WHERE job_id = ?1",
               ARGS(I(id)), NULL, err) >= 0 &&
           run(s, "re-queue the job",
               "UPDATE jobs SET state = 0, error = '', desync_tick = -1, started = 0, finished = 0 WHERE id = ?1",
               ARGS(I(id)), NULL, err) >= 0 &&
           sq_refresh(s, id, err);
}

int sq_retry(svc_store *bs, int64_t id, rs_err *err)
{
    return job_change(bs, id, is_failed, retry_job, err);
}

static void pending_row(void *dst, const sq_res *r, int i)
{
    svc_pending *p = (svc_pending *)dst + i;
    p->id = v_int(r, i, 0);
    p->state = (int)v_int(r, i, 1);
    p->frames_left = v_int(r, i, 2) > 0 ? v_int(r, i, 2) : 0;
}

int sq_pending(svc_store *bs, svc_pending *out, int max, rs_err *err)
{
    if (max <= 0)
        return 0;
    return sq_query(S(bs), "list the queue",
                    "SELECT id, state, frames_total - frames_done FROM jobs WHERE state IN (0, 1) ORDER BY id LIMIT ?1",
                    ARGS(I(max)), pending_row, out, max, err);
}

/* frames over seconds, when there were seconds */
static void speed_row(void *dst, const sq_res *r, int i)
{
    if (v_int(r, i, 1) > 0)
        *(double *)dst = (double)v_int(r, i, 0) / (double)v_int(r, i, 1);
}

bool sq_speed(svc_store *bs, int last, double *fps, rs_err *err)
{
    *fps = 0;
    return sq_query(S(bs), "the recent render speed",
                    "SELECT CAST(COALESCE(SUM(frames_total), 0) AS BIGINT), CAST(COALESCE(SUM(finished - started), 0) AS BIGINT)"
                    " FROM (SELECT frames_total, finished, started FROM jobs WHERE state = 2 AND started > 0"
                    " AND finished > started ORDER BY finished DESC LIMIT ?1) recent",
                    ARGS(I(last)), speed_row, fps, 1, err) >= 0;
}
