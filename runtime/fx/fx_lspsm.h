/* The LSPSM effect's hooks for tests, bench and docs (fx_lspsm.c; the
 * effect itself is reached only through its r_fx_module row). */
#ifndef FX_LSPSM_H
#define FX_LSPSM_H

#include <stdbool.h>

struct r_game;

/* What the last frame's lspsm_map did. */
typedef struct fx_lspsm_stats {
    int casters, casters_drawn;   /* buildings, and those that passed culling */
    int city_triangles, proxy_triangles;
    float range;                  /* the shadow range used (the focus), m */
    float warp, gamma;            /* r_lspsm's warp strength and view-light angle */
    float focus_farthest;         /* the farthest sample the focus found, m */
    int focus_used;               /* samples that counted */
    bool fighters_in_map;         /* the fighters are in the receivers' map (their shadows off) */
    bool fighters_cast;           /* the buildings' map with the fighters was drawn (a shadow may reach one) */
    bool is_static;               /* the map is the static layers (r_quality.lspsm_static) */
    int static_draws;             /* times the static layers were drawn since the look was loaded */
    float static_texel[2];        /* their texels across the light, metres (the longer side), finest first */
} fx_lspsm_stats;
bool fx_lspsm_stats_get(struct r_game *r, fx_lspsm_stats *out);
/* Tests and bench: force the light direction (NULL: the stage's key),
 * switch caster culling off, or the warp (plain uniform shadow mapping). */
void fx_lspsm_test_set(struct r_game *r, const float *light, bool no_cull, bool uniform);
/* Tests: never draw the buildings' map with the fighters (the frame as it
 * would be without it). */
void fx_lspsm_test_no_cast(struct r_game *r, bool off);
/* Tests: "map" (N x N depth floats, N = r_quality.lspsm_size clamped to
 * 256..4096, 0: R_LSPSM_MAP 1024), "cast" (N x N: the buildings' map with
 * the fighters, false until one was drawn), "size" (4 floats: the map's
 * and the buildings' map's width and height as GL has them; the map's
 * twice while the second was never made), "focus" (20x16 depth samples
 * of the frame drawn last), "shadow" (16 floats).  With the static
 * layers (fx_lspsm_stats.is_static) "map" and "cast" are not drawn. */
bool fx_lspsm_read(struct r_game *r, const char *what, float *out);

#endif
