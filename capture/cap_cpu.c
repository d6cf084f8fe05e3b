/* The CPU side: the sequential path's downscale and colour conversion, the
 * same mathematics as shaders/cap_box.frag and cap_yuv.glsl (in double,
 * so results may differ from the GPU's float by a rounding step). */
#include <math.h>

#include "cap.h"

void cap_cpu_downscale(const uint8_t *src, int sw, int sh, uint8_t *dst, int w, int h)
{
    if (sw == 2 * w && sh == 2 * h) { /* exact 2x: integer mean of each 2x2 block, rounded */
        for (int y = 0; y < h; y++) {
            const uint8_t *r0 = src + (size_t)(sh - 1 - 2 * y) * sw * 4, *r1 = r0 - (size_t)sw * 4;
            uint8_t *o = dst + (size_t)y * w * 4;
            for (int x = 0; x < 4 * w; x++) {
                int i = (x / 4) * 8 + x % 4;
                o[x] = (uint8_t)((r0[i] + r0[i + 4] + r1[i] + r1[i + 4] + 2) >> 2);
            }
        }
        return;
    }
    cap_cpu_downscale_area(src, sw, sh, dst, w, h);
}

void cap_cpu_downscale_area(const uint8_t *src, int sw, int sh, uint8_t *dst, int w, int h)
{
    double sx = (double)sw / w, sy = (double)sh / h;
    for (int y = 0; y < h; y++) {
        double y0 = y * sy, y1 = y0 + sy; /* rows from the top */
        for (int x = 0; x < w; x++) {
            double x0 = x * sx, x1 = x0 + sx, acc[4] = {0, 0, 0, 0}, wsum = 0;
            for (int ty = (int)floor(y0); ty < y1 && ty < sh; ty++) {
                double wy = fmin(y1, ty + 1.0) - fmax(y0, (double)ty);
                const uint8_t *row = src + (size_t)(sh - 1 - ty) * sw * 4; /* source is bottom-up */
                for (int tx = (int)floor(x0); tx < x1 && tx < sw; tx++) {
                    double wgt = (fmin(x1, tx + 1.0) - fmax(x0, (double)tx)) * wy;
                    for (int k = 0; k < 4; k++)
                        acc[k] += row[tx * 4 + k] * wgt;
                    wsum += wgt;
                }
            }
            uint8_t *o = dst + ((size_t)y * w + x) * 4;
            for (int k = 0; k < 4; k++)
                o[k] = (uint8_t)lround(acc[k] / wsum);
        }
    }
}

static uint8_t u8(double v)
{
    long r = lround(v);
    return (uint8_t)(r < 0 ? 0 : r > 255 ? 255 : r);
}

void cap_cpu_rgba_to_i420(const uint8_t *rgba, int w, int h, uint8_t *out)
{
    uint8_t *py = out, *pcb = out + (size_t)w * h, *pcr = pcb + (size_t)(w / 2) * (h / 2);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const uint8_t *p = rgba + ((size_t)y * w + x) * 4;
            double l = (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
            py[(size_t)y * w + x] = u8(16 + 219 * l);
        }
    for (int y = 0; y < h / 2; y++)
        for (int x = 0; x < w / 2; x++) {
            double r = 0, g = 0, b = 0;
            for (int k = 0; k < 4; k++) {
                const uint8_t *p = rgba + ((size_t)(2 * y + k / 2) * w + 2 * x + k % 2) * 4;
                r += p[0], g += p[1], b += p[2];
            }
            r /= 4 * 255.0, g /= 4 * 255.0, b /= 4 * 255.0;
            double l = 0.2126 * r + 0.7152 * g + 0.0722 * b;
            pcb[(size_t)y * (w / 2) + x] = u8(128 + 224 * (b - l) / 1.8556);
            pcr[(size_t)y * (w / 2) + x] = u8(128 + 224 * (r - l) / 1.5748);
        }
}
