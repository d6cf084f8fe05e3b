/* svc_store_sqlite: the embedded queue (one database file, WAL).
 *
 * DESIGN: one connection per handle, guarded by the handle's mutex (SQLite
 * connections must not be used by two threads at once).  Two handles on
 * the same file (the daemon's supervisor and its HTTP threads) are two
 * connections; WAL lets readers run beside the writer, and busy_timeout
 * makes a writer wait for the other instead of failing.  Every change is
 * one statement or one IMMEDIATE transaction, so it is committed (and, with
 * synchronous=FULL, on disk) before the caller hears about it.  One daemon
 * per file: the daemon holds a lock file beside it (svc_daemon.c), which
 * is what lets it reap every running job at start-up. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "svc_store.h"

#if defined(RS_HAVE_SQLITE)
#include <sqlite3.h>

typedef struct sq_store {
    svc_store base;
    sqlite3 *db;
    pthread_mutex_t mu;
    char path[512];
} sq_store;

#define NOW "CAST(strftime('%s','now') AS INTEGER)"
#define JOB_COLS                                                                                                      \
    "id, state, name, width, height, format, frames_done, frames_total, fps, attempts, desync_tick, error, owner, "  \
    "created, started, finished, claimed_until"

static const char schema[] =
    "CREATE TABLE IF NOT EXISTS jobs ("
    " id INTEGER PRIMARY KEY AUTOINCREMENT,"
    " state INTEGER NOT NULL DEFAULT 0,"
    " name TEXT NOT NULL DEFAULT '',"
    " width INTEGER NOT NULL, height INTEGER NOT NULL, format TEXT NOT NULL,"
    " frames_done INTEGER NOT NULL DEFAULT 0, frames_total INTEGER NOT NULL DEFAULT 0,"
    " fps REAL NOT NULL DEFAULT 0, attempts INTEGER NOT NULL DEFAULT 0,"
    " desync_tick INTEGER NOT NULL DEFAULT -1, error TEXT NOT NULL DEFAULT '', owner TEXT NOT NULL DEFAULT '',"
    " created INTEGER NOT NULL DEFAULT 0, started INTEGER NOT NULL DEFAULT 0, finished INTEGER NOT NULL DEFAULT 0,"
    " claimed_until INTEGER NOT NULL DEFAULT 0,"
    " replay BLOB NOT NULL);"
    "CREATE INDEX IF NOT EXISTS jobs_state ON jobs(state, id);";

/* BUSY when another connection held the lock past the busy timeout; OPEN
 * when the file cannot be opened or is no database (SQLite opens lazily). */
static int sq_code(sq_store *s)
{
    switch (sqlite3_errcode(s->db)) {
    case SQLITE_BUSY:
    case SQLITE_LOCKED: return SVC_STORE_ERR_BUSY;
    case SQLITE_NOTADB:
    case SQLITE_CANTOPEN: return SVC_STORE_ERR_OPEN;
    default: return SVC_STORE_ERR_QUERY;
    }
}

static bool sq_fail(sq_store *s, rs_err *err, const char *what)
{
    return rs_fail(err, sq_code(s), "%s: %s: %s", s->path, what, sqlite3_errmsg(s->db));
}

static void copy_text(char *dst, size_t n, const unsigned char *src)
{
    snprintf(dst, n, "%s", src ? (const char *)src : "");
}

static void row_to_job(sqlite3_stmt *st, svc_job *j)
{
    memset(j, 0, sizeof *j);
    j->id = sqlite3_column_int64(st, 0);
    j->state = sqlite3_column_int(st, 1);
    copy_text(j->name, sizeof j->name, sqlite3_column_text(st, 2));
    j->width = sqlite3_column_int(st, 3);
    j->height = sqlite3_column_int(st, 4);
    copy_text(j->format, sizeof j->format, sqlite3_column_text(st, 5));
    j->frames_done = sqlite3_column_int64(st, 6);
    j->frames_total = sqlite3_column_int64(st, 7);
    j->fps = sqlite3_column_double(st, 8);
    j->attempts = sqlite3_column_int(st, 9);
    j->desync_tick = sqlite3_column_int64(st, 10);
    copy_text(j->error, sizeof j->error, sqlite3_column_text(st, 11));
    copy_text(j->owner, sizeof j->owner, sqlite3_column_text(st, 12));
    j->created = sqlite3_column_int64(st, 13);
    j->started = sqlite3_column_int64(st, 14);
    j->finished = sqlite3_column_int64(st, 15);
    j->claimed_until = sqlite3_column_int64(st, 16);
}

static sqlite3_stmt *prep(sq_store *s, const char *sql, rs_err *err)
{
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(s->db, sql, -1, &st, NULL) != SQLITE_OK) {
        sq_fail(s, err, "prepare");
        return NULL;
    }
    return st;
}

static bool exec(sq_store *s, const char *sql, rs_err *err)
{
    char *msg = NULL;
    if (sqlite3_exec(s->db, sql, NULL, NULL, &msg) != SQLITE_OK) {
        rs_fail(err, sq_code(s), "%s: %s", s->path, msg ? msg : sqlite3_errmsg(s->db));
        sqlite3_free(msg);
        return false;
    }
    return true;
}

#define S(x) ((sq_store *)(x))

static bool sq_submit(svc_store *bs, svc_job *j, rs_err *err)
{
    sq_store *s = S(bs);
    bool ok = false;
    pthread_mutex_lock(&s->mu);
    sqlite3_stmt *st = prep(s,
                            "INSERT INTO jobs (state, name, width, height, format, frames_total, created, replay) "
                            "VALUES (0, ?1, ?2, ?3, ?4, ?5, " NOW ", ?6) RETURNING id, created",
                            err);
    if (!st)
        goto out;
    sqlite3_bind_text(st, 1, j->name, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int(st, 2, j->width);
    sqlite3_bind_int(st, 3, j->height);
    sqlite3_bind_text(st, 4, j->format, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int64(st, 5, j->frames_total);
    if (j->replay_len)
        sqlite3_bind_blob64(st, 6, j->replay, j->replay_len, SQLITE_TRANSIENT);
    else
        sqlite3_bind_zeroblob(st, 6, 0); /* a NULL pointer would bind SQL NULL */
    if (sqlite3_step(st) != SQLITE_ROW) {
        sq_fail(s, err, "insert job");
        goto out;
    }
    j->id = sqlite3_column_int64(st, 0);
    j->created = sqlite3_column_int64(st, 1);
    j->state = SVC_QUEUED;
    ok = sqlite3_step(st) == SQLITE_DONE || sq_fail(s, err, "insert job");
out:
    sqlite3_finalize(st);
    pthread_mutex_unlock(&s->mu);
    return ok;
}

static int sq_claim(svc_store *bs, const char *owner, int lease_s, svc_job *out, rs_err *err)
{
    sq_store *s = S(bs);
    int rc = -1;
    pthread_mutex_lock(&s->mu);
    /* One statement: the oldest queued row becomes ours, or nothing does.
     * SQLite runs it as one write transaction, so two connections cannot
     * both take the same row. */
    sqlite3_stmt *st = prep(s,
                            "UPDATE jobs SET state = 1, owner = ?1, attempts = attempts + 1, frames_done = 0, fps = 0,"
                            " started = " NOW ", claimed_until = " NOW " + ?2"
                            " WHERE id = (SELECT id FROM jobs WHERE state = 0 ORDER BY id LIMIT 1)"
                            " RETURNING " JOB_COLS ", replay",
                            err);
    if (!st)
        goto out;
    sqlite3_bind_text(st, 1, owner, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int(st, 2, lease_s);
    int r = sqlite3_step(st);
    if (r == SQLITE_DONE) {
        rc = 0;
        goto out;
    }
    if (r != SQLITE_ROW) {
        sq_fail(s, err, "claim");
        goto out;
    }
    row_to_job(st, out);
    int n = sqlite3_column_bytes(st, 17);
    out->replay = malloc(n > 0 ? (size_t)n : 1);
    if (!out->replay) {
        rs_fail(err, SVC_STORE_ERR_NOMEM, "out of memory reading job %lld's replay", (long long)out->id);
        goto out;
    }
    if (n > 0)
        memcpy(out->replay, sqlite3_column_blob(st, 17), (size_t)n);
    out->replay_len = (size_t)n;
    rc = sqlite3_step(st) == SQLITE_DONE ? 1 : (sq_fail(s, err, "claim"), svc_job_free(out), -1);
out:
    sqlite3_finalize(st);
    pthread_mutex_unlock(&s->mu);
    return rc;
}

/* Runs an UPDATE that touches our running row; 1 if it did, 0 if not. */
static int step_changes(sq_store *s, sqlite3_stmt *st, rs_err *err, const char *what)
{
    if (sqlite3_step(st) != SQLITE_DONE) {
        sq_fail(s, err, what);
        return -1;
    }
    return sqlite3_changes(s->db) > 0 ? 1 : 0;
}

static int sq_heartbeat(svc_store *bs, int64_t id, const char *owner, int lease_s, int64_t done, int64_t total,
                        double fps, rs_err *err)
{
    sq_store *s = S(bs);
    int rc = -1;
    pthread_mutex_lock(&s->mu);
    sqlite3_stmt *st = prep(s,
                            "UPDATE jobs SET claimed_until = " NOW " + ?3, frames_done = ?4, frames_total = ?5, fps = ?6"
                            " WHERE id = ?1 AND owner = ?2 AND state = 1",
                            err);
    if (st) {
        sqlite3_bind_int64(st, 1, id);
        sqlite3_bind_text(st, 2, owner, -1, SQLITE_TRANSIENT);
        sqlite3_bind_int(st, 3, lease_s);
        sqlite3_bind_int64(st, 4, done);
        sqlite3_bind_int64(st, 5, total);
        sqlite3_bind_double(st, 6, fps == fps && fps < 1e300 && fps > -1e300 ? fps : 0.0); /* NaN binds NULL */
        rc = step_changes(s, st, err, "heartbeat");
    }
    sqlite3_finalize(st);
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_finish(svc_store *bs, int64_t id, const char *owner, int state, const char *error, int64_t desync,
                     int64_t done, rs_err *err)
{
    sq_store *s = S(bs);
    int rc = -1;
    pthread_mutex_lock(&s->mu);
    sqlite3_stmt *st = prep(s,
                            "UPDATE jobs SET state = ?3, error = ?4, desync_tick = ?5, frames_done = ?6,"
                            " finished = " NOW ", claimed_until = 0"
                            " WHERE id = ?1 AND owner = ?2 AND state = 1",
                            err);
    if (st) {
        sqlite3_bind_int64(st, 1, id);
        sqlite3_bind_text(st, 2, owner, -1, SQLITE_TRANSIENT);
        sqlite3_bind_int(st, 3, state);
        sqlite3_bind_text(st, 4, error ? error : "", -1, SQLITE_TRANSIENT);
        sqlite3_bind_int64(st, 5, desync);
        sqlite3_bind_int64(st, 6, done);
        rc = step_changes(s, st, err, "finish");
    }
    sqlite3_finalize(st);
    pthread_mutex_unlock(&s->mu);
    return rc;
}

/* The shared tail of release and reap: requeue, or dead-letter at the cap.
 * The caller holds the mutex; the row's guard is in where (id = ?1 ...). */
static int release_rows(sq_store *s, const char *where, int64_t id, const char *owner, const char *why,
                        bool count_attempt, int max_attempts, rs_err *err)
{
    char sql[1024];
    /* attempts reached the cap: failed with "gave up after N attempts: why";
     * otherwise queued again with why kept as the last attempt's error */
    static const char head[] =
             "UPDATE jobs SET"
             " attempts = attempts - ?4,"
             " state = CASE WHEN ?4 = 0 AND attempts >= ?5 THEN 3 ELSE 0 END,"
             " error = CASE WHEN ?4 = 0 AND attempts >= ?5 THEN"
             "   'gave up after ' || attempts || ' attempt' || CASE WHEN attempts = 1 THEN '' ELSE 's' END || ': ' || ?3"
             "   ELSE ?3 END,"
             " finished = CASE WHEN ?4 = 0 AND attempts >= ?5 THEN " NOW " ELSE 0 END,"
             " owner = '', claimed_until = 0, fps = 0"
             " WHERE state = 1 AND ";
    snprintf(sql, sizeof sql, "%s%s", head, where);
    sqlite3_stmt *st = prep(s, sql, err);
    if (!st)
        return -1;
    sqlite3_bind_int64(st, 1, id);
    sqlite3_bind_text(st, 2, owner ? owner : "", -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 3, why, -1, SQLITE_TRANSIENT);
    sqlite3_bind_int(st, 4, count_attempt ? 0 : 1);
    sqlite3_bind_int(st, 5, max_attempts);
    int rc = sqlite3_step(st) == SQLITE_DONE ? sqlite3_changes(s->db) : (sq_fail(s, err, "release"), -1);
    sqlite3_finalize(st);
    return rc;
}

static int sq_release(svc_store *bs, int64_t id, const char *owner, const char *why, bool count_attempt,
                      int max_attempts, rs_err *err)
{
    sq_store *s = S(bs);
    pthread_mutex_lock(&s->mu);
    int rc = release_rows(s, "id = ?1 AND owner = ?2", id, owner, why, count_attempt, max_attempts, err);
    pthread_mutex_unlock(&s->mu);
    return rc < 0 ? -1 : rc > 0;
}

static int sq_reap(svc_store *bs, int max_attempts, bool all, rs_err *err)
{
    sq_store *s = S(bs);
    pthread_mutex_lock(&s->mu);
    int rc = release_rows(s, all ? "?1 = ?1" : "?1 = ?1 AND claimed_until < " NOW, 0, NULL, SVC_LEASE_EXPIRED, true,
                          max_attempts, err);
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_get(svc_store *bs, int64_t id, svc_job *out, rs_err *err)
{
    sq_store *s = S(bs);
    int rc = -1;
    pthread_mutex_lock(&s->mu);
    sqlite3_stmt *st = prep(s, "SELECT " JOB_COLS " FROM jobs WHERE id = ?1", err);
    if (st) {
        sqlite3_bind_int64(st, 1, id);
        int r = sqlite3_step(st);
        if (r == SQLITE_ROW) {
            row_to_job(st, out);
            rc = 1;
        } else if (r == SQLITE_DONE)
            rc = 0;
        else
            sq_fail(s, err, "get");
    }
    sqlite3_finalize(st);
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int sq_list(svc_store *bs, int64_t before, int limit, svc_job *out, rs_err *err)
{
    sq_store *s = S(bs);
    int n = -1;
    pthread_mutex_lock(&s->mu);
    sqlite3_stmt *st = prep(s, "SELECT " JOB_COLS " FROM jobs WHERE ?1 = 0 OR id < ?1 ORDER BY id DESC LIMIT ?2", err);
    if (st) {
        sqlite3_bind_int64(st, 1, before);
        sqlite3_bind_int(st, 2, limit);
        n = 0;
        int r;
        while (n < limit && (r = sqlite3_step(st)) == SQLITE_ROW)
            row_to_job(st, &out[n++]);
        if (n < limit && r != SQLITE_DONE)
            n = (sq_fail(s, err, "list"), -1);
    }
    sqlite3_finalize(st);
    pthread_mutex_unlock(&s->mu);
    return n;
}

static int sq_cancel(svc_store *bs, int64_t id, rs_err *err)
{
    sq_store *s = S(bs);
    int rc = -1;
    pthread_mutex_lock(&s->mu);
    sqlite3_stmt *st = prep(s,
                            "UPDATE jobs SET state = 4, finished = " NOW ", claimed_until = 0, fps = 0"
                            " WHERE id = ?1 AND state IN (0, 1)",
                            err);
    if (st) {
        sqlite3_bind_int64(st, 1, id);
        rc = step_changes(s, st, err, "cancel");
    }
    sqlite3_finalize(st);
    if (rc == 0) { /* over already, or no such job? */
        st = prep(s, "SELECT 1 FROM jobs WHERE id = ?1", err);
        if (!st)
            rc = -1;
        else {
            sqlite3_bind_int64(st, 1, id);
            int r = sqlite3_step(st);
            rc = r == SQLITE_ROW ? 2 : r == SQLITE_DONE ? 0 : (sq_fail(s, err, "cancel"), -1);
        }
        sqlite3_finalize(st);
    }
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static bool sq_counts(svc_store *bs, int64_t by_state[SVC_NSTATES], rs_err *err)
{
    sq_store *s = S(bs);
    bool ok = false;
    memset(by_state, 0, sizeof(int64_t) * SVC_NSTATES);
    pthread_mutex_lock(&s->mu);
    sqlite3_stmt *st = prep(s, "SELECT state, COUNT(*) FROM jobs GROUP BY state", err);
    if (st) {
        int r;
        while ((r = sqlite3_step(st)) == SQLITE_ROW) {
            int k = sqlite3_column_int(st, 0);
            if (k >= 0 && k < SVC_NSTATES)
                by_state[k] = sqlite3_column_int64(st, 1);
        }
        ok = r == SQLITE_DONE || sq_fail(s, err, "counts");
    }
    sqlite3_finalize(st);
    pthread_mutex_unlock(&s->mu);
    return ok;
}

static void sq_close(svc_store *bs)
{
    sq_store *s = S(bs);
    if (!s)
        return;
    sqlite3_close(s->db);
    pthread_mutex_destroy(&s->mu);
    free(s);
}

static const svc_store_ops sq_ops = {
    "sqlite", sq_submit, sq_claim, sq_heartbeat, sq_finish, sq_release, sq_reap, sq_get, sq_list, sq_cancel, sq_counts,
    sq_close,
};

svc_store *svc_store_sqlite_open(const char *path, rs_err *err)
{
    sq_store *s = calloc(1, sizeof *s);
    if (!s) {
        rs_fail(err, SVC_STORE_ERR_NOMEM, "out of memory");
        return NULL;
    }
    s->base.ops = &sq_ops;
    snprintf(s->path, sizeof s->path, "%s", path);
    pthread_mutex_init(&s->mu, NULL);
    if (sqlite3_open_v2(path, &s->db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, NULL) !=
        SQLITE_OK) {
        rs_fail(err, SVC_STORE_ERR_OPEN, "%s: cannot open the queue database: %s", path,
                s->db ? sqlite3_errmsg(s->db) : "out of memory");
        goto fail;
    }
    sqlite3_busy_timeout(s->db, 10000);
    /* a file that is not ours (another program's database): refuse it
     * before changing anything in it */
    sqlite3_stmt *st = prep(s, "SELECT COUNT(*) FROM sqlite_master WHERE name NOT LIKE 'sqlite_%'"
                               " AND name NOT IN ('jobs', 'jobs_state')", err);
    if (!st)
        goto fail;
    int foreign = sqlite3_step(st) == SQLITE_ROW ? sqlite3_column_int(st, 0) : -1;
    sqlite3_finalize(st);
    if (foreign != 0) {
        rs_fail(err, SVC_STORE_ERR_SCHEMA, "%s: not a ringside queue (it holds other tables)", path);
        goto fail;
    }
    /* WAL: HTTP readers never wait for the supervisor's writes.  Setting it
     * answers SQLITE_BUSY at once (busy_timeout does not apply) while
     * another connection opens the same new file: retry for a while.
     * synchronous=FULL: a job acknowledged to a client survives power loss. */
    for (int tries = 0;; tries++) {
        rs_err_clear(err);
        if (exec(s, "PRAGMA journal_mode=WAL", err))
            break;
        if (sqlite3_errcode(s->db) != SQLITE_BUSY || tries == 200)
            goto fail;
        sqlite3_sleep(25);
    }
    if (!exec(s, "PRAGMA synchronous=FULL", err))
        goto fail;
    if (!exec(s, schema, err)) {
        if (err && err->code == SVC_STORE_ERR_QUERY)
            err->code = SVC_STORE_ERR_SCHEMA; /* another program's jobs table, say */
        goto fail;
    }
    st = prep(s, "SELECT id, state, name, width, height, format, frames_done, frames_total, fps, attempts,"
                 " desync_tick, error, owner, created, started, finished, claimed_until, replay FROM jobs LIMIT 0",
              err);
    if (!st) {
        rs_err_prefix(err, "%s: not a ringside queue", path);
        if (err)
            err->code = SVC_STORE_ERR_SCHEMA;
        goto fail;
    }
    sqlite3_finalize(st);
    return &s->base;
fail:
    sq_close(&s->base);
    return NULL;
}

#else /* !RS_HAVE_SQLITE */

svc_store *svc_store_sqlite_open(const char *path, rs_err *err)
{
    rs_fail(err, SVC_STORE_ERR_NOT_BUILT, "%s: this ringside was built without SQLite (install libsqlite3-dev and rebuild)", path);
    return NULL;
}

#endif
