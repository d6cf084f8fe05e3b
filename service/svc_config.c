/* svc_config: the table of settings and its three sources. */
#include "svc_config.h"

#include <ctype.h>
#include <errno.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "../capture/cap.h"
#include "../runtime/util/rs_file.h"

typedef enum { C_INT, C_BYTES, C_STR, C_SIZE, C_CHOICE, C_LISTEN, C_DURATION } c_type;

typedef struct c_row {
    const char *name;
    c_type type;
    size_t off, off2; /* off2: the height of a C_SIZE */
    long lo, hi;      /* C_INT, C_BYTES: value; C_SIZE: each side; C_STR: length */
    const char *def;
    const char *choices; /* C_CHOICE: "a|b|c" (the index is stored, or the text for format/backend) */
    const char *help;
} c_row;

#define OFF(f) offsetof(svc_config, f)
static const c_row rows[] = {
    {"listen", C_LISTEN, OFF(listen), 0, 0, sizeof((svc_config *)0)->listen, "127.0.0.1:8080", NULL,
     "address:port for the HTTP API and dashboard (loopback unless told otherwise)"},
    {"workers", C_INT, OFF(workers), 0, 1, 64, "1", NULL, "render processes running at once"},
    {"data", C_STR, OFF(data), 0, 0, sizeof((svc_config *)0)->data - 64, "", NULL,
     "directory for the queue database, work files and (by default) videos (default: $STATE_DIRECTORY under "
     "systemd, else $XDG_STATE_HOME/ringside, else ~/.local/state/ringside)"},
    {"queue", C_STR, OFF(queue), 0, 0, sizeof((svc_config *)0)->queue - 1, "", NULL,
     "sqlite:PATH or postgres://user@host:port/db (default: sqlite:DATA/queue.db)"},
    {"output", C_STR, OFF(output), 0, 0, sizeof((svc_config *)0)->output - 32, "", NULL,
     "directory for finished videos (default: DATA/videos); with files = queue each machine's own"},
    {"files", C_CHOICE, OFF(files), 0, 0, 0, "auto", "auto|queue|local",
     "where what a job's units made is kept for the other daemons: queue (in the queue's database, so daemons on "
     "machines that share no disk join and serve each other's jobs), local (only in the output directory: one "
     "machine, or an output directory every machine mounts); auto: queue on a PostgreSQL queue, local on SQLite"},
    {"max_upload", C_BYTES, OFF(max_upload), 0, 1024, 64L << 20, "1M", NULL, "largest replay accepted (K and M suffixes)"},
    {"max_seconds", C_INT, OFF(max_seconds), 0, 1, 7 * 24 * 3600, "1800", NULL,
     "longest replay accepted, in seconds of game time (a render takes about as long on a GPU)"},
    {"max_attempts", C_INT, OFF(max_attempts), 0, 1, 100, "3", NULL, "attempts before a job is failed for good"},
    {"lease", C_INT, OFF(lease), 0, 3, 3600, "30", NULL,
     "seconds a claimed job stays claimed without a heartbeat (heartbeats come every lease/6 s)"},
    {"watchdog", C_INT, OFF(watchdog), 0, 5, 86400, "120", NULL,
     "seconds a render may go without progress before it is killed and retried"},
    {"grace", C_INT, OFF(grace), 0, 0, 3600, "30", NULL,
     "seconds running jobs get to finish after SIGTERM before they are re-queued"},
    {"segment_seconds", C_INT, OFF(segment_seconds), 0, 0, 3600, "30", NULL,
     "split a longer job into segments of this many seconds of game time, rendered by any free worker of any "
     "daemon and then joined (0: never split)"},
    {"first_segment_seconds", C_INT, OFF(first_segment_seconds), 0, 0, 3600, "2", NULL,
     "a split job's first segment, in seconds of game time; each next one twice as long, up to segment_seconds, "
     "so a job's first seconds can be watched soon (0, or not below segment_seconds: every segment "
     "segment_seconds long, and a job no longer than one rendered whole)"},
    {"size", C_SIZE, OFF(width), OFF(height), 16, 8192, "640x360", NULL, "a job's video size unless it asks"},
    {"max_size", C_SIZE, OFF(max_width), OFF(max_height), 16, 8192, "1920x1080", NULL,
     "the largest video size a job may ask for"},
    {"render_size", C_SIZE, OFF(render_width), OFF(render_height), 16, 8192, "auto", NULL,
     "the size the game is drawn at before the GPU downscale; auto: the job's quality preset decides it from the "
     "job's size (as render --quality does)"},
    {"quality", C_CHOICE, OFF(quality), 0, 0, 0, "standard", "draft|standard|high|reference",
     "a job's quality preset unless it asks (docs/accuracy.md)"},
    {"format", C_CHOICE, OFF(format), 0, 0, 0, "mp4", "mp4|webm|mkv", "a job's video format unless it asks"},
    {"backend", C_CHOICE, OFF(backend), 0, 0, 0, "egl", "egl|osmesa", "GL backend of the render processes"},
    {"log_level", C_CHOICE, OFF(log_level), 0, 0, 0, "info", "debug|info|warn|error", "least important log line shown"},
    {"allowed_hosts", C_STR, OFF(allowed_hosts), 0, 0, sizeof((svc_config *)0)->allowed_hosts - 1, "", NULL,
     "Host header values accepted, comma-separated (default: the listen address and localhost names; * = any); "
     "others get 421"},
    {"cors_origins", C_STR, OFF(cors_origins), 0, 0, sizeof((svc_config *)0)->cors_origins - 1, "", NULL,
     "origins (scheme://host:port, comma-separated) whose web pages may call the API; default none but the "
     "dashboard's own"},
    {"max_connections", C_INT, OFF(max_connections), 0, 16, 1000000, "16384", NULL,
     "HTTP connections held at once, from all addresses"},
    {"max_connections_per_ip", C_INT, OFF(max_connections_per_ip), 0, 0, 1000000, "256", NULL,
     "HTTP connections from one address (0: no cap, for a daemon behind a reverse proxy)"},
    {"header_timeout", C_INT, OFF(header_timeout), 0, 1, 3600, "10", NULL,
     "seconds a connection gets to send a request's headers (an idle keep-alive connection is closed after it)"},
    {"min_body_rate", C_INT, OFF(min_body_rate), 0, 0, 1 << 30, "1024", NULL,
     "bytes per second an upload must average once header_timeout has passed (0: no minimum)"},
    {"upload_memory", C_BYTES, OFF(upload_memory), 0, 1024, 1L << 40, "64M", NULL,
     "bytes held for uploads in progress, all connections together; over it a new upload gets 503"},
    {"token_max_queued", C_INT, OFF(token_max_queued), 0, 0, 1000000, "20", NULL,
     "a new API token's quota: its jobs queued or running at once (0: no cap)"},
    {"token_seconds_per_hour", C_INT, OFF(token_seconds_per_hour), 0, 0, 100000000, "7200", NULL,
     "a new API token's quota: seconds of game time it may submit per hour (0: no cap)"},
    {"retention", C_DURATION, OFF(retention), 0, 0, 100L * 365 * 86400, "0", NULL,
     "how long a finished job's video and hashes are kept (s, m, h or d suffix; 0: keep them)"},
    {"codecs", C_STR, OFF(codecs), 0, 0, sizeof((svc_config *)0)->codecs - 1, "h264,hevc,vp9,av1", NULL,
     "the codecs a job may ask for, comma-separated (* = all the render has); a job without one gets the "
     "format's default (h264, vp9 for webm)"},
    {"min_crf", C_INT, OFF(min_crf), 0, 1, 63, "15", NULL,
     "the lowest crf (best quality, largest file) a job may ask for"},
    {"max_bitrate", C_INT, OFF(max_bitrate), 0, 10, 1000000, "20000", NULL,
     "the highest average bitrate a job may ask for, in kbit/s"},
    {"presets", C_STR, OFF(presets), 0, 0, sizeof((svc_config *)0)->presets - 1,
     "ultrafast,superfast,veryfast,faster,fast,medium,4..13", NULL,
     "the encoder presets a job may ask for, comma-separated, A..B for numbers (* = any the encoder takes); "
     "the default leaves out the slow ones"},
};
#define NROWS (sizeof rows / sizeof rows[0])

static const c_row *find(const char *name)
{
    for (size_t i = 0; i < NROWS; i++)
        if (!strcmp(rows[i].name, name))
            return &rows[i];
    return NULL;
}

/* strtol with the whole string consumed and no overflow */
static bool parse_long(const char *s, long *out, const char **rest)
{
    if (!*s || isspace((unsigned char)*s))
        return false;
    errno = 0;
    char *end;
    long v = strtol(s, &end, 10);
    if (errno || end == s)
        return false;
    *out = v;
    *rest = end;
    return true;
}

static bool set_row(svc_config *c, const c_row *r, const char *v, rs_err *err)
{
    char *base = (char *)c;
    const char *rest;
    long n;
    switch (r->type) {
    case C_INT:
        if (!parse_long(v, &n, &rest) || *rest)
            return rs_fail(err, SVC_CONFIG_ERR_NUMBER, "%s: '%s' is not a whole number", r->name, v);
        if (n < r->lo || n > r->hi)
            return rs_fail(err, SVC_CONFIG_ERR_RANGE, "%s: %ld is out of range (expected %ld..%ld)", r->name, n, r->lo,
                           r->hi);
        *(int *)(base + r->off) = (int)n;
        return true;
    case C_BYTES: {
        if (!parse_long(v, &n, &rest))
            return rs_fail(err, SVC_CONFIG_ERR_BYTES,
                           "%s: '%s' is not a size (expected bytes, or a number with K or M)", r->name, v);
        long mul = 1;
        if (*rest == 'K' || *rest == 'k')
            mul = 1024, rest++;
        else if (*rest == 'M' || *rest == 'm')
            mul = 1024 * 1024, rest++;
        if (*rest || n < 0 || n > r->hi / mul || n * mul < r->lo)
            return rs_fail(err, SVC_CONFIG_ERR_RANGE, "%s: '%s' is out of range (expected %ldK..%ldM)", r->name, v,
                           r->lo / 1024, r->hi >> 20);
        *(long *)(base + r->off) = n * mul;
        return true;
    }
    case C_STR:
        /* the dump must reload as the same value: no comment marks or
         * line breaks, which a config file could not hold */
        if (strpbrk(v, "#\r\n"))
            return rs_fail(err, SVC_CONFIG_ERR_TEXT, "%s: '#' and line breaks are not allowed in values", r->name);
        if (strlen(v) > (size_t)r->hi)
            return rs_fail(err, SVC_CONFIG_ERR_TOO_LONG, "%s: longer than %ld characters", r->name, r->hi);
        if (r->lo && !*v)
            return rs_fail(err, SVC_CONFIG_ERR_EMPTY, "%s: must not be empty", r->name);
        snprintf(base + r->off, (size_t)r->hi + 1, "%s", v);
        return true;
    case C_SIZE: {
        long w, h;
        if (r->off == OFF(render_width) && !strcmp(v, "auto")) {
            *(int *)(base + r->off) = *(int *)(base + r->off2) = 0;
            return true;
        }
        if (!parse_long(v, &w, &rest) || (*rest != 'x' && *rest != 'X') || !parse_long(rest + 1, &h, &rest) || *rest)
            return rs_fail(err, SVC_CONFIG_ERR_DIMENSIONS, "%s: '%s' is not a size (expected WxH, such as 640x360)",
                           r->name, v);
        if (w < r->lo || h < r->lo || w > r->hi || h > r->hi || (w | h) & 1)
            return rs_fail(err, SVC_CONFIG_ERR_RANGE, "%s: %ldx%ld: each side must be even and %ld..%ld", r->name, w, h,
                           r->lo, r->hi);
        *(int *)(base + r->off) = (int)w;
        *(int *)(base + r->off2) = (int)h;
        return true;
    }
    case C_CHOICE: {
        size_t len = strlen(v);
        int idx = 0;
        for (const char *p = r->choices; *p; idx++) {
            const char *bar = strchr(p, '|');
            size_t k = bar ? (size_t)(bar - p) : strlen(p);
            if (k == len && !strncmp(p, v, k)) {
                if (r->off == OFF(log_level))
                    *(int *)(base + r->off) = idx;
                else
                    snprintf(base + r->off, 16 > len + 1 ? len + 1 : 16, "%s", v);
                return true;
            }
            p += k + (bar != NULL);
        }
        return rs_fail(err, SVC_CONFIG_ERR_CHOICE, "%s: '%s' is not one of %s", r->name, v, r->choices);
    }
    case C_DURATION: {
        if (!parse_long(v, &n, &rest))
            return rs_fail(err, SVC_CONFIG_ERR_DURATION,
                           "%s: '%s' is not a duration (expected seconds, or a number with s, m, h or d)", r->name, v);
        long mul = *rest == 'd' ? 86400 : *rest == 'h' ? 3600 : *rest == 'm' ? 60 : 1;
        if (*rest && strchr("smhd", *rest))
            rest++;
        if (*rest || n < 0 || n > r->hi / mul)
            return rs_fail(err, SVC_CONFIG_ERR_RANGE, "%s: '%s' is out of range (expected 0..%ldd)", r->name, v,
                           r->hi / 86400);
        *(long *)(base + r->off) = n * mul;
        return true;
    }
    case C_LISTEN: {
        const char *colon = strrchr(v, ':');
        if (!colon || colon == v || strlen(v) >= (size_t)r->hi || strpbrk(v, "#\r\n "))
            return rs_fail(err, SVC_CONFIG_ERR_ADDRESS, "%s: '%s' is not address:port (such as 127.0.0.1:8080)",
                           r->name, v);
        /* an IPv6 host goes in brackets, or "::1" would read as ":" port 1 */
        if (v[0] == '[' ? colon[-1] != ']' : memchr(v, ':', (size_t)(colon - v)) != NULL)
            return rs_fail(err, SVC_CONFIG_ERR_ADDRESS,
                           "%s: '%s' is not address:port; an IPv6 address goes in brackets, such as [::1]:8080",
                           r->name, v);
        if (!parse_long(colon + 1, &n, &rest) || *rest || n < 0 || n > 65535)
            return rs_fail(err, SVC_CONFIG_ERR_ADDRESS, "%s: '%s': the port must be 0..65535", r->name, v);
        snprintf(base + r->off, (size_t)r->hi, "%s", v);
        return true;
    }
    }
    return false;
}

const char *svc_config_error_text(int code)
{
    static const char *const text[] = {
#define X(id, t) t,
        SVC_CONFIG_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_SVC_CONFIG, text, (int)(sizeof text / sizeof text[0]));
}

void svc_config_defaults(svc_config *c)
{
    memset(c, 0, sizeof *c);
    for (size_t i = 0; i < NROWS; i++)
        if (!set_row(c, &rows[i], rows[i].def, NULL))
            abort(); /* a default outside its own bounds is a bug here */
}

bool svc_config_set(svc_config *c, const char *name, const char *value, rs_err *err)
{
    const c_row *r = find(name);
    if (!r) {
        char known[1024] = "";
        for (size_t i = 0; i < NROWS; i++)
            snprintf(known + strlen(known), sizeof known - strlen(known), "%s%s", i ? ", " : "", rows[i].name);
        return rs_fail(err, SVC_CONFIG_ERR_UNKNOWN, "unknown setting '%s' (known: %s)", name, known);
    }
    return set_row(c, r, value, err);
}

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    char *e = s + strlen(s);
    while (e > s && isspace((unsigned char)e[-1]))
        *--e = 0;
    return s;
}

bool svc_config_parse(svc_config *c, const char *path, const char *text, size_t len, rs_err *err)
{
    if (memchr(text, 0, len))
        return rs_fail(err, SVC_CONFIG_ERR_FILE, "%s: contains a NUL byte (not a text file)", path);
    char *copy = malloc(len + 1); /* lines are cut and trimmed in place */
    if (!copy)
        return rs_fail(err, RS_FILE_ERR_READ, "%s: out of memory", path); /* as rs_read_file says it */
    memcpy(copy, text, len);
    copy[len] = 0;
    bool ok = true;
    int line = 0;
    /* strtok_r would skip empty lines and so miscount; walk by hand */
    for (char *p = copy; p && ok;) {
        char *nl = strchr(p, '\n');
        if (nl)
            *nl = 0;
        line++;
        char *s = p;
        p = nl ? nl + 1 : NULL;
        char *hash = strchr(s, '#');
        if (hash)
            *hash = 0;
        s = trim(s);
        if (!*s)
            continue;
        char *eq = strchr(s, '=');
        if (!eq) {
            ok = rs_fail(err, SVC_CONFIG_ERR_SYNTAX, "%s:%d: expected 'name = value', got '%s'", path, line, s);
            break;
        }
        *eq = 0;
        char *name = trim(s), *value = trim(eq + 1);
        if (!svc_config_set(c, name, value, err)) {
            rs_err_prefix(err, "%s:%d", path, line);
            ok = false;
        }
    }
    free(copy);
    return ok;
}

bool svc_config_load(svc_config *c, const char *path, rs_err *err)
{
    size_t len;
    char *text = rs_read_file(path, 1 << 20, &len, err);
    if (!text)
        return false;
    bool ok = svc_config_parse(c, path, text, len, err);
    free(text);
    return ok;
}

/* DESIGN: the data directory is state, so its default is where state goes:
 * systemd's StateDirectory= (STATE_DIRECTORY; a colon-separated list when
 * the unit names several: ours is the first), else the XDG base directory
 * spec's XDG_STATE_HOME (ignored unless absolute, as the spec says), else
 * its default ~/.local/state.  Never the current directory: a daemon's
 * queue must not depend on where it was started from. */
static bool default_data(svc_config *c, rs_err *err)
{
    const char *v = getenv("STATE_DIRECTORY");
    size_t max = sizeof c->data - 64;
    int n;
    if (v && *v)
        n = snprintf(c->data, max + 1, "%.*s", (int)strcspn(v, ":"), v);
    else if ((v = getenv("XDG_STATE_HOME")) && v[0] == '/')
        n = snprintf(c->data, max + 1, "%s/ringside", v);
    else if ((v = getenv("HOME")) && v[0] == '/')
        n = snprintf(c->data, max + 1, "%s/.local/state/ringside", v);
    else
        return rs_fail(err, SVC_CONFIG_ERR_DATA_DEFAULT,
                       "data: no default (neither STATE_DIRECTORY, XDG_STATE_HOME nor HOME is set); "
                       "give --data DIR");
    if (n < 0 || (size_t)n > max)
        return rs_fail(err, SVC_CONFIG_ERR_DATA_DEFAULT,
                       "data: the default from the environment is longer than %zu characters", max);
    return true;
}

bool svc_config_finish(svc_config *c, rs_err *err)
{
    if (!c->data[0] && !default_data(c, err))
        return false;
    if (!c->queue[0])
        snprintf(c->queue, sizeof c->queue, "sqlite:%s/queue.db", c->data);
    if (!c->output[0])
        snprintf(c->output, sizeof c->output, "%s/videos", c->data);
    if (c->width > c->max_width || c->height > c->max_height)
        return rs_fail(err, SVC_CONFIG_ERR_SIZE_LIMIT, "size %dx%d is larger than max_size %dx%d", c->width, c->height,
                       c->max_width, c->max_height);
    rs_err serr = {0};
    if (c->render_width && !cap_check_sizes_for(CAP_I420, c->render_width, c->render_height, c->width, c->height, &serr))
        return rs_fail(err, SVC_CONFIG_ERR_RENDER_SIZE, "size %dx%d with render_size %dx%d: %s", c->width, c->height,
                       c->render_width, c->render_height, serr.msg);
    return true;
}

void svc_config_print_table(FILE *f)
{
    for (size_t i = 0; i < NROWS; i++)
        fprintf(f, "  %-23s %-16s %s\n", rows[i].name, rows[i].def[0] ? rows[i].def : "(see text)", rows[i].help);
}

const char *svc_config_name(size_t i)
{
    return i < NROWS ? rows[i].name : NULL;
}

void svc_config_dump(const svc_config *c, FILE *f)
{
    static const char *const levels[] = {"debug", "info", "warn", "error"};
    const char *base = (const char *)c;
    for (size_t i = 0; i < NROWS; i++) {
        const c_row *r = &rows[i];
        fprintf(f, "%s = ", r->name);
        switch (r->type) {
        case C_INT:
            fprintf(f, "%d\n", *(const int *)(base + r->off));
            break;
        case C_BYTES:
        case C_DURATION:
            fprintf(f, "%ld\n", *(const long *)(base + r->off));
            break;
        case C_SIZE:
            if (!*(const int *)(base + r->off))
                fprintf(f, "auto\n");
            else
                fprintf(f, "%dx%d\n", *(const int *)(base + r->off), *(const int *)(base + r->off2));
            break;
        case C_CHOICE:
            if (r->off == OFF(log_level))
                fprintf(f, "%s\n", levels[c->log_level & 3]);
            else
                fprintf(f, "%s\n", base + r->off);
            break;
        case C_STR:
        case C_LISTEN:
            fprintf(f, "%s\n", base + r->off);
            break;
        }
    }
}
