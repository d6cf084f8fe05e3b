/* svc_files: where a unit's files go, the command that makes them, and
 * cleaning up what crashed renders, cancelled jobs and other queues leave.
 *
 * DESIGN: called from the supervisor thread only (svc_daemon.c); nothing
 * here keeps state.  The layout under the output directory:
 *
 *   N.fmt, N.hashes, N.png          a finished job (the only names clients see):
 *                                   video, hash list, poster (render --poster)
 *   N.log                           the job's render log: each unit attempt's
 *                                   last stderr lines, appended as it ends
 *   .jobN-PID-aK.fmt/.hashes/.png   an unsplit job's render, claim K, by daemon PID
 *   .jobN-PID-jK.fmt / .hashes      a split job's join, claim K
 *   N.stream/jobN-NONCE/            the job's live stream, kept with its video
 *       track.K.ts, tTICK.ts, uA.idx (capture/cap_hls.h): written by the renders
 *                                   (render --hls-dir), served as HLS
 *   .jobN-NONCE/                    a split job's segments: the directory is
 *                                   named by the job's key (svc_store.h), so a
 *                                   reused job id (a new queue, the same output
 *                                   directory) never meets the old files
 *       sI-aK.fmt, sI-aK.hashes,    segment I as claim K rendered it (its
 *       sI-aK.fmt.seg               manifest last: a manifest means complete);
 *       sI-aK.png                   the poster, from the segment holding its tick
 *                                   (the join moves it to N.png)
 *
 * K is the unit's claim number (svc_unit.claim: attempts + lost leases), so
 * each claim writes names of its own, even when a lost lease gave its
 * attempt back; the join is given the names of the claim the queue
 * recorded (done_attempt), so a stale render of an earlier claim (a daemon
 * cut off by a network partition) can never put its file under the join.  Everything hidden (".job...") belongs to a job;
 * the sweep removes it once its job is over or unknown to the queue, and
 * leaves every other name alone (the directory may be shared). */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../capture/cap_hls.h"
#include "svc_encode.h"
#include "svc_local.h"
#include "svc_log.h"

void svc_unit_paths(const svc_config *cfg, const svc_job *j, int slot, svc_unit_files *f)
{
    memset(f, 0, sizeof *f);
    int pid = (int)getpid();
    snprintf(f->replay, sizeof f->replay, "%s/work/job%" PRId64 "-%d-%d.rsr", cfg->data, j->id, pid, slot);
    if (j->segments > 0)
        snprintf(f->segdir, sizeof f->segdir, "%s/.%s", cfg->output, j->key);
    if (j->unit.kind != SVC_UNIT_JOIN)
        svc_stream_dir(cfg, j, f->stream, sizeof f->stream);
    switch (j->unit.kind) {
    case SVC_UNIT_SEGMENT:
        svc_segment_path(f->out, sizeof f->out, f->segdir, j->unit.index, j->unit.claim, j->format);
        svc_segment_path(f->hashes, sizeof f->hashes, f->segdir, j->unit.index, j->unit.claim, "hashes");
        svc_segment_path(f->poster, sizeof f->poster, f->segdir, j->unit.index, j->unit.claim, "png");
        break;
    case SVC_UNIT_JOIN:
        snprintf(f->out, sizeof f->out, "%s/.job%" PRId64 "-%d-j%d.%s", cfg->output, j->id, pid, j->unit.claim,
                 j->format);
        snprintf(f->hashes, sizeof f->hashes, "%s/.job%" PRId64 "-%d-j%d.hashes", cfg->output, j->id, pid,
                 j->unit.claim);
        break;
    default:
        snprintf(f->out, sizeof f->out, "%s/.job%" PRId64 "-%d-a%d.%s", cfg->output, j->id, pid, j->unit.claim,
                 j->format);
        snprintf(f->hashes, sizeof f->hashes, "%s/.job%" PRId64 "-%d-a%d.hashes", cfg->output, j->id, pid,
                 j->unit.claim);
        snprintf(f->poster, sizeof f->poster, "%s/.job%" PRId64 "-%d-a%d.png", cfg->output, j->id, pid, j->unit.claim);
    }
}

bool svc_stream_dir(const svc_config *cfg, const svc_job *j, char *out, size_t n)
{
    out[0] = 0;
    if (!svc_encode_streamable(j->format, j->encode) || !j->key[0])
        return false;
    snprintf(out, n, "%s/%" PRId64 ".stream/%s", cfg->output, j->id, j->key);
    return true;
}

bool svc_unit_stream_ok(const svc_unit_files *f, const svc_unit *u, char *why, size_t n)
{
    rs_err err = {0};
    if (!f->stream[0] || cap_hls_unit_check(f->stream, (uint64_t)u->first_tick, (uint64_t)u->end_tick, &err))
        return true;
    snprintf(why, n, "its stream pieces do not check: %s", err.msg);
    return false;
}

void svc_job_file(const svc_config *cfg, int64_t id, const char *ext, char *out, size_t n)
{
    snprintf(out, n, "%s/%" PRId64 ".%s", cfg->output, id, ext);
}

void svc_job_log_append(svc_store *st, const svc_config *cfg, int64_t id, const char *block, size_t len)
{
    rs_err err = {0};
    /* files = queue: in the queue, where any daemon reads it (0: the job is gone) */
    int r = svc_keep_on(cfg) ? st->ops->file_append(st, id, "log", block, len, &err) : -1;
    if (r >= 0)
        return;
    if (err.msg[0])
        svc_log(SVC_LOG_WARN, id, "the render log goes to this machine only: %s", err.msg);
    char path[1100];
    svc_job_file(cfg, id, "log", path, sizeof path);
    int fd = open(path, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0) {
        svc_log(SVC_LOG_WARN, id, "%s: cannot write the render log: %s", path, strerror(errno));
        return;
    }
    ssize_t w = write(fd, block, len);
    if (w != (ssize_t)len)
        svc_log(SVC_LOG_WARN, id, "%s: the render log was not written whole", path);
    close(fd);
}

void svc_client_names(const svc_config *cfg, const svc_job *j, const svc_unit_files *f, const char *line, char *out,
                      size_t n)
{
    snprintf(out, n, "%s", line);
    if (j->unit.kind == SVC_UNIT_SEGMENT)
        return;
    char video[1100], hashes[1100], poster[1100];
    svc_job_file(cfg, j->id, j->format, video, sizeof video);
    svc_job_file(cfg, j->id, "hashes", hashes, sizeof hashes);
    svc_job_file(cfg, j->id, "png", poster, sizeof poster);
    const char *const from[] = {f->out, f->hashes, f->poster}, *const to[] = {video, hashes, poster};
    for (int i = 0; i < 3; i++) {
        size_t k = strlen(from[i]);
        char *at;
        if (!k || !(at = strstr(out, from[i])))
            continue;
        char tail[SVC_LOG_LINE];
        snprintf(tail, sizeof tail, "%s", at + k);
        snprintf(at, n - (size_t)(at - out), "%s%s", to[i], tail);
    }
}

void svc_segment_path(char *out, size_t n, const char *segdir, int index, int attempt, const char *ext)
{
    snprintf(out, n, "%s/s%d-a%d.%s", segdir, index, attempt, ext);
}

void svc_argv_free(char **argv)
{
    for (char **a = argv; a && *a; a++)
        free(*a);
    free(argv);
}

/* a growing argv of copies */
typedef struct av {
    char **v;
    int n, cap;
    bool oom;
} av;

static void add(av *a, const char *s)
{
    if (a->oom)
        return;
    if (a->n + 2 > a->cap) {
        int cap = a->cap ? a->cap * 2 : 32;
        char **v = realloc(a->v, (size_t)cap * sizeof *v);
        if (!v) {
            a->oom = true;
            return;
        }
        a->v = v, a->cap = cap;
    }
    if (!(a->v[a->n] = strdup(s))) {
        a->oom = true;
        return;
    }
    a->v[++a->n] = NULL;
}

char **svc_unit_argv(const svc_config *cfg, const svc_job *j, const svc_unit_files *f, const svc_unit *units, int n,
                     rs_err *err)
{
    av a = {0};
    char size[32], rsize[32], ticks[64];
    snprintf(size, sizeof size, "%dx%d", j->width, j->height);
    snprintf(rsize, sizeof rsize, "%dx%d", cfg->render_width, cfg->render_height);
    add(&a, "ringside");
    if (j->unit.kind == SVC_UNIT_JOIN) {
        /* the segments in order, each as the attempt the queue recorded */
        /* -y: the names are the daemon's own; one a crashed attempt left is its to replace */
        const char *const head[] = {"join", "--segment", j->key, "-y", "-o", f->out, "--hashes", f->hashes,
                                    "--progress-fd", "3", "--quiet"};
        for (size_t i = 0; i < sizeof head / sizeof *head; i++)
            add(&a, head[i]);
        /* the job's sound, mixed once for the whole video (segments are silent), unless it asked for none */
        char audio[8];
        svc_encode_get(j->encode, "audio", audio, sizeof audio);
        if (strcmp(audio, "off")) {
            add(&a, "--replay");
            add(&a, f->replay);
        }
        int k = 0;
        for (int i = 0; i < n; i++) {
            if (units[i].kind != SVC_UNIT_SEGMENT)
                continue;
            if (units[i].index != k || units[i].state != SVC_DONE || units[i].done_attempt <= 0) {
                svc_argv_free(a.v);
                rs_fail(err, SVC_ERR_SEGMENTS, "job %" PRId64 ": segment %d is not done (%s): nothing to join yet", j->id, k,
                        svc_state_name(units[i].state));
                return NULL;
            }
            char seg[1200];
            svc_segment_path(seg, sizeof seg, f->segdir, units[i].index, units[i].done_attempt, j->format);
            add(&a, seg);
            k++;
        }
        if (k != j->segments) {
            svc_argv_free(a.v);
            rs_fail(err, SVC_ERR_SEGMENTS, "job %" PRId64 ": %d of %d segments found", j->id, k, j->segments);
            return NULL;
        }
    } else {
        add(&a, "render");
        add(&a, f->replay);
        if (j->unit.kind == SVC_UNIT_SEGMENT) {
            snprintf(ticks, sizeof ticks, "%" PRId64 ":%" PRId64, j->unit.first_tick, j->unit.end_tick);
            add(&a, "--ticks");
            add(&a, ticks);
            add(&a, "--segment");
            add(&a, j->key);
        }
        /* the daemon's workers and segments are its parallelism: a render
         * splits itself (render --jobs auto) only as the machine's one worker */
        const char *jobs = cfg->workers == 1 && j->unit.kind != SVC_UNIT_SEGMENT ? "auto" : "1";
        const char *const tail[] = {"-y", "-o", f->out, "--size", size, "--hashes", f->hashes, "--poster", f->poster,
                                    "--progress-fd", "3", "--progress", "off", "--backend", cfg->backend, "--jobs", jobs};
        for (size_t i = 0; i < sizeof tail / sizeof *tail; i++)
            add(&a, tail[i]);
        if (f->stream[0]) { /* the pieces a viewer watches while the rest renders */
            add(&a, "--hls-dir");
            add(&a, f->stream);
        }
        if (cfg->render_width) { /* the operator's fixed size; else the job's quality decides */
            add(&a, "--render-size");
            add(&a, rsize);
        }
        char opt[8][24], val[8][CAP_ENC_PRESET_MAX]; /* the job's encoder options and quality (svc_encode.c) */
        int nenc = svc_encode_argv(j->encode, opt, val, 8);
        for (int i = 0; i < nenc; i++) {
            add(&a, opt[i]);
            add(&a, val[i]);
        }
    }
    if (a.oom) {
        svc_argv_free(a.v);
        rs_fail(err, SVC_ERR_NOMEM, "out of memory");
        return NULL;
    }
    return a.v;
}

/* name is "sI-aK." something, or a temporary of one (".sI-aK..."). */
static bool of_segment(const char *name, const char *prefix)
{
    if (name[0] == '.')
        name++;
    return !strncmp(name, prefix, strlen(prefix));
}

void svc_segment_remove(const char *segdir, int index, int attempt)
{
    char prefix[64], path[1400];
    snprintf(prefix, sizeof prefix, "s%d-a%d.", index, attempt);
    DIR *dir = opendir(segdir);
    if (!dir)
        return;
    struct dirent *e;
    while ((e = readdir(dir)))
        if (of_segment(e->d_name, prefix)) {
            snprintf(path, sizeof path, "%s/%s", segdir, e->d_name);
            unlink(path);
        }
    closedir(dir);
}

void svc_remove_dir(const char *path)
{
    DIR *dir = opendir(path);
    if (!dir) {
        if (errno == ENOTDIR)
            unlink(path);
        return;
    }
    struct dirent *e;
    char p[1400];
    while ((e = readdir(dir))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        snprintf(p, sizeof p, "%s/%s", path, e->d_name);
        if (unlink(p) != 0 && errno == EISDIR)
            svc_remove_dir(p); /* nothing of ours nests, but a stray directory must not keep its parent */
    }
    closedir(dir);
    rmdir(path);
}

void svc_remove_job_files(const svc_config *cfg, int64_t id)
{
    char prefix[48], path[1400];
    snprintf(prefix, sizeof prefix, ".job%" PRId64 "-", id);
    DIR *dir = opendir(cfg->output);
    struct dirent *e;
    while (dir && (e = readdir(dir)))
        if (!strncmp(e->d_name, prefix, strlen(prefix))) {
            snprintf(path, sizeof path, "%s/%s", cfg->output, e->d_name);
            if (unlink(path) != 0 && (errno == EISDIR || errno == EPERM))
                svc_remove_dir(path);
        }
    if (dir)
        closedir(dir);
}

int svc_remove_job_outputs(const svc_config *cfg, int64_t id, const char *format)
{
    char path[1400];
    int n = 0;
    const char *exts[] = {format, "hashes", "png", "log"};
    for (int i = 0; i < 4; i++) {
        svc_job_file(cfg, id, exts[i], path, sizeof path);
        n += unlink(path) == 0;
    }
    svc_remove_job_files(cfg, id);
    return n + svc_remove_job_stream(cfg, id);
}

int svc_remove_job_stream(const svc_config *cfg, int64_t id)
{
    char path[1100];
    struct stat st;
    svc_job_file(cfg, id, "stream", path, sizeof path);
    if (lstat(path, &st) != 0)
        return 0;
    svc_remove_dir(path);
    return 1;
}

/* ".jobN-..." -> N; 0 when the name is not one of ours.  *pid: the daemon
 * that wrote it (".jobN-PID-aK..." and "-jK...", a render or a join), or
 * 0 (a segment directory ".jobN-NONCE", shared by every claim). */
static int64_t job_of(const char *name, int *pid)
{
    *pid = 0;
    if (strncmp(name, ".job", 4) != 0)
        return 0;
    char *end;
    long long id = strtoll(name + 4, &end, 10);
    if (!(end > name + 4 && *end == '-' && id > 0))
        return 0;
    char *p;
    long v = strtol(end + 1, &p, 10);
    if (p > end + 1 && p[0] == '-' && (p[1] == 'a' || p[1] == 'j') && v > 0 && v < INT32_MAX)
        *pid = (int)v;
    return id;
}

/* A file of a daemon process that is gone: not running here, or (at
 * start-up) our own pid left by an earlier daemon that had it (pid 1 in
 * a container, every time). */
static bool dead_writer(int pid, bool startup)
{
    if (pid == (int)getpid())
        return startup;
    return kill(pid, 0) != 0 && errno == ESRCH;
}

/* Finished jobs older than retention: their video and hashes go (those
 * this host made: another host's output directory is its own to sweep;
 * with files = queue, any job's: their bytes are the queue's, and each
 * host's sweep removes its own copies, sweep_copies), and the queue marks
 * them expired. */
static int sweep_retention(svc_daemon *d)
{
    if (d->cfg.retention <= 0)
        return 0;
    char host[SVC_OWNER_MAX];
    snprintf(host, sizeof host, "%s", d->owner);
    char *colon = strchr(host, ':');
    if (colon)
        *colon = 0;
    int64_t ids[64];
    rs_err err = {0};
    bool keep = svc_keep_on(&d->cfg);
    int n = d->store->ops->expiring(d->store, d->cfg.retention, keep ? NULL : host, ids, 64, &err), removed = 0;
    if (n < 0)
        svc_log(SVC_LOG_ERROR, -1, "retention: cannot list expired jobs: %s", err.msg);
    for (int i = 0; i < n; i++) {
        svc_job j;
        if (d->store->ops->get(d->store, ids[i], &j, &err) != 1)
            continue;
        removed += svc_remove_job_outputs(&d->cfg, ids[i], j.format);
        if (keep && d->store->ops->file_drop(d->store, ids[i], "", &err) < 0) {
            svc_log(SVC_LOG_ERROR, ids[i], "retention: cannot remove its files from the queue: %s", err.msg);
            continue; /* not marked: the next sweep tries again */
        }
        if (d->store->ops->expire(d->store, ids[i], &err) < 0)
            svc_log(SVC_LOG_ERROR, ids[i], "retention: removed its files but could not mark it expired: %s", err.msg);
        else
            svc_log(SVC_LOG_INFO, ids[i], "expired: its video and hashes removed (finished more than %ld s ago)",
                    d->cfg.retention);
    }
    return removed;
}

/* A stream temporary (".NAME.PID.part") of a render process that is gone */
static bool dead_stream_part(const char *name)
{
    size_t n = strlen(name);
    if (name[0] != '.' || n < 8 || strcmp(name + n - 5, ".part") != 0)
        return false;
    const char *p = name + n - 5;
    while (p > name && p[-1] >= '0' && p[-1] <= '9')
        p--;
    long pid = p[-1] == '.' ? strtol(p, NULL, 10) : 0;
    return pid > 0 && pid < INT32_MAX && dead_writer((int)pid, false);
}

/* A fetch's temporary (".NAME.fetch-SEQ-HOST-PID", svc_store_sql_files.c)
 * that a process of this machine left and that no longer runs: the host
 * says whose pid it is, since an output directory may still be shared */
static bool dead_fetch(const char *name)
{
    const char *f = strstr(name, ".fetch-"), *dash = strrchr(name, '-');
    if (!f)
        return false;
    char *seq_end, *pid_end;
    strtoul(f + 7, &seq_end, 10);
    if (seq_end == f + 7 || *seq_end != '-' || dash <= seq_end)
        return false;
    const char *h = seq_end + 1; /* the host, up to the last '-' */
    char host[256] = "";
    gethostname(host, sizeof host - 1);
    size_t hl = (size_t)(dash - h);
    long pid = strtol(dash + 1, &pid_end, 10);
    return *pid_end == 0 && pid > 0 && pid < INT32_MAX && hl == strlen(host) && !strncmp(h, host, hl) &&
           dead_writer((int)pid, false);
}

/* OUTPUT/N.stream/OTHERKEY: an older queue's job of the same id; and, on
 * an SQLite queue (one machine: a pid says who), the temporaries a killed
 * render left in the job's own stream folder */
static int sweep_other_keys(svc_daemon *d, int64_t id, const char *key)
{
    char path[1100], sub[1400];
    svc_job_file(&d->cfg, id, "stream", path, sizeof path);
    DIR *dir = opendir(path);
    struct dirent *e;
    int removed = 0;
    while (dir && (e = readdir(dir))) {
        if (!strcmp(e->d_name, key) && !strcmp(d->store->ops->name, "sqlite")) {
            snprintf(sub, sizeof sub, "%s/%s", path, e->d_name);
            DIR *own = opendir(sub);
            struct dirent *f;
            char part[1700];
            while (own && (f = readdir(own)))
                if (dead_stream_part(f->d_name)) {
                    snprintf(part, sizeof part, "%s/%s", sub, f->d_name);
                    removed += unlink(part) == 0;
                }
            if (own)
                closedir(own);
        }
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..") || !strcmp(e->d_name, key))
            continue;
        snprintf(sub, sizeof sub, "%s/%s", path, e->d_name);
        svc_remove_dir(sub);
        removed++;
        svc_log(SVC_LOG_DEBUG, id, "removed %s (another key's stream)", sub);
    }
    if (dir)
        closedir(dir);
    return removed;
}

/* A copy's name with files = queue (svc_keep.c): the video, hashes,
 * poster or log of job N */
static bool copy_ext(const char *ext)
{
    static const char *const exts[] = {"mp4", "mkv", "webm", "hashes", "png", "log"};
    for (size_t i = 0; i < sizeof exts / sizeof *exts; i++)
        if (!strcmp(ext, exts[i]))
            return true;
    return false;
}

/* The output directory's numbered names, in one walk:
 *  - OUTPUT/N.stream of a job this queue does not have, or that failed, was
 *    cancelled or expired (a done job's stream stays with its video);
 *  - files = queue: the directory holds this machine's copies of what is in
 *    the queue (svc_keep.c), so the video, hashes and poster of a job the
 *    queue no longer has or that expired go, and so does the log of a job
 *    it no longer has, and a fetch's temporary that a process of this
 *    machine left and that is gone.  Without files = queue those names are
 *    the only copy, removed by DELETE and retention alone. */
static int sweep_numbered(svc_daemon *d)
{
    DIR *dir = opendir(d->cfg.output);
    struct dirent *e;
    int removed = 0;
    bool keep = svc_keep_on(&d->cfg);
    char path[1400];
    while (dir && (e = readdir(dir))) {
        snprintf(path, sizeof path, "%s/%s", d->cfg.output, e->d_name);
        if (keep && e->d_name[0] == '.' && dead_fetch(e->d_name)) {
            removed += unlink(path) == 0;
            continue;
        }
        char *end;
        long long id = strtoll(e->d_name, &end, 10);
        if (!(end > e->d_name && e->d_name[0] != '0' && id > 0 && *end == '.'))
            continue;
        bool stream = !strcmp(end, ".stream"), log = !strcmp(end, ".log");
        if (!stream && !(keep && copy_ext(end + 1)))
            continue;
        svc_job j;
        rs_err err = {0};
        int r = d->store->ops->get(d->store, id, &j, &err);
        if (r < 0)
            break; /* the queue is down: keep everything */
        const char *why = r == 0 ? "no such job in this queue" : stream ? "the job is over" : "expired";
        if (stream) {
            if (r == 1 && (j.state == SVC_QUEUED || j.state == SVC_RUNNING || (j.state == SVC_DONE && !j.expired)))
                removed += sweep_other_keys(d, id, j.key);
            else if (svc_remove_job_stream(&d->cfg, id))
                removed++, svc_log(SVC_LOG_DEBUG, id, "removed its stream (%s)", why);
        } else if ((r == 0 || (j.expired && !log)) && unlink(path) == 0)
            removed++, svc_log(SVC_LOG_DEBUG, id, "removed %s (%s)", path, why);
    }
    if (dir)
        closedir(dir);
    return removed;
}

/* The output directory: what belongs to a job that is over or that this
 * queue never had goes; so does a segment directory named by another key
 * than its job's (an older queue's job of the same id), and, on an SQLite
 * queue, a render's or join's file of a daemon process that is gone.  The
 * work directory: replay copies of daemons that are gone.
 *
 * DESIGN (a render finished, its daemon died before the rename or before
 * the queue heard of it): the file is deleted, not renamed into place.
 * The queue is the truth: the unit's lease expired and it was re-queued,
 * perhaps already claimed again; a rename would show a finished video of
 * a job the queue calls queued, and the next render writes the same bytes
 * anyway.  On a PostgreSQL queue the output directory may be shared by
 * hosts and a file name carries only a pid, so such files wait until
 * their job is over (then any daemon removes them). */
void svc_sweep(svc_daemon *d, bool startup)
{
    DIR *dir = opendir(d->cfg.output);
    char path[1400];
    int removed = sweep_retention(d);
    bool one_daemon = !strcmp(d->store->ops->name, "sqlite");
    struct dirent *e;
    while (dir && (e = readdir(dir))) {
        int pid;
        int64_t id = job_of(e->d_name, &pid);
        if (!id)
            continue;
        svc_job j;
        rs_err err = {0};
        int r = d->store->ops->get(d->store, id, &j, &err);
        if (r < 0)
            break; /* the queue is down: keep everything, look again later */
        snprintf(path, sizeof path, "%s/%s", d->cfg.output, e->d_name);
        struct stat st;
        if (lstat(path, &st) != 0)
            continue;
        bool over = r == 0 || j.state == SVC_DONE || j.state == SVC_FAILED || j.state == SVC_CANCELLED;
        bool stale_dir = !over && S_ISDIR(st.st_mode) && (j.segments == 0 || strcmp(e->d_name + 1, j.key) != 0);
        bool orphan = !over && one_daemon && pid && dead_writer(pid, startup);
        if (!over && !stale_dir && !orphan)
            continue;
        if (S_ISDIR(st.st_mode))
            svc_remove_dir(path);
        else
            unlink(path);
        removed++;
        svc_log(SVC_LOG_DEBUG, id, "removed %s (%s)", path,
                r == 0 ? "no such job in this queue" : stale_dir ? "another key's segments"
                         : orphan ? "its daemon is gone" : "the job is over");
    }
    if (dir)
        closedir(dir);
    removed += sweep_numbered(d);
    char work[1100];
    snprintf(work, sizeof work, "%s/work", d->cfg.data);
    dir = opendir(work);
    while (dir && (e = readdir(dir))) {
        long long id;
        int pid;
        if (sscanf(e->d_name, "job%lld-%d", &id, &pid) != 2 || !dead_writer(pid, startup))
            continue; /* ours, or a daemon still running (sharing the data directory) */
        snprintf(path, sizeof path, "%s/%s", work, e->d_name);
        if (unlink(path) == 0)
            removed++;
    }
    if (dir)
        closedir(dir);
    if (removed)
        svc_log(SVC_LOG_INFO, -1, "removed %d leftover or expired file%s", removed, removed == 1 ? "" : "s");
}
