/* A horizontal bar chart written as PNG, for benchmark results: one bar per
 * row with its label and value.  No plotting library; text uses the HUD's
 * 5x7 font. */
#ifndef RS_CHART_H
#define RS_CHART_H

#include <stdbool.h>

#include "rs_err.h"

typedef struct rs_bar {
    const char *label;
    double value;
    int highlight; /* 0 plain, 1 accent */
} rs_bar;

bool rs_chart_png(const char *path, const char *title, const char *unit, const rs_bar *bars, int n, rs_err *err);

#endif
