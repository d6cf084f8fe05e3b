/* svc_main: svc_serve, the daemon's one entry point (svc.h).  It builds
 * what the supervisor (svc_daemon.c) and the HTTP threads (svc_http.c)
 * share: directories, the SQLite lock, the store handles, the owner name
 * our leases carry, the mutex and the live table; then it runs both.
 *
 * DESIGN (threads): this runs on the main thread, which becomes the
 * supervisor; svc_local.h says what the HTTP threads share.  The signal
 * handlers only set d->stop (Redis's habit): the supervisor notices it
 * within one poll interval and drains. */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "svc.h"
#include "svc_auth.h"
#include "svc_local.h"
#include "svc_log.h"
#include "../runtime/util/rs_file.h"

static svc_daemon *the_daemon;

static void on_signal(int sig)
{
    (void)sig;
    if (the_daemon)
        the_daemon->stop = the_daemon->stop ? 2 : 1;
}

/* One daemon per SQLite file: a lock file beside it.  It is also what
 * makes it safe to re-queue every running job at start-up. */
static int lock_sqlite(const char *db, rs_err *err)
{
    char path[1100];
    snprintf(path, sizeof path, "%s.lock", db);
    int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) {
        rs_fail(err, SVC_ERR_SYSTEM, "%s: cannot create the lock file: %s", path, strerror(errno));
        return -1;
    }
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        char other[32] = "";
        ssize_t n = pread(fd, other, sizeof other - 1, 0);
        other[n > 0 ? n : 0] = 0;
        other[strcspn(other, "\n")] = 0;
        rs_fail(err, SVC_ERR_LOCKED, "%s: another daemon (process %s) uses this queue; an SQLite queue serves one daemon "
                        "(use PostgreSQL for several)",
                db, other[0] ? other : "?");
        close(fd);
        return -1;
    }
    char pid[32];
    int n = snprintf(pid, sizeof pid, "%d\n", (int)getpid());
    if (ftruncate(fd, 0) != 0 || pwrite(fd, pid, (size_t)n, 0) != n) {
        /* the lock is what matters; the pid inside is only for the message */
    }
    return fd;
}

static bool mkdir_p(const char *dir, rs_err *err)
{
    char probe[1100];
    snprintf(probe, sizeof probe, "%s/x", dir);
    if (!rs_mkdirs_for(probe, err))
        return false;
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return rs_fail(err, SVC_ERR_DATA_DIR, "%s: not a directory", dir);
    if (access(dir, W_OK) != 0)
        return rs_fail(err, SVC_ERR_DATA_DIR, "%s: not writable", dir);
    return true;
}

/* svc_desc's defaults, in the order start-up needs them: the settings
 * first, the programs and files once the directories exist. */
static bool desc_config(svc_daemon *d, const svc_desc *desc, rs_err *err)
{
    if (desc->config) {
        d->cfg = *desc->config;
        return true;
    }
    svc_config_defaults(&d->cfg);
    return svc_config_finish(&d->cfg, err);
}

static bool desc_files(svc_daemon *d, const svc_desc *desc, rs_err *err)
{
    if (desc->exe)
        snprintf(d->exe, sizeof d->exe, "%s", desc->exe);
    else {
        ssize_t n = readlink("/proc/self/exe", d->exe, sizeof d->exe - 1);
        if (n <= 0)
            return rs_fail(err, SVC_ERR_SYSTEM, "cannot find this program's path (/proc/self/exe) to run the renderer");
        d->exe[n] = 0;
    }
    rs_err derr = {0};
    const char *root = rs_data_dir(&derr);
    /* hls.js: installed beside the page (make install), or where npm put it in the source tree (make web) */
    static const char *const hls[] = {"service/hls.min.js", "service/web/node_modules/hls.js/dist/hls.min.js"};
    for (size_t i = 0; root && i < sizeof hls / sizeof *hls && !d->hls_js[0]; i++) {
        rs_data_path(root, hls[i], d->hls_js, sizeof d->hls_js);
        if (access(d->hls_js, R_OK) != 0)
            d->hls_js[0] = 0;
    }
    if (!d->hls_js[0])
        svc_log(SVC_LOG_INFO, -1, "hls.js was not found ('make web' fetches it): the dashboard plays live streams "
                                  "only in browsers that play HLS themselves");
    if (desc->dashboard) {
        snprintf(d->dashboard, sizeof d->dashboard, "%s", desc->dashboard);
        return true;
    }
    if (root)
        rs_data_path(root, "service/dashboard.html", d->dashboard, sizeof d->dashboard);
    if (!root || access(d->dashboard, R_OK) != 0) {
        svc_log(SVC_LOG_WARN, -1, "the dashboard page (service/dashboard.html) was not found%s%s: GET / shows a note",
                root ? "" : ": ", root ? "" : derr.msg);
        d->dashboard[0] = 0;
    }
    return true;
}

/* Beyond loopback, anyone who reaches the port could list, download and
 * cancel every job: refuse to start without a token to ask for.  Says in
 * the log whether requests need one. */
static bool check_tokens(svc_daemon *d, rs_err *err)
{
    int64_t n = d->store->ops->token_active(d->store, err);
    if (n < 0)
        return false;
    bool loopback = svc_listen_is_loopback(d->cfg.listen);
    if (!loopback && n == 0)
        return rs_fail(err, SVC_ERR_NO_TOKENS,
                       "listen %s reaches beyond this machine and the queue has no API token: make one first with "
                       "'ringside serve token add NAME' (with the same --data or --queue), or listen on 127.0.0.1",
                       d->cfg.listen);
    if (n > 0)
        svc_log(SVC_LOG_INFO, -1, "API tokens required (%lld active)%s", (long long)n,
                loopback ? "" : ": listening beyond loopback");
    else
        svc_log(SVC_LOG_INFO, -1, "API tokens not required: loopback and no tokens ('ringside serve token add NAME' "
                                  "makes the first and turns them on)");
    return true;
}

bool svc_serve(const svc_desc *desc, rs_err *err)
{
    static svc_daemon d;
    memset(&d, 0, sizeof d);
    if (!desc_config(&d, desc, err))
        return false;
    svc_log_level(d.cfg.log_level);
    /* started with stdin/out/err closed, pipes could land on fds 0..2 and
     * be overwritten when a render's stdio is set up: fill them first */
    int nullfd = open("/dev/null", O_RDWR);
    while (nullfd >= 0 && nullfd <= 2)
        nullfd = open("/dev/null", O_RDWR);
    if (nullfd > 2)
        close(nullfd);

    bool ok = false, mu = false;
    int lock_fd = -1;
    struct MHD_Daemon *http = NULL;
    char work[1100];
    snprintf(work, sizeof work, "%s/work", d.cfg.data);
    if (!mkdir_p(d.cfg.data, err) || !mkdir_p(work, err) || !mkdir_p(d.cfg.output, err) ||
        !desc_files(&d, desc, err))
        goto out;
    char host[64] = "localhost";
    gethostname(host, sizeof host - 1);
    /* the nonce: two containers may share a hostname and both be pid 1 */
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    snprintf(d.owner, sizeof d.owner, "%s:%d-%08x", host, (int)getpid(),
             (unsigned)(ts.tv_nsec ^ (ts.tv_sec << 20) ^ ((long)getpid() << 8)));

    bool sqlite = strncmp(d.cfg.queue, "postgres://", 11) != 0 && strncmp(d.cfg.queue, "postgresql://", 13) != 0;
    if (sqlite) {
        const char *db = !strncmp(d.cfg.queue, "sqlite:", 7) ? d.cfg.queue + 7 : d.cfg.queue;
        if (*db && !rs_mkdirs_for(db, err))
            goto out;
        if (*db && (lock_fd = lock_sqlite(db, err)) < 0)
            goto out;
    }
    if (!(d.store = svc_store_open(d.cfg.queue, d.cfg.lease, err)) || !(d.http_store = svc_store_open(d.cfg.queue, d.cfg.lease, err)))
        goto out;
    if (!check_tokens(&d, err))
        goto out;
    if (sqlite) {
        /* we hold the only lock: every running job belonged to a daemon
         * that is gone */
        if (svc_reap_leases(&d, true, err) < 0)
            goto out;
    }
    pthread_mutex_init(&d.mu, NULL);
    mu = true;
    d.live = calloc((size_t)d.cfg.workers, sizeof *d.live);
    if (!d.live) {
        rs_fail(err, SVC_ERR_NOMEM, "out of memory");
        goto out;
    }
    the_daemon = &d;
    struct sigaction sa = {0};
    sa.sa_handler = on_signal;
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    sa.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &sa, NULL); /* a client that hangs up mid-video */
    if (!(http = svc_http_start(&d, err)))
        goto out;
    int64_t counts[SVC_NSTATES] = {0};
    rs_err cerr = {0};
    d.store->ops->counts(d.store, counts, &cerr);
    char shown[160], rsize[48] = "drawn at the size the quality sets";
    if (d.cfg.render_width)
        snprintf(rsize, sizeof rsize, "drawn at %dx%d", d.cfg.render_width, d.cfg.render_height);
    snprintf(shown, sizeof shown, "%s", d.cfg.listen);
    char *colon = strrchr(shown, ':');
    if (colon)
        snprintf(colon + 1, sizeof shown - (size_t)(colon + 1 - shown), "%u", d.port);
    svc_log(SVC_LOG_INFO, -1,
            "listening on http://%s/ (queue %s: %lld queued, %lld running; %d worker%s; videos in %s%s; quality %s, %s)",
            shown, d.store->ops->name, (long long)counts[SVC_QUEUED], (long long)counts[SVC_RUNNING], d.cfg.workers,
            d.cfg.workers == 1 ? "" : "s", d.cfg.output, svc_keep_on(&d.cfg) ? ", kept in the queue" : "",
            d.cfg.quality, rsize);
    ok = svc_run(&d) == 0;
    if (!ok)
        rs_fail(err, SVC_ERR_SUPERVISOR, "the supervisor stopped on an error (see the log above)");
    svc_http_stop(&d, http);
    http = NULL;
    svc_log(SVC_LOG_INFO, -1, "stopped");
out:
    svc_http_stop(&d, http);
    if (d.http_store)
        d.http_store->ops->close(d.http_store);
    if (d.store)
        d.store->ops->close(d.store);
    free(d.live);
    if (mu)
        pthread_mutex_destroy(&d.mu);
    the_daemon = NULL;
    if (lock_fd >= 0)
        close(lock_fd);
    return ok;
}
