/* ringside serve: the replay-to-video daemon (service/, docs/service.md).
 * This file is the command line only: the settings from --config and the
 * options, then svc_serve (service/svc.h) runs the daemon; `serve token`
 * reads the same settings and manages the API tokens of the same queue. */
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "../service/svc.h"
#include "cli.h"
#include "../runtime/util/rs_log.h"

static void help(void)
{
    printf("usage: ringside serve [--config FILE] [--listen ADDR:PORT] [--workers N] [--data DIR]\n"
           "                      [--queue sqlite:PATH|postgres://...] [--output DIR] [--SETTING VALUE ...]\n"
           "                      [--print-config] [-q|-v]\n"
           "       ringside serve token add|list|revoke ...   (API tokens: 'ringside serve token --help')\n"
           "       ringside serve routes                    (the HTTP API's routes, from its route table)\n\n"
           "The replay-to-video service: an HTTP API and dashboard, a durable job queue and\n"
           "worker processes that run 'ringside render'.  Clients upload replays\n"
           "(POST /jobs), watch progress (GET /jobs/ID) and fetch videos (GET /jobs/ID/video);\n"
           "the dashboard is at http://ADDR:PORT/.  docs/service.md has the whole API.\n\n"
           "The queue is SQLite under DATA by default (one daemon per database file);\n"
           "with a PostgreSQL URI any number of daemons on any number of machines share\n"
           "one queue, each with its own directories: what a unit makes is kept in the\n"
           "database too (setting 'files'), so any daemon joins and serves any job.\n"
           "A render that crashes or stalls is retried up to max_attempts; SIGTERM or\n"
           "Ctrl-C stops taking jobs, lets running ones finish for 'grace' seconds,\n"
           "re-queues the rest and exits 0.\n"
           "A job is split into segments (2, 4, 8, 16 s, then segment_seconds: settings\n"
           "first_segment_seconds and segment_seconds) that any free worker of any daemon\n"
           "renders ('ringside render --segment'), then joined ('ringside join'); a daemon\n"
           "that dies loses only the segments it was rendering.  An H.264 or HEVC job is\n"
           "watchable from its first segment on: GET /jobs/N/stream.m3u8 is a live HLS\n"
           "stream of the segments done so far ('ringside render --hls-dir'), which the\n"
           "dashboard plays ('watch live'); GET /jobs/events pushes the job list's changes.\n\n"
           "  --config FILE    settings file: 'name = value' lines, # comments; the options\n"
           "                   below override it\n"
           "  --print-config   print every setting's value after the file and options, and exit\n"
           CLI_LOG_HELP
           "                   (the daemon's log_level; --log-level and the config file win)\n"
           "\nSettings (as --name or --name-with-dashes on the command line):\n");
    svc_config_print_table(stdout);
    printf("\nAPI tokens: 'ringside serve token --help'.  A daemon listening beyond loopback\n"
           "needs at least one (it refuses to start without); on loopback, requests need one\n"
           "as soon as one exists.\n"
           "\nexamples:\n"
           "  ringside serve --data /var/lib/ringside\n"
           "                   one daemon on 127.0.0.1:8080: the dashboard, the API, one worker\n"
           "  ringside serve --config /etc/ringside.conf --print-config\n"
           "                   every setting's value, after the file and the options\n"
           "  ringside serve token add alice --data /var/lib/ringside\n"
           "                   an API token for a client (printed once)\n"
           "\nexit status: 0 after a clean stop (signal), 1 on a start-up failure, 2 on bad usage\n");
}

static void token_help(void)
{
    printf("usage: ringside serve token add NAME [--operator] [--max-queued N] [--seconds-per-hour N] [-q|-v]\n"
           "       ringside serve token list\n"
           "       ringside serve token revoke NAME|ID\n"
           "       (each also takes serve's --config FILE, --data DIR and --queue Q: the queue they act on)\n\n"
           "API tokens for 'ringside serve'.  Clients send one as 'Authorization: Bearer TOKEN'.\n"
           "A token sees and acts on its own jobs only; an operator token on every job.\n"
           "The queue keeps only a token's SHA-256: 'add' prints the token once, and it\n"
           "cannot be shown again.  A revoked token stops working at its next request.\n\n"
           "  --operator             sees, cancels and downloads every job; no quota unless given one\n"
           "  --max-queued N         its jobs queued or running at once (0: no cap;\n"
           "                         default: the setting token_max_queued)\n"
           "  --seconds-per-hour N   game seconds it may submit in any hour (0: no cap;\n"
           "                         default: the setting token_seconds_per_hour)\n"
           CLI_LOG_HELP
           "\nexit status: 0 done, 1 failed (no such token, a name taken, the queue), 2 bad usage\n");
}

/* Every setting is an option twice: --max_upload and --max-upload; the
 * last three are `serve token add`'s own. */
#define SERVE_FIXED 7
static struct option serve_opts[SERVE_FIXED + 2 * 64 + 1];
static char serve_names[64][32];

static bool build_opts(void)
{
    static const struct option fixed[SERVE_FIXED] = {{"config", required_argument, 0, 'c'},
                                                     {"print-config", no_argument, 0, 'P'},
                                                     {"help", no_argument, 0, 'h'},
                                                     {"set", required_argument, 0, 's'},
                                                     {"operator", no_argument, 0, 'o'},
                                                     {"max-queued", required_argument, 0, 'q'},
                                                     {"seconds-per-hour", required_argument, 0, 'p'}};
    memcpy(serve_opts, fixed, sizeof fixed);
    int n = SERVE_FIXED;
    const char *name;
    for (size_t i = 0; (name = svc_config_name(i)); i++) {
        if (i >= 64 || strlen(name) >= sizeof serve_names[0])
            return false; /* the table outgrew this file: a bug, caught by every test */
        serve_opts[n++] = (struct option){name, required_argument, 0, 1};
        if (strchr(name, '_')) {
            snprintf(serve_names[i], sizeof serve_names[i], "%s", name);
            for (char *p = serve_names[i]; *p; p++)
                if (*p == '_')
                    *p = '-';
            serve_opts[n++] = (struct option){serve_names[i], required_argument, 0, 1};
        }
    }
    serve_opts[n] = (struct option){0};
    return true;
}

/* getopt_long's '?' or ':' as one line naming the option. */
static int bad_option(int c, char **argv)
{
    const char *arg = argv[optind - 1];
    if (c == ':')
        cli_error("serve", "option '%s' needs a value", arg);
    else if (!strncmp(arg, "--", 2))
        cli_error("serve", "unknown option '%.*s' (every setting of the table below works as --name VALUE)",
                  (int)strcspn(arg, "="), arg);
    else
        cli_error("serve", "unknown option '%s'", arg);
    return cli_usage_error("serve");
}

/* `serve token add`'s options (-1: not given). */
typedef struct token_args {
    bool is_operator;
    long max_queued, seconds_per_hour;
} token_args;

static bool token_count(const char *opt, const char *v, long *out)
{
    char *end;
    errno = 0;
    *out = strtol(v, &end, 10);
    if (errno || end == v || *end || *out < 0 || *out > 100000000) {
        cli_error("serve", "--%s '%s': expected a count, 0 for no cap", opt, v);
        return false;
    }
    return true;
}

/* The settings from --config, then the options in order; tok: the token
 * subcommand's own options (NULL: serve, which takes none of them).  -1 to
 * go on (the arguments left from argv[optind]), or the exit status. */
static int read_settings(int argc, char **argv, svc_config *cfg, bool *print, token_args *tok)
{
    if (!build_opts()) {
        cli_error("serve", "internal: too many settings for the option table");
        return RS_EXIT_FAIL;
    }
    const struct option *opts = serve_opts;
    svc_config_defaults(cfg);
    rs_err err = {0};
    /* the global --loglevel / -q / -v as the daemon's log_level: a default
     * that --config and --log-level still override */
    if (rs_log_explicit) {
        static const char *const as_setting[] = {"error", "error", "warn", "info", "debug"};
        svc_config_set(cfg, "log_level", as_setting[rs_log_level], &err);
    }
    int c, idx;
    /* pass 1: --help, --config */
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, ":h", opts, &idx)) != -1) {
        if (c == 'h') {
            tok ? token_help() : help();
            return RS_EXIT_OK;
        }
        if (c == '?' || c == ':' || (!tok && (c == 'o' || c == 'q' || c == 'p')))
            return bad_option(c == '?' || c == ':' ? c : '?', argv);
        struct stat st;
        if (c == 'c' && (stat(optarg, &st) != 0 || !S_ISREG(st.st_mode))) {
            /* a missing file is a failure like any other missing input (1);
             * a file that says something wrong is bad usage (2) */
            cli_error("serve", "%s: cannot open the config file: %s", optarg,
                      errno ? strerror(errno) : "not a regular file");
            return RS_EXIT_FAIL;
        }
        if (c == 'c' && !svc_config_load(cfg, optarg, &err)) {
            cli_error("serve", "%s", err.msg);
            return RS_EXIT_USAGE;
        }
    }
    /* pass 2: the settings, in order */
    optind = 1;
    while ((c = getopt_long(argc, argv, ":h", opts, &idx)) != -1) {
        char name[64], value[1100];
        if (c == 'P')
            *print = true;
        if (c == 'o')
            tok->is_operator = true;
        if ((c == 'q' && !token_count("max-queued", optarg, &tok->max_queued)) ||
            (c == 'p' && !token_count("seconds-per-hour", optarg, &tok->seconds_per_hour)))
            return RS_EXIT_USAGE;
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
        if (!svc_config_set(cfg, name, value, &err)) {
            cli_error("serve", "--%s", err.msg);
            return RS_EXIT_USAGE;
        }
    }
    if (!svc_config_finish(cfg, &err)) {
        cli_error("serve", "%s", err.msg);
        return RS_EXIT_USAGE;
    }
    return -1;
}

/* ringside serve token add|list|revoke */
static int cmd_serve_token(int argc, char **argv)
{
    svc_config cfg;
    bool print = false;
    token_args tok = {.max_queued = -1, .seconds_per_hour = -1};
    int rc = read_settings(argc, argv, &cfg, &print, &tok);
    if (rc >= 0)
        return rc;
    int n = argc - optind;
    const char *sub = n > 0 ? argv[optind] : "";
    bool add = !strcmp(sub, "add"), list = !strcmp(sub, "list"), revoke = !strcmp(sub, "revoke");
    if (!add && !list && !revoke) {
        if (n == 0)
            cli_error("serve", "token: which one? add, list or revoke");
        else
            cli_error("serve", "token '%s': expected add, list or revoke", sub);
        return cli_usage_error("serve token");
    }
    if (n != (list ? 1 : 2)) {
        cli_error("serve", list ? "token list takes no argument" : "token %s: expected one NAME%s", sub,
                  revoke ? " or ID" : "");
        return cli_usage_error("serve token");
    }
    if (!add && (tok.is_operator || tok.max_queued >= 0 || tok.seconds_per_hour >= 0)) {
        cli_error("serve", "token %s: --operator, --max-queued and --seconds-per-hour belong to 'token add'", sub);
        return cli_usage_error("serve token");
    }
    /* an operator has no quota unless given one; others get the settings' */
    if (tok.max_queued < 0)
        tok.max_queued = tok.is_operator ? 0 : cfg.token_max_queued;
    if (tok.seconds_per_hour < 0)
        tok.seconds_per_hour = tok.is_operator ? 0 : cfg.token_seconds_per_hour;
    rs_err err = {0};
    bool ok = add    ? svc_token_add(&cfg, argv[optind + 1], tok.is_operator, (int)tok.max_queued,
                                     (int)tok.seconds_per_hour, &err)
              : list ? svc_token_list(&cfg, &err)
                     : svc_token_revoke(&cfg, argv[optind + 1], &err);
    if (!ok) {
        cli_error("serve", "token %s: %s", sub, err.msg);
        return err.code == SVC_TOKEN_USAGE ? RS_EXIT_USAGE : RS_EXIT_FAIL;
    }
    return RS_EXIT_OK;
}

int cmd_serve(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "token"))
        return cmd_serve_token(argc - 1, argv + 1);
    if (argc > 1 && !strcmp(argv[1], "routes")) {
        if (argc > 2) {
            cli_error("serve", "routes takes no argument");
            return cli_usage_error("serve");
        }
        if (svc_routes_print(stdout))
            return RS_EXIT_OK;
        cli_error("serve", "routes: this ringside was built without libmicrohttpd: it has no HTTP API");
        return RS_EXIT_FAIL;
    }
    svc_config cfg;
    bool print = false;
    int rc = read_settings(argc, argv, &cfg, &print, NULL);
    if (rc >= 0)
        return rc;
    if (optind < argc) {
        cli_error("serve", "unexpected argument '%s'", argv[optind]);
        return cli_usage_error("serve");
    }
    rs_err err = {0};
    if (print) {
        svc_config_dump(&cfg, stdout);
        return RS_EXIT_OK;
    }
    if (!svc_serve(&(svc_desc){.config = &cfg}, &err)) {
        cli_error("serve", "%s", err.msg);
        return RS_EXIT_FAIL;
    }
    return RS_EXIT_OK;
}
