/* Snow's procedural textures (fx_snow_tex.h): value noise, no files. */
#include "fx_snow_tex.h"

#include <math.h>
#include <stddef.h>

#include "../util/rs_hash.h"

static float lattice(int x, int y, int period, uint32_t seed)
{
    if (period > 0) /* a tiling texture: the lattice wraps */
        x = (x % period + period) % period, y = (y % period + period) % period;
    return (float)(rs_hash_point((uint32_t)x, (uint32_t)y, seed) & 0xffff) / 65535.0f;
}

/* Smooth value noise in 0..1 at (x, y) in lattice cells; period > 0 makes
 * it tile every `period` cells. */
static float vnoise(float x, float y, int period, uint32_t seed)
{
    float fx = floorf(x), fy = floorf(y);
    int ix = (int)fx, iy = (int)fy;
    float tx = x - fx, ty = y - fy;
    tx = tx * tx * (3 - 2 * tx), ty = ty * ty * (3 - 2 * ty);
    float a = lattice(ix, iy, period, seed), b = lattice(ix + 1, iy, period, seed);
    float c = lattice(ix, iy + 1, period, seed), d = lattice(ix + 1, iy + 1, period, seed);
    return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

/* Rescales h[0..count) onto lo..hi exactly (a flat field lands on lo). */
static void fit(float *h, size_t count, float lo, float hi)
{
    float mn = h[0], mx = h[0];
    for (size_t i = 1; i < count; i++)
        mn = fminf(mn, h[i]), mx = fmaxf(mx, h[i]);
    float k = mx > mn ? (hi - lo) / (mx - mn) : 0;
    for (size_t i = 0; i < count; i++)
        h[i] = fminf(fmaxf(lo + (h[i] - mn) * k, lo), hi);
}

void fx_snow_tex_untouched(float *h, int n, float half)
{
    const float pi = 3.14159265f;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            float x = -half + ((float)i + 0.5f) * 2 * half / (float)n;
            float z = -half + ((float)j + 0.5f) * 2 * half / (float)n;
            /* drifts: metre-scale swells, half-metre lumps on top */
            float drift = vnoise(x / 1.6f + 17, z / 1.6f + 5, 0, 11) * 0.6f + vnoise(x / 0.55f, z / 0.55f, 0, 12) * 0.25f;
            /* wind ripples across the ring, their crests wavering */
            float phase = (x * 0.8f + z * 0.6f) / 0.45f * 2 * pi + vnoise(x / 1.2f, z / 1.2f, 0, 13) * 6;
            float ripple = (sinf(phase) * 0.5f + 0.5f) * 0.15f;
            h[(size_t)j * n + i] = drift + ripple;
        }
    fit(h, (size_t)n * n, R_SNOW_UNTOUCHED_LO, R_SNOW_UNTOUCHED_HI);
}

void fx_snow_tex_trampled(float *h, int n, float half)
{
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            float x = -half + ((float)i + 0.5f) * 2 * half / (float)n;
            float z = -half + ((float)j + 0.5f) * 2 * half / (float)n;
            /* packed snow is lumpy at the scale of a boot, and gritty below it */
            h[(size_t)j * n + i] = vnoise(x / 0.22f, z / 0.22f, 0, 21) * 0.65f + vnoise(x / 0.07f, z / 0.07f, 0, 22) * 0.35f;
        }
    fit(h, (size_t)n * n, R_SNOW_TRAMPLED_LO, R_SNOW_TRAMPLED_HI);
}

static uint8_t u8(float v)
{
    return (uint8_t)lrintf(fminf(fmaxf(v, 0), 1) * 255);
}

void fx_snow_tex_colors(uint8_t *rg, int n)
{
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            float u = (float)x / (float)n * 16, v = (float)y / (float)n * 16;
            uint8_t *p = rg + ((size_t)y * n + x) * 2;
            /* fresh: faint drifts of brightness */
            float g = vnoise(u, v, 16, 31) * 0.6f + vnoise(u * 4, v * 4, 64, 32) * 0.4f;
            p[0] = u8(0.95f + 0.05f * g);
            /* trampled: blotchy compacted snow, a little grit from the boots */
            float t = vnoise(u * 0.75f, v * 0.75f, 12, 41) * 0.5f + vnoise(u * 5, v * 5, 80, 42) * 0.5f;
            float grit = rs_hash_point((uint32_t)x, (uint32_t)y, 43) % 100 < 6 ? 0.75f : 1.0f;
            p[1] = u8((0.85f + 0.15f * t) * grit);
        }
}

static float crust(int x, int y, int n)
{
    float u = (float)x / (float)n * 24, v = (float)y / (float)n * 24;
    return vnoise(u, v, 24, 51) * 0.7f + vnoise(u * 3, v * 3, 72, 52) * 0.3f;
}

void fx_snow_tex_detail_normals(uint8_t *rgba, int n)
{
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            float dx = crust(x + 1, y, n) - crust(x - 1, y, n);
            float dy = crust(x, y + 1, n) - crust(x, y - 1, n);
            float nx = -dx * 2, ny = -dy * 2, nz = 1;
            float l = sqrtf(nx * nx + ny * ny + nz * nz);
            uint8_t *p = rgba + ((size_t)y * n + x) * 4;
            p[0] = u8(nx / l * 0.5f + 0.5f), p[1] = u8(ny / l * 0.5f + 0.5f), p[2] = u8(nz / l * 0.5f + 0.5f);
            p[3] = 255;
        }
}
