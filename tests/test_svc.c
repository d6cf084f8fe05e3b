/* service: the daemon's pure logic, no socket and no database: the settings
 * table (svc_config), the JSON writer (svc_json), HTTP Range parsing and the
 * upload check (svc_http.c's plain functions).  The store has its own file,
 * tests/test_svc_store.c; the running daemon is tests/service/.
 *   build/tests/test_svc [config_|json_|range_|upload_|NAME...] */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/game/g_game.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_hash.h"
#include "../runtime/util/rs_img.h"
#include "../service/svc_auth.h"
#include "../service/svc_config.h"
#include "../service/svc_encode.h"
#include "../service/svc_json.h"
#include "../service/svc_local.h"
#include "../service/svc_upload.h"
#include "../service/svc_wire.h"
#if defined(RS_HAVE_MHD)
#include "../service/svc_http_local.h"
#endif
#include "t.h"

/* Fixed-seed xorshift64*: a failing random case fails the same way each run. */
static uint64_t rng = 0x9e3779b97f4a7c15ull;
static uint32_t rnd(void)
{
    rng ^= rng >> 12, rng ^= rng << 25, rng ^= rng >> 27;
    return (uint32_t)((rng * 0x2545f4914f6cdd1dull) >> 32);
}

/* --- svc_config --- */

/* data's default: systemd's state directory, else XDG's, else ~/.local/state;
 * never the current directory */
static void t_config_data_default(void)
{
    static const char *const vars[] = {"STATE_DIRECTORY", "XDG_STATE_HOME", "HOME"};
    char *saved[3];
    for (int i = 0; i < 3; i++) {
        const char *v = getenv(vars[i]);
        saved[i] = v ? strdup(v) : NULL;
    }
    svc_config c;
    rs_err err = {0};
    setenv("STATE_DIRECTORY", "/var/lib/ringside:/var/lib/other", 1);
    setenv("XDG_STATE_HOME", "/x/state", 1);
    setenv("HOME", "/home/u", 1);
    svc_config_defaults(&c);
    T_ASSERT(svc_config_finish(&c, &err));
    T_ASSERTF(!strcmp(c.data, "/var/lib/ringside"), "%s", c.data);
    T_ASSERTF(!strcmp(c.queue, "sqlite:/var/lib/ringside/queue.db"), "%s", c.queue);
    T_ASSERTF(!strcmp(c.output, "/var/lib/ringside/videos"), "%s", c.output);
    /* files: auto keeps them in a PostgreSQL queue (machines share no disk), not in SQLite's */
    T_ASSERTF(!strcmp(c.files, "auto") && !svc_keep_on(&c), "%s", c.files);
    svc_config_defaults(&c);
    T_ASSERT(svc_config_set(&c, "queue", "postgres://u@h:5432/q", &err) && svc_config_finish(&c, &err));
    T_ASSERT(svc_keep_on(&c));
    svc_config_defaults(&c);
    T_ASSERT(svc_config_set(&c, "queue", "postgres://u@h:5432/q", &err) && svc_config_set(&c, "files", "local", &err) &&
             svc_config_finish(&c, &err));
    T_ASSERT(!svc_keep_on(&c));
    svc_config_defaults(&c);
    T_ASSERT(svc_config_set(&c, "files", "queue", &err) && svc_config_finish(&c, &err) && svc_keep_on(&c));
    T_ASSERT(!svc_config_set(&c, "files", "nfs", &err) && strstr(err.msg, "auto|queue|local"));
    unsetenv("STATE_DIRECTORY");
    svc_config_defaults(&c);
    T_ASSERT(svc_config_finish(&c, &err));
    T_ASSERTF(!strcmp(c.data, "/x/state/ringside"), "%s", c.data);
    setenv("XDG_STATE_HOME", "relative", 1); /* the spec: a relative path is ignored */
    svc_config_defaults(&c);
    T_ASSERT(svc_config_finish(&c, &err));
    T_ASSERTF(!strcmp(c.data, "/home/u/.local/state/ringside"), "%s", c.data);
    unsetenv("XDG_STATE_HOME");
    unsetenv("HOME");
    svc_config_defaults(&c);
    T_ASSERT(!svc_config_finish(&c, &err) && strstr(err.msg, "give --data DIR"));
    /* --data wins over all of them */
    svc_config_defaults(&c);
    T_ASSERT(svc_config_set(&c, "data", "mine", &err) && svc_config_finish(&c, &err));
    T_ASSERTF(!strcmp(c.data, "mine"), "%s", c.data);
    for (int i = 0; i < 3; i++) {
        if (saved[i])
            setenv(vars[i], saved[i], 1);
        else
            unsetenv(vars[i]);
        free(saved[i]);
    }
}

static void t_config_defaults(void)
{
    svc_config c;
    svc_config_defaults(&c);
    T_ASSERT(!strcmp(c.listen, "127.0.0.1:8080")); /* loopback unless told otherwise */
    T_ASSERT(!c.data[0] && !c.queue[0] && !c.output[0]); /* svc_config_finish derives */
    T_ASSERT(!strcmp(c.format, "mp4") && !strcmp(c.backend, "egl"));
    T_ASSERT(c.workers == 1 && c.max_upload == 1 << 20 && c.max_attempts == 3);
    T_ASSERT(c.lease == 30 && c.watchdog == 120 && c.grace == 30);
    T_ASSERT(c.width == 640 && c.height == 360 && c.max_width == 1920 && c.max_height == 1080);
    T_EQ(c.segment_seconds, 30);
    T_ASSERT(c.render_width == 0 && c.render_height == 0); /* auto: the job's quality decides */
    T_ASSERT(!strcmp(c.quality, "standard"));
    T_EQ(c.log_level, SVC_LOG_INFO);
}

/* A value, and what must come of it: the line svc_config_dump then writes
 * (ok), or words of the refusal. */
typedef struct set_case {
    const char *name, *value;
    bool ok;
    const char *want;
} set_case;

static const set_case set_cases[] = {
    {"workers", "1", 1, "workers = 1"}, {"workers", "64", 1, "workers = 64"},
    {"grace", "0", 1, "grace = 0"}, {"watchdog", "86400", 1, "watchdog = 86400"},
    {"segment_seconds", "0", 1, "segment_seconds = 0"}, {"segment_seconds", "3600", 1, "segment_seconds = 3600"},
    {"segment_seconds", "-1", 0, "segment_seconds: -1 is out of range (expected 0..3600)"},
    {"workers", "0", 0, "workers: 0 is out of range (expected 1..64)"},
    {"workers", "65", 0, "workers: 65 is out of range (expected 1..64)"},
    {"workers", "4294967297", 0, "out of range"}, /* wraps to 1 if narrowed before the check */
    {"lease", "2", 0, "lease: 2 is out of range (expected 3..3600)"}, {"max_attempts", "-1", 0, "expected 1..100"},
    {"workers", "abc", 0, "workers: 'abc' is not a whole number"}, {"workers", "3x", 0, "'3x' is not a whole number"},
    {"workers", "", 0, "'' is not a whole number"}, {"workers", " 3", 0, "is not a whole number"},
    {"workers", "4.0", 0, "is not a whole number"}, {"workers", "99999999999999999999", 0, "is not a whole number"},
    {"max_upload", "2048", 1, "max_upload = 2048"}, {"max_upload", "1K", 1, "max_upload = 1024"},
    {"max_upload", "4k", 1, "max_upload = 4096"}, {"max_upload", "2m", 1, "max_upload = 2097152"},
    {"max_upload", "64M", 1, "max_upload = 67108864"},
    {"max_upload", "65M", 0, "max_upload: '65M' is out of range (expected 1K..64M)"},
    {"max_upload", "1023", 0, "out of range"}, {"max_upload", "0", 0, "out of range"},
    {"max_upload", "-1K", 0, "out of range"}, {"max_upload", "1G", 0, "out of range"},
    {"max_upload", "1KB", 0, "out of range"},
    {"max_upload", "9007199254740993K", 0, "out of range"}, /* n * K would overflow */
    {"max_upload", "K", 0, "max_upload: 'K' is not a size (expected bytes, or a number with K or M)"},
    {"max_upload", "99999999999999999999M", 0, "is not a size"}, {"queue", "", 1, "queue = "},
    {"queue", "postgres://u@db:5432/ring", 1, "queue = postgres://u@db:5432/ring"},
    {"data", "", 1, "data = "} /* the default: svc_config_finish picks it */, {"size", "800x600", 1, "size = 800x600"},
    {"max_size", "8192X16", 1, "max_size = 8192x16"},
    {"size", "641x360", 0, "size: 641x360: each side must be even and 16..8192"},
    {"size", "640x361", 0, "must be even"},
    {"size", "14x360", 0, "size: 14x360: each side must be even and 16..8192"},
    {"render_size", "8194x720", 0, "render_size: 8194x720: each side"},
    {"size", "-2x4", 0, "size: -2x4: each side must be even and 16..8192"},
    {"size", "640", 0, "size: '640' is not a size (expected WxH, such as 640x360)"},
    {"size", "x360", 0, "'x360' is not a size"}, {"size", "640x360x2", 0, "'640x360x2' is not a size"},
    {"size", "640x", 0, "is not a size"}, {"size", "640*360", 0, "is not a size"},
    {"size", " 640x360", 0, "is not a size"}, {"size", "640x 360", 0, "is not a size"},
    {"size", "", 0, "is not a size"}, {"size", "99999999999999999999x2", 0, "is not a size"},
    {"format", "webm", 1, "format = webm"}, {"format", "mkv", 1, "format = mkv"},
    {"backend", "osmesa", 1, "backend = osmesa"}, {"log_level", "debug", 1, "log_level = debug"},
    {"log_level", "error", 1, "log_level = error"}, {"format", "MP4", 0, "format: 'MP4' is not one of mp4|webm|mkv"},
    {"format", "mp", 0, "is not one of"},   /* a prefix of a choice */
    {"format", "mp4x", 0, "is not one of"}, /* a choice as a prefix */
    {"format", "mp4|webm", 0, "is not one of"}, {"format", "", 0, "is not one of"},
    {"log_level", "verbose", 0, "log_level: 'verbose' is not one of debug|info|warn|error"},
    {"listen", "0.0.0.0:0", 1, "listen = 0.0.0.0:0"}, {"listen", "localhost:65535", 1, "listen = localhost:65535"},
    {"listen", "[::1]:8080", 1, "listen = [::1]:8080"},
    {"listen", "127.0.0.1", 0, "listen: '127.0.0.1' is not address:port (such as 127.0.0.1:8080)"},
    {"listen", ":8080", 0, "is not address:port"}, {"listen", "", 0, "is not address:port"},
    {"listen", "host:70000", 0, "listen: 'host:70000': the port must be 0..65535"},
    {"listen", "host:", 0, "the port must be 0..65535"}, {"listen", "host:-1", 0, "the port must be 0..65535"},
    {"listen", "host:80x", 0, "the port must be 0..65535"}, {"listen", "[::1]", 0, "an IPv6 address goes in brackets"},
    {"workerz", "1", 0, "unknown setting 'workerz' (known: listen, workers, data, queue, output, files, max_upload, "
                        "max_seconds, max_attempts, lease, watchdog, grace, segment_seconds, first_segment_seconds, size, max_size, render_size, quality, format, backend, log_level, allowed_hosts, cors_origins, "
                        "max_connections, max_connections_per_ip, header_timeout, min_body_rate, upload_memory, "
                        "token_max_queued, token_seconds_per_hour, retention, codecs, min_crf, max_bitrate, presets)"},
    {"", "1", 0, "unknown setting ''"},
    {"retention", "0", 1, "retention = 0"}, {"retention", "90", 1, "retention = 90"},
    {"retention", "90s", 1, "retention = 90"}, {"retention", "15m", 1, "retention = 900"},
    {"retention", "2h", 1, "retention = 7200"}, {"retention", "7d", 1, "retention = 604800"},
    {"retention", "36500d", 1, "retention = 3153600000"},
    {"retention", "36501d", 0, "retention: '36501d' is out of range (expected 0..36500d)"},
    {"retention", "-1", 0, "out of range"}, {"retention", "1w", 0, "out of range"},
    {"retention", "1dd", 0, "out of range"}, {"retention", "d", 0, "retention: 'd' is not a duration"},
    {"retention", "99999999999999999999", 0, "is not a duration"},
    {"upload_memory", "1G", 0, "out of range"}, {"upload_memory", "1024M", 1, "upload_memory = 1073741824"},
    {"max_connections_per_ip", "0", 1, "max_connections_per_ip = 0"},
    {"max_connections", "15", 0, "max_connections: 15 is out of range (expected 16..1000000)"},
    {"allowed_hosts", "ring.example,localhost", 1, "allowed_hosts = ring.example,localhost"},
};

static void set_check(const set_case *k)
{
    svc_config c, before;
    svc_config_defaults(&c);
    before = c;
    rs_err e = {0};
    bool ok = svc_config_set(&c, k->name, k->value, &e);
    T_ASSERTF(ok == k->ok, "%s = '%s': %s", k->name, k->value, ok ? "accepted" : e.msg);
    if (!ok) {
        T_ASSERT(e.code != 0);
        T_CONTAINS(e.msg, k->want);
        /* a bad flag must not half-apply */
        T_ASSERTF(!memcmp(&c, &before, sizeof c), "%s = '%s' changed the config", k->name, k->value);
        return;
    }
    char *text = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&text, &n);
    T_ASSERT(f);
    fputc('\n', f);
    svc_config_dump(&c, f);
    T_ASSERT(fclose(f) == 0);
    char want[1200];
    snprintf(want, sizeof want, "\n%s\n", k->want);
    T_CONTAINS(text, want);
    free(text);
}

static void t_config_set(void)
{
    for (size_t i = 0; i < sizeof set_cases / sizeof *set_cases; i++)
        set_check(&set_cases[i]);
}

/* Each string row at its length limit, and one character past it. */
static void t_config_lengths(void)
{
    static const struct {
        const char *name, *why;
        size_t max;
    } rows[] = {{"data", "data: longer than 448 characters", 448}, /* leaves room for "/queue.db" */
                {"output", "output: longer than 480", 480}, {"queue", "queue: longer than 1023", 1023},
                {"listen", "is not address:port", 127}};
    char v[1100], want[1200];
    for (size_t i = 0; i < sizeof rows / sizeof *rows; i++)
        for (size_t len = rows[i].max; len <= rows[i].max + 1; len++) {
            memset(v, 'a', len), v[len] = 0;
            memcpy(v + len - 5, ":8080", 5); /* listen's port; plain text to the others */
            snprintf(want, sizeof want, "%s = %s", rows[i].name, v);
            set_case k = {rows[i].name, v, len == rows[i].max, len == rows[i].max ? want : rows[i].why};
            set_check(&k);
        }
}

/* An IPv6 address must be bracketed: "::1" would otherwise be read as host
 * ":" and port 1, and only fail at bind time with a resolver message. */
static void t_config_listen_bare_ipv6(void)
{
    set_case k = {"listen", "::1", 0, "listen: '::1'"};
    set_check(&k);
}

static const char *tmp_path(const char *name)
{
    static char p[512];
    snprintf(p, sizeof p, "%s/%s", t_tmpdir(), name);
    return p;
}

static void t_config_load_good(void)
{
    t_write(t_tmpdir(), "good.conf",
            "# ringside serve\n\n   workers=4   \n"
            "\tsize = 1280x720  # trailing comment\r\n"
            "queue = postgres://u@db/ring?sslmode=require\n" /* '=' inside a value */
            "   # indented comment\nformat\t=\twebm\n"
            "log_level = warn"); /* no final newline */
    svc_config c;
    svc_config_defaults(&c);
    rs_err e = {0};
    T_ASSERTF(svc_config_load(&c, tmp_path("good.conf"), &e), "%s", e.msg);
    T_EQ(c.workers, 4);
    T_ASSERT(c.width == 1280 && c.height == 720);
    T_ASSERT(!strcmp(c.queue, "postgres://u@db/ring?sslmode=require") && !strcmp(c.format, "webm"));
    T_EQ(c.log_level, SVC_LOG_WARN);
    T_EQ(c.lease, 30); /* what the file does not name keeps its default */
    t_write(t_tmpdir(), "empty.conf", "");
    T_ASSERTF(svc_config_load(&c, tmp_path("empty.conf"), &e), "%s", e.msg);
}

/* The whole message, with the path and the line it names. */
static void load_bad(const char *text, size_t n, const char *after_path)
{
    const char *path = tmp_path("bad.conf");
    FILE *f = fopen(path, "wb");
    T_ASSERT(f && fwrite(text, 1, n, f) == n && fclose(f) == 0);
    svc_config c;
    svc_config_defaults(&c);
    rs_err e = {0};
    T_ASSERTF(!svc_config_load(&c, path, &e), "accepted: %s", text);
    char want[1024];
    snprintf(want, sizeof want, "%s%s", path, after_path);
    T_ASSERTF(!strcmp(e.msg, want), "got \"%s\", want \"%s\"", e.msg, want);
}
#define LOAD_BAD(text, want) load_bad(text, sizeof text - 1, want)

static void t_config_load_errors(void)
{
    LOAD_BAD("# c\n\nworkers = 0\n", ":3: workers: 0 is out of range (expected 1..64)");
    LOAD_BAD("workers = 2\ngarbage here\n", ":2: expected 'name = value', got 'garbage here'");
    LOAD_BAD("\n\n\n\nnope = 1\n", ":5: unknown setting 'nope' (known: listen, workers, data, queue, output, files, "
                                   "max_upload, max_seconds, max_attempts, lease, watchdog, grace, segment_seconds, first_segment_seconds, size, max_size, render_size, quality, "
                                   "format, backend, log_level, allowed_hosts, cors_origins, max_connections, "
                                   "max_connections_per_ip, header_timeout, min_body_rate, upload_memory, token_max_queued, "
                                   "token_seconds_per_hour, retention, codecs, min_crf, max_bitrate, presets)");
    LOAD_BAD("size = 640x360\r\nsize = 640\r\n", ":2: size: '640' is not a size (expected WxH, such as 640x360)");
    LOAD_BAD("workers = # nothing left\n", ":1: workers: '' is not a whole number");
    LOAD_BAD("workers = 2\0\n", ": contains a NUL byte (not a text file)");
    svc_config c;
    svc_config_defaults(&c);
    rs_err e = {0};
    const char *missing = tmp_path("missing.conf");
    T_ASSERT(!svc_config_load(&c, missing, &e));
    char want[600];
    snprintf(want, sizeof want, "%s: cannot open", missing);
    T_CONTAINS(e.msg, want);
}

#define SET_OK(c, name, value)                                                                     \
    do {                                                                                           \
        rs_err e_ = {0};                                                                           \
        T_ASSERTF(svc_config_set((c), (name), (value), &e_), "%s = '%s': %s", (name), (value), e_.msg); \
    } while (0)

static void t_config_finish(void)
{
    svc_config c;
    svc_config_defaults(&c);
    rs_err e = {0};
    SET_OK(&c, "data", "/srv/ring");
    T_ASSERTF(svc_config_finish(&c, &e), "%s", e.msg);
    T_ASSERT(!strcmp(c.queue, "sqlite:/srv/ring/queue.db") && !strcmp(c.output, "/srv/ring/videos"));
    svc_config_defaults(&c); /* explicit values win over derived ones */
    SET_OK(&c, "queue", "postgres://db/ring");
    SET_OK(&c, "output", "/mnt/v");
    T_ASSERT(svc_config_finish(&c, &e));
    T_ASSERT(!strcmp(c.queue, "postgres://db/ring") && !strcmp(c.output, "/mnt/v"));
    SET_OK(&c, "size", "1920x1080"); /* render_size auto: any size up to max_size */
    T_ASSERTF(svc_config_finish(&c, &e), "%s", e.msg);
    SET_OK(&c, "render_size", "1280x720"); /* an operator's fixed size bounds the job sizes */
    SET_OK(&c, "size", "1280x720"); /* equal to the render size: allowed */
    T_ASSERT(svc_config_finish(&c, &e));
    SET_OK(&c, "size", "1920x1080"); /* within max_size, but larger than what is drawn */
    T_ASSERT(!svc_config_finish(&c, &e));
    T_CONTAINS(e.msg, "size 1920x1080 with render_size 1280x720");
    SET_OK(&c, "size", "16x16"); /* more than 8 times smaller than what is drawn */
    T_ASSERT(!svc_config_finish(&c, &e));
    SET_OK(&c, "render_size", "1920x1080");
    SET_OK(&c, "size", "1920x1080"); /* equal to max_size: allowed */
    T_ASSERT(svc_config_finish(&c, &e));
    SET_OK(&c, "size", "2000x1000");
    T_ASSERT(!svc_config_finish(&c, &e));
    T_ASSERT(!strcmp(e.msg, "size 2000x1000 is larger than max_size 1920x1080"));
    SET_OK(&c, "size", "640x1082");
    T_ASSERT(!svc_config_finish(&c, &e));
}

/* Field by field: char arrays may differ past their terminators. */
static void config_same(const svc_config *a, const svc_config *b)
{
    T_ASSERT(!strcmp(a->listen, b->listen) && !strcmp(a->data, b->data) && !strcmp(a->queue, b->queue));
    T_ASSERT(!strcmp(a->output, b->output) && !strcmp(a->format, b->format) && !strcmp(a->backend, b->backend));
    T_ASSERT(a->workers == b->workers && a->max_upload == b->max_upload && a->max_attempts == b->max_attempts);
    T_ASSERT(a->lease == b->lease && a->watchdog == b->watchdog && a->grace == b->grace);
    T_ASSERT(a->segment_seconds == b->segment_seconds);
    T_ASSERT(a->width == b->width && a->height == b->height && a->max_width == b->max_width);
    T_ASSERT(a->max_height == b->max_height && a->render_width == b->render_width);
    T_ASSERT(a->render_height == b->render_height && a->log_level == b->log_level);
}

static void dump_reload(const svc_config *c, svc_config *back)
{
    const char *path = tmp_path("dump.conf");
    FILE *f = fopen(path, "w");
    T_ASSERT(f);
    svc_config_dump(c, f);
    T_ASSERT(fclose(f) == 0);
    svc_config_defaults(back);
    rs_err e = {0};
    T_ASSERTF(svc_config_load(back, path, &e), "the dump does not load: %s", e.msg);
}

static void t_config_dump_roundtrip(void)
{
    svc_config c, back;
    svc_config_defaults(&c);
    dump_reload(&c, &back);
    config_same(&c, &back);
    /* every row away from its default, so a row the dump forgets shows */
    const char *kv[][2] = {{"listen", "[::1]:9000"}, {"workers", "8"}, {"data", "/srv/ring side"},
                           {"queue", "postgres://u@db:5432/ring?sslmode=require"}, {"output", "/mnt/videos"},
                           {"max_upload", "3M"}, {"max_attempts", "5"}, {"lease", "60"}, {"watchdog", "300"},
                           {"grace", "0"}, {"segment_seconds", "0"}, {"size", "1280x720"}, {"max_size", "3840x2160"},
                           {"render_size", "2560x1440"}, {"format", "mkv"}, {"backend", "osmesa"},
                           {"log_level", "debug"}, {"quality", "high"}};
    for (size_t i = 0; i < sizeof kv / sizeof *kv; i++)
        SET_OK(&c, kv[i][0], kv[i][1]);
    dump_reload(&c, &back);
    config_same(&c, &back);
    rs_err e = {0};
    T_ASSERT(svc_config_finish(&c, &e) && svc_config_finish(&back, &e));
    config_same(&c, &back);
}

/* A value the file syntax cannot carry ('#' starts a comment) must be refused
 * when set or survive the dump: never reload as something else. */
static void t_config_dump_hash(void)
{
    svc_config c, back;
    svc_config_defaults(&c);
    if (!svc_config_set(&c, "data", "/srv/build#2", NULL))
        return;
    dump_reload(&c, &back);
    T_ASSERTF(!strcmp(back.data, c.data), "data '%s' reloads as '%s'", c.data, back.data);
}

/* --- svc_json --- */

/* The next UTF-8 scalar of s[0..n): its length, or 0 when invalid.  Decodes
 * the code point and checks it against its shortest form and the surrogate
 * gap: a different route from svc_json.c's lead-byte table. */
static int u8_scalar(const unsigned char *s, size_t n)
{
    int len = s[0] < 0x80 ? 1 : (s[0] & 0xe0) == 0xc0 ? 2 : (s[0] & 0xf0) == 0xe0 ? 3 : (s[0] & 0xf8) == 0xf0 ? 4 : 0;
    if (!len || (size_t)len > n)
        return 0;
    uint32_t c = len == 1 ? s[0] : s[0] & (0x7fu >> len);
    for (int i = 1; i < len; i++) {
        if ((s[i] & 0xc0) != 0x80)
            return 0;
        c = c << 6 | (s[i] & 0x3f);
    }
    static const uint32_t shortest[] = {0, 0, 0x80, 0x800, 0x10000};
    return c < shortest[len] || c > 0x10ffff || (c >= 0xd800 && c <= 0xdfff) ? 0 : len;
}

static size_t u8_put(unsigned char *o, uint32_t c)
{
    size_t n = c < 0x80 ? 1 : c < 0x800 ? 2 : c < 0x10000 ? 3 : 4;
    static const unsigned char lead[] = {0, 0, 0xc0, 0xe0, 0xf0};
    for (size_t i = n - 1; i > 0; i--, c >>= 6)
        o[i] = (unsigned char)(0x80 | (c & 0x3f));
    o[0] = (unsigned char)(lead[n] | c);
    return n;
}

static int hex4(const unsigned char *p)
{
    char h[5] = {(char)p[0], (char)p[1], (char)p[2], (char)p[3], 0};
    return strspn(h, "0123456789abcdefABCDEF") == 4 ? (int)strtol(h, NULL, 16) : -1;
}

/* A strict reader of exactly one JSON string (RFC 8259) filling s[0..n):
 * only the listed escapes, paired surrogates, no raw control characters,
 * valid UTF-8.  Decodes into out (as long as the input); returns its length,
 * or -1. */
static long json_string(const char *s, size_t n, unsigned char *out)
{
    const unsigned char *p = (const unsigned char *)s, *end = p + n;
    size_t o = 0;
    if (n < 2 || *p++ != '"')
        return -1;
    while (p < end && *p != '"') {
        if (*p < 0x20)
            return -1;
        if (*p != '\\') {
            int k = u8_scalar(p, (size_t)(end - p));
            if (!k)
                return -1;
            memcpy(out + o, p, (size_t)k), o += (size_t)k, p += k;
            continue;
        }
        static const char names[] = "\"\\/bfnrt", vals[] = "\"\\/\b\f\n\r\t";
        const char *esc = end - p >= 2 && p[1] ? strchr(names, p[1]) : NULL;
        if (esc) {
            out[o++] = (unsigned char)vals[esc - names], p += 2;
            continue;
        }
        int u, lo;
        if (end - p < 6 || p[1] != 'u' || (u = hex4(p + 2)) < 0 || (u >= 0xdc00 && u <= 0xdfff))
            return -1;
        p += 6;
        if (u >= 0xd800 && u <= 0xdbff) {
            if (end - p < 6 || p[0] != '\\' || p[1] != 'u' || (lo = hex4(p + 2)) < 0xdc00 || lo > 0xdfff)
                return -1;
            u = 0x10000 + ((u - 0xd800) << 10) + (lo - 0xdc00), p += 6;
        }
        o += u8_put(out + o, (uint32_t)u);
    }
    return p + 1 == end ? (long)o : -1;
}

static void t_json_str_fixed(void)
{
    static const char *const cases[][2] = {
        {"", "\"\""}, {"plain text", "\"plain text\""},
        {"say \"hi\"", "\"say \\\"hi\\\"\""}, {"C:\\dir\\", "\"C:\\\\dir\\\\\""},
        {"a\nb", "\"a\\nb\""}, {"\x01\t\r\x1f", "\"\\u0001\\u0009\\u000d\\u001f\""},
        {"del\x7f", "\"del\\u007f\""}, {"</script>", "\"</script>\""},
        {"caf\xc3\xa9", "\"caf\xc3\xa9\""},           /* 2 bytes */
        {"\xe2\x82\xac 5", "\"\xe2\x82\xac 5\""},     /* 3 bytes */
        {"\xf0\x9f\xa5\x8a", "\"\xf0\x9f\xa5\x8a\""}, /* 4 bytes */
        {"\xf4\x8f\xbf\xbf", "\"\xf4\x8f\xbf\xbf\""}, /* U+10FFFF, the last */
        {"a\x80z", "\"a\\ufffdz\""},                  /* lone continuation bytes */
        {"\xbf\xbf", "\"\\ufffd\\ufffd\""},
        {"\xc0\x80", "\"\\ufffd\\ufffd\""}, /* overlong NUL */
        {"\xc1\xbf", "\"\\ufffd\\ufffd\""},
        {"\xe0\x80\xaf", "\"\\ufffd\\ufffd\\ufffd\""}, /* overlong '/' */
        {"\xf0\x8f\xbf\xbf", "\"\\ufffd\\ufffd\\ufffd\\ufffd\""},
        {"\xed\xa0\x80", "\"\\ufffd\\ufffd\\ufffd\""}, /* surrogates D800, DFFF */
        {"\xed\xbf\xbf", "\"\\ufffd\\ufffd\\ufffd\""},
        {"\xf4\x90\x80\x80", "\"\\ufffd\\ufffd\\ufffd\\ufffd\""}, /* past U+10FFFF */
        {"ok\xe2\x82", "\"ok\\ufffd\\ufffd\""},                   /* cut short by the end */
        {"\xf0\x9f\xa5", "\"\\ufffd\\ufffd\\ufffd\""}, {"\xc3", "\"\\ufffd\""},
        {"\xe2\x82\"", "\"\\ufffd\\ufffd\\\"\""}, /* cut short by a quote */
        {"\xff\xfe", "\"\\ufffd\\ufffd\""},
    };
    svc_buf b = {0};
    unsigned char out[64];
    svc_json_str(&b, NULL); /* a missing name still makes valid JSON */
    T_ASSERT(!strcmp(b.p, "\"\""));
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        b.len = 0;
        svc_json_str(&b, cases[i][0]);
        T_ASSERTF(!strcmp(b.p, cases[i][1]), "case %zu: got %s, want %s", i, b.p, cases[i][1]);
        T_ASSERTF(json_string(b.p, b.len, out) >= 0, "case %zu: %s is not a JSON string", i, b.p);
    }
    svc_buf_free(&b);
}

/* Bytes F5..FF never start UTF-8, even when continuation bytes follow. */
static void t_json_str_f5_lead(void)
{
    svc_buf b = {0};
    svc_json_str(&b, "\xf5\x80\x80|\xf8\x88\x80\x80|\xff\xbf\xbf");
    T_ASSERTF(!strcmp(b.p, "\"\\ufffd\\ufffd\\ufffd|\\ufffd\\ufffd\\ufffd\\ufffd|\\ufffd\\ufffd\\ufffd\""),
              "got %s", b.p);
    svc_buf_free(&b);
}

/* Random bytes, biased towards UTF-8's edges: the output must be one valid
 * JSON string whose text is the input with each invalid byte read as U+FFFD. */
static void t_json_str_random(void)
{
    unsigned char in[40], want[128], got[128];
    svc_buf b = {0};
    for (int iter = 0; iter < 20000; iter++) {
        size_t n = 0, len = rnd() % 32;
        while (n < len) {
            uint32_t k = rnd() % 5;
            if (k < 3) { /* ASCII, any byte, a continuation byte */
                static const uint32_t base[] = {1, 1, 0x80}, span[] = {127, 255, 64};
                in[n++] = (unsigned char)(base[k] + rnd() % span[k]);
                continue;
            }
            /* a sequence: sometimes a surrogate or past U+10FFFF, or cut short (k == 4) */
            static const uint32_t top[] = {0x800, 0x10000, 0x110000, 0x140000};
            unsigned char seq[4];
            size_t m = u8_put(seq, 0x80 + rnd() % (top[rnd() % 4] - 0x80));
            if (k == 4 && m > 1)
                m -= 1 + rnd() % (m - 1);
            for (size_t i = 0; i < m && n < len; i++)
                in[n++] = seq[i];
        }
        in[n] = 0;
        size_t wn = 0;
        for (size_t i = 0; i < n;) {
            int m = u8_scalar(in + i, n - i);
            if (m)
                memcpy(want + wn, in + i, (size_t)m), wn += (size_t)m, i += (size_t)m;
            else
                memcpy(want + wn, "\xef\xbf\xbd", 3), wn += 3, i++;
        }
        b.len = 0;
        svc_json_str(&b, (const char *)in);
        long gn = json_string(b.p, b.len, got);
        if (gn != (long)wn || memcmp(got, want, wn)) {
            char hex[200] = "";
            for (size_t i = 0; i < n; i++)
                snprintf(hex + strlen(hex), sizeof hex - strlen(hex), "%02x ", in[i]);
            t_fail(__FILE__, __LINE__, "iteration %d: bytes %s-> %s (%s)", iter, hex, b.p,
                   gn < 0 ? "not a valid JSON string" : "valid, but the wrong text");
        }
    }
    svc_buf_free(&b);
}

static svc_job job(int state)
{
    svc_job j;
    memset(&j, 0, sizeof j);
    j.id = 42, j.state = state, j.attempts = 1, j.desync_tick = -1;
    snprintf(j.name, sizeof j.name, "dojo \"final\".rsr");
    snprintf(j.format, sizeof j.format, "webm");
    snprintf(j.owner, sizeof j.owner, "box:123"); /* shown only while running */
    j.width = 1280, j.height = 720, j.frames_total = 200;
    j.created = 1700000000; /* 2023-11-14T22:13:20Z */
    j.stage = -1;           /* queued before the replay's header was kept */
    return j;
}

/* The job's JSON is exactly want (exact == starts with want), or contains it. */
static void job_is(const svc_job *j, const char *want, bool exact)
{
    svc_buf b = {0};
    svc_json_job(&b, j, 3, NULL, 0, NULL);
    T_ASSERT(b.p && !b.oom);
    if (exact)
        T_ASSERTF(!strcmp(b.p, want), "\ngot  %s\nwant %s", b.p, want);
    else
        T_CONTAINS(b.p, want);
    svc_buf_free(&b);
}

#define JOB_HEAD "{\"id\":42,\"state\":"
#define JOB_NAME "\"name\":\"dojo \\\"final\\\".rsr\",\"size\":\"1280x720\",\"format\":\"webm\","

static void t_json_job(void)
{
    svc_job j = job(SVC_QUEUED);
    job_is(&j, JOB_HEAD "\"queued\"," JOB_NAME "\"frames_done\":0,\"frames_total\":200,\"progress\":0.0000,"
                        "\"fps\":0.00,\"eta_s\":null," "\"queue_position\":null,\"stage\":null,\"players\":null,\"winner\":null,\"rounds\":null,"
                        "\"length_s\":3.33,\"codec\":\"vp9\",\"audio\":true,\"encode\":\"\",\"quality\":null,\"bytes\":null,\"render_s\":null,"
                        "\"attempts\":1,\"max_attempts\":3,\"error\":null,"
                        "\"desync_tick\":null,\"created\":\"2023-11-14T22:13:20Z\",\"started\":null,"
                        "\"finished\":null,\"url\":\"/jobs/42\",\"log\":\"/jobs/42/log\"}", true);
    j = job(SVC_RUNNING);
    j.frames_done = 50, j.fps = 25, j.started = 1700000060;
    job_is(&j, JOB_HEAD "\"running\"," JOB_NAME "\"frames_done\":50,\"frames_total\":200,\"progress\":0.2500,"
                        "\"fps\":25.00,\"eta_s\":6.0," "\"queue_position\":null,\"stage\":null,\"players\":null,\"winner\":null,\"rounds\":null,"
                        "\"length_s\":3.33,\"codec\":\"vp9\",\"audio\":true,\"encode\":\"\",\"quality\":null,\"bytes\":null,\"render_s\":null,"
                        "\"attempts\":1,\"max_attempts\":3,\"error\":null,"
                        "\"desync_tick\":null,\"worker\":\"box:123\",\"created\":\"2023-11-14T22:13:20Z\","
                        "\"started\":\"2023-11-14T22:14:20Z\",\"finished\":null,\"url\":\"/jobs/42\","
                        "\"log\":\"/jobs/42/log\"}", true);
    j.fps = 0; /* no speed yet: no guess */
    job_is(&j, "\"fps\":0.00,\"eta_s\":null,", false);
    /* a job uploaded with audio=off says so (its renders get --audio off) */
    snprintf(j.encode, sizeof j.encode, "codec=vp9 audio=off");
    job_is(&j, "\"codec\":\"vp9\",\"audio\":false,\"encode\":\"codec=vp9 audio=off\",", false);
    /* and its quality preset */
    snprintf(j.encode, sizeof j.encode, "codec=vp9 quality=high");
    job_is(&j, "\"encode\":\"codec=vp9 quality=high\",\"quality\":\"high\",", false);
    j.encode[0] = 0;
    /* the replay's header, and what the HTTP side adds */
    svc_job k = job(SVC_DONE);
    k.stage = 4, k.kind[0] = RP_HUMAN, k.kind[1] = RP_CPU, k.winner = 2, k.rounds[0] = 1, k.rounds[1] = 2;
    k.started = 1700000060, k.finished = 1700000072;
    svc_job_view v = {.eta_s = -1, .bytes = 123456, .poster = true};
    svc_buf b = {0};
    svc_json_job(&b, &k, 3, NULL, 0, &v);
    T_CONTAINS(b.p, "\"eta_s\":null,\"queue_position\":null,\"stage\":\"snowfield\",\"players\":[\"human\",\"cpu\"],"
                    "\"winner\":2,\"rounds\":[1,2],\"length_s\":3.33,\"codec\":\"vp9\",\"audio\":true,\"encode\":\"\",\"quality\":null,\"bytes\":123456,\"render_s\":12,");
    T_CONTAINS(b.p, "\"poster\":\"/jobs/42/poster\",\"log\":\"/jobs/42/log\"}");
    svc_buf_free(&b);
    k = job(SVC_QUEUED);
    v = (svc_job_view){.queue_position = 3, .eta_s = 42.5, .bytes = -1};
    svc_json_job(&b, &k, 3, NULL, 0, &v);
    T_CONTAINS(b.p, "\"eta_s\":42.5,\"queue_position\":3,");
    T_ASSERT(!strstr(b.p, "poster"));
    svc_buf_free(&b);
    j.fps = 30, j.frames_done = 250; /* a total behind the count must not give a negative ETA */
    job_is(&j, "\"eta_s\":null,", false);
    j = job(SVC_DONE);
    j.frames_done = 190, j.fps = 40; /* the last heartbeat may lag the end */
    j.started = 1700000060, j.finished = 1700000100;
    job_is(&j, JOB_HEAD "\"done\"," JOB_NAME "\"frames_done\":200,\"frames_total\":200,\"progress\":1.0000,"
                        "\"fps\":0.00,\"eta_s\":null," "\"queue_position\":null,\"stage\":null,\"players\":null,\"winner\":null,\"rounds\":null,"
                        "\"length_s\":3.33,\"codec\":\"vp9\",\"audio\":true,\"encode\":\"\",\"quality\":null,\"bytes\":null,\"render_s\":40,"
                        "\"attempts\":1,\"max_attempts\":3,\"error\":null,"
                        "\"desync_tick\":null,\"created\":\"2023-11-14T22:13:20Z\","
                        "\"started\":\"2023-11-14T22:14:20Z\",\"finished\":\"2023-11-14T22:15:00Z\","
                        "\"url\":\"/jobs/42\",\"video\":\"/jobs/42/video\",\"hashes\":\"/jobs/42/hashes\","
                        "\"log\":\"/jobs/42/log\"}", true);
    j = job(SVC_FAILED);
    j.attempts = 3, j.frames_done = 120, j.finished = 1700000100;
    j.desync_tick = 0; /* tick 0 is a tick, not "none" */
    snprintf(j.error, sizeof j.error, "desync at tick 0:\n\"want\" \x01 \xff");
    job_is(&j, JOB_HEAD "\"failed\"," JOB_NAME "\"frames_done\":120,\"frames_total\":200,\"progress\":0.6000,"
                        "\"fps\":0.00,\"eta_s\":null,\"queue_position\":null,\"stage\":null,\"players\":null,"
                        "\"winner\":null,\"rounds\":null,\"length_s\":3.33,\"codec\":\"vp9\",\"audio\":true,\"encode\":\"\",\"quality\":null,\"bytes\":null,"
                        "\"render_s\":null,\"attempts\":3,\"max_attempts\":3,"
                        "\"error\":\"desync at tick 0:\\n\\\"want\\\" \\u0001 \\ufffd\",\"desync_tick\":0,"
                        "\"created\":\"2023-11-14T22:13:20Z\",\"started\":null,"
                        "\"finished\":\"2023-11-14T22:15:00Z\",\"url\":\"/jobs/42\",\"log\":\"/jobs/42/log\"}", true);
    j.desync_tick = 3600;
    job_is(&j, ",\"desync_tick\":3600,", false);
    j = job(SVC_CANCELLED);
    j.frames_total = 0; /* no division by zero */
    job_is(&j, JOB_HEAD "\"cancelled\"," JOB_NAME "\"frames_done\":0,\"frames_total\":0,\"progress\":0.0000,", false);
    /* the live stream: H.264 or HEVC in .mp4 or .mkv, while the job can still have one */
    for (int st = SVC_QUEUED; st <= SVC_CANCELLED; st++) {
        j = job(st);
        snprintf(j.format, sizeof j.format, "mp4");
        svc_buf sb = {0};
        svc_json_job(&sb, &j, 3, NULL, 0, NULL);
        bool has = strstr(sb.p, ",\"stream\":\"/jobs/42/stream.m3u8\"}") != NULL;
        T_ASSERTF(has == (st != SVC_FAILED && st != SVC_CANCELLED), "state %d: %s", st, sb.p);
        svc_buf_free(&sb);
    }
    j = job(SVC_DONE);
    snprintf(j.format, sizeof j.format, "mkv");
    snprintf(j.encode, sizeof j.encode, "codec=hevc crf=24");
    job_is(&j, ",\"stream\":\"/jobs/42/stream.m3u8\"}", false);
    j.expired = true;
    job_is(&j, "\"expired\":true,\"log\":\"/jobs/42/log\"}", false);
    j.expired = false;
    snprintf(j.encode, sizeof j.encode, "codec=av1");
    job_is(&j, "\"log\":\"/jobs/42/log\"}", false); /* AV1: none */
}

/* A split job: its segment count, and with its units who rendered what. */
static void t_json_split_job(void)
{
    svc_job j = job(SVC_RUNNING);
    j.segments = 2, j.segment_ticks = 60, j.frames_total = 120, j.frames_done = 90, j.fps = 20;
    job_is(&j, "\"segment_seconds\":1,\"segment_count\":2,\"url\":", false);
    svc_unit u[3] = {
        {.kind = SVC_UNIT_SEGMENT, .index = 0, .first_tick = 0, .end_tick = 60, .state = SVC_DONE, .attempts = 2,
         .renders = 1, .frames_done = 60},
        {.kind = SVC_UNIT_SEGMENT, .index = 1, .first_tick = 60, .end_tick = 120, .state = SVC_RUNNING, .attempts = 1,
         .frames_done = 30},
        {.kind = SVC_UNIT_JOIN, .index = 2, .end_tick = 120},
    };
    snprintf(u[0].done_by, sizeof u[0].done_by, "box:1-ab/0");
    snprintf(u[0].owner, sizeof u[0].owner, "stale"); /* a done unit names who finished it */
    snprintf(u[0].error, sizeof u[0].error, "lease expired");
    snprintf(u[1].owner, sizeof u[1].owner, "box:1-ab/1");
    svc_buf b = {0};
    svc_json_job(&b, &j, 3, u, 3, NULL);
    T_ASSERT(b.p && !b.oom);
    T_CONTAINS(b.p, "\"segment_seconds\":1,\"segment_count\":2,\"segments\":["
                    "{\"index\":0,\"ticks\":[0,60],\"state\":\"done\",\"attempts\":2,\"renders\":1,"
                    "\"frames_done\":60,\"worker\":\"box:1-ab/0\",\"error\":\"lease expired\"},"
                    "{\"index\":1,\"ticks\":[60,120],\"state\":\"running\",\"attempts\":1,\"renders\":0,"
                    "\"frames_done\":30,\"worker\":\"box:1-ab/1\",\"error\":null}],"
                    "\"join\":{\"state\":\"queued\",\"attempts\":0,\"renders\":0,\"frames_done\":0,"
                    "\"worker\":null,\"error\":null},\"url\":\"/jobs/42\",");
    T_CONTAINS(b.p, "\"progress\":0.7500,\"fps\":20.00,\"eta_s\":1.5,");
    svc_buf_free(&b);
    /* unsplit: not a word more than before */
    j = job(SVC_RUNNING);
    svc_json_job(&b, &j, 3, u, 3, NULL);
    T_ASSERT(!strstr(b.p, "segment"));
    svc_buf_free(&b);
}

static void t_json_buf_growth(void)
{
    svc_buf b = {0};
    size_t n = 3u << 20;
    char *big = malloc(n + 1);
    T_ASSERT(big);
    for (size_t i = 0; i < n; i++)
        big[i] = (char)('a' + i % 26);
    big[n] = 0;
    for (size_t i = 0; i < 3; i++)
        svc_buf_add(&b, big + i * (n / 3), n / 3);
    T_ASSERT(b.len == n && b.cap > n && !memcmp(b.p, big, n) && b.p[n] == 0);
    b.len = 0;
    svc_buf_printf(&b, "<%s>", big);
    T_ASSERT(b.len == n + 2 && b.p[0] == '<' && b.p[n + 1] == '>' && !memcmp(b.p + 1, big, n));
    memset(big, '"', n); /* every byte doubles */
    b.len = 0;
    svc_json_str(&b, big);
    T_EQ(b.len, 2 * n + 2);
    unsigned char *out = malloc(n);
    T_ASSERT(out && json_string(b.p, b.len, out) == (long)n);
    free(out);
    svc_buf_free(&b);
    T_ASSERT(!b.p && !b.len && !b.cap);
    svc_json_error(&b, "bad \"size\"");
    T_ASSERT(!strcmp(b.p, "{\"error\":\"bad \\\"size\\\"\"}\n"));
    svc_buf_free(&b);
    free(big);
}

/* --- svc_parse_range --- */

static void t_range_cases(void)
{
    static const struct {
        const char *h;
        uint64_t len;
        int want;
        uint64_t first, last;
    } cases[] = {
        {"bytes=0-99", 1000, 1, 0, 99}, {"bytes=100-", 1000, 1, 100, 999}, {"bytes=-50", 1000, 1, 950, 999},
        {"bytes=-5000", 1000, 1, 0, 999}, /* more than the file: all of it */
        {"bytes=500-5000", 1000, 1, 500, 999}, {"bytes=0-18446744073709551615", 1000, 1, 0, 999}, /* the end clamps */
        {"bytes=999-999", 1000, 1, 999, 999}, {"bytes=0-0", 1, 1, 0, 0},
        {"bytes=-0", 1000, -1, 0, 0}, {"bytes=1000-", 1000, -1, 0, 0}, {"bytes=1000-2000", 1000, -1, 0, 0},
        {"bytes=18446744073709551615-", 1000, -1, 0, 0},
        {"bytes=0-", 0, -1, 0, 0}, {"bytes=0-0", 0, -1, 0, 0}, {"bytes=-10", 0, -1, 0, 0}, /* nothing to send */
        {NULL, 1000, 0, 0, 0},
        /* 0: serve the whole file, as RFC 9110 allows for what it cannot use */
        {"bytes=5-2", 1000, 0, 0, 0}, {"bytes=0-1,5-6", 1000, 0, 0, 0}, {"0-99", 1000, 0, 0, 0},
        {"items=0-99", 1000, 0, 0, 0}, {"", 1000, 0, 0, 0}, {"bytes=", 1000, 0, 0, 0}, {"bytes=-", 1000, 0, 0, 0},
        {"bytes=abc", 1000, 0, 0, 0}, {"bytes=1", 1000, 0, 0, 0}, {"bytes=1-x", 1000, 0, 0, 0},
        {"bytes=0-99 ", 1000, 0, 0, 0}, {"bytes= 0-9", 1000, 0, 0, 0}, {"bytes=+1-5", 1000, 0, 0, 0},
        {"bytes=1-+5", 1000, 0, 0, 0}, {"bytes=--5", 1000, 0, 0, 0}, {"bytes=-+5", 1000, 0, 0, 0},
        {"bytes=-5x", 1000, 0, 0, 0}, {"bytes=0x10-", 1000, 0, 0, 0},
        /* overflow: no range rather than a wrapped one */
        {"bytes=99999999999999999999-", 1000, 0, 0, 0}, {"bytes=0-99999999999999999999", 1000, 0, 0, 0},
        {"bytes=-99999999999999999999", 1000, 0, 0, 0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        uint64_t f = 777, l = 777;
        int r = svc_parse_range(cases[i].h, cases[i].len, &f, &l);
        T_ASSERTF(r == cases[i].want && (r != 1 || (f == cases[i].first && l == cases[i].last)),
                  "'%s' of %llu bytes: got %d (%llu-%llu)", cases[i].h ? cases[i].h : "(null)",
                  (unsigned long long)cases[i].len, r, (unsigned long long)f, (unsigned long long)l);
    }
}

/* Against a model of RFC 9110's single byte range, with random lengths and
 * bounds near the file's end and far past it. */
static void t_range_random(void)
{
    char h[80];
    for (int iter = 0; iter < 200000; iter++) {
        uint64_t len = rnd() % 4 ? rnd() % 1000 : (uint64_t)rnd() << 32 | rnd();
        uint64_t a = rnd() % 3 ? rnd() % 1100 : (uint64_t)rnd() << 32 | rnd();
        uint64_t b = rnd() % 3 ? rnd() % 1100 : (uint64_t)rnd() << 32 | rnd();
        int form = (int)(rnd() % 3), want;
        uint64_t wf = a, wl = len - 1;
        if (form == 0) {
            snprintf(h, sizeof h, "bytes=%llu-%llu", (unsigned long long)a, (unsigned long long)b);
            want = b < a ? 0 : a >= len ? -1 : 1;
            wl = b < len ? b : len - 1;
        } else if (form == 1) {
            snprintf(h, sizeof h, "bytes=%llu-", (unsigned long long)a);
            want = a >= len ? -1 : 1;
        } else {
            snprintf(h, sizeof h, "bytes=-%llu", (unsigned long long)b);
            want = b == 0 || len == 0 ? -1 : 1;
            wf = b >= len ? 0 : len - b;
        }
        uint64_t f = 0, l = 0;
        int r = svc_parse_range(h, len, &f, &l);
        T_ASSERTF(r == want, "'%s' of %llu bytes: got %d, want %d", h, (unsigned long long)len, r, want);
        T_ASSERTF(r != 1 || (f <= l && l < len && f == wf && l == wl), "'%s' of %llu bytes: got %llu-%llu", h,
                  (unsigned long long)len, (unsigned long long)f, (unsigned long long)l);
    }
}

/* --- svc_check_upload --- */

/* A match recorded in memory with random inputs held for a while, as a
 * player holds them. */
static uint8_t *make_replay(uint64_t ticks, size_t *n)
{
    g_state st;
    g_init(&st, 0, 7);
    rp_recorder rec;
    rp_rec_init(&rec, 0, 7, RP_HUMAN, RP_HUMAN);
    rs_err e = {0};
    g_input in[2] = {0, 0};
    for (uint64_t t = 0; t < ticks; t++) {
        if (rnd() % 8 == 0)
            in[0] = g_input_clean((g_input)(rnd() & 0x7f)), in[1] = g_input_clean((g_input)(rnd() & 0x7f));
        g_step(&st, in, NULL);
        T_ASSERTF(rp_rec_tick(&rec, in, &st, &e), "%s", e.msg);
    }
    uint8_t *buf;
    T_ASSERTF(rp_encode(&rec.rp, &buf, n, &e), "%s", e.msg);
    rp_free(&rec.rp);
    return buf;
}

/* Rewrites the trailing CRC so a change reaches the parser's field checks. */
static void put_crc(uint8_t *buf, size_t n)
{
    uint32_t c = rs_crc32(0, buf, n - 4);
    for (int k = 0; k < 4; k++)
        buf[n - 4 + (size_t)k] = (uint8_t)(c >> (8 * k));
}

/* frames_total (> 0) when accepted; 0 when refused, which must be with the
 * SVC error id code (or, for a code below SVC_ERR_BASE, any id that answers
 * that HTTP status) and a message holding want (want NULL: must be accepted). */
static int64_t upload(const svc_config *cfg, const uint8_t *data, size_t len, int code, const char *want)
{
    svc_job j;
    memset(&j, 0, sizeof j);
    rs_err e = {0};
    if (svc_check_upload(cfg, data, len, "clip.rsr", &j, &e)) {
        T_ASSERT(j.frames_total > 0);
        return j.frames_total;
    }
    bool as_wanted = code > SVC_ERR_BASE ? e.code == code : svc_http_status(e.code) == (unsigned)code;
    T_ASSERTF(want && as_wanted, "%zu bytes: %s (%u), want %s: %s", len, svc_error_text(e.code),
              svc_http_status(e.code), code > SVC_ERR_BASE ? svc_error_text(code) : "that status", e.msg);
    T_CONTAINS(e.msg, want);
    return 0;
}

static void t_upload_refusals(void)
{
    svc_config cfg;
    svc_config_defaults(&cfg);
    T_EQ(upload(&cfg, (const uint8_t *)"", 0, SVC_ERR_EMPTY, "empty upload"), 0);
    T_EQ(upload(&cfg, (const uint8_t *)"hello world", 11, SVC_ERR_REPLAY, "clip.rsr: not a ringside replay"), 0);
    SET_OK(&cfg, "max_upload", "1K");
    uint8_t *junk = calloc(1, 1025);
    T_ASSERT(junk);
    T_EQ(upload(&cfg, junk, 1025, SVC_ERR_TOO_LARGE, "clip.rsr: 1025 bytes is over the upload limit of 1024 bytes"), 0);
    T_EQ(upload(&cfg, junk, 1024, SVC_ERR_REPLAY, "clip.rsr: not a ringside replay"), 0); /* at the limit: parsed */
    free(junk);
    size_t n;
    uint8_t *buf = make_replay(120, &n);
    memset(buf + 20, 0, 8); /* a replay of no ticks: nothing to render */
    put_crc(buf, n);
    T_EQ(upload(&cfg, buf, n, SVC_ERR_REPLAY, "clip.rsr: tick count 0"), 0);
    free(buf);
}

static void t_upload_valid(void)
{
    svc_config cfg;
    svc_config_defaults(&cfg);
    size_t n;
    uint8_t *buf = make_replay(1000, &n);
    T_EQ(upload(&cfg, buf, n, 0, NULL), 1000);
    /* max_seconds: 1000 ticks is 16.7 s of game time */
    cfg.max_seconds = 17;
    T_EQ(upload(&cfg, buf, n, 0, NULL), 1000);
    cfg.max_seconds = 16;
    upload(&cfg, buf, n, SVC_ERR_TOO_LONG, "clip.rsr: the replay lasts 17 s; this service renders at most 16 s (max_seconds)");
    svc_config_defaults(&cfg);
    free(buf);
    char path[1024];
    snprintf(path, sizeof path, "%s/demos/temple.rsr", RS_SOURCE_DIR);
    rs_err e = {0};
    rp_replay rp;
    buf = (uint8_t *)rs_read_file(path, RP_MAX_FILE, &n, &e);
    T_ASSERTF(buf && rp_read(path, &rp, &e), "%s", e.msg);
    T_EQ(upload(&cfg, buf, n, 0, NULL), rp.ticks);
    rp_free(&rp);
    free(buf);
}

/* The upload is re-simulated: a flipped input is refused naming its
 * checkpoint tick, a replay of other game rules naming both versions, each
 * with its own id; a format-1 replay (no game version) is accepted. */
static void t_upload_verified(void)
{
    svc_config cfg;
    svc_config_defaults(&cfg);
    size_t n;
    uint8_t *buf = make_replay(1000, &n);
    rp_replay rp;
    rs_err e = {0};
    T_ASSERTF(rp_decode(buf, n, "mem", &rp, &e), "%s", e.msg);
    free(buf);
    rp.inputs[2 * (70 - 1)] ^= G_IN_GUARD;
    T_ASSERTF(rp_encode(&rp, &buf, &n, &e), "%s", e.msg);
    T_EQ(upload(&cfg, buf, n, SVC_ERR_DESYNC,
                "clip.rsr: desync at tick 120: "), 0);
    free(buf);
    rp.inputs[2 * (70 - 1)] ^= G_IN_GUARD;
    rp.game_version = G_GAME_VERSION + 1;
    T_ASSERTF(rp_encode(&rp, &buf, &n, &e), "%s", e.msg);
    char want[160];
    snprintf(want, sizeof want, "clip.rsr: recorded by another version of the game (replay: %d, this build: %d)",
             G_GAME_VERSION + 1, G_GAME_VERSION);
    T_EQ(upload(&cfg, buf, n, SVC_ERR_GAME_VERSION, want), 0);
    free(buf);
    /* format 1: no game version, and the plain state hashes (format 3 keys them with the kinds) */
    rp.game_version = 0;
    rp_set_format(&rp, 1);
    T_ASSERTF(rp_encode(&rp, &buf, &n, &e), "%s", e.msg);
    T_EQ(upload(&cfg, buf, n, 0, NULL), 1000);
    free(buf);
    rp_free(&rp);
}

/* Every prefix of a good replay is a broken upload: refused with 400, and
 * never read past its end (each copy is exactly k bytes, for ASan). */
static void t_upload_truncations(void)
{
    svc_config cfg;
    svc_config_defaults(&cfg);
    size_t n;
    uint8_t *buf = make_replay(2000, &n);
    for (size_t k = 1; k < n; k++) {
        uint8_t *cut = malloc(k);
        T_ASSERT(cut);
        memcpy(cut, buf, k);
        T_ASSERTF(upload(&cfg, cut, k, SVC_ERR_REPLAY, "clip.rsr") == 0, "the first %zu of %zu bytes were accepted", k, n);
        free(cut);
    }
    free(buf);
}

/* One byte changed: accepted (it still parses) or refused with 400, never a
 * crash.  Half the trials fix the checksum so the field checks are reached. */
static void t_upload_corruptions(void)
{
    svc_config cfg;
    svc_config_defaults(&cfg);
    size_t n;
    uint8_t *buf = make_replay(1500, &n), *bad = malloc(n);
    T_ASSERT(bad);
    int refused = 0;
    for (int iter = 0; iter < 4000; iter++) {
        memcpy(bad, buf, n);
        size_t at = rnd() % n;
        bad[at] ^= (uint8_t)(rnd() % 255 + 1);
        if (iter & 1 && at < n - 4)
            put_crc(bad, n);
        refused += !upload(&cfg, bad, n, 400, "clip.rsr");
    }
    T_ASSERT(refused > 2000); /* the unfixed half all fail the checksum */
    free(bad);
    free(buf);
}

/* Every id has a text, and no two share one. */
static void t_error_ids_have_texts(void)
{
    T_EQ(RS_ERR_MODULE(SVC_ERR_BASE + 1), RS_ERR_MOD_SVC);
    T_EQ(RS_ERR_MODULE(SVC_ERR_END - 1), RS_ERR_MOD_SVC);
    for (int a = SVC_ERR_BASE + 1; a < SVC_ERR_END; a++) {
        const char *t = svc_error_text(a);
        T_ASSERTF(t[0] && strcmp(t, "?") && strcmp(t, "ok"), "id %d has no text", a);
        for (int b = SVC_ERR_BASE + 1; b < a; b++)
            T_ASSERTF(strcmp(t, svc_error_text(b)), "ids %d and %d share the text \"%s\"", b, a, t);
    }
    T_ASSERT(!strcmp(svc_error_text(SVC_ERR_END), "?"));
}

/* The statuses clients have always seen; every id has a row (an id added
 * without one would answer 500). */
/* A job's encoder options: the bounds (lists with A..B ranges), the
 * encoder's own checks, the canonical string and its way back to argv. */
static void t_encode_options(void)
{
    svc_config c;
    svc_config_defaults(&c);
    char out[160];
    rs_err err = {0};
    svc_encode_req q = {.codec = "hevc", .crf = "24", .preset = "fast", .pix_fmt = "yuv444p"};
    T_ASSERTF(svc_encode_check(&c, &q, "mp4", 640, 360, out, sizeof out, &err), "%s", err.msg);
    /* the quality is always stored (the setting's when the job does not ask), so
     * every segment of a job is drawn alike whatever daemon renders it */
    T_ASSERTF(!strcmp(out, "codec=hevc crf=24 preset=fast pix_fmt=yuv444p quality=standard"), "got %s", out);
    char opt[8][24], val[8][CAP_ENC_PRESET_MAX];
    T_ASSERT(svc_encode_argv(out, opt, val, 8) == 5);
    T_ASSERTF(!strcmp(opt[4], "--quality") && !strcmp(val[4], "standard"), "got %s %s", opt[4], val[4]);
    T_ASSERTF(!strcmp(opt[3], "--pix-fmt"), "got %s", opt[3]);
    T_ASSERTF(!strcmp(val[3], "yuv444p"), "got %s", val[3]);
    char codec[16];
    svc_encode_get(out, "codec", codec, sizeof codec);
    T_ASSERTF(!strcmp(codec, "hevc"), "got %s", codec);
    svc_encode_req none = {0};
    T_ASSERT(svc_encode_check(&c, &none, "webm", 640, 360, out, sizeof out, &err));
    T_ASSERTF(!strcmp(out, "quality=standard"), "got %s", out);
    strcpy(c.quality, "draft"); /* the operator's default */
    T_ASSERT(svc_encode_check(&c, &none, "webm", 640, 360, out, sizeof out, &err) && !strcmp(out, "quality=draft"));
    svc_encode_req hi = {.quality = "high"}, bad_q = {.quality = "ultra"};
    T_ASSERT(svc_encode_check(&c, &hi, "webm", 640, 360, out, sizeof out, &err) && !strcmp(out, "quality=high"));
    T_ASSERT(!svc_encode_check(&c, &bad_q, "webm", 640, 360, out, sizeof out, &err));
    T_ASSERTF(err.code == SVC_ERR_BAD_PARAM && strstr(err.msg, "quality 'ultra': expected draft, standard, high or reference"),
              "got %s", err.msg);
    strcpy(c.quality, "standard");
    /* numbered presets by range: 4..13 takes 8 and 13, not 3 or 14 */
    const char *ok[] = {"8", "13", "4"}, *bad[] = {"3", "14", "-1", "slow", "placebo"};
    for (size_t i = 0; i < sizeof ok / sizeof *ok; i++) {
        svc_encode_req r = {.codec = "av1", .preset = ok[i]};
        T_ASSERTF(svc_encode_check(&c, &r, "mkv", 640, 360, out, sizeof out, &err), "%s: %s", ok[i], err.msg);
    }
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        svc_encode_req r = {.codec = "av1", .preset = bad[i]};
        T_ASSERTF(!svc_encode_check(&c, &r, "mkv", 640, 360, out, sizeof out, &err), "%s was allowed", bad[i]);
        T_CONTAINS(err.msg, "setting presets");
    }
    /* the encoder's word: x264 has no preset "8", MP4 holds no VP9 */
    svc_encode_req r1 = {.codec = "h264", .preset = "8"}, r2 = {.codec = "vp9"};
    T_ASSERT(!svc_encode_check(&c, &r1, "mp4", 640, 360, out, sizeof out, &err));
    T_CONTAINS(err.msg, "preset");
    T_ASSERT(!svc_encode_check(&c, &r2, "mp4", 640, 360, out, sizeof out, &err));
    T_CONTAINS(err.msg, "does not hold vp9");
}

static void t_http_status_table(void)
{
    static const struct {
        int id;
        unsigned status;
    } want[] = {
        {SVC_ERR_EMPTY, 400},    {SVC_ERR_TOO_LARGE, 413}, {SVC_ERR_TOO_LONG, 400}, {SVC_ERR_REPLAY, 400},
        {SVC_ERR_BAD_BODY, 400}, {SVC_ERR_BAD_PARAM, 400}, {SVC_ERR_NOT_FOUND, 404}, {SVC_ERR_CONFLICT, 409},
        {SVC_ERR_GONE, 410},     {SVC_ERR_RANGE, 416},     {SVC_ERR_METHOD, 405},   {SVC_ERR_DRAINING, 503},
        {SVC_ERR_AUTH, 401},     {SVC_ERR_QUOTA, 429},
        {SVC_ERR_NOMEM, 500},    {SVC_ERR_BAD_REQUEST, 400}, {SVC_ERR_HOST, 421},   {SVC_ERR_ORIGIN, 403},
        {SVC_ERR_CODING, 501},   {SVC_ERR_BUSY, 503},
        {SVC_ERR_DESYNC, 400},   {SVC_ERR_GAME_VERSION, 400},
        /* the daemon's own failures (start-up, tokens, joins): server errors or the token's state */
        {SVC_ERR_SYSTEM, 500},   {SVC_ERR_DATA_DIR, 500},  {SVC_ERR_LOCKED, 500},   {SVC_ERR_LISTEN, 500},
        {SVC_ERR_NO_HTTP, 500},  {SVC_ERR_NO_TOKENS, 500}, {SVC_ERR_SUPERVISOR, 500}, {SVC_ERR_SEGMENTS, 500},
        {SVC_ERR_TOKEN_EXISTS, 409}, {SVC_ERR_TOKEN_UNKNOWN, 404},
        {SVC_ERR_STREAMS, 503}, /* the event streams are full: come back */
        {SVC_ERR_KEEP, 500},     {SVC_ERR_RERENDER, 503}, /* come back once it is rendered again */
    };
    T_EQ(sizeof want / sizeof want[0], SVC_ERR_END - SVC_ERR_BASE - 1);
    /* every id is an error status (its row of SVC_ERRORS has one) */
    for (int a = SVC_ERR_BASE + 1; a < SVC_ERR_END; a++)
        T_ASSERTF(svc_http_status(a) >= 400 && svc_http_status(a) <= 599, "%s: status %u", svc_error_text(a),
                  svc_http_status(a));
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++)
        T_ASSERTF(svc_http_status(want[i].id) == want[i].status, "%s: %u, want %u", svc_error_text(want[i].id),
                  svc_http_status(want[i].id), want[i].status);
    /* the queue store failing is always "the queue is unavailable" */
    for (int a = SVC_STORE_ERR_BASE + 1; a < SVC_STORE_ERR_END; a++)
        T_EQ(svc_http_status(a), 503);
    /* a code from no list the service knows is a server error, never a client's */
    T_EQ(svc_http_status(1), 500);
    T_EQ(svc_http_status(RP_ERR_FIELD), 500);
}

/* SHA-256 against FIPS 180-4's examples (one block, two blocks, a million
 * bytes) and the padding edges; tokens, Bearer headers, loopback. */
static void t_sha256_known_answers(void)
{
    static const struct {
        const char *msg;
        const char *hex;
    } kat[] = {
        {"", "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"},
        {"abc", "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"},
        {"abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq",
         "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1"},
    };
    char hex[65];
    uint8_t h[32];
    for (size_t i = 0; i < sizeof kat / sizeof kat[0]; i++) {
        svc_token_hash(kat[i].msg, hex);
        T_ASSERTF(!strcmp(hex, kat[i].hex), "sha256(\"%s\") = %s", kat[i].msg, hex);
    }
    char *a = malloc(1000000);
    T_ASSERT(a);
    memset(a, 'a', 1000000);
    svc_sha256(a, 1000000, h);
    free(a);
    static const uint8_t million[32] = {0xcd, 0xc7, 0x6e, 0x5c, 0x99, 0x14, 0xfb, 0x92, 0x81, 0xa1, 0xc7,
                                        0xe2, 0x84, 0xd7, 0x3e, 0x67, 0xf1, 0x80, 0x9a, 0x48, 0xa4, 0x97,
                                        0x20, 0x0e, 0x04, 0x6d, 0x39, 0xcc, 0xc7, 0x11, 0x2c, 0xd0};
    T_ASSERT(!memcmp(h, million, 32));
    /* 55 and 56 bytes: the length fits in the last block, or needs another */
    char m[57];
    memset(m, 'a', sizeof m);
    m[55] = 0;
    svc_token_hash(m, hex);
    T_ASSERT(!strcmp(hex, "9f4390f8d30c2dd92ec9f095b65e2b9ae9b0a925a5258e241c9f1e910f734318"));
    m[55] = 'a', m[56] = 0;
    svc_token_hash(m, hex);
    T_ASSERT(!strcmp(hex, "b35439a4ac6f0948b6d6f9e3c6af0f5f590ce20f1bde7090ef7970686ec6738a"));
}

static void t_tokens_and_bearer(void)
{
    char a[SVC_TOKEN_LEN + 1], b[SVC_TOKEN_LEN + 1];
    rs_err e = {0};
    T_ASSERT(svc_token_make(a, &e) && svc_token_make(b, &e));
    T_EQ(strlen(a), SVC_TOKEN_LEN);
    T_ASSERT(!strncmp(a, "rs_", 3) && strcmp(a, b) != 0);
    T_ASSERT(strspn(a + 3, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_") == 43);
    size_t n = 0;
    const char *t = svc_bearer("  bearer   rs_abc  ", &n);
    T_ASSERT(t && n == 6 && !strncmp(t, "rs_abc", 6));
    T_ASSERT(!svc_bearer("Basic YTpi", &n) && !svc_bearer("Bearerrs_x", &n) && !svc_bearer(NULL, &n));
    T_ASSERT(svc_listen_is_loopback("127.0.0.1:8080") && svc_listen_is_loopback("127.9.8.7:0"));
    T_ASSERT(svc_listen_is_loopback("[::1]:80") && svc_listen_is_loopback("localhost:1"));
    T_ASSERT(!svc_listen_is_loopback("0.0.0.0:8080") && !svc_listen_is_loopback(":8080"));
    T_ASSERT(!svc_listen_is_loopback("[::]:80") && !svc_listen_is_loopback("127.0.0.1.evil:80"));
    T_ASSERT(!svc_listen_is_loopback("10.0.0.1:80") && !svc_listen_is_loopback("1270.0.0.1:80"));
    /* getaddrinfo reads a leading zero as octal: 0127.0.0.1 is 87.0.0.1 (found by fuzz_http) */
    T_ASSERT(!svc_listen_is_loopback("0127.0.0.1:8080") && !svc_listen_is_loopback("127.0.0.4294967296:80"));
}

/* The route table decides routing, 404 against 405, the open routes and
 * each route's query parameters. */
static void t_route_table(void)
{
#if defined(RS_HAVE_MHD)
    svc_match m;
    svc_route_match("/jobs/", "POST", &m); /* a collection answers with a trailing slash */
    T_ASSERT(m.route && m.route->body && !m.open);
    T_CONTAINS(m.route->params, "quality");
    T_CONTAINS(m.route->params, "name");
    svc_route_match("/jobs/12", "DELETE", &m);
    T_ASSERT(m.route && m.id == 12 && !m.route->body);
    svc_route_match("/jobs/12", "POST", &m);
    T_ASSERT(!m.route && m.known && !strcmp(m.methods, "GET or DELETE"));
    svc_route_match("/jobs/12/log", "HEAD", &m); /* a GET route answers HEAD */
    T_ASSERT(m.route && m.id == 12);
    svc_route_match("/jobs/12/retry", "GET", &m);
    T_ASSERT(!m.route && m.known && !strcmp(m.methods, "POST"));
    svc_route_match("/jobs/0", "GET", &m);
    T_ASSERT(!m.route && !m.known && m.bad_id);
    svc_route_match("/jobs/x1/video", "GET", &m);
    T_ASSERT(!m.route && m.bad_id);
    svc_route_match("/jobs/1234567890123456789", "GET", &m); /* 19 digits: past int64 */
    T_ASSERT(!m.route && m.bad_id);
    svc_route_match("/healthz", "GET", &m);
    T_ASSERT(m.route && m.open);
    svc_route_match("/healthz/", "GET", &m);
    T_ASSERT(!m.route && !m.known && !m.bad_id);
    svc_route_match("/jobs/1/video/", "GET", &m);
    T_ASSERT(!m.route && !m.known);
    svc_route_match("/", "POST", &m);
    T_ASSERT(!m.route && m.known && m.open && !strcmp(m.methods, "GET"));
    svc_route_match("/metrics", "GET", &m);
    T_ASSERT(m.route && !m.open && !m.route->params[0]);
    /* the event stream is a path of its own, not a job id; hls.js is open, as the page is */
    svc_route_match("/jobs/events", "GET", &m);
    T_ASSERT(m.route && !m.open && !strcmp(m.route->params, "limit,before"));
    svc_route_match("/jobs/events", "DELETE", &m);
    T_ASSERT(!m.route && m.known && !strcmp(m.methods, "GET"));
    svc_route_match("/hls.js", "GET", &m);
    T_ASSERT(m.route && m.open);
    /* a stream's playlist and pieces: "TICK.ts", the tick without a leading zero */
    svc_route_match("/jobs/7/stream.m3u8", "GET", &m);
    T_ASSERT(m.route && m.id == 7 && !m.open);
    svc_route_match("/jobs/7/stream/120.ts", "GET", &m);
    T_ASSERT(m.route && m.id == 7 && m.tick == 120 && !m.open);
    svc_route_match("/jobs/7/stream/0.ts", "GET", &m);
    T_ASSERT(m.route && m.tick == 0);
    const char *bad[] = {"/jobs/7/stream/0120.ts", "/jobs/7/stream/.ts", "/jobs/7/stream/12.tsx", "/jobs/7/stream/12",
                         "/jobs/7/stream/-1.ts", "/jobs/7/stream/1234567890123.ts", "/jobs/7/stream/12.ts/",
                         "/jobs/7/stream/", "/jobs/7/stream"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        svc_route_match(bad[i], "GET", &m);
        T_ASSERTF(!m.route && !m.known, "%s matched", bad[i]);
    }
    svc_route_match("/jobs/7/stream/12.ts", "DELETE", &m);
    T_ASSERT(!m.route && m.known && !strcmp(m.methods, "GET"));
#else
    T_SKIP_ENV("built without libmicrohttpd");
#endif
}

/* A job's plan: whole, equal segments, or growing ones from a short first */
static void plan_is(int64_t total, int64_t seg, int64_t first, const char *want)
{
    int64_t ends[64];
    int n = svc_plan_segments(total, seg, first, ends, 64);
    char got[512] = "";
    size_t at = 0;
    for (int i = 0; i < n && i < 64; i++)
        at += (size_t)snprintf(got + at, sizeof got - at, "%s%lld", i ? " " : "", (long long)ends[i]);
    T_ASSERTF(!strcmp(got, want), "total %lld, segments %lld, first %lld: ends '%s', want '%s'", (long long)total,
              (long long)seg, (long long)first, got, want);
}

static void t_plan_segments(void)
{
    plan_is(1800, 1800, 0, "");                    /* one segment's worth: whole */
    plan_is(1801, 1800, 0, "1800 1801");           /* equal segments, the last shorter */
    plan_is(5400, 1800, 0, "1800 3600 5400");
    plan_is(5400, 0, 120, "");                     /* 0: never split */
    plan_is(120, 1800, 120, "");                   /* no longer than the first: whole */
    plan_is(480, 1800, 120, "120 360 480");        /* 2 s, 4 s, the 2 s left */
    plan_is(1200, 1800, 120, "120 360 840 1200");  /* the 20 s job: 2, 4, 8, 6 s */
    plan_is(10800, 1800, 120, "120 360 840 1800 3600 5400 7200 9000 10800"); /* 3 minutes: 2 4 8 16 30... */
    plan_is(400, 1800, 120, "120 400");            /* a rest shorter than the first joins the one before */
    plan_is(180, 1800, 120, "");                   /* ... and when that leaves one segment: whole */
    plan_is(600, 60, 120, "60 120 180 240 300 360 420 480 540 600"); /* first not below seg: equal */
    plan_is(5400, 1800, 1800, "1800 3600 5400");
    /* the count without room for the ends */
    T_EQ(svc_plan_segments(10800, 1800, 120, NULL, 0), 9);
    int64_t two[2];
    T_EQ(svc_plan_segments(10800, 1800, 120, two, 2), 9);
    T_ASSERT(two[0] == 120 && two[1] == 360);
    /* every plan covers its ticks, each segment from where the last ended, none empty */
    for (int64_t total = 1; total < 4000; total += 37)
        for (int64_t first = 0; first <= 240; first += 60) {
            int64_t ends[128];
            int n = svc_plan_segments(total, 600, first, ends, 128);
            T_ASSERT(n >= 0 && n < 128 && n != 1); /* never one segment and a join */
            for (int i = 0; i < n; i++)
                T_ASSERTF(ends[i] > (i ? ends[i - 1] : 0) && ends[i] - (i ? ends[i - 1] : 0) <= 600 + 240,
                          "total %lld first %lld: segment %d ends at %lld", (long long)total, (long long)first, i,
                          (long long)ends[i]);
            T_ASSERT(n == 0 || ends[n - 1] == total);
        }
}

/* An upload without HTTP: the body within the limit, form fields and query
 * parameters from one list, the job it asks for. */
static void t_upload_params(void)
{
    svc_config cfg;
    svc_config_defaults(&cfg);
    svc_upload u = {.limit = 8};
    T_ASSERT(svc_upload_append(&u, "1234", 4) && u.len == 4);
    T_ASSERT(svc_upload_append(&u, "56789", 5) && u.too_large && !u.body && u.len == 0);
    svc_upload_free(&u);
    u = (svc_upload){.limit = 1 << 20};
    /* the empty first piece of a file part, as libmicrohttpd may send it
     * (fuzz_upload: pointer arithmetic on the NULL body, UBSan's report) */
    T_ASSERT(svc_upload_field(&u, "replay", "a.rsr", "", 0, 0) && u.len == 0 && !u.body && !strcmp(u.name, "a.rsr"));
    u.name[0] = 0;
    /* a form field in two pieces; one too long for its room is dropped */
    T_ASSERT(svc_upload_field(&u, "codec", NULL, "h2", 0, 2) && svc_upload_field(&u, "codec", NULL, "64", 2, 2));
    T_ASSERT(!strcmp(u.p.codec, "h264"));
    T_ASSERT(svc_upload_field(&u, "crf", NULL, "123456789", 0, 9) && !u.p.crf[0]);
    /* and in pieces, however it is cut: the pieces that fitted go too (found by fuzz_upload) */
    T_ASSERT(svc_upload_field(&u, "crf", NULL, "1234", 0, 4) && svc_upload_field(&u, "crf", NULL, "56789", 4, 5));
    T_ASSERT(!u.p.crf[0]);
    T_ASSERT(svc_upload_field(&u, "replay", "dir/a\x01" "b.rsr", "RS", 0, 2) && u.len == 2);
    T_ASSERT(!strcmp(u.name, "a_b.rsr"));
    T_ASSERT(svc_upload_field(&u, "other", NULL, "x", 0, 1) && svc_upload_field(&u, NULL, NULL, "x", 0, 1));
    /* the query fills what the form left; too long is refused, the form's value stays */
    rs_err e = {0};
    T_ASSERT(svc_upload_param(&u, "codec", "vp9", &e) && !strcmp(u.p.codec, "h264"));
    T_ASSERT(svc_upload_param(&u, "size", "320x180", &e) && !strcmp(u.p.size, "320x180"));
    T_ASSERT(!svc_upload_param(&u, "format", "mp4mp4mp4mp4mp4mp4", &e) && e.code == SVC_ERR_BAD_PARAM);
    T_CONTAINS(e.msg, "format: at most 15 characters");
    T_ASSERT(svc_upload_param(&u, "nosuch", "1", &e));
    /* the job: the parameters checked before the replay */
    svc_job j;
    T_ASSERT(!svc_upload_job(&cfg, &u, &j, &e) && e.code == SVC_ERR_REPLAY);
    snprintf(u.p.size, sizeof u.p.size, "17x9");
    T_ASSERT(!svc_upload_job(&cfg, &u, &j, &e) && e.code == SVC_ERR_BAD_PARAM);
    T_CONTAINS(e.msg, "size 17x9");
    snprintf(u.p.size, sizeof u.p.size, "320x180");
    snprintf(u.p.format, sizeof u.p.format, "avi");
    T_ASSERT(!svc_upload_job(&cfg, &u, &j, &e) && e.code == SVC_ERR_BAD_PARAM);
    T_CONTAINS(e.msg, "format 'avi'");
    svc_upload_free(&u);
    /* the names of the list, as POST /jobs's row of the route table has them */
    T_ASSERT(!strcmp(SVC_JOB_PARAM_LIST, "size,format,codec,crf,bitrate,preset,pix_fmt,audio,quality,name"));
}

/* Config errors carry their own ids: each with a text of its own, in the
 * "service config" block, and a bad value fails with the id of what is
 * wrong with it (the message is for people, the id for callers). */
static void t_config_error_ids(void)
{
    T_EQ(RS_ERR_MODULE(SVC_CONFIG_ERR_BASE + 1), RS_ERR_MOD_SVC_CONFIG);
    T_EQ(RS_ERR_MODULE(SVC_CONFIG_ERR_END - 1), RS_ERR_MOD_SVC_CONFIG);
    T_ASSERT(!strcmp(rs_err_module_name(SVC_CONFIG_ERR_RANGE), "service config"));
    for (int a = SVC_CONFIG_ERR_BASE + 1; a < SVC_CONFIG_ERR_END; a++) {
        const char *t = svc_config_error_text(a);
        T_ASSERTF(t[0] && strcmp(t, "?") && strcmp(t, "ok"), "id %d has no text", a);
        for (int b = SVC_CONFIG_ERR_BASE + 1; b < a; b++)
            T_ASSERTF(strcmp(t, svc_config_error_text(b)), "ids %d and %d share the text \"%s\"", b, a, t);
    }
    T_ASSERT(!strcmp(svc_config_error_text(SVC_CONFIG_ERR_END), "?"));
    static const struct {
        const char *name, *value;
        int code;
    } bad[] = {
        {"workers", "two", SVC_CONFIG_ERR_NUMBER},      {"workers", "100000", SVC_CONFIG_ERR_RANGE},
        {"max_upload", "lots", SVC_CONFIG_ERR_BYTES},   {"size", "640", SVC_CONFIG_ERR_DIMENSIONS},
        {"size", "641x360", SVC_CONFIG_ERR_RANGE},      {"format", "avi", SVC_CONFIG_ERR_CHOICE},
        {"retention", "soon", SVC_CONFIG_ERR_DURATION}, {"listen", "8080", SVC_CONFIG_ERR_ADDRESS},
        {"listen", "::1:80", SVC_CONFIG_ERR_ADDRESS},   {"nope", "1", SVC_CONFIG_ERR_UNKNOWN},
        {"data", "a#b", SVC_CONFIG_ERR_TEXT},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        svc_config c;
        svc_config_defaults(&c);
        rs_err e = {0};
        T_ASSERTF(!svc_config_set(&c, bad[i].name, bad[i].value, &e), "%s = '%s' accepted", bad[i].name,
                  bad[i].value);
        T_ASSERTF(e.code == bad[i].code, "%s = '%s': %s, want %s", bad[i].name, bad[i].value,
                  svc_config_error_text(e.code), svc_config_error_text(bad[i].code));
    }
    svc_config c;
    svc_config_defaults(&c);
    rs_err e = {0};
    SET_OK(&c, "data", "/srv/ring");
    SET_OK(&c, "max_size", "640x360");
    SET_OK(&c, "size", "1280x720");
    T_ASSERT(!svc_config_finish(&c, &e) && e.code == SVC_CONFIG_ERR_SIZE_LIMIT);
    const char *path = tmp_path("bad_ids.conf");
    t_write(t_tmpdir(), "bad_ids.conf", "workers 2\n");
    T_ASSERT(!svc_config_load(&c, path, &e) && e.code == SVC_CONFIG_ERR_SYNTAX);
}

/* --- the raw bytes of requests (svc_wire) --- */

typedef struct wire_case {
    const char *bytes;
    size_t n; /* 0: strlen */
    int status;
    const char *why; /* a part of the reason (NULL: not checked) */
} wire_case;

#define GOOD_HEAD "Host: a\r\n\r\n"
static const wire_case wire_cases[] = {
    {"GET / HTTP/1.1\r\n" GOOD_HEAD, 0, 0, NULL},
    {"GET /jobs/1?x=%00 HTTP/1.0\r\n" GOOD_HEAD, 0, 0, NULL}, /* escapes are the gate's */
    {"OPTIONS * HTTP/1.1\r\n" GOOD_HEAD, 0, 0, NULL},
    {"\r\nGET / HTTP/1.1\r\n" GOOD_HEAD, 0, 0, NULL}, /* an empty line before is ignored */
    {"GET /\xc3\xa9 HTTP/1.1\r\nX-A: \t caf\xc3\xa9\t\r\n" GOOD_HEAD, 0, 0, NULL},
    {"POST /jobs HTTP/1.1\r\nContent-Length: 3\r\n\r\n\0\r\nGET / HTTP/1.1\r\n" GOOD_HEAD, 42, 0, NULL},
    {"POST /jobs HTTP/1.1\r\nTransfer-Encoding: Chunked \r\n\r\n3;x=1\r\n\0\0\0\r\n0\r\nT: 1\r\n\r\n", 0, 0, NULL},
    /* the four, and their neighbours */
    {"GET /jobs/1\0/video HTTP/1.1\r\n" GOOD_HEAD, 35, 400, "raw control byte 0x00 in the request target"},
    {"GET /jobs/ 1 HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "a space inside the target"},
    {"POST /jobs HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\nffffffffffffffff\r\nabc", 0, 413, "max_upload"},
    {"POST /jobs HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n00000000000000001\r\n", 0, 400, "16 hex digits"},
    {"POST /jobs HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n", 0, 400, "not hexadecimal"},
    {"POST /jobs HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n3\r\nabcd\r\n", 0, 400, "longer than its size"},
    {"GET /a\x7f HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "0x7f"},
    {"GET /a\r HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "no HTTP version"},
    {"GET /a\tb HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "0x09 in the request target"},
    {"GET http://a/ HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "origin form"},
    {"GET a HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "origin form"},
    {"GET *x HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "origin form"},
    {"GET  / HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "METHOD TARGET"},
    {"GET / HTTP/1.1 \r\n" GOOD_HEAD, 0, 400, "METHOD TARGET"},
    {"GET / HTTP/2.0\r\n" GOOD_HEAD, 0, 505, "HTTP/2.0 is not supported"},
    {"GET / HTTP/1.2\r\n" GOOD_HEAD, 0, 505, "HTTP/1.2"},
    {"GET / HTTP/0.9\r\n" GOOD_HEAD, 0, 505, NULL},
    {"GET / http/1.1\r\n" GOOD_HEAD, 0, 400, "METHOD TARGET"},
    {"GET / HTTP/1.1\n" GOOD_HEAD, 0, 400, "LF without CR"},
    {"GET / HTTP/1.1\r\nHost: a\n\r\n", 0, 400, "LF without CR"},
    {"GET / HTTP/1.1\r\nHost: a\r\n\n", 0, 400, "LF without CR"},
    {"GET / HTTP/1.1\r\nX-A: a\rb\r\n" GOOD_HEAD, 0, 400, "CR that does not end a line"},
    {"GET / HTTP/1.1\r\nX-A: a\0b\r\n" GOOD_HEAD, 29, 400, "0x00 in a header value"},
    {"GET / HTTP/1.1\r\nX-A: a\001b\r\n" GOOD_HEAD, 0, 400, "0x01 in a header value"},
    {"GET / HTTP/1.1\r\nX-\001: a\r\n" GOOD_HEAD, 0, 400, "0x01 in a header"},
    {"GET / HTTP/1.1\r\nX-A: a\r\n b\r\n" GOOD_HEAD, 0, 400, "folding"},
    {"GET / HTTP/1.1\r\nX-A : a\r\n" GOOD_HEAD, 0, 400, "its colon"},
    {"GET / HTTP/1.1\r\n: a\r\n" GOOD_HEAD, 0, 400, "empty name"},
    {"GE\x01T / HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "0x01"},
    {"G(T / HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "not a token"},
    {"/ HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "begin with a method"},
    {"GET / HTTP/1.1\r\nContent-Length: 1x\r\n\r\n", 0, 400, "not a number"},
    {"GET / HTTP/1.1\r\nContent-Length: 1, 1\r\n\r\n", 0, 400, "not a number"},
    {"GET / HTTP/1.1\r\nContent-Length: 12345678901234567890123\r\n\r\n", 0, 400, "not a number"},
    {"GET / HTTP/1.1\r\nContent-Length: 1\r\nContent-Length: 1\r\n\r\n", 0, 400, "two Content-Length"},
    {"POST / HTTP/1.1\r\nContent-Length: 1\r\nTransfer-Encoding: chunked\r\n\r\n", 0, 400, "both"},
    {"POST / HTTP/1.1\r\nTransfer-Encoding: gzip\r\n\r\n", 0, 501, "'gzip': only chunked"},
    {"POST / HTTP/1.1\r\nTransfer-Encoding: gzip, chunked\r\n\r\n", 0, 501, NULL},
    {"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\nTransfer-Encoding: chunked\r\n\r\n", 0, 501, NULL},
    {"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n1\r\na\r\n0\r\nX: \001\r\n\r\n", 0, 400, "0x01"},
    /* a smuggled second request, its control byte found too */
    {"POST / HTTP/1.1\r\nContent-Length: 2\r\n\r\nabGET /\001 HTTP/1.1\r\n" GOOD_HEAD, 0, 400, "0x01"},
};

static int wire_run(const wire_case *c, uint64_t max, size_t piece, svc_wire *w)
{
    size_t n = c->n ? c->n : strlen(c->bytes);
    svc_wire_init(w, max);
    int st = 0;
    for (size_t i = 0; i < n && !st; i += piece)
        st = svc_wire_feed(w, c->bytes + i, n - i < piece ? n - i : piece);
    return st;
}

static void t_wire_cases(void)
{
    for (size_t i = 0; i < sizeof wire_cases / sizeof *wire_cases; i++) {
        const wire_case *c = &wire_cases[i];
        svc_wire w, one;
        int st = wire_run(c, 1 << 20, (size_t)-1, &w);
        T_ASSERTF(st == c->status, "case %zu (%.40s): %d (%s), want %d", i, c->bytes, st, w.why, c->status);
        T_ASSERTF(!c->why || strstr(w.why, c->why), "case %zu: '%s' does not say '%s'", i, w.why, c->why);
        /* the same verdict, word for word, whatever the pieces */
        for (size_t piece = 1; piece <= 7; piece++) {
            int s1 = wire_run(c, 1 << 20, piece, &one);
            T_ASSERTF(s1 == st && !strcmp(one.why, w.why), "case %zu in pieces of %zu: %d '%s', whole %d '%s'", i,
                      piece, s1, one.why, st, w.why);
        }
    }
    /* a verdict stays */
    svc_wire w;
    svc_wire_init(&w, 0);
    T_EQ(svc_wire_feed(&w, "GET /\001", 6), 400);
    T_EQ(svc_wire_feed(&w, " HTTP/1.1\r\n\r\n", 13), 400);
    T_ASSERT(!strcmp(svc_wire_phrase(505), "HTTP Version Not Supported"));
}

/* Requests are counted as they end, chunked bodies against max_body. */
static void t_wire_framing(void)
{
    svc_wire w;
    svc_wire_init(&w, 10);
    const char *two = "GET / HTTP/1.1\r\nHost: a\r\n\r\nPOST /jobs HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n"
                      "4\r\nabcd\r\n6\r\nabcdef\r\n0\r\n\r\n";
    T_EQ(svc_wire_feed(&w, two, strlen(two)), 0);
    T_EQ((int)w.requests, 2);
    /* 11 bytes in chunks, one past max_body: refused at the size, before its data */
    const char *over = "POST /jobs HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n4\r\nabcd\r\n7\r\n";
    T_EQ(svc_wire_feed(&w, over, strlen(over)), 413);
    T_EQ((int)w.requests, 2); /* the third request is the refused one */
    /* Content-Length bodies are the handler's to limit: not counted here */
    svc_wire_init(&w, 10);
    const char *cl = "POST /jobs HTTP/1.1\r\nContent-Length: 20\r\n\r\n01234567890123456789";
    T_EQ(svc_wire_feed(&w, cl, strlen(cl)), 0);
    T_EQ((int)w.requests, 1);
    /* no limit: a chunk of 2^64 - 1 bytes is framing like any other */
    svc_wire_init(&w, 0);
    const char *big = "POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\nffffffffffffffff\r\nabc";
    T_EQ(svc_wire_feed(&w, big, strlen(big)), 0);
}

/* Random bytes and random edits of good requests: a verdict of the four
 * statuses or none, never a crash (ASan and UBSan watch), the same verdict
 * in any pieces. */
static void t_wire_random(void)
{
    static const char *const good[] = {
        "GET /jobs?limit=5 HTTP/1.1\r\nHost: a\r\nAuthorization: Bearer x\r\n\r\n",
        "POST /jobs HTTP/1.1\r\nHost: a\r\nTransfer-Encoding: chunked\r\n\r\n5\r\nabcde\r\n0\r\n\r\n",
        "POST /jobs HTTP/1.1\r\nHost: a\r\nContent-Length: 4\r\n\r\nabcd",
    };
    char buf[256];
    int seen[4] = {0};
    for (int it = 0; it < 20000; it++) {
        const char *g = good[rnd() % 3];
        size_t n = strlen(g);
        memcpy(buf, g, n);
        if (it % 4 == 0) {
            n = 1 + rnd() % 64;
            for (size_t i = 0; i < n; i++)
                buf[i] = (char)rnd();
        } else
            for (int e = 1 + (int)(rnd() % 3); e > 0; e--)
                buf[rnd() % n] = (char)"\0\r\n \t:;/*%0fF\x7f\x80"[rnd() % 16];
        wire_case c = {buf, n, 0, NULL};
        svc_wire w, p;
        int st = wire_run(&c, 1 << 16, (size_t)-1, &w);
        T_ASSERTF(st == 0 || st == 400 || st == 413 || st == 501 || st == 505, "status %d", st);
        T_ASSERTF(!st == !w.why[0], "status %d with reason '%s'", st, w.why);
        seen[st == 0 ? 0 : st == 400 ? 1 : st == 505 ? 2 : 3]++;
        int sp = wire_run(&c, 1 << 16, 1 + rnd() % 9, &p);
        T_ASSERTF(sp == st && !strcmp(p.why, w.why), "iteration %d: %d '%s' in pieces, %d '%s' whole", it, sp, p.why,
                  st, w.why);
    }
    /* the edits reach both sides of the grammar */
    T_ASSERTF(seen[0] > 100 && seen[1] > 100, "good %d, 400 %d", seen[0], seen[1]);
}

T_MAIN({"sha256_known_answers", t_sha256_known_answers}, {"tokens_and_bearer", t_tokens_and_bearer},
       {"config_defaults", t_config_defaults}, {"config_data_default", t_config_data_default}, {"config_set", t_config_set}, {"config_lengths", t_config_lengths},
       {"config_listen_bare_ipv6", t_config_listen_bare_ipv6}, {"config_load_good", t_config_load_good},
       {"config_load_errors", t_config_load_errors}, {"config_finish", t_config_finish},
       {"config_dump_roundtrip", t_config_dump_roundtrip}, {"config_dump_hash", t_config_dump_hash},
       {"json_str_fixed", t_json_str_fixed}, {"json_str_f5_lead", t_json_str_f5_lead},
       {"json_str_random", t_json_str_random}, {"json_job", t_json_job}, {"json_split_job", t_json_split_job}, {"json_buf_growth", t_json_buf_growth},
       {"range_cases", t_range_cases}, {"range_random", t_range_random}, {"upload_refusals", t_upload_refusals},
       {"upload_valid", t_upload_valid}, {"upload_truncations", t_upload_truncations},
       {"upload_corruptions", t_upload_corruptions}, {"error_ids_have_texts", t_error_ids_have_texts},
       {"upload_verified", t_upload_verified},
       {"http_status_table", t_http_status_table}, {"encode_options", t_encode_options},
       {"route_table", t_route_table}, {"plan_segments", t_plan_segments}, {"upload_params", t_upload_params},
       {"config_error_ids", t_config_error_ids}, {"wire_cases", t_wire_cases}, {"wire_framing", t_wire_framing},
       {"wire_random", t_wire_random})
