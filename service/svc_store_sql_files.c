/* svc_store_sql_files: a job's files kept in the queue (svc_store.h,
 * "Files in the queue"), for daemons that share no disk.
 *
 * DESIGN: a file is rows of job_files (job_id, name, part, data), each at
 * most SVC_FILE_CHUNK bytes, part 0, 1, 2 ... (an append adds the next
 * part).  Rows of about a megabyte, not one value per file and not
 * PostgreSQL's large objects: measured on this project's videos
 * (tools/pg-blob-bench.sh, docs/service.md) bytea rows with TOAST's
 * compression attempt switched off (STORAGE EXTERNAL: video does not
 * compress) were the fastest both ways, they commit with the job's other
 * rows and go with a DELETE, and a reader holds one chunk in memory, not a
 * whole video.  A put is one transaction under the job's row lock: a
 * reader sees a file whole or not at all, and two daemons storing the same
 * unit's stream pieces take turns (the second finds them and keeps them). */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "svc_store_sql_impl.h"

static bool put_one(sq_store *s, int64_t id, const svc_file *f, uint8_t *buf, rs_err *err)
{
    FILE *in = fopen(f->path, "rb");
    if (!in)
        return rs_fail(err, SVC_STORE_ERR_FILE, "%s: cannot read it to store in the queue: %s", f->path,
                       strerror(errno));
    bool ok = run(s, "replace a stored file", "DELETE FROM job_files WHERE job_id = ?1 AND name = ?2",
                  ARGS(I(id), T(f->name)), NULL, err) >= 0;
    for (int part = 0; ok; part++) {
        size_t n = fread(buf, 1, SVC_FILE_CHUNK, in);
        if (ferror(in)) {
            ok = rs_fail(err, SVC_STORE_ERR_FILE, "%s: read error while storing it in the queue", f->path);
            break;
        }
        if (n == 0 && part > 0)
            break;
        ok = run(s, "store a file", "INSERT INTO job_files (job_id, name, part, data) VALUES (?1, ?2, ?3, ?4)",
                 ARGS(I(id), T(f->name), I(part), B(buf, n)), NULL, err) >= 0;
        if (n < SVC_FILE_CHUNK)
            break;
    }
    fclose(in);
    return ok;
}

static int has_file(sq_store *s, int64_t id, const char *name, rs_err *err)
{
    return sq_rows(s, "look for a stored file", "SELECT 1 FROM job_files WHERE job_id = ?1 AND name = ?2 LIMIT 1",
                   ARGS(I(id), T(name)), NULL, NULL, 1, err);
}

int sq_file_put(svc_store *bs, int64_t id, const svc_file *files, int n, const char *keep, rs_err *err)
{
    sq_store *s = S(bs);
    uint8_t *buf = malloc(SVC_FILE_CHUNK);
    if (!buf)
        return rs_fail(err, SVC_STORE_ERR_NOMEM, "out of memory"), -1;
    int64_t now;
    int rc = -1;
    pthread_mutex_lock(&s->mu);
    if (sq_tx_begin(s, &now, err)) {
        int state = 0, l = sq_lock_job(s, id, &state, NULL, err), have = 0;
        bool ok = l >= 0;
        if (l > 0 && (state == SVC_FAILED || state == SVC_CANCELLED))
            l = 0; /* its files went when it ended (sq_end_units): a late render adds none */
        if (l > 0 && keep && keep[0])
            ok = (have = has_file(s, id, keep, err)) >= 0;
        for (int i = 0; ok && l > 0 && !have && i < n; i++)
            ok = put_one(s, id, &files[i], buf, err);
        rc = sq_tx_end(s, ok, l == 0 ? 0 : have ? 2 : 1, err);
    }
    pthread_mutex_unlock(&s->mu);
    free(buf);
    return rc;
}

/* One part at or after *part: written to out, *part set past it. */
typedef struct chunk {
    FILE *out;
    int64_t part;
    bool got, bad;
} chunk;

static void chunk_row(void *dst, const sq_res *r, int i)
{
    chunk *c = dst;
    const sq_val *v = cell(r, i, 1);
    c->got = true;
    c->part = v_int(r, i, 0) + 1;
    if (v->n && fwrite(v->s, 1, v->n, c->out) != v->n)
        c->bad = true;
}

int sq_file_get(svc_store *bs, int64_t id, const char *name, const char *path, rs_err *err)
{
    sq_store *s = S(bs);
    /* "DIR/.NAME.fetch-SEQ-HOST-PID": hidden, and the sweep knows a dead
     * process's (svc_files.c: the host says whose pid, as a directory may
     * be shared); two threads fetching the same file write two */
    static unsigned seq;
    char tmp[1400], host[256] = "";
    gethostname(host, sizeof host - 1);
    const char *slash = strrchr(path, '/');
    int dirlen = slash ? (int)(slash - path + 1) : 0;
    snprintf(tmp, sizeof tmp, "%.*s.%s.fetch-%u-%s-%d", dirlen, path, path + dirlen,
             __atomic_fetch_add(&seq, 1, __ATOMIC_RELAXED), host, (int)getpid());
    FILE *out = fopen(tmp, "wb");
    if (!out)
        return rs_fail(err, SVC_STORE_ERR_FILE, "%s: cannot write a file fetched from the queue: %s", tmp,
                       strerror(errno)),
               -1;
    chunk c = {.out = out};
    int rc = 1;
    /* a part at a time, so a reader holds one chunk, not the whole file;
     * under the handle's lock throughout, so no put of this handle comes
     * between the parts (another daemon's put of a name it already holds
     * writes the same bytes: names are per claim) */
    pthread_mutex_lock(&s->mu);
    for (;;) {
        c.got = false;
        int k = sq_rows(s, "fetch a stored file",
                        "SELECT part, data FROM job_files WHERE job_id = ?1 AND name = ?2 AND part >= ?3"
                        " ORDER BY part LIMIT 1",
                        ARGS(I(id), T(name), I(c.part)), chunk_row, &c, 1, err);
        if (k < 0 || c.bad) {
            rc = -1;
            break;
        }
        if (!c.got) {
            rc = c.part > 0 ? 1 : 0;
            break;
        }
    }
    pthread_mutex_unlock(&s->mu);
    if (c.bad)
        rs_fail(err, SVC_STORE_ERR_FILE, "%s: cannot write a file fetched from the queue: %s", tmp, strerror(errno));
    if (fclose(out) != 0 && rc == 1)
        rc = -1, rs_fail(err, SVC_STORE_ERR_FILE, "%s: cannot write a file fetched from the queue: %s", tmp,
                         strerror(errno));
    if (rc == 1 && rename(tmp, path) != 0)
        rc = -1, rs_fail(err, SVC_STORE_ERR_FILE, "%s: cannot put a file fetched from the queue in place: %s", path,
                         strerror(errno));
    if (rc != 1)
        unlink(tmp);
    return rc;
}

int sq_file_append(svc_store *bs, int64_t id, const char *name, const void *data, size_t len, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now, next = 0;
    int rc = -1;
    pthread_mutex_lock(&s->mu);
    if (sq_tx_begin(s, &now, err)) {
        int l = sq_lock_job(s, id, NULL, NULL, err);
        bool ok = l >= 0;
        if (l > 0)
            ok = sq_rows(s, "find a stored file's end",
                         "SELECT COALESCE(MAX(part) + 1, 0) FROM job_files WHERE job_id = ?1 AND name = ?2",
                         ARGS(I(id), T(name)), sq_int_row, &next, 1, err) == 1 &&
                 run(s, "append to a stored file",
                     "INSERT INTO job_files (job_id, name, part, data) VALUES (?1, ?2, ?3, ?4)",
                     ARGS(I(id), T(name), I(next), B(data, len)), NULL, err) >= 0;
        rc = sq_tx_end(s, ok, l == 0 ? 0 : 1, err);
    }
    pthread_mutex_unlock(&s->mu);
    return rc;
}

int64_t sq_file_drop(svc_store *bs, int64_t id, const char *prefix, rs_err *err)
{
    sq_store *s = S(bs);
    pthread_mutex_lock(&s->mu);
    int64_t n = run(s, "remove stored files",
                    "DELETE FROM job_files WHERE job_id = ?1 AND substr(name, 1, length(?2)) = ?2",
                    ARGS(I(id), T(prefix ? prefix : "")), NULL, err);
    pthread_mutex_unlock(&s->mu);
    return n;
}

int64_t sq_file_bytes(svc_store *bs, int64_t id, rs_err *err)
{
    int64_t n = 0;
    int k = sq_query(S(bs), "count stored bytes",
                     "SELECT CAST(COALESCE(SUM(length(data)), 0) AS BIGINT) FROM job_files WHERE job_id = ?1",
                     ARGS(I(id)), sq_int_row, &n, 1, err);
    return k == 1 ? n : -1;
}
