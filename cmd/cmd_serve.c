/* ringside serve: the replay-to-video daemon (service/, docs/service.md).
 * This file is the command line only: the settings from --config and the
 * options, then svc_serve (service/svc.h) runs the daemon. */
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "../service/svc.h"
#include "cli.h"

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
           "running ones finish for 'grace' seconds, re-queues the rest and exits 0.\n"
           "A job longer than segment_seconds is split into segments that any free worker\n"
           "of any daemon renders ('ringside render --segment'), then joined ('ringside join');\n"
           "a daemon that dies loses only the segments it was rendering.\n\n"
           "  --config FILE    settings file: 'name = value' lines, # comments; the options\n"
           "                   below override it\n"
           "  --print-config   print every setting's value after the file and options, and exit\n"
           "\nSettings (as --name or --name-with-dashes on the command line):\n");
    svc_config_print_table(stdout);
    printf("\nexit status: 0 after a clean stop (signal), 1 on a start-up failure, 2 on bad usage\n");
}

/* Every setting is an option twice: --max_upload and --max-upload. */
#define SERVE_FIXED 4
static struct option serve_opts[SERVE_FIXED + 2 * 64 + 1];
static char serve_names[64][32];

static bool build_opts(void)
{
    static const struct option fixed[SERVE_FIXED] = {{"config", required_argument, 0, 'c'},
                                                     {"print-config", no_argument, 0, 'P'},
                                                     {"help", no_argument, 0, 'h'},
                                                     {"set", required_argument, 0, 's'}};
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

int cmd_serve(int argc, char **argv)
{
    if (!build_opts()) {
        cli_error("serve", "internal: too many settings for the option table");
        return RS_EXIT_FAIL;
    }
    const struct option *opts = serve_opts;
    svc_config cfg;
    svc_config_defaults(&cfg);
    rs_err err = {0};
    bool print = false;
    int c, idx;
    /* pass 1: --help, --config */
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, ":h", opts, &idx)) != -1) {
        if (c == 'h') {
            help();
            return RS_EXIT_OK;
        }
        if (c == '?' || c == ':')
            return bad_option(c, argv);
        struct stat st;
        if (c == 'c' && (stat(optarg, &st) != 0 || !S_ISREG(st.st_mode))) {
            /* a missing file is a failure like any other missing input (1);
             * a file that says something wrong is bad usage (2) */
            cli_error("serve", "%s: cannot open the config file: %s", optarg,
                      errno ? strerror(errno) : "not a regular file");
            return RS_EXIT_FAIL;
        }
        if (c == 'c' && !svc_config_load(&cfg, optarg, &err)) {
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
    while ((c = getopt_long(argc, argv, ":h", opts, &idx)) != -1) {
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
        if (!svc_config_set(&cfg, name, value, &err)) {
            cli_error("serve", "--%s", err.msg);
            return RS_EXIT_USAGE;
        }
    }
    if (!svc_config_finish(&cfg, &err)) {
        cli_error("serve", "%s", err.msg);
        return RS_EXIT_USAGE;
    }
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
