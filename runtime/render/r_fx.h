/* Stage effects (issue 8; techniques A6-A8, B, C, D): each effect is a
 * module of passes that the renderer's pass graph runs only on stages (or
 * frames) that need them.
 *
 * A module (r_fx_<name>.c) keeps its state behind one pointer in r_game
 * (r_local.h) and gives the renderer:
 *   create   at r_game_create: programs and fixed-size GL objects
 *   destroy  at r_game_destroy (also after a failed create)
 *   load     when the look changes (r->stage is the new stage)
 *   passes   by phase, added to the graph in this order:
 *     R_FX_PRE          after the shadow passes, before "scene"
 *                       (simulations, light-space and texture-space maps)
 *     R_FX_SURFACE      after "scene", before "sky": opaque surfaces
 *     R_FX_TRANSLUCENT  after "sky", before "lens"
 * Passes get the r_game as their user pointer; the frame being drawn is
 * r->f.  Simulations step r->f.steps times (whole game ticks since the
 * frame drawn last, 0 when a tick is drawn again) and restart when
 * r->f.reset is set, so a video of a replay (every tick drawn) is the same
 * on any machine.  A frame spanning several ticks knows only the last two
 * (docs/effects.md says what each effect does then). */
#ifndef R_FX_H
#define R_FX_H

#include <stdbool.h>
#include <stdio.h>

#include "../game/g_skel.h"
#include "../gl/rgl.h"
#include "../util/rs_err.h"
#include "r_graph.h"

typedef struct r_game r_game;

/* A fighter's bone capsule in world space (metres; the fight plane is
 * z = 0, a bone's z is its lateral offset for the mesh). */
typedef struct r_fx_capsule {
    float a[3], b[3], r;
} r_fx_capsule;

/* Where a bone capsule dips below a horizontal surface at height level:
 * the point of the segment lowest below it, how deep the capsule reaches
 * under the surface, and how fast that point of the bone moved over the
 * last tick (m/s; the point at the same place along the bone). */
typedef struct r_fx_contact {
    float x, z;     /* on the surface */
    float depth;    /* > 0: metres of the capsule below the level */
    float radius;   /* the capsule's radius */
    float speed;    /* m/s */
    float vel[3];   /* m/s */
    int fighter, bone;
} r_fx_contact;

/* More ticks than this between two frames (a seek) restart the simulations. */
#define R_FX_MAX_GAP 30

enum { R_FX_PRE, R_FX_SURFACE, R_FX_TRANSLUCENT, R_FX_PHASES };

typedef struct r_fx_module {
    const char *name;
    bool (*create)(r_game *r, rs_err *err);
    void (*destroy)(r_game *r);
    bool (*load)(r_game *r, rs_err *err);
    const r_pass *pass[R_FX_PHASES];
    int npass[R_FX_PHASES];
} r_fx_module;

extern const r_fx_module *const r_fx_modules[];
extern const int r_fx_nmodules;

/* Contacts of both fighters' capsules with the plane y = level (at most
 * max, deepest first when there are more).  caps/caps_prev as in
 * r_local.h's frame.  Returns the number written. */
int r_fx_contacts(const r_fx_capsule caps[2][G_BONES], const r_fx_capsule prev[2][G_BONES], float level, r_fx_contact *out,
                  int max);

/* Fog map (r_fx_fog.c): sets program p's fog uniforms (u_fog_on and the
 * map when the fog_map pass ran this frame).  Every program that draws the
 * scene calls it; its shaders include fog_common.glsl. */
void r_fx_fog_bind(r_game *r, GLuint p, int unit);
/* Its hooks for tests and bench accuracy: the mist simulation (NULL when
 * the module was not created), the map of the frame drawn last (size x
 * size floats, row = z, covering x, z in +-half metres; out NULL asks the
 * size only), and the "fog-map resolution vs time" table of bench
 * accuracy (needs a current GL context). */
struct r_fog_sim *r_fx_fog_sim(r_game *r);
bool r_fx_fog_read_map(r_game *r, float *out, int *size, float *half);
bool r_fx_fog_accuracy_rows(FILE *out, rs_err *err);

/* LSPSM (r_fx_lspsm.c): sets program p's u_lspsm_* uniforms and its two
 * maps on units `unit` and `unit + 1` (u_lspsm_on = 0 whenever the map was
 * not drawn this frame).  Every program that draws the scene with
 * lspsm_common.glsl calls it. */
void r_fx_lspsm_bind(r_game *r, GLuint p, int unit);
/* What the last frame's lspsm_map did, for tests, bench and docs. */
typedef struct r_fx_lspsm_stats {
    int casters, casters_drawn;   /* buildings, and those that passed culling */
    int city_triangles, proxy_triangles;
    float range;                  /* the shadow range used (the focus), m */
    float warp, gamma;            /* r_lspsm's warp strength and view-light angle */
    float focus_farthest;         /* the farthest sample the focus found, m */
    int focus_used;               /* samples that counted */
} r_fx_lspsm_stats;
bool r_fx_lspsm_stats_get(r_game *r, r_fx_lspsm_stats *out);
/* Tests and bench: force the light direction (NULL: the stage's key),
 * switch caster culling off, or the warp (plain uniform shadow mapping). */
void r_fx_lspsm_test_set(r_game *r, const float *light, bool no_cull, bool uniform);
/* Tests: "map" (1024x1024 depth floats), "flag" (1024x1024), "focus"
 * (20x16 depth samples of the frame drawn last), "shadow" (16 floats). */
bool r_fx_lspsm_read(r_game *r, const char *what, float *out);

/* Holes (r_fx_holes.c): how many the frame drawn last cut into the ring. */
int r_fx_holes_drawn(r_game *r);

#endif
