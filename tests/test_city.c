/* The buildings round a large ring (runtime/render/r_city.c): layouts are
 * deterministic, never overlap, keep the square open, put the landmark
 * between the ring and the light with a shadow that reaches the ring, and
 * the shadow proxies are low-poly boxes that hold the detailed mesh.  No GL. */
#include <math.h>
#include <stdlib.h>

#include "../runtime/render/r_city.h"
#include "t.h"

static const float sun[3] = {0.7f, 0.42f, 0.3f};

static bool overlap(const r_building *a, const r_building *b, float gap)
{
    return a->lo[0] < b->hi[0] + gap && b->lo[0] < a->hi[0] + gap && a->lo[2] < b->hi[2] + gap &&
           b->lo[2] < a->hi[2] + gap;
}

static void t_deterministic_and_seeded(void)
{
    r_building a[R_CITY_MAX], b[R_CITY_MAX], c[R_CITY_MAX];
    int na = r_city_layout(24, 7, sun, 4, a), nb = r_city_layout(24, 7, sun, 4, b), nc = r_city_layout(24, 8, sun, 4, c);
    T_EQ(na, nb);
    T_ASSERT(!memcmp(a, b, (size_t)na * sizeof a[0]));
    T_ASSERT(na > 20 && nc > 20);
    T_ASSERT(memcmp(&a[1], &c[1], sizeof a[0]) != 0); /* another seed, another city */
}

/* Randomized: many seeds, lights and counts; every layout keeps its rules. */
static void t_never_overlap_and_square_open(void)
{
    unsigned s = 12345;
    int total = 0;
    for (int trial = 0; trial < 400; trial++) {
        s = s * 1103515245u + 12345u;
        float L[3] = {(float)((s >> 8) % 2001) / 1000 - 1, (float)((s >> 4) % 1000) / 1000, (float)(s % 2001) / 1000 - 1};
        int count = 1 + (int)(s >> 20) % R_CITY_MAX;
        float half = 3.5f + (float)(trial % 3) * 0.5f;
        r_building b[R_CITY_MAX];
        int n = r_city_layout(count, s, L, half, b);
        T_ASSERTF(n >= 1 && n <= count, "trial %d: %d of %d", trial, n, count);
        total += n;
        for (int i = 0; i < n; i++) {
            for (int a = 0; a < 3; a++)
                T_ASSERT(isfinite(b[i].lo[a]) && isfinite(b[i].hi[a]) && b[i].lo[a] < b[i].hi[a]);
            T_ASSERTF(b[i].lo[1] == R_CITY_GROUND, "building %d floats", i);
            /* the plant room stands on the roof, inside it */
            T_ASSERT(b[i].plant_lo[1] == b[i].hi[1] && b[i].plant_lo[0] > b[i].lo[0] && b[i].plant_hi[0] < b[i].hi[0] &&
                     b[i].plant_lo[2] > b[i].lo[2] && b[i].plant_hi[2] < b[i].hi[2]);
            /* nothing stands on the ring or within 10 m of it */
            float nx = fmaxf(fmaxf(b[i].lo[0], -b[i].hi[0]), 0), nz = fmaxf(fmaxf(b[i].lo[2], -b[i].hi[2]), 0);
            T_ASSERTF(sqrtf(nx * nx + nz * nz) >= half + 10, "trial %d: building %d %.1f m from the centre", trial, i,
                      sqrtf(nx * nx + nz * nz));
            for (int k = 0; k < i; k++)
                T_ASSERTF(!overlap(&b[i], &b[k], R_CITY_STREET - 1e-3f), "trial %d: %d overlaps %d", trial,
                          i, k);
        }
    }
    T_ASSERT(total > 400 * 10); /* the tries find room for most */
}

/* The landmark stands towards the light, and its roof's shadow reaches
 * past the ring's centre: the ray from the centre towards the light passes
 * below the roof where it crosses the block. */
static void t_landmark_shadows_the_ring(void)
{
    const float lights[][3] = {{0.7f, 0.42f, 0.3f}, {-0.55f, 0.42f, -0.6f}, {0, 0.9f, 0.3f}, {1, 0.2f, 0}};
    for (size_t l = 0; l < sizeof lights / sizeof lights[0]; l++) {
        r_building b[1];
        T_EQ(r_city_layout(1, 3, lights[l], 4, b), 1);
        float cx = (b[0].lo[0] + b[0].hi[0]) / 2, cz = (b[0].lo[2] + b[0].hi[2]) / 2;
        const float *L = lights[l];
        float hl = sqrtf(L[0] * L[0] + L[2] * L[2]);
        T_ASSERTF(cx * L[0] + cz * L[2] > 0.8f * hl * sqrtf(cx * cx + cz * cz), "light %zu: landmark not towards it", l);
        /* a point of the ring's edge on the light's side, and the far edge */
        bool hit = false;
        for (float t = -4; t <= 4 && !hit; t += 0.25f) {
            float p[3] = {t * L[2] / hl, 0, -t * L[0] / hl}; /* across the light through the centre */
            /* march towards the light and see whether the block is in the way */
            for (float s = 0; s < 200 && !hit; s += 0.1f) {
                float q[3] = {p[0] + L[0] * s, p[1] + L[1] * s, p[2] + L[2] * s};
                hit = q[0] > b[0].lo[0] && q[0] < b[0].hi[0] && q[1] > b[0].lo[1] && q[1] < b[0].hi[1] &&
                      q[2] > b[0].lo[2] && q[2] < b[0].hi[2];
            }
        }
        T_ASSERTF(hit || L[1] / hl > 2.5f, "light %zu: the landmark's shadow misses the ring", l);
    }
}

static void t_degenerate_input(void)
{
    r_building b[R_CITY_MAX];
    const float zero[3] = {0, 0, 0}, nan3[3] = {NAN, NAN, NAN}, below[3] = {1, -1, 0};
    T_EQ(r_city_layout(0, 1, sun, 4, b), 0);
    T_EQ(r_city_layout(-3, 1, sun, 4, b), 0);
    T_ASSERT(r_city_layout(1000, 1, sun, 4, b) <= R_CITY_MAX);
    const float *odd[] = {zero, nan3, below, NULL};
    for (int i = 0; i < 4; i++) {
        T_EQ(r_city_layout(1, 1, odd[i], 4, b), 1);
        T_ASSERT(b[0].hi[2] < 0); /* north: -z */
        T_ASSERT(isfinite(b[0].hi[1]) && b[0].hi[1] - b[0].lo[1] >= 20 && b[0].hi[1] - b[0].lo[1] <= 80);
    }
    T_EQ(r_city_layout(3, 0, sun, NAN, b), 3); /* a bad ring size falls back */
}

/* The proxy: 24 triangles that contain every vertex of the detailed mesh
 * (less the ledges' few centimetres: they are thinner than a shadow-map
 * texel), while the mesh has many more triangles. */
static void t_proxy_is_low_poly_and_holds_the_mesh(void)
{
    r_building b[R_CITY_MAX];
    int n = r_city_layout(12, 5, sun, 4, b);
    for (int i = 0; i < n; i++) {
        r_mesh_data m = {0}, p = {0};
        T_ASSERT(r_city_mesh(&m, &b[i]) && r_city_proxy(&p, &b[i]));
        T_EQ(p.ni / 3, 24);
        T_ASSERTF(m.ni / 3 >= 3 * (p.ni / 3), "building %d: %zu triangles against the proxy's %zu", i, m.ni / 3, p.ni / 3);
        float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f}, blo[3], bhi[3];
        for (size_t v = 0; v < p.nv; v++)
            for (int a = 0; a < 3; a++)
                lo[a] = fminf(lo[a], p.v[v].pos[a]), hi[a] = fmaxf(hi[a], p.v[v].pos[a]);
        r_city_bounds(&b[i], blo, bhi);
        for (size_t v = 0; v < m.nv; v++)
            for (int a = 0; a < 3; a++) {
                float x = m.v[v].pos[a];
                T_ASSERTF(x >= lo[a] - 0.31f && x <= hi[a] + 0.31f, "building %d: vertex outside its proxy", i);
                T_ASSERTF(x >= blo[a] - 1e-4f && x <= bhi[a] + 1e-4f, "building %d: vertex outside its bounds", i);
            }
        r_mesh_free(&m);
        r_mesh_free(&p);
    }
}

T_MAIN({"deterministic_and_seeded", t_deterministic_and_seeded},
       {"never_overlap_and_square_open", t_never_overlap_and_square_open},
       {"landmark_shadows_the_ring", t_landmark_shadows_the_ring}, {"degenerate_input", t_degenerate_input},
       {"proxy_is_low_poly_and_holds_the_mesh", t_proxy_is_low_poly_and_holds_the_mesh})
