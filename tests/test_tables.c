/* tables: the tables users read, pinned to the docs.  Each table of the
 * code that a doc writes out is read back from the doc and held to the
 * code both ways, so a row changed in one place only fails here, with a
 * message that names the doc's line and both values:
 *   - the service's settings (docs/service.md, "Settings"; svc_config.c):
 *     every setting documented, with its default and its bounds, and no
 *     documented setting the code lacks;
 *   - the service's error ids (docs/service.md, "HTTP API"; SVC_ERRORS):
 *     each id's status and text;
 *   - the job layer's error ids (docs/architecture.md, "Error ids";
 *     JOB_ERRORS): each id's text.
 * The settings' rows are private to svc_config.c, so their side is what
 * svc_config_set does with values on and past each documented bound: the
 * bounds a user meets, not a copy of the table.  The model is
 * test_quality's presets_are_the_documented_table.
 *   build/tests/test_tables [settings|svc_errors|job_errors] */
#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../cmd/job_err.h"
#include "../runtime/util/rs_file.h"
#include "../service/svc_config.h"
#include "../service/svc_local.h"
#include "t.h"

/* --- a doc's table --- */

enum { MAX_ROWS = 64, MAX_COLS = 4, CELL = 1024 };

typedef struct doc_row {
    int line; /* in the doc, for the messages */
    int ncols;
    char cell[MAX_COLS][CELL];
} doc_row;

typedef struct doc_table {
    const char *doc; /* "docs/service.md" */
    int n;
    doc_row rows[MAX_ROWS];
} doc_table;

/* Every disagreement is printed; the case fails once, at the end, so one
 * run lists them all. */
static int problems;

static void complain(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void complain(const char *fmt, ...)
{
    va_list ap;
    fputs("    ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    problems++;
}

static char *trim(char *s)
{
    while (*s == ' ')
        s++;
    size_t n = strlen(s);
    while (n && s[n - 1] == ' ')
        s[--n] = 0;
    return s;
}

/* The table under the heading `section` of `doc` whose header row is
 * `header`: its body rows, cells trimmed, "\|" read as '|'. */
static void read_table(const char *doc, const char *section, const char *header, doc_table *t)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", RS_SOURCE_DIR, doc);
    size_t len;
    rs_err e = {0};
    char *text = rs_read_file(path, 1 << 22, &len, &e);
    T_ASSERTF(text, "%s", e.msg);
    memset(t, 0, sizeof *t);
    t->doc = doc;
    const char *sec = strstr(text, section);
    T_ASSERTF(sec, "%s has no heading \"%s\"", doc, section + 1);
    const char *end = strstr(sec + 1, "\n## ");
    const char *h = strstr(sec, header);
    T_ASSERTF(h && (!end || h < end), "%s, \"%s\": no table with the header \"%s\"", doc, section + 1, header + 1);
    int line = 1;
    for (const char *p = text; p < h + 1; p++)
        line += *p == '\n';
    const char *p = strchr(h + 1, '\n'); /* the separator row */
    T_ASSERTF(p && !strncmp(p + 1, "|---", 4), "%s:%d: the header is not followed by |---|", doc, line);
    line++;
    for (p = strchr(p + 1, '\n'); p && p[1] == '|'; p = strchr(p + 1, '\n')) {
        line++;
        T_ASSERTF(t->n < MAX_ROWS, "%s:%d: more than %d rows", doc, line, MAX_ROWS);
        doc_row *r = &t->rows[t->n++];
        r->line = line;
        const char *s = p + 2; /* past "\n|" */
        char *out = r->cell[0];
        size_t k = 0;
        for (; *s && *s != '\n'; s++) {
            if (*s == '\\' && s[1] == '|')
                s++;
            else if (*s == '|') {
                out[k] = 0;
                T_ASSERTF(r->ncols + 1 < MAX_COLS, "%s:%d: more than %d columns", doc, line, MAX_COLS - 1);
                out = r->cell[++r->ncols], k = 0;
                continue;
            }
            T_ASSERTF(k + 1 < CELL, "%s:%d: a cell over %d bytes", doc, line, CELL - 1);
            out[k++] = *s;
        }
        out[k] = 0; /* after the last '|': nothing, not a column */
        for (int c = 0; c < r->ncols; c++) {
            char *v = trim(r->cell[c]);
            memmove(r->cell[c], v, strlen(v) + 1);
        }
    }
    T_ASSERTF(t->n > 0, "%s:%d: the table has no rows", doc, line);
    free(text);
}

/* "`x`" alone in a cell: x. */
static bool backticked(const char *cell, char *out, size_t n)
{
    size_t len = strlen(cell);
    if (len < 2 || cell[0] != '`' || cell[len - 1] != '`' || memchr(cell + 1, '`', len - 2))
        return false;
    snprintf(out, n, "%.*s", (int)(len - 2), cell + 1);
    return true;
}

/* The row of t whose first cell is "`key`", or NULL; a second one is a
 * problem of its own. */
static const doc_row *find_row(const doc_table *t, const char *key)
{
    const doc_row *found = NULL;
    char want[256];
    snprintf(want, sizeof want, "`%s`", key);
    for (int i = 0; i < t->n; i++)
        if (!strcmp(t->rows[i].cell[0], want)) {
            if (found)
                complain("%s:%d: %s has a second row (the first at line %d)", t->doc, t->rows[i].line, key,
                         found->line);
            else
                found = &t->rows[i];
        }
    return found;
}

/* --- the settings --- */

/* What kind of value a setting takes, from the code's own refusal of a
 * word no setting takes (a text setting takes it). */
typedef enum { K_TEXT, K_INT, K_BYTES, K_DURATION, K_SIZE, K_CHOICE, K_LISTEN, K_UNKNOWN } kind;

static kind kind_of(const char *name)
{
    svc_config c;
    svc_config_defaults(&c);
    rs_err e = {0};
    if (svc_config_set(&c, name, "?", &e))
        return K_TEXT;
    switch (e.code) {
    case SVC_CONFIG_ERR_NUMBER:
        return K_INT;
    case SVC_CONFIG_ERR_BYTES:
        return K_BYTES;
    case SVC_CONFIG_ERR_DURATION:
        return K_DURATION;
    case SVC_CONFIG_ERR_DIMENSIONS:
        return K_SIZE;
    case SVC_CONFIG_ERR_CHOICE:
        return K_CHOICE;
    case SVC_CONFIG_ERR_ADDRESS:
        return K_LISTEN;
    }
    return K_UNKNOWN;
}

/* svc_config_set on a fresh default config: 0 if taken, else the error id
 * (and its message in msg). */
static int try_set(const char *name, const char *value, char *msg, size_t n)
{
    svc_config c;
    svc_config_defaults(&c);
    rs_err e = {0};
    if (svc_config_set(&c, name, value, &e))
        return 0;
    if (msg)
        snprintf(msg, n, "%s", e.msg);
    return e.code;
}

/* What the code says of a value far out of any bound: its message names
 * its own bounds, for the messages here. */
static const char *code_says(const char *name, kind k, char *buf, size_t n)
{
    static char huge[8200];
    memset(huge, 'a', sizeof huge - 1);
    huge[sizeof huge - 1] = 0;
    const char *far = k == K_SIZE ? "99998x99998" : k == K_TEXT ? huge : k == K_LISTEN ? "127.0.0.1:99999999" :
                      k == K_CHOICE ? "?" : "999999999999999";
    if (!try_set(name, far, buf, n))
        snprintf(buf, n, "it takes '%.40s%s' too", far, strlen(far) > 40 ? "..." : "");
    return buf;
}

/* "name = value" of svc_config_dump, the value. */
static void dumped(const svc_config *c, const char *name, char *out, size_t n)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    T_ASSERT(f);
    svc_config_dump(c, f);
    fclose(f);
    char key[128];
    snprintf(key, sizeof key, "%s = ", name);
    const char *at = NULL;
    for (const char *l = text; l && *l && !at; l = strchr(l, '\n'), l = l ? l + 1 : NULL)
        if (!strncmp(l, key, strlen(key)))
            at = l + strlen(key);
    T_ASSERTF(at, "svc_config_dump wrote no line for %s", name);
    snprintf(out, n, "%.*s", (int)strcspn(at, "\n"), at);
    free(text);
}

/* A number with an optional unit letter from units ("KM", "smhd"), in its
 * base unit (bytes, seconds); *s is moved past it. */
static bool number(const char **s, const char *units, long *v)
{
    const char *p = *s;
    if (!isdigit((unsigned char)*p))
        return false;
    long n = 0;
    for (; isdigit((unsigned char)*p); p++)
        n = n * 10 + (*p - '0');
    if (*p && units && strchr(units, *p)) {
        static const struct { char u; long mul; } mul[] = {{'K', 1024}, {'M', 1024 * 1024}, {'s', 1}, {'m', 60},
                                                          {'h', 3600}, {'d', 86400}};
        for (size_t i = 0; i < sizeof mul / sizeof mul[0]; i++)
            if (mul[i].u == *p)
                n *= mul[i].mul;
        p++;
    }
    *v = n;
    *s = p;
    return true;
}

/* The first "A..B" of a meaning (units as number() reads them): the two
 * values, and their spellings in the doc. */
static bool doc_range(const char *meaning, const char *units, long *lo, long *hi, char *lo_s, char *hi_s)
{
    for (const char *p = meaning; (p = strstr(p, "..")) != NULL; p += 2) {
        const char *a = p;
        while (a > meaning && (isalnum((unsigned char)a[-1])))
            a--;
        const char *s = a, *b = p + 2;
        if (number(&s, units, lo) && s == p && number(&b, units, hi) && !isalnum((unsigned char)*b)) {
            snprintf(lo_s, 32, "%.*s", (int)(p - a), a);
            snprintf(hi_s, 32, "%.*s", (int)(b - p - 2), p + 2);
            return true;
        }
    }
    return false;
}

/* "at most N characters" (or "At most") of a meaning. */
static bool doc_length(const char *meaning, long *n)
{
    for (const char *p = meaning; (p = strstr(p + 1, "t most ")) != NULL;) {
        char word[16];
        if ((p[-1] == 'a' || p[-1] == 'A') && sscanf(p, "t most %ld %15[a-z]", n, word) == 2 &&
            !strcmp(word, "characters"))
            return true;
    }
    return false;
}

/* The doc's range of a number setting against the code: both ends taken,
 * one past each refused as out of range (refused): a value is prefix and
 * the number (the listen address's port). */
static void check_range(const doc_table *t, const doc_row *r, const char *name, kind k, const char *prefix,
                        int refused)
{
    const char *units = k == K_BYTES ? "KM" : k == K_DURATION ? "smhd" : NULL;
    long lo, hi;
    char lo_s[32], hi_s[32], msg[800], says[800];
    if (!doc_range(r->cell[2], units, &lo, &hi, lo_s, hi_s)) {
        complain("%s:%d: %s: no bounds (A..B) in its row; the code: %s", t->doc, r->line, name,
                 code_says(name, k, says, sizeof says));
        return;
    }
    char in[2][64], out[2][64];
    snprintf(in[0], sizeof in[0], "%s%s", prefix, lo_s);
    snprintf(in[1], sizeof in[1], "%s%s", prefix, hi_s);
    snprintf(out[0], sizeof out[0], "%s%ld", prefix, lo - 1);
    snprintf(out[1], sizeof out[1], "%s%ld", prefix, hi + 1);
    for (int i = 0; i < 2; i++) {
        if (try_set(name, in[i], msg, sizeof msg))
            complain("%s:%d: %s: the doc's bounds are %s..%s, but the code refuses %s: %s", t->doc, r->line, name,
                     lo_s, hi_s, in[i], msg);
        int code = try_set(name, out[i], NULL, 0);
        if (code != refused)
            complain("%s:%d: %s: the doc's bounds are %s..%s, but the code %s %s; the code: %s", t->doc, r->line,
                     name, lo_s, hi_s, code ? "refuses for another reason" : "takes", out[i],
                     code_says(name, k, says, sizeof says));
    }
}

/* A size: "each side even and A..B" (render_size's "auto" is a default). */
static void check_size(const doc_table *t, const doc_row *r, const char *name)
{
    long lo, hi;
    char lo_s[32], hi_s[32], says[800];
    if (!strstr(r->cell[2], "each side even and ") || !doc_range(r->cell[2], NULL, &lo, &hi, lo_s, hi_s)) {
        complain("%s:%d: %s: no bounds (each side even and A..B) in its row; the code: %s", t->doc, r->line, name,
                 code_says(name, K_SIZE, says, sizeof says));
        return;
    }
    struct { long w, h; bool ok; } probe[] = {
        {lo, lo, true}, {hi, hi, true}, {lo - 2, lo, false}, {lo, lo - 2, false},
        {hi + 2, hi, false}, {hi, hi + 2, false}, {lo + 1, lo, false}, {lo, lo + 1, false},
    };
    for (size_t i = 0; i < sizeof probe / sizeof probe[0]; i++) {
        char v[48];
        snprintf(v, sizeof v, "%ldx%ld", probe[i].w, probe[i].h);
        int code = try_set(name, v, NULL, 0);
        if (probe[i].ok ? code != 0 : code != SVC_CONFIG_ERR_RANGE)
            complain("%s:%d: %s: the doc says each side even and %s..%s, but the code %s %s; the code: %s", t->doc,
                     r->line, name, lo_s, hi_s, code ? "refuses" : "takes", v,
                     code_says(name, K_SIZE, says, sizeof says));
    }
}

/* A text (or the listen address, padded to length): N characters taken,
 * N + 1 refused. */
static void check_length(const doc_table *t, const doc_row *r, const char *name, kind k)
{
    long n;
    char says[800];
    if (!doc_length(r->cell[2], &n) || n < 8 || n > 8000) {
        complain("%s:%d: %s: no length (at most N characters) in its row; the code: %s", t->doc, r->line, name,
                 code_says(name, k, says, sizeof says));
        return;
    }
    static char v[8200];
    for (long len = n; len <= n + 1; len++) {
        memset(v, 'a', (size_t)len);
        v[len] = 0;
        if (k == K_LISTEN)
            memcpy(v + len - 5, ":8080", 5);
        int code = try_set(name, v, NULL, 0);
        if (len == n ? code != 0 : code == 0)
            complain("%s:%d: %s: the doc says at most %ld characters, but the code %s %ld; the code: %s", t->doc,
                     r->line, name, n, code ? "refuses" : "takes", len, code_says(name, k, says, sizeof says));
    }
}

/* A choice: the meaning's `words` are its choices, every one.  The code's
 * list is private; its refusal of another word is where it is written
 * ("'?' is not one of a|b|c"), so that is read, for this check alone. */
static void check_choices(const doc_table *t, const doc_row *r, const char *name)
{
    char msg[800], doc[512] = "";
    try_set(name, "?", msg, sizeof msg);
    const char *list = strstr(msg, "is not one of ");
    T_ASSERTF(list, "%s: cannot find the choices in the code's refusal '%s'", name, msg);
    char code[512];
    snprintf(code, sizeof code, "|%s|", list + strlen("is not one of "));
    int ndoc = 0;
    for (const char *p = strchr(r->cell[2], '`'); p; p = strchr(p + 1, '`')) {
        const char *q = strchr(p + 1, '`');
        if (!q)
            break;
        char w[64], bar[70];
        snprintf(w, sizeof w, "%.*s", (int)(q - p - 1), p + 1);
        snprintf(bar, sizeof bar, "|%s|", w);
        snprintf(doc + strlen(doc), sizeof doc - strlen(doc), "%s%s", ndoc++ ? "|" : "", w);
        if (!strstr(code, bar))
            complain("%s:%d: %s: the doc offers `%s`, which the code does not take (its choices: %s)", t->doc,
                     r->line, name, w, list + strlen("is not one of "));
        p = q;
    }
    char pad[520];
    snprintf(pad, sizeof pad, "|%s|", doc);
    for (char *w = strtok(code, "|"); w; w = strtok(NULL, "|")) {
        char bar[70];
        snprintf(bar, sizeof bar, "|%s|", w);
        if (!strstr(pad, bar))
            complain("%s:%d: %s: the code takes %s, which the doc does not list (the doc's: %s)", t->doc, r->line,
                     name, w, doc);
    }
}

/* The default: a number or one `literal` is the value (after the derived
 * defaults are filled with data = DATA, as the doc writes queue and
 * output); other words describe a default worked out at start, and the
 * code's own default must then be empty. */
static void check_default(const doc_table *t, const doc_row *r, const char *name)
{
    const char *cell = r->cell[1];
    char lit[256], doc_v[1200], code_v[1200], raw_v[1200];
    svc_config raw, eff;
    svc_config_defaults(&raw);
    svc_config_defaults(&eff);
    rs_err e = {0};
    T_ASSERTF(svc_config_set(&eff, "data", "DATA", &e) && svc_config_finish(&eff, &e), "%s", e.msg);
    dumped(&raw, name, raw_v, sizeof raw_v);
    dumped(&eff, name, code_v, sizeof code_v);
    bool literal = backticked(cell, lit, sizeof lit) || (cell[0] && strspn(cell, "0123456789") == strlen(cell));
    if (!literal) {
        if (raw_v[0])
            complain("%s:%d: %s: the doc's default is a description ('%.60s'), but the code's is %s", t->doc, r->line,
                     name, cell, raw_v);
        return;
    }
    if (!backticked(cell, lit, sizeof lit))
        snprintf(lit, sizeof lit, "%s", cell);
    svc_config c;
    svc_config_defaults(&c);
    if (!svc_config_set(&c, name, lit, &e)) {
        complain("%s:%d: %s: the doc's default %s is refused by the code (%s); the code's default is %s", t->doc,
                 r->line, name, lit, e.msg, code_v);
        return;
    }
    dumped(&c, name, doc_v, sizeof doc_v);
    if (strcmp(doc_v, code_v)) {
        bool spelled = strcmp(doc_v, lit) != 0; /* 1M: say it as the code's 1048576 */
        complain("%s:%d: %s: the doc's default is %s%s%s%s, the code's is %s", t->doc, r->line, name, lit,
                 spelled ? " (" : "", spelled ? doc_v : "", spelled ? ")" : "", code_v);
    }
}

static void t_settings(void)
{
    static doc_table t;
    read_table("docs/service.md", "\n## Settings\n", "\n| setting | default | meaning |", &t);
    problems = 0;
    int n = 0;
    for (const char *name; (name = svc_config_name(n)) != NULL; n++) {
        const doc_row *r = find_row(&t, name);
        if (!r) {
            complain("%s: the setting %s has no row", t.doc, name);
            continue;
        }
        if (r->ncols != 3) {
            complain("%s:%d: %s: a row of %d columns, not 3", t.doc, r->line, name, r->ncols);
            continue;
        }
        check_default(&t, r, name);
        kind k = kind_of(name);
        switch (k) {
        case K_INT:
        case K_BYTES:
        case K_DURATION:
            check_range(&t, r, name, k, "", SVC_CONFIG_ERR_RANGE);
            break;
        case K_SIZE:
            check_size(&t, r, name);
            break;
        case K_TEXT:
            check_length(&t, r, name, k);
            break;
        case K_LISTEN:
            check_range(&t, r, name, k, "127.0.0.1:", SVC_CONFIG_ERR_ADDRESS); /* the port */
            check_length(&t, r, name, k);
            break;
        case K_CHOICE:
            check_choices(&t, r, name);
            break;
        case K_UNKNOWN:
            complain("%s: a setting of a kind this test does not know (add it here)", name);
            break;
        }
    }
    /* the other way: every documented setting is one of the code's */
    for (int i = 0; i < t.n; i++) {
        char name[128];
        bool known = false;
        if (!backticked(t.rows[i].cell[0], name, sizeof name)) {
            complain("%s:%d: '%s' is not a `setting`", t.doc, t.rows[i].line, t.rows[i].cell[0]);
            continue;
        }
        for (int k = 0; k < n; k++)
            known |= !strcmp(svc_config_name((size_t)k), name);
        if (!known)
            complain("%s:%d: %s is documented, but the code has no such setting", t.doc, t.rows[i].line, name);
    }
    T_ASSERTF(n >= 30 && !problems, "%d disagreement(s) between %s's settings and svc_config.c's (above); %d settings",
              problems, t.doc, n);
}

/* --- the error ids --- */

typedef struct code_id {
    const char *name; /* "SVC_ERR_EMPTY" */
    int code;
} code_id;

static void t_svc_errors(void)
{
    static const code_id ids[] = {
#define X(id, status, text) {"SVC_ERR_" #id, SVC_ERR_##id},
        SVC_ERRORS(X)
#undef X
    };
    static doc_table t;
    read_table("docs/service.md", "\n## HTTP API\n", "\n| status | id | text |", &t);
    problems = 0;
    size_t n = sizeof ids / sizeof ids[0];
    for (size_t i = 0; i < n; i++) {
        const doc_row *r = NULL; /* by the second column, the id */
        for (int k = 0; !r && k < t.n; k++) {
            char id[64];
            if (t.rows[k].ncols == 3 && backticked(t.rows[k].cell[1], id, sizeof id) && !strcmp(id, ids[i].name))
                r = &t.rows[k];
        }
        if (!r) {
            complain("%s: %s has no row (status %u, \"%s\" in SVC_ERRORS)", t.doc, ids[i].name,
                     svc_http_status(ids[i].code), svc_error_text(ids[i].code));
            continue;
        }
        unsigned st = (unsigned)strtoul(r->cell[0], NULL, 10);
        if (st != svc_http_status(ids[i].code))
            complain("%s:%d: %s: status %s in the doc, %u in the code (SVC_ERRORS)", t.doc, r->line, ids[i].name,
                     r->cell[0], svc_http_status(ids[i].code));
        if (strcmp(r->cell[2], svc_error_text(ids[i].code)))
            complain("%s:%d: %s: the doc's text is \"%s\", the code's \"%s\"", t.doc, r->line, ids[i].name, r->cell[2],
                     svc_error_text(ids[i].code));
    }
    for (int k = 0; k < t.n; k++) {
        char id[64];
        bool known = false;
        if (t.rows[k].ncols != 3 || !backticked(t.rows[k].cell[1], id, sizeof id)) {
            complain("%s:%d: not a row of | status | `id` | text |", t.doc, t.rows[k].line);
            continue;
        }
        for (size_t i = 0; i < n; i++)
            known |= !strcmp(id, ids[i].name);
        for (int j = 0; j < k; j++)
            if (!strcmp(t.rows[j].cell[1], t.rows[k].cell[1]))
                complain("%s:%d: %s has a second row (the first at line %d)", t.doc, t.rows[k].line, id,
                         t.rows[j].line);
        if (!known)
            complain("%s:%d: %s is documented, but SVC_ERRORS has no such id", t.doc, t.rows[k].line, id);
    }
    T_ASSERTF(!problems, "%d disagreement(s) between %s's error table and SVC_ERRORS (above)", problems, t.doc);
}

static void t_job_errors(void)
{
    static const code_id ids[] = {
#define X(id, text) {"JOB_ERR_" #id, JOB_ERR_##id},
        JOB_ERRORS(X)
#undef X
    };
    static doc_table t;
    read_table("docs/architecture.md", "\n## Error ids\n", "\n| id | text |", &t);
    problems = 0;
    size_t n = sizeof ids / sizeof ids[0];
    for (size_t i = 0; i < n; i++) {
        const doc_row *r = find_row(&t, ids[i].name);
        if (!r)
            complain("%s: %s has no row (\"%s\" in JOB_ERRORS)", t.doc, ids[i].name, job_error_text(ids[i].code));
        else if (r->ncols != 2 || strcmp(r->cell[1], job_error_text(ids[i].code)))
            complain("%s:%d: %s: the doc's text is \"%s\", the code's \"%s\"", t.doc, r->line, ids[i].name, r->cell[1],
                     job_error_text(ids[i].code));
    }
    for (int k = 0; k < t.n; k++) {
        char id[64];
        bool known = false;
        if (!backticked(t.rows[k].cell[0], id, sizeof id)) {
            complain("%s:%d: not a row of | `id` | text |", t.doc, t.rows[k].line);
            continue;
        }
        for (size_t i = 0; i < n; i++)
            known |= !strcmp(id, ids[i].name);
        if (!known)
            complain("%s:%d: %s is documented, but JOB_ERRORS has no such id", t.doc, t.rows[k].line, id);
    }
    T_ASSERTF(!problems, "%d disagreement(s) between %s's job error table and JOB_ERRORS (above)", problems, t.doc);
}

T_MAIN({"settings", t_settings}, {"svc_errors", t_svc_errors}, {"job_errors", t_job_errors})
