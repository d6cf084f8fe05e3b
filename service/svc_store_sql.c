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
 * worst a wasted render (see svc_store_pg.c).
 *
 * This file holds the handle, reading rows and the transactions; the ops
 * are in svc_store_sql_jobs.c, _units.c and _tokens.c, the schema in
 * _schema.c (svc_store_sql_impl.h lists them). */
#include <inttypes.h>
#include <stdlib.h>

#include "svc_store_sql_impl.h"

/* --- reading rows --- */

int sq_rows(sq_store *s, const char *what, const char *sql, const sq_val *a, int n, sq_row_fn *fn, void *dst, int max,
            rs_err *err)
{
    sq_res r;
    if (run(s, what, sql, a, n, &r, err) < 0) {
        res_free(s, &r);
        return -1;
    }
    int k = r.rows < max ? r.rows : max;
    for (int i = 0; fn && i < k; i++)
        fn(dst, &r, i);
    res_free(s, &r);
    return k;
}

int sq_query(sq_store *s, const char *what, const char *sql, const sq_val *a, int n, sq_row_fn *fn, void *dst, int max,
             rs_err *err)
{
    pthread_mutex_lock(&s->mu);
    int k = sq_rows(s, what, sql, a, n, fn, dst, max, err);
    pthread_mutex_unlock(&s->mu);
    return k;
}

void sq_int_row(void *dst, const sq_res *r, int i)
{
    ((int64_t *)dst)[i] = v_int(r, i, 0);
}

/* --- rows into the store's types --- */

void sq_job_from(const sq_res *r, int row, svc_job *j)
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

void sq_job_row(void *dst, const sq_res *r, int i)
{
    svc_job *j = (svc_job *)dst + i;
    sq_job_from(r, i, j);
    extra_from(r, i, j);
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

void sq_unit_row(void *dst, const sq_res *r, int i)
{
    unit_from(r, i, (svc_unit *)dst + i);
}

/* --- transactions --- */

bool sq_tx_begin(sq_store *s, int64_t *now, rs_err *err)
{
    if (!s->drv->begin(s->c, err))
        return false;
    if (sq_rows(s, "read the clock", "SELECT @NOW", NOARGS, sq_int_row, now, 1, err) != 1) {
        s->drv->rollback(s->c);
        return false;
    }
    return true;
}

int sq_tx_end(sq_store *s, bool ok, int rc, rs_err *err)
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

static void lock_row(void *dst, const sq_res *r, int i)
{
    int *got = dst;
    got[0] = (int)v_int(r, i, 0);
    got[1] = (int)v_int(r, i, 1);
}

int sq_lock_job(sq_store *s, int64_t id, int *state, int *segments, rs_err *err)
{
    int got[2];
    int rc = sq_rows(s, "lock the job", "SELECT state, segments FROM jobs WHERE id = ?1@LOCK", ARGS(I(id)), lock_row,
                     got, 1, err);
    if (rc > 0) {
        if (state)
            *state = got[0];
        if (segments)
            *segments = got[1];
    }
    return rc;
}

/* --- the handle --- */

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
    .redo = sq_redo,
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
    .file_put = sq_file_put,
    .file_get = sq_file_get,
    .file_append = sq_file_append,
    .file_drop = sq_file_drop,
    .file_bytes = sq_file_bytes,
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
