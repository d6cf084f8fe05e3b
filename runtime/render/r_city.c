/* Buildings round the ring: layout, detailed meshes, shadow proxies
 * (r_city.h). */
#include "r_city.h"

#include <math.h>
#include <string.h>

#define PARAPET_H 1.0f  /* the roof's low wall */
#define PARAPET_T 0.4f
#define PLANT_H 3.0f    /* the plant room on the roof */
#define LEDGE_EVERY 7.0f /* a ledge every other floor */
#define LEDGE_OUT 0.3f

static unsigned next(unsigned *s) /* xorshift32: the layout is the same everywhere */
{
    unsigned x = *s;
    x ^= x << 13, x ^= x >> 17, x ^= x << 5;
    return *s = x;
}

static float uniform(unsigned *s, float lo, float hi)
{
    return lo + (hi - lo) * (float)(next(s) >> 8) / 16777216.0f;
}

/* The building with its block centred at (x, z), w x d wide, h above the ground. */
static r_building make(float x, float z, float w, float d, float h, unsigned *s)
{
    r_building b;
    b.lo[0] = x - w / 2, b.lo[1] = R_CITY_GROUND, b.lo[2] = z - d / 2;
    b.hi[0] = x + w / 2, b.hi[1] = R_CITY_GROUND + h, b.hi[2] = z + d / 2;
    /* the plant room: 30-50 % of the roof, somewhere inside the parapet */
    float pw = w * uniform(s, 0.3f, 0.5f), pd = d * uniform(s, 0.3f, 0.5f);
    float px = uniform(s, b.lo[0] + PARAPET_T + pw / 2, b.hi[0] - PARAPET_T - pw / 2);
    float pz = uniform(s, b.lo[2] + PARAPET_T + pd / 2, b.hi[2] - PARAPET_T - pd / 2);
    b.plant_lo[0] = px - pw / 2, b.plant_lo[1] = b.hi[1], b.plant_lo[2] = pz - pd / 2;
    b.plant_hi[0] = px + pw / 2, b.plant_hi[1] = b.hi[1] + PLANT_H, b.plant_hi[2] = pz + pd / 2;
    return b;
}

static bool overlaps(const r_building *a, const r_building *b, float gap)
{
    return a->lo[0] < b->hi[0] + gap && b->lo[0] < a->hi[0] + gap && a->lo[2] < b->hi[2] + gap &&
           b->lo[2] < a->hi[2] + gap;
}

int r_city_layout(int count, unsigned seed, const float to_light[3], float ring_half, r_building *out)
{
    if (count <= 0)
        return 0;
    if (count > R_CITY_MAX)
        count = R_CITY_MAX;
    if (!(ring_half > 0 && ring_half < 20))
        ring_half = 4;
    unsigned s = seed * 2654435761u + 0x9e3779b9u;
    if (!s)
        s = 1;
    for (int k = 0; k < 8; k++)
        next(&s);
    /* the landmark: towards the light's horizontal direction, offset to one
     * side so its shadow's edge crosses the ring, as tall as it takes for
     * the shadow to reach the ring's far edge (the light's elevation) */
    float lx = to_light ? to_light[0] : 0, ly = to_light ? to_light[1] : 0, lz = to_light ? to_light[2] : 0;
    float hl = sqrtf(lx * lx + lz * lz);
    float hx = 0, hz = -1, tan_e = 1;
    if (isfinite(hl) && isfinite(ly) && hl > 1e-4f && ly > 0)
        hx = lx / hl, hz = lz / hl, tan_e = ly / hl;
    float w = 9, dist = ring_half + 14 + w / 2;
    float reach = dist + w / 2 + ring_half; /* to the ring's far side */
    float h = fminf(fmaxf(reach * tan_e * 1.15f - R_CITY_GROUND, 20.0f), 80.0f);
    float side = 4.0f; /* across the light: half the ring in the shadow */
    out[0] = make(hx * dist - hz * side, hz * dist + hx * side, w, w, h, &s);
    int n = 1;
    /* the rest, in the annulus, never overlapping */
    for (int i = 1; i < count; i++) {
        for (int t = 0; t < R_CITY_TRIES; t++) {
            float a = uniform(&s, 0, 6.2831853f), r = uniform(&s, ring_half + R_CITY_INNER - 4, R_CITY_OUTER);
            float bw = uniform(&s, 6, 18), bd = uniform(&s, 6, 18);
            /* taller further out: the skyline rises behind the square */
            float bh = uniform(&s, 8, 18) + r * uniform(&s, 0.05f, 0.35f);
            r_building b = make(r * cosf(a), r * sinf(a), bw, bd, bh, &s);
            bool free_place = true;
            for (int k = 0; k < n && free_place; k++)
                free_place = !overlaps(&b, &out[k], R_CITY_STREET);
            /* keep the square round the ring open (the inner radius holds
             * for the block's nearest corner too) */
            float nx = fmaxf(fmaxf(b.lo[0], -b.hi[0]), 0), nz = fmaxf(fmaxf(b.lo[2], -b.hi[2]), 0);
            if (free_place && sqrtf(nx * nx + nz * nz) >= ring_half + R_CITY_INNER - 6) {
                out[n++] = b;
                break;
            }
        }
    }
    return n;
}

void r_city_bounds(const r_building *b, float lo[3], float hi[3])
{
    for (int a = 0; a < 3; a++) {
        lo[a] = fminf(b->lo[a], b->plant_lo[a]) - (a == 1 ? 0 : LEDGE_OUT);
        hi[a] = fmaxf(b->hi[a], b->plant_hi[a]) + (a == 1 ? 0 : LEDGE_OUT);
    }
    hi[1] = fmaxf(hi[1], b->hi[1] + PARAPET_H);
}

static bool box(r_mesh_data *m, float x0, float y0, float z0, float x1, float y1, float z1)
{
    const float lo[3] = {x0, y0, z0}, hi[3] = {x1, y1, z1};
    return r_mesh_box(m, lo, hi) != 0;
}

bool r_city_mesh(r_mesh_data *m, const r_building *b)
{
    const float *lo = b->lo, *hi = b->hi, t = PARAPET_T, top = hi[1] + PARAPET_H;
    bool ok = box(m, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]) &&
              /* parapet: four low walls round the roof */
              box(m, lo[0], hi[1], lo[2], hi[0], top, lo[2] + t) && box(m, lo[0], hi[1], hi[2] - t, hi[0], top, hi[2]) &&
              box(m, lo[0], hi[1], lo[2] + t, lo[0] + t, top, hi[2] - t) &&
              box(m, hi[0] - t, hi[1], lo[2] + t, hi[0], top, hi[2] - t) &&
              box(m, b->plant_lo[0], b->plant_lo[1], b->plant_lo[2], b->plant_hi[0], b->plant_hi[1], b->plant_hi[2]);
    /* ledges: thin slabs round the block every other floor */
    for (float y = lo[1] + LEDGE_EVERY; ok && y < hi[1] - 2; y += LEDGE_EVERY)
        ok = box(m, lo[0] - LEDGE_OUT, y - 0.15f, lo[2] - LEDGE_OUT, hi[0] + LEDGE_OUT, y + 0.15f, hi[2] + LEDGE_OUT);
    return ok;
}

bool r_city_proxy(r_mesh_data *m, const r_building *b)
{
    return box(m, b->lo[0], b->lo[1], b->lo[2], b->hi[0], b->hi[1] + PARAPET_H, b->hi[2]) &&
           box(m, b->plant_lo[0], b->plant_lo[1], b->plant_lo[2], b->plant_hi[0], b->plant_hi[1], b->plant_hi[2]);
}
