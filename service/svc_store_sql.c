/* svc_store_sql: the queue's rules (svc_store.h), once for both SQL
 * backends (svc_store_sql.h says how a driver differs).
 *
 * DESIGN: a store handle is one driver connection guarded by the handle's
 * mutex; any thread may call it.  Every change is one write transaction
 * that first locks the job's row (@LOCK), then changes the job's units,
 * then recomputes the job's row from its units (refresh).  One lock order
 * (job, then units) means no deadlock between daemons, and the recompute
 * runs after the lock, so on PostgreSQL (READ COMMITTED: each statement
 * sees what committed before it began) it sees every other daemon's
 * committed change to the same job.  The claim is the one change that does
 * not know its job beforehand: it picks a unit and locks its job in one
 * statement, passing over jobs another daemon holds (@SKIP), and then
 * takes the unit only if it is still queued (another daemon may have taken
 * it between that statement's snapshot and its lock), else it tries again.
 *
 * PostgreSQL only: a lost connection is reconnected by the driver at the
 * first statement of the next call; a reply lost after a commit makes at
 * worst a wasted render (see svc_store_pg.c). */
#include <fcntl.h>
#include <inttypes.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "svc_store_sql.h"

typedef struct sq_store {
    svc_store base;
    svc_store_ops ops; /* the shared table with the driver's name */
    const sq_driver *drv;
    void *c;
    pthread_mutex_t mu;
} sq_store;

#define S(x) ((sq_store *)(x))

/* parameters: ARGS(I(id), T(owner)) */
#define I(x) ((sq_val){.type = SQ_INT, .i = (int64_t)(x)})
#define R(x) ((sq_val){.type = SQ_REAL, .f = (x)})
#define T(x) ((sq_val){.type = SQ_TEXT, .s = (x)})
#define B(p, len) ((sq_val){.type = SQ_BLOB, .s = (const char *)(p), .n = (len)})
#define ARGS(...) (sq_val[]){__VA_ARGS__}, (int)(sizeof((sq_val[]){__VA_ARGS__}) / sizeof(sq_val))
#define NOARGS NULL, 0

#define UNIT_COLS                                                                                                     \
    "kind, idx, first_tick, end_tick, state, attempts, owner, claimed_until, started, finished, frames_done, fps, "   \
    "error, renders, done_by, done_attempt, lost"

static int64_t run(sq_store *s, const char *what, const char *sql, const sq_val *a, int n, sq_res *out, rs_err *err)
{
    if (out)
        memset(out, 0, sizeof *out);
    return s->drv->exec(s->c, what, sql, a, n, out, err);
}

static void res_free(sq_store *s, sq_res *r)
{
    if (r->own || r->v)
        s->drv->res_free(r);
    memset(r, 0, sizeof *r);
}

static const sq_val *cell(const sq_res *r, int row, int col)
{
    return &r->v[row * r->cols + col];
}

static int64_t v_int(const sq_res *r, int row, int col)
{
    return cell(r, row, col)->i;
}

static void v_text(char *dst, size_t n, const sq_res *r, int row, int col)
{
    const sq_val *v = cell(r, row, col);
    snprintf(dst, n, "%s", v->type == SQ_TEXT && v->s ? v->s : "");
}

static void job_from(const sq_res *r, int row, svc_job *j)
{
    memset(j, 0, sizeof *j);
    j->id = v_int(r, row, 0);
    j->state = (int)v_int(r, row, 1);
    v_text(j->name, sizeof j->name, r, row, 2);
    j->width = (int)v_int(r, row, 3);
    j->height = (int)v_int(r, row, 4);
    v_text(j->format, sizeof j->format, r, row, 5);
    j->frames_done = v_int(r, row, 6);
    j->frames_total = v_int(r, row, 7);
    j->fps = cell(r, row, 8)->f;
    j->attempts = (int)v_int(r, row, 9);
    j->desync_tick = v_int(r, row, 10);
    v_text(j->error, sizeof j->error, r, row, 11);
    v_text(j->owner, sizeof j->owner, r, row, 12);
    j->created = v_int(r, row, 13);
    j->started = v_int(r, row, 14);
    j->finished = v_int(r, row, 15);
    j->claimed_until = v_int(r, row, 16);
    j->segment_ticks = (int)v_int(r, row, 17);
    j->segments = (int)v_int(r, row, 18);
    char nonce[24];
    v_text(nonce, sizeof nonce, r, row, 19);
    snprintf(j->key, sizeof j->key, "job%" PRId64 "-%s", j->id, nonce);
    j->lost = (int)v_int(r, row, 20);
    j->expired = v_int(r, row, 21) != 0;
    v_text(j->encode, sizeof j->encode, r, row, 22);
}

/* get and list read token_id and the replay's header after SQ_JOB_COLS
 * (the claim needs neither) */
#define TOKEN_COL 23 /* SQ_JOB_COLS has 23 columns */
#define EXTRA_COLS "token_id, stage, kind1, kind2, winner, rounds1, rounds2"

static void extra_from(const sq_res *r, int row, svc_job *j)
{
    j->token_id = v_int(r, row, TOKEN_COL);
    j->stage = (int)v_int(r, row, TOKEN_COL + 1);
    j->kind[0] = (int)v_int(r, row, TOKEN_COL + 2);
    j->kind[1] = (int)v_int(r, row, TOKEN_COL + 3);
    j->winner = (int)v_int(r, row, TOKEN_COL + 4);
    j->rounds[0] = (int)v_int(r, row, TOKEN_COL + 5);
    j->rounds[1] = (int)v_int(r, row, TOKEN_COL + 6);
}

static void unit_from(const sq_res *r, int row, svc_unit *u)
{
    memset(u, 0, sizeof *u);
    u->kind = (int)v_int(r, row, 0);
    u->index = (int)v_int(r, row, 1);
    u->first_tick = v_int(r, row, 2);
    u->end_tick = v_int(r, row, 3);
    u->state = (int)v_int(r, row, 4);
    u->attempts = (int)v_int(r, row, 5);
    v_text(u->owner, sizeof u->owner, r, row, 6);
    u->claimed_until = v_int(r, row, 7);
    u->started = v_int(r, row, 8);
    u->finished = v_int(r, row, 9);
    u->frames_done = v_int(r, row, 10);
    u->fps = cell(r, row, 11)->f;
    v_text(u->error, sizeof u->error, r, row, 12);
    u->renders = (int)v_int(r, row, 13);
    v_text(u->done_by, sizeof u->done_by, r, row, 14);
    u->done_attempt = (int)v_int(r, row, 15);
    u->lost = (int)v_int(r, row, 16);
    u->claim = u->attempts + u->lost;
}

/* --- transactions --- */

static bool tx_begin(sq_store *s, int64_t *now, rs_err *err)
{
    if (!s->drv->begin(s->c, err))
        return false;
    sq_res r;
    if (run(s, "read the clock", "SELECT @NOW", NOARGS, &r, err) < 0 || r.rows != 1) {
        res_free(s, &r);
        s->drv->rollback(s->c);
        return false;
    }
    *now = v_int(&r, 0, 0);
    res_free(s, &r);
    return true;
}

/* Commits when ok, rolls back when not; returns rc, or -1 when the
 * commit fails. */
static int tx_end(sq_store *s, bool ok, int rc, rs_err *err)
{
    if (!ok) {
        s->drv->rollback(s->c);
        return -1;
    }
    if (!s->drv->commit(s->c, err)) {
        s->drv->rollback(s->c);
        return -1;
    }
    return rc;
}

/* Locks job id's row.  1: locked (its segment count in *segments, its
 * state in *state); 0: no such job; -1. */
static int lock_job(sq_store *s, int64_t id, int *state, int *segments, rs_err *err)
{
    sq_res r;
    if (run(s, "lock the job", "SELECT state, segments FROM jobs WHERE id = ?1@LOCK", ARGS(I(id)), &r, err) < 0)
        return -1;
    int rc = r.rows > 0;
    if (rc) {
        if (state)
            *state = (int)v_int(&r, 0, 0);
        if (segments)
            *segments = (int)v_int(&r, 0, 1);
    }
    res_free(s, &r);
    return rc;
}

/* The job's row from its units: state while not over, the most attempts,
 * frames and fps summed, a running unit's owner and lease. */
static bool refresh(sq_store *s, int64_t id, rs_err *err)
{
    return run(s, "sum up the job",
               "UPDATE jobs SET"
               " state = CASE WHEN state IN (2, 3, 4) THEN state"
               "   WHEN EXISTS (SELECT 1 FROM units u WHERE u.job_id = jobs.id AND u.state = 1) THEN 1 ELSE 0 END,"
               " attempts = (SELECT COALESCE(MAX(u.attempts), 0) FROM units u WHERE u.job_id = jobs.id),"
               " lost = (SELECT COALESCE(MAX(u.lost), 0) FROM units u WHERE u.job_id = jobs.id),"
               " frames_done = (SELECT CAST(COALESCE(SUM(u.frames_done), 0) AS BIGINT) FROM units u"
               "   WHERE u.job_id = jobs.id AND u.kind <> 2),"
               " fps = (SELECT COALESCE(SUM(u.fps), 0) FROM units u WHERE u.job_id = jobs.id AND u.state = 1),"
               " owner = COALESCE((SELECT u.owner FROM units u WHERE u.job_id = jobs.id AND u.state = 1"
               "   ORDER BY u.idx LIMIT 1), ''),"
               " claimed_until = (SELECT COALESCE(MAX(u.claimed_until), 0) FROM units u"
               "   WHERE u.job_id = jobs.id AND u.state = 1)"
               " WHERE id = ?1",
               ARGS(I(id)), NULL, err) >= 0;
}

/* owner's running unit of job id into u.  1, 0 (none), -1. */
static int owned_unit(sq_store *s, int64_t id, const char *owner, svc_unit *u, rs_err *err)
{
    sq_res r;
    if (run(s, "find the unit", "SELECT " UNIT_COLS " FROM units WHERE job_id = ?1 AND owner = ?2 AND state = 1",
            ARGS(I(id), T(owner)), &r, err) < 0)
        return -1;
    int rc = r.rows > 0;
    if (rc)
        unit_from(&r, 0, u);
    res_free(s, &r);
    return rc;
}

/* The job is over (failed or cancelled): its units that were still to do
 * are cancelled, so their owners' heartbeats answer "not ours". */
static bool end_units(sq_store *s, int64_t id, rs_err *err)
{
    return run(s, "cancel the job's units",
               "UPDATE units SET state = 4, claimed_until = 0, fps = 0 WHERE job_id = ?1 AND state IN (0, 1)",
               ARGS(I(id)), NULL, err) >= 0;
}

static bool fail_job(sq_store *s, int64_t id, const char *why, int64_t desync, int64_t now, rs_err *err)
{
    return end_units(s, id, err) &&
           run(s, "fail the job",
               "UPDATE jobs SET state = 3, error = ?2, desync_tick = ?3, finished = ?4 WHERE id = ?1",
               ARGS(I(id), T(why), I(desync), I(now)), NULL, err) >= 0;
}

/* A unit's attempt that did not finish (the caller holds the job's lock):
 * back to queued, or the job failed at the cap. */
static bool release_unit(sq_store *s, int64_t id, const svc_unit *u, const char *why, bool count_attempt,
                         int max_attempts, int64_t now, rs_err *err)
{
    char ctx[96], msg[SVC_ERROR_MAX + 96];
    svc_unit_context(ctx, sizeof ctx, u);
    if (count_attempt && u->attempts >= max_attempts) {
        char dead[SVC_ERROR_MAX + 128];
        svc_dead_letter(dead, sizeof dead, u->attempts, why);
        snprintf(msg, sizeof msg, "gave up after %d attempt%s: %s%s", u->attempts, u->attempts == 1 ? "" : "s", ctx,
                 why);
        return run(s, "fail the unit",
                   "UPDATE units SET state = 3, error = ?3, owner = '', claimed_until = 0, fps = 0, finished = ?4"
                   " WHERE job_id = ?1 AND idx = ?2",
                   ARGS(I(id), I(u->index), T(dead), I(now)), NULL, err) >= 0 &&
               fail_job(s, id, msg, -1, now, err);
    }
    snprintf(msg, sizeof msg, "%s%s", ctx, why);
    /* a segment starts again from its first frame: its progress goes (the
     * WHOLE unit keeps it until its next claim, as jobs always did) */
    return run(s, "re-queue the unit",
               "UPDATE units SET state = 0, attempts = attempts - ?3, owner = '', claimed_until = 0, fps = 0,"
               " frames_done = CASE WHEN kind = 0 THEN frames_done ELSE 0 END, error = ?4"
               " WHERE job_id = ?1 AND idx = ?2",
               ARGS(I(id), I(u->index), I(count_attempt ? 0 : 1), T(why)), NULL, err) >= 0 &&
           run(s, "note why", "UPDATE jobs SET error = ?2, finished = 0 WHERE id = ?1", ARGS(I(id), T(msg)), NULL,
               err) >= 0;
}

/* A unit whose lease expired (the caller holds the job's lock): its
 * attempt given back and one more lost lease counted, back to queued, or
 * the job failed at SVC_LOST_MAX.  *failed says which. */
static bool lose_unit(sq_store *s, int64_t id, const svc_unit *u, int64_t now, bool *failed, rs_err *err)
{
    char ctx[96], why[128], msg[SVC_ERROR_MAX + 96];
    svc_unit_context(ctx, sizeof ctx, u);
    *failed = u->lost + 1 >= SVC_LOST_MAX;
    if (*failed) {
        snprintf(why, sizeof why, SVC_LOST_FMT, u->lost + 1);
        snprintf(msg, sizeof msg, "%s%s", ctx, why);
        return run(s, "fail the unit",
                   "UPDATE units SET state = 3, lost = lost + 1, attempts = attempts - 1, error = ?3, owner = '',"
                   " claimed_until = 0, fps = 0, finished = ?4 WHERE job_id = ?1 AND idx = ?2",
                   ARGS(I(id), I(u->index), T(why), I(now)), NULL, err) >= 0 &&
               fail_job(s, id, msg, -1, now, err);
    }
    return run(s, "count the lost lease", "UPDATE units SET lost = lost + 1 WHERE job_id = ?1 AND idx = ?2",
               ARGS(I(id), I(u->index)), NULL, err) >= 0 &&
           release_unit(s, id, u, SVC_LEASE_EXPIRED, false, 0, now, err);
}

/* --- the ops --- */

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

static bool sq_submit(svc_store *bs, svc_job *j, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t seg = j->segment_ticks > 0 ? j->segment_ticks : 0;
    /* a replay no longer than one segment is rendered whole: a segment and
     * a join would only add their start-up to the same frames */
    int64_t n = seg > 0 && j->frames_total > seg ? (j->frames_total + seg - 1) / seg : 0;
    char nonce[24];
    new_nonce(nonce, sizeof nonce);
    int64_t now;
    pthread_mutex_lock(&s->mu);
    bool ok = tx_begin(s, &now, err);
    if (!ok)
        goto out;
    sq_res r;
    ok = run(s, "insert job",
             "INSERT INTO jobs (state, name, width, height, format, frames_total, created, replay, segment_ticks,"
             " segments, seg_key, token_id, stage, kind1, kind2, winner, rounds1, rounds2, encode)"
             " VALUES (0, ?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17, ?18) RETURNING id",
             ARGS(T(j->name), I(j->width), I(j->height), T(j->format), I(j->frames_total), I(now),
                  B(j->replay, j->replay_len), I(seg), I(n), T(nonce), I(j->token_id), I(j->stage), I(j->kind[0]),
                  I(j->kind[1]), I(j->winner), I(j->rounds[0]), I(j->rounds[1]), T(j->encode)),
             &r, err) >= 0 &&
         r.rows == 1;
    int64_t id = ok ? v_int(&r, 0, 0) : 0;
    res_free(s, &r);
    if (ok && n == 0)
        ok = run(s, "insert the job's unit",
                 "INSERT INTO units (job_id, idx, kind, first_tick, end_tick) VALUES (?1, 0, 0, 0, ?2)",
                 ARGS(I(id), I(j->frames_total)), NULL, err) >= 0;
    else if (ok)
        ok = run(s, "insert the job's segments",
                 "WITH RECURSIVE k(i) AS (SELECT 0 UNION ALL SELECT i + 1 FROM k WHERE i + 1 < ?2)"
                 " INSERT INTO units (job_id, idx, kind, first_tick, end_tick)"
                 " SELECT ?1, i, 1, i * ?3, CASE WHEN (i + 1) * ?3 < ?4 THEN (i + 1) * ?3 ELSE ?4 END FROM k",
                 ARGS(I(id), I(n), I(seg), I(j->frames_total)), NULL, err) == n &&
             run(s, "insert the job's join",
                 "INSERT INTO units (job_id, idx, kind, first_tick, end_tick) VALUES (?1, ?2, 2, 0, ?3)",
                 ARGS(I(id), I(n), I(j->frames_total)), NULL, err) >= 0;
    if (tx_end(s, ok, 1, err) == 1) {
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
    return ok;
}

/* One try at a claim: 1 claimed, 0 nothing queued, 2 lost a race (try
 * again), -1 error. */
static int claim_once(sq_store *s, const char *owner, int lease_s, svc_job *out, rs_err *err)
{
    int64_t now;
    if (!tx_begin(s, &now, err))
        return -1;
    sq_res r = {0};
    /* the queued unit of the oldest job that has one; a join only once
     * every segment of its job is done */
    bool ok = run(s, "claim",
                  "SELECT u.job_id, u.idx FROM units u JOIN jobs j ON j.id = u.job_id"
                  " WHERE u.state = 0 AND j.state IN (0, 1) AND (u.kind <> 2 OR NOT EXISTS"
                  "   (SELECT 1 FROM units d WHERE d.job_id = u.job_id AND d.kind = 1 AND d.state <> 2))"
                  " ORDER BY u.job_id, u.idx LIMIT 1@SKIP",
                  NOARGS, &r, err) >= 0;
    if (!ok || r.rows == 0) {
        res_free(s, &r);
        return tx_end(s, ok, 0, err);
    }
    int64_t id = v_int(&r, 0, 0), idx = v_int(&r, 0, 1);
    res_free(s, &r);
    int64_t got = run(s, "claim the unit",
                      "UPDATE units SET state = 1, owner = ?3, attempts = attempts + 1, frames_done = 0, fps = 0,"
                      " started = ?4, claimed_until = ?4 + ?5, finished = 0"
                      " WHERE job_id = ?1 AND idx = ?2 AND state = 0",
                      ARGS(I(id), I(idx), T(owner), I(now), I(lease_s)), NULL, err);
    if (got <= 0) {
        s->drv->rollback(s->c);
        return got < 0 ? -1 : 2;
    }
    ok = run(s, "start the job", "UPDATE jobs SET started = ?2 WHERE id = ?1 AND state = 0", ARGS(I(id), I(now)),
             NULL, err) >= 0 &&
         refresh(s, id, err) &&
         run(s, "read the claimed job", "SELECT " SQ_JOB_COLS ", replay FROM jobs WHERE id = ?1", ARGS(I(id)), &r,
             err) >= 0 &&
         r.rows == 1;
    if (ok) {
        job_from(&r, 0, out);
        const sq_val *rp = cell(&r, 0, 23);
        size_t n = rp->type == SQ_BLOB || rp->type == SQ_TEXT ? rp->n : 0;
        out->replay = malloc(n > 0 ? n : 1);
        if (!out->replay)
            ok = rs_fail(err, SVC_STORE_ERR_NOMEM, "out of memory reading job %" PRId64 "'s replay", id);
        else {
            if (n)
                memcpy(out->replay, rp->s, n);
            out->replay_len = n;
        }
    }
    res_free(s, &r);
    ok = ok && run(s, "read the claimed unit", "SELECT " UNIT_COLS " FROM units WHERE job_id = ?1 AND idx = ?2",
                   ARGS(I(id), I(idx)), &r, err) >= 0 &&
         r.rows == 1;
    if (ok)
        unit_from(&r, 0, &out->unit);
    res_free(s, &r);
    int rc = tx_end(s, ok, 1, err);
    if (rc != 1)
        svc_job_free(out);
    return rc;
}

static int sq_claim(svc_store *bs, const char *owner, int lease_s, svc_job *out, rs_err *err)
{
    sq_store *s = S(bs);
    memset(out, 0, sizeof *out);
    pthread_mutex_lock(&s->mu);
    int rc = 2;
    for (int tries = 0; rc == 2 && tries < 8; tries++)
        rc = claim_once(s, owner, lease_s, out, err);
    pthread_mutex_unlock(&s->mu);
    return rc == 2 ? 0 : rc; /* raced eight times: nothing for us this round */
}

static int sq_heartbeat(svc_store *bs, int64_t id, const char *owner, int lease_s, int64_t done, int64_t total,
                        double fps, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1;
    if (!(fps == fps && fps < 1e300 && fps > -1e300))
        fps = 0; /* NaN or inf from a worker that divided by a zero time */
    pthread_mutex_lock(&s->mu);
    if (!tx_begin(s, &now, err))
        goto out;
    int l = lock_job(s, id, NULL, NULL, err);
    int64_t ch = l <= 0 ? l
                        : run(s, "heartbeat",
                              "UPDATE units SET claimed_until = ?3 + ?4, frames_done = ?5, fps = ?6"
                              " WHERE job_id = ?1 AND owner = ?2 AND state = 1",
                              ARGS(I(id), T(owner), I(now), I(lease_s), I(done), R(fps)), NULL, err);
    bool ok = ch >= 0;
    if (ok && ch > 0)
        ok = run(s, "heartbeat", "UPDATE jobs SET frames_total = ?2 WHERE id = ?1 AND segments = 0",
                 ARGS(I(id), I(total)), NULL, err) >= 0 &&
             refresh(s, id, err);
    rc = tx_end(s, ok, ch > 0, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_finish(svc_store *bs, int64_t id, const char *owner, int state, const char *error, int64_t desync,
                     int64_t done, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1;
    svc_unit u;
    if (!error)
        error = "";
    pthread_mutex_lock(&s->mu);
    if (!tx_begin(s, &now, err))
        goto out;
    int l = lock_job(s, id, NULL, NULL, err);
    int have = l <= 0 ? l : owned_unit(s, id, owner, &u, err);
    bool ok = have >= 0;
    if (ok && have && state == SVC_DONE) {
        /* a segment's frames are all there; the WHOLE unit says how many */
        int64_t frames = u.kind == SVC_UNIT_SEGMENT ? u.end_tick - u.first_tick : u.kind == SVC_UNIT_WHOLE ? done : 0;
        ok = run(s, "finish the unit",
                 "UPDATE units SET state = 2, frames_done = ?3, fps = 0, claimed_until = 0, finished = ?4,"
                 " renders = renders + 1, done_by = ?5, done_attempt = attempts + lost, error = ''"
                 " WHERE job_id = ?1 AND idx = ?2",
                 ARGS(I(id), I(u.index), I(frames), I(now), T(owner)), NULL, err) >= 0;
        if (ok && u.kind != SVC_UNIT_SEGMENT)
            ok = run(s, "finish the job",
                     "UPDATE jobs SET state = 2, error = ?2, desync_tick = ?3, finished = ?4 WHERE id = ?1",
                     ARGS(I(id), T(error), I(desync), I(now)), NULL, err) >= 0;
    } else if (ok && have) {
        char ctx[96], msg[SVC_ERROR_MAX + 96];
        svc_unit_context(ctx, sizeof ctx, &u);
        snprintf(msg, sizeof msg, "%s%s", ctx, error);
        ok = run(s, "fail the unit",
                 "UPDATE units SET state = 3, frames_done = ?3, fps = 0, claimed_until = 0, finished = ?4, error = ?5"
                 " WHERE job_id = ?1 AND idx = ?2",
                 ARGS(I(id), I(u.index), I(done), I(now), T(error)), NULL, err) >= 0 &&
             fail_job(s, id, msg, desync, now, err);
    }
    if (ok && have)
        ok = refresh(s, id, err);
    rc = tx_end(s, ok, have > 0, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_release(svc_store *bs, int64_t id, const char *owner, const char *why, bool count_attempt,
                      int max_attempts, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1;
    svc_unit u;
    pthread_mutex_lock(&s->mu);
    if (!tx_begin(s, &now, err))
        goto out;
    int l = lock_job(s, id, NULL, NULL, err);
    int have = l <= 0 ? l : owned_unit(s, id, owner, &u, err);
    bool ok = have >= 0;
    if (ok && have)
        ok = release_unit(s, id, &u, why ? why : "", count_attempt, max_attempts, now, err) && refresh(s, id, err);
    rc = tx_end(s, ok, have > 0, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_reap(svc_store *bs, bool all, svc_reaped *out, int max, rs_err *err)
{
    sq_store *s = S(bs);
    sq_res r;
    int n = 0;
    pthread_mutex_lock(&s->mu);
    if (run(s, "find expired leases",
            "SELECT job_id, idx, owner FROM units WHERE state = 1 AND (?1 <> 0 OR claimed_until < @NOW)"
            " ORDER BY job_id, idx",
            ARGS(I(all)), &r, err) < 0) {
        pthread_mutex_unlock(&s->mu);
        return -1;
    }
    /* each in its own transaction, under its job's lock, checked again:
     * its owner may have renewed it (or finished it) meanwhile */
    for (int i = 0; i < r.rows && n >= 0; i++) {
        int64_t id = v_int(&r, i, 0), now;
        char owner[SVC_OWNER_MAX];
        v_text(owner, sizeof owner, &r, i, 2);
        if (!tx_begin(s, &now, err)) {
            n = -1;
            break;
        }
        svc_unit u;
        sq_res ur;
        int l = lock_job(s, id, NULL, NULL, err);
        bool ok = l >= 0 &&
                  run(s, "find the expired unit",
                      "SELECT " UNIT_COLS " FROM units WHERE job_id = ?1 AND idx = ?2 AND state = 1 AND owner = ?3"
                      " AND (?4 <> 0 OR claimed_until < ?5)",
                      ARGS(I(id), I(v_int(&r, i, 1)), T(owner), I(all), I(now)), &ur, err) >= 0;
        bool hit = ok && ur.rows == 1;
        if (hit)
            unit_from(&ur, 0, &u);
        if (ok)
            res_free(s, &ur);
        bool failed = false;
        if (hit)
            ok = lose_unit(s, id, &u, now, &failed, err) && refresh(s, id, err);
        if (tx_end(s, ok, 1, err) < 0)
            n = -1;
        else if (hit) {
            if (out && n < max)
                out[n] = (svc_reaped){.id = id, .unit = u, .failed = failed};
            n++;
        }
    }
    res_free(s, &r);
    pthread_mutex_unlock(&s->mu);
    return n;
}

static int sq_rejoin(svc_store *bs, int64_t id, const char *owner, const int *bad, int nbad, const char *why,
                     int max_attempts, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1, segments = 0;
    svc_unit join;
    if (!why)
        why = "";
    pthread_mutex_lock(&s->mu);
    if (!tx_begin(s, &now, err))
        goto out;
    int l = lock_job(s, id, NULL, &segments, err);
    int have = l <= 0 ? l : owned_unit(s, id, owner, &join, err);
    bool ok = have >= 0, failed = false;
    if (have && join.kind != SVC_UNIT_JOIN)
        have = 0;
    for (int i = 0; ok && have && !failed && i < nbad; i++) {
        if (bad[i] < 0 || bad[i] >= segments)
            continue;
        sq_res r;
        ok = run(s, "find the segment", "SELECT " UNIT_COLS " FROM units WHERE job_id = ?1 AND idx = ?2 AND kind = 1",
                 ARGS(I(id), I(bad[i])), &r, err) >= 0 &&
             r.rows == 1;
        svc_unit u;
        if (ok)
            unit_from(&r, 0, &u);
        res_free(s, &r);
        if (!ok)
            break;
        if (u.attempts >= max_attempts) {
            /* it was rendered max_attempts times and is still bad: the
             * renderer, not luck; give up with its reason */
            char ctx[96], msg[SVC_ERROR_MAX + 160];
            svc_unit_context(ctx, sizeof ctx, &u);
            snprintf(msg, sizeof msg, "gave up after %d attempt%s: %s%s", u.attempts, u.attempts == 1 ? "" : "s", ctx,
                     why);
            ok = run(s, "fail the segment", "UPDATE units SET state = 3, error = ?3 WHERE job_id = ?1 AND idx = ?2",
                     ARGS(I(id), I(u.index), T(why)), NULL, err) >= 0 &&
                 fail_job(s, id, msg, -1, now, err);
            failed = true;
        } else
            ok = run(s, "re-queue the segment",
                     "UPDATE units SET state = 0, owner = '', frames_done = 0, fps = 0, claimed_until = 0,"
                     " done_attempt = 0, error = ?3 WHERE job_id = ?1 AND idx = ?2",
                     ARGS(I(id), I(u.index), T(why)), NULL, err) >= 0;
    }
    if (ok && have && !failed) {
        char msg[SVC_ERROR_MAX + 16];
        snprintf(msg, sizeof msg, "join: %s", why);
        ok = run(s, "the join waits again",
                 "UPDATE units SET state = 0, attempts = attempts - 1, owner = '', claimed_until = 0, fps = 0,"
                 " frames_done = 0, error = ?2 WHERE job_id = ?1 AND kind = 2",
                 ARGS(I(id), T(why)), NULL, err) >= 0 &&
             run(s, "note why", "UPDATE jobs SET error = ?2 WHERE id = ?1", ARGS(I(id), T(msg)), NULL, err) >= 0;
    }
    if (ok && have)
        ok = refresh(s, id, err);
    rc = tx_end(s, ok, have > 0, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_units(svc_store *bs, int64_t id, svc_unit *out, int max, rs_err *err)
{
    sq_store *s = S(bs);
    if (max <= 0)
        return 0;
    sq_res r;
    pthread_mutex_lock(&s->mu);
    int n = (int)run(s, "list the units", "SELECT " UNIT_COLS " FROM units WHERE job_id = ?1 ORDER BY idx LIMIT ?2",
                     ARGS(I(id), I(max)), &r, err);
    if (n >= 0) {
        n = r.rows < max ? r.rows : max;
        for (int i = 0; i < n; i++)
            unit_from(&r, i, &out[i]);
        res_free(s, &r);
    }
    pthread_mutex_unlock(&s->mu);
    return n < 0 ? -1 : n;
}

static int sq_get(svc_store *bs, int64_t id, svc_job *out, rs_err *err)
{
    sq_store *s = S(bs);
    sq_res r;
    pthread_mutex_lock(&s->mu);
    int rc = run(s, "get", "SELECT " SQ_JOB_COLS ", " EXTRA_COLS " FROM jobs WHERE id = ?1", ARGS(I(id)), &r, err) < 0 ? -1 : 0;
    if (rc == 0 && r.rows > 0) {
        job_from(&r, 0, out);
        extra_from(&r, 0, out);
        rc = 1;
    }
    if (rc >= 0)
        res_free(s, &r);
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_list(svc_store *bs, int64_t token_id, int64_t before, int limit, svc_job *out, rs_err *err)
{
    sq_store *s = S(bs);
    if (limit <= 0) /* PostgreSQL refuses a negative LIMIT */
        return 0;
    sq_res r;
    pthread_mutex_lock(&s->mu);
    /* 0 means "from the newest"; a plain id < ?1 keeps the primary key usable */
    int n = (int)run(s, "list",
                     "SELECT " SQ_JOB_COLS ", " EXTRA_COLS " FROM jobs WHERE id < ?1 AND (?3 = 0 OR token_id = ?3)"
                     " ORDER BY id DESC LIMIT ?2",
                     ARGS(I(before == 0 ? INT64_MAX : before), I(limit), I(token_id)), &r, err);
    if (n >= 0) {
        n = r.rows < limit ? r.rows : limit;
        for (int i = 0; i < n; i++) {
            job_from(&r, i, &out[i]);
            extra_from(&r, i, &out[i]);
        }
        res_free(s, &r);
    }
    pthread_mutex_unlock(&s->mu);
    return n < 0 ? -1 : n;
}

static int sq_cancel(svc_store *bs, int64_t id, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1, state = 0;
    pthread_mutex_lock(&s->mu);
    if (!tx_begin(s, &now, err))
        goto out;
    int l = lock_job(s, id, &state, NULL, err);
    bool ok = l >= 0, live = l > 0 && (state == SVC_QUEUED || state == SVC_RUNNING);
    if (ok && live)
        ok = run(s, "cancel", "UPDATE jobs SET state = 4, finished = ?2 WHERE id = ?1", ARGS(I(id), I(now)), NULL,
                 err) >= 0 &&
             end_units(s, id, err) && refresh(s, id, err);
    rc = tx_end(s, ok, l == 0 ? 0 : live ? 1 : 2, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_expiring(svc_store *bs, int64_t age_s, const char *host, int64_t *out, int max, rs_err *err)
{
    sq_store *s = S(bs);
    if (max <= 0)
        return 0;
    char like[SVC_OWNER_MAX + 4];
    snprintf(like, sizeof like, "%s:%%", host);
    sq_res r;
    pthread_mutex_lock(&s->mu);
    /* the WHOLE unit or the join made the video: its done_by names the host */
    int n = (int)run(s, "find expired videos",
                     "SELECT j.id FROM jobs j WHERE j.state = 2 AND j.expired = 0 AND j.finished < @NOW - ?1"
                     " AND EXISTS (SELECT 1 FROM units u WHERE u.job_id = j.id AND u.kind <> 1 AND u.done_by LIKE ?2)"
                     " ORDER BY j.finished, j.id LIMIT ?3",
                     ARGS(I(age_s), T(like), I(max)), &r, err);
    if (n >= 0) {
        n = r.rows < max ? r.rows : max;
        for (int i = 0; i < n; i++)
            out[i] = v_int(&r, i, 0);
        res_free(s, &r);
    }
    pthread_mutex_unlock(&s->mu);
    return n < 0 ? -1 : n;
}

static int sq_expire(svc_store *bs, int64_t id, rs_err *err)
{
    sq_store *s = S(bs);
    pthread_mutex_lock(&s->mu);
    int64_t n = run(s, "mark expired", "UPDATE jobs SET expired = 1 WHERE id = ?1 AND state = 2", ARGS(I(id)), NULL, err);
    pthread_mutex_unlock(&s->mu);
    return n < 0 ? -1 : n > 0;
}

static int sq_remove(svc_store *bs, int64_t id, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1, state = 0;
    pthread_mutex_lock(&s->mu);
    if (!tx_begin(s, &now, err))
        goto out;
    int l = lock_job(s, id, &state, NULL, err);
    bool ok = l >= 0, over = l > 0 && state != SVC_QUEUED && state != SVC_RUNNING;
    if (ok && over)
        ok = run(s, "remove the units", "DELETE FROM units WHERE job_id = ?1", ARGS(I(id)), NULL, err) >= 0 &&
             run(s, "remove the job", "DELETE FROM jobs WHERE id = ?1", ARGS(I(id)), NULL, err) >= 0;
    rc = tx_end(s, ok, l == 0 ? 0 : over ? 1 : 2, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static bool sq_counts(svc_store *bs, int64_t by_state[SVC_NSTATES], rs_err *err)
{
    sq_store *s = S(bs);
    sq_res r;
    memset(by_state, 0, sizeof(int64_t) * SVC_NSTATES);
    pthread_mutex_lock(&s->mu);
    bool ok = run(s, "counts", "SELECT state, COUNT(*) FROM jobs GROUP BY state", NOARGS, &r, err) >= 0;
    if (ok) {
        for (int i = 0; i < r.rows; i++) {
            int64_t k = v_int(&r, i, 0);
            if (k >= 0 && k < SVC_NSTATES)
                by_state[k] = v_int(&r, i, 1);
        }
        res_free(s, &r);
    }
    pthread_mutex_unlock(&s->mu);
    return ok;
}

static int sq_retry(svc_store *bs, int64_t id, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1, state = 0;
    pthread_mutex_lock(&s->mu);
    if (!tx_begin(s, &now, err))
        goto out;
    int l = lock_job(s, id, &state, NULL, err);
    bool ok = l >= 0, failed = l > 0 && state == SVC_FAILED;
    if (ok && failed)
        ok = run(s, "re-queue the units",
                 "UPDATE units SET state = 0, attempts = 0, lost = 0, error = '', owner = '', claimed_until = 0,"
                 " frames_done = 0, fps = 0, started = 0, finished = 0, done_by = '', done_attempt = 0"
                 " WHERE job_id = ?1",
                 ARGS(I(id)), NULL, err) >= 0 &&
             run(s, "re-queue the job",
                 "UPDATE jobs SET state = 0, error = '', desync_tick = -1, started = 0, finished = 0 WHERE id = ?1",
                 ARGS(I(id)), NULL, err) >= 0 &&
             refresh(s, id, err);
    rc = tx_end(s, ok, l == 0 ? 0 : failed ? 1 : 2, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_pending(svc_store *bs, svc_pending *out, int max, rs_err *err)
{
    sq_store *s = S(bs);
    if (max <= 0)
        return 0;
    sq_res r;
    pthread_mutex_lock(&s->mu);
    int n = (int)run(s, "list the queue",
                     "SELECT id, state, frames_total - frames_done FROM jobs WHERE state IN (0, 1) ORDER BY id LIMIT ?1",
                     ARGS(I(max)), &r, err);
    if (n >= 0) {
        n = r.rows < max ? r.rows : max;
        for (int i = 0; i < n; i++) {
            out[i].id = v_int(&r, i, 0);
            out[i].state = (int)v_int(&r, i, 1);
            out[i].frames_left = v_int(&r, i, 2) > 0 ? v_int(&r, i, 2) : 0;
        }
        res_free(s, &r);
    }
    pthread_mutex_unlock(&s->mu);
    return n < 0 ? -1 : n;
}

static bool sq_speed(svc_store *bs, int last, double *fps, rs_err *err)
{
    sq_store *s = S(bs);
    sq_res r;
    *fps = 0;
    pthread_mutex_lock(&s->mu);
    bool ok = run(s, "the recent render speed",
                  "SELECT CAST(COALESCE(SUM(frames_total), 0) AS BIGINT), CAST(COALESCE(SUM(finished - started), 0) AS BIGINT)"
                  " FROM (SELECT frames_total, finished, started FROM jobs WHERE state = 2 AND started > 0"
                  " AND finished > started ORDER BY finished DESC LIMIT ?1) recent",
                  ARGS(I(last)), &r, err) >= 0;
    if (ok) {
        if (r.rows == 1 && v_int(&r, 0, 1) > 0)
            *fps = (double)v_int(&r, 0, 0) / (double)v_int(&r, 0, 1);
        res_free(s, &r);
    }
    pthread_mutex_unlock(&s->mu);
    return ok;
}

/* --- API tokens --- */

#define TOKEN_COLS "id, name, is_operator, max_queued, seconds_per_hour, created, revoked, last_used"

static void token_from(const sq_res *r, int row, svc_token *t)
{
    memset(t, 0, sizeof *t);
    t->id = v_int(r, row, 0);
    v_text(t->name, sizeof t->name, r, row, 1);
    t->is_operator = v_int(r, row, 2) != 0;
    t->max_queued = (int)v_int(r, row, 3);
    t->seconds_per_hour = (int)v_int(r, row, 4);
    t->created = v_int(r, row, 5);
    t->revoked = v_int(r, row, 6);
    t->last_used = v_int(r, row, 7);
}

/* The first row of a token query into out.  1, 0 (no row), -1. */
static int token_row(sq_store *s, const char *what, const char *sql, const sq_val *a, int n, svc_token *out,
                     rs_err *err)
{
    sq_res r;
    if (run(s, what, sql, a, n, &r, err) < 0)
        return -1;
    int rc = r.rows > 0;
    if (rc && out)
        token_from(&r, 0, out);
    res_free(s, &r);
    return rc;
}

static int sq_token_add(svc_store *bs, svc_token *t, const char *hash, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1;
    pthread_mutex_lock(&s->mu);
    if (!tx_begin(s, &now, err))
        goto out;
    int taken = token_row(s, "look for the name", "SELECT " TOKEN_COLS " FROM tokens WHERE name = ?1@LOCK",
                          ARGS(T(t->name)), NULL, err);
    sq_res r = {0};
    bool ok = taken >= 0;
    if (ok && !taken)
        ok = run(s, "add the token",
                 "INSERT INTO tokens (name, hash, is_operator, max_queued, seconds_per_hour, created)"
                 " VALUES (?1, ?2, ?3, ?4, ?5, ?6) RETURNING id",
                 ARGS(T(t->name), T(hash), I(t->is_operator), I(t->max_queued), I(t->seconds_per_hour), I(now)), &r,
                 err) >= 0 &&
             r.rows == 1;
    if (ok && !taken) {
        t->id = v_int(&r, 0, 0);
        t->created = now;
        t->revoked = t->last_used = 0;
    }
    res_free(s, &r);
    rc = tx_end(s, ok, !taken, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_token_list(svc_store *bs, svc_token *out, int max, rs_err *err)
{
    sq_store *s = S(bs);
    if (max <= 0)
        return 0;
    sq_res r;
    pthread_mutex_lock(&s->mu);
    int n = (int)run(s, "list the tokens", "SELECT " TOKEN_COLS " FROM tokens ORDER BY id LIMIT ?1", ARGS(I(max)), &r,
                     err);
    if (n >= 0) {
        n = r.rows < max ? r.rows : max;
        for (int i = 0; i < n; i++)
            token_from(&r, i, &out[i]);
        res_free(s, &r);
    }
    pthread_mutex_unlock(&s->mu);
    return n < 0 ? -1 : n;
}

static int sq_token_revoke(svc_store *bs, const char *which, svc_token *out, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1;
    /* a name first: "7" may be a token's name as well as another's id */
    char *end;
    long long id = strtoll(which, &end, 10);
    if (*end || end == which)
        id = -1;
    pthread_mutex_lock(&s->mu);
    if (!tx_begin(s, &now, err))
        goto out;
    int have = token_row(s, "find the token", "SELECT " TOKEN_COLS " FROM tokens WHERE name = ?1@LOCK",
                         ARGS(T(which)), out, err);
    if (have == 0)
        have = token_row(s, "find the token", "SELECT " TOKEN_COLS " FROM tokens WHERE id = ?1@LOCK", ARGS(I(id)), out,
                         err);
    bool ok = have >= 0, already = have > 0 && out->revoked != 0;
    if (ok && have && !already) {
        ok = run(s, "revoke the token", "UPDATE tokens SET revoked = ?2 WHERE id = ?1", ARGS(I(out->id), I(now)), NULL,
                 err) >= 0;
        out->revoked = now;
    }
    rc = tx_end(s, ok, !have ? 0 : already ? 2 : 1, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_token_find(svc_store *bs, const char *hash, svc_token *out, rs_err *err)
{
    sq_store *s = S(bs);
    pthread_mutex_lock(&s->mu);
    int rc = token_row(s, "find the token", "SELECT " TOKEN_COLS " FROM tokens WHERE hash = ?1", ARGS(T(hash)), out,
                       err);
    /* last_used to the minute: a write per request would cost a commit each */
    if (rc == 1 && !out->revoked &&
        run(s, "note the token's use", "UPDATE tokens SET last_used = @NOW WHERE id = ?1 AND last_used < @NOW - 60",
            ARGS(I(out->id)), NULL, err) < 0)
        rc = -1;
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int64_t sq_token_active(svc_store *bs, rs_err *err)
{
    sq_store *s = S(bs);
    sq_res r;
    pthread_mutex_lock(&s->mu);
    int64_t n = run(s, "count the tokens", "SELECT COUNT(*) FROM tokens WHERE revoked = 0", NOARGS, &r, err);
    if (n >= 0) {
        n = r.rows == 1 ? v_int(&r, 0, 0) : 0;
        res_free(s, &r);
    }
    pthread_mutex_unlock(&s->mu);
    return n;
}

static bool sq_token_usage(svc_store *bs, int64_t token_id, svc_usage *out, rs_err *err)
{
    sq_store *s = S(bs);
    sq_res r;
    pthread_mutex_lock(&s->mu);
    bool ok = run(s, "measure the token's use",
                  "SELECT (SELECT COUNT(*) FROM jobs WHERE token_id = ?1 AND state IN (0, 1)),"
                  " (SELECT CAST(COALESCE(SUM(frames_total), 0) AS BIGINT) FROM jobs"
                  "   WHERE token_id = ?1 AND created > @NOW - 3600),"
                  " (SELECT COALESCE(MIN(created), 0) FROM jobs WHERE token_id = ?1 AND created > @NOW - 3600), @NOW",
                  ARGS(I(token_id)), &r, err) >= 0 &&
              r.rows == 1;
    if (ok)
        *out = (svc_usage){.active = v_int(&r, 0, 0), .hour_frames = v_int(&r, 0, 1), .oldest = v_int(&r, 0, 2),
                           .now = v_int(&r, 0, 3)};
    res_free(s, &r);
    pthread_mutex_unlock(&s->mu);
    return ok;
}

static void sq_close(svc_store *bs)
{
    sq_store *s = S(bs);
    if (!s)
        return;
    s->drv->close(s->c);
    pthread_mutex_destroy(&s->mu);
    free(s);
}

static const svc_store_ops sq_ops = {
    .submit = sq_submit,
    .claim = sq_claim,
    .heartbeat = sq_heartbeat,
    .finish = sq_finish,
    .release = sq_release,
    .reap = sq_reap,
    .rejoin = sq_rejoin,
    .units = sq_units,
    .get = sq_get,
    .list = sq_list,
    .cancel = sq_cancel,
    .expiring = sq_expiring,
    .expire = sq_expire,
    .remove = sq_remove,
    .counts = sq_counts,
    .retry = sq_retry,
    .pending = sq_pending,
    .speed = sq_speed,
    .token_add = sq_token_add,
    .token_list = sq_token_list,
    .token_revoke = sq_token_revoke,
    .token_find = sq_token_find,
    .token_active = sq_token_active,
    .token_usage = sq_token_usage,
    .close = sq_close,
};

svc_store *sq_store_new(const sq_driver *drv, void *c, rs_err *err)
{
    sq_store *s = calloc(1, sizeof *s);
    if (!s) {
        drv->close(c);
        rs_fail(err, SVC_STORE_ERR_NOMEM, "out of memory");
        return NULL;
    }
    s->ops = sq_ops;
    s->ops.name = drv->name;
    s->base.ops = &s->ops;
    s->drv = drv;
    s->c = c;
    pthread_mutex_init(&s->mu, NULL);
    return &s->base;
}

bool sq_schema_units(const sq_driver *drv, void *c, bool migrate, rs_err *err)
{
    static const char *const add[] = {
        "ALTER TABLE jobs ADD COLUMN segment_ticks INTEGER NOT NULL DEFAULT 0",
        "ALTER TABLE jobs ADD COLUMN segments INTEGER NOT NULL DEFAULT 0",
        "ALTER TABLE jobs ADD COLUMN seg_key TEXT NOT NULL DEFAULT ''",
    };
    for (int i = 0; migrate && i < 3; i++)
        if (drv->exec(c, "add a column to jobs", add[i], NULL, 0, NULL, err) < 0)
            return false;
    if (drv->exec(c, "create the units table",
                  "CREATE TABLE IF NOT EXISTS units ("
                  " job_id BIGINT NOT NULL, idx INTEGER NOT NULL, kind INTEGER NOT NULL,"
                  " first_tick BIGINT NOT NULL, end_tick BIGINT NOT NULL,"
                  " state INTEGER NOT NULL DEFAULT 0, attempts INTEGER NOT NULL DEFAULT 0,"
                  " owner TEXT NOT NULL DEFAULT '', claimed_until BIGINT NOT NULL DEFAULT 0,"
                  " started BIGINT NOT NULL DEFAULT 0, finished BIGINT NOT NULL DEFAULT 0,"
                  " frames_done BIGINT NOT NULL DEFAULT 0, fps DOUBLE PRECISION NOT NULL DEFAULT 0,"
                  " error TEXT NOT NULL DEFAULT '', renders INTEGER NOT NULL DEFAULT 0,"
                  " done_by TEXT NOT NULL DEFAULT '', done_attempt INTEGER NOT NULL DEFAULT 0,"
                  " PRIMARY KEY (job_id, idx))",
                  NULL, 0, NULL, err) < 0 ||
        drv->exec(c, "create the units index", "CREATE INDEX IF NOT EXISTS units_state ON units (state, job_id, idx)",
                  NULL, 0, NULL, err) < 0)
        return false;
    /* a queue from before units: its unfinished jobs become WHOLE units,
     * running ones still held by their owners (their leases run on) */
    return !migrate ||
           drv->exec(c, "make units of the queued jobs",
                     "INSERT INTO units (job_id, idx, kind, first_tick, end_tick, state, attempts, owner,"
                     " claimed_until, started, frames_done, fps, error)"
                     " SELECT id, 0, 0, 0, frames_total, state, attempts, owner, claimed_until, started, frames_done,"
                     " fps, error FROM jobs WHERE state IN (0, 1)",
                     NULL, 0, NULL, err) >= 0;
}

bool sq_schema_lost(const sq_driver *drv, void *c, const char *has_column, rs_err *err)
{
    static const char *const cols[][3] = {
        {"units", "lost", "ALTER TABLE units ADD COLUMN lost INTEGER NOT NULL DEFAULT 0"},
        {"jobs", "lost", "ALTER TABLE jobs ADD COLUMN lost INTEGER NOT NULL DEFAULT 0"},
        {"jobs", "expired", "ALTER TABLE jobs ADD COLUMN expired INTEGER NOT NULL DEFAULT 0"},
    };
    for (int i = 0; i < 3; i++) {
        sq_res r = {0};
        sq_val a[2] = {{.type = SQ_TEXT, .s = cols[i][0]}, {.type = SQ_TEXT, .s = cols[i][1]}};
        if (drv->exec(c, "look for a column", has_column, a, 2, &r, err) < 0)
            return false;
        bool have = r.rows == 1 && r.v[0].i > 0;
        drv->res_free(&r);
        if (!have && drv->exec(c, "add a column", cols[i][2], NULL, 0, NULL, err) < 0)
            return false;
    }
    return true;
}

bool sq_schema_meta(const sq_driver *drv, void *c, const char *has_column, rs_err *err)
{
    static const char *const cols[][2] = {
        {"stage", "ALTER TABLE jobs ADD COLUMN stage INTEGER NOT NULL DEFAULT -1"},
        {"kind1", "ALTER TABLE jobs ADD COLUMN kind1 INTEGER NOT NULL DEFAULT 0"},
        {"kind2", "ALTER TABLE jobs ADD COLUMN kind2 INTEGER NOT NULL DEFAULT 0"},
        {"winner", "ALTER TABLE jobs ADD COLUMN winner INTEGER NOT NULL DEFAULT -1"},
        {"rounds1", "ALTER TABLE jobs ADD COLUMN rounds1 INTEGER NOT NULL DEFAULT 0"},
        {"rounds2", "ALTER TABLE jobs ADD COLUMN rounds2 INTEGER NOT NULL DEFAULT 0"},
        /* the encoder options the job asked for ("codec=hevc crf=24"; svc_encode_argv) */
        {"encode", "ALTER TABLE jobs ADD COLUMN encode TEXT NOT NULL DEFAULT ''"},
    };
    for (size_t i = 0; i < sizeof cols / sizeof *cols; i++) {
        sq_res r = {0};
        sq_val a[2] = {{.type = SQ_TEXT, .s = "jobs"}, {.type = SQ_TEXT, .s = cols[i][0]}};
        if (drv->exec(c, "look for a column", has_column, a, 2, &r, err) < 0)
            return false;
        bool have = r.rows == 1 && r.v[0].i > 0;
        drv->res_free(&r);
        if (!have && drv->exec(c, "add a column", cols[i][1], NULL, 0, NULL, err) < 0)
            return false;
    }
    return true;
}

bool sq_schema_tokens(const sq_driver *drv, void *c, const char *serial, bool migrate, rs_err *err)
{
    char sql[1024];
    snprintf(sql, sizeof sql,
             "CREATE TABLE IF NOT EXISTS tokens ("
             " id %s, name TEXT NOT NULL UNIQUE, hash TEXT NOT NULL UNIQUE,"
             " is_operator INTEGER NOT NULL DEFAULT 0, max_queued INTEGER NOT NULL DEFAULT 0,"
             " seconds_per_hour INTEGER NOT NULL DEFAULT 0, created BIGINT NOT NULL DEFAULT 0,"
             " revoked BIGINT NOT NULL DEFAULT 0, last_used BIGINT NOT NULL DEFAULT 0)",
             serial);
    return (!migrate || drv->exec(c, "add a column to jobs", "ALTER TABLE jobs ADD COLUMN token_id BIGINT NOT NULL DEFAULT 0",
                                  NULL, 0, NULL, err) >= 0) &&
           drv->exec(c, "create the tokens table", sql, NULL, 0, NULL, err) >= 0 &&
           drv->exec(c, "create the jobs' token index", "CREATE INDEX IF NOT EXISTS jobs_token ON jobs (token_id, created)",
                     NULL, 0, NULL, err) >= 0;
}

bool sq_spell(char *out, size_t n, const char *sql, const char *now, const char *lock, const char *skip, bool dollar)
{
    static const char *const names[] = {"@NOW", "@LOCK", "@SKIP"};
    const char *vals[] = {now, lock, skip};
    size_t k = 0;
    for (const char *p = sql; *p;) {
        const char *put = NULL;
        size_t skiplen = 1;
        for (int t = 0; t < 3 && !put; t++)
            if (!strncmp(p, names[t], strlen(names[t])))
                put = vals[t], skiplen = strlen(names[t]);
        char one[2] = {*p, 0};
        if (!put) {
            if (dollar && *p == '?' && p[1] >= '0' && p[1] <= '9')
                one[0] = '$';
            put = one;
        }
        size_t m = strlen(put);
        if (k + m + 1 > n)
            return false;
        memcpy(out + k, put, m);
        k += m;
        p += skiplen;
    }
    out[k] = 0;
    return true;
}
