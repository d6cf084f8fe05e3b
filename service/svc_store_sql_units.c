/* svc_store_sql_units: the units' lifecycle (svc_store.h, "Units"): the
 * claim, a worker's heartbeat, finish and release, the reaper's lost
 * leases, and the join's verdict on bad segments (rejoin).  Each change
 * locks its job, changes units, then sums the job up again (sq_refresh);
 * svc_store_sql.c says why in that order. */
#include <inttypes.h>
#include <stdlib.h>

#include "svc_store_sql_impl.h"

/* The job's row from its units: state while not over, the most attempts,
 * frames and fps summed, a running unit's owner and lease. */
bool sq_refresh(sq_store *s, int64_t id, rs_err *err)
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
    return sq_rows(s, "find the unit", "SELECT " UNIT_COLS " FROM units WHERE job_id = ?1 AND owner = ?2 AND state = 1",
                   ARGS(I(id), T(owner)), sq_unit_row, u, 1, err);
}

/* The job is over (failed or cancelled): its units that were still to do
 * are cancelled, so their owners' heartbeats answer "not ours". */
bool sq_end_units(sq_store *s, int64_t id, rs_err *err)
{
    /* what its units made goes with them; its render log stays */
    return run(s, "cancel the job's units",
               "UPDATE units SET state = 4, claimed_until = 0, fps = 0 WHERE job_id = ?1 AND state IN (0, 1)",
               ARGS(I(id)), NULL, err) >= 0 &&
           run(s, "remove the job's stored files", "DELETE FROM job_files WHERE job_id = ?1 AND name <> 'log'",
               ARGS(I(id)), NULL, err) >= 0;
}

static bool fail_job(sq_store *s, int64_t id, const char *why, int64_t desync, int64_t now, rs_err *err)
{
    return sq_end_units(s, id, err) &&
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

/* row 0 of the claim's pick: the unit's job and index */
static void pick_row(void *dst, const sq_res *r, int i)
{
    int64_t *pick = dst;
    pick[0] = v_int(r, i, 0);
    pick[1] = v_int(r, i, 1);
}

/* The claimed job and a copy of its replay (the column after
 * SQ_JOB_COLS); replay stays NULL when there is no memory for it. */
static void claimed_row(void *dst, const sq_res *r, int i)
{
    svc_job *j = dst;
    sq_job_from(r, i, j);
    const sq_val *rp = cell(r, i, 23);
    size_t n = rp->type == SQ_BLOB || rp->type == SQ_TEXT ? rp->n : 0;
    j->replay = malloc(n > 0 ? n : 1);
    if (j->replay) {
        if (n)
            memcpy(j->replay, rp->s, n);
        j->replay_len = n;
    }
}

/* One try at a claim: 1 claimed, 0 nothing queued, 2 lost a race (try
 * again), -1 error. */
static int claim_once(sq_store *s, const char *owner, int lease_s, svc_job *out, rs_err *err)
{
    int64_t now;
    if (!sq_tx_begin(s, &now, err))
        return -1;
    /* the queued unit of the oldest job that has one; a join only once
     * every segment of its job is done */
    int64_t pick[2];
    int picked = sq_rows(s, "claim",
                         "SELECT u.job_id, u.idx FROM units u JOIN jobs j ON j.id = u.job_id"
                         " WHERE u.state = 0 AND j.state IN (0, 1) AND (u.kind <> 2 OR NOT EXISTS"
                         "   (SELECT 1 FROM units d WHERE d.job_id = u.job_id AND d.kind = 1 AND d.state <> 2))"
                         " ORDER BY u.job_id, u.idx LIMIT 1@SKIP",
                         NOARGS, pick_row, pick, 1, err);
    if (picked <= 0)
        return sq_tx_end(s, picked == 0, 0, err);
    int64_t id = pick[0], idx = pick[1];
    int64_t got = run(s, "claim the unit",
                      "UPDATE units SET state = 1, owner = ?3, attempts = attempts + 1, frames_done = 0, fps = 0,"
                      " started = ?4, claimed_until = ?4 + ?5, finished = 0"
                      " WHERE job_id = ?1 AND idx = ?2 AND state = 0",
                      ARGS(I(id), I(idx), T(owner), I(now), I(lease_s)), NULL, err);
    if (got <= 0) {
        s->drv->rollback(s->c);
        return got < 0 ? -1 : 2;
    }
    bool ok = run(s, "start the job", "UPDATE jobs SET started = ?2 WHERE id = ?1 AND state = 0", ARGS(I(id), I(now)),
                  NULL, err) >= 0 &&
              sq_refresh(s, id, err) &&
              sq_rows(s, "read the claimed job", "SELECT " SQ_JOB_COLS ", replay FROM jobs WHERE id = ?1", ARGS(I(id)),
                      claimed_row, out, 1, err) == 1;
    if (ok && !out->replay)
        ok = rs_fail(err, SVC_STORE_ERR_NOMEM, "out of memory reading job %" PRId64 "'s replay", id);
    ok = ok && sq_rows(s, "read the claimed unit", "SELECT " UNIT_COLS " FROM units WHERE job_id = ?1 AND idx = ?2",
                       ARGS(I(id), I(idx)), sq_unit_row, &out->unit, 1, err) == 1;
    int rc = sq_tx_end(s, ok, 1, err);
    if (rc != 1)
        svc_job_free(out);
    return rc;
}

int sq_claim(svc_store *bs, const char *owner, int lease_s, svc_job *out, rs_err *err)
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

int sq_heartbeat(svc_store *bs, int64_t id, const char *owner, int lease_s, int64_t done, int64_t total, double fps,
                 rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1;
    if (!(fps == fps && fps < 1e300 && fps > -1e300))
        fps = 0; /* NaN or inf from a worker that divided by a zero time */
    pthread_mutex_lock(&s->mu);
    if (!sq_tx_begin(s, &now, err))
        goto out;
    int l = sq_lock_job(s, id, NULL, NULL, err);
    int64_t ch = l <= 0 ? l
                        : run(s, "heartbeat",
                              "UPDATE units SET claimed_until = ?3 + ?4, frames_done = ?5, fps = ?6"
                              " WHERE job_id = ?1 AND owner = ?2 AND state = 1",
                              ARGS(I(id), T(owner), I(now), I(lease_s), I(done), R(fps)), NULL, err);
    bool ok = ch >= 0;
    if (ok && ch > 0)
        ok = run(s, "heartbeat", "UPDATE jobs SET frames_total = ?2 WHERE id = ?1 AND segments = 0",
                 ARGS(I(id), I(total)), NULL, err) >= 0 &&
             sq_refresh(s, id, err);
    rc = sq_tx_end(s, ok, ch > 0, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

int sq_finish(svc_store *bs, int64_t id, const char *owner, int state, const char *error, int64_t desync, int64_t done,
              rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1;
    svc_unit u;
    if (!error)
        error = "";
    pthread_mutex_lock(&s->mu);
    if (!sq_tx_begin(s, &now, err))
        goto out;
    int l = sq_lock_job(s, id, NULL, NULL, err);
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
        ok = sq_refresh(s, id, err);
    rc = sq_tx_end(s, ok, have > 0, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

int sq_release(svc_store *bs, int64_t id, const char *owner, const char *why, bool count_attempt, int max_attempts,
               rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1;
    svc_unit u;
    pthread_mutex_lock(&s->mu);
    if (!sq_tx_begin(s, &now, err))
        goto out;
    int l = sq_lock_job(s, id, NULL, NULL, err);
    int have = l <= 0 ? l : owned_unit(s, id, owner, &u, err);
    bool ok = have >= 0;
    if (ok && have)
        ok = release_unit(s, id, &u, why ? why : "", count_attempt, max_attempts, now, err) && sq_refresh(s, id, err);
    rc = sq_tx_end(s, ok, have > 0, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

int sq_reap(svc_store *bs, bool all, svc_reaped *out, int max, rs_err *err)
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
        if (!sq_tx_begin(s, &now, err)) {
            n = -1;
            break;
        }
        svc_unit u;
        int l = sq_lock_job(s, id, NULL, NULL, err);
        int hit = l < 0 ? -1
                        : sq_rows(s, "find the expired unit",
                                  "SELECT " UNIT_COLS " FROM units WHERE job_id = ?1 AND idx = ?2 AND state = 1"
                                  " AND owner = ?3 AND (?4 <> 0 OR claimed_until < ?5)",
                                  ARGS(I(id), I(v_int(&r, i, 1)), T(owner), I(all), I(now)), sq_unit_row, &u, 1, err);
        bool ok = hit >= 0, failed = false;
        if (hit > 0)
            ok = lose_unit(s, id, &u, now, &failed, err) && sq_refresh(s, id, err);
        if (sq_tx_end(s, ok, 1, err) < 0)
            n = -1;
        else if (hit > 0) {
            if (out && n < max)
                out[n] = (svc_reaped){.id = id, .unit = u, .failed = failed};
            n++;
        }
    }
    res_free(s, &r);
    pthread_mutex_unlock(&s->mu);
    return n;
}

int sq_rejoin(svc_store *bs, int64_t id, const char *owner, const int *bad, int nbad, const char *why, int max_attempts,
              rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1, segments = 0;
    svc_unit join;
    if (!why)
        why = "";
    pthread_mutex_lock(&s->mu);
    if (!sq_tx_begin(s, &now, err))
        goto out;
    int l = sq_lock_job(s, id, NULL, &segments, err);
    int have = l <= 0 ? l : owned_unit(s, id, owner, &join, err);
    bool ok = have >= 0, failed = false;
    if (have && join.kind != SVC_UNIT_JOIN)
        have = 0;
    for (int i = 0; ok && have && !failed && i < nbad; i++) {
        if (bad[i] < 0 || bad[i] >= segments)
            continue;
        svc_unit u;
        ok = sq_rows(s, "find the segment",
                     "SELECT " UNIT_COLS " FROM units WHERE job_id = ?1 AND idx = ?2 AND kind = 1",
                     ARGS(I(id), I(bad[i])), sq_unit_row, &u, 1, err) == 1;
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
        ok = sq_refresh(s, id, err);
    rc = sq_tx_end(s, ok, have > 0, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

int sq_redo(svc_store *bs, int64_t id, int index, const char *why, int max_attempts, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1, state = 0;
    pthread_mutex_lock(&s->mu);
    if (sq_tx_begin(s, &now, err)) {
        int l = sq_lock_job(s, id, &state, NULL, err);
        int64_t n = 0;
        bool ok = l >= 0;
        if (l > 0 && (state == SVC_QUEUED || state == SVC_RUNNING))
            ok = (n = run(s, "re-queue the segment",
                          "UPDATE units SET state = 0, owner = '', frames_done = 0, fps = 0, claimed_until = 0,"
                          " done_attempt = 0, error = ?3 WHERE job_id = ?1 AND idx = ?2 AND kind = 1 AND state = 2"
                          " AND attempts < ?4",
                          ARGS(I(id), I(index), T(why ? why : ""), I(max_attempts)), NULL, err)) >= 0;
        if (ok && n > 0)
            ok = run(s, "the join waits again",
                     "UPDATE units SET state = 0, attempts = attempts - 1, owner = '', claimed_until = 0, fps = 0,"
                     " frames_done = 0 WHERE job_id = ?1 AND kind = 2 AND state = 1",
                     ARGS(I(id)), NULL, err) >= 0 &&
                 sq_refresh(s, id, err);
        rc = sq_tx_end(s, ok, n > 0, err);
    }
    pthread_mutex_unlock(&s->mu);
    return rc;
}
