/* service/svc_store: the queue contract of svc_store.h, checked on every
 * backend by the same code.  SQLite runs always (a file in the case's temp
 * directory); PostgreSQL runs when RINGSIDE_TEST_PG holds a conninfo URI
 * (tests/service/test_store_pg.sh starts a throwaway server and sets it).
 * The PostgreSQL cases work in their own schema, ringside_test, dropped and
 * made again by every case, so they never touch a real queue's table.
 *   build/tests/test_svc_store [sqlite_|pg_|NAME...] */
#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include "../service/svc_store.h"
#include "t.h"

#if defined(RS_HAVE_PQ)
#include <libpq-fe.h>
#endif
#if defined(RS_HAVE_SQLITE)
#include <sqlite3.h>
#endif

#define PG_SCHEMA "ringside_test"

static char spec_buf[1200];

/* --- the two backends --- */

static const char *sqlite_spec(void)
{
#if !defined(RS_HAVE_SQLITE)
    T_SKIP("built without SQLite (install libsqlite3-dev and rebuild)");
#endif
    snprintf(spec_buf, sizeof spec_buf, "sqlite:%s/queue.db", t_tmpdir());
    return spec_buf;
}

static const char *pg_uri(void)
{
    const char *uri = getenv("RINGSIDE_TEST_PG");
    if (!uri || !*uri)
        T_SKIP("RINGSIDE_TEST_PG is not set: give it a conninfo URI (postgresql://USER@HOST:PORT/DB) or run "
               "tests/service/test_store_pg.sh, which starts a throwaway server");
#if !defined(RS_HAVE_PQ)
    T_SKIP("RINGSIDE_TEST_PG is set but this ringside was built without libpq (install libpq-dev and rebuild)");
#endif
    return uri;
}

#if defined(RS_HAVE_PQ)
/* A statement on the test's own connection; the first column of the first
 * row as an integer (0 when there is none). */
static long long pg_admin(const char *sql)
{
    PGconn *c = PQconnectdb(pg_uri());
    T_ASSERTF(PQstatus(c) == CONNECTION_OK, "RINGSIDE_TEST_PG: %s", PQerrorMessage(c));
    PGresult *r = PQexec(c, sql);
    ExecStatusType st = PQresultStatus(r);
    T_ASSERTF(st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK, "%s: %s", sql, PQerrorMessage(c));
    long long v = st == PGRES_TUPLES_OK && PQntuples(r) > 0 ? atoll(PQgetvalue(r, 0, 0)) : 0;
    PQclear(r);
    PQfinish(c);
    return v;
}
#else
static long long pg_admin(const char *sql)
{
    (void)sql;
    T_SKIP("built without libpq");
}
#endif

/* The URI with search_path set to a fresh, empty test schema. */
static const char *pg_spec(void)
{
    const char *uri = pg_uri();
    pg_admin("SET client_min_messages = warning; DROP SCHEMA IF EXISTS " PG_SCHEMA " CASCADE; CREATE SCHEMA " PG_SCHEMA);
    snprintf(spec_buf, sizeof spec_buf, "%s%coptions=-csearch_path%%3D" PG_SCHEMA, uri, strchr(uri, '?') ? '&' : '?');
    return spec_buf;
}

/* --- helpers --- */

static svc_store *open_ok(const char *spec)
{
    rs_err e = {0};
    svc_store *s = svc_store_open(spec, &e);
    T_ASSERTF(s, "open %s: %s", spec, e.msg);
    return s;
}

static int64_t submit(svc_store *s, const char *name, const void *data, size_t n)
{
    rs_err e = {0};
    svc_job j = {.width = 640, .height = 360, .frames_total = 600, .replay = (uint8_t *)data, .replay_len = n};
    snprintf(j.name, sizeof j.name, "%s", name);
    snprintf(j.format, sizeof j.format, "mp4");
    T_ASSERTF(s->ops->submit(s, &j, &e), "submit %s: %s", name, e.msg);
    T_ASSERT(j.id > 0);
    T_EQ(j.state, SVC_QUEUED);
    return j.id;
}

static svc_job get_ok(svc_store *s, int64_t id)
{
    rs_err e = {0};
    svc_job j;
    int r = s->ops->get(s, id, &j, &e);
    T_ASSERTF(r == 1, "get %lld: %d %s", (long long)id, r, e.msg);
    T_ASSERT(j.replay == NULL && j.replay_len == 0);
    return j;
}

static svc_job claim_ok(svc_store *s, const char *owner, int lease_s)
{
    rs_err e = {0};
    svc_job j;
    int r = s->ops->claim(s, owner, lease_s, &j, &e);
    T_ASSERTF(r == 1, "claim by %s: %d %s", owner, r, e.msg);
    T_EQ(j.state, SVC_RUNNING);
    T_ASSERT(strcmp(j.owner, owner) == 0);
    return j;
}

static void claim_none(svc_store *s)
{
    rs_err e = {0};
    svc_job j;
    int r = s->ops->claim(s, "nobody:0", 60, &j, &e);
    T_ASSERTF(r == 0, "claim on an empty queue: %d %s", r, e.msg);
}

static void fill_random(uint8_t *p, size_t n, uint64_t seed)
{
    for (size_t i = 0; i < n; i++) {
        seed ^= seed << 13, seed ^= seed >> 7, seed ^= seed << 17;
        p[i] = (uint8_t)(seed >> 24);
    }
}

/* --- the contract, once for both backends --- */

static void roundtrip(const char *spec)
{
    svc_store *s = open_ok(spec);
    T_ASSERT(!strcmp(s->ops->name, strncmp(spec, "sqlite:", 7) ? "postgres" : "sqlite"));
    size_t big = 1 << 20;
    uint8_t *rnd = malloc(big), pattern[256], empty[1];
    T_ASSERT(rnd);
    fill_random(rnd, big, 0x9e3779b97f4a7c15ull);
    rnd[0] = 0, rnd[big / 2] = 0, rnd[big - 1] = 0; /* NULs inside and at the ends */
    for (int i = 0; i < 256; i++)
        pattern[i] = (uint8_t)i;
    const struct {
        const char *name;
        const uint8_t *data;
        size_t n;
    } cases[] = {{"empty.rsr", empty, 0}, {"bytes 'x' \"y\" \\ \xc3\xbc.rsr", pattern, 256}, {"big.rsr", rnd, big}};
    int64_t ids[3];
    time_t t0 = time(NULL);
    for (int i = 0; i < 3; i++)
        ids[i] = submit(s, cases[i].name, cases[i].data, cases[i].n);
    T_ASSERT(ids[0] < ids[1] && ids[1] < ids[2]);
    for (int i = 0; i < 3; i++) {
        svc_job g = get_ok(s, ids[i]);
        T_EQ(g.id, ids[i]);
        T_EQ(g.state, SVC_QUEUED);
        T_ASSERTF(!strcmp(g.name, cases[i].name), "name '%s', want '%s'", g.name, cases[i].name);
        T_ASSERT(g.width == 640 && g.height == 360 && !strcmp(g.format, "mp4"));
        T_ASSERT(g.frames_done == 0 && g.frames_total == 600 && g.fps == 0);
        T_ASSERT(g.attempts == 0 && g.desync_tick == -1 && !g.error[0] && !g.owner[0]);
        T_ASSERTF(g.created > t0 - 60 && g.created < t0 + 60, "created %lld, now %lld", (long long)g.created,
                  (long long)t0);
        T_ASSERT(g.started == 0 && g.finished == 0 && g.claimed_until == 0);
    }
    for (int i = 0; i < 3; i++) {
        svc_job c = claim_ok(s, "host:1", 60);
        T_EQ(c.id, ids[i]);
        T_EQ(c.replay_len, cases[i].n);
        T_ASSERT(c.replay != NULL);
        T_ASSERTF(cases[i].n == 0 || !memcmp(c.replay, cases[i].data, cases[i].n), "replay %d differs", i);
        svc_job_free(&c);
        T_ASSERT(c.replay == NULL);
    }
    rs_err e = {0};
    svc_job nope;
    T_EQ(s->ops->get(s, ids[2] + 1000, &nope, &e), 0);
    free(rnd);
    s->ops->close(s);
}

static void claim_order(const char *spec)
{
    svc_store *s = open_ok(spec);
    claim_none(s);
    int64_t a = submit(s, "a", "a", 1), b = submit(s, "b", "b", 1), c = submit(s, "c", "c", 1);
    int64_t want[3] = {a, b, c};
    for (int i = 0; i < 3; i++) {
        svc_job j = claim_ok(s, "host:1", 60);
        T_EQ(j.id, want[i]);
        T_EQ(j.attempts, 1);
        T_EQ(j.frames_done, 0);
        T_ASSERT(j.started > 0);
        T_EQ(j.claimed_until, j.started + 60);
        svc_job g = get_ok(s, j.id);
        T_EQ(g.state, SVC_RUNNING);
        T_EQ(g.claimed_until, j.claimed_until);
        svc_job_free(&j);
    }
    claim_none(s);
    s->ops->close(s);
}

static void attempts(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t id = submit(s, "a", "a", 1);
    for (int i = 1; i <= 3; i++) {
        svc_job j = claim_ok(s, "host:1", 60);
        T_EQ(j.id, id);
        T_EQ(j.attempts, i);
        T_EQ(get_ok(s, id).attempts, i);
        svc_job_free(&j);
        T_EQ(s->ops->release(s, id, "host:1", "worker crashed", true, 5, &e), 1);
        T_EQ(get_ok(s, id).attempts, i);
    }
    s->ops->close(s);
}

static void heartbeat(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t id = submit(s, "a", "a", 1), queued = submit(s, "q", "q", 1);
    svc_job j = claim_ok(s, "host:1", 60);
    svc_job_free(&j);
    T_EQ(s->ops->heartbeat(s, id, "host:1", 600, 10, 700, 59.5, &e), 1);
    svc_job g = get_ok(s, id);
    T_EQ(g.frames_done, 10);
    T_EQ(g.frames_total, 700);
    T_ASSERT(g.fps == 59.5);
    T_ASSERTF(g.claimed_until >= j.started + 600, "lease not extended: %lld", (long long)g.claimed_until);
    /* another owner, a queued job, a missing job: not ours, nothing changes */
    T_EQ(s->ops->heartbeat(s, id, "other:2", 600, 99, 99, 1, &e), 0);
    T_EQ(s->ops->heartbeat(s, queued, "host:1", 600, 99, 99, 1, &e), 0);
    T_EQ(s->ops->heartbeat(s, id + 1000, "host:1", 600, 99, 99, 1, &e), 0);
    T_EQ(get_ok(s, id).frames_done, 10);
    T_EQ(get_ok(s, queued).frames_done, 0);
    s->ops->close(s);
}

static void finish(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t a = submit(s, "a", "a", 1), b = submit(s, "b", "b", 1);
    svc_job j = claim_ok(s, "host:1", 60);
    svc_job_free(&j);
    j = claim_ok(s, "host:1", 60);
    svc_job_free(&j);
    T_EQ(s->ops->finish(s, a, "host:1", SVC_DONE, NULL, -1, 600, &e), 1);
    svc_job g = get_ok(s, a);
    T_EQ(g.state, SVC_DONE);
    T_EQ(g.frames_done, 600);
    T_EQ(g.desync_tick, -1);
    T_ASSERT(!g.error[0]);
    T_ASSERT(g.finished >= g.started && g.finished > 0);
    T_EQ(g.claimed_until, 0);
    /* over: neither a second finish nor a heartbeat touches it */
    T_EQ(s->ops->finish(s, a, "host:1", SVC_FAILED, "late", 3, 1, &e), 0);
    T_EQ(s->ops->heartbeat(s, a, "host:1", 60, 1, 1, 1, &e), 0);
    T_EQ(get_ok(s, a).state, SVC_DONE);
    /* someone else's job */
    T_EQ(s->ops->finish(s, b, "other:2", SVC_DONE, NULL, -1, 600, &e), 0);
    T_EQ(get_ok(s, b).state, SVC_RUNNING);
    T_EQ(s->ops->finish(s, b, "host:1", SVC_FAILED, "desync at tick 42", 42, 50, &e), 1);
    g = get_ok(s, b);
    T_EQ(g.state, SVC_FAILED);
    T_ASSERT(!strcmp(g.error, "desync at tick 42"));
    T_EQ(g.desync_tick, 42);
    T_EQ(g.frames_done, 50);
    s->ops->close(s);
}

static void cancel(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t run = submit(s, "run", "r", 1), done = submit(s, "done", "d", 1), queued = submit(s, "q", "q", 1);
    svc_job j = claim_ok(s, "host:1", 60);
    T_EQ(j.id, run);
    svc_job_free(&j);
    j = claim_ok(s, "host:1", 60);
    svc_job_free(&j);
    T_EQ(s->ops->finish(s, done, "host:1", SVC_DONE, NULL, -1, 1, &e), 1);

    T_EQ(s->ops->cancel(s, queued, &e), 1);
    svc_job g = get_ok(s, queued);
    T_EQ(g.state, SVC_CANCELLED);
    T_ASSERT(g.finished > 0);
    claim_none(s); /* a cancelled job is never handed out */

    T_EQ(s->ops->cancel(s, run, &e), 1);
    T_EQ(get_ok(s, run).state, SVC_CANCELLED);
    T_EQ(get_ok(s, run).claimed_until, 0);
    /* the old owner lost it: it can neither extend, finish nor release it */
    T_EQ(s->ops->heartbeat(s, run, "host:1", 60, 5, 5, 1, &e), 0);
    T_EQ(s->ops->finish(s, run, "host:1", SVC_DONE, NULL, -1, 5, &e), 0);
    T_EQ(s->ops->release(s, run, "host:1", "shutting down", false, 3, &e), 0);
    T_EQ(get_ok(s, run).state, SVC_CANCELLED);

    T_EQ(s->ops->cancel(s, done, &e), 2);
    T_EQ(get_ok(s, done).state, SVC_DONE);
    T_EQ(s->ops->cancel(s, queued, &e), 2);
    T_EQ(s->ops->cancel(s, queued + 1000, &e), 0);
    s->ops->close(s);
}

static void dead_letter(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t id = submit(s, "a", "a", 1);
    T_EQ(s->ops->release(s, id, "host:1", "queued, not ours", true, 3, &e), 0);
    for (int i = 1; i <= 3; i++) {
        svc_job j = claim_ok(s, "host:1", 60);
        T_EQ(j.id, id);
        svc_job_free(&j);
        T_EQ(s->ops->release(s, id, "other:2", "not the owner", true, 3, &e), 0);
        T_EQ(s->ops->release(s, id, "host:1", "worker crashed", true, 3, &e), 1);
        svc_job g = get_ok(s, id);
        T_EQ(g.attempts, i);
        T_ASSERT(!g.owner[0]);
        T_EQ(g.claimed_until, 0);
        if (i < 3) {
            T_EQ(g.state, SVC_QUEUED);
            T_ASSERT(!strcmp(g.error, "worker crashed"));
            T_EQ(g.finished, 0);
        } else {
            T_EQ(g.state, SVC_FAILED);
            T_ASSERTF(!strcmp(g.error, "gave up after 3 attempts: worker crashed"), "error '%s'", g.error);
            T_ASSERT(g.finished > 0);
        }
    }
    claim_none(s);
    /* one attempt allowed: the singular */
    int64_t one = submit(s, "b", "b", 1);
    svc_job j = claim_ok(s, "host:1", 60);
    svc_job_free(&j);
    T_EQ(s->ops->release(s, one, "host:1", "boom", true, 1, &e), 1);
    svc_job g = get_ok(s, one);
    T_EQ(g.state, SVC_FAILED);
    T_ASSERTF(!strcmp(g.error, "gave up after 1 attempt: boom"), "error '%s'", g.error);
    s->ops->close(s);
}

static void give_back(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t id = submit(s, "a", "a", 1);
    svc_job j = claim_ok(s, "host:1", 60);
    svc_job_free(&j);
    /* a clean shutdown: even at the cap the job goes back, attempt returned */
    T_EQ(s->ops->release(s, id, "host:1", "daemon shutting down", false, 1, &e), 1);
    svc_job g = get_ok(s, id);
    T_EQ(g.state, SVC_QUEUED);
    T_EQ(g.attempts, 0);
    T_ASSERT(!strcmp(g.error, "daemon shutting down"));
    T_ASSERT(!g.owner[0]);
    j = claim_ok(s, "host:2", 60);
    T_EQ(j.id, id);
    T_EQ(j.attempts, 1);
    svc_job_free(&j);
    s->ops->close(s);
}

static void reap(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t lost = submit(s, "lost", "l", 1), alive = submit(s, "alive", "a", 1), zero = submit(s, "zero", "z", 1);
    int64_t queued = submit(s, "queued", "q", 1);
    svc_job j = claim_ok(s, "a:1", -5); /* a lease that ran out 5 s ago */
    T_EQ(j.id, lost);
    svc_job_free(&j);
    j = claim_ok(s, "b:2", 3600);
    svc_job_free(&j);
    T_EQ(s->ops->reap(s, 3, false, &e), 1);
    svc_job g = get_ok(s, lost);
    T_EQ(g.state, SVC_QUEUED);
    T_ASSERTF(!strcmp(g.error, SVC_LEASE_EXPIRED), "error '%s'", g.error);
    T_ASSERT(!g.owner[0]);
    T_EQ(g.attempts, 1);
    T_EQ(get_ok(s, alive).state, SVC_RUNNING);
    T_EQ(get_ok(s, queued).state, SVC_QUEUED);
    /* the old owner comes back too late */
    T_EQ(s->ops->heartbeat(s, lost, "a:1", 60, 1, 1, 1, &e), 0);
    T_EQ(s->ops->finish(s, lost, "a:1", SVC_DONE, NULL, -1, 1, &e), 0);
    T_EQ(s->ops->release(s, lost, "a:1", "x", true, 3, &e), 0);
    T_EQ(get_ok(s, lost).state, SVC_QUEUED);

    /* reaped at the cap: dead letter */
    j = claim_ok(s, "a:1", -5);
    T_EQ(j.id, lost);
    T_EQ(j.attempts, 2);
    svc_job_free(&j);
    T_EQ(s->ops->reap(s, 2, false, &e), 1);
    g = get_ok(s, lost);
    T_EQ(g.state, SVC_FAILED);
    T_ASSERTF(!strcmp(g.error, "gave up after 2 attempts: " SVC_LEASE_EXPIRED), "error '%s'", g.error);

    /* a lease of 0 s lasts until the end of the current second:
     * claimed_until == now is still valid, claimed_until < now is not */
    j = claim_ok(s, "c:3", 0);
    T_EQ(j.id, zero);
    T_EQ(j.claimed_until, j.started);
    svc_job_free(&j);
    struct timespec ts = {1, 200 * 1000 * 1000};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
    }
    T_EQ(s->ops->reap(s, 3, false, &e), 1);
    T_EQ(get_ok(s, zero).state, SVC_QUEUED);
    T_EQ(get_ok(s, alive).state, SVC_RUNNING);

    /* all: every running job, lease or not (an SQLite daemon starting up) */
    T_EQ(s->ops->reap(s, 3, true, &e), 1);
    g = get_ok(s, alive);
    T_EQ(g.state, SVC_QUEUED);
    T_ASSERT(!strcmp(g.error, SVC_LEASE_EXPIRED));
    T_EQ(g.attempts, 1);
    T_EQ(s->ops->reap(s, 3, true, &e), 0);
    s->ops->close(s);
}

static void list_paging(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    svc_job out[8];
    T_EQ(s->ops->list(s, 0, 8, out, &e), 0);
    int64_t id[5];
    for (int i = 0; i < 5; i++) {
        char name[16];
        snprintf(name, sizeof name, "j%d", i);
        id[i] = submit(s, name, "x", 1);
    }
    T_EQ(s->ops->list(s, 0, 2, out, &e), 2);
    T_EQ(out[0].id, id[4]);
    T_EQ(out[1].id, id[3]);
    T_ASSERT(!strcmp(out[0].name, "j4") && out[0].replay == NULL);
    T_EQ(s->ops->list(s, out[1].id, 2, out, &e), 2);
    T_EQ(out[0].id, id[2]);
    T_EQ(out[1].id, id[1]);
    T_EQ(s->ops->list(s, out[1].id, 8, out, &e), 1);
    T_EQ(out[0].id, id[0]);
    T_EQ(s->ops->list(s, id[0], 8, out, &e), 0);
    T_EQ(s->ops->list(s, 0, 8, out, &e), 5);
    for (int i = 0; i < 5; i++)
        T_EQ(out[i].id, id[4 - i]);
    T_EQ(s->ops->list(s, 0, 0, out, &e), 0);
    s->ops->close(s);
}

static void counts(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t n[SVC_NSTATES];
    T_ASSERTF(s->ops->counts(s, n, &e), "counts: %s", e.msg);
    for (int i = 0; i < SVC_NSTATES; i++)
        T_EQ(n[i], 0);
    int64_t id[6];
    for (int i = 0; i < 6; i++)
        id[i] = submit(s, "x", "x", 1);
    for (int i = 0; i < 4; i++) {
        svc_job j = claim_ok(s, "host:1", 60);
        svc_job_free(&j);
    }
    T_EQ(s->ops->finish(s, id[0], "host:1", SVC_DONE, NULL, -1, 1, &e), 1);
    T_EQ(s->ops->finish(s, id[1], "host:1", SVC_FAILED, "bad", -1, 1, &e), 1);
    T_EQ(s->ops->cancel(s, id[2], &e), 1);
    T_ASSERTF(s->ops->counts(s, n, &e), "counts: %s", e.msg);
    T_EQ(n[SVC_QUEUED], 2);
    T_EQ(n[SVC_RUNNING], 1);
    T_EQ(n[SVC_DONE], 1);
    T_EQ(n[SVC_FAILED], 1);
    T_EQ(n[SVC_CANCELLED], 1);
    T_ASSERT(!strcmp(svc_state_name(SVC_CANCELLED), "cancelled") && !strcmp(svc_state_name(99), "unknown"));
    s->ops->close(s);
}

static void persistence(const char *spec)
{
    uint8_t data[4096];
    fill_random(data, sizeof data, 7);
    svc_store *s = open_ok(spec);
    int64_t a = submit(s, "a", data, sizeof data), b = submit(s, "b", data, sizeof data / 2);
    svc_job j = claim_ok(s, "host:1", 600);
    svc_job_free(&j);
    s->ops->close(s);

    s = open_ok(spec); /* the schema exists now: opening again keeps the rows */
    svc_job g = get_ok(s, a);
    T_EQ(g.state, SVC_RUNNING);
    T_ASSERT(!strcmp(g.owner, "host:1"));
    T_EQ(get_ok(s, b).state, SVC_QUEUED);
    j = claim_ok(s, "host:2", 60);
    T_EQ(j.id, b);
    T_EQ(j.replay_len, sizeof data / 2);
    T_ASSERT(!memcmp(j.replay, data, sizeof data / 2));
    svc_job_free(&j);
    rs_err e = {0};
    T_EQ(s->ops->finish(s, a, "host:1", SVC_DONE, NULL, -1, 1, &e), 1);
    s->ops->close(s);
}

/* Four daemons (processes, one handle each) drain 40 jobs: each job is
 * claimed exactly once. */
#define NJOBS 40
#define NWORKERS 4

static void read_ids(int fd, int hits[NJOBS], const int64_t *ids)
{
    int64_t id;
    ssize_t r;
    while ((r = read(fd, &id, sizeof id)) == (ssize_t)sizeof id) {
        int k = -1;
        for (int i = 0; i < NJOBS; i++)
            if (ids[i] == id)
                k = i;
        T_ASSERTF(k >= 0, "claimed job %lld was never submitted", (long long)id);
        hits[k]++;
    }
    T_EQ(r, 0);
}

static void concurrent_claim(const char *spec)
{
    svc_store *s = open_ok(spec);
    int64_t ids[NJOBS];
    for (int i = 0; i < NJOBS; i++)
        ids[i] = submit(s, "x", &i, sizeof i);
    int fd[2];
    T_ASSERT(pipe(fd) == 0);
    pid_t kid[NWORKERS];
    for (int k = 0; k < NWORKERS; k++) {
        kid[k] = fork();
        T_ASSERT(kid[k] >= 0);
        if (kid[k] == 0) {
            close(fd[0]);
            rs_err e = {0};
            svc_store *w = svc_store_open(spec, &e);
            if (!w) {
                fprintf(stderr, "    worker %d: open: %s\n", k, e.msg);
                _exit(2);
            }
            char owner[32];
            snprintf(owner, sizeof owner, "w%d:%d", k, (int)getpid());
            for (;;) {
                svc_job j;
                int r = w->ops->claim(w, owner, 60, &j, &e);
                if (r == 0)
                    break;
                if (r < 0) {
                    fprintf(stderr, "    worker %d: claim: %s\n", k, e.msg);
                    _exit(3);
                }
                if (write(fd[1], &j.id, sizeof j.id) != (ssize_t)sizeof j.id)
                    _exit(4);
                svc_job_free(&j);
            }
            w->ops->close(w);
            _exit(0);
        }
    }
    close(fd[1]);
    int hits[NJOBS] = {0};
    read_ids(fd[0], hits, ids);
    close(fd[0]);
    for (int k = 0; k < NWORKERS; k++) {
        int st = 0;
        T_ASSERT(waitpid(kid[k], &st, 0) == kid[k]);
        T_ASSERTF(WIFEXITED(st) && WEXITSTATUS(st) == 0, "worker %d ended with status %#x", k, st);
    }
    for (int i = 0; i < NJOBS; i++)
        T_ASSERTF(hits[i] == 1, "job %lld claimed %d times", (long long)ids[i], hits[i]);
    rs_err e = {0};
    int64_t n[SVC_NSTATES];
    T_ASSERT(s->ops->counts(s, n, &e));
    T_EQ(n[SVC_RUNNING], NJOBS);
    T_EQ(n[SVC_QUEUED], 0);
    s->ops->close(s);
}

/* The daemon's HTTP threads share one handle: its mutex must keep them apart. */
typedef struct drain_arg {
    svc_store *s;
    int fd;
    int failed;
} drain_arg;

static void *drain(void *p)
{
    drain_arg *a = p;
    rs_err e = {0};
    svc_job j;
    int r;
    while ((r = a->s->ops->claim(a->s, "threads:1", 60, &j, &e)) == 1) {
        if (write(a->fd, &j.id, sizeof j.id) != (ssize_t)sizeof j.id)
            a->failed = 1;
        svc_job_free(&j);
    }
    if (r < 0)
        a->failed = 1;
    return NULL;
}

static void shared_handle(const char *spec)
{
    svc_store *s = open_ok(spec);
    int64_t ids[NJOBS];
    for (int i = 0; i < NJOBS; i++)
        ids[i] = submit(s, "x", &i, sizeof i);
    int fd[2];
    T_ASSERT(pipe(fd) == 0);
    pthread_t th[NWORKERS];
    drain_arg arg[NWORKERS];
    for (int k = 0; k < NWORKERS; k++) {
        arg[k] = (drain_arg){s, fd[1], 0};
        T_ASSERT(pthread_create(&th[k], NULL, drain, &arg[k]) == 0);
    }
    for (int k = 0; k < NWORKERS; k++) {
        pthread_join(th[k], NULL);
        T_EQ(arg[k].failed, 0);
    }
    close(fd[1]);
    int hits[NJOBS] = {0};
    read_ids(fd[0], hits, ids);
    close(fd[0]);
    for (int i = 0; i < NJOBS; i++)
        T_ASSERTF(hits[i] == 1, "job %lld claimed %d times", (long long)ids[i], hits[i]);
    s->ops->close(s);
}

/* Daemons started together against an empty database all open it (the
 * schema is made once, without a duplicate-table error for the others). */
static void open_race(const char *spec)
{
    enum { N = 8 };
    int gate[2];
    T_ASSERT(pipe(gate) == 0);
    pid_t kid[N];
    for (int k = 0; k < N; k++) {
        kid[k] = fork();
        T_ASSERT(kid[k] >= 0);
        if (kid[k] == 0) {
            close(gate[1]);
            char c;
            while (read(gate[0], &c, 1) < 0 && errno == EINTR) {
            }
            rs_err e = {0};
            svc_store *s = svc_store_open(spec, &e);
            if (!s) {
                fprintf(stderr, "    opener %d: %s\n", k, e.msg);
                _exit(1);
            }
            s->ops->close(s);
            _exit(0);
        }
    }
    close(gate[0]);
    close(gate[1]); /* every child's read returns now */
    for (int k = 0; k < N; k++) {
        int st = 0;
        T_ASSERT(waitpid(kid[k], &st, 0) == kid[k]);
        T_ASSERTF(WIFEXITED(st) && WEXITSTATUS(st) == 0, "opener %d ended with status %#x", k, st);
    }
    svc_store *s = open_ok(spec);
    T_ASSERT(get_ok(s, submit(s, "after", "x", 1)).created > 0);
    s->ops->close(s);
}

#define BOTH(fn)                                                                                                      \
    static void t_sqlite_##fn(void) { fn(sqlite_spec()); }                                                            \
    static void t_pg_##fn(void) { fn(pg_spec()); }
#define CASES(fn) {"sqlite_" #fn, t_sqlite_##fn}, {"pg_" #fn, t_pg_##fn}

BOTH(roundtrip)
BOTH(claim_order)
BOTH(attempts)
BOTH(heartbeat)
BOTH(finish)
BOTH(cancel)
BOTH(dead_letter)
BOTH(give_back)
BOTH(reap)
BOTH(list_paging)
BOTH(counts)
BOTH(persistence)
BOTH(concurrent_claim)
BOTH(shared_handle)
BOTH(open_race)

/* --- what each backend refuses, and how it says so --- */

static void expect_open_fail(const char *spec, int code, const char *want)
{
    rs_err e = {0};
    svc_store *s = svc_store_open(spec, &e);
    T_ASSERTF(!s, "%s opened", spec);
    T_ASSERTF(e.code == code, "%s: %s, want %s (%s)", spec, svc_store_error_text(e.code), svc_store_error_text(code),
              e.msg);
    T_CONTAINS(e.msg, want);
}

static void t_sqlite_bad_files(void)
{
    const char *d = t_tmpdir();
    char p[600];
    expect_open_fail("queue.txt", SVC_STORE_ERR_SPEC, "expected sqlite:PATH, a path ending in .db, or postgres://");
    expect_open_fail("sqlite:", SVC_STORE_ERR_SPEC, "the database path is missing");
    sqlite_spec();
    snprintf(p, sizeof p, "sqlite:%s/no/such/dir/q.db", d);
    expect_open_fail(p, SVC_STORE_ERR_OPEN, "/no/such/dir/q.db");
    /* a file that is not a database at all */
    char text[4096];
    memset(text, 'x', sizeof text - 1);
    text[sizeof text - 1] = 0;
    t_write(d, "notes.db", text);
    snprintf(p, sizeof p, "%s/notes.db", d);
    expect_open_fail(p, SVC_STORE_ERR_OPEN, "notes.db");
#if defined(RS_HAVE_SQLITE)
    /* another program's database with its own jobs table */
    snprintf(p, sizeof p, "%s/other.db", d);
    sqlite3 *db = NULL;
    T_ASSERT(sqlite3_open(p, &db) == SQLITE_OK);
    T_ASSERT(sqlite3_exec(db, "CREATE TABLE jobs (title TEXT, salary INTEGER)", NULL, NULL, NULL) == SQLITE_OK);
    sqlite3_close(db);
    expect_open_fail(p, SVC_STORE_ERR_SCHEMA, "other.db");
#endif
}

static int closed_port(void)
{
    /* a port the kernel just gave us and we let go: nothing listens there */
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    socklen_t n = sizeof a;
    T_ASSERT(fd >= 0 && bind(fd, (struct sockaddr *)&a, sizeof a) == 0);
    T_ASSERT(getsockname(fd, (struct sockaddr *)&a, &n) == 0);
    close(fd);
    return ntohs(a.sin_port);
}

static void t_pg_unreachable(void)
{
    char uri[256], where[64];
    int port = closed_port();
    snprintf(where, sizeof where, "127.0.0.1:%d/ringside", port);
#if defined(RS_HAVE_PQ)
    /* the server is named, the password is not */
    const char *forms[] = {"postgresql://ringside:s3cret-pw@127.0.0.1:%d/ringside",
                           "postgres://ringside@127.0.0.1:%d/ringside?password=s3cret-pw&connect_timeout=5"};
    for (int i = 0; i < 2; i++) {
        snprintf(uri, sizeof uri, forms[i], port);
        rs_err e = {0};
        T_ASSERT(!svc_store_open(uri, &e));
        T_EQ(e.code, SVC_STORE_ERR_OPEN);
        T_CONTAINS(e.msg, where);
        T_ASSERTF(!strstr(e.msg, "s3cret-pw"), "password in '%s'", e.msg);
    }
    /* libpq quotes a malformed URI whole */
    rs_err e = {0};
    T_ASSERT(!svc_store_open("postgresql://ringside:s3cret-pw@[::1/ringside", &e));
    T_EQ(e.code, SVC_STORE_ERR_OPEN);
    T_ASSERT(e.msg[0]);
    T_ASSERTF(!strstr(e.msg, "s3cret-pw"), "password in '%s'", e.msg);
#else
    snprintf(uri, sizeof uri, "postgresql://ringside:s3cret-pw@127.0.0.1:%d/ringside", port);
    expect_open_fail(uri, SVC_STORE_ERR_NOT_BUILT, "built without libpq (install libpq-dev and rebuild)");
    rs_err e = {0};
    svc_store_open(uri, &e);
    T_ASSERT(!strstr(e.msg, "s3cret-pw"));
    (void)where;
#endif
}

static void t_pg_foreign_table(void)
{
    const char *spec = pg_spec();
    pg_admin("CREATE TABLE " PG_SCHEMA ".jobs (title TEXT, salary INTEGER)");
    expect_open_fail(spec, SVC_STORE_ERR_SCHEMA, "table jobs is not a ringside queue");
}

/* Every id has a text, and no two share one. */
static void t_error_ids_have_texts(void)
{
    T_EQ(RS_ERR_MODULE(SVC_STORE_ERR_BASE + 1), RS_ERR_MOD_SVC_STORE);
    T_EQ(RS_ERR_MODULE(SVC_STORE_ERR_END - 1), RS_ERR_MOD_SVC_STORE);
    for (int a = SVC_STORE_ERR_BASE + 1; a < SVC_STORE_ERR_END; a++) {
        const char *t = svc_store_error_text(a);
        T_ASSERTF(t[0] && strcmp(t, "?") && strcmp(t, "ok"), "id %d has no text", a);
        for (int b = SVC_STORE_ERR_BASE + 1; b < a; b++)
            T_ASSERTF(strcmp(t, svc_store_error_text(b)), "ids %d and %d share the text \"%s\"", b, a, t);
    }
    T_ASSERT(!strcmp(svc_store_error_text(SVC_STORE_ERR_END), "?"));
}

/* The server drops our connection (restart, failover): the next call
 * reconnects and succeeds. */
static void t_pg_reconnect(void)
{
    const char *spec = pg_spec();
    char victim[1400], app[64], sql[256];
    snprintf(app, sizeof app, "rs_victim_%d", (int)getpid());
    snprintf(victim, sizeof victim, "%s&application_name=%s", spec, app);
    svc_store *s = open_ok(victim);
    int64_t id = submit(s, "a", "a", 1);
    snprintf(sql, sizeof sql, "SELECT count(pg_terminate_backend(pid)) FROM pg_stat_activity WHERE application_name = '%s'",
             app);
    T_EQ(pg_admin(sql), 1);
    snprintf(sql, sizeof sql, "SELECT count(*) FROM pg_stat_activity WHERE application_name = '%s'", app);
    for (int i = 0; i < 100 && pg_admin(sql) > 0; i++) {
        struct timespec ts = {0, 50 * 1000 * 1000};
        nanosleep(&ts, NULL);
    }
    T_EQ(pg_admin(sql), 0);
    svc_job g = get_ok(s, id); /* fails unless it reconnected */
    T_EQ(g.state, SVC_QUEUED);
    svc_job j = claim_ok(s, "host:1", 60);
    T_EQ(j.id, id);
    svc_job_free(&j);
    s->ops->close(s);
}

T_MAIN(CASES(roundtrip), CASES(claim_order), CASES(attempts), CASES(heartbeat), CASES(finish), CASES(cancel),
       CASES(dead_letter), CASES(give_back), CASES(reap), CASES(list_paging), CASES(counts), CASES(persistence),
       CASES(concurrent_claim), CASES(shared_handle), CASES(open_race), {"sqlite_bad_files", t_sqlite_bad_files},
       {"pg_unreachable", t_pg_unreachable}, {"pg_foreign_table", t_pg_foreign_table},
       {"pg_reconnect", t_pg_reconnect}, {"error_ids_have_texts", t_error_ids_have_texts})
