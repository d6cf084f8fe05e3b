/* Image-based lighting (docs/renderer.md, "Image-based lighting"): a stage's
 * HDR environment and its six prefiltered cube maps, computed on the CPU by
 * straightforward spherical integration and cached on disk.
 *
 * Cube maps use OpenGL's face order and orientation (+X -X +Y -Y +Z -Z;
 * face f, texel (i, j): s = 2(i+0.5)/N - 1, t = 2(j+0.5)/N - 1, row j = 0
 * is the first row uploaded; +X: dir (1, -t, -s), -X: (-1, -t, s),
 * +Y: (s, 1, t), -Y: (s, -1, -t), +Z: (s, -t, 1), -Z: (-s, -t, -1)).
 * Pixels are RGB float, rows packed.
 *
 * Definitions (L: environment radiance, s: sun direction, E: sun
 * irradiance x colour, cos+ = max(0, cos)):
 *   diffuse(n)   = 1/pi        * Int L(w) cos+(n.w) dw      + E/pi * cos+(n.s)
 *   spec_e(r)    = (e+1)/(2pi) * Int L(w) cos+(r.w)^e dw    + E (e+1)/(2pi) * cos+(r.s)^e
 * so a uniform environment of 1 gives 1 everywhere.  The sun of a
 * procedural environment is a delta light (an impulse breaks sampled
 * integration); a loaded environment's sun is whatever its texels hold.
 * Each map comes twice: with the key-light area (key on) and without it
 * (key off: the sun term dropped and texels within key_area_deg of the key
 * direction faded out with a smooth 5-degree edge).  The key direction is
 * the sun's; without a sun, the painted key light's (procedural) or the
 * brightest texel's (loaded).
 *
 * Loaded images (rows top-down, +Y up):
 *   equirectangular (w = 2h): Blender's and three.js's mapping.  Column u
 *     (0..1 left to right) is longitude, u = 0.5 + atan2(z, x) / 2pi: the
 *     image centre looks at +X, u = 0.75 at +Z, u = 0.25 at -Z, the left
 *     and right edges at -X.  Row v (0..1 top to bottom) is latitude,
 *     v = 0.5 - asin(y) / pi: the top row is straight up.
 *   strip (w = 6h): the six faces left to right in GL order, each upright
 *     as uploaded (face row j = image row j).
 *   horizontal cross (3w = 4h, cells of h/3): -X +Z +X -Z along the middle
 *     row, +Y above +Z, -Y below +Z, each face upright as uploaded (GL
 *     faces as they are meet at every seam of that net).
 * env_rotate_deg turns the environment right-handed about +Y: +90 brings
 * what the file has at +X to -Z. */
#ifndef R_IBL_H
#define R_IBL_H

#include <stdbool.h>
#include <stdint.h>

#include "../util/rs_err.h"
#include "r_stage.h"

#define R_IBL_FORMAT_VERSION 1

enum { R_IBL_DIFFUSE, R_IBL_SPEC16, R_IBL_SPEC128, R_IBL_MAPS };
enum { R_IBL_KEY_OFF, R_IBL_KEY_ON };
#define R_IBL_MAX_SIZE 512 /* largest face edge of any cube here */

enum { R_IBL_ERR_FILE = 1, R_IBL_ERR_FORMAT, R_IBL_ERR_MEMORY, R_IBL_ERR_PARAMS };

/* An environment cube: size x size RGB floats per face. */
typedef struct r_env {
    int size;
    float *face[6];
} r_env;

typedef struct r_ibl_params {
    int src_size;      /* integration resolution per face edge (default 32) */
    int out_size[R_IBL_MAPS]; /* output face edge: 16, 32, 32 by default */
    int threads;       /* 0 = number of online CPUs, at most 8 */
} r_ibl_params;

typedef struct r_ibl {
    int size[R_IBL_MAPS];
    float *map[R_IBL_MAPS][2][6]; /* [map][R_IBL_KEY_*][face], RGB */
    float key_dir[3];
    uint64_t hash;     /* the cache key */
    bool from_cache;
    double ms;         /* time spent prefiltering (0 when from the cache) */
} r_ibl;

void r_ibl_default_params(r_ibl_params *p);
float r_ibl_exponent(int map); /* 0 (diffuse), 16, 128 */

/* Texel centre of face f, (i, j) -> unit direction; and the inverse
 * (nearest texel). */
void r_cube_dir(int face, int i, int j, int n, float dir[3]);
void r_cube_texel(const float dir[3], int n, int *face, int *i, int *j);
/* Exact solid angle of texel (i, j) of an n x n face. */
double r_cube_texel_solid_angle(int i, int j, int n);

/* The environment of a stage at `size` texels per face edge: the
 * procedural sky (sky_zenith/horizon/ground gradient plus the painted key
 * and counter lights; the sun is not in the texels) or st->env_path read
 * through OpenImageIO (equirectangular 2:1, a 6:1 strip of faces in GL
 * order, or a 4:3 horizontal cross), rotated and scaled, resampled with
 * area averaging.  Values are clamped to 0..65504; NaN becomes 0. */
bool r_env_build(const r_stage *st, int size, r_env *env, rs_err *err);
void r_env_free(r_env *env);

/* Key direction for the stage and its environment (see above). */
void r_ibl_key_dir(const r_stage *st, const r_env *env, float dir[3]);

/* One unit direction of one map by integration over env (plus the stage's
 * sun term): the function behind the prefilter (a map texel equals it at
 * the texel's r_cube_dir, before the 0..65504 clamp), and the reference of
 * bench accuracy when env is a fine cube. */
void r_ibl_eval(const r_stage *st, const r_env *env, const float key_dir[3], int map, int key, const float dir[3],
                double rgb[3]);

/* All six maps.  cache_dir NULL or "" = no cache; otherwise a hit loads
 * "<cache_dir>/ibl-<hash>.bin" and a miss writes it (atomically).  A
 * corrupt or stale cache file is reported on stderr once and rebuilt. */
bool r_ibl_build(const r_stage *st, const r_ibl_params *p, const char *cache_dir, r_ibl *out, rs_err *err);
void r_ibl_free(r_ibl *ibl);

/* The cache key r_ibl_build uses (p NULL = defaults; reads a loaded
 * environment's file): the format version, the sizes and every stage field
 * the maps depend on. */
bool r_ibl_hash(const r_stage *st, const r_ibl_params *p, uint64_t *hash, rs_err *err);

/* $RINGSIDE_CACHE, else $XDG_CACHE_HOME/ringside, else $HOME/.cache/ringside
 * (NULL when none is set).  "off" in RINGSIDE_CACHE disables the cache. */
const char *r_ibl_cache_dir(void);

#endif
