/* Benchmark bar charts with cairo (see bench_chart.h).
 *
 * DESIGN: one function draws the chart on any cairo surface, so the PNG
 * (an image surface, encoded by rs_png_write at the project's level) and
 * the SVG (cairo's SVG surface, kept in memory) are the same drawing.
 * Cairo's SVG surface turns text into glyph outlines, which no search or
 * screen reader can read, so the chart's words also go into the SVG's
 * <title> and <desc>.  Text uses cairo's toy font API, which asks
 * fontconfig for "DejaVu Sans" (fonts-dejavu-core, tools/deps.sh) and takes
 * its nearest match when that is missing.  Both files are written as
 * "<name>.part" and renamed, like every other output. */
#include "bench_chart.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_img.h"
#include "job_err.h"

#ifdef RS_HAVE_CAIRO
#include <cairo-svg.h>
#include <cairo.h>
#endif

#define CHART_MAX_BARS 64

bool bench_chart_check(const char *path, rs_err *err)
{
    char svg[1100];
    if (!bench_chart_svg_path(path, svg, sizeof svg))
        return rs_fail(err, JOB_ERR_CHART, "%s: a chart is written as .png (and .svg beside it)", path);
#ifdef RS_HAVE_CAIRO
    return true;
#else
    return rs_fail(err, JOB_ERR_CHART, "%s: this build has no cairo, so no charts (install libcairo2-dev and rebuild, or give --chart '')",
                   path);
#endif
}

bool bench_chart_svg_path(const char *path, char *out, size_t n)
{
    size_t len = strlen(path);
    if (len < 5 || strcasecmp(path + len - 4, ".png") != 0 || len + 1 > n)
        return false;
    memcpy(out, path, len - 4);
    memcpy(out + len - 4, ".svg", 5);
    return true;
}

#ifdef RS_HAVE_CAIRO

/* Sizes in pixels, in the SVG too; W and the height (TOP + ROW a bar +
 * 50) are bench_chart.h's promise. */
enum { W = 880, MARGIN = 16, TOP = 58, ROW = 26, BAR = 18, RIGHT = 96, TITLE_PT = 18, TEXT_PT = 12, TICK_PT = 11 };

typedef struct layout {
    double x0, x1, y0, y1; /* the plot area: bars start at x0, the axis maximum is at x1 */
    double vmax, step;     /* axis maximum and tick step, both "nice" numbers */
    int h;
} layout;

static const double BG[3] = {0.98, 0.98, 0.97}, INK[3] = {0.12, 0.12, 0.14}, MUTED[3] = {0.40, 0.40, 0.43},
                    GRID[3] = {0.86, 0.86, 0.84}, BARC[3] = {0.43, 0.55, 0.75}, ACCENT[3] = {0.84, 0.37, 0.18};

static void colour(cairo_t *cr, const double c[3])
{
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
}

static void font(cairo_t *cr, double size, bool bold)
{
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
}

static double text_w(cairo_t *cr, const char *s)
{
    cairo_text_extents_t e;
    cairo_text_extents(cr, s, &e);
    return e.x_advance;
}

/* align: 0 left, 1 centre, 2 right of x; y is the baseline */
static void text_at(cairo_t *cr, double x, double y, int align, const char *s)
{
    cairo_move_to(cr, x - text_w(cr, s) * align / 2.0, y);
    cairo_show_text(cr, s);
}

/* 1, 2 or 5 times a power of ten, so about five ticks cover vmax */
static double nice_step(double vmax)
{
    double raw = vmax / 5, mag = pow(10, floor(log10(raw))), f = raw / mag;
    return (f <= 1 ? 1 : f <= 2 ? 2 : f <= 5 ? 5 : 10) * mag;
}

static layout measure(cairo_t *cr, const bench_chart *c)
{
    layout l = {0};
    font(cr, TEXT_PT, false);
    double label_w = 0;
    for (int i = 0; i < c->n; i++) {
        double w = text_w(cr, c->bars[i].label);
        label_w = w > label_w ? w : label_w;
    }
    double vmax = 0;
    for (int i = 0; i < c->n; i++)
        vmax = c->bars[i].value > vmax ? c->bars[i].value : vmax;
    l.step = nice_step(vmax > 0 ? vmax : 1);
    l.vmax = ceil((vmax > 0 ? vmax : 1) / l.step) * l.step;
    l.x0 = MARGIN + label_w + 12;
    l.x1 = W - RIGHT;
    l.y0 = TOP;
    l.y1 = TOP + c->n * ROW;
    l.h = (int)l.y1 + 50;
    return l;
}

static void draw(cairo_t *cr, const layout *l, const bench_chart *c)
{
    colour(cr, BG);
    cairo_paint(cr);
    colour(cr, INK);
    font(cr, TITLE_PT, true);
    text_at(cr, MARGIN, 30, 0, c->title);

    /* grid and ticks at every step, labels below the axis */
    font(cr, TICK_PT, false);
    cairo_set_line_width(cr, 1);
    for (int k = 0; k * l->step <= l->vmax + l->step * 1e-9; k++) {
        double v = k * l->step, x = floor(l->x0 + (l->x1 - l->x0) * v / l->vmax) + 0.5;
        colour(cr, GRID);
        cairo_move_to(cr, x, l->y0 - 6);
        cairo_line_to(cr, x, l->y1);
        cairo_stroke(cr);
        colour(cr, INK);
        cairo_move_to(cr, x, l->y1);
        cairo_line_to(cr, x, l->y1 + 5);
        cairo_stroke(cr);
        char s[32];
        snprintf(s, sizeof s, "%g", v);
        colour(cr, MUTED);
        text_at(cr, x, l->y1 + 18, 1, s);
    }
    colour(cr, INK); /* the axes */
    cairo_move_to(cr, floor(l->x0) + 0.5, l->y0 - 6);
    cairo_line_to(cr, floor(l->x0) + 0.5, floor(l->y1) + 0.5);
    cairo_line_to(cr, floor(l->x1) + 0.5, floor(l->y1) + 0.5);
    cairo_stroke(cr);
    font(cr, TEXT_PT, false);
    text_at(cr, (l->x0 + l->x1) / 2, l->y1 + 38, 1, c->axis);

    for (int i = 0; i < c->n; i++) {
        double y = l->y0 + i * ROW, len = (l->x1 - l->x0) * c->bars[i].value / l->vmax;
        colour(cr, INK);
        text_at(cr, l->x0 - 8, y + ROW / 2.0 + 4, 2, c->bars[i].label);
        colour(cr, c->bars[i].highlight ? ACCENT : BARC);
        cairo_rectangle(cr, l->x0 + 1, y + (ROW - BAR) / 2.0, len > 1 ? len : 1, BAR);
        cairo_fill(cr);
        char v[64];
        snprintf(v, sizeof v, c->unit && *c->unit ? "%.1f %s" : "%.1f", c->bars[i].value, c->unit);
        colour(cr, INK);
        text_at(cr, l->x0 + 1 + len + 6, y + ROW / 2.0 + 4, 0, v);
    }
}

static bool write_png(const char *path, const layout *l, const bench_chart *c, rs_err *err)
{
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, l->h);
    cairo_t *cr = cairo_create(s);
    draw(cr, l, c);
    cairo_status_t st = cairo_status(cr);
    cairo_destroy(cr);
    cairo_surface_flush(s);
    uint8_t *rgb = st == CAIRO_STATUS_SUCCESS ? malloc((size_t)W * l->h * 3) : NULL;
    bool ok = rgb != NULL;
    if (ok) { /* RGB24 is one native-endian 0x00RRGGBB word a pixel */
        const uint8_t *data = cairo_image_surface_get_data(s);
        int stride = cairo_image_surface_get_stride(s);
        for (int y = 0; y < l->h; y++)
            for (int x = 0; x < W; x++) {
                uint32_t p;
                memcpy(&p, data + (size_t)y * stride + (size_t)x * 4, 4);
                uint8_t *o = rgb + ((size_t)y * W + x) * 3;
                o[0] = (uint8_t)(p >> 16);
                o[1] = (uint8_t)(p >> 8);
                o[2] = (uint8_t)p;
            }
        ok = rs_png_write(path, W, l->h, 3, rgb, err);
    } else {
        rs_fail(err, JOB_ERR_CHART, "%s: cairo: %s", path, st != CAIRO_STATUS_SUCCESS ? cairo_status_to_string(st) : "out of memory");
    }
    free(rgb);
    cairo_surface_destroy(s);
    return ok;
}

typedef struct mem {
    char *p;
    size_t n, cap;
} mem;

static bool mem_put(mem *m, const char *d, size_t n)
{
    if (n > m->cap - m->n) {
        size_t cap = m->cap ? m->cap : 1 << 15;
        while (cap - m->n < n)
            cap *= 2;
        char *p = realloc(m->p, cap);
        if (!p)
            return false;
        m->p = p;
        m->cap = cap;
    }
    memcpy(m->p + m->n, d, n);
    m->n += n;
    return true;
}

static cairo_status_t svg_out(void *closure, const unsigned char *d, unsigned int n)
{
    return mem_put(closure, (const char *)d, n) ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_NO_MEMORY;
}

static bool put_escaped(mem *m, const char *s)
{
    bool ok = true;
    for (; *s && ok; s++)
        ok = *s == '<' ? mem_put(m, "&lt;", 4) : *s == '>' ? mem_put(m, "&gt;", 4) : *s == '&' ? mem_put(m, "&amp;", 5)
                                                                                              : mem_put(m, s, 1);
    return ok;
}

/* <title> and <desc> (the title, the axis, one "label: value unit" a bar),
 * escaped, for the text that cairo wrote as outlines */
static bool svg_words(mem *m, const bench_chart *c)
{
    bool ok = mem_put(m, "<title>", 7) && put_escaped(m, c->title) && mem_put(m, "</title>\n<desc>", 15) &&
              put_escaped(m, c->axis);
    for (int i = 0; ok && i < c->n; i++) {
        char v[64];
        snprintf(v, sizeof v, c->unit && *c->unit ? ": %.1f %s" : ": %.1f", c->bars[i].value, c->unit);
        ok = mem_put(m, "; ", 2) && put_escaped(m, c->bars[i].label) && put_escaped(m, v);
    }
    return ok && mem_put(m, "</desc>\n", 8);
}

static bool write_svg(const char *path, const layout *l, const bench_chart *c, rs_err *err)
{
    mem drawn = {0}, out = {0};
    cairo_surface_t *s = cairo_svg_surface_create_for_stream(svg_out, &drawn, W, l->h);
    cairo_svg_surface_set_document_unit(s, CAIRO_SVG_UNIT_PX); /* the PNG's size, not points */
    cairo_t *cr = cairo_create(s);
    draw(cr, l, c);
    cairo_destroy(cr);
    cairo_surface_finish(s);
    cairo_status_t st = cairo_surface_status(s);
    cairo_surface_destroy(s);
    bool ok = false;
    const char *root = st == CAIRO_STATUS_SUCCESS && mem_put(&drawn, "", 1) ? strstr(drawn.p, "<svg") : NULL;
    const char *end = root ? strchr(root, '>') : NULL;
    if (!end)
        rs_fail(err, JOB_ERR_CHART, "%s: cairo: %s", path,
                st != CAIRO_STATUS_SUCCESS ? cairo_status_to_string(st) : "no <svg> element in its output");
    else if (!mem_put(&out, drawn.p, (size_t)(end + 1 - drawn.p)) || !mem_put(&out, "\n", 1) || !svg_words(&out, c) ||
             !mem_put(&out, end + 1, drawn.n - 1 - (size_t)(end + 1 - drawn.p)))
        rs_fail(err, JOB_ERR_NOMEM, "%s: out of memory", path);
    else
        ok = rs_write_part(path, out.p, out.n, err) && rs_commit_file(path, err);
    free(drawn.p);
    free(out.p);
    return ok;
}

bool bench_chart_write(const char *path, const bench_chart *c, rs_err *err)
{
    char svg[1100];
    if (!bench_chart_check(path, err))
        return false;
    bench_chart_svg_path(path, svg, sizeof svg);
    if (c->n < 1 || c->n > CHART_MAX_BARS)
        return rs_fail(err, JOB_ERR_CHART, "%s: %d bars (expected 1..%d)", path, c->n, CHART_MAX_BARS);
    cairo_surface_t *probe = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1, 1);
    cairo_t *cr = cairo_create(probe);
    layout l = measure(cr, c);
    cairo_destroy(cr);
    cairo_surface_destroy(probe);
    return rs_mkdirs_for(path, err) && write_png(path, &l, c, err) && write_svg(svg, &l, c, err);
}

#else

bool bench_chart_write(const char *path, const bench_chart *c, rs_err *err)
{
    (void)c;
    return bench_chart_check(path, err);
}

#endif
