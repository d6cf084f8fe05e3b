/* runtime/render/r_shader: #version/#include/#line expansion, driver log
 * translation (pure), and the file:line error path on real drivers. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_shader.h"
#include "../runtime/util/rs_file.h"
#include "t.h"

/* A data root in the case's temp dir, used as the current directory so
 * paths print as "shaders/NAME" exactly as from the source tree. */
static const char *root_with(const char *const *files)
{
    const char *d = t_tmpdir();
    for (int i = 0; files[i]; i += 2) {
        char name[256];
        snprintf(name, sizeof name, "shaders/%s", files[i]);
        t_write(d, name, files[i + 1]);
    }
    T_ASSERT(chdir(d) == 0);
    setenv("RINGSIDE_DATA", d, 1);
    rs_data_reset();
    return d;
}

static void t_version_and_defines(void)
{
    const char *root = root_with((const char *const[]){"a.frag", "// note\n\n#version 330 core\nfoo\n", NULL});
    r_src s;
    rs_err e = {0};
    T_ASSERTF(r_src_build(&s, root, "a.frag", "#define X 1\n", &e), "%s", e.msg);
    T_ASSERTF(!strcmp(s.text, "// note\n\n#version 330 core\n#define X 1\n#line 4 0\nfoo\n"), "got:\n%s", s.text);
    T_EQ(s.nfiles, 1);
    T_ASSERT(!strcmp(s.files[0], "shaders/a.frag"));
    r_src_free(&s);
}

static void t_include_line_directives(void)
{
    const char *root = root_with((const char *const[]){"a.frag", "#version 330 core\n#include \"b.glsl\"\nbar",
                                                       "b.glsl", "x\n  #  include \"c.glsl\"\ny\n", "c.glsl", "z\n",
                                                       NULL});
    r_src s;
    rs_err e = {0};
    T_ASSERTF(r_src_build(&s, root, "a.frag", NULL, &e), "%s", e.msg);
    const char *want = "#version 330 core\n#line 2 0\n"
                       "#line 100001 1\nx\n#line 200001 2\nz\n#line 100003 1\ny\n"
                       "#line 3 0\nbar\n";
    T_ASSERTF(!strcmp(s.text, want), "got:\n%s", s.text);
    T_EQ(s.nfiles, 3);
    T_ASSERT(!strcmp(s.files[1], "shaders/b.glsl") && !strcmp(s.files[2], "shaders/c.glsl"));
    r_src_free(&s);
}

static void expect_build_error(const char *const *files, const char *name, const char *want1, const char *want2)
{
    const char *root = root_with(files);
    r_src s;
    rs_err e = {0};
    T_ASSERTF(!r_src_build(&s, root, name, NULL, &e), "%s accepted", name);
    T_CONTAINS(e.msg, want1);
    if (want2)
        T_CONTAINS(e.msg, want2);
    T_ASSERT(s.text == NULL);
}

static void t_include_cycle(void)
{
    expect_build_error((const char *const[]){"a.frag", "#version 330 core\n#include \"b.glsl\"\n", "b.glsl",
                                             "#include \"a.glsl\"\n", "a.glsl", "#include \"b.glsl\"\n", NULL},
                       "a.frag", "nested more than 8 deep", "shaders/");
}

static void t_missing_include(void)
{
    expect_build_error((const char *const[]){"a.frag", "#version 330 core\n\n#include \"nope.glsl\"\n", NULL}, "a.frag",
                       "shaders/a.frag:3:", "nope.glsl: cannot open");
}

static void t_missing_file(void)
{
    expect_build_error((const char *const[]){NULL}, "gone.vert", "shaders/gone.vert: cannot open", NULL);
}

static void t_no_version(void)
{
    expect_build_error((const char *const[]){"a.frag", "// c\nvoid main() {}\n", NULL}, "a.frag",
                       "shaders/a.frag:2: expected #version", NULL);
    expect_build_error((const char *const[]){"e.frag", "", NULL}, "e.frag", "shaders/e.frag:1: no #version", NULL);
}

static void t_version_in_include(void)
{
    expect_build_error((const char *const[]){"a.frag", "#version 330 core\n#include \"b.glsl\"\n", "b.glsl",
                                             "\n#version 330 core\n", NULL},
                       "a.frag", "shaders/b.glsl:2: #version in an included file", NULL);
}

static void t_bad_include_syntax(void)
{
    expect_build_error((const char *const[]){"a.frag", "#version 330 core\n#include <b.glsl>\n", NULL}, "a.frag",
                       "shaders/a.frag:2: expected #include \"file\"", NULL);
    expect_build_error((const char *const[]){"a.frag", "#version 330 core\n#include \"../../etc/passwd\"\n", NULL},
                       "a.frag", "bad shader name", NULL);
}

static void t_log_translation(void)
{
    r_src s = {.nfiles = 2};
    strcpy(s.files[0], "shaders/a.frag");
    strcpy(s.files[1], "shaders/b.glsl");
    static const struct {
        const char *log, *want;
    } cases[] = {
        /* Mesa (whose source number is sometimes 0 inside includes) */
        {"0:12(5): error: syntax error, unexpected ';'\n0:100003(1): warning: unused\n",
         "shaders/a.frag:12: error: syntax error, unexpected ';'\nshaders/b.glsl:3: warning: unused\n"},
        /* NVIDIA */
        {"1(12) : error C0000: syntax error, unexpected '}'\r\n",
         "shaders/a.frag:12: error C0000: syntax error, unexpected '}'\n"},
        /* AMD / ANGLE / glslang */
        {"ERROR: 1:100007: 'x' : undeclared identifier\nWARNING: 0:2: 'y' : unused\n",
         "shaders/b.glsl:7: error: 'x' : undeclared identifier\nshaders/a.frag:2: warning: 'y' : unused\n"},
        /* unknown source number or shape: kept, attributed to the top file */
        {"0:500001(1): error: what\nlinker says no\n\n",
         "shaders/a.frag: 0:500001(1): error: what\nshaders/a.frag: linker says no\n"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char out[1024];
        r_log_translate(&s, cases[i].log, out, sizeof out);
        T_ASSERTF(!strcmp(out, cases[i].want), "case %zu got:\n%s", i, out);
    }
    char tiny[8];
    r_log_translate(&s, cases[0].log, tiny, sizeof tiny); /* truncation is safe */
    T_ASSERT(strlen(tiny) < sizeof tiny);
}

static void compile_error_on(const char *backend)
{
    root_with((const char *const[]){"broken.frag",
                                     "#version 330 core\nout vec4 c;\nvoid main() {\n    c = vec4(1.0) +;\n}\n",
                                     "inc.frag", "#version 330 core\n#include \"bad.glsl\"\nvoid main() {}\n",
                                     "bad.glsl", "// helper\n\nfloat f() { return undefined_thing; }\n", NULL});
    plat *p = t_context(backend);
    rs_err e = {0};
    char *log = NULL;
    T_ASSERT(r_shader_compile("broken.frag", NULL, &log, &e) == 0);
    T_EQ(e.code, R_SHADER_ERR_COMPILE);
    T_ASSERTF(!strncmp(e.msg, "shaders/broken.frag:4: ", 23), "got: %s", e.msg);
    T_ASSERT(log && strstr(log, "shaders/broken.frag:4:"));
    free(log);
    T_ASSERT(r_shader_compile("inc.frag", NULL, NULL, &e) == 0);
    T_ASSERTF(!strncmp(e.msg, "shaders/bad.glsl:3: ", 20), "got: %s", e.msg);
    T_EQ(gl.GetError(), GL_NO_ERROR);
    plat_destroy(p);
}

static void t_compile_error_egl(void) { compile_error_on("egl"); }
static void t_compile_error_osmesa(void) { compile_error_on("osmesa"); }

static void t_link_error(void)
{
    root_with((const char *const[]){"l.vert", "#version 330 core\nvoid main() { gl_Position = vec4(0.0); }\n",
                                    "l.frag", "#version 330 core\nout vec4 c;\nvoid notmain() { c = vec4(1.0); }\n",
                                    NULL});
    plat *p = t_context("egl");
    rs_err e = {0};
    T_ASSERT(r_program(&(r_program_desc){.vs = "l.vert", .fs = "l.frag"}, &e) == 0);
    T_EQ(e.code, R_SHADER_ERR_LINK);
    T_CONTAINS(e.msg, "shaders/l.vert + shaders/l.frag: link failed");
    T_ASSERT(r_program(&(r_program_desc){.vs = "l.vert", .fs = "none.frag"}, &e) == 0);
    T_CONTAINS(e.msg, "none.frag: cannot open");
    plat_destroy(p);
}

static void t_defines_reach_the_shader(void)
{
    root_with((const char *const[]){"d.frag", "#version 330 core\nout vec4 c;\nvoid main() { c = vec4(VALUE); }\n",
                                    NULL});
    plat *p = t_context("egl");
    rs_err e = {0};
    GLuint sh = r_shader_compile("d.frag", NULL, NULL, &e);
    T_ASSERT(sh == 0);
    T_CONTAINS(e.msg, "shaders/d.frag:3:");
    sh = r_shader_compile("d.frag", "#define VALUE 0.5\n", NULL, &e);
    T_ASSERTF(sh != 0, "%s", e.msg);
    gl.DeleteShader(sh);
    plat_destroy(p);
}

static void t_every_shader_compiles(void)
{
    plat *p = t_context("egl");
    rs_err e = {0};
    const char *root = rs_data_dir(&e);
    T_ASSERTF(root, "%s", e.msg);
    char dir[1100];
    snprintf(dir, sizeof dir, "%s/shaders", root);
    DIR *dp = opendir(dir);
    T_ASSERT(dp);
    int n = 0;
    struct dirent *de;
    while ((de = readdir(dp)) != NULL) {
        if (!r_shader_stage(de->d_name))
            continue;
        /* every variant the file declares (docs/shaders.md), else once */
        char *vars = r_shader_variants(root, de->d_name);
        const char *v = vars ? vars : "-";
        char defs[512], var[128];
        while (r_shader_next_variant(&v, defs, sizeof defs, var, sizeof var)) {
            GLuint sh = r_shader_compile(de->d_name, defs[0] ? defs : NULL, NULL, &e);
            T_ASSERTF(sh, "%s [%s]: %s", de->d_name, var, e.msg);
            gl.DeleteShader(sh);
            n++;
        }
        free(vars);
    }
    closedir(dp);
    T_ASSERTF(n >= 30, "only %d compiles", n);
    plat_destroy(p);
}

T_MAIN({"version_and_defines", t_version_and_defines}, {"include_line_directives", t_include_line_directives},
       {"include_cycle", t_include_cycle}, {"missing_include", t_missing_include}, {"missing_file", t_missing_file},
       {"no_version", t_no_version}, {"version_in_include", t_version_in_include},
       {"bad_include_syntax", t_bad_include_syntax}, {"log_translation", t_log_translation},
       {"compile_error_egl", t_compile_error_egl}, {"compile_error_osmesa", t_compile_error_osmesa},
       {"link_error", t_link_error}, {"defines_reach_the_shader", t_defines_reach_the_shader},
       {"every_shader_compiles", t_every_shader_compiles})
