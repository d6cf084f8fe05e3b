/* Fixed-point arithmetic for the simulation.
 *
 * The game state holds no floating point at all: positions and speeds are
 * Q16.16 metres (fx, 1.0 = 65536), angles are 1/65536 of a turn (fang,
 * 16384 = 90 degrees), times are integer ticks.  Integer arithmetic gives the
 * same answer at every optimisation level, under sanitizers and on every
 * machine, so replays stay in sync by construction, and nothing accumulates
 * rounding drift over a 24-hour run.  Products go through int64. */
#ifndef G_FIXED_H
#define G_FIXED_H

#include <stdint.h>

/* Fixed point relies on >> of a negative value being an arithmetic
 * (flooring) shift.  C11 leaves that to the implementation; every compiler
 * we build with does it, and this stops the build on one that does not. */
_Static_assert((-65536 >> 16) == -1 && (-1 >> 1) == -1, "arithmetic right shift required");

typedef int32_t fx;   /* Q16.16 */
typedef int32_t fang; /* 65536 per turn */

#define FX_ONE 65536
/* compile-time constants from decimals: FX(1.25) */
#define FX(x) ((fx)((x) * 65536.0 + ((x) >= 0 ? 0.5 : -0.5)))
#define DEG(d) ((fang)((d) * 65536.0 / 360.0 + ((d) >= 0 ? 0.5 : -0.5)))

static inline fx fx_mul(fx a, fx b)
{
    return (fx)(((int64_t)a * b) >> 16);
}

static inline fx fx_div(fx a, fx b)
{
    return (fx)(((int64_t)a * 65536) / b);
}

static inline fx fx_abs(fx a)
{
    return a < 0 ? -a : a;
}

static inline fx fx_clamp(fx v, fx lo, fx hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

extern const int32_t g_sin_quarter[1025];

/* sin and cos of a fang, Q16.16, linear between table steps of 1/4096 turn. */
static inline fx fx_sin(fang a)
{
    uint32_t u = (uint32_t)a & 0xffffu; /* one turn */
    uint32_t quarter = u >> 14, within = u & 0x3fffu;
    uint32_t idx = within >> 4, frac = within & 15u;
    if (quarter & 1) { /* mirrored quarter: read the table backwards */
        uint32_t back = 0x4000u - within;
        idx = back >> 4;
        frac = back & 15u;
    }
    int32_t lo = g_sin_quarter[idx], hi = g_sin_quarter[idx < 1024 ? idx + 1 : 1024];
    int32_t v = lo + (int32_t)(((int64_t)(hi - lo) * (int32_t)frac) >> 4);
    return quarter >= 2 ? -v : v;
}

static inline fx fx_cos(fang a)
{
    return fx_sin((fang)(a + 16384));
}

/* Integer square root of a non-negative 64-bit value (floor). */
static inline uint32_t g_isqrt64(uint64_t v)
{
    uint64_t r = 0, bit = (uint64_t)1 << 62;
    while (bit > v)
        bit >>= 2;
    while (bit) {
        if (v >= r + bit) {
            v -= r + bit;
            r = (r >> 1) + bit;
        } else {
            r >>= 1;
        }
        bit >>= 2;
    }
    return (uint32_t)r;
}

/* Float views for the renderer only; never feed them back into the game. */
static inline float fx_to_float(fx v)
{
    return (float)v / 65536.0f;
}

static inline float fang_to_rad(fang a)
{
    return (float)a * (6.28318530718f / 65536.0f);
}

#endif
