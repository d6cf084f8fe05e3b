/* The stage-effect contract (docs/effects.md, "The effect contract").
 *
 * An effect is a module in runtime/fx/ (fx_<name>.c): one r_fx_module row
 * in the table runtime/fx/fx_table.c lists.  The render core calls it only
 * through this struct and never names an effect, its resources or its
 * texture units; adding an effect is adding its file and one row.  An
 * effect's own tests and bench hooks live in its own header in runtime/fx/
 * (fx_fog.h, fx_lspsm.h, fx_holes.h, fx_snow_tex.h, fx_water_sim.h).
 *
 * State.  A module keeps its state behind one pointer that the core holds
 * for it: r_fx_set_state at create, r_fx_state(r, &its_module) after.
 *
 * Lifecycle.
 *   create   at r_game_create: programs and fixed-size GL objects
 *   destroy  at r_game_destroy (also after a failed create; the state
 *            may then be NULL or half made)
 *   load     when the look changes (r_fx_stage(r) is the new look)
 *
 * Passes, by phase; r_game.c's build_graph adds them in table order:
 *   R_FX_PRE          after the shadow passes, before "scene"
 *                     (simulations, light-space and texture-space maps)
 *   R_FX_SURFACE      after "scene", before "sky": opaque surfaces
 *   R_FX_TRANSLUCENT  after "sky", before "lens"
 * Passes get the r_game as their user pointer; the frame being drawn is
 * r_fx_frame(r).  What the core hands the effects (the frame, the look,
 * its GL objects, its drawing helpers) is r_fx_core.h; they see nothing
 * else of it.
 *
 * Resources.  Bits from R_RES_FX_FIRST up of the pass graph's mask belong
 * to the effects (runtime/fx/fx_local.h gives them out); a module names
 * those it writes in res[] (persistent ones survive from frame to frame),
 * and scene_reads says which of them the scene, sky and lens programs may
 * read through its bind hook.
 *
 * Binding into the scene.  Every program that draws the scene (the
 * fighters and stage programs, the sky, the visors, and effect passes that
 * use r_stage_uniforms) calls r_fx_bind, which calls each module's bind
 * with `units` texture units of its own, handed out by the core from
 * R_FX_UNIT_FIRST in table order.  A module binds its maps there (or 0
 * with its "on" uniform off when its pass did not run this frame).
 *
 * The look's programs.  scene_define names a preprocessor symbol that the
 * scene programs (scene.vert/.frag, sky.frag, lens.frag) are compiled with
 * while the loaded stage uses the effect, NULL while it does not: the
 * effect's code in those shaders sits inside #ifdef NAME, so a stage
 * without it pays nothing for it.  (A uniform "on" test is not enough:
 * a software rasteriser such as llvmpipe runs both sides of every branch,
 * and mist and LSPSM taps on every pixel of every stage cost dojo's scene
 * pass a quarter of its time.)  The "on" uniform stays, for the frames
 * whose pass did not run.
 *
 * Inside "scene".  scene_cleared says the effect already cleared the HDR
 * target and drew into it this frame (the holes: stencil volumes before
 * the fighters), so scene must not clear it; draw_ring draws the ring mesh
 * in the effect's own order (scene has bound the stage program and the
 * ring's VAO) and returns true, or returns false and scene draws it whole.
 * scene_depth draws, before the ring, the depth of the opaque surfaces its
 * R_FX_SURFACE pass will shade this frame (depth_prog: the depth-only program,
 * the camera's uniforms set, colour writes off) and returns true when it
 * drew: the ring's and the ground's pixels behind them then fail the depth
 * test before they are shaded (a software rasteriser shades every fragment
 * that passes the depth test), and the
 * surface pass draws over its own depth with GL_LEQUAL (scene.vert's
 * invariant gl_Position makes the two agree exactly).
 *
 * History.  Simulations step the frame's steps times (r_fx_frame: whole
 * game ticks since the frame drawn last, 0 when a tick is drawn again)
 * and restart when its reset is set, so a video of a replay (every tick drawn) is the same
 * on any machine.  What a module carries from one frame to the next is its
 * history, and a render that starts at tick A > 0 (render --ticks A:B, a
 * segment of a split job) rebuilds it exactly through three hooks:
 *   warmup(r)       on the loaded stage, how much history frame A depends
 *                   on: R_FX_STATELESS (0: the frame is a function of the
 *                   game states), N > 0 (the last N ticks: older history
 *                   provably no longer changes a bit of the frame), or
 *                   R_FX_FROM_START (every tick since the last reset).
 *                   NULL: stateless on every stage.
 *   advance(r)      moves the history on by exactly one game tick without
 *                   drawing (r_game_advance sets up the frame for the tick
 *                   first, reset included).  Called on every advanced
 *                   tick, inside the module's window or not, so that a
 *                   reset reaches it; a module whose window is N ticks
 *                   starts the window from its reset state.
 *   needs_frame(r)  inside the module's window, true when its history
 *                   cannot move on without the frame itself (LSPSM's
 *                   auto-focus reads the drawn depth buffer): r_game_advance
 *                   then draws the frame, which advances every module the
 *                   way a full render does.
 * So that drawing ticks 0..A-1 and then A gives the same frame A as
 * advancing the ticks the modules ask for and drawing A
 * (r_game_history says how far back that is).
 * docs/effects.md ("The effect contract") lists each effect's history. */
#ifndef R_FX_H
#define R_FX_H

#include <stdbool.h>
#include <stdint.h>

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

/* What r_fx_bind is binding for (a module's bind may skip some). */
enum { R_FX_BIND_SCENE, R_FX_BIND_SKY, R_FX_BIND_LENS };

enum { R_FX_STATELESS = 0, R_FX_FROM_START = -1 };

#define R_FX_MAX_RES 4     /* resources a module may own */
#define R_FX_MAX_MODULES 16

typedef struct r_fx_res {
    uint32_t bit;      /* one bit from R_RES_FX_FIRST up */
    const char *name;  /* for the graph's messages */
    bool persistent;   /* valid without a writer this frame (carried history) */
} r_fx_res;

typedef struct r_fx_module {
    const char *name;
    /* lifecycle; each may be NULL */
    bool (*create)(r_game *r, rs_err *err);
    void (*destroy)(r_game *r);
    bool (*load)(r_game *r, rs_err *err);
    /* passes by phase */
    const r_pass *pass[R_FX_PHASES];
    int npass[R_FX_PHASES];
    /* the resources it writes, and those the scene programs may read */
    r_fx_res res[R_FX_MAX_RES];
    uint32_t scene_reads;
    /* binding into the scene: `units` texture units from `unit` on */
    int units;
    void (*bind)(r_game *r, GLuint prog, int unit, int what);
    const char *(*scene_define)(const r_game *r); /* the look's define, or NULL */
    /* inside "scene" (NULL: nothing to do there) */
    bool (*scene_cleared)(r_game *r);
    bool (*draw_ring)(r_game *r);
    bool (*scene_depth)(r_game *r, GLuint depth_prog);
    /* history */
    int (*warmup)(r_game *r);         /* on the loaded stage: R_FX_STATELESS, N ticks or R_FX_FROM_START */
    void (*advance)(r_game *r);       /* one game tick, the frame set up; draws nothing on screen */
    bool (*needs_frame)(r_game *r);   /* in its window: its history needs the drawn frame */
} r_fx_module;

/* The table (runtime/fx/fx_table.c), in the order the passes run. */
extern const r_fx_module *const r_fx_modules[];
extern const int r_fx_nmodules;

/* A module's state pointer, kept by the core (NULL until set). */
void *r_fx_state(const r_game *r, const r_fx_module *m);
void r_fx_set_state(r_game *r, const r_fx_module *m, void *state);

/* Texture units handed to the modules' bind hooks: from here up, below the
 * IBL's units 8..13 (r_bind_ibl).  r_game_create checks they fit. */
#define R_FX_UNIT_FIRST 3
#define R_FX_UNIT_END 8

/* Contacts of both fighters' capsules with the plane y = level (at most
 * max, deepest first when there are more).  caps/caps_prev as in
 * r_fx_core.h's frame.  Returns the number written. */
int r_fx_contacts(const r_fx_capsule caps[2][G_BONES], const r_fx_capsule prev[2][G_BONES], float level, r_fx_contact *out,
                  int max);

#endif
