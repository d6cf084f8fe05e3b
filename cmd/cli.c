#include "cli.h"

#include <ctype.h>
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../runtime/game/g_game.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_quality.h"
#include "../runtime/render/r_stage.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_log.h"
#include "../runtime/util/rs_out.h"
#include "../runtime/util/rs_progress.h"

const char *cli_command;

/* A bad option value: "ringside CMD: message" (just "ringside:" outside a command). */
static void opt_error(const char *fmt, ...) RS_PRINTF(1, 2);
static void opt_error(const char *fmt, ...)
{
    if (!rs_log_on(RS_LOG_ERROR))
        return;
    va_list ap;
    fprintf(stderr, cli_command ? "ringside %s: " : "ringside: ", cli_command);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

static void say(int level, const char *cmd, const char *what, const char *fmt, va_list ap)
{
    if (!rs_log_on(level))
        return;
    fprintf(stderr, "ringside %s: %s", cmd, what);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
}

void cli_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    say(RS_LOG_ERROR, cmd, "", fmt, ap);
    va_end(ap);
}

void cli_warn(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    say(RS_LOG_WARNING, cmd, "warning: ", fmt, ap);
    va_end(ap);
}

void cli_info(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    say(RS_LOG_INFO, cmd, "", fmt, ap);
    va_end(ap);
}

void cli_debug(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    say(RS_LOG_DEBUG, cmd, "", fmt, ap);
    va_end(ap);
}

int cli_usage_error(const char *cmd)
{
    if (rs_log_on(RS_LOG_ERROR))
        fprintf(stderr, "ringside %s: see 'ringside %s --help'\n", cmd, cmd);
    return RS_EXIT_USAGE;
}

bool cli_log_options(int *argc, char **argv)
{
    int out = 1;
    bool ok = true, ended = false;
    for (int i = 1; i < *argc; i++) {
        const char *a = argv[i];
        int level = -1;
        ended |= !strcmp(a, "--"); /* what follows is the command's, as it is */
        if (ended || a[0] != '-') {
            argv[out++] = argv[i];
            continue;
        }
        if (!strcmp(a, "-q") || !strcmp(a, "--quiet"))
            level = RS_LOG_WARNING;
        else if (!strcmp(a, "-v") || !strcmp(a, "--verbose"))
            level = RS_LOG_DEBUG;
        else if (!strcmp(a, "--loglevel") || !strncmp(a, "--loglevel=", 11)) {
            const char *v = a[10] == '=' ? a + 11 : i + 1 < *argc ? argv[++i] : NULL;
            if (!v || !rs_log_parse(v, &level)) {
                fprintf(stderr, "ringside: --loglevel '%s': expected quiet, error, warning, info or debug\n",
                        v ? v : "");
                ok = false;
                continue;
            }
        } else {
            argv[out++] = argv[i];
            continue;
        }
        rs_log_level = level;
        rs_log_explicit = true;
    }
    argv[out] = NULL;
    *argc = out;
    return ok;
}

int cli_bad_option(const char *cmd, char *const *argv)
{
    cli_error(cmd, "bad option or missing value '%s'", argv[optind - 1]);
    return cli_usage_error(cmd);
}

void cli_progress_fd(int fd, uint64_t done, uint64_t total, double *last)
{
    if (fd < 0)
        return;
    double now = rs_now();
    if (done < total && now - *last < 0.25)
        return;
    *last = now;
    dprintf(fd, "frames %" PRIu64 " %" PRIu64 "\n", done, total);
}

bool cli_int(const char *opt, const char *arg, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(arg, &end, 10);
    if (errno || end == arg || *end || v < lo || v > hi) {
        opt_error("%s '%s': expected a whole number from %ld to %ld", opt, arg, lo, hi);
        return false;
    }
    *out = v;
    return true;
}

/* "SS[.s]", "MM:SS[.s]" or "HH:MM:SS[.s]": seconds, or -1 when malformed */
static double clock_seconds(const char *arg)
{
    double total = 0;
    const char *p = arg;
    for (int field = 0; field < 3; field++) {
        char *end;
        if (!isdigit((unsigned char)*p))
            return -1;
        errno = 0;
        double v = strtod(p, &end);
        if (errno || end == p)
            return -1;
        bool frac = memchr(p, '.', (size_t)(end - p)) != NULL;
        if (field > 0 && (v >= 60 || end - p < 2)) /* MM:SS: two digits after a colon, under 60 */
            return -1;
        total = total * 60 + v;
        if (*end == 0)
            return total;
        if (*end != ':' || frac || field == 2)
            return -1;
        p = end + 1;
    }
    return -1;
}

bool cli_time(const char *opt, const char *arg, long *ticks)
{
    double s = arg[0] && !strpbrk(arg, "eExXpP") ? clock_seconds(arg) : -1;
    if (s < 0 || s > CLI_TIME_MAX_S) {
        opt_error("%s '%s': expected seconds (12.5), MM:SS (1:05) or HH:MM:SS (0:01:05.5), up to a week", opt, arg);
        return false;
    }
    *ticks = lround(s * 60);
    return true;
}

bool cli_u64(const char *opt, const char *arg, uint64_t *out)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(arg, &end, 0);
    if (errno || end == arg || *end || arg[0] == '-') {
        opt_error("%s '%s': expected a non-negative whole number", opt, arg);
        return false;
    }
    *out = v;
    return true;
}

/* WxH with each side in min..max. */
static bool size_in(const char *opt, const char *arg, int min, int max, int *w, int *h)
{
    char *x;
    errno = 0;
    long a = strtol(arg, &x, 10), b = 0;
    bool ok = !errno && x != arg && (*x == 'x' || *x == 'X');
    if (ok) {
        char *end;
        b = strtol(x + 1, &end, 10);
        ok = !errno && end != x + 1 && !*end;
    }
    if (!ok || a < min || b < min || a > max || b > max) {
        opt_error("%s '%s': expected WIDTHxHEIGHT, each from %d to %d (e.g. 1280x720)", opt, arg, min, max);
        return false;
    }
    *w = (int)a;
    *h = (int)b;
    return true;
}

bool cli_size(const char *opt, const char *arg, int max, int *w, int *h)
{
    return size_in(opt, arg, 1, max, w, h);
}

bool cli_out_size(const char *opt, const char *arg, int *w, int *h)
{
    return size_in(opt, arg, CLI_SIZE_MIN, R_RENDER_MAX, w, h);
}

const struct r_preset *cli_quality(const char *cmd, const char *arg)
{
    const r_preset *p = r_preset_named(arg);
    if (!p)
        cli_error(cmd, "--quality '%s': expected %s", arg, r_preset_list());
    return p;
}

const char *cli_quality_help(void)
{
    static char text[1024];
    if (!text[0]) {
        size_t n = 0;
        for (int i = 0; i < R_PRESETS && n < sizeof text; i++)
            n += (size_t)snprintf(text + n, sizeof text - n, "                       %-10s %s\n", r_presets[i].name,
                                  r_presets[i].what);
    }
    return text;
}

bool cli_stage(const char *arg, int *stage)
{
    for (int i = 0; i < G_STAGES; i++) {
        char num[8];
        snprintf(num, sizeof num, "%d", i);
        if (!strcmp(arg, g_stages[i].name) || !strcmp(arg, num)) {
            *stage = i;
            return true;
        }
    }
    if (!rs_log_on(RS_LOG_ERROR))
        return false;
    fprintf(stderr, cli_command ? "ringside %s: " : "ringside: ", cli_command);
    fprintf(stderr, "--stage '%s': unknown stage (expected", arg);
    for (int i = 0; i < G_STAGES; i++)
        fprintf(stderr, "%s %d/%s", i ? "," : "", i, g_stages[i].name);
    fprintf(stderr, ")\n");
    return false;
}

int cli_plat_status(const struct rs_err *err)
{
    return err->code == PLAT_ERR_UNKNOWN_BACKEND ? RS_EXIT_USAGE : RS_EXIT_FAIL;
}

bool cli_hdr_format(const char *arg, int *fmt)
{
    if (!strcmp(arg, "rgba16f"))
        *fmt = R_HDR_RGBA16F;
    else if (!strcmp(arg, "r11g11b10f"))
        *fmt = R_HDR_R11G11B10F;
    else {
        opt_error("--hdr-format '%s': expected rgba16f or r11g11b10f", arg);
        return false;
    }
    return true;
}

bool cli_passes(const char *cmd, const char *arg, int *mode)
{
    if (!arg || !strcmp(arg, "summary"))
        *mode = 1;
    else if (!strcmp(arg, "frames"))
        *mode = 2;
    else {
        cli_error(cmd, "--passes='%s': expected summary or frames", arg);
        return false;
    }
    return true;
}

bool cli_out_ok(const char *cmd, const char *path, bool overwrite)
{
    rs_err err = {0};
    if (rs_out_check(path, overwrite, &err))
        return true;
    cli_error(cmd, "%s", err.msg);
    return false;
}

bool cli_pattern_ok(const char *cmd, const char *pattern, uint64_t first, uint64_t end, bool overwrite)
{
    /* the pattern was checked by cap_sink_for: one %d or %0Nd and nothing else */
    for (uint64_t i = first; i < end; i++) {
        char name[1100];
        snprintf(name, sizeof name, pattern, (int)i);
        if (!cli_out_ok(cmd, name, overwrite))
            return false;
    }
    return true;
}

FILE *cli_text_open(const char *cmd, const char *path, bool overwrite)
{
    if (!strcmp(path, "-"))
        return stdout;
    if (!cli_out_ok(cmd, path, overwrite))
        return NULL;
    FILE *f = fopen(path, "w");
    if (!f)
        cli_error(cmd, "%s: cannot create: %s", path, strerror(errno));
    return f;
}

int cli_fclose(FILE *f)
{
    if (f != stdout)
        return fclose(f);
    return fflush(f) != 0 || ferror(f) ? EOF : 0;
}

FILE *cli_bench_open(const char *cmd, const char *path, bool user, bool overwrite)
{
    if (user)
        return cli_text_open(cmd, path, overwrite);
    rs_err err = {0};
    FILE *f = rs_mkdirs_for(path, &err) ? fopen(path, "w") : NULL;
    if (!f)
        cli_error(cmd, "%s: cannot create", path);
    return f;
}

bool cli_text_close(const char *cmd, const char *path, FILE *f)
{
    bool ok = cli_fclose(f) == 0;
    if (!ok)
        cli_error(cmd, "%s: write failed", path);
    return ok;
}

bool cli_progress_mode(const char *cmd, const char *arg, int *mode)
{
    rs_progress_mode m;
    if (!rs_progress_parse(arg, &m)) {
        cli_error(cmd, "--progress '%s': expected tty, plain or off", arg);
        return false;
    }
    *mode = (int)m;
    return true;
}
