/* Shadows in a large world (docs/effects.md, "Shadows in a large world"): light space
 * perspective shadow maps over a stage with buildings.
 *
 * The mathematics is r_lspsm.c (tested without GL); this module gives it
 * its passes, on stages with `lspsm = yes` only:
 *
 *   lspsm_map    (R_FX_PRE)  the auto-focus takes the depth samples the
 *                previous frame read back (its PBO, one frame late), then
 *                r_lspsm_build makes this frame's matrices, and one
 *                1024x1024 depth map is drawn from the buildings' low-poly
 *                proxies (one merged mesh; each building's range is drawn
 *                only when r_lspsm_caster_visible says it can cast into
 *                the view), and the fighters (movable: their own mesh)
 *                only where the fighter shadows do not cast them already
 *                (below).
 *   buildings    (R_FX_SURFACE) the detailed building meshes, lit like the
 *                stage (IBL, fog, the LSPSM map).  Runs on any stage with
 *                `buildings` > 0, shadow map or not.
 *   lspsm_focus  (R_FX_TRANSLUCENT) the depth buffer is complete: the
 *                20x16 tilted pattern is gathered into a 20x16 R32F target
 *                on the GPU and read into a pixel-pack buffer; the next
 *                frame maps it.
 *
 * The receivers (shaders/lspsm_common.glsl, lspsm_bind): the ring,
 * the ground and the buildings look the map up at their own position
 * (pushed along the normal); the fighters look it up where the ray towards
 * the light leaves their own box (no self-shadow, others' shadows received)
 * and keep u_lspsm_keep of the key light in full shadow, so they keep their
 * directional shading.  When the stage's fighter shadows run (the blurred
 * silhouette on the stage, the screen-space mask on the fighters), those
 * already cast the fighters on the ring, the ground and each other, so
 * the map holds the buildings alone; without them it casts the fighters
 * too.  The silhouette stops short of the buildings, though: on a frame
 * where a fighter's shadow can reach a building (fighters_reach_buildings),
 * a second map, this one with the fighters drawn in, is what the
 * buildings look up.  (The map used to hold the fighters always, with an
 * R8 target flagging their texels and four more taps a pixel to take them
 * out again: on plaza, llvmpipe spent about 2 ms a frame on those taps, and
 * they could not see a building's shadow behind a fighter.)
 *
 * The static layers (r_quality.lspsm_static; static_mode): where the
 * light and the buildings stand still and the fighters' own shadows run,
 * the map is instead two orthographic layers of one depth array
 * (r_lspsm_static_build), drawn from every proxy on the first frame of a
 * look (draw_static) and looked up with an affine map and one tap
 * (FX_LSPSM_STATIC in the scene's programs).  No focus, no history:
 * lspsm_focus does not run and nothing warms up.  The fighters go into a
 * copy of the layers on the frames their shadow can reach a building.
 *
 * The focus readback waits, in the next frame, for the previous frame's
 * 1280-byte transfer; every frame is then a function of the frames drawn
 * before it, so a replay's video is the same on every run.  A reset
 * (first frame, seek, new stage) forgets the pending samples and starts
 * from the 100 m limit. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../game/g_game.h"
#include "../render/r_city.h"
#include "../render/r_lspsm.h"
#include "../render/r_shader.h"
#include "fx_local.h"
#include "fx_lspsm.h"

extern const r_fx_module fx_lspsm_module;
#define LSPSM(r) ((struct fx_lspsm_state *)r_fx_state((r), &fx_lspsm_module))

#define KEEP 0.4f         /* a fighter in full shadow keeps 40 % of the key light */
#define DEPTH_BIAS 0.0005f /* receivers, window depth units */
#define STATIC_BIAS_M 0.03f /* the static layers' receivers, metres along the light */

struct fx_lspsm_state {
    GLuint prog_map, prog_focus;
    GLuint map_tex, map_fbo;   /* map x map depth (compare mode): every receiver's */
    GLuint cast_tex, cast_fbo; /* the same with the fighters in it, for the buildings (made when first needed) */
    int map;                   /* the maps' edge: r_quality.lspsm_size, 0 = R_LSPSM_MAP */
    int unit;                  /* the map's texture unit in the scene programs (lspsm_bind) */
    bool cast_drawn;           /* cast_tex holds this frame's map */
    GLuint focus_tex, focus_fbo;       /* 20x16 R32F */
    GLuint pbo;                        /* the samples of the frame drawn last */
    bool pending;                      /* pbo holds samples not used yet */
    int pending_w, pending_h;
    r_mat4 pending_inv_vp;
    r_lspsm_focus focus;
    r_lspsm s;            /* this frame's matrices */
    /* the static layers (r_quality.lspsm_static, static_mode): drawn once */
    bool stat;                 /* this look's map is the static layers */
    int stat_size;             /* their edge, texels */
    GLuint stat_tex, stat_fbo[R_LSPSM_LAYERS];           /* the layers' depth array (compare mode) */
    GLuint stat_cast_tex, stat_cast_fbo[R_LSPSM_LAYERS]; /* the same with the fighters, made when first needed */
    bool stat_drawn;           /* stat_tex holds the layers for stat_light */
    bool cast_all;             /* this frame every receiver looks up the map with the fighters */
    r_vec3 stat_light;
    r_lspsm_static st;
    /* the city */
    int nb;
    r_building b[R_CITY_MAX];
    float lo[R_CITY_MAX][3], hi[R_CITY_MAX][3];
    GLuint city_vao, city_vbo, city_ibo, proxy_vao, proxy_vbo, proxy_ibo;
    GLsizei city_count;
    bool depth_laid; /* this frame's buildings' depth is in the depth buffer (scene_depth) */
    GLint proxy_first[R_CITY_MAX];
    GLsizei proxy_count[R_CITY_MAX];
    /* tests and --passes */
    bool no_cull, uniform, no_cast;
    bool light_override;
    r_vec3 light;
    fx_lspsm_stats stats;
};

static bool need_map(void *u)
{
    r_game *r = u;
    return r_fx_stage(r)->lspsm && LSPSM(r);
}

/* The static layers: asked for by the quality (lspsm_static), with the
 * fighters' own shadows on (they cast the fighters; the layers hold the
 * buildings alone) and buildings to cast. */
static bool static_mode(const r_game *r)
{
    const r_stage *st = r_fx_stage(r);
    return r_fx_quality(r)->lspsm_static > 0 && st->lspsm && st->shadows && st->buildings > 0;
}

static bool need_focus(void *u)
{
    r_game *r = u;
    return need_map(u) && !LSPSM(r)->stat;
}

static bool need_buildings(void *u)
{
    r_game *r = u;
    return LSPSM(r) && LSPSM(r)->nb > 0;
}

/* The key light: the direction the other shadows use (frame.light_dir),
 * or a test's. */
static r_vec3 to_light(const r_game *r)
{
    return LSPSM(r)->light_override ? LSPSM(r)->light : r_fx_frame(r)->light_dir;
}

static void take_focus(struct fx_lspsm_state *ls, bool reset)
{
    if (reset) {
        ls->pending = false;
        ls->focus.range = 0; /* the limit until samples come */
        return;
    }
    if (!ls->pending)
        return;
    ls->pending = false;
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, ls->pbo);
    /* the previous frame's transfer: long finished on a GPU that is less
     * than a frame behind; else this waits for it (deterministic videos) */
    const float *d = gl.MapBufferRange(GL_PIXEL_PACK_BUFFER, 0, R_LSPSM_FOCUS_N * sizeof(float), GL_MAP_READ_BIT);
    if (d) {
        float depth[R_LSPSM_FOCUS_N];
        memcpy(depth, d, sizeof depth);
        gl.UnmapBuffer(GL_PIXEL_PACK_BUFFER);
        r_lspsm_focus_update(&ls->focus, depth, ls->pending_w, ls->pending_h, ls->pending_inv_vp);
    }
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
}

/* The fighters' boxes: each bone's origin +-0.4 m holds its far end too
 * (lo 0, hi 0, lo 1, hi 1). */
static void fighter_boxes(const frame *f, float box[4][3])
{
    for (int i = 0; i < 2; i++) {
        for (int a = 0; a < 3; a++)
            box[2 * i][a] = 1e9f, box[2 * i + 1][a] = -1e9f;
        for (int k = 0; k < G_BONES; k++)
            for (int a = 0; a < 3; a++) {
                float c = f->bones[i][k][12 + a];
                box[2 * i][a] = fminf(box[2 * i][a], c - 0.4f);
                box[2 * i + 1][a] = fmaxf(box[2 * i + 1][a], c + 0.4f);
            }
    }
}

/* Can a fighter's shadow fall on a building?  Each fighter's box is swept
 * away from the light until its top is below every building's base, and
 * tested against each building's box grown by the fighter box's half size
 * (the swept centre, a segment, against a box: the slab test).  A yes may
 * be a near miss, never a no a hit. */
static bool fighters_reach_buildings(const struct fx_lspsm_state *ls, const float box[4][3], r_vec3 L)
{
    const float d[3] = {-L.x, -L.y, -L.z}, far = 1e4f;
    float base = 1e30f;
    for (int j = 0; j < ls->nb; j++)
        base = fminf(base, ls->lo[j][1]);
    for (int i = 0; i < 2; i++) {
        float c[3], e[3];
        for (int a = 0; a < 3; a++)
            c[a] = 0.5f * (box[2 * i][a] + box[2 * i + 1][a]), e[a] = 0.5f * (box[2 * i + 1][a] - box[2 * i][a]);
        /* the top drops L.y a metre along the sweep */
        float len = L.y > 1e-3f ? fminf((box[2 * i + 1][1] - base) / L.y, far) : far;
        for (int j = 0; j < ls->nb; j++) {
            float t0 = 0, t1 = len;
            for (int a = 0; a < 3 && t0 <= t1; a++) {
                float lo = ls->lo[j][a] - e[a], hi = ls->hi[j][a] + e[a];
                if (fabsf(d[a]) < 1e-9f) {
                    if (c[a] < lo || c[a] > hi)
                        t1 = -1;
                    continue;
                }
                float ta = (lo - c[a]) / d[a], tb = (hi - c[a]) / d[a];
                t0 = fmaxf(t0, fminf(ta, tb)), t1 = fminf(t1, fmaxf(ta, tb));
            }
            if (t0 <= t1)
                return true;
        }
    }
    return false;
}

/* A depth map target: compare mode, bilinear = 2x2 PCF; outside it (the
 * border) nothing casts. */
static bool make_map(int n, GLuint *tex, GLuint *fbo)
{
    const float one[4] = {1, 1, 1, 1};
    *tex = r_tex2d(GL_DEPTH_COMPONENT24, n, n, GL_DEPTH_COMPONENT, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_BORDER);
    gl.TexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, one);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.GenFramebuffers(1, fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, *fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, *tex, 0);
    GLenum none = GL_NONE;
    gl.DrawBuffers(1, &none);
    gl.ReadBuffer(GL_NONE);
    GLenum st = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    return st == GL_FRAMEBUFFER_COMPLETE;
}

/* The layers' depth array, n x n each, compare mode, bilinear (2x2 PCF),
 * lit beyond its border, with a framebuffer per layer. */
static bool make_layers(int n, GLuint *tex, GLuint fbo[R_LSPSM_LAYERS])
{
    const float one[4] = {1, 1, 1, 1};
    gl.GenTextures(1, tex);
    gl.BindTexture(GL_TEXTURE_2D_ARRAY, *tex);
    gl.TexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_DEPTH_COMPONENT16, n, n, R_LSPSM_LAYERS, 0, GL_DEPTH_COMPONENT,
                  GL_UNSIGNED_SHORT, NULL);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    gl.TexParameterfv(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BORDER_COLOR, one);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    gl.BindTexture(GL_TEXTURE_2D_ARRAY, 0);
    gl.GenFramebuffers(R_LSPSM_LAYERS, fbo);
    bool ok = true;
    for (int l = 0; l < R_LSPSM_LAYERS; l++) {
        gl.BindFramebuffer(GL_FRAMEBUFFER, fbo[l]);
        gl.FramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, *tex, 0, l);
        GLenum none = GL_NONE;
        gl.DrawBuffers(1, &none);
        gl.ReadBuffer(GL_NONE);
        ok = ok && gl.CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    }
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    return ok;
}

/* The fighters into dst: src's depth (n x n) copied, then the fighters
 * drawn with the light's matrix vp (the casters' state is on). */
static void copy_with_fighters(r_game *r, GLuint p, GLuint src, GLuint dst, int n, const r_mat4 *vp)
{
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, src);
    gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, dst);
    gl.BlitFramebuffer(0, 0, n, n, 0, 0, n, n, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    gl.BindFramebuffer(GL_FRAMEBUFFER, dst);
    gl.UseProgram(p);
    gl.UniformMatrix4fv(r_loc(p, "u_view_proj"), 1, GL_FALSE, vp->m);
    r_draw_fighters(r, p);
}

/* The casters' state of both kinds of map: depth, front faces (closed
 * proxies: the faces turned from the light lie behind the ones turned to
 * it), polygon offset, depth clamp (a tall building nearer the light than
 * the map's near plane still casts). */
static void caster_state_end(void)
{
    gl.Disable(GL_CULL_FACE);
    gl.Disable(GL_POLYGON_OFFSET_FILL);
    gl.Disable(GL_DEPTH_CLAMP);
}

static void caster_state(void)
{
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.DepthMask(GL_TRUE);
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_BACK);
    gl.Enable(GL_POLYGON_OFFSET_FILL);
    gl.PolygonOffset(1.5f, 4.0f);
    gl.Enable(GL_DEPTH_CLAMP);
}

/* The static layers for light L: every building's proxy, once.  Layer 1
 * covers every receiver within R_LSPSM_LIMIT of an eye that stays within
 * STATIC_EYE_REACH of the ring's centre (r_game_camera_parts keeps it
 * within 12 m), layer 0 the ring and STATIC_INNER metres round it. */
#define STATIC_EYE_REACH 20.0f
#define STATIC_INNER 6.0f
static void draw_static(r_game *r, struct fx_lspsm_state *ls, r_vec3 L)
{
    float ring_half = 4.0f, top = R_CITY_GROUND + 1;
    int gs = r_fx_stage_game(r) >= 0 ? r_fx_stage_game(r) : r_fx_stage(r)->game_index;
    if (gs >= 0 && gs < G_STAGES)
        ring_half = fx_to_float(g_stages[gs].ring_half);
    for (int i = 0; i < ls->nb; i++)
        top = fmaxf(top, ls->hi[i][1]);
    float reach = R_LSPSM_LIMIT + STATIC_EYE_REACH, in = ring_half + STATIC_INNER;
    const float box[R_LSPSM_LAYERS][2][3] = {{{-in, R_CITY_GROUND, -in}, {in, 3.0f, in}},
                                             {{-reach, R_CITY_GROUND, -reach}, {reach, top, reach}}};
    r_lspsm_static_build(L, box, &ls->st);
    caster_state();
    gl.Viewport(0, 0, ls->stat_size, ls->stat_size);
    gl.ClearDepth(1.0);
    GLuint p = ls->prog_map;
    gl.UseProgram(p);
    gl.BindVertexArray(ls->proxy_vao);
    for (int l = 0; l < R_LSPSM_LAYERS; l++) {
        gl.BindFramebuffer(GL_FRAMEBUFFER, ls->stat_fbo[l]);
        gl.Clear(GL_DEPTH_BUFFER_BIT);
        gl.UniformMatrix4fv(r_loc(p, "u_view_proj"), 1, GL_FALSE, ls->st.light_vp[l].m);
        gl.DrawElements(GL_TRIANGLES, (GLsizei)(ls->stats.proxy_triangles * 3), GL_UNSIGNED_INT, NULL);
    }
    caster_state_end();
    ls->stat_drawn = true;
    ls->stat_light = L;
    ls->stats.static_draws++;
    for (int l = 0; l < R_LSPSM_LAYERS; l++)
        ls->stats.static_texel[l] = fmaxf(ls->st.extent[l][0], ls->st.extent[l][1]) / (float)ls->stat_size;
}

/* A static frame: the layers (drawn when the light is new), and the
 * fighters into a copy of them when they must cast through the map. */
static void run_static(r_game *r, struct fx_lspsm_state *ls, const frame *f)
{
    r_vec3 L = to_light(r);
    if (!ls->stat_drawn || L.x != ls->stat_light.x || L.y != ls->stat_light.y || L.z != ls->stat_light.z)
        draw_static(r, ls, L);
    ls->cast_drawn = ls->cast_all = false;
    bool ssfsm = r_ran(f, r, "mask_filter") && r_ran(f, r, "silhouette_mips");
    float box[4][3];
    fighter_boxes(f, box);
    ls->stats.fighters_in_map = !ssfsm;
    ls->stats.fighters_cast = false;
    ls->stats.casters_drawn = 0;
    ls->stats.casters = ls->nb;
    ls->stats.range = R_LSPSM_LIMIT;
    ls->stats.warp = 0;
    if (f->depth_only)
        return;
    /* the fighters' own shadows cast them on everything but the buildings;
     * without them (a pass left out) everything looks the copy up */
    bool cast = !ssfsm || (!ls->no_cast && fighters_reach_buildings(ls, box, L));
    if (!cast || !(ls->stat_cast_tex || make_layers(ls->stat_size, &ls->stat_cast_tex, ls->stat_cast_fbo)))
        return;
    caster_state();
    gl.Disable(GL_CULL_FACE);
    gl.Viewport(0, 0, ls->stat_size, ls->stat_size);
    for (int l = 0; l < R_LSPSM_LAYERS; l++)
        copy_with_fighters(r, ls->prog_map, ls->stat_fbo[l], ls->stat_cast_fbo[l], ls->stat_size, &ls->st.light_vp[l]);
    caster_state_end();
    ls->cast_drawn = true;
    ls->cast_all = !ssfsm;
    ls->stats.fighters_cast = ssfsm;
}

static void run_map(void *u)
{
    r_game *r = u;
    struct fx_lspsm_state *ls = LSPSM(r);
    const frame *f = r_fx_frame(r);
    if (ls->stat) {
        run_static(r, ls, f);
        return;
    }
    take_focus(ls, f->reset);
    r_lspsm_desc d = {.cam = r_lspsm_camera_from(f->view, f->proj), .to_light = to_light(r),
                      .far = ls->focus.range > 0 ? ls->focus.range : R_LSPSM_LIMIT, .uniform = ls->uniform};
    r_lspsm_build(&d, &ls->s);
    ls->cast_drawn = false;
    if (f->depth_only) /* a warm-up frame: the focus above is the history; the map only shades */
        return;

    gl.BindFramebuffer(GL_FRAMEBUFFER, ls->map_fbo);
    gl.Viewport(0, 0, ls->map, ls->map);
    gl.ClearDepth(1.0);
    gl.Clear(GL_DEPTH_BUFFER_BIT);
    /* only the proxies' faces turned to the light are drawn (lspsm_map 5.1
     * -> 3.3 ms a plaza frame single-threaded).  Where the warp clips a
     * face turned to the light, the one behind no longer stands in for it:
     * in 30 frames of plaza, 433 bytes of 31 MB changed on one shadow
     * edge, and bench quality's dB did not move */
    caster_state();
    GLuint p = ls->prog_map;
    gl.UseProgram(p);
    gl.UniformMatrix4fv(r_loc(p, "u_view_proj"), 1, GL_FALSE, ls->s.light_vp.m);
    /* static scenery: each building's proxy, when it can cast into the view */
    gl.BindVertexArray(ls->proxy_vao);
    int drawn = 0;
    for (int i = 0; i < ls->nb; i++) {
        r_vec3 lo = r_v3(ls->lo[i][0], ls->lo[i][1], ls->lo[i][2]), hi = r_v3(ls->hi[i][0], ls->hi[i][1], ls->hi[i][2]);
        if (!ls->no_cull && !r_lspsm_caster_visible(&ls->s, lo, hi))
            continue;
        gl.DrawElements(GL_TRIANGLES, ls->proxy_count[i], GL_UNSIGNED_INT,
                        (const void *)((size_t)ls->proxy_first[i] * sizeof(unsigned)));
        drawn++;
    }
    /* movable casters: the fighters, both sides.  With the fighter
     * shadows on (the same test as run_scene's) they cast on the ring, the
     * ground and the fighters already, so they go only into the buildings'
     * map, and only when their shadow can reach one */
    gl.Disable(GL_CULL_FACE);
    bool ssfsm = r_ran(f, r, "mask_filter") && r_ran(f, r, "silhouette_mips");
    float box[4][3];
    fighter_boxes(f, box);
    ls->stats.fighters_in_map = !ssfsm;
    ls->stats.fighters_cast = false;
    if (!ssfsm) {
        r_draw_fighters(r, p);
    } else if (ls->nb > 0 && !ls->no_cast && fighters_reach_buildings(ls, box, to_light(r)) &&
               (ls->cast_fbo || make_map(ls->map, &ls->cast_tex, &ls->cast_fbo))) {
        /* the buildings' map: this one's depth, then the fighters */
        copy_with_fighters(r, p, ls->map_fbo, ls->cast_fbo, ls->map, &ls->s.light_vp);
        ls->cast_drawn = ls->stats.fighters_cast = true;
    }
    caster_state_end();
    ls->stats.casters_drawn = drawn;
    ls->stats.casters = ls->nb;
    ls->stats.range = d.far;
    ls->stats.warp = ls->s.warp;
    ls->stats.gamma = ls->s.gamma;
}

static void run_buildings(void *u)
{
    r_game *r = u;
    struct fx_lspsm_state *ls = LSPSM(r);
    r_begin_opaque(r);
    if (r_fx_frame(r)->depth_only) { /* a warm-up frame: their depth, for the focus (r_fx_core.h) */
        GLuint d = r_fx_core_gl(r).prog_depth;
        gl.ColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        r_camera_uniforms(r, d);
        gl.BindVertexArray(ls->city_vao);
        gl.DrawElements(GL_TRIANGLES, ls->city_count, GL_UNSIGNED_INT, NULL);
        gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        gl.Disable(GL_CULL_FACE);
        return;
    }
    /* over the depth scene_depth laid before the ring */
    if (ls->depth_laid)
        gl.DepthFunc(GL_LEQUAL);
    ls->depth_laid = false;
    GLuint p = r_stage_program(r, R_MAT_BUILDING);
    /* the fighters' blurred silhouette stops short of the buildings: the
     * map with the fighters in it casts them there, when run_map drew it */
    gl.Uniform1i(r_loc(p, "u_shadows"), 0);
    if (ls->cast_drawn)
        r_bind_tex(p, "u_lspsm_map", ls->unit, ls->stat ? GL_TEXTURE_2D_ARRAY : GL_TEXTURE_2D,
                   ls->stat ? ls->stat_cast_tex : ls->cast_tex);
    gl.BindVertexArray(ls->city_vao);
    gl.DrawElements(GL_TRIANGLES, ls->city_count, GL_UNSIGNED_INT, NULL);
    gl.Disable(GL_CULL_FACE);
}

/* Inside "scene", before the ring: the buildings' depth (r_fx.h) */
static bool lspsm_scene_depth(r_game *r, GLuint depth_prog)
{
    struct fx_lspsm_state *ls = LSPSM(r);
    (void)depth_prog; /* bound, with the camera's uniforms */
    if (!ls)
        return false;
    ls->depth_laid = false;
    if (!need_buildings(r))
        return false;
    gl.BindVertexArray(ls->city_vao);
    gl.DrawElements(GL_TRIANGLES, ls->city_count, GL_UNSIGNED_INT, NULL);
    ls->depth_laid = true;
    return true;
}

static void run_focus(void *u)
{
    r_game *r = u;
    struct fx_lspsm_state *ls = LSPSM(r);
    const frame *f = r_fx_frame(r);
    gl.BindFramebuffer(GL_FRAMEBUFFER, ls->focus_fbo);
    gl.Viewport(0, 0, R_LSPSM_FOCUS_W, R_LSPSM_FOCUS_H);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.Disable(GL_CULL_FACE);
    gl.UseProgram(ls->prog_focus);
    r_bind_tex(ls->prog_focus, "u_depth", 0, GL_TEXTURE_2D, r_fx_core_gl(r).depth_tex);
    r_fullscreen(r);
    /* into the pixel-pack buffer: glReadPixels returns at once */
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, ls->pbo);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.ReadPixels(0, 0, R_LSPSM_FOCUS_W, R_LSPSM_FOCUS_H, GL_RED, GL_FLOAT, NULL);
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    ls->pending = true;
    ls->pending_w = f->w, ls->pending_h = f->h;
    ls->pending_inv_vp = f->inv_vp;
}

static const r_pass map_passes[] = {
    {"lspsm_map", RES_ENV, RES_LSPSM, need_map, run_map, 0},
};
static const r_pass surface_passes[] = {
    {"buildings", RES_ENV, RES_HDR | RES_DEPTH, need_buildings, run_buildings, RES_LSPSM | RES_FOGMAP},
};
static const r_pass focus_passes[] = {
    {"lspsm_focus", RES_DEPTH, 0, need_focus, run_focus, 0},
};

/* ---- the receivers' side ---- */

/* The scene's programs (lspsm_common.glsl): u_lspsm_* and the map on unit
 * `unit` (u_lspsm_on = 0 whenever the map was not drawn this frame).  The
 * sky and the visors do not receive it. */
static void lspsm_bind(r_game *r, GLuint p, int unit, int what)
{
    if (what != R_FX_BIND_SCENE)
        return;
    struct fx_lspsm_state *ls = LSPSM(r);
    bool on = ls && r_fx_stage(r)->lspsm && r_ran(r_fx_frame(r), r, "lspsm_map");
    gl.UseProgram(p);
    gl.Uniform1i(r_loc(p, "u_lspsm_on"), on);
    /* the sampler gets its unit whether on or not: samplers of different
     * types must never share a unit */
    if (ls && ls->stat)
        r_bind_tex(p, "u_lspsm_map", unit, GL_TEXTURE_2D_ARRAY,
                   !on ? 0 : ls->cast_all ? ls->stat_cast_tex : ls->stat_tex);
    else
        r_bind_tex(p, "u_lspsm_map", unit, GL_TEXTURE_2D, on ? ls->map_tex : 0);
    if (ls)
        ls->unit = unit;
    if (!on)
        return;
    const frame *f = r_fx_frame(r);
    r_vec3 L = to_light(r);
    if (ls->stat) {
        const r_lspsm_static *st = &ls->st;
        gl.UniformMatrix4fv(r_loc(p, "u_lspsm_shadow"), 1, GL_FALSE, st->shadow.m);
        gl.Uniform4fv(r_loc(p, "u_lspsm_fit"), R_LSPSM_LAYERS - 1, &st->fit[0][0]);
        gl.Uniform3f(r_loc(p, "u_lspsm_eye"), f->eye.x, f->eye.y, f->eye.z);
        gl.Uniform2f(r_loc(p, "u_lspsm_fade"), R_LSPSM_LIMIT * (1 - R_LSPSM_FADE), R_LSPSM_LIMIT);
        gl.Uniform1f(r_loc(p, "u_lspsm_bias"), STATIC_BIAS_M / st->depth_m);
        gl.Uniform1f(r_loc(p, "u_lspsm_texel"), 1.0f / (float)ls->stat_size);
    } else {
        gl.UniformMatrix4fv(r_loc(p, "u_lspsm_shadow"), 1, GL_FALSE, ls->s.shadow.m);
        gl.Uniform3f(r_loc(p, "u_lspsm_eye"), ls->s.eye.x, ls->s.eye.y, ls->s.eye.z);
        gl.Uniform2f(r_loc(p, "u_lspsm_fade"), ls->s.fade[0], ls->s.fade[1]);
        gl.Uniform1f(r_loc(p, "u_lspsm_bias"), DEPTH_BIAS);
        gl.Uniform1f(r_loc(p, "u_lspsm_texel"), 1.0f / (float)ls->map);
    }
    gl.Uniform3f(r_loc(p, "u_lspsm_dir"), L.x, L.y, L.z);
    gl.Uniform1f(r_loc(p, "u_lspsm_keep"), KEEP);
    float box[4][3];
    fighter_boxes(f, box);
    gl.Uniform3fv(r_loc(p, "u_lspsm_box"), 4, &box[0][0]);
}

/* ---- the module ---- */

static void free_city(struct fx_lspsm_state *ls)
{
    r_free_mesh(&ls->city_vao, &ls->city_vbo, &ls->city_ibo);
    r_free_mesh(&ls->proxy_vao, &ls->proxy_vbo, &ls->proxy_ibo);
    ls->nb = 0;
    ls->city_count = 0;
}

static void lspsm_destroy(r_game *r)
{
    struct fx_lspsm_state *ls = LSPSM(r);
    if (!ls)
        return;
    free_city(ls);
    GLuint tex[5] = {ls->map_tex, ls->cast_tex, ls->focus_tex, ls->stat_tex, ls->stat_cast_tex},
           fbo[3] = {ls->map_fbo, ls->cast_fbo, ls->focus_fbo};
    gl.DeleteTextures(5, tex);
    gl.DeleteFramebuffers(3, fbo);
    gl.DeleteFramebuffers(R_LSPSM_LAYERS, ls->stat_fbo);
    gl.DeleteFramebuffers(R_LSPSM_LAYERS, ls->stat_cast_fbo);
    if (ls->pbo)
        gl.DeleteBuffers(1, &ls->pbo);
    gl.DeleteProgram(ls->prog_map);
    gl.DeleteProgram(ls->prog_focus);
    free(ls);
    r_fx_set_state(r, &fx_lspsm_module, NULL);
}

static bool lspsm_create(r_game *r, rs_err *err)
{
    struct fx_lspsm_state *ls = calloc(1, sizeof *ls);
    if (!ls)
        return rs_fail(err, R_ERR_NOMEM, "lspsm: out of memory");
    r_fx_set_state(r, &fx_lspsm_module, ls);
    if (!(ls->prog_map = r_program(&(r_program_desc){.vs = "scene.vert", .fs = "light_depth.frag",
                                                     .defines = "#define LIGHT_VIEW 1\n"},
                                   err)) ||
        !(ls->prog_focus = r_program(&(r_program_desc){.vs = "cap_fullscreen.vert", .fs = "lspsm_focus.frag"}, err))) {
        lspsm_destroy(r);
        return false;
    }
    int q = r_fx_quality(r)->lspsm_size;
    ls->map = q <= 0 ? R_LSPSM_MAP : q < 256 ? 256 : q > 4096 ? 4096 : q;
    GLenum st = make_map(ls->map, &ls->map_tex, &ls->map_fbo) ? GL_FRAMEBUFFER_COMPLETE : GL_FRAMEBUFFER_UNSUPPORTED;
    ls->focus_tex = r_tex2d(GL_R32F, R_LSPSM_FOCUS_W, R_LSPSM_FOCUS_H, GL_RED, GL_FLOAT, NULL, GL_NEAREST, GL_CLAMP_TO_EDGE);
    ls->focus_fbo = r_fbo_for(ls->focus_tex, 0, 0);
    GLenum st2 = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.GenBuffers(1, &ls->pbo);
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, ls->pbo);
    gl.BufferData(GL_PIXEL_PACK_BUFFER, R_LSPSM_FOCUS_N * sizeof(float), NULL, GL_STREAM_READ);
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    if (st != GL_FRAMEBUFFER_COMPLETE || st2 != GL_FRAMEBUFFER_COMPLETE) {
        lspsm_destroy(r);
        return rs_fail(err, R_ERR_TARGET, "lspsm: shadow map target incomplete (%s)",
                       rgl_enum_name(st != GL_FRAMEBUFFER_COMPLETE ? st : st2));
    }
    RGL_CHECK("lspsm create");
    return true;
}

/* A new look: the buildings of its layout (their meshes), the focus afresh. */
static bool lspsm_load(r_game *r, rs_err *err)
{
    struct fx_lspsm_state *ls = LSPSM(r);
    free_city(ls);
    ls->pending = false;
    ls->focus.range = 0;
    memset(&ls->stats, 0, sizeof ls->stats);
    ls->stat = false;
    ls->stat_drawn = ls->cast_all = false;
    const r_stage *st = r_fx_stage(r);
    if (st->buildings <= 0)
        return true;
    int gs = r_fx_stage_game(r) >= 0 ? r_fx_stage_game(r) : st->game_index;
    float ring_half = gs >= 0 && gs < G_STAGES ? fx_to_float(g_stages[gs].ring_half) : 4.0f;
    ls->nb = r_city_layout(st->buildings, (unsigned)st->buildings_seed, r_fx_key_dir(r), ring_half, ls->b);
    r_mesh_data city = {0}, proxy = {0};
    bool ok = true;
    for (int i = 0; i < ls->nb && ok; i++) {
        r_city_bounds(&ls->b[i], ls->lo[i], ls->hi[i]);
        ls->proxy_first[i] = (GLint)proxy.ni;
        ok = r_city_mesh(&city, &ls->b[i]) && r_city_proxy(&proxy, &ls->b[i]);
        ls->proxy_count[i] = (GLsizei)(proxy.ni - (size_t)ls->proxy_first[i]);
    }
    if (ok) {
        r_upload_mesh(&city, &ls->city_vao, &ls->city_vbo, &ls->city_ibo);
        r_upload_mesh(&proxy, &ls->proxy_vao, &ls->proxy_vbo, &ls->proxy_ibo);
        ls->city_count = (GLsizei)city.ni;
        ls->stats.city_triangles = (int)(city.ni / 3);
        ls->stats.proxy_triangles = (int)(proxy.ni / 3);
    }
    r_mesh_free(&city);
    r_mesh_free(&proxy);
    if (!ok) {
        free_city(ls);
        return rs_fail(err, R_ERR_NOMEM, "stage '%s': out of memory for %d buildings", st->name, st->buildings);
    }
    if (static_mode(r)) { /* the look's programs were built for them (lspsm_define) */
        /* the quality is the renderer's for its life: the size never changes */
        int n = r_fx_quality(r)->lspsm_static;
        n = n < 256 ? 256 : n > 4096 ? 4096 : n;
        ls->stat_size = n;
        if (!ls->stat_tex && !make_layers(n, &ls->stat_tex, ls->stat_fbo))
            return rs_fail(err, R_ERR_TARGET, "lspsm: the static shadow layers (%dx%d, %d layers) are incomplete", n, n,
                          R_LSPSM_LAYERS);
        RGL_CHECK("lspsm static layers");
        ls->stat = ls->stats.is_static = true;
    }
    return true;
}

/* History: the auto-focus range, and the depth samples read back one
 * frame late.  The range follows the farthest sample at once when it
 * grows and shrinks at most 2 % a frame (R_LSPSM_SHRINK); the samples are
 * the drawn frame's depth buffer (the ring, the craters, the buildings,
 * the fighters), which only drawing the frame gives.  So:
 *   warm-up      r_lspsm_focus_memory frames (228 with the defaults): a
 *                range rebuilt from a reset that long ago equals the full
 *                render's, bit for bit (r_lspsm.h says why);
 *   needs_frame  inside that window the frames are drawn;
 *   advance      before it, only a reset reaches the module: it forgets
 *                the samples and the range, so the window starts from the
 *                reset state whatever this renderer drew before. */
static int lspsm_warmup(r_game *r)
{
    return need_map(r) && !LSPSM(r)->stat ? r_lspsm_focus_memory(&LSPSM(r)->focus) : R_FX_STATELESS;
}

static bool lspsm_needs_frame(r_game *r)
{
    return need_map(r) && !LSPSM(r)->stat;
}

static void lspsm_advance(r_game *r)
{
    if (LSPSM(r) && r_fx_frame(r)->reset)
        take_focus(LSPSM(r), true);
}

static const char *lspsm_define(const r_game *r)
{
    return !r_fx_stage(r)->lspsm ? NULL : static_mode(r) ? "FX_LSPSM_STATIC" : "FX_LSPSM";
}

const r_fx_module fx_lspsm_module = {
    .name = "lspsm", .create = lspsm_create, .destroy = lspsm_destroy, .load = lspsm_load,
    .pass = {map_passes, surface_passes, focus_passes},
    .npass = {(int)(sizeof map_passes / sizeof map_passes[0]), (int)(sizeof surface_passes / sizeof surface_passes[0]),
              (int)(sizeof focus_passes / sizeof focus_passes[0])},
    .res = {{RES_LSPSM, "lspsm map", false}}, .scene_reads = RES_LSPSM,
    .units = 1, .bind = lspsm_bind, .scene_define = lspsm_define, .scene_depth = lspsm_scene_depth,
    .warmup = lspsm_warmup, .advance = lspsm_advance, .needs_frame = lspsm_needs_frame,
};

/* ---- tests, bench and --passes ---- */

bool fx_lspsm_stats_get(r_game *r, fx_lspsm_stats *out)
{
    if (!LSPSM(r))
        return false;
    *out = LSPSM(r)->stats;
    out->focus_farthest = LSPSM(r)->focus.farthest;
    out->focus_used = LSPSM(r)->focus.used;
    return true;
}

void fx_lspsm_test_set(r_game *r, const float *light, bool no_cull, bool uniform)
{
    if (!LSPSM(r))
        return;
    LSPSM(r)->light_override = light != NULL;
    if (light)
        LSPSM(r)->light = r_v3(light[0], light[1], light[2]);
    LSPSM(r)->no_cull = no_cull;
    LSPSM(r)->uniform = uniform;
}

void fx_lspsm_test_no_cast(r_game *r, bool off)
{
    if (LSPSM(r))
        LSPSM(r)->no_cast = off;
}

bool fx_lspsm_read(r_game *r, const char *what, float *out)
{
    struct fx_lspsm_state *ls = LSPSM(r);
    if (!ls)
        return false;
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    if (!strcmp(what, "map") || !strcmp(what, "cast")) {
        GLuint t = what[0] == 'm' ? ls->map_tex : ls->cast_tex;
        if (!t)
            return false;
        gl.BindTexture(GL_TEXTURE_2D, t);
        gl.GetTexImage(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT, GL_FLOAT, out);
        gl.BindTexture(GL_TEXTURE_2D, 0);
        return true;
    }
    if (!strcmp(what, "size")) {
        GLuint tex[2] = {ls->map_tex, ls->cast_tex ? ls->cast_tex : ls->map_tex};
        for (int i = 0; i < 2; i++) {
            GLint w = 0, h = 0;
            gl.BindTexture(GL_TEXTURE_2D, tex[i]);
            gl.GetTexLevelParameteriv(GL_TEXTURE_2D, 0, GL_TEXTURE_WIDTH, &w);
            gl.GetTexLevelParameteriv(GL_TEXTURE_2D, 0, GL_TEXTURE_HEIGHT, &h);
            out[2 * i] = (float)w, out[2 * i + 1] = (float)h;
        }
        gl.BindTexture(GL_TEXTURE_2D, 0);
        return true;
    }
    if (!strcmp(what, "focus")) {
        gl.BindTexture(GL_TEXTURE_2D, ls->focus_tex);
        gl.GetTexImage(GL_TEXTURE_2D, 0, GL_RED, GL_FLOAT, out);
        gl.BindTexture(GL_TEXTURE_2D, 0);
        return true;
    }
    if (!strcmp(what, "shadow")) { /* the frame's world -> map matrix */
        memcpy(out, ls->s.shadow.m, sizeof ls->s.shadow.m);
        return true;
    }
    return false;
}
