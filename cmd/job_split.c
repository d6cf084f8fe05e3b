/* job_split: a render as parallel segments, joined (job_split.h).
 *
 * DESIGN: one thread (the command's) owns the children.  Each child has
 * two pipes to it: fd 3, its "frames DONE TOTAL" / "desync TICK" lines
 * (render --progress-fd), and fd 2, whose last bytes are kept for its
 * error message.  The loop polls both, reaps the children as they end,
 * and sums their frames into one progress line.  The first child to fail
 * decides the outcome: the others get SIGTERM, which render answers by
 * removing its partial output.  Every file lives in one hidden folder
 * beside the output, made here and emptied and removed here, so nothing
 * is left behind by a failure, a signal or a killed child.
 * The sound is mixed on the command's thread before the loop, and
 * encoded on a thread of its own while the children draw (ahead_main):
 * the join then only writes its packets, where it used to encode the
 * whole track on one core after both segments were done (3.2 s of
 * FFmpeg's AAC for dojo's 79 s). */
#define _GNU_SOURCE /* pipe2, sched_getaffinity */
#include "job_split.h"
#include "../runtime/util/rs_log.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../capture/cap_seg.h"
#include "../runtime/util/rs_file.h"
#include "cli.h"
#include "job_err.h"

typedef struct child {
    pid_t pid;
    int prog, err;             /* read ends; -1 once closed */
    uint64_t first, end, done; /* its ticks, and frames done */
    char seg[1100];
    char line[128];            /* a progress line being read */
    size_t nline;
    char tail[4096];           /* the last of its stderr */
    size_t ntail;
    int status;                /* wait status once reaped */
    bool reaped;
    uint64_t desync;           /* > 0: the tick it reported */
} child;

int job_split_cpus(void)
{
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
        return CPU_COUNT(&set);
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}

int job_split_auto(uint64_t frames)
{
    uint64_t n = frames / JOB_SPLIT_MIN_FRAMES;
    int cpus = job_split_cpus();
    if (n > (uint64_t)cpus)
        n = (uint64_t)cpus;
    if (n > JOB_SPLIT_MAX)
        n = JOB_SPLIT_MAX;
    return n < 2 ? 1 : (int)n;
}

/* Keeps the last sizeof c->tail bytes a child wrote on stderr. */
static void keep_tail(child *c, const char *buf, size_t n)
{
    size_t cap = sizeof c->tail - 1;
    if (n > cap) {
        buf += n - cap;
        n = cap;
    }
    if (c->ntail + n > cap) {
        size_t drop = c->ntail + n - cap;
        memmove(c->tail, c->tail + drop, c->ntail - drop);
        c->ntail -= drop;
    }
    memcpy(c->tail + c->ntail, buf, n);
    c->ntail += n;
    c->tail[c->ntail] = 0;
}

/* The last non-empty line of a child's stderr, without "ringside CMD: ". */
static void last_line(const child *c, char *out, size_t n)
{
    const char *end = c->tail + c->ntail;
    while (end > c->tail && (end[-1] == '\n' || end[-1] == '\r' || end[-1] == ' '))
        end--;
    const char *start = end;
    while (start > c->tail && start[-1] != '\n')
        start--;
    const char *p = start;
    if (!strncmp(p, "ringside ", 9)) {
        const char *colon = memchr(p, ':', (size_t)(end - p));
        if (colon && colon + 2 <= end)
            p = colon + 2;
    }
    snprintf(out, n, "%.*s", (int)(end - p), p);
}

/* A line of the "; key ..." tail of a summary: from `key` to the line's end. */
static void summary_part(const child *c, const char *lead, const char *key, char *out, size_t n)
{
    out[0] = 0;
    const char *l = strstr(c->tail, lead);
    if (!l)
        return;
    const char *k = strstr(l, key), *nl = strchr(l, '\n');
    if (k && (!nl || k < nl))
        snprintf(out, n, "%.*s", (int)(nl ? nl - k : (long)strlen(k)), k);
}

static void on_line(child *c, const char *line)
{
    uint64_t a, b;
    if (sscanf(line, "frames %" SCNu64 " %" SCNu64, &a, &b) == 2)
        c->done = a;
    else if (sscanf(line, "desync %" SCNu64, &a) == 1)
        c->desync = a > 0 ? a : 1;
}

/* Reads what is there; false at end of file (the fd is then closed). */
static bool drain(child *c, int *fd, bool progress)
{
    char buf[2048];
    ssize_t n = read(*fd, buf, sizeof buf);
    if (n < 0 && (errno == EINTR || errno == EAGAIN))
        return true;
    if (n <= 0) {
        close(*fd);
        *fd = -1;
        return false;
    }
    if (!progress) {
        keep_tail(c, buf, (size_t)n);
        return true;
    }
    for (ssize_t i = 0; i < n; i++) {
        if (buf[i] == '\n') {
            c->line[c->nline] = 0;
            on_line(c, c->line);
            c->nline = 0;
        } else if (c->nline + 1 < sizeof c->line) {
            c->line[c->nline++] = buf[i];
        }
    }
    return true;
}

/* fork + exec argv with fd 3 (progress, when want_prog) and fd 2 piped to
 * c; LP_NUM_THREADS=threads in its environment unless the user set one. */
static bool spawn(child *c, const char *exe, char *const *argv, bool want_prog, int threads, rs_err *err)
{
    int pp[2] = {-1, -1}, ep[2] = {-1, -1};
    if ((want_prog && pipe2(pp, O_CLOEXEC) != 0) || pipe2(ep, O_CLOEXEC) != 0) {
        int e = errno;
        if (pp[0] >= 0)
            close(pp[0]), close(pp[1]);
        return rs_fail(err, JOB_ERR_PROCESS, "cannot make a pipe: %s", strerror(e));
    }
    pid_t pid = fork();
    if (pid < 0) {
        int e = errno;
        if (pp[0] >= 0)
            close(pp[0]), close(pp[1]);
        close(ep[0]), close(ep[1]);
        return rs_fail(err, JOB_ERR_PROCESS, "cannot start a process: %s", strerror(e));
    }
    if (pid == 0) {
        prctl(PR_SET_PDEATHSIG, SIGTERM); /* a render killed outright takes its segments with it */
        int null = open("/dev/null", O_RDONLY);
        if (null >= 0)
            dup2(null, 0);
        if (want_prog)
            dup2(pp[1], 3);
        dup2(ep[1], 2);
        if (threads >= 0 && !getenv("LP_NUM_THREADS")) {
            char t[16];
            snprintf(t, sizeof t, "%d", threads);
            setenv("LP_NUM_THREADS", t, 1);
        }
        execv(exe, argv);
        dprintf(2, "ringside render: cannot run %s: %s\n", exe, strerror(errno));
        _exit(127);
    }
    if (want_prog) {
        close(pp[1]);
        c->prog = pp[0];
        fcntl(c->prog, F_SETFL, O_NONBLOCK);
    } else {
        c->prog = -1;
    }
    close(ep[1]);
    c->err = ep[0];
    fcntl(c->err, F_SETFL, O_NONBLOCK);
    c->pid = pid;
    return true;
}

/* Runs until every child in cs[0..n) has ended.  Returns the index of the
 * first that failed, n if none did; *stopped when d->stop ended it. */
static int supervise(const job_split_desc *d, child *cs, int n, rs_progress *prog, uint64_t total, bool *stopped)
{
    int failed = n, running = n;
    double last_fd = 0;
    bool killing = false;
    *stopped = false;
    while (running > 0) {
        if (!killing && d->stop && *d->stop) {
            *stopped = killing = true;
            for (int i = 0; i < n; i++)
                if (!cs[i].reaped)
                    kill(cs[i].pid, SIGTERM);
        }
        struct pollfd pf[2 * JOB_SPLIT_MAX + 2];
        int np = 0, who[2 * JOB_SPLIT_MAX + 2];
        for (int i = 0; i < n; i++) {
            if (cs[i].prog >= 0)
                pf[np] = (struct pollfd){.fd = cs[i].prog, .events = POLLIN}, who[np++] = 2 * i;
            if (cs[i].err >= 0)
                pf[np] = (struct pollfd){.fd = cs[i].err, .events = POLLIN}, who[np++] = 2 * i + 1;
        }
        if (np > 0 && poll(pf, (nfds_t)np, 250) > 0) {
            for (int k = 0; k < np; k++)
                if (pf[k].revents) {
                    child *c = &cs[who[k] / 2];
                    if (who[k] % 2 == 0)
                        drain(c, &c->prog, true);
                    else
                        drain(c, &c->err, false);
                }
        } else if (np == 0) {
            usleep(50000);
        }
        for (int i = 0; i < n; i++) {
            child *c = &cs[i];
            if (c->reaped || c->prog >= 0 || c->err >= 0) /* read everything it wrote first */
                continue;
            if (waitpid(c->pid, &c->status, 0) != c->pid)
                continue;
            c->reaped = true;
            running--;
            bool ok = WIFEXITED(c->status) && WEXITSTATUS(c->status) == 0;
            if (!ok && failed == n && !killing) {
                failed = i;
                killing = true;
                for (int j = 0; j < n; j++)
                    if (!cs[j].reaped)
                        kill(cs[j].pid, SIGTERM);
            }
        }
        uint64_t done = 0;
        for (int i = 0; i < n; i++)
            done += cs[i].done;
        if (prog && total) {
            rs_progress_update(prog, done > total ? total : done);
            cli_progress_fd(d->progress_fd, done > total ? total : done, total, &last_fd);
        }
    }
    return failed;
}

/* Empties and removes the folder made for the segments. */
static void remove_dir(const char *dir)
{
    DIR *dp = opendir(dir);
    if (dp) {
        struct dirent *e;
        char p[1400];
        while ((e = readdir(dp)))
            if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
                snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
                unlink(p);
            }
        closedir(dp);
    }
    rmdir(dir);
}

typedef struct args {
    char *v[256];
    int n;
    char store[4096];
    size_t used;
} args;

static void add(args *a, const char *s)
{
    if (a->n < (int)(sizeof a->v / sizeof a->v[0]) - 1)
        a->v[a->n++] = (char *)s;
    a->v[a->n] = NULL;
}

/* "A:B" (two) or "A" (one) into a's own storage */
static const char *ticks_arg(args *a, uint64_t x, uint64_t y, bool two)
{
    char *p = a->store + a->used;
    int k = two ? snprintf(p, sizeof a->store - a->used, "%" PRIu64 ":%" PRIu64, x, y)
                : snprintf(p, sizeof a->store - a->used, "%" PRIu64, x);
    if (k < 0 || (size_t)k >= sizeof a->store - a->used)
        return "";
    a->used += (size_t)k + 1;
    return p;
}

/* a segment join found bad: its message, once (this render made it, so
 * it is this render's failure) */
static void seg_bad(void *ctx, int index, const rs_err *e)
{
    rs_err *first = ctx;
    if (!first->msg[0])
        rs_fail(first, e->code, "segment %d: %s", index, e->msg);
}

/* The track encoded ahead (cap_atrack_encode) on its own thread; stop
 * ends it at its next read when the render fails or is interrupted. */
typedef struct ahead {
    const job_split_desc *d;
    cap_sink sink; /* d->sink's track, read through ahead_read */
    atomic_int stop;
    cap_atrack *track;
    rs_err err;
    pthread_t thread;
    bool running;
} ahead;

static bool ahead_read(void *u, float *dst, size_t frames, rs_err *err)
{
    ahead *a = u;
    if (atomic_load(&a->stop))
        return rs_fail(err, JOB_ERR_INTERRUPTED, "%s: the sound's encoding stopped with the render", a->d->out);
    return a->d->sink->audio(a->d->sink->audio_u, dst, frames, err);
}

static void *ahead_main(void *u)
{
    ahead *a = u;
    a->track = cap_atrack_encode(&a->sink, a->d->out, &a->err);
    return NULL;
}

static void ahead_start(ahead *a, const job_split_desc *d)
{
    a->d = d;
    a->sink = *d->sink;
    a->sink.audio = ahead_read;
    a->sink.audio_u = a;
    atomic_init(&a->stop, 0);
    /* no thread (out of them): the join encodes the track itself, as before */
    a->running = pthread_create(&a->thread, NULL, ahead_main, a) == 0;
}

/* Waits for the thread (stopping it first unless keep); the track or NULL. */
static cap_atrack *ahead_end(ahead *a, bool keep, rs_err *err)
{
    if (!a->running)
        return NULL;
    if (!keep)
        atomic_store(&a->stop, 1);
    pthread_join(a->thread, NULL);
    a->running = false;
    if (!a->track && keep)
        *err = a->err;
    return a->track;
}

/* The segments into the output with the sound, as `ringside join` does
 * (cmd_join.c): every one verified, then stream-copied.  track: the sound
 * encoded ahead, or NULL to encode it here. */
static int join(const job_split_desc *d, const child *cs, int n, const char *key, cap_atrack *track, rs_err *err)
{
    cap_join *j = cap_join_open(&(cap_join_desc){.out = d->out, .hashes = d->hashes, .stop = d->stop}, err);
    if (!j)
        return RS_EXIT_FAIL;
    cap_seg segs[JOB_SPLIT_MAX];
    memset(segs, 0, sizeof segs);
    for (int i = 0; i < n; i++)
        segs[i].path = cs[i].seg;
    cap_seg_want want = {.key = key, .format = cap_seg_format_of(d->out), .first = d->first, .hashes = d->hashes != NULL};
    rs_err bad = {0};
    if (cap_seg_verify(segs, n, &want, seg_bad, &bad) > 0) {
        cap_join_close(j, false, NULL);
        *err = bad;
        return RS_EXIT_FAIL;
    }
    if (track)
        cap_join_audio_track(j, track);
    else if (d->audio->muxed)
        cap_join_audio(j, d->sink);
    int bad_index = -1;
    bool ok = cap_join_copy(j, segs, n, &bad_index, err);
    if (!cap_join_close(j, ok, ok ? err : NULL) || !ok)
        return RS_EXIT_FAIL;
    return RS_EXIT_OK;
}

/* The summary line, after the notes the first segment printed (an
 * encoder fallback) that the caller did not print already. */
static void summary(const job_split_desc *d, const child *cs, int n, uint64_t total, double secs, double secs_join)
{
    /* the notes a segment printed (an encoder fallback), once: the first segment's */
    const char *p = cs[0].tail;
    while (*p) {
        const char *nl = strchr(p, '\n');
        size_t len = nl ? (size_t)(nl - p) : strlen(p);
        bool said = d->said && d->said[0] && len == 17 + strlen(d->said) && !strncmp(p + 17, d->said, len - 17);
        if (len && !said && strncmp(p, "ringside render: wrote ", 23) && strncmp(p, "ringside render: warm-up ", 25) &&
            strncmp(p, "ringside render: poster ", 24))
            fprintf(stderr, "%.*s\n", (int)len, p);
        p += len + (nl != NULL);
    }
    char said[300], enc[120];
    job_audio_describe(d->audio, d->sink, said, sizeof said);
    summary_part(&cs[0], "ringside render: wrote ", "; encoder", enc, sizeof enc);
    fprintf(stderr,
            "ringside render: wrote %s: %" PRIu64 " frames %s in %.1f s, %.1f fps; %d segments at once (--jobs %d), joined in "
            "%.1f s%s%s\n",
            d->out, total, d->what, secs, secs > 0 ? (double)total / secs : 0.0, n, n, secs_join, said, enc);
}

int job_split_run(const job_split_desc *d, rs_err *err)
{
    int n = d->jobs;
    uint64_t total = d->end - d->first;
    if (n < 2 || n > JOB_SPLIT_MAX || total < (uint64_t)n)
        return rs_fail(err, JOB_ERR_ARG, "cannot split %" PRIu64 " frames into %d segments", total, n), RS_EXIT_FAIL;
    const char *ext = cap_seg_format_of(d->out);
    /* the folder beside the output: the same file system, so nothing is copied */
    char dir[1100];
    const char *slash = strrchr(d->out, '/');
    snprintf(dir, sizeof dir, "%.*s.ringside-render-XXXXXX", slash ? (int)(slash - d->out + 1) : 0, d->out);
    if (!mkdtemp(dir))
        return rs_fail(err, JOB_ERR_CREATE, "%s: cannot make a folder for the segments: %s", dir, strerror(errno)), RS_EXIT_FAIL;
    char key[40], poster[1200];
    snprintf(key, sizeof key, "render-%d", (int)getpid());
    snprintf(poster, sizeof poster, "%s/poster.png", dir);
    int cpus = job_split_cpus();
    int threads = cpus / n - 1; /* llvmpipe's own threads, beside each child's main thread */
    if (threads < 0)
        threads = 0;

    child cs[JOB_SPLIT_MAX];
    memset(cs, 0, sizeof cs);
    cap_atrack *track = NULL; /* the sound, encoded while the segments draw */
    int status = RS_EXIT_FAIL, started = 0;
    rs_progress prog;
    rs_progress_start(&prog, "render", "frames", total, d->quiet ? RS_PROGRESS_OFF : d->progress);
    for (int i = 0; i < n; i++) {
        child *c = &cs[i];
        c->first = d->first + total * (uint64_t)i / (uint64_t)n;
        c->end = d->first + total * (uint64_t)(i + 1) / (uint64_t)n;
        snprintf(c->seg, sizeof c->seg, "%s/s%d.%s", dir, i, ext);
        char hashes[1100];
        cap_seg_hashes_path(c->seg, hashes, sizeof hashes);
        args a = {0};
        add(&a, "ringside");
        add(&a, "render");
        add(&a, d->replay);
        for (int k = 0; d->pass && d->pass[k]; k++)
            add(&a, d->pass[k]);
        add(&a, "--ticks");
        add(&a, ticks_arg(&a, c->first, c->end, true));
        const char *const tail[] = {"--segment", key, "-o", c->seg, "-y", "--audio", "off", "--jobs", "1",
                                    "--progress", "off", "--progress-fd", "3"};
        for (size_t k = 0; k < sizeof tail / sizeof *tail; k++)
            add(&a, tail[k]);
        if (d->hashes) {
            add(&a, "--hashes");
            add(&a, hashes);
        }
        if (d->poster) { /* only the segment that holds its frame writes it (job_poster.h) */
            add(&a, "--poster");
            add(&a, poster);
        }
        if (!spawn(c, d->exe, a.v, true, threads, err))
            break;
        started++;
    }
    /* the sound, while they draw (this process has nothing else to do) */
    bool mixed = started < n || job_audio_plan(d->audio, d->sink, d->rp, d->replay, d->first, d->end, err);
    if (!mixed)
        for (int i = 0; i < started; i++)
            kill(cs[i].pid, SIGTERM);
    ahead ah = {0};
    if (mixed && started == n && d->audio->muxed)
        ahead_start(&ah, d);
    bool stopped = false;
    int failed = supervise(d, cs, started, &prog, total, &stopped);
    bool drawn = mixed && started == n && !stopped && failed >= started;
    rs_err track_err = {0};
    track = ahead_end(&ah, drawn, &track_err);
    if (track_err.code) { /* the thread ran to the end and failed: its message */
        *err = track_err;
        goto done;
    }
    if (!mixed)
        goto done;
    if (started < n) { /* err says why the rest did not start */
        goto done;
    }
    if (stopped) {
        uint64_t done = 0;
        for (int i = 0; i < started; i++)
            done += cs[i].done;
        rs_fail(err, JOB_ERR_INTERRUPTED, "%s: interrupted at frame %" PRIu64 " of %" PRIu64 "; the partial output was removed", d->out, done,
                total);
        goto done;
    }
    if (failed < started) {
        child *c = &cs[failed];
        char msg[400];
        last_line(c, msg, sizeof msg);
        if (c->desync && d->progress_fd >= 0)
            dprintf(d->progress_fd, "desync %" PRIu64 "\n", c->desync);
        if (WIFEXITED(c->status))
            rs_fail(err, JOB_ERR_SEGMENT, "%s: segment %d of %d (ticks %" PRIu64 "..%" PRIu64 "): %s", d->out, failed + 1, n, c->first,
                    c->end - 1, msg[0] ? msg : "its render failed");
        else
            rs_fail(err, JOB_ERR_SEGMENT, "%s: segment %d of %d (ticks %" PRIu64 "..%" PRIu64 "): its render ended by signal %d%s%s", d->out,
                    failed + 1, n, c->first, c->end - 1, WTERMSIG(c->status), msg[0] ? ": " : "", msg);
        if (WIFEXITED(c->status) && WEXITSTATUS(c->status) == RS_EXIT_USAGE)
            status = RS_EXIT_USAGE;
        goto done;
    }

    /* the join: the output, its hash list and its sound */
    double t1 = rs_now();
    if ((status = join(d, cs, n, key, track, err)) != RS_EXIT_OK)
        goto done;
    status = RS_EXIT_FAIL;
    if (d->poster) {
        if (access(poster, F_OK) == 0) {
            if (rename(poster, d->poster) != 0) {
                rs_fail(err, JOB_ERR_WRITE, "%s: cannot put the poster in place: %s; %s removed with it", d->poster, strerror(errno),
                        d->out);
                unlink(d->out);
                goto done;
            }
        } else if (rs_log_on(RS_LOG_WARNING)) {
            fprintf(stderr, "ringside render: no poster written: its frame is outside --ticks %" PRIu64 ":%" PRIu64 "\n",
                    d->first, d->end);
        }
    }
    double secs = rs_progress_end(&prog), secs_join = rs_now() - t1;
    if (!d->quiet)
        summary(d, cs, n, total, secs, secs_join);
    status = RS_EXIT_OK;
done:
    cap_atrack_free(track);
    for (int i = 0; i < started; i++) { /* a start that failed half way: nothing may outlive us */
        if (!cs[i].reaped) {
            kill(cs[i].pid, SIGKILL);
            waitpid(cs[i].pid, NULL, 0);
        }
        if (cs[i].prog >= 0)
            close(cs[i].prog);
        if (cs[i].err >= 0)
            close(cs[i].err);
    }
    if (status != RS_EXIT_OK)
        rs_progress_end(&prog);
    remove_dir(dir);
    return status;
}
