/* Meshes generated at load from primitives: no asset files.
 *
 * Vertex format (r_vertex): position, normal, tangent (xyz + handedness),
 * uv, bone index.  Tangents and UVs are there for the normal and colour
 * specular maps of the renderer-core work; the plain renderer uses
 * position, normal and bone. */
#ifndef R_MESH_H
#define R_MESH_H

#include <stdbool.h>
#include <stddef.h>

#include "../game/g_skel.h"

typedef struct r_vertex {
    float pos[3], normal[3], tangent[4], uv[2];
    float bone;
} r_vertex;

typedef struct r_mesh_data {
    r_vertex *v;
    unsigned *idx;
    size_t nv, ni, capv, capi;
} r_mesh_data;

/* A capsule along +x from 0 to `length`, radius r, for bone `bone`. */
int r_mesh_capsule(r_mesh_data *m, float length, float r, int bone, int segments, int rings);
/* A unit sphere round the y axis for bone `bone`: rows of seg + 1
 * vertices at the polar angles phi[0..rows-1], from the -y pole (0) to the
 * +y pole (pi), ascending; the same vertex layout and winding as a
 * capsule's (outward faces counter-clockwise), so a caller places the
 * rows where its picture needs them. */
int r_mesh_sphere_rows(r_mesh_data *m, int bone, int seg, const float *phi, int rows);
/* An axis-aligned box from lo to hi (bone index -1: world space). */
int r_mesh_box(r_mesh_data *m, const float lo[3], const float hi[3]);
/* The whole fighter: one capsule per bone of g_bones, at a level of
 * detail.  Fine: 20 segments round the thick bones, 14 round the thin
 * ones, 5 rings a cap; coarse: 14, 10 and 4, a little under half the
 * triangles, for frames drawn at few rows (r_game.c, R_FIGHTER_COARSE_ROWS),
 * where the fine mesh's extra triangles are smaller than the pixels but
 * still cost a software rasteriser every pass that draws the fighters. */
enum { R_FIGHTER_COARSE, R_FIGHTER_FINE, R_FIGHTER_LODS };
#define R_FIGHTER_COARSE_ROWS 540 /* frames drawn at fewer rows take the coarse mesh */
int r_mesh_fighter(r_mesh_data *m, int lod);
void r_mesh_free(r_mesh_data *m);

#endif
