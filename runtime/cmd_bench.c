/* ringside bench: benchmarks that print ratios measured in one run.
 *
 *   bench platform   the headless backends side by side on the smoke scene:
 *                    context start-up, draw, draw + glReadPixels. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "gl/rgl.h"
#include "platform/plat.h"
#include "render/r_smoke.h"

static void help(void)
{
    printf("usage: ringside bench platform [--size WxH] [--frames N] [--runs N] [--csv FILE]\n\n"
           "Times every headless backend built in (egl, osmesa) in one run on the smoke\n"
           "scene: context start-up, draw (glFinish), and draw + full-frame glReadPixels.\n"
           "Each figure is the median over the runs; the ratio line compares backends\n"
           "measured side by side, which is what to trust on a noisy machine.\n\n"
           "  --size WxH    frame size (default 1280x720)\n"
           "  --frames N    frames per run (default 60)\n"
           "  --runs N      runs per backend (default 5)\n"
           "  --csv FILE    also write the table as CSV\n");
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

typedef struct result {
    const char *backend;
    double create_ms, draw_ms, read_ms;
    char renderer[128];
} result;

static bool bench_backend(const char *name, int w, int h, int frames, int runs, result *r, rs_err *err)
{
    memset(r, 0, sizeof *r);
    r->backend = name;
    double t0 = now_ms();
    plat *p = plat_create(&(plat_desc){.backend = name, .hidden = true}, err);
    if (!p)
        return false;
    r_smoke *s = r_smoke_create(w, h, err);
    if (!s) {
        plat_destroy(p);
        return false;
    }
    r->create_ms = now_ms() - t0;
    snprintf(r->renderer, sizeof r->renderer, "%s", glcaps.renderer);
    uint8_t *px = malloc((size_t)w * h * 4);
    double draw[64], rd[64];
    r_smoke_draw(s); /* warm-up: shader JIT, first allocation */
    gl.Finish();
    for (int run = 0; run < runs; run++) {
        t0 = now_ms();
        for (int f = 0; f < frames; f++) {
            r_smoke_draw(s);
            gl.Finish();
        }
        draw[run] = (now_ms() - t0) / frames;
        t0 = now_ms();
        for (int f = 0; f < frames; f++) {
            r_smoke_draw(s);
            r_smoke_read(s, px);
        }
        rd[run] = (now_ms() - t0) / frames;
    }
    r->draw_ms = median(draw, runs);
    r->read_ms = median(rd, runs);
    free(px);
    r_smoke_destroy(s);
    plat_destroy(p);
    return true;
}

int cmd_bench(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        help();
        return argc < 2 ? RS_EXIT_USAGE : RS_EXIT_OK;
    }
    if (strcmp(argv[1], "platform") != 0) {
        cli_error("bench", "unknown benchmark '%s' (expected: platform)", argv[1]);
        return RS_EXIT_USAGE;
    }
    static const struct option opts[] = {{"size", required_argument, 0, 's'},  {"frames", required_argument, 0, 'f'},
                                         {"runs", required_argument, 0, 'r'},  {"csv", required_argument, 0, 'c'},
                                         {"help", no_argument, 0, 'h'},        {0}};
    int w = 1280, h = 720, c;
    long frames = 60, runs = 5;
    const char *csv = NULL;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc - 1, argv + 1, "h", opts, NULL)) != -1) {
        switch (c) {
        case 's':
            if (!cli_size("--size", optarg, 8192, &w, &h))
                return RS_EXIT_USAGE;
            break;
        case 'f':
            if (!cli_int("--frames", optarg, 1, 100000, &frames))
                return RS_EXIT_USAGE;
            break;
        case 'r':
            if (!cli_int("--runs", optarg, 1, 64, &runs))
                return RS_EXIT_USAGE;
            break;
        case 'c': csv = optarg; break;
        case 'h': help(); return RS_EXIT_OK;
        default:
            cli_error("bench", "bad option or missing value '%s'", argv[optind]);
            return cli_usage_error("bench");
        }
    }
    if (w < R_SMOKE_MIN_SIZE || h < R_SMOKE_MIN_SIZE) {
        cli_error("bench", "--size %dx%d: each side must be at least %d", w, h, R_SMOKE_MIN_SIZE);
        return RS_EXIT_USAGE;
    }
    static const char *const names[] = {"egl", "osmesa"};
    result res[2];
    int nres = 0;
    printf("bench platform: smoke scene %dx%d, %ld frames x %ld runs, medians\n", w, h, frames, runs);
    printf("%-8s %10s %14s %19s %8s  %s\n", "backend", "create ms", "draw ms/frame", "draw+read ms/frame", "fps",
           "renderer");
    for (int i = 0; i < 2; i++) {
        if (!plat_backend_built(names[i]))
            continue;
        rs_err err = {0};
        if (!bench_backend(names[i], w, h, (int)frames, (int)runs, &res[nres], &err)) {
            printf("%-8s unavailable: %s\n", names[i], err.msg);
            continue;
        }
        result *r = &res[nres++];
        printf("%-8s %10.1f %14.3f %19.3f %8.1f  %s\n", r->backend, r->create_ms, r->draw_ms, r->read_ms,
               1000.0 / r->read_ms, r->renderer);
    }
    if (nres == 2)
        printf("ratio osmesa/egl: draw %.2f, draw+read %.2f (>1: osmesa slower)\n", res[1].draw_ms / res[0].draw_ms,
               res[1].read_ms / res[0].read_ms);
    if (csv) {
        FILE *f = fopen(csv, "w");
        if (!f) {
            cli_error("bench", "%s: cannot create", csv);
            return RS_EXIT_FAIL;
        }
        fprintf(f, "backend,width,height,frames,runs,create_ms,draw_ms,draw_read_ms,fps,renderer\n");
        for (int i = 0; i < nres; i++)
            fprintf(f, "%s,%d,%d,%ld,%ld,%.3f,%.4f,%.4f,%.2f,\"%s\"\n", res[i].backend, w, h, frames, runs,
                    res[i].create_ms, res[i].draw_ms, res[i].read_ms, 1000.0 / res[i].read_ms, res[i].renderer);
        if (fclose(f) != 0) {
            cli_error("bench", "%s: write failed", csv);
            return RS_EXIT_FAIL;
        }
    }
    return nres ? RS_EXIT_OK : RS_EXIT_FAIL;
}
