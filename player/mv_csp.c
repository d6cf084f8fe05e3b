/* YCbCr <-> RGB maths (see mv_csp.h). */
#include "mv_csp.h"

#include "mv.h"

static void weights(int matrix, double *kr, double *kb)
{
    if (matrix == MV_BT709) {
        *kr = 0.2126;
        *kb = 0.0722;
    } else {
        *kr = 0.299;
        *kb = 0.114;
    }
}

/* Code-value levels: black, white (Y) and the chroma excursion. */
static void levels(bool full, double *ymin, double *ymax, double *crange)
{
    if (full) {
        *ymin = 0;
        *ymax = 255;
        *crange = 255;
    } else {
        *ymin = 16;
        *ymax = 235;
        *crange = 224;
    }
}

void mv_csp_make(int matrix, bool full_range, mv_csp *out)
{
    double kr, kb, kg, ymin, ymax, crange;
    weights(matrix, &kr, &kb);
    kg = 1.0 - kr - kb;
    levels(full_range, &ymin, &ymax, &crange);
    /* normalised Y' in 0..1, Cb Cr in -0.5..0.5 -> RGB (rows) */
    double k[3][3] = {
        {1, 0, 2 * (1 - kr)},
        {1, -2 * kb * (1 - kb) / kg, -2 * kr * (1 - kr) / kg},
        {1, 2 * (1 - kb), 0},
    };
    /* sample (code/255) -> normalised: (s - o) * scale */
    double scale[3] = {255.0 / (ymax - ymin), 255.0 / crange, 255.0 / crange};
    for (int col = 0; col < 3; col++)
        for (int row = 0; row < 3; row++)
            out->m[col * 3 + row] = (float)(k[row][col] * scale[col]);
    out->offset[0] = (float)(ymin / 255.0);
    out->offset[1] = out->offset[2] = (float)(128.0 / 255.0);
}

void mv_csp_apply(const mv_csp *c, double y, double cb, double cr, double rgb[3])
{
    double s[3] = {y / 255.0 - c->offset[0], cb / 255.0 - c->offset[1], cr / 255.0 - c->offset[2]};
    for (int row = 0; row < 3; row++)
        rgb[row] = c->m[row] * s[0] + c->m[3 + row] * s[1] + c->m[6 + row] * s[2];
}

void mv_csp_forward(int matrix, bool full_range, const double rgb[3], double ycc[3])
{
    double kr, kb, ymin, ymax, crange;
    weights(matrix, &kr, &kb);
    levels(full_range, &ymin, &ymax, &crange);
    double y = kr * rgb[0] + (1 - kr - kb) * rgb[1] + kb * rgb[2];
    double cb = (rgb[2] - y) / (2 * (1 - kb)), cr = (rgb[0] - y) / (2 * (1 - kr));
    ycc[0] = ymin + y * (ymax - ymin);
    ycc[1] = 128 + cb * crange;
    ycc[2] = 128 + cr * crange;
}

const char *mv_matrix_name(int matrix)
{
    return matrix == MV_BT709 ? "BT.709" : "BT.601";
}
