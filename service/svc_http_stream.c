/* svc_http_stream: a job's live stream, HLS (docs/service.md, "Watching
 * while it renders").
 *
 *   GET /jobs/N/stream.m3u8    the playlist: the pieces of the job's units
 *                              that are done, in tick order up to the first
 *                              that is not, and #EXT-X-ENDLIST once the job
 *                              is done; it grows as units finish
 *   GET /jobs/N/stream/T.ts    the piece from tick T, checked against its
 *                              unit's index (size and FNV-1a) as it is sent
 *
 * DESIGN: the playlist is made from the queue (which units are done) and
 * the units' index files, on every request; nothing is cached, so any
 * daemon that sees the output directory answers the same.  A unit is
 * listed only when the queue says it is done, and the daemon that finished
 * it read its pieces back first (svc_daemon.c, stream_ok): a listed piece
 * is complete, and a unit rendered again later keeps the pieces already
 * listed (cap_hls.h).  Tokens apply as for the video: another token's job
 * is 404. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "svc.h"

#if defined(RS_HAVE_MHD)
#include "../capture/cap_hls.h"
#include "svc_encode.h"
#include "svc_http_local.h"
#include "svc_log.h"

/* The job's listed units: their indexes in ix[0..*n-1] (malloc'd), and
 * whether that is all of the job (*all).  False with the answer in *ret. */
static bool listed_units(svc_daemon *d, struct MHD_Connection *c, const svc_job *j, const char *dir, cap_hls_index **ix,
                         int *n, bool *all, enum MHD_Result *ret)
{
    int cap = j->segments > 0 ? j->segments + 1 : 1;
    svc_unit *units = calloc((size_t)cap, sizeof *units);
    *ix = calloc((size_t)cap, sizeof **ix);
    *n = 0;
    *all = false;
    rs_err err = {0};
    if (!units || !*ix) {
        free(units);
        free(*ix);
        *ret = http_error(c, SVC_ERR_NOMEM, NULL, NULL, "out of memory");
        return false;
    }
    int nu = d->http_store->ops->units(d->http_store, j->id, units, cap, &err);
    if (nu < 0) {
        free(units);
        free(*ix);
        *ret = http_store_error(c, &err);
        return false;
    }
    int want = 0, k = 0;
    for (int i = 0; i < nu; i++) {
        if (units[i].kind == SVC_UNIT_JOIN)
            continue;
        want++;
        /* done once is enough: a segment the join sent back keeps its
         * pieces (cap_hls.h), and the playlist never takes back a line */
        if (k < want - 1 || (units[i].state != SVC_DONE && units[i].renders == 0))
            continue; /* after a gap nothing is listed */
        int r = cap_hls_index_read(dir, (uint64_t)units[i].first_tick, &(*ix)[k], &err);
        if (r == 0 && svc_keep_on(&d->cfg)) {
            /* files = queue: a unit another machine rendered */
            char name[64], path[1200];
            snprintf(name, sizeof name, "stream/u%" PRId64 ".idx", units[i].first_tick);
            snprintf(path, sizeof path, "%s/u%" PRId64 ".idx", dir, units[i].first_tick);
            if (svc_fetch(d->http_store, j->id, name, path, &err) == 1)
                r = cap_hls_index_read(dir, (uint64_t)units[i].first_tick, &(*ix)[k], &err);
        }
        if (r == 1 && (*ix)[k].end == (uint64_t)units[i].end_tick)
            k++;
        else {
            if (r == 1)
                cap_hls_index_free(&(*ix)[k]);
            if (r != 0)
                svc_log(SVC_LOG_WARN, j->id, "stream: %s", r < 0 ? err.msg : "an index for other ticks");
        }
    }
    free(units);
    *n = k;
    *all = k == want && want > 0;
    return true;
}

static void free_units(cap_hls_index *ix, int n)
{
    for (int i = 0; i < n; i++)
        cap_hls_index_free(&ix[i]);
    free(ix);
}

/* The job, visible, with a stream that can exist: false with the answer in *ret. */
static bool stream_job(svc_daemon *d, struct MHD_Connection *c, const req *q, svc_job *j, char *dir, size_t n,
                       enum MHD_Result *ret)
{
    if (!http_job_visible(d, c, q, j, ret))
        return false;
    if (!svc_stream_dir(&d->cfg, j, dir, n)) {
        char codec[16];
        svc_encode_get(j->encode, "codec", codec, sizeof codec);
        *ret = http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL,
                          "job %" PRId64 " has no stream: a live stream carries H.264 or HEVC in .mp4 or .mkv jobs, "
                          "and this one is %s%s%s",
                          j->id, j->format, codec[0] ? " " : "", codec);
        return false;
    }
    if (j->expired) {
        *ret = http_error(c, SVC_ERR_GONE, NULL, NULL, "job %" PRId64 "'s stream was removed by retention (kept %ld s after it finished)",
                          j->id, d->cfg.retention);
        return false;
    }
    if (j->state == SVC_FAILED || j->state == SVC_CANCELLED) {
        *ret = http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL, "job %" PRId64 " is %s: it has no stream", j->id,
                          svc_state_name(j->state));
        return false;
    }
    return true;
}

/* What a request of a job's stream sees: the job and its listed units. */
typedef struct stream_view {
    svc_job j;
    char dir[1100];
    cap_hls_index *ix; /* the listed units' indexes, in tick order */
    int n;
    bool all;          /* every unit of the job is listed */
} stream_view;

/* False with the answer in *ret. */
static bool view_stream(svc_daemon *d, struct MHD_Connection *c, const req *q, stream_view *v, enum MHD_Result *ret)
{
    return stream_job(d, c, q, &v->j, v->dir, sizeof v->dir, ret) &&
           listed_units(d, c, &v->j, v->dir, &v->ix, &v->n, &v->all, ret);
}

enum MHD_Result http_stream(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    stream_view v;
    enum MHD_Result ret;
    if (!view_stream(d, c, q, &v, &ret))
        return ret;
    if (v.j.state == SVC_DONE && !v.all) {
        free_units(v.ix, v.n);
        return http_error(c, SVC_ERR_GONE, NULL, NULL,
                          "job %" PRId64 " is done but its stream is not whole on this server (%s; the video is at /jobs/%"
                          PRId64 "/video)", v.j.id, v.dir, v.j.id);
    }
    size_t len;
    char *text = cap_hls_playlist(v.ix, v.n, v.j.state == SVC_DONE, "stream/", &len);
    free_units(v.ix, v.n);
    if (!text)
        return http_error(c, SVC_ERR_NOMEM, NULL, NULL, "out of memory");
    ret = http_reply(c, 200, "application/vnd.apple.mpegurl", text, len);
    free(text);
    return ret;
}

enum MHD_Result http_piece(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    stream_view v;
    enum MHD_Result ret;
    if (!view_stream(d, c, q, &v, &ret))
        return ret;
    const cap_hls_piece *p = NULL;
    int unit = -1; /* the listed unit holding it: the segment of that index (listed from 0, without gaps) */
    for (int u = 0; u < v.n && !p; u++)
        for (int i = 0; i < v.ix[u].n && !p; i++)
            if (v.ix[u].p[i].tick == (uint64_t)q->m.tick)
                p = &v.ix[u].p[i], unit = u;
    if (!p) {
        free_units(v.ix, v.n);
        return http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL, "job %" PRId64 " lists no piece from tick %" PRId64 " (yet)",
                          v.j.id, q->m.tick);
    }
    uint8_t *data = NULL;
    rs_err err = {0};
    char name[64], path[1200];
    snprintf(name, sizeof name, "stream/t%" PRId64 ".ts", q->m.tick);
    snprintf(path, sizeof path, "%s/t%" PRId64 ".ts", v.dir, q->m.tick);
    bool keep = svc_keep_on(&d->cfg);
    if (keep && svc_fetch(d->http_store, v.j.id, name, path, &err) < 0)
        svc_log(SVC_LOG_WARN, v.j.id, "stream: %s", err.msg);
    bool ok = cap_hls_piece_check(v.dir, p, &data, &err);
    if (!ok && keep) {
        /* files = queue: a copy damaged here is fetched again */
        svc_log(SVC_LOG_WARN, v.j.id, "stream: %s; fetching it again from the queue", err.msg);
        unlink(path);
        memset(&err, 0, sizeof err);
        ok = svc_fetch(d->http_store, v.j.id, name, path, &err) == 1 && cap_hls_piece_check(v.dir, p, &data, &err);
    }
    uint64_t len = p->bytes;
    free_units(v.ix, v.n);
    if (!ok) {
        svc_log(SVC_LOG_WARN, v.j.id, "stream: %s", err.msg);
        /* a split job not done yet renders that segment again (its join
         * waits for it); a listed piece's bytes never change, so the new
         * render's pieces are the ones the index names */
        rs_err rerr = {0};
        char why[SVC_ERROR_MAX];
        snprintf(why, sizeof why, "its stream piece from tick %" PRId64 " was missing or damaged", q->m.tick);
        int r = v.j.segments > 0 ? d->http_store->ops->redo(d->http_store, v.j.id, unit, why, d->cfg.max_attempts, &rerr)
                                 : 0;
        if (r < 0)
            svc_log(SVC_LOG_ERROR, v.j.id, "stream: could not send segment %d back to render: %s", unit, rerr.msg);
        if (r == 1) {
            static const http_header later = {"Retry-After", "10"};
            svc_log(SVC_LOG_WARN, v.j.id, "segment %d: re-queued: %s", unit, why);
            return http_error(c, SVC_ERR_RERENDER, &later, NULL,
                              "job %" PRId64 "'s piece from tick %" PRId64 " was damaged on this server: segment %d "
                              "is being rendered again", v.j.id, q->m.tick, unit);
        }
        return http_error(c, SVC_ERR_GONE, NULL, NULL, "job %" PRId64 "'s piece from tick %" PRId64
                          " is missing or damaged on this server", v.j.id, q->m.tick);
    }
    ret = http_reply(c, 200, "video/mp2t", (const char *)data, (size_t)len);
    free(data);
    return ret;
}

#endif
