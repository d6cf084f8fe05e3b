/* ringside shaders: compile every stage file in shaders/ on this driver. */
#include <dirent.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_shader.h"
#include "../runtime/util/rs_file.h"

static void help(void)
{
    printf("usage: ringside shaders [--backend egl|osmesa|glfw] [-q|-v] [--emit DIR]\n\n"
           "Compiles every .vert, .frag, .geom and .comp file in the shaders directory\n"
           "(found through RINGSIDE_DATA, the source tree or the install prefix) and\n"
           "prints each error as shaders/FILE:LINE: message.  .glsl files are include\n"
           "files and are compiled as part of the stages that include them.  A file with\n"
           "a line '// variants: A B+C' is compiled once per variant, with '#define A 1'\n"
           "and then '#define B 1' and '#define C 1' ('-' is the variant with none).\n"
           "Exit status 1 if any shader fails.\n\n"
           "  --backend B   GL backend (default egl, falling back to osmesa)\n"
           CLI_LOG_HELP
           "  --emit DIR    compile nothing: write each variant's whole source, as the\n"
           "                driver is given it (includes and defines in place), to\n"
           "                DIR/NAME.VARIANT.EXT, for another compiler (the tests run\n"
           "                the Khronos reference compiler, glslangValidator, on them)\n");
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* --emit: every variant's source, expanded, to dir/NAME.VARIANT.EXT; frees names */
static int emit_all(const char *root, char **names, int n, const char *dir, bool quiet)
{
    int failed = 0, written = 0;
    for (int i = 0; i < n; i++) {
        char *vars = r_shader_variants(root, names[i]);
        const char *v = vars ? vars : "-";
        char defs[512], var[128];
        const char *dot = strrchr(names[i], '.');
        int base = dot ? (int)(dot - names[i]) : (int)strlen(names[i]);
        while (r_shader_next_variant(&v, defs, sizeof defs, var, sizeof var)) {
            char path[1400];
            snprintf(path, sizeof path, "%s/%.*s.%s%s", dir, base, names[i], strcmp(var, "-") ? var : "default",
                     dot ? dot : "");
            r_src src = {0};
            rs_err err = {0};
            FILE *f = NULL;
            bool ok = r_src_build(&src, root, names[i], defs[0] ? defs : NULL, &err) && (f = fopen(path, "w")) &&
                      fwrite(src.text, 1, src.len, f) == src.len;
            if (f && fclose(f) != 0)
                ok = false;
            if (!ok) {
                failed++;
                printf("FAILED  %s: %s\n", path, err.msg[0] ? err.msg : "cannot write");
            } else {
                written++;
                if (!quiet)
                    printf("wrote   %s\n", path);
            }
            r_src_free(&src);
        }
        free(vars);
        free(names[i]);
    }
    printf("%d shader files, %d variants written to %s, %d failed\n", n, written, dir, failed);
    return failed ? RS_EXIT_FAIL : RS_EXIT_OK;
}

int cmd_shaders(int argc, char **argv)
{
    static const struct option opts[] = {{"backend", required_argument, 0, 'b'},
                                         {"help", no_argument, 0, 'h'},
                                         {"emit", required_argument, 0, 'e'},
                                         {0}};
    plat_desc d = {.hidden = true};
    bool quiet = !rs_log_on(RS_LOG_INFO);
    const char *emit = NULL;
    int c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'b': d.backend = optarg; break;
        case 'e': emit = optarg; break;
        case 'h': help(); return RS_EXIT_OK;
        default: return cli_bad_option("shaders", argv);
        }
    }
    if (optind < argc) {
        cli_error("shaders", "unexpected argument '%s'", argv[optind]);
        return cli_usage_error("shaders");
    }
    rs_err err = {0};
    const char *root = rs_data_dir(&err);
    if (!root) {
        cli_error("shaders", "%s", err.msg);
        return RS_EXIT_FAIL;
    }
    char dir[1100];
    snprintf(dir, sizeof dir, "%s/shaders", root);
    DIR *dp = opendir(dir);
    if (!dp) {
        cli_error("shaders", "%s: cannot open", dir);
        return RS_EXIT_FAIL;
    }
    char *names[512];
    int n = 0;
    struct dirent *de;
    while ((de = readdir(dp)) != NULL) {
        if (!r_shader_stage(de->d_name))
            continue;
        if (n == 512 || !(names[n] = strdup(de->d_name))) {
            cli_error("shaders", "%s: more than 512 shader files (or out of memory)", dir);
            for (int i = 0; i < n; i++)
                free(names[i]);
            closedir(dp);
            return RS_EXIT_FAIL;
        }
        n++;
    }
    closedir(dp);
    qsort(names, (size_t)n, sizeof names[0], by_name);
    if (emit)
        return emit_all(root, names, n, emit, quiet);

    plat *p = plat_create(&d, &err);
    if (!p) {
        cli_error("shaders", "%s", err.msg);
        for (int i = 0; i < n; i++)
            free(names[i]);
        return cli_plat_status(&err);
    }
    int failed = 0, compiled = 0;
    for (int i = 0; i < n; i++) {
        char shown[1200];
        rs_data_path(root, "shaders", shown, sizeof shown);
        char *vars = r_shader_variants(root, names[i]);
        const char *v = vars ? vars : "-";
        char defs[512], var[128];
        while (r_shader_next_variant(&v, defs, sizeof defs, var, sizeof var)) {
            char label[160] = "";
            if (vars)
                snprintf(label, sizeof label, " [%s]", var);
            char *log = NULL;
            GLuint sh = r_shader_compile(names[i], defs[0] ? defs : NULL, &log, &err);
            compiled++;
            if (sh) {
                if (!quiet)
                    printf("ok      %s/%s%s\n", shown, names[i], label);
                gl.DeleteShader(sh);
            } else {
                failed++;
                printf("FAILED  %s/%s%s\n%s", shown, names[i], label, log ? log : err.msg);
                if (!log)
                    putchar('\n');
            }
            free(log);
        }
        free(vars);
        free(names[i]);
    }
    printf("%d shader files, %d compiles, %d failed (%s, GL %d.%d)\n", n, compiled, failed, plat_backend_name(p), glcaps.major, glcaps.minor);
    plat_destroy(p);
    return failed ? RS_EXIT_FAIL : RS_EXIT_OK;
}
