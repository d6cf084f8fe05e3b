/* svc_store_sql: the queue's rules (svc_store.h) written once, in the SQL
 * that SQLite and PostgreSQL both speak, over a small driver each backend
 * provides (svc_store_sqlite.c, svc_store_pg.c).  Private to service/.
 *
 * The driver runs one statement at a time with typed parameters and hands
 * back every row at once (sq_res).  Statements are written with SQLite's
 * ?1..?N placeholders and three tokens a driver spells its own way:
 *   @NOW   the database's clock in Unix seconds
 *   @LOCK  " FOR UPDATE" (PostgreSQL: lock the rows read; SQLite takes the
 *          whole database for a write transaction anyway: nothing)
 *   @SKIP  " FOR UPDATE OF j SKIP LOCKED" (the claim: a job another daemon
 *          is changing right now is passed over, not waited for)
 * Nothing else may differ, so one test of the rules covers both. */
#ifndef SVC_STORE_SQL_H
#define SVC_STORE_SQL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "svc_store.h"

typedef enum { SQ_NULL, SQ_INT, SQ_REAL, SQ_TEXT, SQ_BLOB } sq_type;

typedef struct sq_val {
    sq_type type;
    int64_t i;     /* SQ_INT (also set for SQ_REAL results, truncated) */
    double f;      /* SQ_REAL (also set for SQ_INT results) */
    const char *s; /* SQ_TEXT: NUL-terminated; SQ_BLOB: n bytes */
    size_t n;
} sq_val;

/* Every row of one statement's result; free with the driver's res_free. */
typedef struct sq_res {
    int rows, cols;
    sq_val *v;       /* rows * cols, row by row */
    int64_t changed; /* rows an INSERT, UPDATE or DELETE touched */
    void *own;       /* the driver's storage behind v */
} sq_res;

typedef struct sq_driver {
    const char *name; /* "sqlite", "postgres" */
    /* A write transaction (SQLite: BEGIN IMMEDIATE; PostgreSQL: BEGIN). */
    bool (*begin)(void *c, rs_err *err);
    bool (*commit)(void *c, rs_err *err);
    void (*rollback)(void *c);
    /* One statement.  out may be NULL (rows are dropped); returns the rows
     * changed, or -1 with err filled (a store error id).  what names the
     * statement in messages. */
    int64_t (*exec)(void *c, const char *what, const char *sql, const sq_val *args, int nargs, sq_res *out,
                    rs_err *err);
    void (*res_free)(sq_res *r);
    void (*close)(void *c);
} sq_driver;

/* The store on top of a driver's open connection c (which it then owns:
 * closed with the store).  NULL on out of memory (c closed). */
svc_store *sq_store_new(const sq_driver *drv, void *c, rs_err *err);

/* Schema work for the backends' open, inside their own transaction: the
 * units table and its index (same text on both), and for a queue made
 * before units existed (migrate true) the jobs table's new columns and a
 * WHOLE unit for every queued or running job. */
bool sq_schema_units(const sq_driver *drv, void *c, bool migrate, rs_err *err);

/* The columns that came after units (lost leases counted apart from
 * attempts, retention): units.lost, jobs.lost and jobs.expired, added
 * where they are missing, to new and old queues alike (so the CREATE
 * statements stay as they were).  has_column is the driver's query
 * for "how many columns named ?2 has table ?1" (0 or 1). */
bool sq_schema_lost(const sq_driver *drv, void *c, const char *has_column, rs_err *err);
/* The tokens table (its id column as serial says: each backend spells an
 * auto-numbered key its own way) and the jobs' token index; migrate true
 * adds jobs.token_id to a queue made before tokens existed. */
bool sq_schema_tokens(const sq_driver *drv, void *c, const char *serial, bool migrate, rs_err *err);

/* The replay's header kept with each job (docs/service.md, "Dashboard": the
 * stage, players, winner): jobs.stage, kind1, kind2, winner, rounds1 and
 * rounds2, added where missing, to new and old queues alike, as
 * sq_schema_lost does.  Old jobs read stage -1: not known. */
bool sq_schema_meta(const sq_driver *drv, void *c, const char *has_column, rs_err *err);

/* The job_files table (svc_store.h, "Files in the queue"), its data
 * column of type blob; external true (PostgreSQL): stored out of line
 * without a compression attempt (video does not compress). */
bool sq_schema_files(const sq_driver *drv, void *c, const char *blob, bool external, rs_err *err);
/* sql with @NOW, @LOCK and @SKIP spelt the driver's way, and with dollar
 * true ?N as $N (PostgreSQL).  False when out is too small. */
bool sq_spell(char *out, size_t n, const char *sql, const char *now, const char *lock, const char *skip, bool dollar);

/* The columns of jobs before units existed: a table without them is not
 * a ringside queue, and is never migrated. */
#define SQ_JOB_COLS_V1                                                                                                \
    "id, state, name, width, height, format, frames_done, frames_total, fps, attempts, desync_tick, error, owner, "  \
    "created, started, finished, claimed_until, replay"

/* The columns of jobs (without replay) every backend checks at open. */
#define SQ_JOB_COLS                                                                                                   \
    "id, state, name, width, height, format, frames_done, frames_total, fps, attempts, desync_tick, error, owner, "  \
    "created, started, finished, claimed_until, segment_ticks, segments, seg_key, lost, expired, encode"

#endif
