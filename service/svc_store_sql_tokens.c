/* svc_store_sql_tokens: the API tokens (svc_store.h): add, list, revoke,
 * find by hash (noting its use), and how much of its quota a token's jobs
 * use.  Only a token's hash is stored. */
#include <stdlib.h>

#include "svc_store_sql_impl.h"

#define TOKEN_COLS "id, name, is_operator, max_queued, seconds_per_hour, created, revoked, last_used"

static void token_row(void *dst, const sq_res *r, int i)
{
    svc_token *t = (svc_token *)dst + i;
    memset(t, 0, sizeof *t);
    t->id = v_int(r, i, 0);
    v_text(t->name, sizeof t->name, r, i, 1);
    t->is_operator = v_int(r, i, 2) != 0;
    t->max_queued = (int)v_int(r, i, 3);
    t->seconds_per_hour = (int)v_int(r, i, 4);
    t->created = v_int(r, i, 5);
    t->revoked = v_int(r, i, 6);
    t->last_used = v_int(r, i, 7);
}

int sq_token_add(svc_store *bs, svc_token *t, const char *hash, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1;
    pthread_mutex_lock(&s->mu);
    if (!sq_tx_begin(s, &now, err))
        goto out;
    int taken = sq_rows(s, "look for the name", "SELECT " TOKEN_COLS " FROM tokens WHERE name = ?1@LOCK",
                        ARGS(T(t->name)), NULL, NULL, 1, err);
    bool ok = taken >= 0;
    int64_t id = 0;
    if (ok && !taken)
        ok = sq_rows(s, "add the token",
                     "INSERT INTO tokens (name, hash, is_operator, max_queued, seconds_per_hour, created)"
                     " VALUES (?1, ?2, ?3, ?4, ?5, ?6) RETURNING id",
                     ARGS(T(t->name), T(hash), I(t->is_operator), I(t->max_queued), I(t->seconds_per_hour), I(now)),
                     sq_int_row, &id, 1, err) == 1;
    if (ok && !taken) {
        t->id = id;
        t->created = now;
        t->revoked = t->last_used = 0;
    }
    rc = sq_tx_end(s, ok, !taken, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

int sq_token_list(svc_store *bs, svc_token *out, int max, rs_err *err)
{
    if (max <= 0)
        return 0;
    return sq_query(S(bs), "list the tokens", "SELECT " TOKEN_COLS " FROM tokens ORDER BY id LIMIT ?1", ARGS(I(max)),
                    token_row, out, max, err);
}

int sq_token_revoke(svc_store *bs, const char *which, svc_token *out, rs_err *err)
{
    sq_store *s = S(bs);
    int64_t now;
    int rc = -1;
    /* a name first: "7" may be a token's name as well as another's id */
    char *end;
    long long id = strtoll(which, &end, 10);
    if (*end || end == which)
        id = -1;
    pthread_mutex_lock(&s->mu);
    if (!sq_tx_begin(s, &now, err))
        goto out;
    int have = sq_rows(s, "find the token", "SELECT " TOKEN_COLS " FROM tokens WHERE name = ?1@LOCK", ARGS(T(which)),
                       token_row, out, 1, err);
    if (have == 0)
        have = sq_rows(s, "find the token", "SELECT " TOKEN_COLS " FROM tokens WHERE id = ?1@LOCK", ARGS(I(id)),
                       token_row, out, 1, err);
    bool ok = have >= 0, already = have > 0 && out->revoked != 0;
    if (ok && have && !already) {
        ok = run(s, "revoke the token", "UPDATE tokens SET revoked = ?2 WHERE id = ?1", ARGS(I(out->id), I(now)), NULL,
                 err) >= 0;
        out->revoked = now;
    }
    rc = sq_tx_end(s, ok, !have ? 0 : already ? 2 : 1, err);
out:
    pthread_mutex_unlock(&s->mu);
    return rc;
}

int sq_token_find(svc_store *bs, const char *hash, svc_token *out, rs_err *err)
{
    sq_store *s = S(bs);
    pthread_mutex_lock(&s->mu);
    int rc = sq_rows(s, "find the token", "SELECT " TOKEN_COLS " FROM tokens WHERE hash = ?1", ARGS(T(hash)), token_row,
                     out, 1, err);
    /* last_used to the minute: a write per request would cost a commit each */
    if (rc == 1 && !out->revoked &&
        run(s, "note the token's use", "UPDATE tokens SET last_used = @NOW WHERE id = ?1 AND last_used < @NOW - 60",
            ARGS(I(out->id)), NULL, err) < 0)
        rc = -1;
    pthread_mutex_unlock(&s->mu);
    return rc;
}

int64_t sq_token_active(svc_store *bs, rs_err *err)
{
    int64_t n = 0;
    if (sq_query(S(bs), "count the tokens", "SELECT COUNT(*) FROM tokens WHERE revoked = 0", NOARGS, sq_int_row, &n, 1,
                 err) < 0)
        return -1;
    return n;
}

static void usage_row(void *dst, const sq_res *r, int i)
{
    *(svc_usage *)dst = (svc_usage){.active = v_int(r, i, 0), .hour_frames = v_int(r, i, 1),
                                    .oldest = v_int(r, i, 2), .now = v_int(r, i, 3)};
}

bool sq_token_usage(svc_store *bs, int64_t token_id, svc_usage *out, rs_err *err)
{
    return sq_query(S(bs), "measure the token's use",
                    "SELECT (SELECT COUNT(*) FROM jobs WHERE token_id = ?1 AND state IN (0, 1)),"
                    " (SELECT CAST(COALESCE(SUM(frames_total), 0) AS BIGINT) FROM jobs"
                    "   WHERE token_id = ?1 AND created > @NOW - 3600),"
                    " (SELECT COALESCE(MIN(created), 0) FROM jobs WHERE token_id = ?1 AND created > @NOW - 3600), @NOW",
                    ARGS(I(token_id)), usage_row, out, 1, err) == 1;
}
