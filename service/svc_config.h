/* svc_config: the daemon's settings, one table of typed, bounded rows
 * (Redis's config.c habit).  A setting comes from its default, then the
 * config file (`name = value` lines, # comments), then the command line;
 * each source is checked against the same row, so a bad value reads
 * "file:line: name: message" or "--name: message". */
#ifndef SVC_CONFIG_H
#define SVC_CONFIG_H

#include <stdbool.h>
#include <stdio.h>

#include "../runtime/util/rs_err.h"

/* Error ids (rs_err.h) of the settings: a value, a config file, or the
 * settings taken together.  The message names the setting and the value. */
#define SVC_CONFIG_ERRORS(X)                                                                  \
    X(NUMBER, "not a whole number")                                                           \
    X(RANGE, "a value outside the setting's bounds")                                          \
    X(BYTES, "not a size in bytes (a number, or one with K or M)")                            \
    X(TEXT, "a text value with '#' or a line break")                                          \
    X(TOO_LONG, "a text value longer than the setting holds")                                 \
    X(EMPTY, "an empty value where one is needed")                                            \
    X(DIMENSIONS, "not a WxH size")                                                           \
    X(CHOICE, "not one of the setting's choices")                                             \
    X(DURATION, "not a duration (seconds, or a number with s, m, h or d)")                   \
    X(ADDRESS, "not address:port")                                                            \
    X(UNKNOWN, "no setting by that name")                                                     \
    X(FILE, "the config file is not text")                                                    \
    X(SYNTAX, "a config file line is not 'name = value'")                                     \
    X(DATA_DEFAULT, "no usable default data directory from the environment")                 \
    X(SIZE_LIMIT, "size is larger than max_size")                                             \
    X(RENDER_SIZE, "size and render_size do not go together")

typedef enum svc_config_error {
    SVC_CONFIG_ERR_BASE = RS_ERR_BASE(RS_ERR_MOD_SVC_CONFIG),
#define X(id, text) SVC_CONFIG_ERR_##id,
    SVC_CONFIG_ERRORS(X)
#undef X
        SVC_CONFIG_ERR_END
} svc_config_error;

const char *svc_config_error_text(int code);

enum { SVC_LOG_DEBUG, SVC_LOG_INFO, SVC_LOG_WARN, SVC_LOG_ERROR };

typedef struct svc_config {
    char listen[128];     /* host:port; loopback unless told otherwise */
    int workers;          /* render processes at once */
    char data[512];       /* queue database, work files, default output */
    char queue[1024];     /* sqlite:PATH or postgres://...; "" = sqlite:<data>/queue.db */
    char output[512];     /* where videos go; "" = <data>/videos */
    char files[16];       /* "queue": units' files kept in the queue's database too (svc_store.h); "local";
                             "auto": queue on PostgreSQL (svc_keep_on) */
    long max_upload;      /* bytes */
    int max_seconds;      /* longest replay accepted (game time) */
    int max_attempts;     /* claims before a job is failed for good */
    int lease;            /* seconds a claim lasts without a heartbeat */
    int watchdog;         /* seconds without progress before a render is killed */
    int grace;            /* seconds running jobs get to finish on SIGTERM */
    int segment_seconds;  /* split a job into segments of this much game time (0: never) */
    int first_segment_seconds; /* the first segment's length, doubling up to segment_seconds (0: all equal) */
    int width, height;    /* a job's output size unless it asks for one */
    int max_width, max_height; /* the largest output a job may ask for */
    int render_width, render_height; /* the size the game is drawn at; 0x0 ("auto"): the job's quality
                                        preset decides it from the job's size */
    char quality[16];     /* a job's quality preset unless it asks (r_quality.h) */
    char format[8];       /* mp4, webm or mkv */
    char backend[16];     /* egl or osmesa */
    int log_level;
    /* the network (docs/service.md, "On a network") */
    char allowed_hosts[512]; /* Host header values accepted ("" = the listen address and localhost names; "*" = any) */
    char cors_origins[512];  /* origins allowed to call the API from a browser ("" = none but our own) */
    int max_connections;     /* connections held at once, all addresses */
    int max_connections_per_ip; /* from one address (0 = no cap, for a daemon behind a proxy) */
    int header_timeout;      /* seconds a connection gets to send a request's headers */
    int min_body_rate;       /* bytes/s an upload must keep up, averaged, after header_timeout */
    long upload_memory;      /* bytes held for uploads in progress, all connections together */
    int token_max_queued;    /* a new token's default: its jobs queued or running at once */
    int token_seconds_per_hour; /* a new token's default: seconds of game time it may submit per hour */
    long retention;          /* seconds a finished job's files are kept (0 = keep) */
    /* the encoder options a job may ask for (svc_encode.c) */
    char codecs[64];         /* comma-separated; "" or "*" = every one the render has */
    int min_crf;             /* the best quality (largest files) a job may ask for */
    int max_bitrate;         /* kbit/s */
    char presets[256];       /* comma-separated; "" or "*" = any the encoder takes */
} svc_config;

void svc_config_defaults(svc_config *c);
/* One setting by name; the message names the value and what was expected. */
bool svc_config_set(svc_config *c, const char *name, const char *value, rs_err *err);
/* A config file; errors read "path:line: ...". */
bool svc_config_load(svc_config *c, const char *path, rs_err *err);
/* A config file's len bytes (need not be NUL-terminated), path for the
 * messages: what svc_config_load does once the file is read. */
bool svc_config_parse(svc_config *c, const char *path, const char *text, size_t len, rs_err *err);
/* Fills the derived defaults (queue, output from data) and checks the
 * settings against each other. */
bool svc_config_finish(svc_config *c, rs_err *err);
/* The table, for --help and docs: name, default, meaning. */
void svc_config_print_table(FILE *f);
/* The settings' names, in the table's order: i = 0.. until NULL (the
 * command line makes an option of each). */
const char *svc_config_name(size_t i);
/* Every setting's current value, one "name = value" line each (a config
 * file that reproduces c). */
void svc_config_dump(const svc_config *c, FILE *f);

#endif
