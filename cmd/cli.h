/* Shared pieces of the command-line front end. */
#ifndef CLI_H
#define CLI_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

/* The exit statuses (README, "Exit status"): 0 done; 1 the job failed; 2
 * bad usage (an option, a name that cannot be written, a range past the
 * replay); 3 join only: one or more segments are bad (they are to be
 * rendered again); 4 the program reading -o - closed the pipe early. */
enum { RS_EXIT_OK = 0, RS_EXIT_FAIL = 1, RS_EXIT_USAGE = 2, RS_EXIT_SEGMENT = 3, RS_EXIT_PIPE = 4 };

typedef struct cli_cmd {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} cli_cmd;

/* --progress-fd: "frames DONE TOTAL" on fd for programs (ringside serve),
 * at most 4 lines a second, and always the last; fd < 0: nothing.
 * last: when the previous line went out (start at 0). */
void cli_progress_fd(int fd, uint64_t done, uint64_t total, double *last);
/* Parses "WxH" with 1 <= W,H <= max; prints a usage error naming opt. */
bool cli_size(const char *opt, const char *arg, int max, int *w, int *h);
/* An output size: "WxH" with CLI_SIZE_MIN <= W,H <= R_RENDER_MAX (r_quality.h). */
#define CLI_SIZE_MIN 16
bool cli_out_size(const char *opt, const char *arg, int *w, int *h);
/* --quality NAME: the preset, or NULL after a usage error naming cmd. */
struct r_preset;
const struct r_preset *cli_quality(const char *cmd, const char *arg);
/* The presets for --help: one indented line each, "draft ... \n". */
const char *cli_quality_help(void);
/* Parses a non-negative 64-bit number (decimal or 0x hex). */
bool cli_u64(const char *opt, const char *arg, uint64_t *out);
/* A time: seconds ("12.5"), "MM:SS" or "HH:MM:SS" (fractions on the last
 * field), at most CLI_TIME_MAX_S, as ticks (1/60 s, rounded to the
 * nearest); prints a usage error naming opt. */
#define CLI_TIME_MAX_S (7 * 24 * 3600.0)
bool cli_time(const char *opt, const char *arg, long *ticks);
/* Parses an integer in [lo, hi]; prints a usage error naming opt. */
bool cli_int(const char *opt, const char *arg, long lo, long hi, long *out);
/* "ringside CMD: message" on stderr, at the error level (rs_log.h). */
void cli_error(const char *cmd, const char *fmt, ...);
/* "ringside CMD: warning: message", at the warning level. */
void cli_warn(const char *cmd, const char *fmt, ...);
/* "ringside CMD: message", at the info level: what a command did. */
void cli_info(const char *cmd, const char *fmt, ...);
/* "ringside CMD: message", at the debug level (-v). */
void cli_debug(const char *cmd, const char *fmt, ...);
/* The options every command takes, wherever they stand before "--":
 * --loglevel LEVEL, --loglevel=LEVEL, -q (warning), --quiet, -v (debug),
 * --verbose.  Removes them from argv (argc updated) and sets rs_log_level;
 * false after a usage error (an unknown level). */
bool cli_log_options(int *argc, char **argv);
/* The line every command's --help ends its options with. */
#define CLI_LOG_HELP \
    "  -q, -v, --loglevel LEVEL\n" \
    "                     how much goes to stderr: quiet, error, warning (-q), info\n" \
    "                     (the default) or debug (-v)\n"
/* The command running now ("render"), set by main before it runs one: the
 * option parsers above name it in their messages. */
extern const char *cli_command;
/* Unknown option or missing argument: prints the hint to --help; returns RS_EXIT_USAGE. */
int cli_usage_error(const char *cmd);
/* The tail of every option loop, for getopt_long's '?' (opterr 0, so it
 * printed nothing): names the bad option, prints the hint to --help and
 * returns RS_EXIT_USAGE.  argv: the vector getopt_long was given. */
int cli_bad_option(const char *cmd, char *const *argv);

int cmd_info(int argc, char **argv);
int cmd_smoke(int argc, char **argv);
int cmd_shaders(int argc, char **argv);
int cmd_bench(int argc, char **argv);
int bench_capture(int argc, char **argv);
int bench_accuracy(int argc, char **argv);
int cmd_record(int argc, char **argv);
int cmd_play(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_replay(int argc, char **argv);
int cmd_movie(int argc, char **argv);
int cmd_attract(int argc, char **argv);
int bench_upload(int argc, char **argv);
int bench_encode(int argc, char **argv);
int bench_audio(int argc, char **argv);
int bench_quality(int argc, char **argv);
int cmd_serve(int argc, char **argv);
int cmd_join(int argc, char **argv);

/* Exit status for a failed plat_create: 2 for an unknown backend name. */
struct rs_err;
int cli_plat_status(const struct rs_err *err);

/* "rgba16f" / "r11g11b10f" -> r_hdr_format; prints a usage error. */
bool cli_hdr_format(const char *arg, int *fmt);
/* --passes[=summary|frames]: 1 summary, 2 per frame; prints the error. */
bool cli_passes(const char *cmd, const char *arg, int *mode);

/* Stage by name ("dojo") or number; prints a usage error on failure. */
bool cli_stage(const char *arg, int *stage);

/* Output rules (runtime/util/rs_out.h) for a command's user-named output:
 * prints "ringside CMD: PATH: exists (use -y to overwrite)" or the folder
 * that is missing, and returns false. */
bool cli_out_ok(const char *cmd, const char *path, bool overwrite);
/* A text output option (--hashes, --csv ...): "-" is standard output;
 * anything else is checked by cli_out_ok and created.  NULL after printing
 * the error.  Close with cli_text_close, which reports a failed write. */
FILE *cli_text_open(const char *cmd, const char *path, bool overwrite);
/* An image pattern's outputs: the folder of its names, and every name of
 * frames first..end-1 (any one that exists is refused without overwrite). */
bool cli_pattern_ok(const char *cmd, const char *pattern, uint64_t first, uint64_t end, bool overwrite);
bool cli_text_close(const char *cmd, const char *path, FILE *f);
/* fclose, except that standard output is only flushed: 0 when all went out. */
int cli_fclose(FILE *f);
/* A benchmark's table: its own default name (user false: under out/,
 * created, replaced each run) or one the user gave (cli_text_open). */
FILE *cli_bench_open(const char *cmd, const char *path, bool user, bool overwrite);
/* --progress tty|plain|off; prints a usage error naming the command. */
bool cli_progress_mode(const char *cmd, const char *arg, int *mode);

#endif
