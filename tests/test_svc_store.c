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

#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
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
    T_SKIP_INSTALL("built without SQLite (install libsqlite3-dev and rebuild)");
#endif
    snprintf(spec_buf, sizeof spec_buf, "sqlite:%s/queue.db", t_tmpdir());
    return spec_buf;
}

static const char *pg_uri(void)
{
    const char *uri = getenv("RINGSIDE_TEST_PG");
    if (!uri || !*uri)
        T_SKIP_ENV("no PostgreSQL server given (RINGSIDE_TEST_PG, a conninfo URI postgresql://USER@HOST:PORT/DB); "
                   "make test-service runs these cases against a throwaway one (tests/service/test_store_pg.sh)");
#if !defined(RS_HAVE_PQ)
    T_SKIP_INSTALL("RINGSIDE_TEST_PG is set but this ringside was built without libpq (install libpq-dev and rebuild)");
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
    T_SKIP_INSTALL("built without libpq");
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
    svc_store *s = svc_store_open(spec, 30, &e);
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
    T_ASSERT(strcmp(j.unit.owner, owner) == 0);
    T_ASSERT(j.unit.kind != SVC_UNIT_WHOLE || strcmp(j.owner, owner) == 0);
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

/* API tokens: add (names unique, revoked ones too), find by hash, revoke
 * by name or id, the active count, a token's jobs and its usage. */
static void tokens(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    T_EQ(s->ops->token_active(s, &e), 0);
    svc_token a = {.max_queued = 3, .seconds_per_hour = 60}, b = {.is_operator = true}, got;
    snprintf(a.name, sizeof a.name, "alice");
    snprintf(b.name, sizeof b.name, "ops");
    T_EQ(s->ops->token_add(s, &a, "hash-a", &e), 1);
    T_EQ(s->ops->token_add(s, &b, "hash-b", &e), 1);
    T_ASSERT(a.id > 0 && b.id > a.id && a.created > 0);
    svc_token dup = {0};
    snprintf(dup.name, sizeof dup.name, "alice");
    T_EQ(s->ops->token_add(s, &dup, "hash-c", &e), 0);
    T_EQ(s->ops->token_active(s, &e), 2);
    T_EQ(s->ops->token_find(s, "hash-a", &got, &e), 1);
    T_ASSERT(got.id == a.id && !strcmp(got.name, "alice") && !got.is_operator && got.max_queued == 3 &&
             got.seconds_per_hour == 60 && got.revoked == 0);
    T_EQ(s->ops->token_find(s, "nope", &got, &e), 0);
    svc_token list[4];
    T_EQ(s->ops->token_list(s, list, 4, &e), 2);
    T_ASSERT(list[0].id == a.id && list[1].is_operator && list[0].last_used > 0 && list[1].last_used == 0);
    /* a job of alice's, one of nobody's */
    svc_job j = {.width = 64, .height = 36, .frames_total = 600, .replay = (uint8_t *)"x", .replay_len = 1,
                 .token_id = a.id};
    snprintf(j.format, sizeof j.format, "mp4");
    T_ASSERT(s->ops->submit(s, &j, &e));
    int64_t mine = j.id;
    submit(s, "anon.rsr", "y", 1);
    T_EQ(get_ok(s, mine).token_id, a.id);
    svc_job out[4];
    T_EQ(s->ops->list(s, a.id, 0, 4, out, &e), 1);
    T_EQ(out[0].id, mine);
    T_EQ(s->ops->list(s, b.id, 0, 4, out, &e), 0);
    T_EQ(s->ops->list(s, 0, 0, 4, out, &e), 2);
    svc_usage u;
    T_ASSERT(s->ops->token_usage(s, a.id, &u, &e));
    T_ASSERT(u.active == 1 && u.hour_frames == 600 && u.oldest > 0 && u.oldest <= u.now);
    T_EQ(s->ops->cancel(s, mine, &e), 1);
    T_ASSERT(s->ops->token_usage(s, a.id, &u, &e));
    T_ASSERT(u.active == 0 && u.hour_frames == 600); /* the hour counts what was submitted */
    /* revoke by name, then by id; twice is "already" */
    T_EQ(s->ops->token_revoke(s, "alice", &got, &e), 1);
    T_ASSERT(got.id == a.id && got.revoked > 0);
    T_EQ(s->ops->token_revoke(s, "alice", &got, &e), 2);
    char id[32];
    snprintf(id, sizeof id, "%lld", (long long)b.id);
    T_EQ(s->ops->token_revoke(s, id, &got, &e), 1);
    T_EQ(s->ops->token_revoke(s, "nobody", &got, &e), 0);
    T_EQ(s->ops->token_active(s, &e), 0);
    T_EQ(s->ops->token_find(s, "hash-a", &got, &e), 1);
    T_ASSERT(got.revoked > 0);
    s->ops->close(s);
}

/* Files in the queue: a file of two and a half rows comes back byte for
 * byte, an empty one too; keep stores nothing when its name is there;
 * appends add to the end; a prefix drops only its names; a cancelled job
 * keeps only its log and takes no more files; remove takes every row. */
static void write_file(const char *path, const uint8_t *p, size_t n)
{
    FILE *f = fopen(path, "wb");
    T_ASSERT(f && fwrite(p, 1, n, f) == n && fclose(f) == 0);
}

static void files(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t id = submit(s, "f.rsr", "f", 1);
    size_t big = SVC_FILE_CHUNK * 2 + SVC_FILE_CHUNK / 2;
    uint8_t *data = malloc(big);
    T_ASSERT(data);
    fill_random(data, big, 7);
    char a[1100], b[1100], got[1100];
    snprintf(a, sizeof a, "%s/a.bin", t_tmpdir());
    snprintf(b, sizeof b, "%s/empty.bin", t_tmpdir());
    snprintf(got, sizeof got, "%s/got.bin", t_tmpdir());
    write_file(a, data, big);
    write_file(b, data, 0);
    svc_file two[] = {{"seg/s0-a1.mp4", a}, {"seg/s0-a1.hashes", b}};
    T_EQ(s->ops->file_put(s, id, two, 2, NULL, &e), 1);
    T_EQ(s->ops->file_bytes(s, id, &e), (int64_t)big);
    T_EQ(s->ops->file_get(s, id, "seg/s0-a1.mp4", got, &e), 1);
    size_t n = 0;
    rs_err fe = {0};
    uint8_t *back = (uint8_t *)rs_read_file(got, big + 1, &n, &fe);
    T_ASSERTF(back && n == big && !memcmp(back, data, big), "%s: %zu bytes back of %zu", got, n, big);
    free(back);
    T_EQ(s->ops->file_get(s, id, "seg/s0-a1.hashes", got, &e), 1);
    back = (uint8_t *)rs_read_file(got, 16, &n, &fe);
    T_ASSERT(back && n == 0);
    free(back);
    T_EQ(s->ops->file_get(s, id, "seg/s9-a1.mp4", got, &e), 0);
    T_EQ(s->ops->file_get(s, id + 100, "seg/s0-a1.mp4", got, &e), 0);
    /* keep: the name is there, nothing changes; a job that is not: 0 */
    svc_file other[] = {{"seg/s0-a1.mp4", b}};
    T_EQ(s->ops->file_put(s, id, other, 1, "seg/s0-a1.mp4", &e), 2);
    T_EQ(s->ops->file_bytes(s, id, &e), (int64_t)big);
    T_EQ(s->ops->file_put(s, id + 100, other, 1, NULL, &e), 0);
    /* a file that cannot be read: an error naming it, nothing stored */
    svc_file gone[] = {{"poster.png", b}, {"video.mp4", "/nonexistent/x.mp4"}};
    T_EQ(s->ops->file_put(s, id, gone, 2, NULL, &e), -1);
    T_ASSERTF(e.code == SVC_STORE_ERR_FILE && strstr(e.msg, "/nonexistent/x.mp4"), "%s", e.msg);
    T_EQ(s->ops->file_get(s, id, "poster.png", got, &e), 0);
    /* appends */
    T_EQ(s->ops->file_append(s, id, "log", "one\n", 4, &e), 1);
    T_EQ(s->ops->file_append(s, id, "log", "two\n", 4, &e), 1);
    T_EQ(s->ops->file_get(s, id, "log", got, &e), 1);
    back = (uint8_t *)rs_read_file(got, 64, &n, &fe);
    T_ASSERT(back && n == 8 && !memcmp(back, "one\ntwo\n", 8));
    free(back);
    /* a prefix drops its names only */
    T_EQ(s->ops->file_drop(s, id, "seg/s0-a1.h", &e), 1);
    T_EQ(s->ops->file_get(s, id, "seg/s0-a1.mp4", got, &e), 1);
    T_EQ(s->ops->file_get(s, id, "seg/s0-a1.hashes", got, &e), 0);
    /* cancelled: its files go but the log, and a late put stores nothing */
    T_EQ(s->ops->cancel(s, id, &e), 1);
    T_EQ(s->ops->file_get(s, id, "seg/s0-a1.mp4", got, &e), 0);
    T_EQ(s->ops->file_get(s, id, "log", got, &e), 1);
    T_EQ(s->ops->file_put(s, id, two, 1, NULL, &e), 0);
    T_EQ(s->ops->file_bytes(s, id, &e), 8);
    T_EQ(s->ops->remove(s, id, &e), 1);
    T_EQ(s->ops->file_bytes(s, id, &e), 0);
    T_EQ(s->ops->file_get(s, id, "log", got, &e), 0);
    free(data);
    s->ops->close(s);
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
    svc_reaped got[4];
    T_EQ(s->ops->reap(s, false, got, 4, &e), 1);
    T_ASSERT(got[0].id == lost && !got[0].failed && got[0].unit.lost == 0);
    svc_job g = get_ok(s, lost);
    T_EQ(g.state, SVC_QUEUED);
    T_ASSERTF(!strcmp(g.error, SVC_LEASE_EXPIRED), "error '%s'", g.error);
    T_ASSERT(!g.owner[0]);
    /* a lost lease is no attempt: it is given back and counted apart */
    T_EQ(g.attempts, 0);
    T_EQ(g.lost, 1);
    T_EQ(get_ok(s, alive).state, SVC_RUNNING);
    T_EQ(get_ok(s, queued).state, SVC_QUEUED);
    /* the old owner comes back too late */
    T_EQ(s->ops->heartbeat(s, lost, "a:1", 60, 1, 1, 1, &e), 0);
    T_EQ(s->ops->finish(s, lost, "a:1", SVC_DONE, NULL, -1, 1, &e), 0);
    T_EQ(s->ops->release(s, lost, "a:1", "x", true, 3, &e), 0);
    T_EQ(get_ok(s, lost).state, SVC_QUEUED);

    /* the next claim is attempt 1 again, under a claim number of its own
     * (its files never meet the lost claim's) */
    j = claim_ok(s, "a:1", -5);
    T_EQ(j.id, lost);
    T_EQ(j.attempts, 1);
    T_ASSERT(j.unit.attempts == 1 && j.unit.lost == 1 && j.unit.claim == 2);
    svc_job_free(&j);
    /* a job that loses its daemon every time still ends: SVC_LOST_MAX */
    for (int i = 2; i <= SVC_LOST_MAX; i++) {
        if (i > 2) {
            j = claim_ok(s, "a:1", -5);
            T_EQ(j.id, lost);
            svc_job_free(&j);
        }
        T_EQ(s->ops->reap(s, false, got, 4, &e), 1);
        T_EQ(got[0].failed, i == SVC_LOST_MAX);
    }
    g = get_ok(s, lost);
    T_EQ(g.state, SVC_FAILED);
    T_EQ(g.lost, SVC_LOST_MAX);
    T_EQ(g.attempts, 0);
    char want[96];
    snprintf(want, sizeof want, SVC_LOST_FMT, SVC_LOST_MAX);
    T_ASSERTF(!strcmp(g.error, want), "error '%s'", g.error);

    /* a lease of 0 s lasts until the end of the current second:
     * claimed_until == now is still valid, claimed_until < now is not */
    j = claim_ok(s, "c:3", 0);
    T_EQ(j.id, zero);
    T_EQ(j.claimed_until, j.started);
    svc_job_free(&j);
    struct timespec ts = {1, 200 * 1000 * 1000};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
    }
    T_EQ(s->ops->reap(s, false, NULL, 0, &e), 1);
    T_EQ(get_ok(s, zero).state, SVC_QUEUED);
    T_EQ(get_ok(s, alive).state, SVC_RUNNING);

    /* all: every running job, lease or not (an SQLite daemon starting up) */
    T_EQ(s->ops->reap(s, true, NULL, 0, &e), 1);
    g = get_ok(s, alive);
    T_EQ(g.state, SVC_QUEUED);
    T_ASSERT(!strcmp(g.error, SVC_LEASE_EXPIRED));
    T_EQ(g.attempts, 0);
    T_EQ(s->ops->reap(s, true, NULL, 0, &e), 0);
    s->ops->close(s);
}

/* The replay's header kept with a job; the queue order (pending); retry
 * of a failed job only, from scratch; the recent speed. */
static void retry_and_queue(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    svc_job j = {.width = 64, .height = 36, .frames_total = 600, .replay = (uint8_t *)"x", .replay_len = 1,
                 .stage = 5, .kind = {RP_HUMAN, RP_CPU}, .winner = 2, .rounds = {1, 2}};
    snprintf(j.format, sizeof j.format, "mp4");
    T_ASSERT(s->ops->submit(s, &j, &e));
    int64_t a = j.id, b = submit(s, "b.rsr", "y", 1), c = submit(s, "c.rsr", "z", 1);
    svc_job g = get_ok(s, a);
    T_ASSERT(g.stage == 5 && g.kind[0] == RP_HUMAN && g.kind[1] == RP_CPU && g.winner == 2 && g.rounds[0] == 1 &&
             g.rounds[1] == 2);
    svc_job out[2];
    T_EQ(s->ops->list(s, 0, 0, 2, out, &e), 2);
    T_ASSERT(out[1].id == b && out[0].stage == 0); /* submit()'s jobs: a zeroed header */
    svc_job w = claim_ok(s, "host:1", 60);
    T_EQ(w.id, a);
    svc_job_free(&w);
    T_EQ(s->ops->heartbeat(s, a, "host:1", 60, 100, 600, 10.0, &e), 1);
    svc_pending p[4];
    T_EQ(s->ops->pending(s, p, 4, &e), 3);
    T_ASSERT(p[0].id == a && p[0].state == SVC_RUNNING && p[0].frames_left == 500);
    T_ASSERT(p[1].id == b && p[1].state == SVC_QUEUED && p[1].frames_left == 600 && p[2].id == c);
    T_EQ(s->ops->finish(s, a, "host:1", SVC_FAILED, "the render failed", 42, 100, &e), 1);
    T_EQ(s->ops->retry(s, b, &e), 2); /* queued: not failed */
    T_EQ(s->ops->retry(s, 999999, &e), 0);
    T_EQ(s->ops->retry(s, a, &e), 1);
    g = get_ok(s, a);
    T_ASSERT(g.state == SVC_QUEUED && g.attempts == 0 && g.error[0] == 0 && g.desync_tick == -1 && g.finished == 0);
    T_EQ(s->ops->pending(s, p, 4, &e), 3);
    T_ASSERT(p[0].id == a && p[0].state == SVC_QUEUED && p[0].frames_left == 600);
    w = claim_ok(s, "host:2", 60);
    T_ASSERT(w.id == a && w.unit.attempts == 1 && w.unit.claim == 1);
    svc_job_free(&w);
    T_EQ(s->ops->finish(s, a, "host:2", SVC_DONE, "", -1, 600, &e), 1);
    T_EQ(s->ops->retry(s, a, &e), 2); /* done */
    double fps = -1;
    T_ASSERT(s->ops->speed(s, 20, &fps, &e));
    T_ASSERT(fps >= 0);
    s->ops->close(s);
}

/* Retention lists the done jobs of one host past their age; remove takes
 * only jobs that are over. */
static void expire_and_remove(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t a = submit(s, "a", "a", 1), b = submit(s, "b", "b", 1), c = submit(s, "c", "c", 1);
    svc_job j = claim_ok(s, "here:1-x/0", 60);
    T_EQ(s->ops->finish(s, a, "here:1-x/0", SVC_DONE, NULL, -1, 1, &e), 1);
    svc_job_free(&j);
    j = claim_ok(s, "there:1-y/0", 60);
    T_EQ(s->ops->finish(s, b, "there:1-y/0", SVC_DONE, NULL, -1, 1, &e), 1);
    svc_job_free(&j);
    int64_t ids[4];
    T_EQ(s->ops->expiring(s, 3600, "here", ids, 4, &e), 0); /* not old enough */
    T_EQ(s->ops->expiring(s, -5, "here", ids, 4, &e), 1);   /* "finished more than -5 s ago" */
    T_EQ(ids[0], a);
    T_EQ(s->ops->expiring(s, -5, "there", ids, 4, &e), 1);
    T_EQ(ids[0], b);
    T_EQ(s->ops->expire(s, a, &e), 1);
    T_ASSERT(get_ok(s, a).expired && get_ok(s, a).state == SVC_DONE);
    T_EQ(s->ops->expiring(s, -5, "here", ids, 4, &e), 0);
    T_EQ(s->ops->expire(s, c, &e), 0); /* queued: nothing to expire */
    /* remove: over jobs only */
    T_EQ(s->ops->remove(s, c, &e), 2);
    T_EQ(s->ops->remove(s, a, &e), 1);
    svc_job g;
    T_EQ(s->ops->get(s, a, &g, &e), 0);
    svc_unit u[1];
    T_EQ(s->ops->units(s, a, u, 1, &e), 0);
    T_EQ(s->ops->remove(s, a, &e), 0);
    T_EQ(s->ops->cancel(s, c, &e), 1);
    T_EQ(s->ops->remove(s, c, &e), 1);
    T_EQ(get_ok(s, b).state, SVC_DONE);
    s->ops->close(s);
}

static void list_paging(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    svc_job out[8];
    T_EQ(s->ops->list(s, 0, 0, 8, out, &e), 0);
    int64_t id[5];
    for (int i = 0; i < 5; i++) {
        char name[16];
        snprintf(name, sizeof name, "j%d", i);
        id[i] = submit(s, name, "x", 1);
    }
    T_EQ(s->ops->list(s, 0, 0, 2, out, &e), 2);
    T_EQ(out[0].id, id[4]);
    T_EQ(out[1].id, id[3]);
    T_ASSERT(!strcmp(out[0].name, "j4") && out[0].replay == NULL);
    T_EQ(s->ops->list(s, 0, out[1].id, 2, out, &e), 2);
    T_EQ(out[0].id, id[2]);
    T_EQ(out[1].id, id[1]);
    T_EQ(s->ops->list(s, 0, out[1].id, 8, out, &e), 1);
    T_EQ(out[0].id, id[0]);
    T_EQ(s->ops->list(s, 0, id[0], 8, out, &e), 0);
    T_EQ(s->ops->list(s, 0, 0, 8, out, &e), 5);
    for (int i = 0; i < 5; i++)
        T_EQ(out[i].id, id[4 - i]);
    T_EQ(s->ops->list(s, 0, 0, 0, out, &e), 0);
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
            svc_store *w = svc_store_open(spec, 30, &e);
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
            svc_store *s = svc_store_open(spec, 30, &e);
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

/* --- units: split jobs (svc_store.h, "Units") --- */

static int64_t submit_split(svc_store *s, int64_t frames, int seg_ticks, svc_job *out)
{
    rs_err e = {0};
    svc_job j = {.width = 160, .height = 90, .frames_total = frames, .segment_ticks = seg_ticks,
                 .replay = (uint8_t *)"r", .replay_len = 1};
    snprintf(j.name, sizeof j.name, "split.rsr");
    snprintf(j.format, sizeof j.format, "mp4");
    T_ASSERTF(s->ops->submit(s, &j, &e), "submit: %s", e.msg);
    if (out)
        *out = j;
    return j.id;
}

static int units_of(svc_store *s, int64_t id, svc_unit *u, int max)
{
    rs_err e = {0};
    int n = s->ops->units(s, id, u, max, &e);
    T_ASSERTF(n >= 0, "units of %lld: %s", (long long)id, e.msg);
    return n;
}

/* claims the next unit and checks it is (kind, index) of job id */
static svc_job claim_unit(svc_store *s, const char *owner, int64_t id, int kind, int index)
{
    svc_job j = claim_ok(s, owner, 60);
    T_ASSERTF(j.id == id && j.unit.kind == kind && j.unit.index == index, "claimed job %lld %s %d, want job %lld %s %d",
              (long long)j.id, svc_unit_kind_name(j.unit.kind), j.unit.index, (long long)id, svc_unit_kind_name(kind),
              index);
    T_EQ(j.unit.state, SVC_RUNNING);
    T_ASSERT(!strcmp(j.unit.owner, owner));
    svc_job_free(&j);
    return j;
}

static void split_plan(const char *spec)
{
    svc_store *s = open_ok(spec);
    svc_job a, b;
    int64_t id = submit_split(s, 250, 60, &a);
    T_EQ(a.segments, 5);
    T_EQ(a.segment_ticks, 60);
    svc_unit u[8];
    T_EQ(units_of(s, id, u, 8), 6);
    static const int64_t first[] = {0, 60, 120, 180, 240}, end[] = {60, 120, 180, 240, 250};
    for (int i = 0; i < 5; i++) {
        T_EQ(u[i].kind, SVC_UNIT_SEGMENT);
        T_EQ(u[i].index, i);
        T_EQ(u[i].first_tick, first[i]);
        T_EQ(u[i].end_tick, end[i]);
        T_ASSERT(u[i].state == SVC_QUEUED && u[i].attempts == 0 && u[i].renders == 0 && !u[i].done_attempt);
    }
    T_EQ(u[5].kind, SVC_UNIT_JOIN);
    T_EQ(u[5].index, 5);
    T_EQ(u[5].end_tick, 250);
    T_EQ(units_of(s, id, u, 2), 2);
    /* the key: the job's id and a nonce of its own */
    char want[32];
    snprintf(want, sizeof want, "job%lld-", (long long)id);
    T_ASSERTF(!strncmp(a.key, want, strlen(want)) && strlen(a.key) == strlen(want) + 16, "key '%s'", a.key);
    svc_job g = get_ok(s, id);
    T_ASSERT(!strcmp(g.key, a.key) && g.segments == 5 && g.segment_ticks == 60);
    submit_split(s, 250, 60, &b);
    T_ASSERT(strcmp(a.key + strlen(want), b.key + strlen(want) + (b.id >= 10)));
    /* no longer than one segment, or no segment length: one WHOLE unit */
    const int64_t whole[][2] = {{60, 60}, {59, 60}, {250, 0}};
    for (int i = 0; i < 3; i++) {
        int64_t w = submit_split(s, whole[i][0], (int)whole[i][1], &a);
        T_EQ(a.segments, 0);
        T_EQ(units_of(s, w, u, 8), 1);
        T_ASSERT(u[0].kind == SVC_UNIT_WHOLE && u[0].first_tick == 0 && u[0].end_tick == whole[i][0]);
    }
    s->ops->close(s);
}

static void split_run(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t id = submit_split(s, 150, 60, NULL), after = submit(s, "after", "a", 1);
    /* segments in order, to any owner; the join waits for all of them */
    claim_unit(s, "a:1", id, SVC_UNIT_SEGMENT, 0);
    claim_unit(s, "b:2", id, SVC_UNIT_SEGMENT, 1);
    claim_unit(s, "c:3", id, SVC_UNIT_SEGMENT, 2);
    svc_job g = get_ok(s, id);
    T_EQ(g.state, SVC_RUNNING);
    T_EQ(g.attempts, 1);
    /* progress: the frames of every segment, the fps of the running ones */
    T_EQ(s->ops->heartbeat(s, id, "a:1", 60, 30, 60, 10.0, &e), 1);
    T_EQ(s->ops->heartbeat(s, id, "b:2", 60, 20, 60, 5.5, &e), 1);
    T_EQ(s->ops->heartbeat(s, id, "z:9", 60, 20, 60, 5.5, &e), 0);
    g = get_ok(s, id);
    T_EQ(g.frames_done, 50);
    T_EQ(g.frames_total, 150);
    T_ASSERTF(g.fps == 15.5, "fps %g", g.fps);
    T_ASSERT(g.owner[0]);
    T_EQ(s->ops->finish(s, id, "a:1", SVC_DONE, NULL, -1, 60, &e), 1);
    T_EQ(s->ops->finish(s, id, "a:1", SVC_DONE, NULL, -1, 60, &e), 0); /* once */
    T_EQ(get_ok(s, id).state, SVC_RUNNING);
    T_EQ(s->ops->finish(s, id, "b:2", SVC_DONE, NULL, -1, 60, &e), 1);
    /* the join is not claimable yet: the other job comes first */
    claim_unit(s, "a:1", after, SVC_UNIT_WHOLE, 0);
    claim_none(s);
    T_EQ(s->ops->finish(s, id, "c:3", SVC_DONE, NULL, -1, 30, &e), 1);
    g = get_ok(s, id);
    T_EQ(g.frames_done, 150);
    T_EQ(g.state, SVC_QUEUED); /* nothing of it runs, nothing is over */
    claim_unit(s, "b:2", id, SVC_UNIT_JOIN, 3);
    T_EQ(get_ok(s, id).state, SVC_RUNNING);
    T_EQ(s->ops->heartbeat(s, id, "b:2", 60, 150, 150, 0, &e), 1);
    T_EQ(get_ok(s, id).frames_done, 150); /* the join's own count is not the job's frames */
    T_EQ(s->ops->finish(s, id, "b:2", SVC_DONE, NULL, -1, 150, &e), 1);
    g = get_ok(s, id);
    T_EQ(g.state, SVC_DONE);
    T_EQ(g.frames_done, 150);
    T_ASSERT(g.finished > 0 && g.claimed_until == 0 && g.fps == 0);
    svc_unit u[4];
    T_EQ(units_of(s, id, u, 4), 4);
    const char *by[] = {"a:1", "b:2", "c:3", "b:2"};
    for (int i = 0; i < 4; i++) {
        T_EQ(u[i].state, SVC_DONE);
        T_EQ(u[i].renders, 1);
        T_EQ(u[i].done_attempt, 1);
        T_ASSERTF(!strcmp(u[i].done_by, by[i]), "unit %d done by '%s'", i, u[i].done_by);
        T_ASSERT(!u[i].owner[0] || u[i].claimed_until == 0);
    }
    T_EQ(u[2].frames_done, 30);
    claim_none(s);
    s->ops->close(s);
}

static void split_retry(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t id = submit_split(s, 180, 60, NULL);
    claim_unit(s, "a:1", id, SVC_UNIT_SEGMENT, 0);
    claim_unit(s, "b:2", id, SVC_UNIT_SEGMENT, 1);
    T_EQ(s->ops->finish(s, id, "a:1", SVC_DONE, NULL, -1, 60, &e), 1);
    T_EQ(s->ops->heartbeat(s, id, "b:2", 60, 40, 60, 3, &e), 1);
    /* segment 1 crashes: it alone goes back, its progress with it */
    T_EQ(s->ops->release(s, id, "b:2", "worker crashed", true, 2, &e), 1);
    svc_job g = get_ok(s, id);
    T_EQ(g.state, SVC_QUEUED);
    T_EQ(g.frames_done, 60);
    T_CONTAINS(g.error, "segment 1 (ticks 60-120): worker crashed");
    svc_unit u[4];
    units_of(s, id, u, 4);
    T_ASSERT(u[0].state == SVC_DONE && u[0].renders == 1);
    T_ASSERT(u[1].state == SVC_QUEUED && u[1].attempts == 1 && !strcmp(u[1].error, "worker crashed"));
    /* a clean shutdown gives the attempt back */
    claim_unit(s, "c:3", id, SVC_UNIT_SEGMENT, 1);
    T_EQ(s->ops->release(s, id, "c:3", "daemon stopping", false, 2, &e), 1);
    units_of(s, id, u, 4);
    T_EQ(u[1].attempts, 1);
    /* the cap is per segment: segment 2 has its own attempts */
    claim_unit(s, "c:3", id, SVC_UNIT_SEGMENT, 1);
    claim_unit(s, "d:4", id, SVC_UNIT_SEGMENT, 2);
    T_EQ(get_ok(s, id).attempts, 2);
    /* segment 1 runs out: the job fails with its reason, and the others
     * stop (their heartbeats are answered "not ours") */
    T_EQ(s->ops->release(s, id, "c:3", "the render process was killed by signal 9", true, 2, &e), 1);
    g = get_ok(s, id);
    T_EQ(g.state, SVC_FAILED);
    T_ASSERTF(!strcmp(g.error, "gave up after 2 attempts: segment 1 (ticks 60-120): the render process was killed by "
                               "signal 9"),
              "error '%s'", g.error);
    T_ASSERT(g.finished > 0);
    T_EQ(s->ops->heartbeat(s, id, "d:4", 60, 1, 60, 1, &e), 0);
    T_EQ(s->ops->finish(s, id, "d:4", SVC_DONE, NULL, -1, 60, &e), 0);
    units_of(s, id, u, 4);
    T_ASSERT(u[0].state == SVC_DONE && u[1].state == SVC_FAILED && u[2].state == SVC_CANCELLED &&
             u[3].state == SVC_CANCELLED);
    claim_none(s);
    s->ops->close(s);
}

static void split_cancel_and_desync(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t a = submit_split(s, 120, 60, NULL), b = submit_split(s, 180, 60, NULL);
    claim_unit(s, "a:1", a, SVC_UNIT_SEGMENT, 0);
    T_EQ(s->ops->cancel(s, a, &e), 1);
    T_EQ(s->ops->heartbeat(s, a, "a:1", 60, 1, 60, 1, &e), 0);
    T_EQ(s->ops->release(s, a, "a:1", "x", true, 3, &e), 0);
    svc_unit u[4];
    T_EQ(units_of(s, a, u, 4), 3);
    for (int i = 0; i < 3; i++)
        T_EQ(u[i].state, SVC_CANCELLED);
    T_EQ(s->ops->cancel(s, a, &e), 2);
    /* a segment that desyncs fails the job with the tick, not retried */
    claim_unit(s, "a:1", b, SVC_UNIT_SEGMENT, 0);
    claim_unit(s, "b:2", b, SVC_UNIT_SEGMENT, 1);
    T_EQ(s->ops->finish(s, b, "b:2", SVC_FAILED, "b.rsr: desync at tick 120", 120, 40, &e), 1);
    svc_job g = get_ok(s, b);
    T_EQ(g.state, SVC_FAILED);
    T_EQ(g.desync_tick, 120);
    T_ASSERTF(!strcmp(g.error, "segment 1 (ticks 60-120): b.rsr: desync at tick 120"), "error '%s'", g.error);
    T_EQ(s->ops->heartbeat(s, b, "a:1", 60, 1, 60, 1, &e), 0);
    claim_none(s);
    s->ops->close(s);
}

/* A daemon dies: its running segments come back, finished ones stay. */
static void split_reap_resumes(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t id = submit_split(s, 240, 60, NULL);
    claim_unit(s, "a:1", id, SVC_UNIT_SEGMENT, 0);
    T_EQ(s->ops->finish(s, id, "a:1", SVC_DONE, NULL, -1, 60, &e), 1);
    svc_job j = claim_ok(s, "a:1", -5); /* expired */
    T_EQ(j.unit.index, 1);
    svc_job_free(&j);
    claim_unit(s, "b:2", id, SVC_UNIT_SEGMENT, 2);
    T_EQ(s->ops->reap(s, false, NULL, 0, &e), 1);
    svc_unit u[5];
    units_of(s, id, u, 5);
    T_ASSERT(u[0].state == SVC_DONE && u[1].state == SVC_QUEUED && u[2].state == SVC_RUNNING);
    T_ASSERT(!strcmp(u[1].error, SVC_LEASE_EXPIRED));
    T_EQ(s->ops->reap(s, true, NULL, 0, &e), 1); /* start-up of the one SQLite daemon */
    units_of(s, id, u, 5);
    T_ASSERT(u[0].state == SVC_DONE && u[0].renders == 1 && u[2].state == SVC_QUEUED);
    T_EQ(get_ok(s, id).state, SVC_QUEUED);
    T_EQ(get_ok(s, id).frames_done, 60);
    /* the rest, then the join: segment 0 is never handed out again */
    for (int i = 1; i < 4; i++) {
        char owner[16];
        snprintf(owner, sizeof owner, "c:%d", i);
        claim_unit(s, owner, id, SVC_UNIT_SEGMENT, i);
        T_EQ(s->ops->finish(s, id, owner, SVC_DONE, NULL, -1, 60, &e), 1);
    }
    claim_unit(s, "c:1", id, SVC_UNIT_JOIN, 4);
    units_of(s, id, u, 5);
    for (int i = 0; i < 4; i++)
        T_EQ(u[i].renders, 1);
    T_EQ(u[1].done_attempt, 2);
    T_EQ(u[2].done_attempt, 2);
    s->ops->close(s);
}

static void split_rejoin(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t id = submit_split(s, 240, 60, NULL);
    for (int i = 0; i < 4; i++) {
        claim_unit(s, "a:1", id, SVC_UNIT_SEGMENT, i);
        T_EQ(s->ops->finish(s, id, "a:1", SVC_DONE, NULL, -1, 60, &e), 1);
    }
    int bad[] = {1, 3};
    T_EQ(s->ops->rejoin(s, id, "a:1", bad, 2, "not a join", 3, &e), 0); /* a:1 holds nothing */
    claim_unit(s, "a:1", id, SVC_UNIT_JOIN, 4);
    T_EQ(s->ops->rejoin(s, id, "b:2", bad, 2, "not ours", 3, &e), 0);
    T_EQ(s->ops->rejoin(s, id, "a:1", bad, 2, "s1.mp4: truncated", 3, &e), 1);
    svc_unit u[5];
    units_of(s, id, u, 5);
    T_ASSERT(u[0].state == SVC_DONE && u[2].state == SVC_DONE);
    T_ASSERT(u[1].state == SVC_QUEUED && u[1].done_attempt == 0 && !strcmp(u[1].error, "s1.mp4: truncated"));
    T_ASSERT(u[3].state == SVC_QUEUED);
    T_ASSERT(u[4].state == SVC_QUEUED && u[4].attempts == 0); /* the join's attempt was given back */
    svc_job g = get_ok(s, id);
    T_EQ(g.frames_done, 120);
    T_CONTAINS(g.error, "join: s1.mp4: truncated");
    /* those two again, and then the join */
    claim_unit(s, "b:2", id, SVC_UNIT_SEGMENT, 1);
    claim_unit(s, "c:3", id, SVC_UNIT_SEGMENT, 3);
    claim_none(s);
    T_EQ(s->ops->finish(s, id, "b:2", SVC_DONE, NULL, -1, 60, &e), 1);
    T_EQ(s->ops->finish(s, id, "c:3", SVC_DONE, NULL, -1, 60, &e), 1);
    units_of(s, id, u, 5);
    T_ASSERT(u[1].renders == 2 && u[1].done_attempt == 2 && u[0].renders == 1);
    /* bad again and again: at the cap the job fails with the segment's reason */
    int one[] = {1};
    for (int k = 0; k < 2; k++) {
        claim_unit(s, "a:1", id, SVC_UNIT_JOIN, 4);
        T_EQ(s->ops->rejoin(s, id, "a:1", one, 1, "s1.mp4: wrong size", 3, &e), 1);
        if (k == 0) {
            claim_unit(s, "a:1", id, SVC_UNIT_SEGMENT, 1);
            T_EQ(s->ops->finish(s, id, "a:1", SVC_DONE, NULL, -1, 60, &e), 1);
        }
    }
    g = get_ok(s, id);
    T_EQ(g.state, SVC_FAILED);
    T_ASSERTF(!strcmp(g.error, "gave up after 3 attempts: segment 1 (ticks 60-120): s1.mp4: wrong size"), "error '%s'",
              g.error);
    claim_none(s);
    s->ops->close(s);
}

/* A damaged stream piece: its done segment back to queued, a running
 * join back to waiting (its owner's heartbeat says not ours, its attempt
 * given back); nothing for a segment not done, at the cap, or a done job. */
static void split_redo(const char *spec)
{
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    int64_t id = submit_split(s, 180, 60, NULL);
    claim_unit(s, "a:1", id, SVC_UNIT_SEGMENT, 0);
    T_EQ(s->ops->redo(s, id, 0, "running", 3, &e), 0); /* not done yet */
    T_EQ(s->ops->finish(s, id, "a:1", SVC_DONE, NULL, -1, 60, &e), 1);
    for (int i = 1; i < 3; i++) {
        claim_unit(s, "a:1", id, SVC_UNIT_SEGMENT, i);
        T_EQ(s->ops->finish(s, id, "a:1", SVC_DONE, NULL, -1, 60, &e), 1);
    }
    claim_unit(s, "j:1", id, SVC_UNIT_JOIN, 3);
    T_EQ(s->ops->redo(s, id, 1, "t60.ts damaged", 3, &e), 1);
    T_EQ(s->ops->redo(s, id, 1, "again", 3, &e), 0); /* queued already */
    svc_unit u[4];
    units_of(s, id, u, 4);
    T_ASSERT(u[1].state == SVC_QUEUED && u[1].done_attempt == 0 && u[1].renders == 1 &&
             !strcmp(u[1].error, "t60.ts damaged"));
    T_ASSERT(u[0].state == SVC_DONE && u[2].state == SVC_DONE);
    T_ASSERT(u[3].state == SVC_QUEUED && u[3].attempts == 0);
    T_EQ(s->ops->heartbeat(s, id, "j:1", 60, 0, 180, 0, &e), 0);
    claim_unit(s, "b:2", id, SVC_UNIT_SEGMENT, 1);
    T_EQ(s->ops->finish(s, id, "b:2", SVC_DONE, NULL, -1, 60, &e), 1);
    units_of(s, id, u, 4);
    T_ASSERT(u[1].renders == 2 && u[1].done_attempt == 2);
    /* at the cap: left alone (the piece answers 410) */
    T_EQ(s->ops->redo(s, id, 1, "x", 2, &e), 0);
    claim_unit(s, "j:1", id, SVC_UNIT_JOIN, 3);
    T_EQ(s->ops->finish(s, id, "j:1", SVC_DONE, NULL, -1, 180, &e), 1);
    T_EQ(s->ops->redo(s, id, 0, "done", 3, &e), 0);
    T_EQ(get_ok(s, id).state, SVC_DONE);
    s->ops->close(s);
}

/* Four processes (four daemons) render three split jobs: every unit is
 * claimed once, every segment finished once, every join after its
 * segments. */
static void split_concurrent(const char *spec)
{
    enum { JOBS = 3, W = 4 };
    svc_store *s = open_ok(spec);
    int64_t ids[JOBS];
    for (int i = 0; i < JOBS; i++)
        ids[i] = submit_split(s, 600, 60, NULL); /* 10 segments and a join each */
    pid_t kid[W];
    for (int k = 0; k < W; k++) {
        kid[k] = fork();
        T_ASSERT(kid[k] >= 0);
        if (kid[k] == 0) {
            rs_err e = {0};
            svc_store *w = svc_store_open(spec, 30, &e);
            if (!w)
                _exit(2);
            char owner[32];
            snprintf(owner, sizeof owner, "w%d:%d", k, (int)getpid());
            int idle = 0;
            while (idle < 20) {
                svc_job j;
                int r = w->ops->claim(w, owner, 60, &j, &e);
                if (r < 0) {
                    fprintf(stderr, "    worker %d: claim: %s\n", k, e.msg);
                    _exit(3);
                }
                if (r == 0) { /* a join may be waiting for another worker's segment */
                    idle++;
                    nanosleep(&(struct timespec){0, 20 * 1000 * 1000}, NULL);
                    continue;
                }
                idle = 0;
                nanosleep(&(struct timespec){0, 5 * 1000 * 1000}, NULL); /* "rendering" */
                if (j.unit.kind == SVC_UNIT_JOIN) {
                    svc_unit u[16];
                    int n = w->ops->units(w, j.id, u, 16, &e);
                    for (int i = 0; i < n - 1; i++)
                        if (u[i].state != SVC_DONE)
                            _exit(4); /* a join before all its segments */
                }
                if (w->ops->finish(w, j.id, owner, SVC_DONE, NULL, -1, 60, &e) != 1)
                    _exit(5);
                svc_job_free(&j);
            }
            w->ops->close(w);
            _exit(0);
        }
    }
    for (int k = 0; k < W; k++) {
        int st = 0;
        T_ASSERT(waitpid(kid[k], &st, 0) == kid[k]);
        T_ASSERTF(WIFEXITED(st) && WEXITSTATUS(st) == 0, "worker %d ended with status %#x", k, st);
    }
    int owners_seen = 0;
    char first_owner[64] = "";
    for (int i = 0; i < JOBS; i++) {
        T_EQ(get_ok(s, ids[i]).state, SVC_DONE);
        svc_unit u[16];
        T_EQ(units_of(s, ids[i], u, 16), 11);
        for (int k = 0; k < 11; k++) {
            T_ASSERTF(u[k].renders == 1 && u[k].attempts == 1, "job %lld unit %d: %d renders, %d attempts",
                      (long long)ids[i], k, u[k].renders, u[k].attempts);
            if (!first_owner[0])
                snprintf(first_owner, sizeof first_owner, "%s", u[k].done_by);
            else if (strcmp(first_owner, u[k].done_by))
                owners_seen = 1;
        }
    }
    T_ASSERTF(owners_seen, "every unit went to %s", first_owner);
    s->ops->close(s);
}

/* A queue made before units: it opens, its jobs become WHOLE units. */
static void migrate_v1(const char *spec, void (*sql)(const char *spec, const char *stmt))
{
    sql(spec, "CREATE TABLE jobs (id " "%ID%" ", state INTEGER NOT NULL DEFAULT 0, name TEXT NOT NULL DEFAULT '',"
              " width INTEGER NOT NULL, height INTEGER NOT NULL, format TEXT NOT NULL,"
              " frames_done BIGINT NOT NULL DEFAULT 0, frames_total BIGINT NOT NULL DEFAULT 0,"
              " fps DOUBLE PRECISION NOT NULL DEFAULT 0, attempts INTEGER NOT NULL DEFAULT 0,"
              " desync_tick BIGINT NOT NULL DEFAULT -1, error TEXT NOT NULL DEFAULT '', owner TEXT NOT NULL DEFAULT '',"
              " created BIGINT NOT NULL DEFAULT 0, started BIGINT NOT NULL DEFAULT 0, finished BIGINT NOT NULL DEFAULT 0,"
              " claimed_until BIGINT NOT NULL DEFAULT 0, replay %BLOB% NOT NULL)");
    sql(spec, "INSERT INTO jobs (state, width, height, format, frames_total, replay, name) VALUES"
              " (2, 64, 36, 'mp4', 60, %X%, 'done'), (1, 64, 36, 'mp4', 60, %X%, 'running'),"
              " (0, 64, 36, 'mp4', 60, %X%, 'queued')");
    sql(spec, "UPDATE jobs SET owner = 'old:1', attempts = 1, claimed_until = 1 WHERE state = 1");
    svc_store *s = open_ok(spec);
    rs_err e = {0};
    svc_unit u[2];
    T_EQ(units_of(s, 1, u, 2), 0);
    T_EQ(units_of(s, 2, u, 2), 1);
    T_ASSERT(u[0].kind == SVC_UNIT_WHOLE && u[0].state == SVC_RUNNING && !strcmp(u[0].owner, "old:1"));
    T_EQ(s->ops->reap(s, false, NULL, 0, &e), 1); /* its lease ran out long ago: no attempt charged */
    svc_job j = claim_unit(s, "new:1", 2, SVC_UNIT_WHOLE, 0);
    T_EQ(j.attempts, 1);
    T_EQ(j.unit.lost, 1);
    T_EQ(j.segments, 0);
    claim_unit(s, "new:2", 3, SVC_UNIT_WHOLE, 0);
    T_EQ(s->ops->finish(s, 3, "new:2", SVC_DONE, NULL, -1, 60, &e), 1);
    T_EQ(get_ok(s, 3).state, SVC_DONE);
    T_EQ(get_ok(s, 1).state, SVC_DONE);
    T_EQ(get_ok(s, 3).token_id, 0); /* jobs from before tokens were made without one */
    s->ops->close(s);
    s = open_ok(spec); /* and again: nothing more to migrate */
    T_EQ(units_of(s, 3, u, 2), 1);
    s->ops->close(s);
}

/* stmt with %ID%, %BLOB% and %X% in the backend's words */
static void spell_admin(char *out, size_t n, const char *stmt, const char *id, const char *blob, const char *x)
{
    size_t k = 0;
    for (const char *p = stmt; *p && k + 64 < n;) {
        const char *put = NULL;
        if (!strncmp(p, "%ID%", 4))
            put = id, p += 4;
        else if (!strncmp(p, "%BLOB%", 6))
            put = blob, p += 6;
        else if (!strncmp(p, "%X%", 3))
            put = x, p += 3;
        if (put) {
            k += (size_t)snprintf(out + k, n - k, "%s", put);
            continue;
        }
        out[k++] = *p++;
    }
    out[k] = 0;
}

static void sqlite_admin(const char *spec, const char *stmt)
{
#if defined(RS_HAVE_SQLITE)
    char sql[2048];
    spell_admin(sql, sizeof sql, stmt, "INTEGER PRIMARY KEY AUTOINCREMENT", "BLOB", "x'00'");
    sqlite3 *db = NULL;
    T_ASSERT(sqlite3_open(spec + strlen("sqlite:"), &db) == SQLITE_OK);
    char *msg = NULL;
    T_ASSERTF(sqlite3_exec(db, sql, NULL, NULL, &msg) == SQLITE_OK, "%s: %s", sql, msg ? msg : "?");
    sqlite3_close(db);
#else
    (void)spec, (void)stmt;
#endif
}

static void pg_admin_in_schema(const char *spec, const char *stmt)
{
    (void)spec;
    char sql[2048], full[2100];
    spell_admin(sql, sizeof sql, stmt, "BIGSERIAL PRIMARY KEY", "BYTEA", "'\\x00'::bytea");
    snprintf(full, sizeof full, "SET search_path = " PG_SCHEMA "; %s", sql);
    pg_admin(full);
}

/* A queue made before lost leases and retention: the columns are added,
 * a lease lost then is no attempt either. */
static void migrate_v2(const char *spec, void (*sql)(const char *spec, const char *stmt))
{
    svc_store *s = open_ok(spec);
    int64_t id = submit(s, "old", "o", 1);
    svc_job j = claim_ok(s, "old:1", -5);
    svc_job_free(&j);
    s->ops->close(s);
    sql(spec, "ALTER TABLE units DROP COLUMN lost");
    sql(spec, "ALTER TABLE jobs DROP COLUMN lost");
    sql(spec, "ALTER TABLE jobs DROP COLUMN expired");
    s = open_ok(spec);
    rs_err e = {0};
    T_EQ(s->ops->reap(s, false, NULL, 0, &e), 1);
    svc_job g = get_ok(s, id);
    T_ASSERT(g.state == SVC_QUEUED && g.attempts == 0 && g.lost == 1 && !g.expired);
    s->ops->close(s);
}

static void t_sqlite_migrate_v2(void)
{
    migrate_v2(sqlite_spec(), sqlite_admin);
}

static void t_pg_migrate_v2(void)
{
    migrate_v2(pg_spec(), pg_admin_in_schema);
}

static void t_sqlite_migrate_v1(void)
{
    migrate_v1(sqlite_spec(), sqlite_admin);
}

static void t_pg_migrate_v1(void)
{
    migrate_v1(pg_spec(), pg_admin_in_schema);
}

#define BOTH(fn)                                                                                                      \
    static void t_sqlite_##fn(void) { fn(sqlite_spec()); }                                                            \
    static void t_pg_##fn(void) { fn(pg_spec()); }
#define CASES(fn) {"sqlite_" #fn, t_sqlite_##fn}, {"pg_" #fn, t_pg_##fn}

BOTH(roundtrip)
BOTH(expire_and_remove)
BOTH(retry_and_queue)
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
BOTH(split_plan)
BOTH(split_run)
BOTH(split_retry)
BOTH(split_cancel_and_desync)
BOTH(split_reap_resumes)
BOTH(split_rejoin)
BOTH(split_redo)
BOTH(split_concurrent)
BOTH(tokens)
BOTH(files)

/* --- what each backend refuses, and how it says so --- */

static void expect_open_fail(const char *spec, int code, const char *want)
{
    rs_err e = {0};
    svc_store *s = svc_store_open(spec, 30, &e);
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
        T_ASSERT(!svc_store_open(uri, 30, &e));
        T_EQ(e.code, SVC_STORE_ERR_OPEN);
        T_CONTAINS(e.msg, where);
        T_ASSERTF(!strstr(e.msg, "s3cret-pw"), "password in '%s'", e.msg);
    }
    /* libpq quotes a malformed URI whole */
    rs_err e = {0};
    T_ASSERT(!svc_store_open("postgresql://ringside:s3cret-pw@[::1/ringside", 30, &e));
    T_EQ(e.code, SVC_STORE_ERR_OPEN);
    T_ASSERT(e.msg[0]);
    T_ASSERTF(!strstr(e.msg, "s3cret-pw"), "password in '%s'", e.msg);
#else
    snprintf(uri, sizeof uri, "postgresql://ringside:s3cret-pw@127.0.0.1:%d/ringside", port);
    expect_open_fail(uri, SVC_STORE_ERR_NOT_BUILT, "built without libpq (install libpq-dev and rebuild)");
    rs_err e = {0};
    svc_store_open(uri, 30, &e);
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
       CASES(concurrent_claim), CASES(shared_handle), CASES(open_race), CASES(split_plan), CASES(split_run),
       CASES(split_retry), CASES(split_cancel_and_desync), CASES(split_reap_resumes), CASES(split_rejoin), CASES(split_redo),
        CASES(split_concurrent), CASES(tokens), CASES(files), CASES(migrate_v1), CASES(migrate_v2), CASES(expire_and_remove),
        CASES(retry_and_queue),
        {"sqlite_bad_files", t_sqlite_bad_files},
       {"pg_unreachable", t_pg_unreachable}, {"pg_foreign_table", t_pg_foreign_table},
       {"pg_reconnect", t_pg_reconnect}, {"error_ids_have_texts", t_error_ids_have_texts})
