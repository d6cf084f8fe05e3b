/* YCbCr -> RGB for the movie shader: the matrix and range maths, after
 * mpv's csputils (mp_get_csp_matrix): the BT.601 / BT.709 luma weights
 * (Kr, Kb) give the inverse matrix; the range says where black, white and
 * zero chroma sit in 8-bit code values (limited: Y 16..235, C 16..240
 * around 128; full: Y 0..255, C 0..255 around 128).
 *
 * For a texture sample s = code / 255 the shader computes
 *     rgb = m * (s - offset)
 * with m column-major (GL's order), so the range scaling is folded into m. */
#ifndef MV_CSP_H
#define MV_CSP_H

#include <stdbool.h>

typedef struct mv_csp {
    float m[9];      /* column-major 3x3 */
    float offset[3]; /* in sample units (code / 255) */
} mv_csp;

void mv_csp_make(int matrix, bool full_range, mv_csp *out);
/* The same maths on the CPU, in double: 8-bit code values in, RGB 0..1
 * (unclamped) out.  The tests' reference. */
void mv_csp_apply(const mv_csp *c, double y, double cb, double cr, double rgb[3]);
/* The forward matrix (RGB 0..1 -> code values), for tests. */
void mv_csp_forward(int matrix, bool full_range, const double rgb[3], double ycc[3]);
const char *mv_matrix_name(int matrix);

#endif
