/* svc_daemon: the supervisor loop of `ringside serve`.
 *
 * DESIGN: one thread (main) owns the workers and every child process; see
 * svc_local.h for what the HTTP threads share.  Each worker slot runs one
 * `ringside render` child at a time:
 *
 *   claim (store) -> write the replay to DATA/work -> fork+exec render
 *     fd 3: "frames DONE TOTAL" / "desync TICK" lines (--progress-fd 3)
 *     fd 2: its messages; the last line is the job's error if it fails
 *   every lease/6 s: heartbeat (progress + lease); "not ours" -> SIGTERM it
 *   no new frame for `watchdog` s -> SIGKILL, retried like a crash
 *   exit 0 -> rename the output into place, finish(done)
 *   desync -> finish(failed) with the tick: a replay that desyncs once
 *     desyncs every time, so it is not retried
 *   anything else (crash, signal, exit 1) -> release: re-queued until
 *     max_attempts, then failed with every attempt's reason counted
 *
 * The render writes "<output>/.jobN-PID-aK.fmt" (its own .part first), and
 * only a finished one is renamed to "<output>/N.fmt": a render killed at
 * any point leaves no file that looks finished, and two daemons that both
 * think they own a job (a lease lost to a network partition) write
 * different temporary names and the same final bytes.
 *
 * Children get PR_SET_PDEATHSIG: a daemon killed with SIGKILL takes its
 * renders with it, so a restarted daemon never races an orphan. */
#define _GNU_SOURCE /* pipe2, O_CLOEXEC, close_range */
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "svc_local.h"
#include "svc_log.h"
#include "../runtime/util/rs_file.h"

typedef struct worker {
    int slot;
    char owner[SVC_OWNER_MAX]; /* "host:pid-nonce/slot": a lease belongs to one slot, so a job re-claimed
                                  by another slot of this daemon is no longer the old render's */
    bool busy;
    pid_t pid;
    svc_job job;
    int prog_fd, err_fd;        /* read ends, non-blocking; -1 closed */
    char prog_buf[256], err_buf[1024];
    size_t prog_len, err_len;
    char last_err[SVC_ERROR_MAX]; /* the render's last message line */
    int64_t done, total, desync;
    double spawned, last_frame, last_beat, fps_t0;
    int64_t fps_d0;
    double fps;
    enum { K_NONE, K_WATCHDOG, K_CANCEL, K_SHUTDOWN } killed;
    double killed_at;
    char out_tmp[1024], hashes_tmp[1024], replay_path[1024];
} worker;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void final_paths(const svc_daemon *d, const svc_job *j, char *video, size_t nv, char *hashes, size_t nh)
{
    snprintf(video, nv, "%s/%" PRId64 ".%s", d->cfg.output, j->id, j->format);
    snprintf(hashes, nh, "%s/%" PRId64 ".hashes", d->cfg.output, j->id);
}

static void publish(svc_daemon *d, const worker *w)
{
    pthread_mutex_lock(&d->mu);
    svc_live *l = &d->live[w->slot];
    l->job = w->busy ? w->job.id : 0;
    l->pid = w->busy ? w->pid : 0;
    l->done = w->done;
    l->total = w->total;
    l->fps = w->fps;
    pthread_mutex_unlock(&d->mu);
}

static void close_fd(int *fd)
{
    if (*fd >= 0)
        close(*fd);
    *fd = -1;
}

static void worker_clear(svc_daemon *d, worker *w)
{
    close_fd(&w->prog_fd);
    close_fd(&w->err_fd);
    if (w->replay_path[0])
        unlink(w->replay_path);
    /* a render killed with SIGKILL could not remove its own ".part" files */
    char part[1100];
    const char *tmps[] = {w->out_tmp, w->hashes_tmp};
    for (int i = 0; i < 2; i++)
        if (tmps[i][0]) {
            unlink(tmps[i]);
            snprintf(part, sizeof part, "%s.part", tmps[i]);
            unlink(part);
        }
    svc_job_free(&w->job);
    int slot = w->slot;
    char owner[SVC_OWNER_MAX];
    memcpy(owner, w->owner, sizeof owner);
    memset(w, 0, sizeof *w);
    w->slot = slot;
    memcpy(w->owner, owner, sizeof owner);
    w->prog_fd = w->err_fd = -1;
    publish(d, w);
}

/* Starts the render of w->job.  False: the job could not even start
 * (a local problem such as a full disk); the caller releases it. */
static bool spawn(svc_daemon *d, worker *w, rs_err *err)
{
    const svc_job *j = &w->job;
    pid_t me = getpid();
    snprintf(w->replay_path, sizeof w->replay_path, "%s/work/job%" PRId64 "-%d.rsr", d->cfg.data, j->id, (int)me);
    snprintf(w->out_tmp, sizeof w->out_tmp, "%s/.job%" PRId64 "-%d-a%d.%s", d->cfg.output, j->id, (int)me, j->attempts,
             j->format);
    snprintf(w->hashes_tmp, sizeof w->hashes_tmp, "%s/.job%" PRId64 "-%d-a%d.hashes", d->cfg.output, j->id, (int)me,
             j->attempts);
    if (!rs_mkdirs_for(w->replay_path, err) || !rs_write_part(w->replay_path, j->replay, j->replay_len, err) ||
        !rs_commit_file(w->replay_path, err))
        return false;
    char size[32], rsize[32];
    snprintf(size, sizeof size, "%dx%d", j->width, j->height);
    snprintf(rsize, sizeof rsize, "%dx%d", d->cfg.render_width, d->cfg.render_height);
    char *argv[] = {"ringside", "render", w->replay_path, "-o", w->out_tmp, "--size", size, "--render-size", rsize,
                    "--hashes", w->hashes_tmp, "--progress-fd", "3", "--quiet", "--backend", d->cfg.backend, NULL};
    int prog[2], errp[2];
    if (pipe2(prog, O_CLOEXEC) != 0)
        return rs_fail(err, 1, "pipe: %s", strerror(errno));
    if (pipe2(errp, O_CLOEXEC) != 0) {
        close(prog[0]), close(prog[1]);
        return rs_fail(err, 1, "pipe: %s", strerror(errno));
    }
    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid < 0) {
        close(prog[0]), close(prog[1]), close(errp[0]), close(errp[1]);
        return rs_fail(err, 1, "fork: %s", strerror(errno));
    }
    if (pid == 0) {
        /* the child: only async-signal-safe calls until exec */
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent)
            _exit(127);
        /* its own process group: Ctrl-C at the daemon's terminal (or a
         * signal to the daemon's group) reaches the daemon, which decides */
        setpgid(0, 0);
        int devnull = open("/dev/null", O_RDWR);
        if (devnull < 0 || dup2(devnull, 0) < 0 || dup2(devnull, 1) < 0 || dup2(errp[1], 2) < 0 ||
            dup2(prog[1], 3) < 0)
            _exit(127);
        /* dup2 clears close-on-exec on 0..3; everything else (the HTTP
         * sockets, the database) was opened with it or is closed here */
        close_range(4, ~0U, 0);
        struct sigaction sa = {0};
        sa.sa_handler = SIG_DFL;
        sigaction(SIGTERM, &sa, NULL);
        sigaction(SIGINT, &sa, NULL);
        sigaction(SIGPIPE, &sa, NULL);
        sigset_t none;
        sigemptyset(&none);
        sigprocmask(SIG_SETMASK, &none, NULL);
        execv(d->exe, argv);
        static const char msg[] = "ringside serve: cannot run the renderer\n";
        ssize_t r = write(2, msg, sizeof msg - 1);
        (void)r;
        _exit(127);
    }
    close(prog[1]);
    close(errp[1]);
    w->prog_fd = prog[0];
    w->err_fd = errp[0];
    fcntl(w->prog_fd, F_SETFL, O_NONBLOCK);
    fcntl(w->err_fd, F_SETFL, O_NONBLOCK);
    w->pid = pid;
    w->busy = true;
    w->total = j->frames_total;
    w->desync = -1;
    w->spawned = w->last_frame = w->last_beat = w->fps_t0 = now_s();
    svc_log(SVC_LOG_INFO, j->id, "rendering %s (%" PRId64 " frames, %dx%d %s, attempt %d of %d) in process %d",
            j->name, j->frames_total, j->width, j->height, j->format, j->attempts, d->cfg.max_attempts, (int)pid);
    publish(d, w);
    return true;
}

static void on_prog_line(worker *w, char *line)
{
    long long a, b;
    if (sscanf(line, "frames %lld %lld", &a, &b) == 2) {
        if (a != w->done)
            w->last_frame = now_s();
        w->done = a;
        w->total = b;
    } else if (sscanf(line, "desync %lld", &a) == 1)
        w->desync = a;
}

static void on_err_line(svc_daemon *d, worker *w, char *line)
{
    if (!*line)
        return;
    /* "ringside render: x.rsr: desync ..." -> the part after "render: " */
    const char *m = strstr(line, "ringside render: ");
    m = m ? m + strlen("ringside render: ") : line;
    /* the render knows the replay by its work-file name; people know it
     * by the name it was uploaded under */
    size_t rl = strlen(w->replay_path);
    if (rl && !strncmp(m, w->replay_path, rl))
        snprintf(w->last_err, sizeof w->last_err, "%s%s", w->job.name, m + rl);
    else
        snprintf(w->last_err, sizeof w->last_err, "%s", m);
    svc_log(SVC_LOG_DEBUG, w->job.id, "render says: %s", m);
    (void)d;
}

/* Reads what is there; splits lines.  Returns false at EOF or error. */
static bool drain(svc_daemon *d, worker *w, int *fd, char *buf, size_t cap, size_t *len, bool prog)
{
    while (*fd >= 0) {
        ssize_t n = read(*fd, buf + *len, cap - 1 - *len);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
            return true;
        if (n <= 0) {
            close_fd(fd);
            if (*len) { /* an unterminated last line */
                buf[*len] = 0;
                prog ? on_prog_line(w, buf) : on_err_line(d, w, buf);
                *len = 0;
            }
            return false;
        }
        *len += (size_t)n;
        buf[*len] = 0;
        char *start = buf, *nl;
        while ((nl = strchr(start, '\n'))) {
            *nl = 0;
            prog ? on_prog_line(w, start) : on_err_line(d, w, start);
            start = nl + 1;
        }
        *len = (size_t)(buf + *len - start);
        memmove(buf, start, *len);
        if (*len == cap - 1) /* a line longer than the buffer: take it as it is */
            *len = 0;
    }
    return false;
}

static void describe_status(int status, char *out, size_t n)
{
    if (WIFEXITED(status))
        snprintf(out, n, "exit status %d", WEXITSTATUS(status));
    else if (WIFSIGNALED(status))
        snprintf(out, n, "killed by signal %d (%s)", WTERMSIG(status), strsignal(WTERMSIG(status)));
    else
        snprintf(out, n, "status %d", status);
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

/* A render process ended: decide what its job becomes. */
static void on_exit_status(svc_daemon *d, worker *w, int status)
{
    drain(d, w, &w->prog_fd, w->prog_buf, sizeof w->prog_buf, &w->prog_len, true);
    drain(d, w, &w->err_fd, w->err_buf, sizeof w->err_buf, &w->err_len, false);
    svc_job *j = &w->job;
    rs_err err = {0};
    char how[128], why[SVC_ERROR_MAX + 160];
    describe_status(status, how, sizeof how);
    double secs = now_s() - w->spawned;

    bool exited_ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (w->killed == K_CANCEL && !exited_ok) {
        svc_log(SVC_LOG_INFO, j->id, "cancelled; render process stopped after %.1f s", secs);
        goto out;
    }
    /* a finished render counts even if a stop signal came just too late */
    if (exited_ok) {
        char video[1100], hashes[1100];
        final_paths(d, j, video, sizeof video, hashes, sizeof hashes);
        if (rename(w->hashes_tmp, hashes) != 0 || rename(w->out_tmp, video) != 0) {
            /* this machine's problem (disk, a vanished directory), not the job's */
            snprintf(why, sizeof why, "the render finished but its output could not be moved to %s: %s", video,
                     strerror(errno));
            if (d->store->ops->release(d->store, j->id, w->owner, why, false, d->cfg.max_attempts, &err) < 0)
                svc_log(SVC_LOG_ERROR, j->id, "could not re-queue: %s", err.msg);
            local_failure(now_s());
            svc_log(SVC_LOG_ERROR, j->id, "%s; re-queued, no new jobs for %.0f s", why, local_backoff);
            goto out;
        }
        int r = d->store->ops->finish(d->store, j->id, w->owner, SVC_DONE, "", -1, w->total, &err);
        if (r == 1) {
            svc_log(SVC_LOG_INFO, j->id, "done: %s, %" PRId64 " frames in %.1f s (%.1f fps)", video, w->total, secs,
                    secs > 0 ? (double)w->total / secs : 0.0);
            pthread_mutex_lock(&d->mu);
            d->jobs_done++;
            pthread_mutex_unlock(&d->mu);
        } else if (r == 0) {
            /* cancelled meanwhile: its files go; finished by another daemon
             * (a lease lost and re-claimed): the same bytes, keep them */
            svc_job cur;
            if (d->store->ops->get(d->store, j->id, &cur, &err) == 1 && cur.state == SVC_CANCELLED) {
                unlink(video);
                unlink(hashes);
                svc_log(SVC_LOG_INFO, j->id, "finished just after it was cancelled: video removed");
            } else
                svc_log(SVC_LOG_WARN, j->id, "finished, but the job is no longer ours (re-claimed elsewhere)");
        } else
            svc_log(SVC_LOG_ERROR, j->id, "finished, but recording it failed: %s (the lease will expire and the "
                                          "job will run again)", err.msg);
        goto out;
    }
    if (w->killed == K_SHUTDOWN || (d->stop && w->killed == K_NONE)) {
        /* stopped for the daemon's shutdown (by us after the grace period,
         * or by a signal to the whole service): not the job's fault */
        if (d->store->ops->release(d->store, j->id, w->owner, "the daemon shut down before the render finished", false,
                                   d->cfg.max_attempts, &err) < 0)
            svc_log(SVC_LOG_ERROR, j->id, "could not re-queue: %s", err.msg);
        else
            svc_log(SVC_LOG_INFO, j->id, "re-queued: the daemon is shutting down (%" PRId64 " of %" PRId64 " frames done)",
                    w->done, w->total);
        goto out;
    }
    if (w->desync >= 0 || (WIFEXITED(status) && WEXITSTATUS(status) == 2)) {
        /* the replay's own fault (or a usage error of ours): retrying
         * cannot help */
        snprintf(why, sizeof why, "%s", w->last_err[0] ? w->last_err : how);
        if (d->store->ops->finish(d->store, j->id, w->owner, SVC_FAILED, why, w->desync, w->done, &err) < 0)
            svc_log(SVC_LOG_ERROR, j->id, "could not record the failure: %s", err.msg);
        svc_log(SVC_LOG_WARN, j->id, "failed: %s", why);
        pthread_mutex_lock(&d->mu);
        d->jobs_failed++;
        pthread_mutex_unlock(&d->mu);
        goto out;
    }
    if (w->killed == K_WATCHDOG)
        snprintf(why, sizeof why, "the render made no progress for %d s at frame %" PRId64 " of %" PRId64
                                  " and was killed (watchdog)",
                 d->cfg.watchdog, w->done, w->total);
    else if (WIFSIGNALED(status))
        snprintf(why, sizeof why, "the render process was %s at frame %" PRId64 " of %" PRId64, how, w->done, w->total);
    else
        snprintf(why, sizeof why, "%s (%s)", w->last_err[0] ? w->last_err : "the render failed", how);
    pthread_mutex_lock(&d->mu);
    d->worker_crashes++;
    pthread_mutex_unlock(&d->mu);
    {
        int r = d->store->ops->release(d->store, j->id, w->owner, why, true, d->cfg.max_attempts, &err);
        if (r < 0)
            svc_log(SVC_LOG_ERROR, j->id, "could not re-queue after \"%s\": %s", why, err.msg);
        else if (r == 0)
            svc_log(SVC_LOG_WARN, j->id, "%s; the job is no longer ours", why);
        else if (j->attempts >= d->cfg.max_attempts) {
            svc_log(SVC_LOG_WARN, j->id, "failed for good after %d attempts: %s", j->attempts, why);
            pthread_mutex_lock(&d->mu);
            d->jobs_failed++;
            pthread_mutex_unlock(&d->mu);
        } else {
            svc_log(SVC_LOG_WARN, j->id, "%s; re-queued (attempt %d of %d)", why, j->attempts, d->cfg.max_attempts);
            pthread_mutex_lock(&d->mu);
            d->jobs_retried++;
            pthread_mutex_unlock(&d->mu);
        }
    }
out:
    worker_clear(d, w);
}

/* Heartbeat, fps, watchdog for one busy worker. */
static void tend(svc_daemon *d, worker *w, double now)
{
    int64_t before = w->done;
    drain(d, w, &w->prog_fd, w->prog_buf, sizeof w->prog_buf, &w->prog_len, true);
    drain(d, w, &w->err_fd, w->err_buf, sizeof w->err_buf, &w->err_len, false);
    if (w->done > before) {
        pthread_mutex_lock(&d->mu);
        d->frames_rendered += (uint64_t)(w->done - before);
        pthread_mutex_unlock(&d->mu);
    }
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
        int r = d->store->ops->heartbeat(d->store, w->job.id, w->owner, d->cfg.lease, w->done, w->total, w->fps, &err);
        if (r == 0) {
            /* cancelled by DELETE (or, after a long stall, re-claimed) */
            svc_job cur;
            bool cancelled = d->store->ops->get(d->store, w->job.id, &cur, &err) == 1 && cur.state == SVC_CANCELLED;
            svc_log(SVC_LOG_INFO, w->job.id, "%s: stopping its render", cancelled ? "cancelled" : "no longer ours");
            w->killed = K_CANCEL;
            w->killed_at = now;
            kill(w->pid, SIGTERM);
            return;
        }
        if (r < 0)
            svc_log(SVC_LOG_WARN, w->job.id, "heartbeat failed: %s", err.msg);
    }
    if (now - w->last_frame > d->cfg.watchdog) {
        svc_log(SVC_LOG_WARN, w->job.id, "no progress for %d s (frame %" PRId64 " of %" PRId64 "): killing process %d",
                d->cfg.watchdog, w->done, w->total, (int)w->pid);
        w->killed = K_WATCHDOG;
        w->killed_at = now;
        kill(w->pid, SIGKILL);
        pthread_mutex_lock(&d->mu);
        d->watchdog_kills++;
        pthread_mutex_unlock(&d->mu);
    }
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
        snprintf(why, sizeof why, "could not start the render: %s", err.msg);
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
    double last_reap = 0, drain_start = 0;
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
        if (draining && busy == 0)
            break;
        if (!draining && now - last_reap >= 2.0) {
            rs_err err = {0};
            int r = d->store->ops->reap(d->store, d->cfg.max_attempts, false, &err);
            if (r > 0)
                svc_log(SVC_LOG_WARN, -1, "%d job%s with an expired lease re-queued (or failed at the attempt cap)",
                        r, r == 1 ? "" : "s");
            else if (r < 0)
                svc_log(SVC_LOG_ERROR, -1, "reaping expired leases failed: %s", err.msg);
            last_reap = now;
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
