/* ringside info: what GL context this machine gives us. */
#include <getopt.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"

static void help(void)
{
    printf("usage: ringside info [--backend egl|osmesa|glfw] [--debug] [-q|-v]\n\n"
           "Creates a GL context and prints the backend, GL vendor, renderer, version,\n"
           "GLSL version, max texture size and which optional features exist.\n\n"
           "  --backend B   egl (headless), osmesa (software) or glfw (window, needs X);\n"
           "                default: egl, falling back to osmesa\n"
           "  --debug       ask for a debug context (KHR_debug messages on stderr)\n"
           CLI_LOG_HELP);
}

static const char *yn(bool b)
{
    return b ? "yes" : "no";
}

int cmd_info(int argc, char **argv)
{
    static const struct option opts[] = {
        {"backend", required_argument, 0, 'b'}, {"debug", no_argument, 0, 'd'}, {"help", no_argument, 0, 'h'}, {0}};
    plat_desc d = {.hidden = true, .width = 64, .height = 64};
    int c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'b': d.backend = optarg; break;
        case 'd': d.debug = true; break;
        case 'h': help(); return RS_EXIT_OK;
        default: return cli_bad_option("info", argv);
        }
    }
    if (optind < argc) {
        cli_error("info", "unexpected argument '%s'", argv[optind]);
        return cli_usage_error("info");
    }
    rs_err err = {0};
    plat *p = plat_create(&d, &err);
    if (!p) {
        cli_error("info", "%s", err.msg);
        return cli_plat_status(&err);
    }
    if (plat_fallback_reason(p)[0] && rs_log_on(RS_LOG_WARNING))
        fprintf(stderr, "ringside info: egl unavailable, using %s: %s\n", plat_backend_name(p), plat_fallback_reason(p));
    printf("backend         %s (%s)\n", plat_backend_name(p), plat_detail(p));
    printf("vendor          %s\n", glcaps.vendor);
    printf("renderer        %s\n", glcaps.renderer);
    printf("version         %s\n", glcaps.version);
    printf("context         %d.%d %s%s\n", glcaps.major, glcaps.minor, glcaps.core ? "core" : "compatibility",
           glcaps.debug_ctx ? " debug" : "");
    printf("glsl            %s\n", glcaps.glsl);
    printf("max texture     %d\n", glcaps.max_texture_size);
    printf("float targets   %s\n", yn(glcaps.float_rt));
    printf("fences          %s\n", yn(glcaps.fences));
    printf("timer queries   %s\n", yn(glcaps.timer_query));
    printf("buffer storage  %s\n", yn(glcaps.buffer_storage));
    printf("texture storage %s\n", yn(glcaps.texture_storage));
    printf("KHR_debug       %s\n", yn(glcaps.khr_debug));
    printf("built backends  %s\n", plat_built_backends());
    plat_destroy(p);
    return RS_EXIT_OK;
}
