/* The game renderer (renderer core, docs/renderer.md): the Virtua
 * Fighter 5 look (docs/renderer.md) on a pass graph.
 *
 *   shadow_map, silhouette, silhouette_mips   from the key light
 *   z_prepass, shadow_mask, mask_filter        SSFSM for the fighters
 *   scene, sky, lens                           HDR (RGBA16F), IBL, alpha = mask
 *   bloom_bright, bloom_blur                   bloom from the HDR buffer
 *   sun_visibility, flare                      only when the sun is on screen
 *   tonemap, hud                               YCbCr curve into the output
 *
 * It reads game state and never writes it.  Draws interpolate between the
 * previous and the current tick (alpha 0..1).  State in, pixels out, into
 * whatever framebuffer is bound. */
#ifndef R_GAME_H
#define R_GAME_H

#include <stdio.h>

#include "../game/g_game.h"
#include "../util/rs_err.h"
#include "r_err.h"
#include "r_graph.h"
#include "r_math.h"
#include "r_stage.h"

typedef struct r_game r_game;

/* r_game_opts.hdr_format: zero is the stage's own (r_stage.hdr_format). */
typedef enum r_game_hdr { R_GAME_HDR_STAGE, R_GAME_HDR_RGBA16F, R_GAME_HDR_R11G11B10F } r_game_hdr;

/* An r_hdr_format (cli_hdr_format's) as an r_game_hdr. */
static inline r_game_hdr r_game_hdr_of(int fmt)
{
    return fmt == R_HDR_R11G11B10F ? R_GAME_HDR_R11G11B10F : R_GAME_HDR_RGBA16F;
}

/* The renderer's cost/accuracy knobs (docs/accuracy.md, "Quality"): zero
 * in every field is the full-quality default.  The render scale (how many
 * pixels are drawn per output pixel) is not here: it is the caller's
 * choice of the size passed to r_game_draw.  Presets are rs_quality's
 * (runtime/render/r_quality.h); each field is read at r_game_create_opts. */
typedef enum r_aa { R_AA_OFF, R_AA_FXAA } r_aa;
typedef struct r_quality {
    int shadow_size;  /* SSFSM light depth map, texels a side, 128..4096: 0 = 1024 */
    int sil_size;     /* projection-shadow silhouette, level 0, 64..2048: 0 = 512 */
    bool mask_half;   /* SSFSM's shadow mask and its filter at half the render size */
    int bloom_levels; /* bloom pyramid levels added, 1..2: 0 = 2 (1/4 and 1/8 of 720 rows) */
    r_aa aa;          /* post-process anti-aliasing on the tone-mapped image */
    int lspsm_size;   /* LSPSM shadow map, texels a side: 0 = the module's default; clamped to 256..4096 */
    int lspsm_static; /* where the light and the casters stand still (plaza) and the fighters' own shadows
                         run: the buildings' shadows from two orthographic layers of this many texels a
                         side (256..4096), drawn once per look, instead of an LSPSM map every frame; 0 = off */
    int fog_size;     /* the mist's top-down density map, 64..1024: 0 = the module's default */
    int water_grid;   /* water surface quads a side, 16..256: 0 = the module's default */
    int snow_light;   /* the snow's texture-space light map, texels a side, 64..256: 0 = 256 */
    int scene_pct;    /* the scene and every pass before the tone map drawn at this percentage of the output's
                         width and height, 50..100: 0 = 100; the tone map too, its 8-bit image then
                         blitted up (bilinear), and the HUD at the output size (with anti-aliasing the tone
                         map runs at the output size, reading the scene bilinearly) */
    bool stage_scene; /* scene_pct 0: the stage's standard_scene_pct (r_stage.h), measured per stage */
} r_quality;

/* The scene's percentage of the output's size under q for a stage whose
 * standard_scene_pct is stage_pct: q.scene_pct, else the stage's when
 * q.stage_scene, else 100. */
int r_scene_pct(const r_quality *q, int stage_pct);

/* The scene's size for an output of w x h at pct percent (w x h itself at
 * 100), at least a pixel each way. */
void r_scene_size(int pct, int w, int h, int *sw, int *sh);

/* Zero is the default for every field. */
typedef struct r_game_opts {
    const char *stage_file; /* NULL: <data>/stages/<game stage>.stage */
    bool mask;              /* output alpha = the fighters' mask (and no HUD) */
    bool no_hud;
    r_game_hdr hdr_format;  /* 0 (R_GAME_HDR_STAGE): the stage's */
    const char *cache_dir;  /* NULL: r_ibl_cache_dir(); "" = no cache */
    int lut_size;           /* 0: R_TONE_LUT_DEFAULT */
    bool quiet;             /* no note when prefiltering takes a while */
    bool aa_plain;          /* tests: FXAA as one full pass over every pixel (no early out; the same bytes) */
    bool whole_meshes;      /* tests: effects draw the fighters' whole mesh where they draw some bones (the
                               afterimage; the same bytes) */
    bool light_apart;       /* tests: the shadow map and the silhouette in passes of their own even when their
                               sides agree (r_shadow.c draws both at once then; the same bytes) */
    bool fine_mesh;         /* the fine fighter mesh at any size (r_mesh_fighter; by default the coarse one
                               below R_FIGHTER_COARSE_ROWS rows drawn) */
    r_quality q;            /* zero: full quality */
} r_game_opts;

/* Needs a current GL context. */
r_game *r_game_create(rs_err *err);
r_game *r_game_create_opts(const r_game_opts *o, rs_err *err);
void r_game_destroy(r_game *r);

/* Loads the look of a game stage now (stage file, environment, IBL), so
 * errors come before the first frame; r_game_draw does it on demand. */
bool r_game_prepare(r_game *r, int game_stage, rs_err *err);
/* Uses this stage description (whatever the game stage) from now on. */
bool r_game_set_stage(r_game *r, const r_stage *st, rs_err *err);
const r_stage *r_game_stage(const r_game *r);

/* Draws into the bound framebuffer, viewport 0,0,w,h.  Returns false with
 * err filled (and clears to black) when the frame cannot be drawn: a size
 * out of range (R_ERR_SIZE), a look that cannot load (the stage file's,
 * shaders' or IBL's id), targets the driver cannot make (R_ERR_TARGET),
 * out of memory (R_ERR_NOMEM). */
bool r_game_draw(r_game *r, const g_state *prev, const g_state *cur, float alpha, int w, int h, rs_err *err);
/* Starting a render at tick A > 0 exactly (r_fx.h, "History"):
 *
 *   h = r_game_history(r, stage, err);        how far back frame A looks
 *   from = h == R_GAME_FROM_START ? 0 : A - min(A, h);
 *   r_game_restart(r);                        the first tick advanced resets
 *   for (t = from; t < A; t++)                states before `from`: simulated only
 *       r_game_advance(r, &prev_t, &cur_t, w, h, A - t, NULL, err);
 *   r_game_draw(r, &prev_A, &cur_A, 1, w, h, err); the frame a full render draws
 *
 * r_game_history loads the stage's look (as r_game_prepare) and returns the
 * ticks of history its effects carry into a frame: 0 (none: frame A needs
 * nothing before it), N, or R_GAME_FROM_START (every tick from 0); -2 with
 * err filled when the look cannot load. */
#define R_GAME_FROM_START (-1)
int64_t r_game_history(r_game *r, int game_stage, rs_err *err);
/* The next frame drawn or advanced starts a new sequence (a reset). */
void r_game_restart(r_game *r);
/* Moves the stage effects' history on by the one game tick cur without
 * drawing it; `ahead` is the number of ticks from this one to the first
 * frame that will be drawn (>= 1).  Where an effect whose window holds
 * this tick needs the frame itself (LSPSM's auto-focus), the frame is
 * drawn into the bound framebuffer at alpha 1 and *drew (may be NULL) is
 * set.  prev, w, h as r_game_draw would get them.  Returns false with err
 * filled as r_game_draw does. */
bool r_game_advance(r_game *r, const g_state *prev, const g_state *cur, int w, int h, uint64_t ahead, bool *drew,
                    rs_err *err);

/* --passes: time every pass; per_frame prints one line per frame to out. */
void r_game_passes(r_game *r, bool per_frame, FILE *out);
void r_game_report(r_game *r, FILE *out);
r_graph *r_game_graph(r_game *r);

/* Reads back the HDR buffer of the last frame (w*h*4 floats, bottom-up) or
 * a named intermediate ("hdr", "bloom", "mask", "depth" (w*h floats), "shadow" (the light depth
 * map, one float a texel), "silhouette", the blurred
 * levels "silhouette1".."silhouette4"): tests.  out NULL: size only. */
bool r_game_read_buffer(r_game *r, const char *name, float *out, int *w, int *h);

/* Tests: the core passes' C paths (the default on a software rasteriser:
 * bloom's blurs and glow, r_bloom.h; the silhouette's blurred levels) or
 * their GL passes; returns the setting before. */
bool r_game_set_cpu_paths(r_game *r, bool cpu);

/* The game stage whose ring size the last frame drew (the match's, also
 * under a --stage-file look for another stage); -1 before the first. */
int r_game_ring_stage(const r_game *r);

/* The camera r_game_draw used for this state (tests project with it). */
r_mat4 r_game_camera(const g_state *st, int w, int h, r_vec3 *eye);
/* The same camera as view and projection (r_game_camera = proj * view). */
void r_game_camera_parts(const g_state *st, int w, int h, r_mat4 *view, r_mat4 *proj, r_vec3 *eye);

/* Fighter colours, for tests that look for them. */
extern const float r_fighter_color[2][3];

#endif
