/* svc_daemon: the supervisor loop of `ringside serve`.
 *
 * DESIGN: one thread (main) owns the workers and every child process; see
 * svc_local.h for what the HTTP threads share.  Each worker slot runs one
 * child at a time for the unit of work it claimed (svc_store.h, "Units"):
 * `ringside render` for a whole job or a segment of one, `ringside join`
 * for a split job's join (svc_files.c: the files and the command line):
 *
 *   claim a unit (store) -> write the replay to DATA/work -> fork+exec
 *     fd 3: "frames DONE TOTAL" / "desync TICK" / "bad INDEX REASON" /
 *       "hls-failed" lines (the last: the video is written, its stream
 *       pieces are not: exit 1 that counts as done, the stream unlisted)
 *     fd 2: its messages; the last line is the unit's error if it fails, and
 *       the last SVC_LOG_LINES go to the job's render log (OUTPUT/N.log,
 *       appended when the unit ends; GET /jobs/N/log shows it and, while
 *       the unit runs, the lines so far from svc_live.log)
 *   every lease/6 s: heartbeat (progress + lease); "not ours" -> SIGTERM it
 *   no new frame for `watchdog` s -> SIGKILL, retried like a crash
 *   exit 0 -> a whole job or a join: rename the output and the poster
 *     (render --poster; a join takes the segment's that held its frame)
 *     into place, finish(done); a segment: its files stay where they are (the queue
 *     records which attempt made them), finish(done)
 *   desync -> finish(failed) with the tick: a replay that desyncs once
 *     desyncs every time, so it is not retried
 *   the join's exit 3 (bad segments) -> those segments are deleted and
 *     rendered again, the join waits for them (rejoin); its exit 1 (disk
 *     full, directory gone) -> a local problem, no attempt counted
 *   anything else (crash, signal, exit 1) -> release: the unit re-queued
 *     until max_attempts, then its job failed with its reason
 *
 * An unsplit render writes "<output>/.jobN-PID-aK.fmt" (its own .part
 * first), and only a finished one is renamed to "<output>/N.fmt": a render
 * killed at any point leaves no file that looks finished, and two daemons
 * that both think they own a job (a lease lost to a network partition)
 * write different temporary names and the same final bytes.  Segments and
 * joins keep the same rules (svc_files.c).  What a crash leaves behind is
 * removed when the unit ends, and the sweep (svc_sweep: at start-up,
 * every 10 s and at the end of a drain) removes what belongs to jobs that
 * are over or to daemons that are gone, and expires old videos
 * (retention).
 *
 * Attempts are charged for render failures only: a unit whose daemon died
 * comes back through reap (svc_reap_leases) with its attempt given back
 * and a lost lease counted (svc_store.h).
 *
 * Children get PR_SET_PDEATHSIG (svc_child.c, which starts them and reads
 * their pipes): a daemon killed with SIGKILL takes its renders with it, so
 * a restarted daemon never races an orphan. */
#include <errno.h>
#include <inttypes.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "svc_child.h"
#include "svc_local.h"
#include "svc_log.h"
#include "../runtime/util/rs_file.h"

typedef struct worker {
    int slot;
    char owner[SVC_OWNER_MAX]; /* "host:pid-nonce/slot": a lease belongs to one slot, so a unit re-claimed
                                  by another slot of this daemon is no longer the old child's */
    bool busy;
    pid_t pid;
    svc_job job;                /* job.unit: the unit this slot holds */
    svc_unit_files f;           /* its files */
    svc_unit *units;            /* the join: the job's units when it started (segment files by done_attempt) */
    int nunits;
    int *bad, nbad;             /* the join: segments it found bad ("bad INDEX REASON") */
    char bad_why[SVC_ERROR_MAX];
    bool keep;                  /* a segment the queue recorded: its files stay */
    bool hls_failed;            /* "hls-failed": its output is good, its stream pieces are not */
    int prog_fd, err_fd;        /* read ends, non-blocking; -1 closed */
    char prog_buf[1024], err_buf[1024];
    size_t prog_len, err_len;
    char last_err[SVC_ERROR_MAX]; /* the child's last message line */
    char log[SVC_LOG_LINES][SVC_LOG_LINE]; /* its last stderr lines, a ring from log_head */
    int log_n, log_head;
    int64_t done, total, desync;
    double spawned, last_frame, last_beat, fps_t0;
    int64_t fps_d0, beat_done;
    double fps, beat_fps;
    enum { K_NONE, K_WATCHDOG, K_CANCEL, K_SHUTDOWN } killed;
    double killed_at;
} worker;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void publish(svc_daemon *d, const worker *w)
{
    pthread_mutex_lock(&d->mu);
    svc_live *l = &d->live[w->slot];
    l->job = w->busy ? w->job.id : 0;
    l->pid = w->busy ? w->pid : 0;
    l->kind = w->job.unit.kind;
    l->index = w->job.unit.index;
    l->done = w->done;
    l->total = w->total;
    l->fps = w->fps;
    l->beat_done = w->beat_done;
    l->beat_fps = w->beat_fps;
    pthread_mutex_unlock(&d->mu);
}

/* The unit's log so far, oldest line first, into out (n >= 1). */
static size_t log_text(const worker *w, char *out, size_t n)
{
    size_t k = 0;
    out[0] = 0;
    for (int i = 0; i < w->log_n && k + 1 < n; i++) {
        int r = snprintf(out + k, n - k, "%s\n", w->log[(w->log_head + i) % SVC_LOG_LINES]);
        k = r < 0 ? k : k + (size_t)r >= n ? n - 1 : k + (size_t)r;
    }
    return k;
}

/* A stderr line into the ring, and the ring to the HTTP threads. */
static void log_line(svc_daemon *d, worker *w, const char *line)
{
    int at = (w->log_head + w->log_n) % SVC_LOG_LINES;
    if (w->log_n == SVC_LOG_LINES)
        w->log_head = (w->log_head + 1) % SVC_LOG_LINES;
    else
        w->log_n++;
    svc_client_names(&d->cfg, &w->job, &w->f, line, w->log[at], SVC_LOG_LINE);
    pthread_mutex_lock(&d->mu);
    log_text(w, d->live[w->slot].log, sizeof d->live[w->slot].log);
    pthread_mutex_unlock(&d->mu);
}

/* What a unit's log lines start with after "job N: ": "" for a whole job,
 * "segment 2 (ticks 120-180): " or "join: " */
static const char *ctx(const worker *w)
{
    static char buf[96];
    svc_unit_context(buf, sizeof buf, &w->job.unit);
    return buf;
}

static void worker_clear(svc_daemon *d, worker *w)
{
    svc_child_close(&w->prog_fd);
    svc_child_close(&w->err_fd);
    if (w->f.replay[0])
        unlink(w->f.replay);
    /* a child killed with SIGKILL could not remove its own ".part" files */
    char part[1200];
    const char *tmps[] = {w->f.out, w->f.hashes, w->f.poster};
    for (int i = 0; i < 3 && w->job.unit.kind != SVC_UNIT_SEGMENT; i++)
        if (tmps[i][0]) {
            unlink(tmps[i]);
            snprintf(part, sizeof part, "%s.part", tmps[i]);
            unlink(part);
        }
    if (w->job.unit.kind == SVC_UNIT_SEGMENT && !w->keep)
        svc_segment_remove(w->f.segdir, w->job.unit.index, w->job.unit.claim);
    /* the job is over (failed, cancelled, done): its segments go too, and
     * whatever crashed attempts (of any daemon) left */
    svc_job cur;
    rs_err err = {0};
    int have = w->busy ? d->store->ops->get(d->store, w->job.id, &cur, &err) : -1;
    if (have == 1 && cur.state != SVC_QUEUED && cur.state != SVC_RUNNING)
        svc_remove_job_files(&d->cfg, w->job.id);
    if (have == 0) /* deleted while it ran: the log this unit just wrote has no job */
        svc_remove_job_outputs(&d->cfg, w->job.id, w->job.format);
    svc_job_free(&w->job);
    free(w->units);
    free(w->bad);
    int slot = w->slot;
    char owner[SVC_OWNER_MAX];
    memcpy(owner, w->owner, sizeof owner);
    memset(w, 0, sizeof *w);
    w->slot = slot;
    memcpy(w->owner, owner, sizeof owner);
    w->prog_fd = w->err_fd = -1;
    pthread_mutex_lock(&d->mu);
    d->live[w->slot].log[0] = 0;
    pthread_mutex_unlock(&d->mu);
    publish(d, w);
}

/* Starts the child for w->job's unit.  False: it could not even start
 * (a local problem such as a full disk); the caller releases it. */
static bool spawn(svc_daemon *d, worker *w, rs_err *err)
{
    svc_job *j = &w->job;
    svc_unit_paths(&d->cfg, j, w->slot, &w->f);
    if (j->unit.kind == SVC_UNIT_JOIN) {
        w->units = calloc((size_t)j->segments + 1, sizeof *w->units);
        w->bad = calloc((size_t)j->segments + 1, sizeof *w->bad);
        if (!w->units || !w->bad)
            return rs_fail(err, SVC_ERR_NOMEM, "out of memory");
        w->nunits = d->store->ops->units(d->store, j->id, w->units, j->segments + 1, err);
        if (w->nunits < 0)
            return false;
        /* files = queue: segments other machines rendered come from the queue */
        if (svc_keep_on(&d->cfg) && !svc_fetch_segments(d->store, j, &w->f, w->units, w->nunits, err))
            return false;
    }
    /* every unit gets the replay: renders draw it, the join mixes its sound */
    if (!rs_mkdirs_for(w->f.replay, err) || !rs_write_part(w->f.replay, j->replay, j->replay_len, err) ||
        !rs_commit_file(w->f.replay, err))
        return false;
    if (j->unit.kind == SVC_UNIT_SEGMENT && !rs_mkdirs_for(w->f.out, err))
        return false;
    char **argv = svc_unit_argv(&d->cfg, j, &w->f, w->units, w->nunits, err);
    if (!argv)
        return false;
    pid_t pid;
    /* a job's later segments yield to any first one (nice 10): a first
     * segment's pieces are what a viewer is waiting for (docs/service.md,
     * "Watching while it renders"); the cores are still all used */
    int nice = j->unit.kind == SVC_UNIT_SEGMENT && j->unit.index > 0 ? SVC_LATER_NICE : 0;
    bool started = svc_child_start(d->exe, argv, nice, &pid, &w->prog_fd, &w->err_fd, err);
    svc_argv_free(argv);
    if (!started)
        return false;
    w->pid = pid;
    w->busy = true;
    w->total = j->unit.kind == SVC_UNIT_SEGMENT ? j->unit.end_tick - j->unit.first_tick : j->frames_total;
    w->desync = -1;
    w->spawned = w->last_frame = w->last_beat = w->fps_t0 = now_s();
    if (j->unit.kind == SVC_UNIT_WHOLE)
        svc_log(SVC_LOG_INFO, j->id, "rendering %s (%" PRId64 " frames, %dx%d %s, attempt %d of %d) in process %d",
                j->name, j->frames_total, j->width, j->height, j->format, j->unit.attempts, d->cfg.max_attempts,
                (int)pid);
    else if (j->unit.kind == SVC_UNIT_SEGMENT)
        svc_log(SVC_LOG_INFO, j->id, "%srendering %s (%" PRId64 " frames, %dx%d %s, attempt %d of %d) in process %d",
                ctx(w), j->name, w->total, j->width, j->height, j->format, j->unit.attempts, d->cfg.max_attempts,
                (int)pid);
    else
        svc_log(SVC_LOG_INFO, j->id, "joining %d segments of %s (%" PRId64 " frames, attempt %d) in process %d",
                j->segments, j->name, j->frames_total, j->unit.attempts, (int)pid);
    publish(d, w);
    return true;
}

static void on_prog_line(worker *w, char *line)
{
    long long a, b;
    int idx, off = 0;
    if (sscanf(line, "frames %lld %lld", &a, &b) == 2) {
        if (a != w->done)
            w->last_frame = now_s();
        w->done = a;
        w->total = b;
    } else if (sscanf(line, "desync %lld", &a) == 1)
        w->desync = a;
    else if (!strcmp(line, "hls-failed"))
        w->hls_failed = true;
    else if (w->bad && sscanf(line, "bad %d %n", &idx, &off) == 1 && off > 0 && idx >= 0 && idx < w->job.segments) {
        /* the join: segment idx failed its checks; keep the first reasons */
        bool seen = false;
        for (int i = 0; i < w->nbad; i++)
            seen |= w->bad[i] == idx;
        if (!seen)
            w->bad[w->nbad++] = idx;
        size_t n = strlen(w->bad_why);
        if (n + 8 < sizeof w->bad_why)
            snprintf(w->bad_why + n, sizeof w->bad_why - n, "%ssegment %d: %s", n ? "; " : "", idx, line + off);
    }
}

static void on_err_line(svc_daemon *d, worker *w, char *line)
{
    if (*line)
        log_line(d, w, line);
    /* a usage error's second line says where help is: the first says why */
    if (!*line || (strstr(line, "see 'ringside ") && strstr(line, "--help'")))
        return;
    /* "ringside render: x.rsr: desync ..." -> the part after "render: " */
    const char *m = strstr(line, "ringside render: ");
    m = m ? m + strlen("ringside render: ") : (m = strstr(line, "ringside join: ")) ? m + strlen("ringside join: ") : line;
    /* the render knows the replay by its work-file name; people know it
     * by the name it was uploaded under */
    size_t rl = strlen(w->f.replay);
    if (rl && !strncmp(m, w->f.replay, rl))
        snprintf(w->last_err, sizeof w->last_err, "%s%s", w->job.name, m + rl);
    else
        snprintf(w->last_err, sizeof w->last_err, "%s", m);
    svc_log(SVC_LOG_DEBUG, w->job.id, "%s%s says: %s", ctx(w), w->job.unit.kind == SVC_UNIT_JOIN ? "join" : "render", m);
}

/* The child's progress (fd 3) and message (stderr) lines so far. */
static void prog_line(void *w, char *line)
{
    on_prog_line(w, line);
}

typedef struct err_ctx {
    svc_daemon *d;
    worker *w;
} err_ctx;

static void err_line(void *c, char *line)
{
    err_ctx *e = c;
    on_err_line(e->d, e->w, line);
}

static void read_child(svc_daemon *d, worker *w)
{
    err_ctx e = {d, w};
    svc_child_read(&w->prog_fd, w->prog_buf, sizeof w->prog_buf, &w->prog_len, prog_line, w);
    svc_child_read(&w->err_fd, w->err_buf, sizeof w->err_buf, &w->err_len, err_line, &e);
}

/* A problem of this machine (full disk, output directory gone): the jobs
 * are not at fault, so no attempt is counted, and claiming pauses (1 s,
 * doubling to 60 s) so one bad disk cannot run the whole queue into the
 * attempt cap. */
static double local_backoff, claim_after;

static void local_failure(double now)
{
    local_backoff = local_backoff ? local_backoff * 2 : 1.0;
    if (local_backoff > 60)
        local_backoff = 60;
    claim_after = now + local_backoff;
}

static void count(svc_daemon *d, uint64_t *what)
{
    pthread_mutex_lock(&d->mu);
    (*what)++;
    pthread_mutex_unlock(&d->mu);
}

/* A local problem (full disk, output directory gone): the unit goes back
 * without an attempt counted, and this daemon pauses its claims. */
static void give_back_local(svc_daemon *d, worker *w, const char *why)
{
    rs_err err = {0};
    if (d->store->ops->release(d->store, w->job.id, w->owner, why, false, d->cfg.max_attempts, &err) < 0)
        svc_log(SVC_LOG_ERROR, w->job.id, "could not re-queue: %s", err.msg);
    local_failure(now_s());
    svc_log(SVC_LOG_ERROR, w->job.id, "%s%s; re-queued, no new jobs for %.0f s", ctx(w), why, local_backoff);
}

/* The poster beside the video: the whole render's own, or for a join the
 * one segment whose ticks held its frame (render --poster).  A job
 * without one (its render could not write it) is still done: the poster
 * route answers 404. */
static void place_poster(svc_daemon *d, worker *w)
{
    char poster[1100], seg[1200];
    svc_job_file(&d->cfg, w->job.id, "png", poster, sizeof poster);
    if (w->job.unit.kind != SVC_UNIT_JOIN) {
        if (rename(w->f.poster, poster) != 0)
            svc_log(SVC_LOG_WARN, w->job.id, "no poster: %s: %s", w->f.poster, strerror(errno));
        return;
    }
    for (int i = 0; i < w->nunits; i++) {
        if (w->units[i].kind != SVC_UNIT_SEGMENT)
            continue;
        svc_segment_path(seg, sizeof seg, w->f.segdir, w->units[i].index, w->units[i].done_attempt, "png");
        if (rename(seg, poster) == 0)
            return;
    }
    svc_log(SVC_LOG_WARN, w->job.id, "no poster: no segment wrote one");
}

/* A whole job or a join that exited 0: its output moves into place. */
static void finished_video(svc_daemon *d, worker *w, double secs)
{
    svc_job *j = &w->job;
    rs_err err = {0};
    char video[1100], hashes[1100], why[SVC_ERROR_MAX];
    svc_job_file(&d->cfg, j->id, j->format, video, sizeof video);
    svc_job_file(&d->cfg, j->id, "hashes", hashes, sizeof hashes);
    if (rename(w->f.hashes, hashes) != 0 || rename(w->f.out, video) != 0) {
        /* this machine's problem (disk, a vanished directory), not the job's */
        snprintf(why, sizeof why, "the %s finished but its output could not be moved to %s: %s",
                 j->unit.kind == SVC_UNIT_JOIN ? "join" : "render", video, strerror(errno));
        give_back_local(d, w, why);
        return;
    }
    place_poster(d, w);
    bool stream = true;
    if (j->unit.kind == SVC_UNIT_WHOLE && !svc_unit_stream_ok(&w->f, &w->job.unit, why, sizeof why)) {
        svc_log(SVC_LOG_WARN, j->id, "%s (the video is good: it is kept, the stream is not listed)", why);
        stream = false;
    }
    char kept[64]; /* files = queue: stored before the done mark, so done means any daemon can serve it */
    if (!svc_keep_unit(d->store, &d->cfg, j, &w->f, stream, kept, sizeof kept, &err)) {
        snprintf(why, sizeof why, "the %s finished but its files could not be kept in the queue: %s",
                 j->unit.kind == SVC_UNIT_JOIN ? "join" : "render", err.msg);
        give_back_local(d, w, why);
        return;
    }
    int64_t frames = j->unit.kind == SVC_UNIT_JOIN ? j->frames_total : w->total;
    int r = d->store->ops->finish(d->store, j->id, w->owner, SVC_DONE, "", -1, frames, &err);
    if (r == 1) {
        if (j->unit.kind == SVC_UNIT_JOIN) {
            svc_keep_drop(d->store, &d->cfg, j->id, -1, 0); /* the segments are in the video now */
            svc_log(SVC_LOG_INFO, j->id, "done: %s, %" PRId64 " frames from %d segments (joined in %.1f s%s)", video,
                    frames, j->segments, secs, kept);
        } else
            svc_log(SVC_LOG_INFO, j->id, "done: %s, %" PRId64 " frames in %.1f s (%.1f fps%s)", video, frames, secs,
                    secs > 0 ? (double)frames / secs : 0.0, kept);
        count(d, &d->jobs_done);
    } else if (r == 0) {
        /* cancelled meanwhile: its files go; finished by another daemon
         * (a lease lost and re-claimed): the same bytes, keep them */
        svc_job cur;
        if (d->store->ops->get(d->store, j->id, &cur, &err) == 1 && cur.state == SVC_CANCELLED) {
            svc_remove_job_outputs(&d->cfg, j->id, j->format);
            svc_log(SVC_LOG_INFO, j->id, "finished just after it was cancelled: video removed");
        } else
            svc_log(SVC_LOG_WARN, j->id, "finished, but the job is no longer ours (re-claimed elsewhere)");
    } else
        svc_log(SVC_LOG_ERROR, j->id, "finished, but recording it failed: %s (the lease will expire and the "
                                      "job will run again)", err.msg);
}

/* A segment that exited 0: the queue records which attempt made it. */
static bool finished_segment(svc_daemon *d, worker *w, double secs)
{
    svc_job *j = &w->job;
    rs_err err = {0};
    char manifest[1200];
    snprintf(manifest, sizeof manifest, "%s.seg", w->f.out);
    if (access(manifest, F_OK) != 0) {
        snprintf(w->last_err, sizeof w->last_err, "the segment render exited 0 but left no manifest (%s)", manifest);
        return false; /* retried like a crash */
    }
    char why[SVC_ERROR_MAX];
    bool stream = svc_unit_stream_ok(&w->f, &w->job.unit, why, sizeof why);
    if (!stream) /* a viewer never gets a piece that is not whole */
        svc_log(SVC_LOG_WARN, j->id, "%s%s (the segment is good: it is kept, the stream stops before it)", ctx(w), why);
    char kept[64]; /* files = queue: stored before the done mark, so a done segment can be joined anywhere */
    if (!svc_keep_unit(d->store, &d->cfg, j, &w->f, stream, kept, sizeof kept, &err)) {
        snprintf(why, sizeof why, "the segment finished but its files could not be kept in the queue: %s", err.msg);
        give_back_local(d, w, why);
        return true;
    }
    int r = d->store->ops->finish(d->store, j->id, w->owner, SVC_DONE, "", -1, w->total, &err);
    if (r == 1) {
        w->keep = true;
        svc_log(SVC_LOG_INFO, j->id, "%sdone, %" PRId64 " frames in %.1f s (%.1f fps%s)", ctx(w), w->total, secs,
                secs > 0 ? (double)w->total / secs : 0.0, kept);
    } else if (r == 0)
        svc_log(SVC_LOG_WARN, j->id, "%sfinished, but it is no longer ours (cancelled or re-claimed)", ctx(w));
    else
        svc_log(SVC_LOG_ERROR, j->id, "%sfinished, but recording it failed: %s (the lease will expire and it will "
                                      "run again)", ctx(w), err.msg);
    return true;
}

/* The join found bad segments: they are deleted and rendered again. */
static void bad_segments(svc_daemon *d, worker *w)
{
    svc_job *j = &w->job;
    rs_err err = {0};
    char why[SVC_ERROR_MAX];
    snprintf(why, sizeof why, "the join found bad segment files: %s", w->bad_why);
    for (int i = 0; i < w->nbad; i++)
        for (int k = 0; k < w->nunits; k++)
            if (w->units[k].kind == SVC_UNIT_SEGMENT && w->units[k].index == w->bad[i]) {
                svc_segment_remove(w->f.segdir, w->bad[i], w->units[k].done_attempt);
                svc_keep_drop(d->store, &d->cfg, j->id, w->bad[i], w->units[k].done_attempt);
            }
    int r = d->store->ops->rejoin(d->store, j->id, w->owner, w->bad, w->nbad, why, d->cfg.max_attempts, &err);
    if (r < 0)
        svc_log(SVC_LOG_ERROR, j->id, "join: could not send the bad segments back: %s", err.msg);
    else if (r == 0)
        svc_log(SVC_LOG_WARN, j->id, "join: %s; the join is no longer ours", why);
    else
        svc_log(SVC_LOG_WARN, j->id, "join: %s; %d segment%s to render again", why, w->nbad, w->nbad == 1 ? "" : "s");
    count(d, &d->jobs_retried);
}

/* The child's progress so far, and the frames it drew since the last read
 * into the daemon's count (a join copies frames, it draws none): on every
 * tend and once more when it exits, so the last frames, reported just
 * before the exit, count too */
static void take_progress(svc_daemon *d, worker *w)
{
    int64_t before = w->done;
    read_child(d, w);
    if (w->done > before && w->job.unit.kind != SVC_UNIT_JOIN) {
        pthread_mutex_lock(&d->mu);
        d->frames_rendered += (uint64_t)(w->done - before);
        pthread_mutex_unlock(&d->mu);
    }
}

/* A child ended: decide what its unit (and so its job) becomes. */
static void on_exit_status(svc_daemon *d, worker *w, int status)
{
    take_progress(d, w);
    svc_job *j = &w->job;
    int kind = j->unit.kind;
    rs_err err = {0};
    char how[128], why[SVC_ERROR_MAX + 160];
    svc_child_status(status, how, sizeof how);
    double secs = now_s() - w->spawned;
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    {
        /* the job's render log: this attempt's header and last lines, in one write */
        char block[SVC_LOG_LINES * SVC_LOG_LINE + 512];
        int k = snprintf(block, sizeof block, "== %s%s, attempt %d, process %d: %s after %.1f s ==\n", ctx(w),
                         kind == SVC_UNIT_JOIN ? "join" : "render", j->unit.claim, (int)w->pid, how, secs);
        size_t len = (size_t)k + log_text(w, block + k, sizeof block - (size_t)k);
        svc_job_log_append(d->store, &d->cfg, j->id, block, len);
    }

    if (w->killed == K_CANCEL && code != 0) {
        svc_log(SVC_LOG_INFO, j->id, "%scancelled; %s process stopped after %.1f s", ctx(w),
                kind == SVC_UNIT_JOIN ? "join" : "render", secs);
        goto out;
    }
    /* a finished child counts even if a stop signal came just too late;
     * so does one whose video is good but its stream pieces are not */
    if (code == 1 && w->hls_failed && w->killed == K_NONE && kind != SVC_UNIT_JOIN) {
        svc_log(SVC_LOG_WARN, j->id, "%sits stream pieces could not be made: %s", ctx(w), w->last_err);
        code = 0;
    }
    if (code == 0 && kind != SVC_UNIT_SEGMENT) {
        finished_video(d, w, secs);
        goto out;
    }
    if (code == 0 && finished_segment(d, w, secs))
        goto out;
    if (w->killed == K_SHUTDOWN || (d->stop && w->killed == K_NONE)) {
        /* stopped for the daemon's shutdown (by us after the grace period,
         * or by a signal to the whole service): not the job's fault */
        if (d->store->ops->release(d->store, j->id, w->owner, "the daemon shut down before the render finished", false,
                                   d->cfg.max_attempts, &err) < 0)
            svc_log(SVC_LOG_ERROR, j->id, "could not re-queue: %s", err.msg);
        else
            svc_log(SVC_LOG_INFO, j->id, "%sre-queued: the daemon is shutting down (%" PRId64 " of %" PRId64 " frames done)",
                    ctx(w), w->done, w->total);
        goto out;
    }
    if (kind == SVC_UNIT_JOIN && code == 3 && w->nbad > 0) {
        bad_segments(d, w);
        goto out;
    }
    if (kind == SVC_UNIT_JOIN && code == 1 && w->killed == K_NONE) {
        /* the join says its output could not be written (disk full, the
         * directory gone): this machine, not the segments */
        snprintf(why, sizeof why, "the join could not write the video: %s", w->last_err[0] ? w->last_err : how);
        give_back_local(d, w, why);
        goto out;
    }
    if (w->desync >= 0 || code == 2) {
        /* the replay's own fault (or a usage error of ours): retrying
         * cannot help */
        snprintf(why, sizeof why, "%s", w->last_err[0] ? w->last_err : how);
        if (d->store->ops->finish(d->store, j->id, w->owner, SVC_FAILED, why, w->desync, w->done, &err) < 0)
            svc_log(SVC_LOG_ERROR, j->id, "could not record the failure: %s", err.msg);
        svc_log(SVC_LOG_WARN, j->id, "%sfailed: %s", ctx(w), why);
        count(d, &d->jobs_failed);
        goto out;
    }
    const char *what = kind == SVC_UNIT_JOIN ? "join" : "render";
    if (w->killed == K_WATCHDOG)
        snprintf(why, sizeof why, "the %s made no progress for %d s at frame %" PRId64 " of %" PRId64
                                  " and was killed (watchdog)",
                 what, d->cfg.watchdog, w->done, w->total);
    else if (WIFSIGNALED(status))
        snprintf(why, sizeof why, "the %s process was %s at frame %" PRId64 " of %" PRId64, what, how, w->done, w->total);
    else
        snprintf(why, sizeof why, "%s (%s)", w->last_err[0] ? w->last_err : code == 0 ? "no manifest" : "the render failed",
                 how);
    count(d, &d->worker_crashes);
    {
        int r = d->store->ops->release(d->store, j->id, w->owner, why, true, d->cfg.max_attempts, &err);
        if (r < 0)
            svc_log(SVC_LOG_ERROR, j->id, "could not re-queue after \"%s\": %s", why, err.msg);
        else if (r == 0)
            svc_log(SVC_LOG_WARN, j->id, "%s%s; the job is no longer ours", ctx(w), why);
        else if (j->unit.attempts >= d->cfg.max_attempts) {
            svc_log(SVC_LOG_WARN, j->id, "%sfailed for good after %d attempts: %s", ctx(w), j->unit.attempts, why);
            count(d, &d->jobs_failed);
        } else {
            svc_log(SVC_LOG_WARN, j->id, "%s%s; re-queued (attempt %d of %d)", ctx(w), why, j->unit.attempts,
                    d->cfg.max_attempts);
            count(d, &d->jobs_retried);
        }
    }
out:
    worker_clear(d, w);
}

/* Heartbeat, fps, watchdog for one busy worker. */
static void tend(svc_daemon *d, worker *w, double now)
{
    take_progress(d, w);
    if (now - w->fps_t0 >= 1.0) {
        /* smoothed over a few seconds, so the ETA does not jump about */
        double f = (double)(w->done - w->fps_d0) / (now - w->fps_t0);
        w->fps = w->fps > 0 && f > 0 ? 0.7 * w->fps + 0.3 * f : f;
        w->fps_t0 = now;
        w->fps_d0 = w->done;
    }
    publish(d, w);
    if (w->killed) {
        /* a render stopped with SIGTERM that has not gone in 10 s (hung in
         * the driver or the encoder) gets SIGKILL */
        if (now - w->killed_at > 10.0)
            kill(w->pid, SIGKILL);
        return;
    }
    double beat = d->cfg.lease / 6.0 < 1.0 ? 1.0 : d->cfg.lease / 6.0;
    if (now - w->last_beat >= beat) {
        rs_err err = {0};
        w->last_beat = now;
        /* a join's speed is packets copied, not frames drawn: not the job's fps */
        double fps = w->job.unit.kind == SVC_UNIT_JOIN ? 0 : w->fps;
        int64_t done = w->done;
        int r = d->store->ops->heartbeat(d->store, w->job.id, w->owner, d->cfg.lease, done, w->total, fps, &err);
        if (r == 1) {
            w->beat_done = done;
            w->beat_fps = fps;
            publish(d, w);
        }
        if (r == 0) {
            /* cancelled by DELETE (or, after a long stall, re-claimed) */
            svc_job cur;
            bool cancelled = d->store->ops->get(d->store, w->job.id, &cur, &err) == 1 && cur.state == SVC_CANCELLED;
            svc_log(SVC_LOG_INFO, w->job.id, "%s%s: stopping its %s", ctx(w), cancelled ? "cancelled" : "no longer ours",
                    w->job.unit.kind == SVC_UNIT_JOIN ? "join" : "render");
            w->killed = K_CANCEL;
            w->killed_at = now;
            kill(w->pid, SIGTERM);
            return;
        }
        if (r < 0)
            svc_log(SVC_LOG_WARN, w->job.id, "heartbeat failed: %s", err.msg);
    }
    if (now - w->last_frame > d->cfg.watchdog) {
        svc_log(SVC_LOG_WARN, w->job.id, "%sno progress for %d s (frame %" PRId64 " of %" PRId64 "): killing process %d",
                ctx(w), d->cfg.watchdog, w->done, w->total, (int)w->pid);
        w->killed = K_WATCHDOG;
        w->killed_at = now;
        kill(w->pid, SIGKILL);
        pthread_mutex_lock(&d->mu);
        d->watchdog_kills++;
        pthread_mutex_unlock(&d->mu);
    }
}

int svc_reap_leases(svc_daemon *d, bool all, rs_err *err)
{
    svc_reaped got[64];
    int n = d->store->ops->reap(d->store, all, got, 64, err);
    const char *whose = all ? "its daemon stopped" : "its lease expired: its daemon stopped or was cut off";
    for (int i = 0; i < n && i < 64; i++) {
        char c[96];
        svc_unit_context(c, sizeof c, &got[i].unit);
        if (got[i].failed)
            svc_log(SVC_LOG_WARN, got[i].id, "%sfailed: " SVC_LOST_FMT, c, got[i].unit.lost + 1);
        else
            svc_log(SVC_LOG_INFO, got[i].id, "%sre-queued (%s; no attempt charged, %d lost lease%s of %d)", c, whose,
                    got[i].unit.lost + 1, got[i].unit.lost ? "s" : "", SVC_LOST_MAX);
    }
    if (n > 64)
        svc_log(SVC_LOG_INFO, -1, "%d more units taken back from lost leases (not listed one by one)", n - 64);
    return n;
}

static void start_job(svc_daemon *d, worker *w)
{
    rs_err err = {0};
    if (now_s() < claim_after)
        return;
    int r = d->store->ops->claim(d->store, w->owner, d->cfg.lease, &w->job, &err);
    if (r <= 0) {
        if (r < 0)
            svc_log(SVC_LOG_ERROR, -1, "claiming a job failed: %s", err.msg);
        return;
    }
    if (!spawn(d, w, &err)) {
        char why[SVC_ERROR_MAX];
        snprintf(why, sizeof why, "could not start the %s: %s", w->job.unit.kind == SVC_UNIT_JOIN ? "join" : "render",
                 err.msg);
        svc_log(SVC_LOG_ERROR, w->job.id, "%s", why);
        rs_err e2 = {0};
        if (d->store->ops->release(d->store, w->job.id, w->owner, why, false, d->cfg.max_attempts, &e2) < 0)
            svc_log(SVC_LOG_ERROR, w->job.id, "could not re-queue: %s", e2.msg);
        local_failure(now_s());
        svc_log(SVC_LOG_WARN, -1, "a local problem: no new jobs for %.0f s", local_backoff);
        worker_clear(d, w);
        return;
    }
    local_backoff = 0;
}

int svc_run(svc_daemon *d)
{
    int n = d->cfg.workers;
    worker *ws = calloc((size_t)n, sizeof *ws);
    if (!ws) {
        svc_log(SVC_LOG_ERROR, -1, "out of memory");
        return 1;
    }
    for (int i = 0; i < n; i++) {
        ws[i].slot = i;
        ws[i].prog_fd = ws[i].err_fd = -1;
        snprintf(ws[i].owner, sizeof ws[i].owner, "%s/%d", d->owner, i);
    }
    double last_reap = 0, drain_start = 0, last_sweep = now_s();
    svc_sweep(d, true); /* what the last run (or a crash) left */
    bool draining = false;
    for (;;) {
        double now = now_s();
        if (d->stop && !draining) {
            draining = true;
            drain_start = now;
            pthread_mutex_lock(&d->mu);
            d->draining = true;
            pthread_mutex_unlock(&d->mu);
            int busy = 0;
            for (int i = 0; i < n; i++)
                busy += ws[i].busy;
            svc_log(SVC_LOG_INFO, -1, "stopping: no new jobs; %d running job%s %s %d s to finish (a second "
                                      "signal re-queues %s now)",
                    busy, busy == 1 ? "" : "s", busy == 1 ? "gets" : "get", d->cfg.grace, busy == 1 ? "it" : "them");
        }
        if (draining && (d->stop > 1 || now - drain_start >= d->cfg.grace)) {
            for (int i = 0; i < n; i++)
                if (ws[i].busy && !ws[i].killed) {
                    ws[i].killed = K_SHUTDOWN;
                    ws[i].killed_at = now;
                    kill(ws[i].pid, SIGTERM);
                }
            /* a render that ignores SIGTERM for 10 s gets SIGKILL */
            for (int i = 0; i < n; i++)
                if (ws[i].busy && now - ws[i].killed_at > 10.0)
                    kill(ws[i].pid, SIGKILL);
        }
        /* children that ended */
        for (int i = 0; i < n; i++) {
            if (!ws[i].busy)
                continue;
            int status;
            pid_t r = waitpid(ws[i].pid, &status, WNOHANG);
            if (r == ws[i].pid)
                on_exit_status(d, &ws[i], status);
        }
        int busy = 0;
        for (int i = 0; i < n; i++)
            busy += ws[i].busy;
        if (draining && busy == 0) {
            svc_sweep(d, false); /* what the last jobs' ends left: not until the next start */
            break;
        }
        if (!draining && now - last_reap >= 2.0) {
            rs_err err = {0};
            if (svc_reap_leases(d, false, &err) < 0)
                svc_log(SVC_LOG_ERROR, -1, "reaping expired leases failed: %s", err.msg);
            last_reap = now;
        }
        if (!draining && now - last_sweep >= 10.0) {
            svc_sweep(d, false);
            last_sweep = now;
        }
        for (int i = 0; i < n && !draining; i++)
            if (!ws[i].busy)
                start_job(d, &ws[i]);
        for (int i = 0; i < n; i++)
            if (ws[i].busy)
                tend(d, &ws[i], now);
        /* sleep until a worker says something, a signal, or 100 ms (the
         * queue is polled: another daemon may have added work) */
        struct pollfd pfd[128];
        int np = 0;
        for (int i = 0; i < n && np < 126; i++) {
            if (ws[i].prog_fd >= 0)
                pfd[np++] = (struct pollfd){.fd = ws[i].prog_fd, .events = POLLIN};
            if (ws[i].err_fd >= 0)
                pfd[np++] = (struct pollfd){.fd = ws[i].err_fd, .events = POLLIN};
        }
        poll(pfd, (nfds_t)np, busy < n ? 200 : 100);
    }
    free(ws);
    return 0;
}
