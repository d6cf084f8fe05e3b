/* svc_keep: a job's files kept in the queue for daemons that share no
 * disk (files = queue; docs/service.md, "Several machines").
 *
 * DESIGN: the output directory stays where renders, joins and the HTTP
 * routes read and write, as on one machine; this file copies what they
 * make into the queue (svc_store.h, "Files in the queue") and brings back
 * what another machine made when it is missing here:
 *
 *   a segment done        its files and stream pieces stored, then its
 *                         done mark (svc_daemon.c): done means stored
 *   a video done          video, hashes and poster stored, then done
 *   a join starting       the segments it names, fetched where missing
 *   GET video, hashes,    fetched where missing (svc_http_jobs.c,
 *   poster, stream        svc_http_stream.c); a stream piece that does
 *                         not check is fetched once more
 *   the render log        appended in the queue, read from it
 *
 * A file fetched is written beside its place and renamed into it, so the
 * output directory never holds half of one.  What is here is a copy: the
 * sweep removes the copies of jobs that are over or gone (svc_files.c). */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../capture/cap_hls.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_progress.h"
#include "svc_local.h"
#include "svc_log.h"

bool svc_keep_on(const svc_config *cfg)
{
    /* auto: daemons of a PostgreSQL queue may be on machines that share no disk */
    return !strcmp(cfg->files, "queue") || (!strcmp(cfg->files, "auto") && !strncmp(cfg->queue, "postgres", 8));
}

static const char *base(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

/* names[i] = prefix + path's file name, for files that exist (optional
 * ones may not); false when a required one is missing */
typedef struct file_list {
    svc_file f[8];
    char names[8][96];
    int n;
} file_list;

static bool list_add(file_list *l, const char *prefix, const char *path, bool optional, rs_err *err)
{
    if (access(path, F_OK) != 0)
        return optional || rs_fail(err, SVC_ERR_KEEP, "%s: %s", path, strerror(errno));
    if (l->n >= 8)
        return rs_fail(err, SVC_ERR_KEEP, "too many files to keep");
    snprintf(l->names[l->n], sizeof l->names[l->n], "%s%s", prefix, base(path));
    l->f[l->n] = (svc_file){.name = l->names[l->n], .path = path};
    l->n++;
    return true;
}

static bool put(svc_store *st, int64_t id, const svc_file *f, int n, const char *keep, rs_err *err)
{
    int r = st->ops->file_put(st, id, f, n, keep, err);
    if (r < 0)
        rs_err_prefix(err, "storing job %" PRId64 "'s files in the queue", id);
    return r >= 0;
}

static bool keep_stream(svc_store *st, int64_t id, const char *dir, uint64_t first, rs_err *err)
{
    cap_hls_index ix;
    int r = cap_hls_index_read(dir, first, &ix, err);
    if (r <= 0)
        return r == 0; /* no index: nothing cut, nothing to keep */
    int n = ix.n + 1;
    svc_file *f = calloc((size_t)n, sizeof *f);
    char (*names)[48] = calloc((size_t)n, sizeof *names);
    char (*paths)[1200] = calloc((size_t)n, sizeof *paths);
    bool ok = f && names && paths;
    if (!ok)
        rs_fail(err, SVC_ERR_NOMEM, "out of memory");
    for (int i = 0; ok && i < ix.n; i++) {
        snprintf(names[i], sizeof names[i], "stream/t%" PRIu64 ".ts", ix.p[i].tick);
        snprintf(paths[i], sizeof paths[i], "%s/t%" PRIu64 ".ts", dir, ix.p[i].tick);
        f[i] = (svc_file){names[i], paths[i]};
    }
    if (ok) {
        /* the index last: the pieces before it in the same transaction */
        snprintf(names[ix.n], sizeof names[ix.n], "stream/u%" PRIu64 ".idx", first);
        snprintf(paths[ix.n], sizeof paths[ix.n], "%s/u%" PRIu64 ".idx", dir, first);
        f[ix.n] = (svc_file){names[ix.n], paths[ix.n]};
        /* a unit whose pieces were stored by an earlier render keeps them:
         * a listed piece never changes (cap_hls.h) */
        ok = put(st, id, f, n, names[ix.n], err);
    }
    free(f);
    free(names);
    free(paths);
    cap_hls_index_free(&ix);
    return ok;
}

static bool keep_segment(svc_store *st, const svc_job *j, const svc_unit_files *f, rs_err *err)
{
    file_list l = {0};
    char manifest[1200];
    snprintf(manifest, sizeof manifest, "%s.seg", f->out);
    return list_add(&l, "seg/", f->out, false, err) && list_add(&l, "seg/", manifest, false, err) &&
           list_add(&l, "seg/", f->hashes, false, err) && list_add(&l, "seg/", f->poster, true, err) &&
           put(st, j->id, l.f, l.n, NULL, err);
}

static bool keep_video(svc_store *st, const svc_config *cfg, const svc_job *j, rs_err *err)
{
    char video[1100], hashes[1100], poster[1100], vname[24];
    svc_job_file(cfg, j->id, j->format, video, sizeof video);
    svc_job_file(cfg, j->id, "hashes", hashes, sizeof hashes);
    svc_job_file(cfg, j->id, "png", poster, sizeof poster);
    snprintf(vname, sizeof vname, "video.%s", j->format);
    svc_file f[3] = {{vname, video}, {"hashes", hashes}, {"poster.png", poster}};
    /* a job without a poster (its render could not write one) is still done */
    return put(st, j->id, f, access(poster, F_OK) == 0 ? 3 : 2, NULL, err);
}

bool svc_keep_unit(svc_store *st, const svc_config *cfg, const svc_job *j, const svc_unit_files *f, bool stream,
                   char *note, size_t n, rs_err *err)
{
    note[0] = 0;
    if (!svc_keep_on(cfg))
        return true;
    double t0 = rs_now();
    bool ok = j->unit.kind == SVC_UNIT_SEGMENT ? keep_segment(st, j, f, err) : keep_video(st, cfg, j, err);
    if (ok && stream && j->unit.kind != SVC_UNIT_JOIN)
        ok = keep_stream(st, j->id, f->stream, (uint64_t)j->unit.first_tick, err);
    snprintf(note, n, "; kept in the queue in %.0f ms", (rs_now() - t0) * 1e3);
    return ok;
}

void svc_keep_drop(svc_store *st, const svc_config *cfg, int64_t id, int index, int attempt)
{
    char prefix[64];
    rs_err err = {0};
    if (index < 0)
        snprintf(prefix, sizeof prefix, "seg/");
    else
        snprintf(prefix, sizeof prefix, "seg/s%d-a%d.", index, attempt);
    if (svc_keep_on(cfg) && st->ops->file_drop(st, id, prefix, &err) < 0)
        svc_log(SVC_LOG_WARN, id, "could not remove %s from the queue: %s",
                index < 0 ? "its segments" : "a bad segment", err.msg);
}

int svc_fetch(svc_store *st, int64_t id, const char *name, const char *path, rs_err *err)
{
    if (access(path, F_OK) == 0)
        return 1;
    if (!rs_mkdirs_for(path, err))
        return -1;
    int r = st->ops->file_get(st, id, name, path, err);
    if (r < 0)
        rs_err_prefix(err, "fetching job %" PRId64 "'s %s from the queue", id, name);
    return r;
}

bool svc_fetch_segments(svc_store *st, const svc_job *j, const svc_unit_files *f, const svc_unit *u, int n,
                        rs_err *err)
{
    char manifest[16];
    snprintf(manifest, sizeof manifest, "%s.seg", j->format);
    const char *const exts[] = {j->format, manifest, "hashes", "png"};
    int fetched = 0;
    for (int i = 0; i < n; i++) {
        if (u[i].kind != SVC_UNIT_SEGMENT || u[i].done_attempt <= 0)
            continue;
        for (int k = 0; k < 4; k++) {
            char path[1200], name[96];
            svc_segment_path(path, sizeof path, f->segdir, u[i].index, u[i].done_attempt, exts[k]);
            if (access(path, F_OK) == 0)
                continue;
            snprintf(name, sizeof name, "seg/%s", base(path));
            /* one not stored (no poster in this segment; or lost) is the
             * join's to find: it sends a missing segment back to render */
            int r = svc_fetch(st, j->id, name, path, err);
            if (r < 0)
                return false;
            fetched += r;
        }
    }
    if (fetched)
        svc_log(SVC_LOG_INFO, j->id, "join: %d segment file%s fetched from the queue", fetched, fetched == 1 ? "" : "s");
    return true;
}
