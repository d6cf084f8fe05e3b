/* Bloom's blurs and glow on the CPU (r_bloom.h). */
#include "r_bloom.h"

#include <math.h>

#define HALF_MAX 65504.0f

static int clampi(int v, int hi)
{
    return v < 0 ? 0 : v > hi ? hi : v;
}

/* A texel, RGBA: one SSE register (GCC and Clang vector extensions), so
 * that each tap is one multiply-add whatever the compiler's vectoriser
 * makes of the loops.  Buffers may be 4-byte aligned only. */
typedef float v4 __attribute__((vector_size(16), aligned(4)));

static v4 splat(float k)
{
    return (v4){k, k, k, k};
}

/* blur.frag's REACH 4 blur along x (across) or y: the 9 texels weighted
 * kw[|i|], clamped at the edges. */
static void blur(const v4 *src, v4 *dst, int w, int h, const float kw[5], bool across)
{
    const v4 k0 = splat(kw[0]), k1 = splat(kw[1]), k2 = splat(kw[2]), k3 = splat(kw[3]), k4 = splat(kw[4]);
    for (int y = 0; y < h; y++) {
        v4 *out = dst + (size_t)y * (size_t)w;
        if (across) {
            const v4 *row = src + (size_t)y * (size_t)w;
            for (int x = 0; x < w; x++) {
                if (x >= 4 && x < w - 4) {
                    out[x] = k0 * row[x] + k1 * (row[x - 1] + row[x + 1]) + k2 * (row[x - 2] + row[x + 2]) +
                             k3 * (row[x - 3] + row[x + 3]) + k4 * (row[x - 4] + row[x + 4]);
                    continue;
                }
                int m = w - 1;
                out[x] = k0 * row[x] + k1 * (row[clampi(x - 1, m)] + row[clampi(x + 1, m)]) +
                         k2 * (row[clampi(x - 2, m)] + row[clampi(x + 2, m)]) +
                         k3 * (row[clampi(x - 3, m)] + row[clampi(x + 3, m)]) +
                         k4 * (row[clampi(x - 4, m)] + row[clampi(x + 4, m)]);
            }
        } else {
            const v4 *p[9];
            for (int k = -4; k <= 4; k++)
                p[k + 4] = src + (size_t)clampi(y + k, h - 1) * (size_t)w;
            for (int x = 0; x < w; x++)
                out[x] = k0 * p[4][x] + k1 * (p[3][x] + p[5][x]) + k2 * (p[2][x] + p[6][x]) + k3 * (p[1][x] + p[7][x]) +
                         k4 * (p[0][x] + p[8][x]);
        }
    }
}

/* GL_LINEAR with GL_CLAMP_TO_EDGE at uv */
static v4 bilinear(const v4 *src, int w, int h, float u, float v)
{
    float fx = u * (float)w - 0.5f, fy = v * (float)h - 0.5f;
    float bx = floorf(fx), by = floorf(fy);
    v4 tx = splat(fx - bx), ty = splat(fy - by);
    int x0 = (int)bx, y0 = (int)by;
    int xa = clampi(x0, w - 1), xb = clampi(x0 + 1, w - 1), ya = clampi(y0, h - 1), yb = clampi(y0 + 1, h - 1);
    const v4 *ra = src + (size_t)ya * (size_t)w, *rb = src + (size_t)yb * (size_t)w;
    v4 lo = ra[xa] + (ra[xb] - ra[xa]) * tx, hi = rb[xa] + (rb[xb] - rb[xa]) * tx;
    return lo + (hi - lo) * ty;
}

/* dst (dw x dh) += src (w x h) sampled bilinearly at dst's pixel centres,
 * clamped at the edges.  At twice the size (the glow over the second
 * level, over the flare's quarter-size image) every weight is a quarter
 * or three: by rows into tmp (dw x h), then down the columns; other
 * ratios tap pixel by pixel. */
static void add_upsampled(v4 *dst, int dw, int dh, const v4 *src, int w, int h, v4 *tmp)
{
    if (dw != 2 * w || dh != 2 * h) {
        for (int y = 0; y < dh; y++)
            for (int x = 0; x < dw; x++)
                dst[(size_t)y * (size_t)dw + (size_t)x] +=
                    bilinear(src, w, h, ((float)x + 0.5f) / (float)dw, ((float)y + 0.5f) / (float)dh);
        return;
    }
    /* output 2i + 1/2 lies at source i + 1/4 (3/4 of i, 1/4 of i + 1),
     * 2i - 1/2 at i - 1/4 (3/4 of i, 1/4 of i - 1), clamped */
    const v4 q1 = splat(0.25f), q3 = splat(0.75f);
    for (int y = 0; y < h; y++) {
        const v4 *s = src + (size_t)y * (size_t)w;
        v4 *o = tmp + (size_t)y * (size_t)dw;
        for (int i = 0; i < w; i++) {
            v4 c = q3 * s[i];
            o[2 * i] = c + q1 * s[clampi(i - 1, w - 1)];
            o[2 * i + 1] = c + q1 * s[clampi(i + 1, w - 1)];
        }
    }
    for (int y = 0; y < dh; y++) {
        int i = y / 2, n = clampi(y % 2 ? i + 1 : i - 1, h - 1);
        const v4 *c = tmp + (size_t)i * (size_t)dw, *m = tmp + (size_t)n * (size_t)dw;
        v4 *o = dst + (size_t)y * (size_t)dw;
        for (int x = 0; x < dw; x++)
            o[x] += q3 * c[x] + q1 * m[x];
    }
}

/* downsample.frag from the first level to the second: a halving is the
 * 4x4 box of texels 2i-1..2i+2 (clamped), summed by rows into tmp
 * (dw x h) and then down the columns; other ratios its four bilinear taps
 * half a target pixel either way. */
static void down(const v4 *src, int w, int h, v4 *dst, int dw, int dh, v4 *tmp)
{
    if (w != 2 * dw || h != 2 * dh) {
        float ou = 0.5f / (float)dw, ov = 0.5f / (float)dh;
        for (int j = 0; j < dh; j++)
            for (int i = 0; i < dw; i++) {
                float u = ((float)i + 0.5f) / (float)dw, v = ((float)j + 0.5f) / (float)dh;
                dst[(size_t)j * (size_t)dw + (size_t)i] =
                    splat(0.25f) * (bilinear(src, w, h, u - ou, v - ov) + bilinear(src, w, h, u + ou, v - ov) +
                                    bilinear(src, w, h, u - ou, v + ov) + bilinear(src, w, h, u + ou, v + ov));
            }
        return;
    }
    for (int y = 0; y < h; y++) {
        const v4 *s = src + (size_t)y * (size_t)w;
        v4 *o = tmp + (size_t)y * (size_t)dw;
        for (int i = 0; i < dw; i++)
            o[i] = s[clampi(2 * i - 1, w - 1)] + s[2 * i] + s[2 * i + 1] + s[clampi(2 * i + 2, w - 1)];
    }
    const v4 k = splat(1.0f / 16);
    for (int j = 0; j < dh; j++) {
        const v4 *r0 = tmp + (size_t)clampi(2 * j - 1, h - 1) * (size_t)dw, *r1 = tmp + (size_t)(2 * j) * (size_t)dw;
        const v4 *r2 = tmp + (size_t)(2 * j + 1) * (size_t)dw, *r3 = tmp + (size_t)clampi(2 * j + 2, h - 1) * (size_t)dw;
        v4 *o = dst + (size_t)j * (size_t)dw;
        for (int x = 0; x < dw; x++)
            o[x] = k * (r0[x] + r1[x] + r2[x] + r3[x]);
    }
}

size_t r_bloom_scratch_floats(const r_bloom_cpu *b)
{
    /* two of the first level's size (the blur across, the row passes'
     * w4 x h8 or w8 x h4 and w4 x h8), two of the second's */
    return 4 * (2 * (size_t)b->w4 * (size_t)b->h4 + 2 * (size_t)b->w8 * (size_t)b->h8);
}

void r_bloom_glow(const r_bloom_cpu *b, const float *bright, float *scratch, float *glow)
{
    size_t n4 = (size_t)b->w4 * (size_t)b->h4, n8 = (size_t)b->w8 * (size_t)b->h8;
    v4 *across = (v4 *)scratch, *tmp = across + n4, *l2 = tmp + n4, *l2t = l2 + n8, *g = (v4 *)glow;
    /* the first level across; the second made from that, then blurred both ways */
    blur((const v4 *)bright, across, b->w4, b->h4, b->kw, true);
    if (b->level2) {
        down(across, b->w4, b->h4, l2, b->w8, b->h8, tmp);
        blur(l2, l2t, b->w8, b->h8, b->kw, true);
        blur(l2t, l2, b->w8, b->h8, b->kw, false);
    }
    /* the first level down the columns, + the second, x bloom, + the flare */
    blur(across, g, b->w4, b->h4, b->kw, false);
    if (b->level2)
        add_upsampled(g, b->w4, b->h4, l2, b->w8, b->h8, tmp);
    const v4 k = splat(b->bloom);
    for (size_t j = 0; j < n4; j++)
        g[j] *= k;
    if (b->flare)
        add_upsampled(g, b->w4, b->h4, (const v4 *)b->flare, b->fw, b->fh, tmp);
    for (size_t j = 0; j < n4; j++) {
        v4 c = g[j];
        for (int a = 0; a < 3; a++)
            c[a] = c[a] > 0 ? (c[a] < HALF_MAX ? c[a] : HALF_MAX) : 0; /* NaN -> 0 */
        c[3] = 1;
        g[j] = c;
    }
}
