/* svc_store: what the backends share (names, the open dispatch). */
#include "svc_store.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *svc_state_name(int st)
{
    static const char *const names[] = {
#define X(id, s) s,
        SVC_STATES(X)
#undef X
    };
    return st >= 0 && st < SVC_NSTATES ? names[st] : "unknown";
}

void svc_job_free(svc_job *j)
{
    free(j->replay);
    j->replay = NULL;
    j->replay_len = 0;
}

void svc_dead_letter(char *out, size_t n, int attempts, const char *why)
{
    snprintf(out, n, "gave up after %d attempt%s: %s", attempts, attempts == 1 ? "" : "s", why);
}

static bool has_prefix(const char *s, const char *p)
{
    return strncmp(s, p, strlen(p)) == 0;
}

const char *svc_store_error_text(int code)
{
    static const char *const text[] = {
#define X(id, t) t,
        SVC_STORE_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_SVC_STORE, text, (int)(sizeof text / sizeof text[0]));
}

svc_store *svc_store_open(const char *spec, int lease_s, rs_err *err)
{
    if (has_prefix(spec, "postgres://") || has_prefix(spec, "postgresql://"))
        return svc_store_pg_open(spec, lease_s, err);
    if (has_prefix(spec, "sqlite:"))
        spec += strlen("sqlite:");
    else {
        size_t n = strlen(spec);
        if (n < 3 || strcmp(spec + n - 3, ".db") != 0) {
            rs_fail(err, SVC_STORE_ERR_SPEC, "queue '%s': expected sqlite:PATH, a path ending in .db, or postgres://...", spec);
            return NULL;
        }
    }
    if (!*spec) {
        rs_fail(err, SVC_STORE_ERR_SPEC, "queue 'sqlite:': the database path is missing");
        return NULL;
    }
    return svc_store_sqlite_open(spec, err);
}

const char *svc_unit_kind_name(int kind)
{
    static const char *const names[] = {
#define X(id, s) s,
        SVC_UNIT_KINDS(X)
#undef X
    };
    return kind >= 0 && kind < (int)(sizeof names / sizeof names[0]) ? names[kind] : "unknown";
}

void svc_unit_context(char *out, size_t n, const svc_unit *u)
{
    if (u->kind == SVC_UNIT_SEGMENT)
        snprintf(out, n, "segment %d (ticks %lld-%lld): ", u->index, (long long)u->first_tick, (long long)u->end_tick);
    else if (u->kind == SVC_UNIT_JOIN)
        snprintf(out, n, "join: ");
    else if (n)
        out[0] = 0;
}

int svc_plan_segments(int64_t total, int64_t seg, int64_t first, int64_t *ends, int max)
{
    if (seg <= 0 || total <= 0)
        return 0;
    bool growing = first > 0 && first < seg;
    if (total <= (growing ? first : seg))
        return 0; /* a segment and a join would only add their start-up to the same frames */
    int n = 0;
    int64_t at = 0, len = growing ? first : seg, min_len = growing ? first : 1;
    while (at < total) {
        int64_t end = at + len;
        if (end >= total || total - end < min_len)
            end = total; /* the rest, or a remnant too short for a process of its own */
        if (n < max)
            ends[n] = end;
        n++;
        at = end;
        len = len * 2 < seg ? len * 2 : seg;
    }
    return n > 1 ? n : 0; /* one segment and a join would be the whole job, twice the start-up */
}
