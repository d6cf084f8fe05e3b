/* The render core as the stage effects (runtime/fx/) see it: the frame
 * being drawn, the loaded look, the GL objects they draw with or read,
 * and the core's drawing helpers.  The contract the effects implement is
 * r_fx.h; this is what the core hands them for it (docs/effects.md, "The
 * effect contract").  The core's own insides (struct r_game) stay in
 * r_local.h, which the effects do not include. */
#ifndef R_FX_CORE_H
#define R_FX_CORE_H

#include <stdbool.h>
#include <stdint.h>

#include "../game/g_game.h"
#include "../gl/rgl.h"
#include "r_fx.h"
#include "r_game.h"
#include "r_math.h"
#include "r_mesh.h"
#include "r_stage.h"

#define SIL_LEVELS 5     /* the sharp level and 4 blurred ones */

/* resources of the pass graph */
enum {
    RES_ENV = 1u << 0,  /* IBL maps, sky, LUT, textures: built at load */
    RES_SHADOW = 1u << 1,
    RES_SIL = 1u << 2,
    RES_DEPTH = 1u << 3,
    RES_MASK = 1u << 4,
    RES_HDR = 1u << 5,
    RES_BLOOM = 1u << 6,
    RES_SUNVIS = 1u << 7,
    RES_OUT = 1u << 8,
    RES_FLARE = 1u << 9,
};
#define R_RES_CORE 10      /* the core's resources: bits 0..9 */
#define R_RES_FX_FIRST 10  /* from here up, the stage effects' (r_fx.h) */

/* scene.frag's materials (MATERIAL): what the stage programs draw */
enum { R_MAT_PLANKS, R_MAT_PAVED, R_MAT_BUILDING, R_MAT_HOLE };

/* stencil bits: the scene pass marks the fighters' pixels */
#define R_STENCIL_FIGHTER 0x80

/* The frame being drawn (or advanced: r_game_advance), set up by the core
 * before any pass runs. */
typedef struct frame {
    const g_state *prev, *cur;
    float alpha;
    int w, h;         /* the scene's size: every pass up to the tone map */
    int out_w, out_h; /* the output's: the tone map, the AA pass, the HUD (r_quality.scene_pct) */
    r_mat4 vp, inv_vp, light;
    r_vec3 eye, light_dir, waist[2];
    float bones[2][16][16], colors[2][16][4];
    float flash, saturation, exposure;
    bool sun_on_screen;
    float sun_px[2];
    int fig_box[4]; /* x, y, w, h: the fighters on screen plus the mask filter's reach */
    GLint out_fbo;
    /* for the stage effects (r_fx.h): whole ticks, never interpolated, so
     * what the simulations see is a function of the game states alone */
    r_fx_capsule caps[2][G_BONES], caps_prev[2][G_BONES]; /* at cur->tick and prev->tick */
    int steps;   /* game ticks since the frame drawn last: simulation steps to run now */
    bool reset;  /* the sequence broke (first frame, seek, new stage): restart simulations */
    r_mat4 view, proj, view_prev; /* the camera now and at prev->tick (afterimages); vp = proj * view */
    float bones_prev[2][16][16], bones_tick[2][16][16]; /* at prev->tick and cur->tick, not interpolated */
    /* a warm-up frame (r_game_advance drawing for an effect's history): the
     * scene's depth is all that history reads (LSPSM's focus), so the
     * scene passes draw depth alone and the light-space maps are not drawn */
    bool depth_only;
} frame;

/* The frame being drawn: what a pass, a hook or a module's history reads
 * of it (r_fx.h, "History": steps and reset). */
const frame *r_fx_frame(const r_game *r);
/* The loaded look (after r_game_prepare or r_game_set_stage; a module's
 * load hook sees the new one). */
const r_stage *r_fx_stage(const r_game *r);
/* The game stage the look was loaded for; -1 when r_game_set_stage set it
 * (then the look's own game_index names it). */
int r_fx_stage_game(const r_game *r);
/* The IBL's key direction, towards the light (unit): shadows are cast
 * from it. */
const float *r_fx_key_dir(const r_game *r);
/* The quality knobs r_game_create_opts was given (range checked there). */
const r_quality *r_fx_quality(const r_game *r);
/* The fighters' level of detail this frame (R_FIGHTER_COARSE below
 * R_FIGHTER_COARSE_ROWS rows drawn, unless the options ask for the fine
 * one; r_mesh.h): an effect's own meshes follow the same choice, indexed
 * the same way. */
int r_fx_mesh_lod(const r_game *r);

/* The core's GL objects an effect draws with or reads.  The screen
 * targets are remade when the render size changes: ask again each frame. */
typedef struct r_fx_gl {
    GLuint hdr_fbo, hdr_tex, depth_tex; /* the scene's HDR target and its depth (and stencil) */
    GLuint sil_tex;                     /* the fighters' silhouette from the key light, SIL_LEVELS mips */
    GLuint sky_tex;                     /* the environment as seen */
    GLuint diffuse_on;                  /* the IBL's diffuse map with the key light */
    GLuint empty_vao;                   /* no attributes: full-screen passes */
    GLuint fighter_vao, ring_vao;       /* the fighter mesh, the ring mesh */
    GLsizei fighter_count, ring_count;  /* their index counts */
    /* the fighter mesh's triangles by bone: bone b's indices are
     * [fighter_bone_first[b], fighter_bone_first[b + 1]) */
    GLsizei fighter_bone_first[G_BONES + 1];
    bool whole_meshes; /* r_game_opts.whole_meshes: draw whole meshes, not bone ranges (tests) */
    GLuint prog_depth;                  /* depth only (scene.vert, bones or not) */
    GLuint prog_sky;                    /* the sky (sky.frag) */
} r_fx_gl;
r_fx_gl r_fx_core_gl(const r_game *r);

/* the GL layer (r_gl.c) */
GLint r_loc(GLuint p, const char *name);
void r_upload_mesh(const r_mesh_data *m, GLuint *vao, GLuint *vbo, GLuint *ibo);
void r_free_mesh(GLuint *vao, GLuint *vbo, GLuint *ibo);
GLuint r_tex2d(GLenum ifmt, int w, int h, GLenum fmt, GLenum type, const void *px, GLenum filter, GLenum wrap);
GLuint r_fbo_for(GLuint color, int level, GLuint depth); /* depth: a GL_DEPTH24_STENCIL8 texture or 0 */
void r_bind_tex(GLuint p, const char *name, int unit, GLenum target, GLuint t);
void r_bind_ibl(r_game *r, GLuint p); /* units 8..13 */
void r_fullscreen(r_game *r);      /* one triangle: cap_fullscreen.vert */
int r_half(int v, int k);          /* v >> k, at least 1 */
void r_blur_into(r_game *r, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float dx, float dy);

/* did the pass run this frame (so far) (r_frame.c) */
bool r_ran(const frame *f, r_game *r, const char *name);

/* the scene (r_scene.c) */
void r_draw_fighters(r_game *r, GLuint p); /* both fighters with program p (scene.vert), VAO left bound */
void r_camera_uniforms(r_game *r, GLuint p); /* uses p; u_view_proj, u_eye */
/* Uses the stage program that draws `material` (R_MAT_*) and sets its
 * uniforms for this frame (lighting, shadows, the effects' maps through
 * r_fx_bind); returns it.  The ring's material is r_ring_material's
 * (paved ground on a look with buildings). */
GLuint r_stage_program(r_game *r, int material);
/* Opaque drawing into the HDR target: its FBO and the frame's viewport,
 * depth test (less) and writes, back faces culled, no blending. */
void r_begin_opaque(r_game *r);
/* The ring mesh (build_ring): its box's +y face, the destructible ring
 * top, is the 6 indices from here; the ground's box follows the ring's. */
#define R_RING_TOP_FIRST 30
/* The key light's uniforms (u_light_proj, u_light_dir), the fighters'
 * waists (u_waist) and the silhouette's LOD range (u_lod_start,
 * u_lod_scale): what a program that looks up the fighters' shadows
 * needs of the frame; p in use. */
void r_light_uniforms(GLuint p, const frame *f);
/* The sun disc of the sky program (sky.frag), p in use: u_sun_dir,
 * u_sun_radiance (the stage's intensity spread over the disc's solid
 * angle, each channel kept below fp16's largest) and u_sun_cos. */
void r_sun_uniforms(GLuint p, const r_stage *st);

#endif
