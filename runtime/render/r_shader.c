#include "r_shader.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../util/rs_file.h"

static bool put(r_src *s, const char *p, size_t n, rs_err *err)
{
    if (s->len + n + 1 > s->cap) {
        size_t cap = s->cap ? s->cap : 4096;
        while (cap < s->len + n + 1)
            cap *= 2;
        if (cap > 4 * R_SHADER_MAX_BYTES)
            return rs_fail(err, R_SHADER_ERR_FILE, "%s: expanded source larger than %u bytes", s->files[0],
                           4 * R_SHADER_MAX_BYTES);
        char *t = realloc(s->text, cap);
        if (!t)
            return rs_fail(err, R_SHADER_ERR_FILE, "%s: out of memory", s->files[0]);
        s->text = t;
        s->cap = cap;
    }
    memcpy(s->text + s->len, p, n);
    s->len += n;
    s->text[s->len] = 0;
    return true;
}

/* "#line" for `line` of file `idx`; see R_SHADER_LINE_BASE. */
static bool put_line(r_src *s, rs_err *err, int line, int idx)
{
    char buf[64];
    int n = snprintf(buf, sizeof buf, "#line %ld %d\n", (long)idx * R_SHADER_LINE_BASE + line, idx);
    return put(s, buf, (size_t)n, err);
}

static const char *skip_ws(const char *p, const char *end)
{
    while (p < end && (*p == ' ' || *p == '\t'))
        p++;
    return p;
}

/* Is [p,end) a preprocessor line "# word ..."?  Returns the text after word. */
static const char *directive(const char *p, const char *end, const char *word)
{
    p = skip_ws(p, end);
    if (p >= end || *p != '#')
        return NULL;
    p = skip_ws(p + 1, end);
    size_t n = strlen(word);
    if ((size_t)(end - p) < n || memcmp(p, word, n) != 0)
        return NULL;
    p += n;
    if (p < end && *p != ' ' && *p != '\t')
        return NULL;
    return skip_ws(p, end);
}

static bool is_blank_or_comment(const char *p, const char *end)
{
    p = skip_ws(p, end);
    return p >= end || *p == '\r' || (end - p >= 2 && p[0] == '/' && p[1] == '/');
}

static bool expand(r_src *s, const char *root, const char *name, const char *defines, int depth, const char *from,
                   rs_err *err)
{
    int idx = s->nfiles;
    if (idx >= R_SHADER_MAX_FILES)
        return rs_fail(err, R_SHADER_ERR_SYNTAX, "%s: more than %d shader files included", from, R_SHADER_MAX_FILES);
    if (depth > R_SHADER_MAX_DEPTH)
        return rs_fail(err, R_SHADER_ERR_SYNTAX, "%s: includes nested more than %d deep (an include cycle?)", from,
                       R_SHADER_MAX_DEPTH);
    if (name[0] == '/' || strstr(name, "..") || strlen(name) > 128)
        return rs_fail(err, R_SHADER_ERR_SYNTAX, "%s: bad shader name \"%s\" (expected a name inside shaders/)", from,
                       name);
    char rel[160], path[1024];
    snprintf(rel, sizeof rel, "shaders/%s", name);
    rs_data_path(root, rel, s->files[idx], sizeof s->files[idx]);
    snprintf(path, sizeof path, "%s/%s", root, rel);
    s->nfiles++;
    const char *disp = s->files[idx];

    size_t n;
    char *text = rs_read_file(path, R_SHADER_MAX_BYTES, &n, err);
    if (!text) {
        if (from)
            rs_err_prefix(err, "%s", from);
        return false;
    }
    bool ok = true, seen_version = depth > 0;
    int line = 0;
    const char *p = text, *end = text + n;
    while (ok && p < end) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        const char *next = eol ? eol + 1 : end;
        if (!eol)
            eol = end;
        if (++line >= R_SHADER_LINE_BASE) {
            ok = rs_fail(err, R_SHADER_ERR_SYNTAX, "%s: more than %d lines", disp, R_SHADER_LINE_BASE - 1);
            break;
        }
        const char *arg;
        if (!seen_version) {
            if ((arg = directive(p, eol, "version")) != NULL) {
                seen_version = true;
                ok = put(s, p, (size_t)(next - p), err) && (eol != end || put(s, "\n", 1, err));
                if (ok && defines && *defines) {
                    ok = put(s, defines, strlen(defines), err) &&
                         (defines[strlen(defines) - 1] == '\n' || put(s, "\n", 1, err));
                }
                ok = ok && put_line(s, err, line + 1, idx);
            } else if (is_blank_or_comment(p, eol)) {
                ok = put(s, p, (size_t)(next - p), err);
            } else {
                ok = rs_fail(err, R_SHADER_ERR_SYNTAX, "%s:%d: expected #version before any code", disp, line);
            }
        } else if ((arg = directive(p, eol, "include")) != NULL) {
            const char *q = arg, *qe;
            if (q >= eol || *q != '"' || !(qe = memchr(q + 1, '"', (size_t)(eol - q - 1)))) {
                ok = rs_fail(err, R_SHADER_ERR_SYNTAX, "%s:%d: expected #include \"file\"", disp, line);
                break;
            }
            char inc[160], here[300];
            snprintf(inc, sizeof inc, "%.*s", (int)(qe - q - 1), q + 1);
            snprintf(here, sizeof here, "%s:%d", disp, line);
            ok = put_line(s, err, 1, s->nfiles) && expand(s, root, inc, NULL, depth + 1, here, err) &&
                 put_line(s, err, line + 1, idx);
        } else if (depth > 0 && directive(p, eol, "version")) {
            ok = rs_fail(err, R_SHADER_ERR_SYNTAX, "%s:%d: #version in an included file", disp, line);
        } else {
            ok = put(s, p, (size_t)(next - p), err) && (eol != end || put(s, "\n", 1, err));
        }
        p = next;
    }
    if (ok && !seen_version)
        ok = rs_fail(err, R_SHADER_ERR_SYNTAX, "%s:%d: no #version line (expected #version 330 core or newer)", disp,
                     line ? line : 1);
    free(text);
    return ok;
}

bool r_src_build(r_src *s, const char *root, const char *name, const char *defines, rs_err *err)
{
    memset(s, 0, sizeof *s);
    if (!expand(s, root, name, defines, 0, NULL, err)) {
        r_src_free(s);
        return false;
    }
    return true;
}

void r_src_free(r_src *s)
{
    free(s->text);
    s->text = NULL;
    s->len = s->cap = 0;
}

static bool read_uint(const char **p, long *v)
{
    const char *q = *p;
    long x = 0;
    if (*q < '0' || *q > '9')
        return false;
    while (*q >= '0' && *q <= '9' && x < 100000000)
        x = x * 10 + (*q++ - '0');
    *p = q;
    *v = x;
    return true;
}

static bool eat(const char **p, const char *lit)
{
    size_t n = strlen(lit);
    if (strncmp(*p, lit, n) != 0)
        return false;
    *p += n;
    return true;
}

/* Recognises the three common log shapes; returns the message start. */
static const char *parse_loc(const char *ln, long *file, long *line, const char **kind)
{
    const char *p = ln;
    *kind = "";
    /* Mesa: 0:12(5): error: ... */
    if (read_uint(&p, file) && eat(&p, ":") && read_uint(&p, line)) {
        long col;
        if (eat(&p, "(") && read_uint(&p, &col) && eat(&p, "):"))
            return skip_ws(p, p + strlen(p));
        if (eat(&p, ":"))
            return skip_ws(p, p + strlen(p));
    }
    /* NVIDIA: 0(12) : error C0000: ... */
    p = ln;
    if (read_uint(&p, file) && eat(&p, "(") && read_uint(&p, line) && eat(&p, ")")) {
        p = skip_ws(p, p + strlen(p));
        if (eat(&p, ":"))
            return skip_ws(p, p + strlen(p));
    }
    /* AMD / ANGLE / glslang: ERROR: 0:12: ... */
    p = ln;
    if (eat(&p, "ERROR: "))
        *kind = "error: ";
    else if (eat(&p, "WARNING: "))
        *kind = "warning: ";
    if (**kind && read_uint(&p, file) && eat(&p, ":") && read_uint(&p, line) && eat(&p, ":"))
        return skip_ws(p, p + strlen(p));
    return NULL;
}

int r_log_translate(const r_src *s, const char *log, char *out, size_t n)
{
    size_t o = 0;
    int lines = 0;
    if (n)
        out[0] = 0;
    for (const char *p = log; p && *p;) {
        const char *eol = strchr(p, '\n');
        size_t len = eol ? (size_t)(eol - p) : strlen(p);
        char ln[1024];
        snprintf(ln, sizeof ln, "%.*s", (int)len, p);
        p = eol ? eol + 1 : NULL;
        size_t l = strlen(ln);
        while (l && (ln[l - 1] == '\r' || ln[l - 1] == ' '))
            ln[--l] = 0;
        if (!l)
            continue;
        long file = 0, line = 0;
        const char *kind, *msg = parse_loc(ln, &file, &line, &kind);
        file = line / R_SHADER_LINE_BASE; /* the reported source number is not trusted */
        line %= R_SHADER_LINE_BASE;
        int k;
        if (msg && file < s->nfiles)
            k = snprintf(out + o, n - o, "%s:%ld: %s%s\n", s->files[file], line, kind, msg);
        else
            k = snprintf(out + o, n - o, "%s: %s\n", s->nfiles ? s->files[0] : "shader", ln);
        if (k < 0 || (size_t)k >= n - o)
            break;
        o += (size_t)k;
        lines++;
    }
    return lines;
}

GLenum r_shader_stage(const char *name)
{
    const char *dot = strrchr(name, '.');
    if (!dot)
        return 0;
    if (strcmp(dot, ".vert") == 0)
        return GL_VERTEX_SHADER;
    if (strcmp(dot, ".frag") == 0)
        return GL_FRAGMENT_SHADER;
    if (strcmp(dot, ".geom") == 0)
        return GL_GEOMETRY_SHADER;
    if (strcmp(dot, ".comp") == 0)
        return GL_COMPUTE_SHADER;
    return 0;
}

/* First line of a translated log, plus how many more there were. */
static void first_line(rs_err *err, int code, const char *log, int lines)
{
    const char *eol = strchr(log, '\n');
    int len = eol ? (int)(eol - log) : (int)strlen(log);
    if (lines > 1)
        rs_fail(err, code, "%.*s (+%d more; `ringside shaders` prints all)", len, log, lines - 1);
    else
        rs_fail(err, code, "%.*s", len, log);
}

GLuint r_shader_compile(const char *name, const char *defines, char **full_log, rs_err *err)
{
    if (full_log)
        *full_log = NULL;
    const char *root = rs_data_dir(err);
    if (!root) {
        if (err)
            err->code = R_SHADER_ERR_FILE;
        return 0;
    }
    GLenum stage = r_shader_stage(name);
    if (!stage) {
        rs_fail(err, R_SHADER_ERR_FILE, "shaders/%s: unknown shader stage (expected .vert, .frag, .geom or .comp)", name);
        return 0;
    }
    if (stage == GL_COMPUTE_SHADER && (glcaps.major < 4 || (glcaps.major == 4 && glcaps.minor < 3))) {
        rs_fail(err, R_SHADER_ERR_COMPILE, "shaders/%s: compute shaders need GL 4.3 (context is %d.%d)", name,
                glcaps.major, glcaps.minor);
        return 0;
    }
    r_src src;
    if (!r_src_build(&src, root, name, defines, err))
        return 0;
    GLuint sh = gl.CreateShader(stage);
    const GLchar *text = src.text;
    GLint len = (GLint)src.len, ok = 0;
    gl.ShaderSource(sh, 1, &text, &len);
    gl.CompileShader(sh);
    gl.GetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        GLint loglen = 0;
        gl.GetShaderiv(sh, GL_INFO_LOG_LENGTH, &loglen);
        char *log = calloc(1, (size_t)loglen + 1);
        size_t outn = (size_t)loglen * 2 + 1024;
        char *out = malloc(outn);
        if (log && out) {
            gl.GetShaderInfoLog(sh, loglen, NULL, log);
            int lines = r_log_translate(&src, log, out, outn);
            if (lines == 0)
                snprintf(out, outn, "%s: compile failed (the driver gave no log)\n", src.files[0]);
            first_line(err, R_SHADER_ERR_COMPILE, out, lines);
            if (full_log) {
                *full_log = out;
                out = NULL;
            }
        } else {
            rs_fail(err, R_SHADER_ERR_COMPILE, "%s: compile failed (out of memory for the log)", src.files[0]);
        }
        free(log);
        free(out);
        gl.DeleteShader(sh);
        sh = 0;
    }
    r_src_free(&src);
    return sh;
}

GLuint r_program(const r_program_desc *d, rs_err *err)
{
    GLuint vs = r_shader_compile(d->vs, d->defines, NULL, err);
    if (!vs)
        return 0;
    GLuint fs = r_shader_compile(d->fs, d->defines, NULL, err);
    if (!fs) {
        gl.DeleteShader(vs);
        return 0;
    }
    GLuint prog = gl.CreateProgram();
    gl.AttachShader(prog, vs);
    gl.AttachShader(prog, fs);
    gl.LinkProgram(prog);
    gl.DetachShader(prog, vs);
    gl.DetachShader(prog, fs);
    gl.DeleteShader(vs);
    gl.DeleteShader(fs);
    GLint ok = 0;
    gl.GetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[1024] = "";
        gl.GetProgramInfoLog(prog, sizeof log, NULL, log);
        rs_fail(err, R_SHADER_ERR_LINK, "shaders/%s + shaders/%s: link failed: %s", d->vs, d->fs,
                log[0] ? log : "(no log)");
        gl.DeleteProgram(prog);
        return 0;
    }
    return prog;
}

/* The "// variants:" line of shaders/<name>, or NULL when the file has
 * none (it is then compiled once, without defines). */
char *r_shader_variants(const char *root, const char *name)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/shaders/%s", root, name);
    FILE *f = fopen(path, "r");
    if (!f)
        return NULL;
    char line[512], *out = NULL;
    for (int n = 0; n < 40 && fgets(line, sizeof line, f); n++) {
        char *v = strstr(line, "// variants:");
        if (v == line) {
            v += strlen("// variants:");
            v[strcspn(v, "\r\n")] = 0;
            out = strdup(v);
            break;
        }
    }
    fclose(f);
    return out;
}

/* "B+C" -> "#define B 1\n#define C 1\n"; "B=2" -> "#define B 2\n"; "-" -> "". */
void r_shader_variant_defines(const char *tok, size_t len, char *out, size_t n)
{
    out[0] = 0;
    size_t at = 0;
    while (len > 0) {
        size_t k = 0;
        while (k < len && tok[k] != '+')
            k++;
        if (k > 0 && !(k == 1 && tok[0] == '-')) {
            const char *eq = memchr(tok, '=', k);
            int w = eq ? snprintf(out + at, n - at, "#define %.*s %.*s\n", (int)(eq - tok), tok, (int)(k - (size_t)(eq - tok) - 1),
                                  eq + 1)
                       : snprintf(out + at, n - at, "#define %.*s 1\n", (int)k, tok);
            if (w < 0 || (size_t)w >= n - at)
                return;
            at += (size_t)w;
        }
        tok += k;
        len -= k;
        if (len > 0) {
            tok++;
            len--;
        }
    }
}

bool r_shader_next_variant(const char **cursor, char *defs, size_t ndefs, char *name, size_t nname)
{
    const char *v = *cursor + strspn(*cursor, " \t");
    size_t len = strcspn(v, " \t");
    if (len == 0)
        return false;
    r_shader_variant_defines(v, len, defs, ndefs);
    snprintf(name, nname, "%.*s", (int)len, v);
    *cursor = v + len;
    return true;
}
