/* Stage description files (docs/stages.md).
 *
 * One table of typed rows with bounds, in the manner of Redis's config.c.
 * The same rows parse a file, apply the defaults and write a stage back
 * out.  Each row's default is text run through the row's own parser, so
 * the documented defaults and the accepted values cannot drift apart, and
 * a default is normalised exactly as a file's value would be. */
#include "r_stage.h"

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "../game/g_game.h"
#include "../util/rs_file.h"

typedef enum kind {
    K_NAME,   /* 1..31 of [a-z0-9_-] */
    K_GAME,   /* a g_stages name; also sets game_index */
    K_ENV,    /* "procedural" or an .hdr/.exr path */
    K_NUM,    /* float in lo..hi */
    K_INT,    /* a whole number in lo..hi, stored as int */
    K_COLOR,  /* 3 floats, each in lo..hi */
    K_DIR,    /* 3 floats, not all zero, normalised */
    K_BOOL,
    K_LIGHT,  /* r_paint_light: 8 numbers */
    K_FORMAT, /* r_hdr_format */
    K_AFTERIMAGE, /* r_afterimage */
} kind;

typedef struct row {
    const char *key;
    kind kind;
    size_t off;      /* of the field in r_stage */
    double lo, hi;   /* bounds of a K_NUM, or of each K_COLOR component */
    const char *def; /* the default as written in a file; NULL: required */
} row;

#define F(field) offsetof(r_stage, field)
#define HALF ((double)R_HALF_MAX)
static const row rows[] = {
    {"name", K_NAME, F(name), 0, 0, NULL},
    {"game", K_GAME, F(game), 0, 0, NULL},
    {"environment", K_ENV, F(env_path), 0, 0, "procedural"},
    {"environment_rotate", K_NUM, F(env_rotate_deg), -360, 360, "0"},
    {"environment_scale", K_NUM, F(env_scale), 0, HALF, "1"},
    {"sky_zenith", K_COLOR, F(sky_zenith), 0, HALF, "0.25 0.45 0.90"},
    {"sky_horizon", K_COLOR, F(sky_horizon), 0, HALF, "0.9 0.85 0.8"},
    {"ground", K_COLOR, F(ground), 0, HALF, "0.12 0.10 0.08"},
    {"sun", K_BOOL, F(sun), 0, 0, "yes"},
    {"sun_direction", K_DIR, F(sun_dir), 0, 0, "-0.4 0.55 0.35"},
    {"sun_color", K_COLOR, F(sun_color), 0, HALF, "1 0.95 0.85"},
    {"sun_intensity", K_NUM, F(sun_intensity), 0, HALF, "6"},
    {"sun_size", K_NUM, F(sun_size_deg), 0.05, 20, "0.53"},
    {"key_light", K_LIGHT, F(key), 0, 0, "0.5 0.6 0.6 1 0.9 0.8 4 12"},
    {"counter_light", K_LIGHT, F(counter), 0, 0, "-0.6 0.3 -0.5 0.4 0.5 0.8 2 20"},
    {"key_area", K_NUM, F(key_area_deg), 1, 90, "25"},
    {"ring_color", K_COLOR, F(ring_color), 0, 1, "0.55 0.42 0.28"},
    {"exposure", K_NUM, F(exposure), 0.001, 1000, "1"},
    {"gamma", K_NUM, F(gamma), 0.1, 10, "2.2"},
    {"saturation", K_NUM, F(saturation), 0, 10, "1"},
    {"bloom", K_NUM, F(bloom), 0, 10, "0.35"},
    {"bloom_threshold", K_NUM, F(bloom_threshold), 0, HALF, "1"},
    {"flare", K_BOOL, F(flare), 0, 0, "yes"},
    {"shadows", K_BOOL, F(shadows), 0, 0, "yes"},
    {"hdr_format", K_FORMAT, F(hdr_format), 0, 0, "rgba16f"},
    {"standard_scene_pct", K_INT, F(standard_scene_pct), 50, 100, "100"},
    {"water", K_BOOL, F(water), 0, 0, "no"},
    {"snow", K_BOOL, F(snow), 0, 0, "no"},
    {"fog", K_BOOL, F(fog), 0, 0, "no"},
    {"holes", K_BOOL, F(holes), 0, 0, "no"},
    {"lspsm", K_BOOL, F(lspsm), 0, 0, "no"},
    {"buildings", K_INT, F(buildings), 0, R_STAGE_MAX_BUILDINGS, "0"},
    {"buildings_seed", K_INT, F(buildings_seed), 0, 16777216, "1"},
    {"afterimage", K_AFTERIMAGE, F(afterimage), 0, 0, "view"},
    {"afterimage_stretch", K_NUM, F(afterimage_stretch), 1, 8, "1"},
    {"afterimage_speed", K_NUM, F(afterimage_speed), 0, 1000, "2"},
};
static const char *const afterimage_names[] = {"off", "view", "world"};
#define NROWS (sizeof rows / sizeof rows[0])

/* Light components: a direction (any finite size, not zero), a colour and
 * an intensity (HDR values) and the disc's angular radius. */
static const char *const light_part[8] = {"x", "y", "z", "r", "g", "b", "intensity", "size_deg"};
static const double light_lo[8] = {-HALF, -HALF, -HALF, 0, 0, 0, 0, 0.5};
static const double light_hi[8] = {HALF, HALF, HALF, HALF, HALF, HALF, HALF, 90};

static const char *const hdr_names[] = {"rgba16f", "r11g11b10f"};

/* Where a value comes from: messages read "path:line: key: ...". */
typedef struct ctx {
    const char *path;
    int line;
    rs_err *err;
} ctx;

const char *r_stage_error_text(int code)
{
    static const char *const text[] = {
#define X(id, t) t,
        R_STAGE_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_R_STAGE, text, (int)(sizeof text / sizeof text[0]));
}

static bool bad(const ctx *c, int code, const char *fmt, ...) RS_PRINTF(3, 4);
static bool bad(const ctx *c, int code, const char *fmt, ...)
{
    char msg[640];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return rs_fail(c->err, code, "%s:%d: %s", c->path, c->line, msg);
}

/* A value as a message shows it: at most 48 bytes, control bytes as '?'
 * (the text is the user's, the message is one line). */
typedef struct quoted {
    char s[56];
} quoted;

static quoted quote(const char *s, size_t n)
{
    quoted q;
    size_t k = 0;
    for (; k < n && k < 48; k++)
        q.s[k] = (unsigned char)s[k] < 0x20 || s[k] == 0x7f ? '?' : s[k];
    if (k < n) {
        memcpy(q.s + k, "...", 3);
        k += 3;
    }
    q.s[k] = 0;
    return q;
}

#define Q(str) (quote((str), strlen(str)).s)

static bool is_ws(char ch)
{
    return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\f' || ch == '\v';
}

static char *trim(char *s)
{
    while (is_ws(*s))
        s++;
    size_t n = strlen(s);
    while (n && is_ws(s[n - 1]))
        s[--n] = 0;
    return s;
}

/* Splits s at whitespace into at most max tokens; returns how many there
 * are in all (it may be more than max: the caller reports the count). */
static int tokens(const char *s, const char *tok[], size_t len[], int max)
{
    int n = 0;
    for (;;) {
        while (is_ws(*s))
            s++;
        if (!*s)
            return n;
        const char *t = s;
        while (*s && !is_ws(*s))
            s++;
        if (n < max) {
            tok[n] = t;
            len[n] = (size_t)(s - t);
        }
        n++;
    }
}

/* A token that is all of one finite number in lo..hi.  The token ends at
 * whitespace or the end of the value, where strtod stops in any case. */
static bool number(const ctx *c, const char *key, const char *part, const char *tok, size_t n, double lo, double hi,
                   float *out)
{
    char *end;
    double v = n ? strtod(tok, &end) : NAN;
    bool is_num = n && end == tok + n && isfinite(v);
    if (!is_num || v < lo || v > hi)
        return bad(c, is_num ? R_STAGE_ERR_RANGE : R_STAGE_ERR_VALUE, "%s: %s%sexpected a number in %g..%g, got '%s'",
                   key, part ? part : "", part ? ": " : "", lo, hi, quote(tok, n).s);
    *out = (float)v;
    return true;
}

/* Normalises a direction in place; false when it is zero.  A vector that is
 * already unit length to float precision is kept as it is, so writing a
 * stage and reading it back cannot move it by an ulp. */
static bool normalise(float v[3])
{
    double x = v[0], y = v[1], z = v[2];
    double l2 = x * x + y * y + z * z;
    if (l2 == 0)
        return false;
    if (fabs(l2 - 1) <= 1e-6)
        return true;
    double l = sqrt(l2);
    v[0] = (float)(x / l);
    v[1] = (float)(y / l);
    v[2] = (float)(z / l);
    return true;
}

static bool parse_bool(const char *v, bool *out)
{
    static const char *const yes[] = {"yes", "true", "on", "1"}, *const no[] = {"no", "false", "off", "0"};
    for (size_t i = 0; i < 4; i++) {
        if (!strcmp(v, yes[i]) || !strcmp(v, no[i])) {
            *out = !strcmp(v, yes[i]);
            return true;
        }
    }
    return false;
}

static bool set_env(r_stage *st, const char *v, const ctx *c)
{
    if (!strcmp(v, "procedural")) {
        st->env_path[0] = 0;
        return true;
    }
    size_t n = strlen(v);
    if (n <= 4 || (strcasecmp(v + n - 4, ".hdr") && strcasecmp(v + n - 4, ".exr")))
        return bad(c, R_STAGE_ERR_VALUE, "environment: expected 'procedural' or an .hdr or .exr file, got '%s'", Q(v));
    /* relative to the stage file's directory: "stages/x.stage" + "sky.hdr" */
    const char *slash = v[0] == '/' ? NULL : strrchr(c->path, '/');
    size_t dir = slash ? (size_t)(slash - c->path) + 1 : 0;
    if (dir + n >= sizeof st->env_path)
        return bad(c, R_STAGE_ERR_VALUE, "environment: the path is longer than %zu bytes, got '%s'",
                   sizeof st->env_path - 1, Q(v));
    memcpy(st->env_path, c->path, dir);
    memcpy(st->env_path + dir, v, n + 1);
    return true;
}

static bool set_light(r_paint_light *l, const char *key, const char *v, const ctx *c)
{
    const char *tok[8];
    size_t len[8];
    int n = tokens(v, tok, len, 8);
    if (n != 8)
        return bad(c, R_STAGE_ERR_VALUE, "%s: expected 8 numbers (x y z r g b intensity size_deg), got %d: '%s'", key,
                   n, Q(v));
    float f[8];
    for (int i = 0; i < 8; i++)
        if (!number(c, key, light_part[i], tok[i], len[i], light_lo[i], light_hi[i], &f[i]))
            return false;
    float dir[3] = {f[0], f[1], f[2]};
    if (!normalise(dir))
        return bad(c, R_STAGE_ERR_VALUE, "%s: expected a direction x y z that is not all zero, got '%s'", key, Q(v));
    memcpy(l->dir, dir, sizeof dir);
    memcpy(l->color, f + 3, sizeof l->color);
    l->intensity = f[6];
    l->size_deg = f[7];
    return true;
}

/* Parses value v of row r into st; v is trimmed and free of comments. */
static bool set(r_stage *st, const row *r, const char *v, const ctx *c)
{
    void *field = (char *)st + r->off;
    switch (r->kind) {
    case K_NAME: {
        size_t n = strlen(v);
        bool ok = n >= 1 && n < sizeof st->name;
        for (size_t i = 0; ok && i < n; i++)
            ok = (v[i] >= 'a' && v[i] <= 'z') || (v[i] >= '0' && v[i] <= '9') || v[i] == '_' || v[i] == '-';
        if (!ok)
            return bad(c, R_STAGE_ERR_VALUE, "name: expected 1 to %zu characters of a-z 0-9 _ -, got '%s'",
                       sizeof st->name - 1, Q(v));
        memcpy(st->name, v, n + 1);
        return true;
    }
    case K_GAME: {
        char names[256] = "";
        for (int i = 0; i < G_STAGES; i++) {
            if (!strcmp(v, g_stages[i].name)) {
                snprintf(st->game, sizeof st->game, "%s", g_stages[i].name);
                st->game_index = i;
                return true;
            }
            size_t k = strlen(names);
            snprintf(names + k, sizeof names - k, "%s%s", i ? (i == G_STAGES - 1 ? " or " : ", ") : "",
                     g_stages[i].name);
        }
        return bad(c, R_STAGE_ERR_VALUE, "game: expected a game stage (%s), got '%s'", names, Q(v));
    }
    case K_ENV:
        return set_env(st, v, c);
    case K_NUM: {
        size_t n = strlen(v);
        return number(c, r->key, NULL, v, n, r->lo, r->hi, field);
    }
    case K_INT: {
        /* digits only, no sign: "+7", "0x7" and "1e3" are refused */
        size_t nd = strspn(v, "0123456789");
        long x = nd && nd <= 9 && !v[nd] ? strtol(v, NULL, 10) : -1;
        if (x < 0 || x < (long)r->lo || x > (long)r->hi)
            return bad(c, nd && !v[nd] ? R_STAGE_ERR_RANGE : R_STAGE_ERR_VALUE, "%s: expected a whole number in %ld..%ld, got '%s'", r->key, (long)r->lo,
                       (long)r->hi, Q(v));
        *(int *)field = (int)x;
        return true;
    }
    case K_COLOR:
    case K_DIR: {
        static const char *const rgb[3] = {"r", "g", "b"}, *const xyz[3] = {"x", "y", "z"};
        const char *tok[3];
        size_t len[3];
        int n = tokens(v, tok, len, 3);
        bool dir = r->kind == K_DIR;
        if (n != 3)
            return bad(c, R_STAGE_ERR_VALUE, "%s: expected 3 numbers (%s), got %d: '%s'", r->key,
                       dir ? "x y z" : "r g b", n, Q(v));
        float f[3];
        for (int i = 0; i < 3; i++)
            if (!number(c, r->key, (dir ? xyz : rgb)[i], tok[i], len[i], dir ? -HALF : r->lo, dir ? HALF : r->hi,
                        &f[i]))
                return false;
        if (dir && !normalise(f))
            return bad(c, R_STAGE_ERR_VALUE, "%s: expected a direction x y z that is not all zero, got '%s'", r->key,
                       Q(v));
        memcpy(field, f, sizeof f);
        return true;
    }
    case K_BOOL: {
        bool b;
        if (!parse_bool(v, &b))
            return bad(c, R_STAGE_ERR_VALUE, "%s: expected yes or no (or true/false, on/off, 1/0), got '%s'", r->key,
                       Q(v));
        *(bool *)field = b;
        return true;
    }
    case K_LIGHT:
        return set_light(field, r->key, v, c);
    case K_FORMAT:
        for (size_t i = 0; i < sizeof hdr_names / sizeof hdr_names[0]; i++) {
            if (!strcmp(v, hdr_names[i])) {
                *(r_hdr_format *)field = (r_hdr_format)i;
                return true;
            }
        }
        return bad(c, R_STAGE_ERR_VALUE, "hdr_format: expected rgba16f or r11g11b10f, got '%s'", Q(v));
    case K_AFTERIMAGE:
        for (size_t i = 0; i < sizeof afterimage_names / sizeof afterimage_names[0]; i++) {
            if (!strcmp(v, afterimage_names[i])) {
                *(r_afterimage *)field = (r_afterimage)i;
                return true;
            }
        }
        return bad(c, R_STAGE_ERR_VALUE, "afterimage: expected view, world or off, got '%s'", Q(v));
    }
    return bad(c, R_STAGE_ERR_VALUE, "%s: internal error: unknown kind %d", r->key, (int)r->kind);
}

void r_stage_defaults(r_stage *st)
{
    memset(st, 0, sizeof *st);
    /* the required keys too, so the defaults alone are a complete stage */
    snprintf(st->name, sizeof st->name, "default");
    snprintf(st->game, sizeof st->game, "%s", g_stages[0].name);
    st->game_index = 0;
    ctx c = {"(defaults)", 0, NULL};
    for (size_t i = 0; i < NROWS; i++)
        if (rows[i].def)
            set(st, &rows[i], rows[i].def, &c);
}

/* Edit distance, for "did you mean"; keys are short. */
static size_t distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b), d[40];
    if (la >= 40 || lb >= 40)
        return 99;
    for (size_t j = 0; j <= lb; j++)
        d[j] = j;
    for (size_t i = 1; i <= la; i++) {
        size_t diag = d[0];
        d[0] = i;
        for (size_t j = 1; j <= lb; j++) {
            size_t up = d[j], best = diag + (a[i - 1] != b[j - 1]);
            if (up + 1 < best)
                best = up + 1;
            if (d[j - 1] + 1 < best)
                best = d[j - 1] + 1;
            d[j] = best;
            diag = up;
        }
    }
    return d[lb];
}

static bool unknown_key(const char *key, const ctx *c)
{
    const char *best = NULL;
    size_t bd = 3; /* suggest only near misses */
    for (size_t i = 0; i < NROWS; i++) {
        size_t d = strcasecmp(key, rows[i].key) ? distance(key, rows[i].key) : 0;
        if (d < bd) {
            bd = d;
            best = rows[i].key;
        }
    }
    if (best)
        return bad(c, R_STAGE_ERR_UNKNOWN_KEY, "unknown key '%s' (did you mean '%s'?)", Q(key), best);
    return bad(c, R_STAGE_ERR_UNKNOWN_KEY, "unknown key '%s' (keys are listed in docs/stages.md)", Q(key));
}

/* One line, NUL-terminated, without its '\n'.  seen[i] is the line where
 * rows[i] was set, 0 if not yet. */
static bool parse_line(r_stage *st, char *s, int seen[NROWS], const ctx *c)
{
    char *hash = strchr(s, '#');
    if (hash)
        *hash = 0;
    s = trim(s);
    if (!*s)
        return true;
    char *eq = strchr(s, '=');
    if (!eq)
        return bad(c, R_STAGE_ERR_SYNTAX, "missing '=' (expected key = value), got '%s'", Q(s));
    *eq = 0;
    char *key = trim(s), *val = trim(eq + 1);
    if (!*key)
        return bad(c, R_STAGE_ERR_SYNTAX, "missing key before '=' (expected key = value)");
    size_t i = 0;
    while (i < NROWS && strcmp(key, rows[i].key))
        i++;
    if (i == NROWS)
        return unknown_key(key, c);
    if (seen[i])
        return bad(c, R_STAGE_ERR_DUPLICATE_KEY, "duplicate key '%s' (first on line %d)", key, seen[i]);
    seen[i] = c->line;
    return set(st, &rows[i], val, c);
}

bool r_stage_parse(r_stage *st, const char *path, const char *text, size_t len, rs_err *err)
{
    if (len > R_STAGE_MAX_BYTES)
        return rs_fail(err, R_STAGE_ERR_FILE, "%s: %zu bytes is larger than the %u-byte limit for stage files", path,
                       len, R_STAGE_MAX_BYTES);
    /* a private copy: lines are cut and trimmed in place */
    char *buf = malloc(len + 1);
    if (!buf)
        return rs_fail(err, R_STAGE_ERR_FILE, "%s: out of memory", path);
    if (len)
        memcpy(buf, text, len);
    buf[len] = 0;
    r_stage_defaults(st);
    int seen[NROWS] = {0};
    ctx c = {path, 0, err};
    bool ok = true;
    /* a UTF-8 byte-order mark, as some Windows editors write, is not part of the first key */
    size_t start = len >= 3 && !memcmp(buf, "\xef\xbb\xbf", 3) ? 3 : 0;
    for (size_t o = start; ok && o < len;) {
        char *line = buf + o, *nl = memchr(line, '\n', len - o);
        size_t n = nl ? (size_t)(nl - line) : len - o;
        o += n + 1;
        c.line++;
        char *nul = memchr(line, 0, n);
        if (nul) {
            ok = bad(&c, R_STAGE_ERR_SYNTAX, "NUL byte at column %zu (a stage file is text)", (size_t)(nul - line) + 1);
            break;
        }
        line[n] = 0;
        ok = parse_line(st, line, seen, &c);
    }
    for (size_t i = 0; ok && i < NROWS; i++)
        if (!rows[i].def && !seen[i])
            ok = rs_fail(err, R_STAGE_ERR_MISSING_KEY, "%s: missing required key '%s' (every stage file sets name and game)",
                         path, rows[i].key);
    free(buf);
    return ok;
}

bool r_stage_load(r_stage *st, const char *path, rs_err *err)
{
    size_t len = 0;
    char *text = rs_read_file(path, R_STAGE_MAX_BYTES, &len, err);
    if (!text) {
        if (err)
            err->code = R_STAGE_ERR_FILE;
        return false;
    }
    bool ok = r_stage_parse(st, path, text, len, err);
    free(text);
    return ok;
}

bool r_stage_for_game(r_stage *st, int game_index, rs_err *err)
{
    if (game_index < 0 || game_index >= G_STAGES)
        return rs_fail(err, R_STAGE_ERR_GAME, "game stage %d does not exist (expected 0..%d)", game_index,
                       G_STAGES - 1);
    const char *root = rs_data_dir(err);
    if (!root) {
        if (err)
            err->code = R_STAGE_ERR_FILE;
        return false;
    }
    char rel[64], path[PATH_MAX];
    snprintf(rel, sizeof rel, "stages/%s.stage", g_stages[game_index].name);
    rs_data_path(root, rel, path, sizeof path);
    if (!r_stage_load(st, path, err))
        return false;
    if (st->game_index != game_index)
        return rs_fail(err, R_STAGE_ERR_GAME,
                       "%s: game is '%s', but this file dresses game stage '%s' (expected game = %s)", path, st->game,
                       g_stages[game_index].name, g_stages[game_index].name);
    return true;
}

/* ---------- writing ---------- */
typedef struct sink {
    char *p;
    size_t n, len;
} sink;

static void put(sink *s, const char *fmt, ...) RS_PRINTF(2, 3);
static void put(sink *s, const char *fmt, ...)
{
    size_t room = s->len < s->n ? s->n - s->len : 0;
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(room ? s->p + s->len : NULL, room, fmt, ap);
    va_end(ap);
    if (k > 0)
        s->len += (size_t)k;
}

/* %.9g: enough digits that every float reads back as itself. */
int r_stage_format(const r_stage *st, char *out, size_t n)
{
    sink s = {out, n, 0};
    if (n)
        out[0] = 0;
    put(&s, "# ringside stage file (docs/stages.md)\n");
    for (size_t i = 0; i < NROWS; i++) {
        const row *r = &rows[i];
        const void *field = (const char *)st + r->off;
        const float *f = field;
        put(&s, "%s = ", r->key);
        switch (r->kind) {
        case K_NAME:
        case K_GAME:
            put(&s, "%s\n", (const char *)field);
            break;
        case K_ENV:
            put(&s, "%s\n", st->env_path[0] ? st->env_path : "procedural");
            break;
        case K_NUM:
            put(&s, "%.9g\n", f[0]);
            break;
        case K_INT:
            put(&s, "%d\n", *(const int *)field);
            break;
        case K_COLOR:
        case K_DIR:
            put(&s, "%.9g %.9g %.9g\n", f[0], f[1], f[2]);
            break;
        case K_BOOL:
            put(&s, "%s\n", *(const bool *)field ? "yes" : "no");
            break;
        case K_LIGHT: {
            const r_paint_light *l = field;
            put(&s, "%.9g %.9g %.9g  %.9g %.9g %.9g  %.9g %.9g\n", l->dir[0], l->dir[1], l->dir[2], l->color[0],
                l->color[1], l->color[2], l->intensity, l->size_deg);
            break;
        }
        case K_AFTERIMAGE: {
            int a = (int)*(const r_afterimage *)field;
            put(&s, "%s\n", afterimage_names[a >= 0 && a < 3 ? a : 0]);
            break;
        }
        case K_FORMAT: {
            r_hdr_format h = *(const r_hdr_format *)field;
            put(&s, "%s\n", h == R_HDR_R11G11B10F ? "r11g11b10f" : "rgba16f");
            break;
        }
        }
    }
    return s.len > INT_MAX ? INT_MAX : (int)s.len;
}
