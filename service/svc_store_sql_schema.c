/* svc_store_sql_schema: the tables both SQL backends make and the
 * columns they add to older queues (svc_store_sql.h says when each runs),
 * and sq_spell, which writes a statement in a driver's own words. */
#include <stdio.h>
#include <string.h>

#include "svc_store_sql.h"

bool sq_schema_units(const sq_driver *drv, void *c, bool migrate, rs_err *err)
{
    static const char *const add[] = {
        "ALTER TABLE jobs ADD COLUMN segment_ticks INTEGER NOT NULL DEFAULT 0",
        "ALTER TABLE jobs ADD COLUMN segments INTEGER NOT NULL DEFAULT 0",
        "ALTER TABLE jobs ADD COLUMN seg_key TEXT NOT NULL DEFAULT ''",
    };
    for (int i = 0; migrate && i < 3; i++)
        if (drv->exec(c, "add a column to jobs", add[i], NULL, 0, NULL, err) < 0)
            return false;
    if (drv->exec(c, "create the units table",
                  "CREATE TABLE IF NOT EXISTS units ("
                  " job_id BIGINT NOT NULL, idx INTEGER NOT NULL, kind INTEGER NOT NULL,"
                  " first_tick BIGINT NOT NULL, end_tick BIGINT NOT NULL,"
                  " state INTEGER NOT NULL DEFAULT 0, attempts INTEGER NOT NULL DEFAULT 0,"
                  " owner TEXT NOT NULL DEFAULT '', claimed_until BIGINT NOT NULL DEFAULT 0,"
                  " started BIGINT NOT NULL DEFAULT 0, finished BIGINT NOT NULL DEFAULT 0,"
                  " frames_done BIGINT NOT NULL DEFAULT 0, fps DOUBLE PRECISION NOT NULL DEFAULT 0,"
                  " error TEXT NOT NULL DEFAULT '', renders INTEGER NOT NULL DEFAULT 0,"
                  " done_by TEXT NOT NULL DEFAULT '', done_attempt INTEGER NOT NULL DEFAULT 0,"
                  " PRIMARY KEY (job_id, idx))",
                  NULL, 0, NULL, err) < 0 ||
        drv->exec(c, "create the units index", "CREATE INDEX IF NOT EXISTS units_state ON units (state, job_id, idx)",
                  NULL, 0, NULL, err) < 0)
        return false;
    /* a queue from before units: its unfinished jobs become WHOLE units,
     * running ones still held by their owners (their leases run on) */
    return !migrate ||
           drv->exec(c, "make units of the queued jobs",
                     "INSERT INTO units (job_id, idx, kind, first_tick, end_tick, state, attempts, owner,"
                     " claimed_until, started, frames_done, fps, error)"
                     " SELECT id, 0, 0, 0, frames_total, state, attempts, owner, claimed_until, started, frames_done,"
                     " fps, error FROM jobs WHERE state IN (0, 1)",
                     NULL, 0, NULL, err) >= 0;
}

bool sq_schema_lost(const sq_driver *drv, void *c, const char *has_column, rs_err *err)
{
    static const char *const cols[][3] = {
        {"units", "lost", "ALTER TABLE units ADD COLUMN lost INTEGER NOT NULL DEFAULT 0"},
        {"jobs", "lost", "ALTER TABLE jobs ADD COLUMN lost INTEGER NOT NULL DEFAULT 0"},
        {"jobs", "expired", "ALTER TABLE jobs ADD COLUMN expired INTEGER NOT NULL DEFAULT 0"},
    };
    for (int i = 0; i < 3; i++) {
        sq_res r = {0};
        sq_val a[2] = {{.type = SQ_TEXT, .s = cols[i][0]}, {.type = SQ_TEXT, .s = cols[i][1]}};
        if (drv->exec(c, "look for a column", has_column, a, 2, &r, err) < 0)
            return false;
        bool have = r.rows == 1 && r.v[0].i > 0;
        drv->res_free(&r);
        if (!have && drv->exec(c, "add a column", cols[i][2], NULL, 0, NULL, err) < 0)
            return false;
    }
    return true;
}

bool sq_schema_meta(const sq_driver *drv, void *c, const char *has_column, rs_err *err)
{
    static const char *const cols[][2] = {
        {"stage", "ALTER TABLE jobs ADD COLUMN stage INTEGER NOT NULL DEFAULT -1"},
        {"kind1", "ALTER TABLE jobs ADD COLUMN kind1 INTEGER NOT NULL DEFAULT 0"},
        {"kind2", "ALTER TABLE jobs ADD COLUMN kind2 INTEGER NOT NULL DEFAULT 0"},
        {"winner", "ALTER TABLE jobs ADD COLUMN winner INTEGER NOT NULL DEFAULT -1"},
        {"rounds1", "ALTER TABLE jobs ADD COLUMN rounds1 INTEGER NOT NULL DEFAULT 0"},
        {"rounds2", "ALTER TABLE jobs ADD COLUMN rounds2 INTEGER NOT NULL DEFAULT 0"},
        /* the encoder options the job asked for ("codec=hevc crf=24"; svc_encode_argv) */
        {"encode", "ALTER TABLE jobs ADD COLUMN encode TEXT NOT NULL DEFAULT ''"},
    };
    for (size_t i = 0; i < sizeof cols / sizeof *cols; i++) {
        sq_res r = {0};
        sq_val a[2] = {{.type = SQ_TEXT, .s = "jobs"}, {.type = SQ_TEXT, .s = cols[i][0]}};
        if (drv->exec(c, "look for a column", has_column, a, 2, &r, err) < 0)
            return false;
        bool have = r.rows == 1 && r.v[0].i > 0;
        drv->res_free(&r);
        if (!have && drv->exec(c, "add a column", cols[i][1], NULL, 0, NULL, err) < 0)
            return false;
    }
    return true;
}

bool sq_schema_tokens(const sq_driver *drv, void *c, const char *serial, bool migrate, rs_err *err)
{
    char sql[1024];
    snprintf(sql, sizeof sql,
             "CREATE TABLE IF NOT EXISTS tokens ("
             " id %s, name TEXT NOT NULL UNIQUE, hash TEXT NOT NULL UNIQUE,"
             " is_operator INTEGER NOT NULL DEFAULT 0, max_queued INTEGER NOT NULL DEFAULT 0,"
             " seconds_per_hour INTEGER NOT NULL DEFAULT 0, created BIGINT NOT NULL DEFAULT 0,"
             " revoked BIGINT NOT NULL DEFAULT 0, last_used BIGINT NOT NULL DEFAULT 0)",
             serial);
    return (!migrate || drv->exec(c, "add a column to jobs", "ALTER TABLE jobs ADD COLUMN token_id BIGINT NOT NULL DEFAULT 0",
                                  NULL, 0, NULL, err) >= 0) &&
           drv->exec(c, "create the tokens table", sql, NULL, 0, NULL, err) >= 0 &&
           drv->exec(c, "create the jobs' token index", "CREATE INDEX IF NOT EXISTS jobs_token ON jobs (token_id, created)",
                     NULL, 0, NULL, err) >= 0;
}

bool sq_schema_files(const sq_driver *drv, void *c, const char *blob, bool external, rs_err *err)
{
    char sql[512];
    snprintf(sql, sizeof sql,
             "CREATE TABLE IF NOT EXISTS job_files ("
             " job_id BIGINT NOT NULL, name TEXT NOT NULL, part INTEGER NOT NULL, data %s,"
             " PRIMARY KEY (job_id, name, part))",
             blob);
    return drv->exec(c, "create the job_files table", sql, NULL, 0, NULL, err) >= 0 &&
           (!external || drv->exec(c, "store files without compressing them",
                                   "ALTER TABLE job_files ALTER COLUMN data SET STORAGE EXTERNAL", NULL, 0, NULL,
                                   err) >= 0);
}

bool sq_spell(char *out, size_t n, const char *sql, const char *now, const char *lock, const char *skip, bool dollar)
{
    static const char *const names[] = {"@NOW", "@LOCK", "@SKIP"};
    const char *vals[] = {now, lock, skip};
    size_t k = 0;
    for (const char *p = sql; *p;) {
        const char *put = NULL;
        size_t skiplen = 1;
        for (int t = 0; t < 3 && !put; t++)
            if (!strncmp(p, names[t], strlen(names[t])))
                put = vals[t], skiplen = strlen(names[t]);
        char one[2] = {*p, 0};
        if (!put) {
            if (dollar && *p == '?' && p[1] >= '0' && p[1] <= '9')
                one[0] = '$';
            put = one;
        }
        size_t m = strlen(put);
        if (k + m + 1 > n)
            return false;
        memcpy(out + k, put, m);
        k += m;
        p += skiplen;
    }
    out[k] = 0;
    return true;
}
