/* Snow (docs/effects.md, "Snow"): the effect's procedural textures, plain CPU
 * functions so tests check them without GL, and the snow module's
 * read-back hooks for the tests (defined in fx_snow.c).
 *
 * Heights are metres above the ring top (y = 0).  The displacement map
 * covers the ring top, x and z in -half..+half, row j at
 * z = -half + (j + 0.5) * 2 half / n, column i likewise in x. */
#ifndef R_FX_SNOW_TEX_H
#define R_FX_SNOW_TEX_H

#include <stdbool.h>
#include <stdint.h>

#define R_SNOW_MAP 256        /* displacement map texels per side */
#define R_SNOW_TEX 256        /* tiling colour and detail textures */
#define R_SNOW_UNTOUCHED_LO 0.10f /* fresh snow: drifts 0.10..0.14 m deep */
#define R_SNOW_UNTOUCHED_HI 0.14f
#define R_SNOW_TRAMPLED_LO 0.02f  /* fully trampled: 0.02..0.04 m, uneven */
#define R_SNOW_TRAMPLED_HI 0.04f

/* n x n heights of the untouched snow over a ring of half-size `half`:
 * broad drifts with wind ripples, exactly spanning UNTOUCHED_LO..HI. */
void fx_snow_tex_untouched(float *h, int n, float half);
/* The fully trampled minimum: compacted, lumpy, TRAMPLED_LO..HI.  Below
 * the untouched heights everywhere (the ranges do not overlap). */
void fx_snow_tex_trampled(float *h, int n, float half);
/* The two colour textures, fresh and trampled snow, packed into one
 * tiling RG8 texture so a pixel takes one fetch: snow has no hue of its
 * own, so each is a brightness times a tint (SNOW_FRESH, SNOW_TRAMPLED in
 * shaders/snow_common.glsl).  r: fresh (faint drifts), g: trampled
 * (blotchy, with grit).  n x n x 2 bytes. */
void fx_snow_tex_colors(uint8_t *rg, int n);
/* Tiling RGBA8 tangent-space normal map of the snow's crust (xyz * 0.5 +
 * 0.5, a = 255). */
void fx_snow_tex_detail_normals(uint8_t *rgba, int n);

/* Test hooks (fx_snow.c).  which: "map" (the displacement map),
 * "untouched", "trampled" (R_SNOW_MAP^2 floats) or "light" (the blurred
 * texture-space lighting, RGBA: fx_snow_light_size(r)^2 * 4).
 * False when the snow module has no such texture. */
typedef struct r_game r_game;
bool fx_snow_read(r_game *r, const char *which, float *out);
int fx_snow_light_size(r_game *r); /* 0: no snow module */
/* Triangles of the surface grid the frame drawn last drew (its level of
 * detail: fx_snow.c, snow_grid_lod); 0: none yet. */
int fx_snow_grid_drawn(r_game *r);
/* Tests: the scene draws the ring's top face under the snow after all
 * (true), or leaves it to the snow as it does by default (false). */
void fx_snow_test_keep_ring_top(r_game *r, bool keep);
/* Stamps n capsules into the map the way a tick's contacts are stamped
 * (the next frame's reset restarts it). */
typedef struct r_fx_capsule r_fx_capsule;
void fx_snow_stamp(r_game *r, const r_fx_capsule *caps, int n);

#endif
