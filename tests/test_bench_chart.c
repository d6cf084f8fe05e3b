/* cmd/bench_chart: the benchmarks' bar charts (cairo), PNG and SVG. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../cmd/bench_chart.h"
#include "../cmd/job_err.h"
#include "../runtime/util/rs_oiio.h"
#include "t.h"

static const bench_bar bars[] = {{"sequential", 76.9, 1}, {"async pbo2 q8", 96.3, 0}, {"render-only", 178.2, 0}};
static const bench_chart chart = {"capture fps, 1280x720 to 640x360, mp4", "frames per second (fps)", "fps", bars, 3};

#ifdef RS_HAVE_CAIRO
/* pixels in [x0,x1) x [y0,y1) that are not the background; *grey counts
 * those between background and ink in every channel (antialiased edges) */
static int inked(const float *rgb, int w, int x0, int y0, int x1, int y1, int *grey)
{
    int n = 0;
    *grey = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            const float *p = rgb + ((size_t)y * w + x) * 3;
            bool bg = fabsf(p[0] - 250 / 255.0f) < 0.01f && fabsf(p[1] - 250 / 255.0f) < 0.01f &&
                      fabsf(p[2] - 247 / 255.0f) < 0.01f;
            n += !bg;
            *grey += !bg && p[0] > 0.2f && p[0] < 0.9f && fabsf(p[0] - p[1]) < 0.05f;
        }
    return n;
}

static void t_png_and_svg(void)
{
    char png[512], svg[512];
    snprintf(png, sizeof png, "%s/c.png", t_tmpdir());
    rs_err e = {0};
    T_ASSERTF(bench_chart_write(png, &chart, &e), "%s", e.msg);
    T_ASSERT(bench_chart_svg_path(png, svg, sizeof svg));
    T_ASSERT(access(svg, F_OK) == 0);

    /* the SVG is XML with the title and the axis' unit in it */
    char cmd[1400];
    snprintf(cmd, sizeof cmd,
             "python3 -c 'import sys, xml.etree.ElementTree as E\n"
             "r = E.parse(sys.argv[1]).getroot(); ns = \"{http://www.w3.org/2000/svg}\"\n"
             "assert r.tag == ns + \"svg\" and r.get(\"width\") == \"880px\", (r.tag, r.attrib)\n"
             "assert r.find(ns + \"title\").text == sys.argv[2], r.find(ns + \"title\").text\n"
             "d = r.find(ns + \"desc\").text\n"
             "assert \"frames per second (fps)\" in d and \"render-only: 178.2 fps\" in d, d' '%s' '%s'",
             svg, chart.title);
    if (system("command -v python3 >/dev/null 2>&1") != 0)
        T_SKIP_INSTALL("no python3 to parse the SVG");
    T_ASSERTF(system(cmd) == 0, "%s: not the chart's SVG", svg);

    int w = 0, h = 0;
    float *rgb = NULL;
    if (!rs_oiio_read_float(png, &w, &h, &rgb, &e))
        T_SKIP_INSTALL("%s", e.msg); /* no OpenImageIO to read it back */
    T_EQ(w, 880);
    T_EQ(h, 108 + 26 * 3);
    int grey, n;
    n = inked(rgb, w, 16, 10, 400, 36, &grey); /* the title */
    T_ASSERTF(n > 300 && grey > 20, "title area: %d inked pixels, %d antialiased", n, grey);
    n = inked(rgb, w, 300, h - 24, 560, h - 8, &grey); /* the value axis' label, centred below */
    T_ASSERTF(n > 100 && grey > 10, "axis label area: %d inked pixels, %d antialiased", n, grey);
    n = inked(rgb, w, 0, h - 6, w, h, &grey); /* the bottom margin stays empty */
    T_EQ(n, 0);
    free(rgb);
}
#endif

static void t_refusals(void)
{
    char path[512];
    rs_err e = {0};
    snprintf(path, sizeof path, "%s/c.jpg", t_tmpdir());
    T_ASSERT(!bench_chart_check(path, &e));
    T_CONTAINS(e.msg, "c.jpg: a chart is written as .png");
    T_ASSERT(!bench_chart_write(path, &chart, &e));
    T_ASSERT(access(path, F_OK) != 0);
    snprintf(path, sizeof path, "%s/c.png", t_tmpdir());
#ifdef RS_HAVE_CAIRO
    bench_chart none = {"t", "x", NULL, bars, 0};
    T_ASSERT(!bench_chart_write(path, &none, &e));
    T_CONTAINS(e.msg, "0 bars (expected 1..64)");
#else
    T_ASSERT(!bench_chart_check(path, &e));
    T_CONTAINS(e.msg, "this build has no cairo");
#endif
    T_ASSERT(access(path, F_OK) != 0);
}

/* The command layer's ids (cmd/job_err.h): every one has a text of its
 * own and belongs to the "job" block, as the chart's refusals do. */
static void t_job_error_ids(void)
{
    T_EQ(RS_ERR_MODULE(JOB_ERR_BASE + 1), RS_ERR_MOD_JOB);
    T_EQ(RS_ERR_MODULE(JOB_ERR_END - 1), RS_ERR_MOD_JOB);
    for (int a = JOB_ERR_BASE + 1; a < JOB_ERR_END; a++) {
        const char *t = job_error_text(a);
        T_ASSERTF(t[0] && strcmp(t, "?") && strcmp(t, "ok"), "id %d has no text", a);
        T_ASSERTF(!strcmp(rs_err_module_name(a), "job"), "id %d is in module %s", a, rs_err_module_name(a));
        for (int b = JOB_ERR_BASE + 1; b < a; b++)
            T_ASSERTF(strcmp(t, job_error_text(b)), "ids %d and %d share the text \"%s\"", b, a, t);
    }
    T_ASSERT(!strcmp(job_error_text(JOB_ERR_END), "?"));
    T_ASSERT(!strcmp(job_error_text(0), "ok"));
    rs_err e = {0};
    char path[512];
    snprintf(path, sizeof path, "%s/c.jpg", t_tmpdir());
    T_ASSERT(!bench_chart_check(path, &e));
    T_EQ(e.code, JOB_ERR_CHART);
}

T_MAIN(
    {"job_error_ids", t_job_error_ids},
#ifdef RS_HAVE_CAIRO
    {"png_and_svg", t_png_and_svg},
#endif
    {"refusals", t_refusals})
