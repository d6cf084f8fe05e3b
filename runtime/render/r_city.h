/* The buildings round a large outdoor ring (docs/effects.md, "Shadows in a large world"):
 * a deterministic layout from a stage's `buildings` and `buildings_seed`,
 * the detailed meshes the camera sees and the low-poly shadow proxies the
 * LSPSM map is drawn from.  Pure C, no GL: tests/test_city.c.
 *
 * Layout rules:
 *   - building 0, the landmark, stands between the ring and the key light,
 *     tall enough that its shadow falls across the ring (so the stage
 *     always shows a building's shadow on the fighters at some point);
 *   - the others stand in an annulus from R_CITY_INNER to R_CITY_OUTER
 *     metres round the ring centre, with at least R_CITY_STREET metres of
 *     street between any two (placement never overlaps);
 *   - a building that finds no free place after R_CITY_TRIES attempts is
 *     left out, so the count is an upper bound.
 * Buildings stand on the ground at R_CITY_GROUND (y, metres). */
#ifndef R_CITY_H
#define R_CITY_H

#include <stdbool.h>

#include "r_mesh.h"

#define R_CITY_GROUND (-3.0f)
#define R_CITY_INNER 16.0f
#define R_CITY_OUTER 95.0f
#define R_CITY_STREET 4.0f
#define R_CITY_TRIES 200
#define R_CITY_MAX 48

typedef struct r_building {
    float lo[3], hi[3];         /* the block, ground to roof */
    float plant_lo[3], plant_hi[3]; /* the plant room on the roof */
} r_building;

/* Up to `count` buildings (at most R_CITY_MAX) into out; returns how many
 * were placed.  to_light need not be unit length; a zero or non-finite one
 * (or a light at or below the horizon) puts the landmark to the north (-z). */
int r_city_layout(int count, unsigned seed, const float to_light[3], float ring_half, r_building *out);

/* The whole bounding box of a building (block, parapet and plant room). */
void r_city_bounds(const r_building *b, float lo[3], float hi[3]);

/* Appends building b's detailed mesh (block, parapet, plant room, ledges:
 * what the camera sees) to m.  False when out of memory. */
bool r_city_mesh(r_mesh_data *m, const r_building *b);

/* Appends its shadow proxy: two boxes (block with parapet, plant room),
 * 24 triangles.  False when out of memory. */
bool r_city_proxy(r_mesh_data *m, const r_building *b);

#endif
