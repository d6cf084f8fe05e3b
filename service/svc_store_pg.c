/* svc_store_pg: the shared queue (PostgreSQL through libpq).
 *
 * DESIGN: one PGconn per handle, guarded by the handle's mutex (a PGconn
 * must not be used by two threads at once).  Any number of daemons on any
 * number of machines share one database.  Every change is one statement in
 * its own transaction, committed before the caller hears about it.  claim
 * picks the oldest queued row with FOR UPDATE SKIP LOCKED, so two daemons
 * never get the same row and never queue behind each other's claim.  Times
 * come from the server's clock (now()), never from the calling machine.
 *
 * A lost connection (server restart, failover, an idle connection cut by a
 * proxy) is reset once and the statement retried once (run()).  A reply
 * lost after its statement committed makes that statement run twice: a
 * second claim takes another job (the first one's lease runs out and reap
 * requeues it), a second submit queues a duplicate, a second finish,
 * release or cancel answers "not ours" / "already over".  Each is at worst
 * a wasted render, never a lost or doubly finished job.
 *
 * Values travel as text parameters, except the replay, which is bound and
 * read back as binary bytea (exact bytes, no escaping); results are binary
 * so the replay arrives as it was stored. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "svc_store.h"

#if defined(RS_HAVE_PQ)
#include <limits.h>

#include <libpq-fe.h>

typedef struct pg_store {
    svc_store base;
    PGconn *conn;
    pthread_mutex_t mu;
    char label[256]; /* "postgres host:port/db": names the server in messages, never the password */
} pg_store;

/* Unix seconds on the server's clock.  floor, not a plain ::bigint cast
 * (which rounds): the same second as SQLite's strftime('%s') and time(). */
#define NOW "floor(extract(epoch from now()))::bigint"
#define JOB_COLS                                                                                                      \
    "id, state, name, width, height, format, frames_done, frames_total, fps, attempts, desync_tick, error, owner, "  \
    "created, started, finished, claimed_until"
/* Serialises schema creation between daemons that start at the same moment
 * on an empty database ("ring" in ASCII; any constant other programs are
 * unlikely to pick). */
#define SCHEMA_LOCK "1919512167"

static const char create_table[] =
    "CREATE TABLE IF NOT EXISTS jobs ("
    " id BIGSERIAL PRIMARY KEY,"
    " state INTEGER NOT NULL DEFAULT 0,"
    " name TEXT NOT NULL DEFAULT '',"
    " width INTEGER NOT NULL, height INTEGER NOT NULL, format TEXT NOT NULL,"
    " frames_done BIGINT NOT NULL DEFAULT 0, frames_total BIGINT NOT NULL DEFAULT 0,"
    " fps DOUBLE PRECISION NOT NULL DEFAULT 0, attempts INTEGER NOT NULL DEFAULT 0,"
    " desync_tick BIGINT NOT NULL DEFAULT -1, error TEXT NOT NULL DEFAULT '', owner TEXT NOT NULL DEFAULT '',"
    " created BIGINT NOT NULL DEFAULT 0, started BIGINT NOT NULL DEFAULT 0, finished BIGINT NOT NULL DEFAULT 0,"
    " claimed_until BIGINT NOT NULL DEFAULT 0,"
    " replay BYTEA NOT NULL)";

/* --- parameters: up to eight per statement, text unless bound as bytes --- */

typedef struct params {
    int n;
    const char *val[8];
    int len[8], fmt[8];
    char buf[8][32];
} params;

static void p_text(params *p, const char *s)
{
    p->val[p->n] = s ? s : "";
    p->len[p->n] = 0;
    p->fmt[p->n++] = 0;
}

static void p_i64(params *p, int64_t v)
{
    snprintf(p->buf[p->n], sizeof p->buf[0], "%lld", (long long)v);
    p_text(p, p->buf[p->n]);
}

static void p_f64(params *p, double v)
{
    /* %.17g round-trips a double; inf and NaN (a worker dividing by a zero
     * elapsed time) are not worth failing a heartbeat over */
    snprintf(p->buf[p->n], sizeof p->buf[0], "%.17g", isfinite(v) ? v : 0.0);
    p_text(p, p->buf[p->n]);
}

static void p_bytes(params *p, const void *b, int n)
{
    p->val[p->n] = b ? (const char *)b : ""; /* a NULL value would be SQL NULL */
    p->len[p->n] = n;
    p->fmt[p->n++] = 1;
}

/* --- results (binary: integers big-endian, float8 IEEE, text as is) --- */

static int64_t col_int(const PGresult *r, int row, int col)
{
    const unsigned char *b = (const unsigned char *)PQgetvalue(r, row, col);
    int n = PQgetlength(r, row, col);
    if (n <= 0 || n > 8)
        return 0;
    uint64_t v = 0;
    for (int i = 0; i < n; i++)
        v = v << 8 | b[i];
    if (n < 8 && (b[0] & 0x80)) /* int4 (and int2): sign-extend */
        v |= ~(uint64_t)0 << (8 * n);
    return (int64_t)v;
}

static double col_f64(const PGresult *r, int row, int col)
{
    if (PQgetlength(r, row, col) != 8)
        return 0;
    uint64_t bits = (uint64_t)col_int(r, row, col);
    double d;
    memcpy(&d, &bits, sizeof d);
    return d;
}

static void col_text(char *dst, size_t n, const PGresult *r, int row, int col)
{
    snprintf(dst, n, "%s", PQgetvalue(r, row, col)); /* libpq ends every value with a NUL */
}

static void row_to_job(const PGresult *r, int row, svc_job *j)
{
    memset(j, 0, sizeof *j);
    j->id = col_int(r, row, 0);
    j->state = (int)col_int(r, row, 1);
    col_text(j->name, sizeof j->name, r, row, 2);
    j->width = (int)col_int(r, row, 3);
    j->height = (int)col_int(r, row, 4);
    col_text(j->format, sizeof j->format, r, row, 5);
    j->frames_done = col_int(r, row, 6);
    j->frames_total = col_int(r, row, 7);
    j->fps = col_f64(r, row, 8);
    j->attempts = (int)col_int(r, row, 9);
    j->desync_tick = col_int(r, row, 10);
    col_text(j->error, sizeof j->error, r, row, 11);
    col_text(j->owner, sizeof j->owner, r, row, 12);
    j->created = col_int(r, row, 13);
    j->started = col_int(r, row, 14);
    j->finished = col_int(r, row, 15);
    j->claimed_until = col_int(r, row, 16);
}

/* --- running statements --- */

/* libpq's messages span lines and indent with tabs: one line, single spaces. */
static void one_line(char *dst, size_t n, const char *src)
{
    size_t k = 0;
    for (; *src && k + 1 < n; src++) {
        bool space = *src == ' ' || *src == '\t' || *src == '\n' || *src == '\r';
        if (!space)
            dst[k++] = *src;
        else if (k > 0 && dst[k - 1] != ' ')
            dst[k++] = ' ';
    }
    while (k > 0 && dst[k - 1] == ' ')
        k--;
    dst[k] = 0;
}

static bool pg_fail(pg_store *s, rs_err *err, const char *what, const PGresult *r)
{
    /* the primary message alone, without libpq's "ERROR:  ", when there is one */
    const char *m = r ? PQresultErrorField(r, PG_DIAG_MESSAGE_PRIMARY) : NULL;
    char msg[512];
    one_line(msg, sizeof msg, m ? m : s->conn ? PQerrorMessage(s->conn) : "out of memory");
    return rs_fail(err, SVC_STORE_ERR_QUERY, "%s: %s: %s", s->label, what, msg);
}

/* One statement; the result on success (PQclear it), NULL with err filled.
 * The caller holds the mutex. */
static PGresult *run(pg_store *s, const char *what, const char *sql, const params *p, rs_err *err)
{
    for (int tries = 0;; tries++) {
        PGresult *r = PQexecParams(s->conn, sql, p->n, NULL, p->val, p->len, p->fmt, 1);
        ExecStatusType st = PQresultStatus(r); /* PGRES_FATAL_ERROR for NULL */
        if (st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK)
            return r;
        if (tries == 0 && PQstatus(s->conn) != CONNECTION_OK) {
            /* the server went away: reconnect once and try again; a
             * statement error on a live connection is not retried */
            PQclear(r);
            PQreset(s->conn);
            if (PQstatus(s->conn) == CONNECTION_OK)
                continue;
            char msg[512];
            one_line(msg, sizeof msg, PQerrorMessage(s->conn));
            rs_fail(err, SVC_STORE_ERR_CONNECTION, "%s: %s: lost the connection and could not reconnect: %s", s->label, what, msg);
            return NULL;
        }
        pg_fail(s, err, what, r);
        PQclear(r);
        return NULL;
    }
}

/* An UPDATE guarded by its WHERE: 1 if it touched a row, 0 if not, -1. */
static int run_changes(pg_store *s, const char *what, const char *sql, const params *p, rs_err *err)
{
    PGresult *r = run(s, what, sql, p, err);
    if (!r)
        return -1;
    int n = atoi(PQcmdTuples(r));
    PQclear(r);
    return n;
}

#define S(x) ((pg_store *)(x))

static bool pg_submit(svc_store *bs, svc_job *j, rs_err *err)
{
    pg_store *s = S(bs);
    if (j->replay_len > INT_MAX) /* libpq's lengths are ints (and bytea stops at 1 GiB) */
        return rs_fail(err, SVC_STORE_ERR_TOO_LARGE, "%s: replay of %zu bytes is too large to queue", s->label, j->replay_len);
    params p = {0};
    p_text(&p, j->name);
    p_i64(&p, j->width);
    p_i64(&p, j->height);
    p_text(&p, j->format);
    p_i64(&p, j->frames_total);
    p_bytes(&p, j->replay, (int)j->replay_len);
    pthread_mutex_lock(&s->mu);
    PGresult *r = run(s, "insert job",
                      "INSERT INTO jobs (state, name, width, height, format, frames_total, created, replay)"
                      " VALUES (0, $1, $2::int, $3::int, $4, $5::bigint, " NOW ", $6::bytea) RETURNING id, created",
                      &p, err);
    pthread_mutex_unlock(&s->mu);
    if (!r)
        return false;
    j->id = col_int(r, 0, 0);
    j->created = col_int(r, 0, 1);
    j->state = SVC_QUEUED;
    PQclear(r);
    return true;
}

static int pg_claim(svc_store *bs, const char *owner, int lease_s, svc_job *out, rs_err *err)
{
    pg_store *s = S(bs);
    params p = {0};
    p_text(&p, owner);
    p_i64(&p, lease_s);
    pthread_mutex_lock(&s->mu);
    /* SKIP LOCKED: a row another daemon is claiming right now is passed
     * over, not waited for; the row we lock is ours until we commit. */
    PGresult *r = run(s, "claim",
                      "UPDATE jobs SET state = 1, owner = $1, attempts = attempts + 1, frames_done = 0, fps = 0,"
                      " started = " NOW ", claimed_until = " NOW " + $2::bigint"
                      " WHERE id = (SELECT id FROM jobs WHERE state = 0 ORDER BY id LIMIT 1 FOR UPDATE SKIP LOCKED)"
                      " RETURNING " JOB_COLS ", replay",
                      &p, err);
    pthread_mutex_unlock(&s->mu);
    if (!r)
        return -1;
    int rc = 0;
    if (PQntuples(r) == 1) {
        row_to_job(r, 0, out);
        int n = PQgetlength(r, 0, 17);
        out->replay = malloc(n > 0 ? (size_t)n : 1);
        if (!out->replay) {
            rs_fail(err, SVC_STORE_ERR_NOMEM, "out of memory reading job %lld's replay", (long long)out->id);
            rc = -1;
        } else {
            memcpy(out->replay, PQgetvalue(r, 0, 17), (size_t)n);
            out->replay_len = (size_t)n;
            rc = 1;
        }
    }
    PQclear(r);
    return rc;
}

static int pg_heartbeat(svc_store *bs, int64_t id, const char *owner, int lease_s, int64_t done, int64_t total,
                        double fps, rs_err *err)
{
    pg_store *s = S(bs);
    params p = {0};
    p_i64(&p, id);
    p_text(&p, owner);
    p_i64(&p, lease_s);
    p_i64(&p, done);
    p_i64(&p, total);
    p_f64(&p, fps);
    pthread_mutex_lock(&s->mu);
    int rc = run_changes(s, "heartbeat",
                         "UPDATE jobs SET claimed_until = " NOW " + $3::bigint, frames_done = $4::bigint,"
                         " frames_total = $5::bigint, fps = $6::float8"
                         " WHERE id = $1::bigint AND owner = $2 AND state = 1",
                         &p, err);
    pthread_mutex_unlock(&s->mu);
    return rc < 0 ? -1 : rc > 0;
}

static int pg_finish(svc_store *bs, int64_t id, const char *owner, int state, const char *error, int64_t desync,
                     int64_t done, rs_err *err)
{
    pg_store *s = S(bs);
    params p = {0};
    p_i64(&p, id);
    p_text(&p, owner);
    p_i64(&p, state);
    p_text(&p, error);
    p_i64(&p, desync);
    p_i64(&p, done);
    pthread_mutex_lock(&s->mu);
    int rc = run_changes(s, "finish",
                         "UPDATE jobs SET state = $3::int, error = $4, desync_tick = $5::bigint, frames_done = $6::bigint,"
                         " finished = " NOW ", claimed_until = 0"
                         " WHERE id = $1::bigint AND owner = $2 AND state = 1",
                         &p, err);
    pthread_mutex_unlock(&s->mu);
    return rc < 0 ? -1 : rc > 0;
}

/* The shared tail of release and reap: requeue, or dead-letter at the cap.
 * The caller holds the mutex; the row's guard is in where ($1, $2).  SET
 * reads the row as it was, so attempts in the CASEs is the claimed count. */
static int release_rows(pg_store *s, const char *where, int64_t id, const char *owner, const char *why,
                        bool count_attempt, int max_attempts, rs_err *err)
{
    char sql[1024];
    snprintf(sql, sizeof sql,
             "UPDATE jobs SET"
             " attempts = attempts - $4::int,"
             " state = CASE WHEN $4::int = 0 AND attempts >= $5::int THEN 3 ELSE 0 END,"
             " error = CASE WHEN $4::int = 0 AND attempts >= $5::int THEN"
             "   'gave up after ' || attempts || ' attempt' || CASE WHEN attempts = 1 THEN '' ELSE 's' END"
             "   || ': ' || $3::text ELSE $3::text END,"
             " finished = CASE WHEN $4::int = 0 AND attempts >= $5::int THEN " NOW " ELSE 0 END,"
             " owner = '', claimed_until = 0, fps = 0"
             " WHERE state = 1 AND %s",
             where);
    params p = {0};
    p_i64(&p, id);
    p_text(&p, owner);
    p_text(&p, why);
    p_i64(&p, count_attempt ? 0 : 1);
    p_i64(&p, max_attempts);
    return run_changes(s, "release", sql, &p, err);
}

static int pg_release(svc_store *bs, int64_t id, const char *owner, const char *why, bool count_attempt,
                      int max_attempts, rs_err *err)
{
    pg_store *s = S(bs);
    pthread_mutex_lock(&s->mu);
    int rc = release_rows(s, "id = $1::bigint AND owner = $2", id, owner, why, count_attempt, max_attempts, err);
    pthread_mutex_unlock(&s->mu);
    return rc < 0 ? -1 : rc > 0;
}

static int pg_reap(svc_store *bs, int max_attempts, bool all, rs_err *err)
{
    pg_store *s = S(bs);
    /* $1 and $2 are bound either way; "IS NOT NULL" only gives them a type */
    const char *where = all ? "$1::bigint IS NOT NULL AND $2::text IS NOT NULL"
                            : "$1::bigint IS NOT NULL AND $2::text IS NOT NULL AND claimed_until < " NOW;
    pthread_mutex_lock(&s->mu);
    int rc = release_rows(s, where, 0, NULL, SVC_LEASE_EXPIRED, true, max_attempts, err);
    pthread_mutex_unlock(&s->mu);
    return rc;
}

static int pg_get(svc_store *bs, int64_t id, svc_job *out, rs_err *err)
{
    pg_store *s = S(bs);
    params p = {0};
    p_i64(&p, id);
    pthread_mutex_lock(&s->mu);
    PGresult *r = run(s, "get", "SELECT " JOB_COLS " FROM jobs WHERE id = $1::bigint", &p, err);
    pthread_mutex_unlock(&s->mu);
    if (!r)
        return -1;
    int rc = PQntuples(r) > 0;
    if (rc)
        row_to_job(r, 0, out);
    PQclear(r);
    return rc;
}

static int pg_list(svc_store *bs, int64_t before, int limit, svc_job *out, rs_err *err)
{
    pg_store *s = S(bs);
    if (limit <= 0) /* PostgreSQL refuses a negative LIMIT */
        return 0;
    params p = {0};
    /* 0 means "from the newest"; a plain id < $1 keeps the primary key usable */
    p_i64(&p, before == 0 ? INT64_MAX : before);
    p_i64(&p, limit);
    pthread_mutex_lock(&s->mu);
    PGresult *r = run(s, "list", "SELECT " JOB_COLS " FROM jobs WHERE id < $1::bigint ORDER BY id DESC LIMIT $2::int",
                      &p, err);
    pthread_mutex_unlock(&s->mu);
    if (!r)
        return -1;
    int n = PQntuples(r);
    for (int i = 0; i < n && i < limit; i++)
        row_to_job(r, i, &out[i]);
    PQclear(r);
    return n < limit ? n : limit;
}

static int pg_cancel(svc_store *bs, int64_t id, rs_err *err)
{
    pg_store *s = S(bs);
    params p = {0};
    p_i64(&p, id);
    pthread_mutex_lock(&s->mu);
    /* One statement tells the three answers apart: the outer SELECT sees
     * the rows as they were before the CTE's UPDATE. */
    PGresult *r = run(s, "cancel",
                      "WITH u AS (UPDATE jobs SET state = 4, finished = " NOW ", claimed_until = 0, fps = 0"
                      " WHERE id = $1::bigint AND state IN (0, 1) RETURNING id)"
                      " SELECT (SELECT count(*) FROM u), (SELECT count(*) FROM jobs WHERE id = $1::bigint)",
                      &p, err);
    pthread_mutex_unlock(&s->mu);
    if (!r)
        return -1;
    int rc = col_int(r, 0, 0) > 0 ? 1 : col_int(r, 0, 1) > 0 ? 2 : 0;
    PQclear(r);
    return rc;
}

static bool pg_counts(svc_store *bs, int64_t by_state[SVC_NSTATES], rs_err *err)
{
    pg_store *s = S(bs);
    params p = {0};
    memset(by_state, 0, sizeof(int64_t) * SVC_NSTATES);
    pthread_mutex_lock(&s->mu);
    PGresult *r = run(s, "counts", "SELECT state, count(*) FROM jobs GROUP BY state", &p, err);
    pthread_mutex_unlock(&s->mu);
    if (!r)
        return false;
    for (int i = 0; i < PQntuples(r); i++) {
        int64_t k = col_int(r, i, 0);
        if (k >= 0 && k < SVC_NSTATES)
            by_state[k] = col_int(r, i, 1);
    }
    PQclear(r);
    return true;
}

static void pg_close(svc_store *bs)
{
    pg_store *s = S(bs);
    if (!s)
        return;
    PQfinish(s->conn);
    pthread_mutex_destroy(&s->mu);
    free(s);
}

static const svc_store_ops pg_ops = {
    "postgres", pg_submit, pg_claim, pg_heartbeat, pg_finish, pg_release, pg_reap, pg_get, pg_list, pg_cancel,
    pg_counts, pg_close,
};

/* --- opening --- */

/* CREATE TABLE IF NOT EXISTS prints a NOTICE on every start; notices are
 * not errors and must not reach the daemon's stderr. */
static void quiet(void *arg, const char *message)
{
    (void)arg;
    (void)message;
}

/* "postgres host:port/db" from the connection's settings (defaults filled). */
static void make_label(pg_store *s)
{
    const char *host = NULL, *addr = NULL, *port = NULL, *db = NULL;
    PQconninfoOption *opts = s->conn ? PQconninfo(s->conn) : NULL;
    for (PQconninfoOption *o = opts; o && o->keyword; o++) {
        if (!o->val || !*o->val)
            continue;
        if (!strcmp(o->keyword, "host"))
            host = o->val;
        else if (!strcmp(o->keyword, "hostaddr"))
            addr = o->val;
        else if (!strcmp(o->keyword, "port"))
            port = o->val;
        else if (!strcmp(o->keyword, "dbname"))
            db = o->val;
    }
    if (!db) /* libpq could not even parse the URI: nothing trustworthy to show */
        snprintf(s->label, sizeof s->label, "postgres (malformed URI)");
    else
        snprintf(s->label, sizeof s->label, "postgres %s:%s/%s", host ? host : addr ? addr : "localhost",
                 port ? port : "5432", db);
    PQconninfoFree(opts);
}

/* libpq quotes a malformed URI whole in its message: blank out the
 * password of user:password@ and of password=... before showing it. */
static void scrub(char *msg, const char *conninfo)
{
    const char *spans[2][2] = {{NULL, NULL}, {NULL, NULL}};
    const char *p = strstr(conninfo, "://");
    if (p) {
        p += 3;
        const char *end = p + strcspn(p, "/?");
        const char *at = NULL;
        for (const char *q = p; q < end; q++)
            if (*q == '@')
                at = q;
        const char *colon = at ? memchr(p, ':', (size_t)(at - p)) : NULL;
        if (colon)
            spans[0][0] = colon + 1, spans[0][1] = at;
    }
    if ((p = strstr(conninfo, "password=")) != NULL) {
        p += strlen("password=");
        spans[1][0] = p, spans[1][1] = p + strcspn(p, "& ");
    }
    for (int i = 0; i < 2; i++) {
        char secret[512];
        size_t n = spans[i][0] ? (size_t)(spans[i][1] - spans[i][0]) : 0;
        if (n == 0 || n >= sizeof secret)
            continue;
        memcpy(secret, spans[i][0], n);
        secret[n] = 0;
        for (char *hit = msg; (hit = strstr(hit, secret)) != NULL; hit += n)
            memset(hit, '*', n);
    }
}

static bool exec_ok(pg_store *s, const char *sql, const char *what, rs_err *err)
{
    PGresult *r = PQexec(s->conn, sql);
    ExecStatusType st = PQresultStatus(r);
    bool ok = st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK || pg_fail(s, err, what, r);
    PQclear(r);
    return ok;
}

static bool create_schema(pg_store *s, rs_err *err)
{
    /* Only create what is missing: CREATE ... IF NOT EXISTS still needs the
     * CREATE privilege, which a role given just the jobs table lacks. */
    PGresult *r = PQexec(s->conn, "SELECT to_regclass('jobs') IS NULL");
    if (PQresultStatus(r) != PGRES_TUPLES_OK) {
        pg_fail(s, err, "look for the jobs table", r);
        PQclear(r);
        return false;
    }
    bool missing = PQntuples(r) == 1 && PQgetvalue(r, 0, 0)[0] == 't';
    PQclear(r);
    /* Two daemons starting together on an empty database would both run
     * CREATE TABLE, and IF NOT EXISTS does not stop the loser failing on a
     * duplicate catalog row: the advisory lock puts them in line, and the
     * second one's IF NOT EXISTS then sees the first one's table. */
    if (missing && !(exec_ok(s, "BEGIN", "create the queue", err) &&
                     exec_ok(s, "SELECT pg_advisory_xact_lock(" SCHEMA_LOCK ")", "create the queue", err) &&
                     exec_ok(s, create_table, "create the jobs table", err) &&
                     exec_ok(s, "CREATE INDEX IF NOT EXISTS jobs_state ON jobs (state, id)", "create the index", err) &&
                     exec_ok(s, "COMMIT", "create the queue", err))) {
        PQclear(PQexec(s->conn, "ROLLBACK"));
        return false;
    }
    /* a jobs table that is not ours (another program's) */
    if (!exec_ok(s, "SELECT " JOB_COLS ", replay FROM jobs LIMIT 0", "check the jobs table", err)) {
        rs_err_prefix(err, "%s: table jobs is not a ringside queue", s->label);
        if (err)
            err->code = SVC_STORE_ERR_SCHEMA;
        return false;
    }
    return true;
}

svc_store *svc_store_pg_open(const char *conninfo, rs_err *err)
{
    pg_store *s = calloc(1, sizeof *s);
    if (!s) {
        rs_fail(err, SVC_STORE_ERR_NOMEM, "out of memory");
        return NULL;
    }
    s->base.ops = &pg_ops;
    pthread_mutex_init(&s->mu, NULL);
    /* Defaults the URI may override (its settings come after these): give
     * up on an unreachable server in seconds, not the minutes TCP would
     * take, and name ourselves in pg_stat_activity. */
    const char *const keys[] = {"connect_timeout", "fallback_application_name", "dbname", NULL};
    const char *const vals[] = {"10", "ringside", conninfo, NULL};
    s->conn = PQconnectdbParams(keys, vals, 1);
    make_label(s);
    if (!s->conn) {
        rs_fail(err, SVC_STORE_ERR_NOMEM, "%s: out of memory", s->label);
        goto fail;
    }
    if (PQstatus(s->conn) != CONNECTION_OK) {
        char msg[512];
        one_line(msg, sizeof msg, PQerrorMessage(s->conn));
        scrub(msg, conninfo);
        rs_fail(err, SVC_STORE_ERR_OPEN, "%s: cannot open the queue database: %s", s->label, msg);
        goto fail;
    }
    PQsetNoticeProcessor(s->conn, quiet, NULL);
    if (!create_schema(s, err))
        goto fail;
    return &s->base;
fail:
    pg_close(&s->base);
    return NULL;
}

#else /* !RS_HAVE_PQ */

svc_store *svc_store_pg_open(const char *conninfo, rs_err *err)
{
    (void)conninfo; /* may hold a password: not repeated */
    rs_fail(err, SVC_STORE_ERR_NOT_BUILT, "postgres: this ringside was built without libpq (install libpq-dev and rebuild)");
    return NULL;
}

#endif
