/* svc: the replay-to-video daemon's public face, all the command line
 * (cmd/cmd_serve.c) sees of service/.  The settings themselves are the
 * typed table in svc_config.h; everything else (the supervisor, the HTTP
 * threads, the stores, their shared state in svc_local.h) stays inside. */
#ifndef SVC_H
#define SVC_H

#include <stdbool.h>
#include <stdio.h>

#include "../runtime/util/rs_err.h"
#include "svc_config.h"

/* Zero means default for every field. */
typedef struct svc_desc {
    const svc_config *config; /* settings after svc_config_finish; NULL: every default */
    const char *exe;          /* the binary whose `render` the workers run; NULL: this program */
    const char *dashboard;    /* the dashboard page; NULL: service/dashboard.html under the data root */
} svc_desc;

/* Runs the daemon until a signal stops it: creates the data, work and output
 * directories, locks an SQLite queue (one daemon per file) and re-queues the
 * jobs a previous run left running, opens the store handles, installs the
 * signal handlers (SIGTERM/SIGINT drain, a second one stops now; SIGPIPE
 * ignored) and serves HTTP while the supervisor runs the workers.  Returns
 * true after a clean stop; false with err filled when it could not start or
 * the supervisor failed.  One daemon per process. */
bool svc_serve(const svc_desc *desc, rs_err *err);

/* `ringside serve token ...`: API tokens in the queue of cfg (after
 * svc_config_finish), docs/service.md "Tokens".  add prints the new token
 * on stdout (once: only its hash is kept) and a note on stderr; list
 * prints a table of every token, never a token itself; revoke takes a
 * name, or an id.  false with err filled: err->code SVC_TOKEN_USAGE for a
 * bad name (bad usage), anything else a failure. */
#define SVC_TOKEN_USAGE 2
bool svc_token_add(const svc_config *cfg, const char *name, bool is_operator, int max_queued, int seconds_per_hour,
                   rs_err *err);
bool svc_token_list(const svc_config *cfg, rs_err *err);
bool svc_token_revoke(const svc_config *cfg, const char *which, rs_err *err);

/* `ringside serve routes`: the HTTP API's route table, one row a route
 * (method, path, whether it needs a token, whether it takes a body, the
 * query parameters it takes).  False when built without an HTTP server. */
bool svc_routes_print(FILE *out);

#endif
