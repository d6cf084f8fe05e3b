#include "bench_chart.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/render/r_font.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_img.h"

typedef struct canvas {
    int w, h;
    uint8_t *px;
} canvas;

static void fill(canvas *c, int x, int y, int w, int h, const uint8_t rgb[3])
{
    for (int j = y; j < y + h; j++)
        for (int i = x; i < x + w; i++)
            if (i >= 0 && j >= 0 && i < c->w && j < c->h)
                memcpy(c->px + ((size_t)j * c->w + i) * 3, rgb, 3);
}

static void text(canvas *c, int x, int y, int scale, const char *s, const uint8_t rgb[3])
{
    for (; *s; s++, x += 6 * scale) {
        char ch = (char)toupper((unsigned char)*s);
        for (int g = 0; g < R_FONT_GLYPHS; g++) {
            if (r_font_glyphs[g].c != ch)
                continue;
            for (int row = 0; row < R_FONT_H; row++)
                for (int col = 0; col < R_FONT_W; col++)
                    if (r_font_glyphs[g].rows[row] & (0x10 >> col))
                        fill(c, x + col * scale, y + row * scale, scale, scale, rgb);
        }
    }
}

bool bench_chart_png(const char *path, const char *title, const char *unit, const bench_bar *bars, int n, rs_err *err)
{
    const int label_w = 230, bar_max = 460, row_h = 26, top = 48;
    canvas c = {label_w + bar_max + 120, top + n * row_h + 20, NULL};
    c.px = malloc((size_t)c.w * c.h * 3);
    if (!c.px)
        return rs_fail(err, 1, "%s: out of memory", path);
    static const uint8_t bg[3] = {250, 250, 247}, ink[3] = {30, 30, 35}, bar[3] = {110, 140, 190},
                         accent[3] = {215, 95, 45}, grid[3] = {220, 220, 215};
    fill(&c, 0, 0, c.w, c.h, bg);
    text(&c, 12, 12, 2, title, ink);
    double vmax = 0;
    for (int i = 0; i < n; i++)
        if (bars[i].value > vmax)
            vmax = bars[i].value;
    if (vmax <= 0)
        vmax = 1;
    for (int k = 1; k <= 4; k++) /* quarter grid lines */
        fill(&c, label_w + bar_max * k / 4, top - 6, 1, n * row_h + 6, grid);
    for (int i = 0; i < n; i++) {
        int y = top + i * row_h;
        text(&c, 12, y + 6, 2, bars[i].label, ink);
        int len = (int)(bar_max * bars[i].value / vmax + 0.5);
        fill(&c, label_w, y + 3, len > 1 ? len : 1, row_h - 6, bars[i].highlight ? accent : bar);
        char v[48];
        snprintf(v, sizeof v, "%.1f %s", bars[i].value, unit);
        text(&c, label_w + len + 6, y + 9, 1, v, ink);
    }
    bool ok = rs_mkdirs_for(path, err) && rs_png_write(path, c.w, c.h, 3, c.px, err);
    free(c.px);
    return ok;
}
