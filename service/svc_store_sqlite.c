/* svc_store_sqlite: the embedded queue (one database file, WAL), a driver
 * under svc_store_sql.c, which holds the queue's rules.
 *
 * DESIGN: one connection per handle, used under the handle's mutex (SQLite
 * connections must not be used by two threads at once; svc_store_sql.c
 * holds it around every call).  Two handles on the same file (the daemon's
 * supervisor and its HTTP threads) are two connections; WAL lets readers
 * run beside the writer, and busy_timeout makes a writer wait for the other
 * instead of failing.  Every change is one IMMEDIATE transaction, so it is
 * committed (and, with synchronous=FULL, on disk) before the caller hears
 * about it.  One daemon per file: the daemon holds a lock file beside it
 * (svc_main.c), which is what lets it reap every running unit at start-up. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "svc_store.h"
#include "svc_store_sql.h"

#if defined(RS_HAVE_SQLITE)
#include <sqlite3.h>

typedef struct sq_conn {
    sqlite3 *db;
    char path[512];
} sq_conn;

#define C(x) ((sq_conn *)(x))

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
    " replay BLOB NOT NULL,"
    " segment_ticks INTEGER NOT NULL DEFAULT 0, segments INTEGER NOT NULL DEFAULT 0, seg_key TEXT NOT NULL DEFAULT '',"
    " token_id INTEGER NOT NULL DEFAULT 0);"
    "CREATE INDEX IF NOT EXISTS jobs_state ON jobs(state, id);";

/* BUSY when another connection held the lock past the busy timeout; OPEN
 * when the file cannot be opened or is no database (SQLite opens lazily). */
static int sq_code(sq_conn *c)
{
    switch (sqlite3_errcode(c->db)) {
    case SQLITE_BUSY:
    case SQLITE_LOCKED: return SVC_STORE_ERR_BUSY;
    case SQLITE_NOTADB:
    case SQLITE_CANTOPEN: return SVC_STORE_ERR_OPEN;
    default: return SVC_STORE_ERR_QUERY;
    }
}

static bool sq_fail(sq_conn *c, rs_err *err, const char *what)
{
    return rs_fail(err, sq_code(c), "%s: %s: %s", c->path, what, sqlite3_errmsg(c->db));
}

static bool exec_plain(sq_conn *c, const char *sql, rs_err *err)
{
    char *msg = NULL;
    if (sqlite3_exec(c->db, sql, NULL, NULL, &msg) != SQLITE_OK) {
        rs_fail(err, sq_code(c), "%s: %s", c->path, msg ? msg : sqlite3_errmsg(c->db));
        sqlite3_free(msg);
        return false;
    }
    return true;
}

/* --- the driver --- */

static void d_res_free(sq_res *r)
{
    for (int i = 0; r->v && i < r->rows * r->cols; i++)
        if (r->v[i].type == SQ_TEXT || r->v[i].type == SQ_BLOB)
            free((void *)r->v[i].s);
    free(r->v);
    memset(r, 0, sizeof *r);
}

/* One row's cells appended to r (text and blobs copied). */
static bool take_row(sqlite3_stmt *st, sq_res *r, int *cap)
{
    if ((r->rows + 1) * r->cols > *cap) {
        int ncap = *cap ? *cap * 2 : 16 * (r->cols ? r->cols : 1);
        while (ncap < (r->rows + 1) * r->cols)
            ncap *= 2;
        sq_val *v = realloc(r->v, (size_t)ncap * sizeof *v);
        if (!v)
            return false;
        r->v = v;
        *cap = ncap;
    }
    sq_val *row = &r->v[r->rows * r->cols];
    memset(row, 0, (size_t)r->cols * sizeof *row);
    r->rows++; /* counted now, so d_res_free frees a half-copied row too */
    for (int k = 0; k < r->cols; k++) {
        sq_val *v = &row[k];
        switch (sqlite3_column_type(st, k)) {
        case SQLITE_INTEGER:
            v->type = SQ_INT;
            v->i = sqlite3_column_int64(st, k);
            v->f = (double)v->i;
            break;
        case SQLITE_FLOAT:
            v->type = SQ_REAL;
            v->f = sqlite3_column_double(st, k);
            v->i = (int64_t)v->f;
            break;
        case SQLITE_TEXT:
        case SQLITE_BLOB: {
            bool text = sqlite3_column_type(st, k) == SQLITE_TEXT;
            const void *p = text ? (const void *)sqlite3_column_text(st, k) : sqlite3_column_blob(st, k);
            size_t n = (size_t)sqlite3_column_bytes(st, k);
            char *copy = malloc(n + 1);
            if (!copy)
                return false;
            if (n)
                memcpy(copy, p, n);
            copy[n] = 0;
            v->type = text ? SQ_TEXT : SQ_BLOB;
            v->s = copy;
            v->n = n;
            break;
        }
        default: v->type = SQ_NULL;
        }
    }
    return true;
}

static int64_t d_exec(void *cp, const char *what, const char *sql, const sq_val *args, int nargs, sq_res *out,
                      rs_err *err)
{
    sq_conn *c = C(cp);
    char text[4096];
    if (!sq_spell(text, sizeof text, sql, "CAST(strftime('%s','now') AS INTEGER)", "", "", false))
        return rs_fail(err, SVC_STORE_ERR_QUERY, "%s: %s: statement too long", c->path, what), -1;
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(c->db, text, -1, &st, NULL) != SQLITE_OK) {
        sq_fail(c, err, what);
        return -1;
    }
    int used = sqlite3_bind_parameter_count(st);
    for (int i = 0; i < nargs && i < used; i++) {
        const sq_val *a = &args[i];
        switch (a->type) {
        case SQ_INT: sqlite3_bind_int64(st, i + 1, a->i); break;
        case SQ_REAL: sqlite3_bind_double(st, i + 1, a->f); break;
        case SQ_TEXT: sqlite3_bind_text(st, i + 1, a->s ? a->s : "", -1, SQLITE_TRANSIENT); break;
        case SQ_BLOB:
            if (a->n)
                sqlite3_bind_blob64(st, i + 1, a->s, a->n, SQLITE_TRANSIENT);
            else
                sqlite3_bind_zeroblob(st, i + 1, 0); /* a NULL pointer would bind SQL NULL */
            break;
        default: sqlite3_bind_null(st, i + 1);
        }
    }
    sq_res r = {.cols = sqlite3_column_count(st)};
    int cap = 0, rc;
    while ((rc = sqlite3_step(st)) == SQLITE_ROW)
        if (!take_row(st, &r, &cap)) {
            d_res_free(&r);
            sqlite3_finalize(st);
            return rs_fail(err, SVC_STORE_ERR_NOMEM, "%s: %s: out of memory", c->path, what), -1;
        }
    if (rc != SQLITE_DONE) {
        sq_fail(c, err, what);
        d_res_free(&r);
        sqlite3_finalize(st);
        return -1;
    }
    r.changed = sqlite3_stmt_readonly(st) ? 0 : sqlite3_changes64(c->db);
    sqlite3_finalize(st);
    int64_t changed = r.changed;
    if (out)
        *out = r;
    else
        d_res_free(&r);
    return changed;
}

static bool d_begin(void *c, rs_err *err)
{
    return exec_plain(C(c), "BEGIN IMMEDIATE", err);
}

static bool d_commit(void *c, rs_err *err)
{
    return exec_plain(C(c), "COMMIT", err);
}

static void d_rollback(void *c)
{
    if (!sqlite3_get_autocommit(C(c)->db))
        sqlite3_exec(C(c)->db, "ROLLBACK", NULL, NULL, NULL);
}

static void d_close(void *cp)
{
    sq_conn *c = C(cp);
    if (!c)
        return;
    sqlite3_close(c->db);
    free(c);
}

static const sq_driver sqlite_driver = {
    .name = "sqlite",
    .begin = d_begin,
    .commit = d_commit,
    .rollback = d_rollback,
    .exec = d_exec,
    .res_free = d_res_free,
    .close = d_close,
};

/* The tokens table, and jobs.token_id in a queue made before tokens. */
static bool schema_tokens(sq_conn *c, rs_err *err)
{
    sq_res r = {0};
    if (d_exec(c, "look at the jobs table", "SELECT COUNT(*) FROM pragma_table_info('jobs') WHERE name = 'token_id'",
               NULL, 0, &r, err) < 0)
        return false;
    bool migrate = r.rows == 1 && r.v[0].i == 0;
    d_res_free(&r);
    return sq_schema_tokens(&sqlite_driver, c, "INTEGER PRIMARY KEY AUTOINCREMENT", migrate, err);
}

/* The schema, made or brought up to date in one transaction. */
static bool make_schema(sq_conn *c, rs_err *err)
{
    if (!exec_plain(c, "BEGIN IMMEDIATE", err))
        return false;
    sq_res r = {0};
    bool ok = exec_plain(c, schema, err);
    if (!ok && err && err->code == SVC_STORE_ERR_QUERY)
        err->code = SVC_STORE_ERR_SCHEMA; /* another program's jobs table, say */
    ok = ok && d_exec(c, "look at the jobs table", "SELECT COUNT(*) FROM pragma_table_info('jobs') WHERE name = 'segments'",
                      NULL, 0, &r, err) >= 0;
    bool migrate = ok && r.rows == 1 && r.v[0].i == 0;
    d_res_free(&r);
    if (migrate && d_exec(c, "check the jobs table", "SELECT " SQ_JOB_COLS_V1 " FROM jobs LIMIT 0", NULL, 0, NULL, err) < 0) {
        if (err)
            err->code = SVC_STORE_ERR_SCHEMA; /* another program's jobs table: never migrated */
        ok = false;
    }
    ok = ok && sq_schema_units(&sqlite_driver, c, migrate, err) &&
         sq_schema_lost(&sqlite_driver, c, "SELECT COUNT(*) FROM pragma_table_info(?1) WHERE name = ?2", err) &&
         schema_tokens(c, err) &&
         sq_schema_meta(&sqlite_driver, c, "SELECT COUNT(*) FROM pragma_table_info(?1) WHERE name = ?2", err) &&
         sq_schema_files(&sqlite_driver, c, "BLOB", false, err) &&
         exec_plain(c, "COMMIT", err);
    if (!ok)
        d_rollback(c);
    return ok;
}

svc_store *svc_store_sqlite_open(const char *path, rs_err *err)
{
    sq_conn *c = calloc(1, sizeof *c);
    if (!c) {
        rs_fail(err, SVC_STORE_ERR_NOMEM, "out of memory");
        return NULL;
    }
    snprintf(c->path, sizeof c->path, "%s", path);
    if (sqlite3_open_v2(path, &c->db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, NULL) !=
        SQLITE_OK) {
        rs_fail(err, SVC_STORE_ERR_OPEN, "%s: cannot open the queue database: %s", path,
                c->db ? sqlite3_errmsg(c->db) : "out of memory");
        goto fail;
    }
    sqlite3_busy_timeout(c->db, 10000);
    /* a file that is not ours (another program's database): refuse it
     * before changing anything in it */
    sq_res r = {0};
    if (d_exec(c, "look at the tables",
               "SELECT COUNT(*) FROM sqlite_master WHERE name NOT LIKE 'sqlite_%'"
               " AND name NOT IN ('jobs', 'jobs_state', 'jobs_token', 'units', 'units_state', 'tokens', 'job_files')",
               NULL, 0, &r, err) < 0)
        goto fail;
    int64_t foreign = r.rows == 1 ? r.v[0].i : -1;
    d_res_free(&r);
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
        if (exec_plain(c, "PRAGMA journal_mode=WAL", err))
            break;
        if (sqlite3_errcode(c->db) != SQLITE_BUSY || tries == 200)
            goto fail;
        sqlite3_sleep(25);
    }
    if (!exec_plain(c, "PRAGMA synchronous=FULL", err) || !make_schema(c, err))
        goto fail;
    if (d_exec(c, "check the jobs table", "SELECT " SQ_JOB_COLS ", replay FROM jobs LIMIT 0", NULL, 0, NULL, err) < 0 ||
        d_exec(c, "check the units table", "SELECT job_id, idx, kind, renders, done_attempt, lost FROM units LIMIT 0", NULL,
               0, NULL, err) < 0) {
        rs_err_prefix(err, "%s: not a ringside queue", path);
        if (err)
            err->code = SVC_STORE_ERR_SCHEMA;
        goto fail;
    }
    return sq_store_new(&sqlite_driver, c, err);
fail:
    d_close(c);
    return NULL;
}

#else /* !RS_HAVE_SQLITE */

svc_store *svc_store_sqlite_open(const char *path, rs_err *err)
{
    rs_fail(err, SVC_STORE_ERR_NOT_BUILT, "%s: this ringside was built without SQLite (install libsqlite3-dev and rebuild)", path);
    return NULL;
}

#endif
