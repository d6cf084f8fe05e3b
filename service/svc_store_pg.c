/* svc_store_pg: the shared queue (PostgreSQL through libpq), a driver under
 * svc_store_sql.c, which holds the queue's rules.
 *
 * DESIGN: one PGconn per handle, used under the handle's mutex (a PGconn
 * must not be used by two threads at once; svc_store_sql.c holds it around
 * every call).  Any number of daemons on any number of machines share one
 * database.  Every change is one transaction, committed before the caller
 * hears about it.  The claim locks the job it takes with FOR UPDATE SKIP
 * LOCKED, so two daemons never get the same unit and never queue behind
 * each other's claim.  Times come from the server's clock (now()), never
 * from the calling machine.
 *
 * A lost connection (server restart, failover, an idle connection cut by a
 * proxy) is reset once and the statement retried once, when the statement
 * is the first of a call (a BEGIN, or a read on its own); inside a
 * transaction the call fails and the next one reconnects.  A reply lost
 * after a commit makes that call's change happen without the caller
 * knowing: a claim takes a unit nobody renders (its lease runs out and
 * reap requeues it), a submit queues a duplicate, a finish, release or
 * cancel answers "not ours" / "already over" when tried again.  Each is at
 * worst a wasted render, never a lost or doubly finished job.
 *
 * Values travel as typed parameters (int8, float8, text as text; the
 * replay as binary bytea: exact bytes, no escaping); results come back
 * binary, so the replay arrives as it was stored. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "svc_store.h"
#include "svc_store_sql.h"

#if defined(RS_HAVE_PQ)
#include <errno.h>
#include <limits.h>
#include <poll.h>
#include <time.h>

#include <libpq-fe.h>

typedef struct pg_conn {
    PGconn *conn;
    bool in_tx;      /* inside BEGIN..COMMIT: a lost connection is not retried */
    int wait_ms;     /* longest wait for an answer (lease_defaults) */
    char label[256]; /* "postgres host:port/db": names the server in messages, never the password */
} pg_conn;



#define C(x) ((pg_conn *)(x))

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
    " replay BYTEA NOT NULL,"
    " segment_ticks INTEGER NOT NULL DEFAULT 0, segments INTEGER NOT NULL DEFAULT 0, seg_key TEXT NOT NULL DEFAULT '',"
    " token_id BIGINT NOT NULL DEFAULT 0)";

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


static bool pg_fail(pg_conn *s, rs_err *err, const char *what, const PGresult *r)
{
    /* the primary message alone, without libpq's "ERROR:  ", when there is one */
    const char *m = r ? PQresultErrorField(r, PG_DIAG_MESSAGE_PRIMARY) : NULL;
    char msg[512];
    one_line(msg, sizeof msg, m ? m : s->conn ? PQerrorMessage(s->conn) : "out of memory");
    return rs_fail(err, SVC_STORE_ERR_QUERY, "%s: %s: %s", s->label, what, msg);
}

/* --- results (binary: integers big-endian, float8 IEEE, text as is) --- */

static int64_t be_int(const unsigned char *b, int n)
{
    if (n <= 0 || n > 8)
        return 0;
    uint64_t v = 0;
    for (int i = 0; i < n; i++)
        v = v << 8 | b[i];
    if (n < 8 && (b[0] & 0x80)) /* int4 and int2: sign-extend */
        v |= ~(uint64_t)0 << (8 * n);
    return (int64_t)v;
}

/* PostgreSQL type oids (pg_type.h), the ones our statements return */
enum { OID_BOOL = 16, OID_BYTEA = 17, OID_INT8 = 20, OID_INT2 = 21, OID_INT4 = 23, OID_TEXT = 25, OID_FLOAT4 = 700,
       OID_FLOAT8 = 701 };

static bool take_result(PGresult *r, sq_res *out)
{
    out->rows = PQntuples(r);
    out->cols = PQnfields(r);
    out->changed = atoll(PQcmdTuples(r));
    out->own = r;
    if (out->rows == 0 || out->cols == 0)
        return true;
    out->v = calloc((size_t)out->rows * (size_t)out->cols, sizeof *out->v);
    if (!out->v)
        return false;
    for (int k = 0; k < out->cols; k++) {
        Oid t = PQftype(r, k);
        for (int i = 0; i < out->rows; i++) {
            sq_val *v = &out->v[i * out->cols + k];
            const unsigned char *b = (const unsigned char *)PQgetvalue(r, i, k);
            int n = PQgetlength(r, i, k);
            if (PQgetisnull(r, i, k)) {
                v->type = SQ_NULL;
                continue;
            }
            switch (t) {
            case OID_BOOL:
            case OID_INT2:
            case OID_INT4:
            case OID_INT8:
                v->type = SQ_INT;
                v->i = be_int(b, n);
                v->f = (double)v->i;
                break;
            case OID_FLOAT4:
            case OID_FLOAT8: {
                uint64_t bits = (uint64_t)be_int(b, n);
                if (n == 8) {
                    memcpy(&v->f, &bits, sizeof v->f);
                } else {
                    uint32_t b4 = (uint32_t)bits;
                    float f;
                    memcpy(&f, &b4, sizeof f);
                    v->f = f;
                }
                v->type = SQ_REAL;
                v->i = (int64_t)v->f;
                break;
            }
            case OID_BYTEA:
                v->type = SQ_BLOB;
                v->s = (const char *)b;
                v->n = (size_t)n;
                break;
            default: /* text and its kin; libpq ends every value with a NUL */
                v->type = SQ_TEXT;
                v->s = (const char *)b;
                v->n = (size_t)n;
            }
        }
    }
    return true;
}

static void d_res_free(sq_res *r)
{
    PQclear(r->own);
    free(r->v);
    memset(r, 0, sizeof *r);
}

/* --- the driver --- */

static int64_t now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

/* PQexecParams, but waiting at most s->wait_ms for the answer: a server
 * that stopped answering (stalled, or a partition that TCP has not noticed
 * yet) holds no thread longer than that.  Its connection is then dropped
 * (PQresetStart: a new one is begun, the next call completes or fails it
 * within connect_timeout) and *late is set.  NULL or the last result. */
static PGresult *exec_within(pg_conn *s, const char *text, int nargs, const Oid *types, const char *const *vals,
                             const int *lens, const int *fmts, bool *late)
{
    *late = false;
    if (!PQsendQueryParams(s->conn, text, nargs, types, vals, lens, fmts, 1))
        return NULL;
    int64_t deadline = now_ms() + s->wait_ms;
    while (PQisBusy(s->conn)) {
        int64_t left = deadline - now_ms();
        if (left <= 0) {
            *late = true;
            PQresetStart(s->conn);
            return NULL;
        }
        struct pollfd p = {.fd = PQsocket(s->conn), .events = POLLIN};
        int n = poll(&p, 1, (int)left);
        if ((n < 0 && errno != EINTR) || (n > 0 && !PQconsumeInput(s->conn)))
            break; /* the connection failed: PQgetResult says how */
    }
    PGresult *last = NULL, *r;
    while ((r = PQgetResult(s->conn)) != NULL) {
        PQclear(last);
        last = r;
    }
    return last;
}

static int64_t d_exec(void *cp, const char *what, const char *sql, const sq_val *args, int nargs, sq_res *out,
                      rs_err *err)
{
    pg_conn *s = C(cp);
    char text[4096];
    if (!sq_spell(text, sizeof text, sql, "floor(extract(epoch from now()))::bigint", " FOR UPDATE",
                  " FOR UPDATE OF j SKIP LOCKED", true))
        return rs_fail(err, SVC_STORE_ERR_QUERY, "%s: %s: statement too long", s->label, what), -1;
    enum { MAXP = 24 }; /* the job insert has 17 */
    if (nargs > MAXP)
        return rs_fail(err, SVC_STORE_ERR_QUERY, "%s: %s: too many parameters", s->label, what), -1;
    Oid types[MAXP];
    const char *vals[MAXP];
    int lens[MAXP], fmts[MAXP];
    char buf[MAXP][32];
    for (int i = 0; i < nargs; i++) {
        const sq_val *a = &args[i];
        lens[i] = 0;
        fmts[i] = 0;
        switch (a->type) {
        case SQ_INT:
            types[i] = OID_INT8;
            snprintf(buf[i], sizeof buf[i], "%lld", (long long)a->i);
            vals[i] = buf[i];
            break;
        case SQ_REAL:
            /* %.17g round-trips a double; inf and NaN are not worth an error */
            types[i] = OID_FLOAT8;
            snprintf(buf[i], sizeof buf[i], "%.17g", isfinite(a->f) ? a->f : 0.0);
            vals[i] = buf[i];
            break;
        case SQ_TEXT:
            types[i] = OID_TEXT;
            vals[i] = a->s ? a->s : "";
            break;
        case SQ_BLOB:
            if (a->n > INT_MAX) /* libpq's lengths are ints (and bytea stops at 1 GiB) */
                return rs_fail(err, SVC_STORE_ERR_TOO_LARGE, "%s: %zu bytes are too large to queue", s->label, a->n), -1;
            types[i] = OID_BYTEA;
            vals[i] = a->s ? a->s : ""; /* a NULL value would be SQL NULL */
            lens[i] = (int)a->n;
            fmts[i] = 1;
            break;
        default: types[i] = 0, vals[i] = NULL;
        }
    }
    for (int tries = 0;; tries++) {
        bool late;
        PGresult *r = exec_within(s, text, nargs, types, vals, lens, fmts, &late);
        if (late) {
            rs_fail(err, SVC_STORE_ERR_CONNECTION, "%s: %s: no answer in %.1f s (the server is stalled or unreachable); "
                    "the connection was dropped", s->label, what, s->wait_ms / 1000.0);
            return -1;
        }
        ExecStatusType st = PQresultStatus(r); /* PGRES_FATAL_ERROR for NULL */
        if (st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK) {
            sq_res res = {0};
            if (!take_result(r, &res)) {
                d_res_free(&res);
                return rs_fail(err, SVC_STORE_ERR_NOMEM, "%s: %s: out of memory", s->label, what), -1;
            }
            int64_t changed = res.changed;
            if (out)
                *out = res;
            else
                d_res_free(&res);
            return changed;
        }
        if (tries == 0 && !s->in_tx && PQstatus(s->conn) != CONNECTION_OK) {
            /* the server went away: reconnect once and try again; a
             * statement error on a live connection is not retried */
            PQclear(r);
            PQreset(s->conn);
            if (PQstatus(s->conn) == CONNECTION_OK)
                continue;
            char msg[512];
            one_line(msg, sizeof msg, PQerrorMessage(s->conn));
            rs_fail(err, SVC_STORE_ERR_CONNECTION, "%s: %s: lost the connection and could not reconnect: %s", s->label,
                    what, msg);
            return -1;
        }
        if (PQstatus(s->conn) != CONNECTION_OK) {
            char msg[512];
            one_line(msg, sizeof msg, PQerrorMessage(s->conn));
            rs_fail(err, SVC_STORE_ERR_CONNECTION, "%s: %s: lost the connection: %s", s->label, what, msg);
        } else
            pg_fail(s, err, what, r);
        PQclear(r);
        return -1;
    }
}

static bool d_begin(void *c, rs_err *err)
{
    C(c)->in_tx = false;
    if (d_exec(c, "begin", "BEGIN", NULL, 0, NULL, err) < 0)
        return false;
    C(c)->in_tx = true;
    return true;
}

static bool d_commit(void *c, rs_err *err)
{
    bool ok = d_exec(c, "commit", "COMMIT", NULL, 0, NULL, err) >= 0;
    C(c)->in_tx = false;
    return ok;
}

static void d_rollback(void *c)
{
    pg_conn *s = C(c);
    if (s->in_tx && PQstatus(s->conn) == CONNECTION_OK)
        PQclear(PQexec(s->conn, "ROLLBACK"));
    s->in_tx = false;
}

static void d_close(void *c)
{
    pg_conn *s = C(c);
    if (!s)
        return;
    PQfinish(s->conn);
    free(s);
}

static const sq_driver pg_driver = {
    .name = "postgres",
    .begin = d_begin,
    .commit = d_commit,
    .rollback = d_rollback,
    .exec = d_exec,
    .res_free = d_res_free,
    .close = d_close,
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
static void make_label(pg_conn *s)
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


/* What the schema lacks: 1 the jobs table, 2 its segment columns (a queue
 * from before units), 4 the units table, 8 the lost-lease column (a queue
 * from before it: sq_schema_lost), 16 jobs.token_id (a queue from before
 * tokens), 32 the tokens table, 64 the replay header's columns (a queue
 * from before them: sq_schema_meta), 128 the job_files table; -1 on error. */
static int schema_needs(pg_conn *s, rs_err *err)
{
    sq_res r;
    if (d_exec(s, "look for the queue's tables",
               "SELECT to_regclass('jobs') IS NULL, NOT EXISTS (SELECT 1 FROM information_schema.columns"
               " WHERE table_schema = current_schema() AND table_name = 'jobs' AND column_name = 'segments'),"
               " to_regclass('units') IS NULL, NOT EXISTS (SELECT 1 FROM information_schema.columns"
               " WHERE table_schema = current_schema() AND table_name = 'units' AND column_name = 'lost'),"
               " NOT EXISTS (SELECT 1 FROM information_schema.columns"
               " WHERE table_schema = current_schema() AND table_name = 'jobs' AND column_name = 'token_id'),"
               " to_regclass('tokens') IS NULL, NOT EXISTS (SELECT 1 FROM information_schema.columns"
               " WHERE table_schema = current_schema() AND table_name = 'jobs' AND column_name = 'encode'),"
               " to_regclass('job_files') IS NULL",
               NULL, 0, &r, err) < 0)
        return -1;
    int need = r.rows == 1 ? (int)(r.v[0].i | r.v[1].i << 1 | r.v[2].i << 2 | r.v[3].i << 3 | r.v[4].i << 4 |
                                   r.v[5].i << 5 | r.v[6].i << 6 | r.v[7].i << 7)
                           : -1;
    d_res_free(&r);
    return need;
}

#define PG_HAS_COLUMN                                                                                               \
    "SELECT COUNT(*) FROM information_schema.columns WHERE table_schema = current_schema() AND table_name = ?1"     \
    " AND column_name = ?2"

static bool create_schema(pg_conn *s, rs_err *err)
{
    /* Only create what is missing: CREATE ... IF NOT EXISTS still needs the
     * CREATE privilege, which a role given just the queue's tables lacks. */
    int need = schema_needs(s, err);
    if (need < 0)
        return false;
    /* another program's jobs table is refused before anything changes */
    if (!(need & 1) && d_exec(s, "check the jobs table", "SELECT " SQ_JOB_COLS_V1 " FROM jobs LIMIT 0", NULL, 0, NULL, err) < 0) {
        rs_err_prefix(err, "%s: table jobs is not a ringside queue", s->label);
        if (err)
            err->code = SVC_STORE_ERR_SCHEMA;
        return false;
    }
    /* Two daemons starting together on an empty database would both run
     * CREATE TABLE, and IF NOT EXISTS does not stop the loser failing on a
     * duplicate catalog row: the advisory lock puts them in line, and the
     * second one looks again and finds the first one's tables. */
    if (need) {
        bool ok = d_begin(s, err) &&
                  d_exec(s, "create the queue", "SELECT pg_advisory_xact_lock(" SCHEMA_LOCK ")", NULL, 0, NULL, err) >= 0 &&
                  (need = schema_needs(s, err)) >= 0;
        /* a jobs table made here has the segment columns already */
        bool migrate = ok && (need & 2) && !(need & 1);
        ok = ok && (!(need & 1) || d_exec(s, "create the jobs table", create_table, NULL, 0, NULL, err) >= 0) &&
             (!(need & 1) || d_exec(s, "create the index", "CREATE INDEX IF NOT EXISTS jobs_state ON jobs (state, id)",
                                    NULL, 0, NULL, err) >= 0) &&
             (!(need & 15) || sq_schema_units(&pg_driver, s, migrate, err)) &&
             (!(need & 15) || sq_schema_lost(&pg_driver, s, PG_HAS_COLUMN, err)) &&
             (!(need & 48) || sq_schema_tokens(&pg_driver, s, "BIGSERIAL PRIMARY KEY", (need & 16) && !(need & 1), err)) &&
             (!(need & 65) || sq_schema_meta(&pg_driver, s, PG_HAS_COLUMN, err)) &&
             (!(need & 128) || sq_schema_files(&pg_driver, s, "bytea", true, err)) &&
             d_commit(s, err);
        if (!ok) {
            d_rollback(s);
            return false;
        }
    }
    /* a jobs table that is not ours (another program's) */
    if (d_exec(s, "check the jobs table", "SELECT " SQ_JOB_COLS ", replay FROM jobs LIMIT 0", NULL, 0, NULL, err) < 0 ||
        d_exec(s, "check the units table", "SELECT job_id, idx, kind, renders, done_attempt, lost FROM units LIMIT 0", NULL, 0,
               NULL, err) < 0) {
        rs_err_prefix(err, "%s: table jobs is not a ringside queue", s->label);
        if (err)
            err->code = SVC_STORE_ERR_SCHEMA;
        return false;
    }
    return true;
}

/* Connection defaults from the lease L (seconds), as libpq keyword values.
 *
 * DESIGN: a daemon's store handle must notice a server it cannot reach
 * well before a lease runs out (heartbeats come every L/6 s), not after
 * the minutes TCP takes to give up: connecting gives up after L/3 s
 * (at least 2), a statement after L/3 s (server side), unacknowledged data
 * after L/3 s (TCP_USER_TIMEOUT), and an idle connection whose server
 * vanished is found by keepalives in L/6 + 3 * L/12 s.  Each is a default:
 * the URI's own setting wins (its settings come after these), and a URI
 * with its own "options" replaces the statement timeout with them.  (A
 * server that stops answering altogether -- stalled, or cut off before TCP
 * notices -- is covered by exec_within's own deadline, L/3 + 1 s.) */
typedef struct pg_defaults {
    char connect[16], idle[16], interval[16], user_timeout[16], options[64];
} pg_defaults;

static void lease_defaults(int lease_s, pg_defaults *p)
{
    int third = lease_s / 3 > 1 ? lease_s / 3 : 1;
    snprintf(p->connect, sizeof p->connect, "%d", third > 2 ? third : 2);
    snprintf(p->idle, sizeof p->idle, "%d", lease_s / 6 > 1 ? lease_s / 6 : 1);
    snprintf(p->interval, sizeof p->interval, "%d", lease_s / 12 > 1 ? lease_s / 12 : 1);
    snprintf(p->user_timeout, sizeof p->user_timeout, "%d", third * 1000);
    snprintf(p->options, sizeof p->options, "-c statement_timeout=%d", third * 1000);
}

svc_store *svc_store_pg_open(const char *conninfo, int lease_s, rs_err *err)
{
    pg_conn *s = calloc(1, sizeof *s);
    if (!s) {
        rs_fail(err, SVC_STORE_ERR_NOMEM, "out of memory");
        return NULL;
    }
    pg_defaults def;
    lease_defaults(lease_s, &def);
    /* the server's statement timeout (L/3) answers first when it can answer at all */
    s->wait_ms = (lease_s / 3 > 1 ? lease_s / 3 : 1) * 1000 + 1000;
    /* defaults first, the URI (dbname, expanded) after them: it overrides */
    const char *const keys[] = {"connect_timeout", "keepalives", "keepalives_idle", "keepalives_interval",
                                "keepalives_count", "tcp_user_timeout", "options", "fallback_application_name",
                                "dbname", NULL};
    const char *const vals[] = {def.connect, "1", def.idle, def.interval, "3", def.user_timeout, def.options,
                                "ringside", conninfo, NULL};
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
    return sq_store_new(&pg_driver, s, err);
fail:
    d_close(s);
    return NULL;
}

#else /* !RS_HAVE_PQ */

svc_store *svc_store_pg_open(const char *conninfo, int lease_s, rs_err *err)
{
    (void)conninfo; /* may hold a password: not repeated */
    (void)lease_s;
    rs_fail(err, SVC_STORE_ERR_NOT_BUILT, "postgres: this ringside was built without libpq (install libpq-dev and rebuild)");
    return NULL;
}

#endif
