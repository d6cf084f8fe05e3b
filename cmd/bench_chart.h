/* A horizontal bar chart written as PNG, for benchmark results: one bar per
 * row with its label and value.  No plotting library; text uses the HUD's
 * 5x7 font.  It lives in the command layer, beside the benchmarks that are
 * its only users, because the font is the renderer's and util must not
 * include the renderer. */
#ifndef BENCH_CHART_H
#define BENCH_CHART_H

#include <stdbool.h>

#include "../runtime/util/rs_err.h"

typedef struct bench_bar {
    const char *label;
    double value;
    int highlight; /* 0 plain, 1 accent */
} bench_bar;

bool bench_chart_png(const char *path, const char *title, const char *unit, const bench_bar *bars, int n, rs_err *err);

#endif
