/* svc_store_sql_impl: what the SQL store's files share, private to them.
 *
 *   svc_store_sql.c         the handle, reading rows, transactions, the ops table
 *   svc_store_sql_jobs.c    submit, and the reads and changes of a whole job
 *   svc_store_sql_units.c   the units' lifecycle: claim, heartbeat, finish,
 *                           release, reap, rejoin
 *   svc_store_sql_tokens.c  API tokens and their use
 *   svc_store_sql_files.c   a job's files kept in the queue
 *   svc_store_sql_schema.c  tables, migrations, and spelling a statement
 *
 * A read is one call: sq_query runs the statement under the handle's lock
 * and hands each row to a row function (sq_rows does the same inside a
 * transaction the caller holds). */
#ifndef SVC_STORE_SQL_IMPL_H
#define SVC_STORE_SQL_IMPL_H

#include <pthread.h>
#include <stdio.h>
#include <string.h>

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

/* get and list read token_id and the replay's header after SQ_JOB_COLS
 * (the claim needs neither) */
#define TOKEN_COL 23 /* SQ_JOB_COLS has 23 columns */
#define EXTRA_COLS "token_id, stage, kind1, kind2, winner, rounds1, rounds2"

static inline int64_t run(sq_store *s, const char *what, const char *sql, const sq_val *a, int n, sq_res *out,
                          rs_err *err)
{
    if (out)
        memset(out, 0, sizeof *out);
    return s->drv->exec(s->c, what, sql, a, n, out, err);
}

static inline void res_free(sq_store *s, sq_res *r)
{
    if (r->own || r->v)
        s->drv->res_free(r);
    memset(r, 0, sizeof *r);
}

static inline const sq_val *cell(const sq_res *r, int row, int col)
{
    return &r->v[row * r->cols + col];
}

static inline int64_t v_int(const sq_res *r, int row, int col)
{
    return cell(r, row, col)->i;
}

static inline void v_text(char *dst, size_t n, const sq_res *r, int row, int col)
{
    const sq_val *v = cell(r, row, col);
    snprintf(dst, n, "%s", v->type == SQ_TEXT && v->s ? v->s : "");
}

/* Row i of a result into the caller's dst (for a list, dst is an array
 * and row i goes to its element i). */
typedef void sq_row_fn(void *dst, const sq_res *r, int i);

/* One statement, its first max rows handed to fn (none when fn is NULL),
 * its result freed.  The rows handed (0..max), or -1 with err filled.
 * The caller holds the handle's lock. */
int sq_rows(sq_store *s, const char *what, const char *sql, const sq_val *a, int n, sq_row_fn *fn, void *dst, int max,
            rs_err *err);
/* sq_rows under the handle's lock: a read on its own. */
int sq_query(sq_store *s, const char *what, const char *sql, const sq_val *a, int n, sq_row_fn *fn, void *dst, int max,
             rs_err *err);

/* Row functions for sq_rows and sq_query. */
sq_row_fn sq_int_row; /* int64_t[]: the first column */
void sq_job_from(const sq_res *r, int row, svc_job *j); /* SQ_JOB_COLS */
sq_row_fn sq_job_row;  /* svc_job[]: SQ_JOB_COLS, EXTRA_COLS */
sq_row_fn sq_unit_row; /* svc_unit[]: UNIT_COLS */

/* A write transaction with the database's clock read into *now. */
bool sq_tx_begin(sq_store *s, int64_t *now, rs_err *err);
/* Commits when ok, rolls back when not; returns rc, or -1 when the
 * commit fails. */
int sq_tx_end(sq_store *s, bool ok, int rc, rs_err *err);
/* Locks job id's row.  1: locked (its segment count in *segments, its
 * state in *state); 0: no such job; -1. */
int sq_lock_job(sq_store *s, int64_t id, int *state, int *segments, rs_err *err);
/* The job's row from its units (the caller holds the job's lock). */
bool sq_refresh(sq_store *s, int64_t id, rs_err *err);
/* The job is over: its units still to do are cancelled. */
bool sq_end_units(sq_store *s, int64_t id, rs_err *err);

/* The ops (svc_store.h), by file. */
bool sq_submit(svc_store *bs, svc_job *j, rs_err *err);
int sq_units(svc_store *bs, int64_t id, svc_unit *out, int max, rs_err *err);
int sq_get(svc_store *bs, int64_t id, svc_job *out, rs_err *err);
int sq_list(svc_store *bs, int64_t token_id, int64_t before, int limit, svc_job *out, rs_err *err);
int sq_cancel(svc_store *bs, int64_t id, rs_err *err);
int sq_expiring(svc_store *bs, int64_t age_s, const char *host, int64_t *out, int max, rs_err *err);
int sq_expire(svc_store *bs, int64_t id, rs_err *err);
int sq_remove(svc_store *bs, int64_t id, rs_err *err);
bool sq_counts(svc_store *bs, int64_t by_state[SVC_NSTATES], rs_err *err);
int sq_retry(svc_store *bs, int64_t id, rs_err *err);
int sq_pending(svc_store *bs, svc_pending *out, int max, rs_err *err);
bool sq_speed(svc_store *bs, int last, double *fps, rs_err *err);

int sq_claim(svc_store *bs, const char *owner, int lease_s, svc_job *out, rs_err *err);
int sq_heartbeat(svc_store *bs, int64_t id, const char *owner, int lease_s, int64_t done, int64_t total, double fps,
                 rs_err *err);
int sq_finish(svc_store *bs, int64_t id, const char *owner, int state, const char *error, int64_t desync,
              int64_t done, rs_err *err);
int sq_release(svc_store *bs, int64_t id, const char *owner, const char *why, bool count_attempt, int max_attempts,
               rs_err *err);
int sq_reap(svc_store *bs, bool all, svc_reaped *out, int max, rs_err *err);
int sq_redo(svc_store *bs, int64_t id, int index, const char *why, int max_attempts, rs_err *err);
int sq_rejoin(svc_store *bs, int64_t id, const char *owner, const int *bad, int nbad, const char *why,
              int max_attempts, rs_err *err);

int sq_token_add(svc_store *bs, svc_token *t, const char *hash, rs_err *err);
int sq_token_list(svc_store *bs, svc_token *out, int max, rs_err *err);
int sq_token_revoke(svc_store *bs, const char *which, svc_token *out, rs_err *err);
int sq_token_find(svc_store *bs, const char *hash, svc_token *out, rs_err *err);
int64_t sq_token_active(svc_store *bs, rs_err *err);
bool sq_token_usage(svc_store *bs, int64_t token_id, svc_usage *out, rs_err *err);

int sq_file_put(svc_store *bs, int64_t id, const svc_file *files, int n, const char *keep, rs_err *err);
int sq_file_get(svc_store *bs, int64_t id, const char *name, const char *path, rs_err *err);
int sq_file_append(svc_store *bs, int64_t id, const char *name, const void *data, size_t len, rs_err *err);
int64_t sq_file_drop(svc_store *bs, int64_t id, const char *prefix, rs_err *err);
int64_t sq_file_bytes(svc_store *bs, int64_t id, rs_err *err);

#endif
