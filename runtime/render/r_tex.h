/* Procedural textures of the renderer core, generated at load (no asset
 * files): the fighters' normal map and colour specular map (docs/renderer.md,
 * "HDR, materials, mask": normal maps plus colour specular maps make
 * highlights sparkle) and the sun flare.  Plain CPU functions so tests can
 * check them without GL. */
#ifndef R_TEX_H
#define R_TEX_H

#include <stdint.h>

#define R_TEX_SIZE 256
#define R_FLARE_SIZE 128

/* RGBA8, size x size: xyz = tangent-space normal * 0.5 + 0.5 (unit length
 * within rounding), a = 255.  A woven fabric with fine bumps; tiles. */
void r_tex_normal_map(uint8_t *rgba, int size);
/* RGBA8: rgb = specular colour, a = gloss (exponent 16 + 112 * a / 255).
 * A dull sheen with sparse bright coloured flecks (~3%); tiles. */
void r_tex_spec_map(uint8_t *rgba, int size);
/* RGBA8: a soft glow with a thin halo ring and a faint 6-point star,
 * centred, 0 at the border. */
void r_tex_flare(uint8_t *rgba, int size);

#endif
