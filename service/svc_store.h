/* svc_store: the durable job queue behind `ringside serve`.
 *
 * One small table of function pointers per backend (raylib's platform
 * contract, Redis's habit): svc_store_sqlite.c (embedded default, one
 * daemon per database file) and svc_store_pg.c (PostgreSQL through libpq,
 * any number of daemons on any number of machines).  Adding a backend is
 * adding a file and a line in svc_store_open.
 *
 * The rules every backend keeps (tests/test_svc_store.c checks them on each):
 *  - submit commits the job before it returns, so an id given to a client
 *    always survives a crash;
 *  - claim hands the oldest queued job to exactly one owner, sets its lease
 *    (claimed_until = now + lease_s, the database's clock) and adds one to
 *    its attempts;
 *  - heartbeat, finish and release act only while the row is still running
 *    and owned by the caller: a job whose lease was taken away (reaped, or
 *    cancelled by DELETE) cannot be finished by its old owner;
 *  - reap turns expired leases back into queued jobs, or into failed ones
 *    (dead letter: "gave up after N attempts: why") once attempts reach the
 *    cap; a job is never retried forever;
 *  - times are Unix seconds from the database's clock, so machines with
 *    skewed clocks still agree on leases.
 *
 * Threads: a store handle is one database connection guarded by its own
 * mutex; any thread may call it.  The daemon opens one handle for its
 * supervisor loop and one for the HTTP threads. */
#ifndef SVC_STORE_H
#define SVC_STORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "../runtime/util/rs_err.h"

/* The states, in the order of the database's integer column. */
#define SVC_STATES(X) X(QUEUED, "queued") X(RUNNING, "running") X(DONE, "done") X(FAILED, "failed") X(CANCELLED, "cancelled")
typedef enum {
#define X(id, s) SVC_##id,
    SVC_STATES(X)
#undef X
    SVC_NSTATES
} svc_state;
const char *svc_state_name(int st);

/* Error ids (rs_err.h) of every backend.  "No such job" and "already
 * over" are not errors: get and cancel say them in their return values. */
#define SVC_STORE_ERRORS(X)                                                                \
    X(SPEC, "the queue setting names no backend or no database")                           \
    X(NOT_BUILT, "this build has no driver for that backend")                              \
    X(OPEN, "cannot open or connect to the queue database")                                \
    X(SCHEMA, "not a ringside queue (other tables or columns), or no schema could be made") \
    X(BUSY, "the database stayed locked past the busy timeout")                            \
    X(QUERY, "a statement failed")                                                         \
    X(CONNECTION, "lost the connection to the database and could not reconnect")           \
    X(TOO_LARGE, "the replay is too large to queue")                                       \
    X(NOMEM, "out of memory")

typedef enum svc_store_error {
    SVC_STORE_ERR_BASE = RS_ERR_BASE(RS_ERR_MOD_SVC_STORE),
#define X(id, text) SVC_STORE_ERR_##id,
    SVC_STORE_ERRORS(X)
#undef X
        SVC_STORE_ERR_END
} svc_store_error;

const char *svc_store_error_text(int code);

#define SVC_NAME_MAX 128
#define SVC_ERROR_MAX 512
#define SVC_OWNER_MAX 128

typedef struct svc_job {
    int64_t id;
    int state;                   /* svc_state */
    char name[SVC_NAME_MAX];     /* the uploaded file's name, for people ("dojo.rsr") */
    int width, height;           /* output video size */
    char format[8];              /* "mp4", "webm", "mkv" */
    int64_t frames_done, frames_total;
    double fps;                  /* render speed of the running attempt */
    int attempts;                /* claims so far (the running one included) */
    int64_t desync_tick;         /* first checkpoint tick that differed; -1: none */
    char error[SVC_ERROR_MAX];   /* why it failed (or why the last attempt did) */
    char owner[SVC_OWNER_MAX];   /* "host:pid" of the daemon running it */
    int64_t created, started, finished, claimed_until; /* Unix seconds; 0: not yet */
    /* the replay: submit reads it, claim fills it (malloc'd; svc_job_free) */
    uint8_t *replay;
    size_t replay_len;
} svc_job;

void svc_job_free(svc_job *j);

typedef struct svc_store svc_store;

typedef struct svc_store_ops {
    const char *name; /* "sqlite", "postgres" */
    /* j: name, width, height, format, frames_total, replay, replay_len.
     * Fills j->id and j->created; committed before it returns. */
    bool (*submit)(svc_store *s, svc_job *j, rs_err *err);
    /* 1: claimed the oldest queued job into out (replay included);
     * 0: nothing queued; -1: error. */
    int (*claim)(svc_store *s, const char *owner, int lease_s, svc_job *out, rs_err *err);
    /* Extends the lease and records progress.  1: still ours; 0: not ours
     * any more (cancelled, reaped, finished elsewhere): stop the worker;
     * -1: error (keep going; the lease may still be valid). */
    int (*heartbeat)(svc_store *s, int64_t id, const char *owner, int lease_s, int64_t frames_done,
                     int64_t frames_total, double fps, rs_err *err);
    /* The end of an attempt: state SVC_DONE or SVC_FAILED (no retry: a
     * desync, say), with error and desync_tick (-1: none).  1: recorded;
     * 0: not ours any more (nothing changed); -1: error. */
    int (*finish)(svc_store *s, int64_t id, const char *owner, int state, const char *error, int64_t desync_tick,
                  int64_t frames_done, rs_err *err);
    /* An attempt that did not finish: back to queued with error as the
     * reason, or failed ("gave up after N attempts: error") when attempts
     * has reached max_attempts.  count_attempt false (a clean shutdown)
     * gives the attempt back.  1: released; 0: not ours; -1: error. */
    int (*release)(svc_store *s, int64_t id, const char *owner, const char *error, bool count_attempt,
                   int max_attempts, rs_err *err);
    /* Running jobs whose lease has expired (all running jobs when all is
     * true: the single daemon of an SQLite file starting up) are released
     * as above with error "lease expired (worker or daemon lost)".
     * Returns how many, or -1. */
    int (*reap)(svc_store *s, int max_attempts, bool all, rs_err *err);
    /* 1: found; 0: no such job; -1: error.  out->replay stays NULL. */
    int (*get)(svc_store *s, int64_t id, svc_job *out, rs_err *err);
    /* Newest first, ids below before_id (0: from the newest); up to limit
     * rows into out.  Returns the count, or -1. */
    int (*list)(svc_store *s, int64_t before_id, int limit, svc_job *out, rs_err *err);
    /* Queued or running -> cancelled.  1: cancelled; 0: no such job;
     * 2: already over (done, failed or cancelled); -1: error. */
    int (*cancel)(svc_store *s, int64_t id, rs_err *err);
    /* Jobs per state. */
    bool (*counts)(svc_store *s, int64_t by_state[SVC_NSTATES], rs_err *err);
    void (*close)(svc_store *s);
} svc_store_ops;

struct svc_store {
    const svc_store_ops *ops;
};

/* "sqlite:PATH" or a bare path ending in .db: SQLite (WAL);
 * "postgres://..." or "postgresql://...": PostgreSQL (libpq conninfo URI).
 * Creates the schema if it is missing.  NULL with err filled on failure. */
svc_store *svc_store_open(const char *spec, rs_err *err);
svc_store *svc_store_sqlite_open(const char *path, rs_err *err);
svc_store *svc_store_pg_open(const char *conninfo, rs_err *err);

/* The standard reason texts, shared so every backend words them alike. */
#define SVC_LEASE_EXPIRED "lease expired (worker or daemon lost)"
/* "gave up after N attempts: why" into out. */
void svc_dead_letter(char *out, size_t n, int attempts, const char *why);

#endif
