#include "r_tex.h"

#include <math.h>
#include <stddef.h>

#include "../util/rs_hash.h"

static float noise01(int x, int y, int size, uint32_t seed)
{
    uint32_t wx = (uint32_t)((x % size + size) % size), wy = (uint32_t)((y % size + size) % size);
    return (float)(rs_hash_point(wx, wy, seed) & 0xffff) / 65535.0f;
}

static float height(int x, int y, int size)
{
    const float pi = 3.14159265f;
    /* weave: threads along u and v alternating over and under */
    float u = (float)x / size * 16, v = (float)y / size * 16;
    float wu = sinf(u * 2 * pi) * 0.5f + 0.5f, wv = sinf(v * 2 * pi) * 0.5f + 0.5f;
    int cell = ((int)floorf(u) + (int)floorf(v)) & 1;
    float weave = cell ? wu * 0.8f + wv * 0.2f : wv * 0.8f + wu * 0.2f;
    return weave * 1.5f + noise01(x, y, size, 7) * 0.35f;
}

void r_tex_normal_map(uint8_t *rgba, int size)
{
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++) {
            float dx = height(x + 1, y, size) - height(x - 1, y, size);
            float dy = height(x, y + 1, size) - height(x, y - 1, size);
            float nx = -dx * 0.5f, ny = -dy * 0.5f, nz = 1;
            float l = sqrtf(nx * nx + ny * ny + nz * nz);
            uint8_t *p = rgba + ((size_t)y * size + x) * 4;
            p[0] = (uint8_t)lrintf((nx / l * 0.5f + 0.5f) * 255);
            p[1] = (uint8_t)lrintf((ny / l * 0.5f + 0.5f) * 255);
            p[2] = (uint8_t)lrintf((nz / l * 0.5f + 0.5f) * 255);
            p[3] = 255;
        }
}

void r_tex_spec_map(uint8_t *rgba, int size)
{
    static const uint8_t fleck[4][3] = {{255, 210, 120}, {140, 220, 255}, {255, 150, 220}, {200, 255, 170}};
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++) {
            uint8_t *p = rgba + ((size_t)y * size + x) * 4;
            uint32_t h = rs_hash_point((uint32_t)x, (uint32_t)y, 99);
            if ((h & 1023) < 31) { /* ~3%: a bright coloured fleck, very glossy */
                const uint8_t *c = fleck[(h >> 10) & 3];
                p[0] = c[0], p[1] = c[1], p[2] = c[2], p[3] = 255;
            } else { /* the fabric: a dull, slightly varying sheen */
                uint8_t s = (uint8_t)(50 + (h >> 12) % 30);
                p[0] = p[1] = p[2] = s;
                p[3] = 40;
            }
        }
}

void r_tex_flare(uint8_t *rgba, int size)
{
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++) {
            float u = ((float)x + 0.5f) / size * 2 - 1, v = ((float)y + 0.5f) / size * 2 - 1;
            float r = sqrtf(u * u + v * v), a = atan2f(v, u);
            float glow = expf(-r * r * 9);
            float ring = expf(-(r - 0.75f) * (r - 0.75f) * 900) * 0.5f;
            float star = powf(fabsf(cosf(a * 3)), 40) * expf(-r * 3) * 0.6f;
            float val = (glow + ring + star) * (r < 1 ? 1 - r * r : 0);
            float c[3] = {val, val * 0.95f, val * 0.85f};
            uint8_t *p = rgba + ((size_t)y * size + x) * 4;
            for (int k = 0; k < 3; k++)
                p[k] = (uint8_t)lrintf(fminf(c[k], 1) * 255);
            p[3] = 255;
        }
}
