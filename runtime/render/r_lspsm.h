/* Light Space Perspective Shadow Maps (docs/effects.md, "Shadows in a large
 * world"): the CPU side, no GL.
 *
 * One 1024x1024 map covers the part of the view frustum between `near` and
 * `far` (at most 100 m; "the body").  The map is warped by a perspective
 * whose axis lies across the light, along the view direction (Wimmer,
 * Scherzer, Purgathofer 2004), so texels crowd near the camera.  The warp
 * fades out smoothly as the view turns towards the light (parallel or
 * anti-parallel), reaching plain uniform shadow mapping at the end of an
 * angle band.  It also fades, over a 10 deg band of its own, as the view
 * frustum's outermost edge turns to perpendicular to the warp axis (past
 * that the frustum reaches behind the eye along the axis, and a warp would
 * serve its far edge instead of the eye): with the game's 16:9 view the
 * warp is off below 22 deg with the light above the view, 36 deg with it to
 * the side.  Both blends are continuous in the angles: no pop.  The far end
 * follows the previous frame's depth buffer ("auto-focus"); shadows fade
 * out towards it.
 *
 * Per frame:
 *   r_lspsm_focus_gather + r_lspsm_focus_update   range from last frame's depth
 *   r_lspsm_build (desc.far = focus.range)        matrices for this frame
 *   r_lspsm_caster_visible                        cull casters (shadow pass)
 *   out.light_vp / out.shadow / out.fade          uniforms of the two passes
 * Receivers: texture coordinates = shadow * world position (divide by w),
 * strength *= 1 - smoothstep(fade[0], fade[1], distance to out.eye).
 * Fighters look up at r_lspsm_box_exit() of their own AABB instead. */
#ifndef R_LSPSM_H
#define R_LSPSM_H

#include <stdbool.h>
#include <stdio.h>

#include "r_math.h"

#define R_LSPSM_MAP 1024          /* map edge, texels */
#define R_LSPSM_LIMIT 100.0f      /* shadows only within this distance, metres */
#define R_LSPSM_BAND_START 0.349066f /* 20 deg: warp starts to fade out */
#define R_LSPSM_BAND_END 0.0872665f  /* 5 deg: uniform from here on */
#define R_LSPSM_CASTER_REACH 100.0f  /* casters up to this far towards the light */
#define R_LSPSM_MARGIN 0.1f       /* focus range = farthest point * (1 + margin) */
#define R_LSPSM_FADE 0.2f         /* last 20 % of the limit fades out */
#define R_LSPSM_SHRINK 0.02f      /* focus range shrinks at most 2 % a frame */
#define R_LSPSM_MIN_RANGE 1.0f    /* focus never closer than this, metres */
#define R_LSPSM_WARP_NEAR 2.0f    /* the warp's near distance, metres (below) */

/* The viewer.  r_lspsm_camera_from() reads one off a view and a perspective
 * projection matrix (r_look_at, r_perspective). */
typedef struct r_lspsm_camera {
    r_vec3 eye, dir, up; /* dir and up need not be unit nor orthogonal */
    float fovy, aspect;  /* vertical field of view, radians; width / height */
    float near, far;     /* the projection's clip planes, metres */
} r_lspsm_camera;

/* Zero means default for every field but cam and to_light. */
typedef struct r_lspsm_desc {
    r_lspsm_camera cam;
    r_vec3 to_light;        /* from the scene towards the (directional) light */
    float near, far;        /* shadowed view depths: cam.near / limit */
    float limit;            /* R_LSPSM_LIMIT; far is clamped to it (and to cam.far) */
    float band_start, band_end; /* fallback band, radians between view and light */
    float caster_reach;     /* R_LSPSM_CASTER_REACH metres towards the light */
    float margin, fade;     /* R_LSPSM_MARGIN, R_LSPSM_FADE: where shadows fade */
    bool uniform;           /* no warp at all: plain (uniform) shadow mapping */
    float warp_near;        /* R_LSPSM_WARP_NEAR: the near distance Wimmer's n_opt
                               is chosen for (at least `near`); the camera's 0.1 m
                               would spend the map on the first metres, where the
                               game shows nothing, and leave 2 m texels at 80 m */
} r_lspsm_desc;

typedef struct r_lspsm {
    r_mat4 light_vp; /* world -> clip of the shadow pass: the body (and casters up
                        to caster_reach towards the light) in -1..1, OpenGL z */
    r_mat4 shadow;   /* world -> (u, v, depth, w): 0..1 after dividing by w */
    float fade[2];   /* strength 1 up to fade[0] m from eye, 0 from fade[1] on:
                        min(far / (1 + margin), limit * (1 - fade)) .. far */
    float near, far; /* the body's view depths, as used */
    float gamma;     /* angle between view and light direction, 0..pi */
    float warp;      /* the perspective's strength 1/n, per metre; 0 = uniform */
    float n;         /* its centre's distance behind the body, metres: Wimmer's
                        n_opt weakened by the blends; INFINITY when uniform */
    r_vec3 eye;
    r_vec3 axis[3];  /* light frame: map x, map y (the warp axis), to_light */
} r_lspsm;

r_lspsm_camera r_lspsm_camera_from(r_mat4 view, r_mat4 proj);

/* Always finite, whatever the angles (parallel, anti-parallel, zero vectors). */
void r_lspsm_build(const r_lspsm_desc *d, r_lspsm *out);

/* Shadow strength at p (1 = full, 0 = none): the receivers' fade. */
float r_lspsm_fade(const r_lspsm *s, r_vec3 p);

/* False when the box cannot cast into the map: outside light_vp's frustum,
 * which runs from caster_reach towards the light to the body's far side
 * (conservative: a box near a frustum corner may pass). */
bool r_lspsm_caster_visible(const r_lspsm *s, r_vec3 lo, r_vec3 hi);

/* Where the ray from p (inside or on the box) along dir leaves the box:
 * slab method, zero components allowed; p itself when dir is zero or p
 * lies outside towards dir.  GLSL twin, identical arithmetic:
 *
 *   vec3 box_exit(vec3 p, vec3 d, vec3 lo, vec3 hi)
 *   {
 *       vec3 t = (mix(lo, hi, step(0.0, d)) - p) / d;  // exit time per slab
 *       t = mix(t, vec3(1e30), equal(d, vec3(0.0)));  // select: no inf/NaN
 *       float te = max(min(min(t.x, t.y), t.z), 0.0);
 *       return te < 1e30 ? p + d * te : p;
 *   }
 */
r_vec3 r_lspsm_box_exit(r_vec3 p, r_vec3 dir, r_vec3 lo, r_vec3 hi);

/* Shadow-map texels per metre at p: map_size * the geometric mean of the
 * map's two scale factors, measured across the light (what a receiver
 * facing the light gets; other receivers scale both methods alike). */
double r_lspsm_texels_per_metre(const r_lspsm *s, r_vec3 p, int map_size);

/* `bench accuracy` rows: LSPSM against uniform shadow mapping, same map and
 * range, near (2 m) and far (50 m) on the view axis of the game camera, for
 * 90/60/30/10/0 deg between view and light.  csv may be NULL. */
void r_lspsm_density_rows(FILE *out, FILE *csv);

/* ---- static layers (r_quality.lspsm_static) ----
 * Where neither the light nor the casters move for a whole look (plaza's
 * sun and buildings), their shadows need not be drawn every frame:
 * orthographic layers of one depth-map array are drawn once, each over a
 * world box: the last covers every receiver within reach, the first a
 * smaller box round the ring, where the camera is close, in finer
 * texels.  All share the light frame and the depth range, so a receiver
 * needs one affine map: c = shadow * p (w = 1, no divide) gives the last
 * layer's (u, v, depth); layer l's (u, v) = c.xy * fit[l].xy + fit[l].zw,
 * the finest whose (u, v) lies inside 0..1 taken.  Two layers: a third
 * between them (40 m round the ring) bought nothing in `bench quality`.  Casters nearer the light
 * than the range are clamped to it (GL_DEPTH_CLAMP), so they still cast. */
#define R_LSPSM_LAYERS 2
typedef struct r_lspsm_static {
    r_mat4 light_vp[R_LSPSM_LAYERS];  /* world -> clip of each layer (OpenGL z) */
    r_mat4 shadow;                    /* world -> the last layer's (u, v, depth, 1), 0..1 over its box */
    float fit[R_LSPSM_LAYERS - 1][4]; /* layer l's (u, v) from the last's: scale u, v, offset u, v */
    float depth_m;                    /* metres of light depth across the depth range 0..1 */
    float extent[R_LSPSM_LAYERS][2];  /* each layer's width and height across the light, metres */
    r_vec3 axis[3];                   /* light frame: map x, map y, to_light */
} r_lspsm_static;

/* The layers for a light (from the scene towards it; any direction, a zero
 * one taken as straight up) and a world box per layer (box[l][0] lo,
 * box[l][1] hi; each is fitted on its own, the last gives the depth
 * range).  Always finite. */
void r_lspsm_static_build(r_vec3 to_light, const float box[R_LSPSM_LAYERS][2][3], r_lspsm_static *out);

/* ---- auto-focus ----
 * 20x16 samples of the previous frame's depth buffer in a tilted grid: every
 * sample has its own cell of the 20x16 grid, and its own column and row of
 * the buffer (from 320x320 pixels up), so a horizontal or vertical edge
 * moving over the screen changes one sample at a time. */
#define R_LSPSM_FOCUS_W 20
#define R_LSPSM_FOCUS_H 16
#define R_LSPSM_FOCUS_N (R_LSPSM_FOCUS_W * R_LSPSM_FOCUS_H)

typedef struct r_lspsm_focus {
    float range;  /* the shadow range to use (desc.far); 0 before the first update */
    float limit, margin, shrink, min_range; /* zero: the R_LSPSM_* defaults */
    float farthest; /* last update's farthest distance found, metres (sky: limit) */
    int used;       /* last update's samples that counted (finite, in 0..1) */
} r_lspsm_focus;

/* Sample k's pixel (origin bottom-left, as glReadPixels), k < FOCUS_N. */
void r_lspsm_focus_point(int k, int w, int h, int *x, int *y);
/* Picks the samples out of a w x h window-depth buffer (rows bottom-up). */
void r_lspsm_focus_gather(const float *depth, int w, int h, float out[R_LSPSM_FOCUS_N]);
/* One frame: depth[k] = window depth (0..1, 1 = sky) at sample k of a w x h
 * buffer rendered with inv_vp's inverse.  Range = farthest distance from that
 * eye * (1 + margin), capped at limit; grows at once, shrinks by at most
 * `shrink` a frame.  NaN or out-of-range samples are ignored; with none left
 * the state stays.  Returns the new range. */
float r_lspsm_focus_update(r_lspsm_focus *f, const float depth[R_LSPSM_FOCUS_N], int w, int h, r_mat4 inv_vp);

/* How many updates the range remembers.  Two chains of updates fed the
 * same samples, one from any state and one from the limit (a reset), are
 * equal, bit for bit, from the first update at which the second one lands
 * on its target (it is never below the first, and the target is a lower
 * bound of both); without landing, the second one can only shrink from the
 * limit, and it reaches min_range after this many updates, where it must
 * have landed.  So the range after n >= this many updates from a reset is
 * the range after any longer history (every update having used >= 1
 * sample, which a depth buffer always gives). */
int r_lspsm_focus_memory(const r_lspsm_focus *f);

#endif
