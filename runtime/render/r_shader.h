/* Shader files: loaded from <data>/shaders/ at run time.
 *
 * A shader file starts with its own #version (330 core or newer).  Lines of
 * the form  #include "name.glsl"  pull in another file from shaders/ (nested
 * up to R_SHADER_MAX_DEPTH; use #ifndef guards for shared headers).  The
 * loader emits #line directives that carry the file in the line number
 * itself (file index * R_SHADER_LINE_BASE + line; the source-string number
 * is set too, but Mesa reports it wrongly for some errors), so the driver's
 * log maps back to the file: every compile error reads
 *     shaders/name.frag:LINE: error: ...
 * whatever driver produced it (Mesa "0:12(3):", NVIDIA "0(12) :",
 * AMD/ANGLE "ERROR: 0:12:").
 *
 * Preprocessing and log translation are plain functions (r_src_*,
 * r_log_translate) so they are tested without GL. */
#ifndef R_SHADER_H
#define R_SHADER_H

#include <stdbool.h>
#include <stddef.h>

#include "../gl/rgl.h"
#include "../util/rs_err.h"

#define R_SHADER_MAX_FILES 16
#define R_SHADER_MAX_DEPTH 8
#define R_SHADER_MAX_BYTES (1u << 20)
#define R_SHADER_LINE_BASE 100000 /* also the line limit per file */

enum {
    R_SHADER_ERR_FILE = 1, /* missing or unreadable file, or no data dir */
    R_SHADER_ERR_SYNTAX,   /* our own syntax: #version, #include */
    R_SHADER_ERR_COMPILE,  /* the driver refused to compile */
    R_SHADER_ERR_LINK,     /* the driver refused to link */
};

typedef struct r_src {
    char *text;
    size_t len, cap;
    int nfiles;
    char files[R_SHADER_MAX_FILES][256]; /* display path per source-string number */
} r_src;

/* Builds the source of shaders/<name> under data root `root`, inserting
 * `defines` (lines of "#define X 1", may be NULL) right after #version. */
bool r_src_build(r_src *s, const char *root, const char *name, const char *defines, rs_err *err);
void r_src_free(r_src *s);

/* Rewrites a driver info log into "path:line: message" lines.  Returns the
 * number of lines written to out (NUL-terminated, truncated to n). */
int r_log_translate(const r_src *s, const char *log, char *out, size_t n);

/* Compiles shaders/<name>; the stage comes from the extension (.vert, .frag,
 * .geom, .comp).  On failure returns 0, err holds the first error line and
 * *full_log (if not NULL) gets every translated line (free() it). */
GLuint r_shader_compile(const char *name, const char *defines, char **full_log, rs_err *err);

typedef struct r_program_desc {
    const char *vs, *fs;   /* file names in shaders/, e.g. "smoke.vert" */
    const char *defines;   /* optional "#define ..." lines for both stages */
} r_program_desc;

/* Compiles and links; 0 on failure with a file:line message in err. */
GLuint r_program(const r_program_desc *d, rs_err *err);

/* GL stage for a file name, or 0 when the extension is not a stage. */
GLenum r_shader_stage(const char *name);

/* Variants: a line "// variants: A B+C -" in the first 40 lines of a
 * shader file lists the #define sets it is built with (docs/shaders.md).
 * Returns the list after the colon (free() it), NULL when there is none. */
char *r_shader_variants(const char *root, const char *name);
/* One token of that list ("B+C", len bytes) -> "#define B 1\n#define C 1\n";
 * "-" -> "". */
void r_shader_variant_defines(const char *tok, size_t len, char *out, size_t n);
/* Walks a variants list: *cursor starts at the list (or "-" for a file
 * without one); each call fills defs and the token (name, e.g. "B+C") and
 * advances; false at the end. */
bool r_shader_next_variant(const char **cursor, char *defs, size_t ndefs, char *name, size_t nname);

#endif
