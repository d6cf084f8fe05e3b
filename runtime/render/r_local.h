/* The game renderer's insides, shared by the render core's files.  Not an
 * API: include only from runtime/render.  The stage effects (runtime/fx/)
 * see the part of the core they use through r_fx_core.h. */
#ifndef R_LOCAL_H
#define R_LOCAL_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "../gl/rgl.h"
#include "r_fx.h"
#include "r_fx_core.h"
#include "r_game.h"
#include "r_graph.h"
#include "r_ibl.h"
#include "r_mesh.h"

#define HUD_MAX_QUADS 4096
#define SHADOW_SIZE 1024 /* SSFSM light depth map: r->shadow_size (r_quality.shadow_size) */
#define SIL_SIZE 512     /* silhouette, level 0: r->sil_size (r_quality.sil_size) */
/* Screen-space sizes are fractions of the frame height, with today's
 * look kept at R_REF_ROWS (docs/renderer.md, "Resolution independence"). */
#define R_REF_ROWS 720
#define BLOOM_ROWS 180 /* the bloom's first level at any render size; the second has half */
#define BLOOM_XSTEPS 5 /* halvings past the half-size bright pass before the resample */
#define SKY_SIZE 128     /* the environment as seen */
#define LENS_ALPHA 0.15f

#define RES_PERSISTENT RES_ENV

typedef struct hud_vertex {
    float x, y, u, v, r, g, b, a;
} hud_vertex;

typedef struct prog {
    GLuint id;
} prog;

/* P_FIGHTER .. P_STAGE_HOLE are the look's programs: compiled when a look
 * loads, with the look's defines (build_look_programs in r_game.c); the
 * rest once at create.  P_STAGE draws the ring and the ground, P_STAGE_BUILDING
 * the city's buildings and P_STAGE_HOLE the craters' insides (0 on a look
 * without them). */
enum { P_FIGHTER, P_STAGE, P_STAGE_BUILDING, P_STAGE_HOLE, P_LENS, P_SKY, P_LOOK_END,
       P_DEPTH = P_LOOK_END, P_SIL, P_MASK, P_GROW, P_BLUR, P_BLUR_TEXELS, /* + 3: reaching 1..4 texels */
       P_DOWN = P_BLUR_TEXELS + 4, P_DOWN_RGBE, P_DOWN_RGBE_IN, /* into a bloom level (RGBE), and from one too */
       P_BLUR_RGBE, /* one of bloom's levels (RGBE) across or down */
       P_SUNVIS, P_FLARE, P_HUD, P_HUD_RECT, P_HUD_2TAPS, P_FXAA, P_FXAA_MARK,
       P_GLOW, /* + 4 variants: bloom's last blur with its second level x the flare (r_post.c) */
       P_TONE = P_GLOW + 4, /* + 1: with the glow; + 2: scaling the scene up (r_quality.scene_pct), + 3 both */
       P_COUNT = P_TONE + 4 };


struct r_game {
    r_game_opts opts;
    char stage_file[1024];
    GLuint prog[P_COUNT];
    char look_defines[320]; /* what the look's programs were compiled with */
    /* the fighter mesh at each level of detail (r_mesh_fighter), and the
     * one this frame draws (draw(), by the rows it is drawn at) */
    struct fighter_mesh {
        GLuint vao, vbo, ibo;
        GLsizei count, bone_first[G_BONES + 1];
    } fighter_lod[R_FIGHTER_LODS];
    const struct fighter_mesh *fighter; /* points into fighter_lod */
    GLuint lens_vao, lens_vbo, lens_ibo;
    GLsizei lens_count;
    GLuint ring_vao, ring_vbo, ring_ibo;
    GLsizei ring_count;
    int ring_stage; /* the game stage the ring mesh has the size of; -1 none */
    GLuint empty_vao;
    GLuint hud_vao, hud_vbo, font_tex;
    hud_vertex *hud;
    int nhud;
    /* look */
    bool have_stage;
    int stage_game; /* the game stage the look was loaded for; -1 = set by r_game_set_stage */
    float key_dir[3]; /* the IBL's key direction: shadows are cast from it */
    r_stage stage;
    r_hdr_format hdr_format;
    GLuint ibl_tex[R_IBL_MAPS][2], sky_tex, lut_tex, normal_tex, spec_tex, flare_tex;
    int lut_size;
    float lut_gamma;
    /* light-space targets, sides from r_quality (0: SHADOW_SIZE, SIL_SIZE) */
    int shadow_size, sil_size;
    GLuint shadow_tex, shadow_fbo;
    GLuint shadow_sil_fbo; /* the shadow map and silhouette level 0 together, when their sides agree (else 0) */
    GLuint sil_tex, sil_tmp, sil_fbo[SIL_LEVELS], sil_tmp_fbo[SIL_LEVELS];
    /* C instead of GL passes where a CPU does the work better: on a
     * software rasteriser (rgl_is_software), bloom's blurs (r_post.c) and
     * the silhouette's blurred levels (r_shadow.c) */
    bool cpu_paths;
    uint8_t *sil_buf; /* the levels as bytes, and the C blurs' floats */
    size_t sil_buf_n;
    uint8_t *mask_buf; /* the shadow mask's filter in C: bytes in and out, and floats */
    size_t mask_buf_n;
    /* screen targets */
    int tw, th;   /* the scene's targets' size */
    int tow, toh; /* the output's, for the AA pass's targets */
    r_hdr_format tfmt;
    GLuint hdr_tex, depth_tex, hdr_fbo, depth_fbo;
    GLuint mask_tex[2], mask_fbo[2];
    /* bloom: b2 and bx RGBA16F, the levels b4 and b8 RGBE in RGBA8 (rgbe_common.glsl), the glow RGBA16F */
    GLuint b2_tex, b2_fbo, b4_tex[2], b4_fbo[2], b8_tex[2], b8_fbo[2], glow_tex, glow_fbo;
    GLuint bx_tex[BLOOM_XSTEPS], bx_fbo[BLOOM_XSTEPS]; /* halvings between b2 and b4 (renders over 720 rows) */
    /* on a software rasteriser (cpu_paths) the bright pass's level is
     * RGBA32F (bc), read back, and the blurs and the glow are C (r_bloom.c) */
    GLuint bc_tex, bc_fbo;
    float *bloom_buf; /* the level, the glow, the flare and r_bloom_glow's scratch */
    size_t bloom_buf_n;
    int bloom_steps, b4_w, b8_w; /* hdr -> b4 in bloom_steps steps; b4 BLOOM_ROWS rows, b8 half */
    int mask_w, mask_h;          /* the shadow mask: the render size, or half (q.mask_half) */
    GLuint fl_tex, fl_fbo; /* the flare image, quarter size */
    GLuint sunvis_tex, sunvis_fbo;
    GLuint ldr_tex, ldr_fbo; /* the tone map's output when the AA pass runs after it (RGBA8) */
    GLuint sc_tex, sc_fbo;   /* the tone map's output at the scene's size when that is smaller than the
                                output's (r_quality.scene_pct) and no AA pass follows: RGBA8, blitted up */
    GLuint luma_tex;         /* beside it (attachment 1): its luma, R8, for the AA pass's early out (r_aa.c) */
    bool aa_gather;          /* the AA pass's early out may use textureGather (GL 4.0 or ARB_texture_gather) */
    int mask_final; /* index of the filtered mask */
    /* graph */
    r_graph graph;
    int pass_ids[R_GRAPH_MAX];
    bool per_frame;
    FILE *passes_out;
    const char *res_names[32]; /* the graph's resources: the core's, then the effects' */
    r_graph_mask history_skip; /* the core's passes that only shade: left out of frames drawn
                                  for the effects' history (r_game_advance) */
    /* stage effects: each module's state, by its index in r_fx_modules (r_fx.h) */
    void *fx_state[R_FX_MAX_MODULES];
    uint64_t last_tick; /* of the frame drawn last, for frame.steps */
    bool have_last;
    frame f;
};


/* the core's side of the effect contract (r_fx.c) */
int r_fx_units(void);                          /* texture units the modules' bind hooks take */
void r_fx_bind(r_game *r, GLuint p, int what); /* every module's bind, units from R_FX_UNIT_FIRST */
bool r_fx_scene_cleared(r_game *r);            /* an effect cleared the HDR target this frame */
bool r_fx_draw_ring(r_game *r);                /* an effect drew the ring its own way */
void r_fx_scene_depth(r_game *r, GLuint depth_prog);  /* the effects' opaque surfaces' depth, before the ring */
int r_fx_warmup(r_game *r, const r_fx_module *m); /* its warm-up on the loaded stage */
int64_t r_fx_history(r_game *r);               /* the most of them (R_FX_FROM_START wins) */
bool r_fx_needs_frame(r_game *r, uint64_t ahead); /* a module whose window holds the tick `ahead` ticks
                                                     before the first drawn one needs the frame */
void r_fx_advance(r_game *r);                  /* every module's history, one tick */


/* the GL layer (r_gl.c), beside r_fx_core.h's */
GLuint r_cube_tex(int n, float *const face[6], int levels); /* RGB16F faces; mipmapped when levels > 1 */
/* r_blur_into's state with program p (blur.frag or a variant), not drawn:
 * the caller sets the variant's uniforms, then r_fullscreen */
void r_blur_setup(GLuint p, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float dx, float dy);
/* blur.frag's kernel for a step of k texels (0 < k <= 1) as the weights
 * of the texels 0..4 away (w[5]); returns how many it reaches (1..4) */
int r_blur_kernel(float k, float w[5]);
/* r_blur_into reading each texel once: for the 8-bit targets (silhouette
 * levels, with their zero border, and the shadow mask), where on llvmpipe
 * it is cheaper; the RGBA16F ones (bloom) and the wrapped ones (fog) keep
 * the bilinear pairs */
void r_blur_texels_into(r_game *r, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float dx, float dy,
                        bool zero_border);
void r_down_into(r_game *r, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float threshold, float scale);
/* r_down_into with program p: P_DOWN, or the RGBE variants for bloom's levels */
void r_down_with(r_game *r, GLuint p, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float threshold, float scale);
/* r_blur_setup for blur.frag's RGBE variants (program p): one texel a
 * step along x (across) or y, read texel by texel, clamped at the edge */
void r_blur_rgbe_setup(GLuint p, GLuint dst_fbo, GLuint src_tex, int w, int h, bool across);
/* The bloom pyramid for a w x h render: *steps down from the HDR image
 * to the BLOOM_ROWS level (halvings, the last a resample), *w4 its width. */
void r_bloom_plan(int w, int h, int *steps, int *w4);

/* per-frame set-up (r_frame.c) */
void r_frame_setup(r_game *r, frame *f); /* f->prev, cur, alpha, w, h, out_fbo set: the rest */

/* the scene (r_scene.c) */
int r_ring_material(const r_game *r);
bool r_build_lens(r_mesh_data *m); /* the visor's mesh */

/* The core passes, each in the file of its responsibility; r_game.c's
 * build_graph puts them in order with the effects' phases between. */
#define R_SHADOW_NPASS 6
#define R_POST_NPASS 5
extern const r_pass r_shadow_passes[R_SHADOW_NPASS]; /* r_shadow.c */
extern const r_pass r_scene_pass, r_sky_pass, r_lens_pass; /* r_scene.c */
extern const r_pass r_post_passes[R_POST_NPASS];     /* r_post.c: bloom, sun visibility, flare, tone map */
extern const r_pass r_hud_pass;                      /* r_hud.c */
extern const r_pass r_aa_pass;                       /* r_aa.c: FXAA, tone map output -> output */
void r_update_lut(r_game *r);                        /* r_post.c: the tone curve for the stage's gamma */
GLuint r_hud_font(void);                             /* r_hud.c: the font texture */

#endif
