/* ringside serve: the replay-to-video daemon (service/, docs/service.md).
 * This file is the command line: settings, the queue, the lock, signals;
 * the supervisor loop is service/svc_daemon.c and the API svc_http.c. */
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "../service/svc_local.h"
#include "../service/svc_log.h"
#include "cli.h"
#include "../runtime/util/rs_file.h"

static void help(void)
{
    printf("usage: ringside serve [--config FILE] [--listen ADDR:PORT] [--workers N] [--data DIR]\n"
           "                      [--queue sqlite:PATH|postgres://...] [--output DIR] [--SETTING VALUE ...]\n"
           "                      [--print-config]\n\n"
           "The replay-to-video service: an HTTP API and dashboard, a durable job queue and\n"
           "worker processes that run 'ringside render'.  Clients upload replays\n"
           "(POST /jobs), watch progress (GET /jobs/ID) and fetch videos (GET /jobs/ID/video);\n"
           "the dashboard is at http://ADDR:PORT/.  docs/service.md has the whole API.\n\n"
           "The queue is SQLite under DATA by default (one daemon per database file);\n"
           "with a PostgreSQL URI any number of daemons on any number of machines share\n"
           "one queue (give them a shared --output directory).  A render that crashes or\n"
           "stalls is retried up to max_attempts; SIGTERM or Ctrl-C stops taking jobs, lets\n"
           "running ones finish for 'grace' seconds, re-queues the rest and exits 0.\n\n"
           "  --config FILE    settings file: 'name = value' lines, # comments; the options\n"
           "                   below override it\n"
           "  --print-config   print every setting's value after the file and options, and exit\n"
           "\nSettings (as --name or --name-with-dashes on the command line):\n");
    svc_config_print_table(stdout);
    printf("\nexit status: 0 after a clean stop (signal), 1 on a start-up failure, 2 on bad usage\n");
}

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
        rs_fail(err, 1, "%s: cannot create the lock file: %s", path, strerror(errno));
        return -1;
    }
    if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        char other[32] = "";
        ssize_t n = pread(fd, other, sizeof other - 1, 0);
        other[n > 0 ? n : 0] = 0;
        other[strcspn(other, "\n")] = 0;
        rs_fail(err, 1, "%s: another daemon (process %s) uses this queue; an SQLite queue serves one daemon "
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
        return rs_fail(err, 1, "%s: not a directory", dir);
    if (access(dir, W_OK) != 0)
        return rs_fail(err, 1, "%s: not writable", dir);
    return true;
}

int cmd_serve(int argc, char **argv)
{
    /* every setting is also an option; --config is read before the rest */
    static const struct option opts[] = {
        {"config", required_argument, 0, 'c'}, {"print-config", no_argument, 0, 'P'}, {"help", no_argument, 0, 'h'},
        {"set", required_argument, 0, 's'},
        {"listen", required_argument, 0, 1}, {"workers", required_argument, 0, 1}, {"data", required_argument, 0, 1},
        {"queue", required_argument, 0, 1}, {"output", required_argument, 0, 1},
        {"max-upload", required_argument, 0, 1}, {"max_upload", required_argument, 0, 1},
        {"max-attempts", required_argument, 0, 1}, {"max_attempts", required_argument, 0, 1},
        {"lease", required_argument, 0, 1}, {"watchdog", required_argument, 0, 1}, {"grace", required_argument, 0, 1},
        {"size", required_argument, 0, 1}, {"max-size", required_argument, 0, 1}, {"max_size", required_argument, 0, 1},
        {"render-size", required_argument, 0, 1}, {"render_size", required_argument, 0, 1},
        {"format", required_argument, 0, 1}, {"backend", required_argument, 0, 1},
        {"log-level", required_argument, 0, 1}, {"log_level", required_argument, 0, 1}, {0}};
    static svc_daemon d;
    memset(&d, 0, sizeof d);
    svc_config_defaults(&d.cfg);
    rs_err err = {0};
    bool print = false;
    int c, idx;
    /* pass 1: --help, --config */
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "h", opts, &idx)) != -1) {
        if (c == 'h') {
            help();
            return RS_EXIT_OK;
        }
        if (c == '?' || c == ':')
            return cli_usage_error("serve");
        if (c == 'c' && !svc_config_load(&d.cfg, optarg, &err)) {
            cli_error("serve", "%s", err.msg);
            return RS_EXIT_USAGE;
        }
    }
    if (optind < argc) {
        cli_error("serve", "unexpected argument '%s'", argv[optind]);
        return cli_usage_error("serve");
    }
    /* pass 2: the settings, in order */
    optind = 1;
    while ((c = getopt_long(argc, argv, "h", opts, &idx)) != -1) {
        char name[64], value[1100];
        if (c == 'P')
            print = true;
        if (c == 's') { /* --set name=value */
            const char *eq = strchr(optarg, '=');
            if (!eq || eq == optarg || (size_t)(eq - optarg) >= sizeof name) {
                cli_error("serve", "--set '%s': expected NAME=VALUE", optarg);
                return RS_EXIT_USAGE;
            }
            snprintf(name, sizeof name, "%.*s", (int)(eq - optarg), optarg);
            snprintf(value, sizeof value, "%s", eq + 1);
        } else if (c == 1) {
            snprintf(name, sizeof name, "%s", opts[idx].name);
            for (char *p = name; *p; p++)
                if (*p == '-')
                    *p = '_';
            snprintf(value, sizeof value, "%s", optarg);
        } else
            continue;
        if (!svc_config_set(&d.cfg, name, value, &err)) {
            cli_error("serve", "--%s", err.msg);
            return RS_EXIT_USAGE;
        }
    }
    if (!svc_config_finish(&d.cfg, &err)) {
        cli_error("serve", "%s", err.msg);
        return RS_EXIT_USAGE;
    }
    if (print) {
        svc_config_dump(&d.cfg, stdout);
        return RS_EXIT_OK;
    }
    svc_log_level(d.cfg.log_level);
    /* started with stdin/out/err closed, pipes could land on fds 0..2 and
     * be overwritten when a render's stdio is set up: fill them first */
    int nullfd = open("/dev/null", O_RDWR);
    while (nullfd >= 0 && nullfd <= 2)
        nullfd = open("/dev/null", O_RDWR);
    if (nullfd > 2)
        close(nullfd);

    int status = RS_EXIT_FAIL, lock_fd = -1;
    struct MHD_Daemon *http = NULL;
    char work[1100];
    snprintf(work, sizeof work, "%s/work", d.cfg.data);
    if (!mkdir_p(d.cfg.data, &err) || !mkdir_p(work, &err) || !mkdir_p(d.cfg.output, &err))
        goto fail;
    ssize_t n = readlink("/proc/self/exe", d.exe, sizeof d.exe - 1);
    if (n <= 0) {
        rs_fail(&err, 1, "cannot find this program's path (/proc/self/exe) to run the renderer");
        goto fail;
    }
    d.exe[n] = 0;
    rs_err derr = {0};
    const char *root = rs_data_dir(&derr);
    if (root)
        rs_data_path(root, "service/dashboard.html", d.dashboard, sizeof d.dashboard);
    if (!root || access(d.dashboard, R_OK) != 0) {
        svc_log(SVC_LOG_WARN, -1, "the dashboard page (service/dashboard.html) was not found%s%s: GET / shows a note",
                root ? "" : ": ", root ? "" : derr.msg);
        d.dashboard[0] = 0;
    }
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
        if (*db && !rs_mkdirs_for(db, &err))
            goto fail;
        if (*db && (lock_fd = lock_sqlite(db, &err)) < 0)
            goto fail;
    }
    if (!(d.store = svc_store_open(d.cfg.queue, &err)) || !(d.http_store = svc_store_open(d.cfg.queue, &err)))
        goto fail;
    if (sqlite) {
        /* we hold the only lock: every running job belonged to a daemon
         * that is gone */
        int r = d.store->ops->reap(d.store, d.cfg.max_attempts, true, &err);
        if (r < 0)
            goto fail;
        if (r > 0)
            svc_log(SVC_LOG_INFO, -1, "%d interrupted job%s from the last run re-queued", r, r == 1 ? "" : "s");
    }
    pthread_mutex_init(&d.mu, NULL);
    d.live = calloc((size_t)d.cfg.workers, sizeof *d.live);
    if (!d.live) {
        rs_fail(&err, 1, "out of memory");
        goto fail;
    }
    the_daemon = &d;
    struct sigaction sa = {0};
    sa.sa_handler = on_signal;
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    sa.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &sa, NULL); /* a client that hangs up mid-video */
    if (!(http = svc_http_start(&d, &err)))
        goto fail;
    int64_t counts[SVC_NSTATES] = {0};
    d.store->ops->counts(d.store, counts, &err);
    char shown[160];
    snprintf(shown, sizeof shown, "%s", d.cfg.listen);
    char *colon = strrchr(shown, ':');
    if (colon)
        snprintf(colon + 1, sizeof shown - (size_t)(colon + 1 - shown), "%u", d.port);
    svc_log(SVC_LOG_INFO, -1,
            "listening on http://%s/ (queue %s: %lld queued, %lld running; %d worker%s; videos in %s; drawn at %dx%d)",
            shown, d.store->ops->name, (long long)counts[SVC_QUEUED], (long long)counts[SVC_RUNNING], d.cfg.workers,
            d.cfg.workers == 1 ? "" : "s", d.cfg.output, d.cfg.render_width, d.cfg.render_height);
    status = svc_run(&d) == 0 ? RS_EXIT_OK : RS_EXIT_FAIL;
    svc_http_stop(http);
    http = NULL;
    svc_log(SVC_LOG_INFO, -1, "stopped");
    goto out;
fail:
    cli_error("serve", "%s", err.msg);
out:
    svc_http_stop(http);
    if (d.http_store)
        d.http_store->ops->close(d.http_store);
    if (d.store)
        d.store->ops->close(d.store);
    free(d.live);
    the_daemon = NULL;
    if (lock_fd >= 0)
        close(lock_fd);
    return status;
}
