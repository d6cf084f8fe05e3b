/* pg-blob-bench: how fast a file's bytes go into PostgreSQL and back, two
 * ways a render farm without a shared disk could keep a finished unit's
 * bytes in its queue's database (docs/service.md, "Several
 * machines"): bytea rows of CHUNK bytes (with and without TOAST compression),
 * and a large object.  Built and
 * run by tools/pg-blob-bench.sh, which starts a throwaway server.
 *
 *   pg-blob-bench CONNINFO FILE [CHUNK_KIB] [RUNS]
 *
 * Prints one line per way and direction: MB/s (median of RUNS), and the
 * bytes the table or object takes on the server (pg_total_relation_size,
 * or pg_largeobject's growth). */
#include <libpq-fe.h>
#include <libpq/libpq-fs.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static PGresult *run(PGconn *c, const char *sql)
{
    PGresult *r = PQexec(c, sql);
    ExecStatusType st = PQresultStatus(r);
    if (st != PGRES_COMMAND_OK && st != PGRES_TUPLES_OK) {
        fprintf(stderr, "pg-blob-bench: %s: %s", sql, PQerrorMessage(c));
        exit(1);
    }
    return r;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp);
    return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

/* bytea: one row per chunk of table t, written in one transaction, read back in order */
static void bytea_round(PGconn *c, const char *t_name, const uint8_t *data, size_t len, size_t chunk, double *w, double *r)
{
    char sql[256];
    snprintf(sql, sizeof sql, "TRUNCATE %s", t_name);
    PQclear(run(c, sql));
    double t = now();
    PQclear(run(c, "BEGIN"));
    for (size_t off = 0, k = 0; off < len; off += chunk, k++) {
        char idx[32];
        snprintf(idx, sizeof idx, "%zu", k);
        size_t n = len - off < chunk ? len - off : chunk;
        const char *vals[2] = {idx, (const char *)data + off};
        int lens[2] = {0, (int)n}, fmts[2] = {0, 1};
        snprintf(sql, sizeof sql, "INSERT INTO %s (job, name, chunk, data) VALUES (1, 's0.mp4', $1, $2)", t_name);
        PGresult *res = PQexecParams(c, sql, 2, NULL, vals, lens, fmts, 1);
        if (PQresultStatus(res) != PGRES_COMMAND_OK) {
            fprintf(stderr, "pg-blob-bench: insert: %s", PQerrorMessage(c));
            exit(1);
        }
        PQclear(res);
    }
    PQclear(run(c, "COMMIT"));
    *w = now() - t;
    t = now();
    snprintf(sql, sizeof sql, "SELECT data FROM %s WHERE job = 1 AND name = 's0.mp4' ORDER BY chunk", t_name);
    PGresult *res = PQexecParams(c, sql, 0, NULL, NULL, NULL, NULL, 1);
    size_t got = 0;
    for (int i = 0; i < PQntuples(res); i++) {
        size_t n = (size_t)PQgetlength(res, i, 0);
        if (got + n > len || memcmp(PQgetvalue(res, i, 0), data + got, n)) {
            fprintf(stderr, "pg-blob-bench: bytea read back other bytes\n");
            exit(1);
        }
        got += n;
    }
    PQclear(res);
    *r = now() - t;
    if (got != len) {
        fprintf(stderr, "pg-blob-bench: bytea read back %zu of %zu bytes\n", got, len);
        exit(1);
    }
}

/* a large object: created, written in CHUNK writes, read back */
static Oid lo_round(PGconn *c, const uint8_t *data, size_t len, size_t chunk, double *w, double *r)
{
    double t = now();
    PQclear(run(c, "BEGIN"));
    Oid o = lo_creat(c, INV_READ | INV_WRITE);
    int fd = lo_open(c, o, INV_WRITE);
    for (size_t off = 0; off < len; off += chunk) {
        size_t n = len - off < chunk ? len - off : chunk;
        if (lo_write(c, fd, (const char *)data + off, n) != (int)n) {
            fprintf(stderr, "pg-blob-bench: lo_write: %s", PQerrorMessage(c));
            exit(1);
        }
    }
    lo_close(c, fd);
    PQclear(run(c, "COMMIT"));
    *w = now() - t;
    t = now();
    PQclear(run(c, "BEGIN"));
    fd = lo_open(c, o, INV_READ);
    char *buf = malloc(chunk);
    size_t got = 0;
    int n;
    while (buf && (n = lo_read(c, fd, buf, chunk)) > 0) {
        if (got + (size_t)n > len || memcmp(buf, data + got, (size_t)n)) {
            fprintf(stderr, "pg-blob-bench: the large object read back other bytes\n");
            exit(1);
        }
        got += (size_t)n;
    }
    free(buf);
    lo_close(c, fd);
    PQclear(run(c, "COMMIT"));
    *r = now() - t;
    if (got != len) {
        fprintf(stderr, "pg-blob-bench: the large object read back %zu of %zu bytes\n", got, len);
        exit(1);
    }
    return o;
}

static long long size_of(PGconn *c, const char *sql)
{
    PGresult *r = run(c, sql);
    long long v = atoll(PQgetvalue(r, 0, 0));
    PQclear(r);
    return v;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: pg-blob-bench CONNINFO FILE [CHUNK_KIB] [RUNS]\n");
        return 2;
    }
    size_t chunk = (size_t)(argc > 3 ? atol(argv[3]) : 1024) * 1024;
    int runs = argc > 4 ? atoi(argv[4]) : 5;
    if (chunk == 0 || runs < 1 || runs > 100) {
        fprintf(stderr, "pg-blob-bench: CHUNK_KIB must be > 0 and RUNS 1..100\n");
        return 2;
    }
    FILE *f = fopen(argv[2], "rb");
    if (!f) {
        perror(argv[2]);
        return 1;
    }
    fseek(f, 0, SEEK_END);
    size_t len = (size_t)ftell(f);
    rewind(f);
    uint8_t *data = malloc(len ? len : 1);
    if (!data || fread(data, 1, len, f) != len) {
        fprintf(stderr, "pg-blob-bench: cannot read %s\n", argv[2]);
        return 1;
    }
    fclose(f);
    PGconn *c = PQconnectdb(argv[1]);
    if (PQstatus(c) != CONNECTION_OK) {
        fprintf(stderr, "pg-blob-bench: %s", PQerrorMessage(c));
        return 1;
    }
    PQclear(run(c, "CREATE TABLE IF NOT EXISTS blob_chunks (job bigint, name text, chunk int, data bytea, "
                   "PRIMARY KEY (job, name, chunk))"));
    /* the same without TOAST's compression attempt (video does not compress) */
    PQclear(run(c, "CREATE TABLE IF NOT EXISTS blob_plain (job bigint, name text, chunk int, data bytea, "
                   "PRIMARY KEY (job, name, chunk))"));
    PQclear(run(c, "ALTER TABLE blob_plain ALTER COLUMN data SET STORAGE EXTERNAL"));
    double bw[100], br[100], pw[100], pr[100], lw[100], lr[100];
    long long lo0 = size_of(c, "SELECT pg_total_relation_size('pg_largeobject')");
    Oid last = 0;
    for (int i = 0; i < runs; i++) {
        bytea_round(c, "blob_chunks", data, len, chunk, &bw[i], &br[i]);
        bytea_round(c, "blob_plain", data, len, chunk, &pw[i], &pr[i]);
        if (last)
            lo_unlink(c, last);
        last = lo_round(c, data, len, chunk, &lw[i], &lr[i]);
    }
    long long tb = size_of(c, "SELECT pg_total_relation_size('blob_chunks')");
    long long lo1 = size_of(c, "SELECT pg_total_relation_size('pg_largeobject')");
    double mb = (double)len / 1e6;
    printf("file %s: %.2f MB, chunks of %zu KiB, median of %d runs\n", argv[2], mb, chunk / 1024, runs);
    long long tp = size_of(c, "SELECT pg_total_relation_size('blob_plain')");
    printf("bytea rows:    write %7.1f MB/s  read %7.1f MB/s  table %.2f MB\n", mb / median(bw, runs),
           mb / median(br, runs), tb / 1e6);
    printf("bytea, EXTERNAL (no compression): write %7.1f MB/s  read %7.1f MB/s  table %.2f MB\n", mb / median(pw, runs),
           mb / median(pr, runs), tp / 1e6);
    printf("large object:  write %7.1f MB/s  read %7.1f MB/s  pg_largeobject +%.2f MB (one object; earlier runs' pages "
           "not yet vacuumed)\n",
           mb / median(lw, runs), mb / median(lr, runs), (lo1 - lo0) / 1e6);
    lo_unlink(c, last);
    PQclear(run(c, "DROP TABLE blob_chunks"));
    PQclear(run(c, "DROP TABLE blob_plain"));
    PQfinish(c);
    free(data);
    return 0;
}
