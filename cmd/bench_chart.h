/* Horizontal bar charts for benchmark results, drawn with cairo: a title,
 * one labelled bar per row with its value at the end, a value axis with
 * ticks, grid lines and a label naming the unit.  Written as PNG (through
 * rs_png_write) and, beside it, the same drawing as SVG for the docs.
 * A build without cairo (configure did not find it) refuses with a message
 * naming the library; the benchmarks' CSV files do not depend on it. */
#ifndef BENCH_CHART_H
#define BENCH_CHART_H

#include <stdbool.h>

#include "../runtime/util/rs_err.h"

typedef struct bench_bar {
    const char *label;
    double value;
    int highlight; /* 0 plain, 1 accent */
} bench_bar;

typedef struct bench_chart {
    const char *title;
    const char *axis; /* the value axis' label, unit included: "frames per second (fps)" */
    const char *unit; /* after each bar's value ("fps"); NULL: none */
    const bench_bar *bars;
    int n; /* 1..64 bars */
} bench_chart;

/* Whether a chart can be written to path: a .png name and a build with
 * cairo; the message names the problem. */
bool bench_chart_check(const char *path, rs_err *err);

/* Writes path, which must end in .png, and the same chart as SVG beside it
 * (x.png -> x.svg): 880 pixels wide, 108 + 26 a bar high.  Each file
 * appears only when complete. */
bool bench_chart_write(const char *path, const bench_chart *c, rs_err *err);

/* "x.png" -> "x.svg" in out (n bytes); false when path does not end in .png */
bool bench_chart_svg_path(const char *path, char *out, size_t n);

#endif
