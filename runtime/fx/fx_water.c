/* Water (docs/effects.md, "Water"): the stage effect of `water = yes`.
 *
 *   water_sim      (R_FX_PRE)  contacts -> splats on the CPU; per game tick
 *                              one automaton step on the 256x256 RGBA32F
 *                              ping-pong pair plus the splats drawn as
 *                              GL_POINTS; then the normal map.  On a
 *                              software rasteriser the steps and the
 *                              normal map run in C (fx_water_sim.c, the
 *                              automaton's reference) and are uploaded
 *   water_reflect  (R_FX_PRE)  the reflection map: the sky and a simple
 *                              model of the fighters, mirrored in the water
 *                              plane, at half the screen size
 *   water_under    (SURFACE)   the scene drawn so far (ring floor, legs)
 *                              under the water plane, with height fog, into
 *                              its own texture
 *   water_surface  (SURFACE)   the displaced mesh, opaque with depth write,
 *                              compositing under-water (refracted),
 *                              reflection (Fresnel) and turbidity
 *
 * The water lies over the ring's top face (x, z within +-ring_half) at
 * R_WATER_LEVEL.  The simulation is a function of the game states alone:
 * it steps frame.steps times (at most R_WATER_MAX_STEPS; the ticks past
 * that are dropped) with the contacts of the frame's tick, and restarts
 * flat on frame.reset.  Nothing is built until a stage with water loads. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../game/g_game.h"
#include "fx_water_sim.h"
#include "fx_local.h"
#include "../render/r_shader.h"

extern const r_fx_module fx_water_module;
#define WATER(r) ((struct fx_water_state *)r_fx_state((r), &fx_water_module))

enum { W_SIM, W_SPLAT, W_NORMAL, W_MIRROR, W_UNDER, W_SURFACE, W_PROGS };

#define MESH_N 64        /* surface quads per side: 12.5 cm; the normal map carries the finer detail;
                            r_quality.water_grid overrides it */
#define COLOR_SIZE 128   /* the turbidity textures */
#define MAX_SPLATS (2 * G_BONES)
/* the look (not the automaton: fx_water_sim_params) */
#define REFRACT 0.025f      /* screen uv offset per unit of normal tilt */
#define DISTORT 0.04f       /* the same for the reflection map */
#define TURB_BASE 0.15f     /* deep-colour share of flat water */
#define TURB_RANGE 0.02f    /* metres of height from all shallow to all deep */
#define TURB_TILE 0.35f     /* colour-texture repeats per metre */
#define FOG_BASE 0.5f       /* under-water fog density at the surface, 1/m */
#define FOG_DEPTH 8.0f      /* ... and added per metre of depth, 1/m^2 */
static const float fog_color[3] = {0.10f, 0.26f, 0.27f};

typedef struct fx_water_state {
    bool built;
    fx_water_sim_params prm;
    GLuint prog[W_PROGS];
    GLuint sim_tex[2], sim_fbo[2];
    int cur; /* the sim texture (or grid) holding the latest state */
    /* On a software rasteriser (cpu) the automaton runs in C on grid and
     * the drawn frame uploads its state and normal map (nrm): llvmpipe
     * took 3.1-3.6 ms a frame (one thread) for the step's and the normal
     * map's full-screen passes; in C the step takes about 0.4 ms, the
     * normal map 0.9 and the uploads 0.35, and the ticks a segment
     * advances before its first frame cost a step each, not a pass. */
    bool cpu;
    float *grid[2]; /* 2 n^2 floats each: h, h a step earlier */
    float *heights; /* n^2: the latest heights made safe (cpu_normal_map) */
    uint8_t *nrm;   /* n^2 RGBA8 texels */
    GLuint normal_tex, normal_fbo;
    GLuint splat_vao, splat_vbo;
    fx_water_sim_splat splat[MAX_SPLATS];
    int nsplat;
    GLuint mesh_vao, mesh_vbo, mesh_ibo;
    GLsizei mesh_count;
    int mesh_n; /* quads a side: r_quality.water_grid or MESH_N */
    GLuint shallow_tex, deep_tex;
    /* screen-sized, made for the frame's size */
    int sw, sh;
    GLuint refl_tex, refl_depth, refl_fbo;
    GLuint under_tex, under_fbo;
} fx_water_state;

/* ---- building ---- */

static uint32_t hash2(uint32_t x, uint32_t y, uint32_t seed)
{
    uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ seed * 0xcb1ab31fu;
    h ^= h >> 13, h *= 0x5bd1e995u, h ^= h >> 15;
    return h;
}

/* Tiling value noise, 0..1: octaves of a smoothly interpolated lattice. */
static float noise(int x, int y, int size, uint32_t seed)
{
    float sum = 0, norm = 0, amp = 1;
    for (int cells = 4; cells <= 32; cells *= 2, amp *= 0.55f) {
        float px = (float)x * cells / size, py = (float)y * cells / size;
        int ix = (int)px, iy = (int)py;
        float tx = px - ix, ty = py - iy;
        tx = tx * tx * (3 - 2 * tx), ty = ty * ty * (3 - 2 * ty);
        float v[4];
        for (int k = 0; k < 4; k++)
            v[k] = (float)(hash2((uint32_t)((ix + (k & 1)) % cells), (uint32_t)((iy + (k >> 1)) % cells),
                                 seed + (uint32_t)cells) & 0xffff) / 65535.0f;
        sum += amp * ((v[0] * (1 - tx) + v[1] * tx) * (1 - ty) + (v[2] * (1 - tx) + v[3] * tx) * ty);
        norm += amp;
    }
    return sum / norm;
}

/* The two turbidity colours (linear RGB; alpha = how much of the
 * under-water image the colour hides): clear pale water and murky teal,
 * each with drifting silt. */
static GLuint color_tex(uint8_t *px, bool deep)
{
    static const float shallow_rgb[3] = {0.60f, 0.78f, 0.72f}, deep_rgb[3] = {0.07f, 0.24f, 0.25f};
    for (int y = 0; y < COLOR_SIZE; y++)
        for (int x = 0; x < COLOR_SIZE; x++) {
            float s = noise(x, y, COLOR_SIZE, deep ? 77u : 11u);
            uint8_t *o = px + ((size_t)y * COLOR_SIZE + x) * 4;
            for (int c = 0; c < 3; c++) {
                float v = (deep ? deep_rgb[c] * (0.7f + 0.6f * s) : shallow_rgb[c] * (0.9f + 0.2f * s));
                o[c] = (uint8_t)(fminf(v, 1.0f) * 255 + 0.5f);
            }
            float a = deep ? 0.55f + 0.3f * s : 0.06f + 0.1f * s;
            o[3] = (uint8_t)(a * 255 + 0.5f);
        }
    /* smooth silt, about 3 m a tile: no mip levels needed (and bilinear
     * is half the price of trilinear on a software renderer) */
    return r_tex2d(GL_RGBA8, COLOR_SIZE, COLOR_SIZE, GL_RGBA, GL_UNSIGNED_BYTE, px, GL_LINEAR, GL_REPEAT);
}

/* The surface grid (u, v, 0) and the skirt: per edge a strip from the
 * surface (u, v, 2) down to the ring floor (u, v, 1). */
static bool build_mesh(fx_water_state *w)
{
    const int n = w->mesh_n, row = n + 1, ngrid = row * row, nv = ngrid + 4 * 2 * row;
    float *v = malloc((size_t)nv * 3 * sizeof *v);
    unsigned *idx = malloc(((size_t)n * n + 4 * (size_t)n) * 6 * sizeof *idx);
    if (!v || !idx) {
        free(v), free(idx);
        return false;
    }
    size_t ni = 0;
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            float *o = v + (size_t)(j * row + i) * 3;
            o[0] = (float)i / n, o[1] = (float)j / n, o[2] = 0;
        }
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            unsigned a = (unsigned)(j * row + i), b = a + 1, c = a + (unsigned)row, d = c + 1;
            unsigned q[6] = {a, c, b, b, c, d};
            memcpy(idx + ni, q, sizeof q);
            ni += 6;
        }
    for (int e = 0; e < 4; e++) {
        unsigned base = (unsigned)(ngrid + e * 2 * row);
        for (int k = 0; k <= n; k++) {
            float t = (float)k / n;
            float u = e == 0 ? t : e == 1 ? t : e == 2 ? 0.0f : 1.0f;
            float vv = e == 0 ? 0.0f : e == 1 ? 1.0f : t;
            float *top = v + (size_t)(base + 2 * k) * 3, *bottom = top + 3;
            top[0] = bottom[0] = u, top[1] = bottom[1] = vv;
            top[2] = 2, bottom[2] = 1;
        }
        for (int k = 0; k < n; k++) {
            unsigned a = base + 2 * (unsigned)k, b = a + 1, c = a + 2, d = a + 3;
            unsigned q[6] = {a, b, c, c, b, d};
            memcpy(idx + ni, q, sizeof q);
            ni += 6;
        }
    }
    gl.GenVertexArrays(1, &w->mesh_vao);
    gl.BindVertexArray(w->mesh_vao);
    gl.GenBuffers(1, &w->mesh_vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, w->mesh_vbo);
    gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)((size_t)nv * 3 * sizeof *v), v, GL_STATIC_DRAW);
    gl.GenBuffers(1, &w->mesh_ibo);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, w->mesh_ibo);
    gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(ni * sizeof *idx), idx, GL_STATIC_DRAW);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), (void *)0);
    gl.BindVertexArray(0);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
    w->mesh_count = (GLsizei)ni;
    free(v), free(idx);
    return true;
}

static void free_targets(fx_water_state *w)
{
    GLuint tex[] = {w->refl_tex, w->under_tex};
    gl.DeleteTextures(2, tex);
    gl.DeleteRenderbuffers(1, &w->refl_depth);
    GLuint fbo[] = {w->refl_fbo, w->under_fbo};
    gl.DeleteFramebuffers(2, fbo);
    w->refl_tex = w->under_tex = w->refl_depth = w->refl_fbo = w->under_fbo = 0;
    w->sw = w->sh = 0;
}

static void free_gl(fx_water_state *w)
{
    for (int i = 0; i < W_PROGS; i++)
        if (w->prog[i])
            gl.DeleteProgram(w->prog[i]);
    gl.DeleteTextures(2, w->sim_tex);
    gl.DeleteFramebuffers(2, w->sim_fbo);
    GLuint tex[] = {w->normal_tex, w->shallow_tex, w->deep_tex};
    gl.DeleteTextures(3, tex);
    gl.DeleteFramebuffers(1, &w->normal_fbo);
    r_free_mesh(&w->mesh_vao, &w->mesh_vbo, &w->mesh_ibo);
    if (w->splat_vao)
        gl.DeleteVertexArrays(1, &w->splat_vao);
    if (w->splat_vbo)
        gl.DeleteBuffers(1, &w->splat_vbo);
    free_targets(w);
    free(w->grid[0]), free(w->grid[1]), free(w->heights), free(w->nrm);
    fx_water_sim_params prm = w->prm;
    memset(w, 0, sizeof *w);
    w->prm = prm;
}

static bool build(fx_water_state *w, rs_err *err)
{
    static const struct {
        int id;
        const char *vs, *fs, *defines;
    } d[] = {
        {W_SIM, "cap_fullscreen.vert", "water_sim.frag", NULL},
        {W_SPLAT, "water_splat.vert", "water_splat.frag", NULL},
        {W_NORMAL, "cap_fullscreen.vert", "water_normal.frag", NULL},
        {W_MIRROR, "scene.vert", "water_mirror.frag", "#define FIGHTER 1\n"}, /* the fighters' vertex program */
        {W_UNDER, "water_under.vert", "water_under.frag", NULL},
        {W_SURFACE, "water_surface.vert", "water_surface.frag", NULL},
    };
    for (size_t i = 0; i < sizeof d / sizeof d[0]; i++)
        if (!(w->prog[d[i].id] = r_program(&(r_program_desc){.vs = d[i].vs, .fs = d[i].fs, .defines = d[i].defines}, err)))
            goto fail;
    /* the simulation: 256x256 RGBA32F ping-pong (r height, g previous height) */
    for (int k = 0; k < 2; k++) {
        w->sim_tex[k] = r_tex2d(GL_RGBA32F, R_WATER_N, R_WATER_N, GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
        w->sim_fbo[k] = r_fbo_for(w->sim_tex[k], 0, 0);
        if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
            rs_fail(err, R_ERR_TARGET, "water: the %dx%d RGBA32F simulation target is not renderable on this driver", R_WATER_N,
                    R_WATER_N);
            goto fail;
        }
    }
    w->normal_tex = r_tex2d(GL_RGBA8, R_WATER_N, R_WATER_N, GL_RGBA, GL_UNSIGNED_BYTE, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    w->normal_fbo = r_fbo_for(w->normal_tex, 0, 0);
    gl.GenVertexArrays(1, &w->splat_vao);
    gl.BindVertexArray(w->splat_vao);
    gl.GenBuffers(1, &w->splat_vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, w->splat_vbo);
    gl.BufferData(GL_ARRAY_BUFFER, sizeof w->splat, NULL, GL_STREAM_DRAW);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, sizeof(fx_water_sim_splat), (void *)0);
    gl.BindVertexArray(0);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
    uint8_t *px = malloc((size_t)COLOR_SIZE * COLOR_SIZE * 4);
    if (!px || !build_mesh(w)) {
        free(px);
        rs_fail(err, R_ERR_NOMEM, "out of memory for the water");
        goto fail;
    }
    w->shallow_tex = color_tex(px, false);
    w->deep_tex = color_tex(px, true);
    free(px);
    const size_t cells = (size_t)R_WATER_N * R_WATER_N;
    w->grid[0] = calloc(2 * cells, sizeof(float)), w->grid[1] = calloc(2 * cells, sizeof(float));
    w->nrm = malloc(4 * cells), w->heights = malloc(cells * sizeof(float));
    if (!w->grid[0] || !w->grid[1] || !w->nrm || !w->heights) {
        rs_fail(err, R_ERR_NOMEM, "out of memory for the water");
        goto fail;
    }
    w->cpu = rgl_is_software();
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    w->built = true;
    RGL_CHECK("water build");
    return true;
fail:
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    free_gl(w);
    return false;
}

static bool create(r_game *r, rs_err *err)
{
    fx_water_state *w = calloc(1, sizeof *w);
    if (!w)
        return rs_fail(err, R_ERR_NOMEM, "out of memory");
    r_fx_set_state(r, &fx_water_module, w);
    fx_water_sim_params_fix(&w->prm);
    w->mesh_n = r_fx_quality(r)->water_grid > 0 ? r_fx_quality(r)->water_grid : MESH_N; /* range checked by r_game_create_opts */
    return true;
}

static void destroy(r_game *r)
{
    if (!WATER(r))
        return;
    free_gl(WATER(r));
    free(WATER(r));
    r_fx_set_state(r, &fx_water_module, NULL);
}

/* Builds on the first stage with water; a later stage keeps what is built
 * but the screen-sized targets, which only a water stage needs. */
static bool load(r_game *r, rs_err *err)
{
    fx_water_state *w = WATER(r);
    if (w && !r_fx_stage(r)->water)
        free_targets(w);
    return !r_fx_stage(r)->water || !w || w->built || build(w, err);
}

static bool need_water(void *u)
{
    r_game *r = u;
    return r_fx_stage(r)->water && WATER(r) && WATER(r)->built;
}

/* ---- the simulation ---- */

static void restore_draw_state(void)
{
    gl.Disable(GL_BLEND);
    gl.Disable(GL_PROGRAM_POINT_SIZE);
    gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

static void clear_state(fx_water_state *w)
{
    const float zero[4] = {0, 0, 0, 0};
    for (int k = 0; k < 2; k++)
        memset(w->grid[k], 0, (size_t)R_WATER_N * R_WATER_N * 2 * sizeof(float));
    for (int k = 0; k < 2; k++) {
        gl.BindFramebuffer(GL_FRAMEBUFFER, w->sim_fbo[k]);
        gl.ClearBufferfv(GL_COLOR, 0, zero);
    }
}

/* steps automaton steps, each followed by the splats (additive points into
 * the red channel: an impulse of vertical velocity, h_prev untouched) */
static void gpu_steps(r_game *r, fx_water_state *w, const fx_water_sim_splat *s, int ns, int steps)
{
    if (steps <= 0)
        return;
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    gl.Disable(GL_SCISSOR_TEST);
    gl.Disable(GL_BLEND);
    gl.Viewport(0, 0, R_WATER_N, R_WATER_N);
    if (ns > 0) {
        gl.BindBuffer(GL_ARRAY_BUFFER, w->splat_vbo);
        gl.BufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)((size_t)ns * sizeof *s), s);
        gl.BindBuffer(GL_ARRAY_BUFFER, 0);
    }
    const fx_water_sim_params *p = &w->prm;
    for (int k = 0; k < steps; k++) {
        int dst = 1 - w->cur;
        gl.BindFramebuffer(GL_FRAMEBUFFER, w->sim_fbo[dst]);
        GLuint q = w->prog[W_SIM];
        gl.UseProgram(q);
        r_bind_tex(q, "u_state", 0, GL_TEXTURE_2D, w->sim_tex[w->cur]);
        gl.Uniform1f(r_loc(q, "u_c2"), p->courant * p->courant);
        gl.Uniform1f(r_loc(q, "u_damping"), p->damping);
        gl.Uniform1f(r_loc(q, "u_h_max"), p->h_max);
        r_fullscreen(r);
        if (ns > 0) {
            q = w->prog[W_SPLAT];
            gl.Enable(GL_BLEND);
            gl.BlendEquation(GL_FUNC_ADD);
            gl.BlendFunc(GL_ONE, GL_ONE);
            gl.ColorMask(GL_TRUE, GL_FALSE, GL_FALSE, GL_FALSE);
            gl.Enable(GL_PROGRAM_POINT_SIZE);
            gl.UseProgram(q);
            gl.Uniform2f(r_loc(q, "u_grid"), (float)R_WATER_N, (float)R_WATER_N);
            gl.BindVertexArray(w->splat_vao);
            gl.DrawArrays(GL_POINTS, 0, ns);
            restore_draw_state();
        }
        w->cur = dst;
    }
}

/* gpu_steps in C: the automaton's reference step (the shader's arithmetic,
 * test_fx_water/gpu_matches_cpu), then the splats' bumps */
static void cpu_steps(fx_water_state *w, const fx_water_sim_splat *s, int ns, int steps)
{
    for (int k = 0; k < steps; k++) {
        int dst = 1 - w->cur;
        fx_water_sim_step(&w->prm, R_WATER_N, w->grid[w->cur], w->grid[dst]);
        for (int i = 0; i < ns; i++)
            fx_water_sim_add_splat(R_WATER_N, w->grid[dst], &s[i]);
        w->cur = dst;
    }
}

/* water_normal.frag in C, and the state and the normal map uploaded for
 * the passes that read them (the surface's vertices and pixels) */
static void cpu_normal_map(fx_water_state *w)
{
    const int n = R_WATER_N;
    const float *g = w->grid[w->cur], hm = w->prm.h_max, k2dx = (float)n / (2 * w->prm.size);
    float *hs = w->heights; /* the safe heights, once each */
    for (size_t k = 0; k < (size_t)n * n; k++)
        hs[k] = fx_water_sim_height(g[2 * k], hm);
    for (int j = 0; j < n; j++) {
        const float *row = hs + (size_t)j * n, *down = hs + (size_t)(j > 0 ? j - 1 : 0) * n;
        const float *up = hs + (size_t)(j < n - 1 ? j + 1 : n - 1) * n;
        uint8_t *o = w->nrm + 4 * (size_t)j * n;
        for (int i = 0; i < n; i++, o += 4) {
            float l = row[i > 0 ? i - 1 : 0], r = row[i < n - 1 ? i + 1 : n - 1];
            float nx = (l - r) * k2dx, nz = (down[i] - up[i]) * k2dx, inv = 1 / sqrtf(nx * nx + 1 + nz * nz);
            float c[4] = {nx * inv * 0.5f + 0.5f, inv * 0.5f + 0.5f, nz * inv * 0.5f + 0.5f, row[i] * 0.5f / hm + 0.5f};
            for (int q = 0; q < 4; q++) { /* GL's float -> unorm8: clamped, rounded to nearest */
                float v = c[q] < 0 ? 0 : c[q] > 1 ? 1 : c[q];
                o[q] = (uint8_t)(v * 255 + 0.5f);
            }
        }
    }
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.BindTexture(GL_TEXTURE_2D, w->normal_tex);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, n, n, GL_RGBA, GL_UNSIGNED_BYTE, w->nrm);
    gl.BindTexture(GL_TEXTURE_2D, w->sim_tex[w->cur]);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, n, n, GL_RG, GL_FLOAT, g);
    gl.BindTexture(GL_TEXTURE_2D, 0);
}

static float ring_half(const r_game *r)
{
    int st = r_game_ring_stage(r) >= 0 ? r_game_ring_stage(r) : r_fx_stage(r)->game_index;
    return st >= 0 && st < G_STAGES ? fx_to_float(g_stages[st].ring_half) : 4.0f;
}

/* The automaton's part of water_sim: f->steps steps with this tick's
 * splats (the history; water_advance runs only this).  False when no step
 * ran and nothing was reset: the normal map still stands. */
static bool step_sim(r_game *r)
{
    fx_water_state *w = WATER(r);
    const frame *f = r_fx_frame(r);
    if (f->reset)
        clear_state(w);
    w->prm.size = 2 * ring_half(r);
    /* the CPU's part: where the bone capsules dip under the surface, and a
     * splat per contact as strong as that part of the bone is fast */
    r_fx_contact c[MAX_SPLATS];
    int nc = r_fx_contacts(f->caps, f->caps_prev, R_WATER_LEVEL, c, MAX_SPLATS);
    w->nsplat = 0;
    for (int k = 0; k < nc; k++)
        if (fx_water_sim_splat_for(&w->prm, R_WATER_N, c[k].x, c[k].z, c[k].radius, c[k].depth, c[k].speed,
                              &w->splat[w->nsplat]))
            w->nsplat++;
    /* one step per game tick; a frame that skipped ticks replays this
     * tick's splats for each (there are no states between) */
    int steps = f->steps < R_WATER_MAX_STEPS ? f->steps : R_WATER_MAX_STEPS;
    if (w->cpu)
        cpu_steps(w, w->splat, w->nsplat, steps);
    else
        gpu_steps(r, w, w->splat, w->nsplat, steps);
    return steps > 0 || f->reset;
}

static void run_sim(void *u)
{
    r_game *r = u;
    fx_water_state *w = WATER(r);
    if (!step_sim(r))
        return; /* the same tick again: the normal map stands */
    if (w->cpu) {
        cpu_normal_map(w);
        return;
    }
    /* the normal map from the heights: made for the drawn frame only (an
     * advanced tick's would be made again before anyone reads it) */
    GLuint q = w->prog[W_NORMAL];
    gl.BindFramebuffer(GL_FRAMEBUFFER, w->normal_fbo);
    gl.Viewport(0, 0, R_WATER_N, R_WATER_N);
    gl.Disable(GL_DEPTH_TEST);
    gl.UseProgram(q);
    r_bind_tex(q, "u_state", 0, GL_TEXTURE_2D, w->sim_tex[w->cur]);
    gl.Uniform1f(r_loc(q, "u_dx"), w->prm.size / R_WATER_N);
    gl.Uniform1f(r_loc(q, "u_h_max"), w->prm.h_max);
    r_fullscreen(r);
    RGL_CHECK("water_sim");
}

/* ---- the reflection and the under-water image ---- */

static void ensure_targets(fx_water_state *w, int sw, int sh)
{
    if (w->sw == sw && w->sh == sh)
        return;
    free_targets(w);
    int rw = r_half(sw, 1), rh = r_half(sh, 1);
    w->refl_tex = r_tex2d(GL_RGBA16F, rw, rh, GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    gl.GenRenderbuffers(1, &w->refl_depth);
    gl.BindRenderbuffer(GL_RENDERBUFFER, w->refl_depth);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, rw, rh);
    gl.BindRenderbuffer(GL_RENDERBUFFER, 0);
    w->refl_fbo = r_fbo_for(w->refl_tex, 0, 0);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, w->refl_depth);
    w->under_tex = r_tex2d(GL_RGBA16F, sw, sh, GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    w->under_fbo = r_fbo_for(w->under_tex, 0, 0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    w->sw = sw, w->sh = sh;
}

static void run_reflect(void *u)
{
    r_game *r = u;
    fx_water_state *w = WATER(r);
    const frame *f = r_fx_frame(r);
    ensure_targets(w, f->w, f->h);
    gl.BindFramebuffer(GL_FRAMEBUFFER, w->refl_fbo);
    gl.Viewport(0, 0, r_half(f->w, 1), r_half(f->h, 1));
    gl.Disable(GL_BLEND);
    gl.Disable(GL_CULL_FACE);
    gl.DepthMask(GL_TRUE);
    gl.ClearDepth(1.0);
    gl.Clear(GL_DEPTH_BUFFER_BIT);
    /* the camera mirrored in the plane y = level: y -> 2 level - y */
    r_mat4 mirror = r_identity();
    mirror.m[5] = -1, mirror.m[13] = 2 * R_WATER_LEVEL;
    r_mat4 vp = r_mul(f->vp, mirror);
    /* the sky seen in the mirror, the sun disc too (its glint on the water) */
    const r_stage *st = r_fx_stage(r);
    GLuint p = r_fx_core_gl(r).prog_sky;
    gl.Disable(GL_DEPTH_TEST);
    gl.UseProgram(p);
    /* the sky program keeps the fog uniforms run_sky set last frame (maybe
     * another stage's): the mirror is not fogged */
    gl.Uniform1i(r_loc(p, "u_fog_on"), 0);
    r_mat4 inv = r_invert(vp);
    gl.UniformMatrix4fv(r_loc(p, "u_inv_view_proj"), 1, GL_FALSE, inv.m);
    r_bind_tex(p, "u_env", 0, GL_TEXTURE_CUBE_MAP, r_fx_core_gl(r).sky_tex);
    r_sun_uniforms(p, st);
    gl.Uniform1f(r_loc(p, "u_flash"), f->flash);
    r_fullscreen(r);
    /* the simple model: the fighters above the water, mirrored */
    p = w->prog[W_MIRROR];
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.UseProgram(p);
    gl.UniformMatrix4fv(r_loc(p, "u_view_proj"), 1, GL_FALSE, vp.m);
    gl.Uniform1f(r_loc(p, "u_level"), R_WATER_LEVEL);
    r_bind_ibl(r, p);
    /* A mirror turns the winding round: the faces towards the camera are
     * GL_BACK here.  Culling the others halves the fighters' fragments
     * and triangles (single-threaded at 640x360, shallows: this pass 3.8-5.4
     * -> 2.6-2.9 ms).  What culling them loses: where a limb goes under the
     * water, a ray through the discarded part met the inside of the
     * capsule above the plane; now it meets what is behind it.  A few
     * pixels at the waterline, 65 dB from the image with them. */
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_FRONT);
    r_draw_fighters(r, p);
    gl.CullFace(GL_BACK);
    gl.Disable(GL_CULL_FACE);
    RGL_CHECK("water_reflect");
}

/* The screen rectangle of the water's box (floor to the highest wave);
 * the whole screen when a corner is behind the camera. */
static void water_box(const r_game *r, float half, int box[4])
{
    const frame *f = r_fx_frame(r);
    float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
    for (int k = 0; k < 8; k++) {
        r_vec3 c = r_v3(k & 1 ? half : -half, k & 2 ? R_WATER_LEVEL + WATER(r)->prm.h_max : 0.0f, k & 4 ? half : -half);
        float x, y;
        if (!r_project(f->vp, c, f->w, f->h, &x, &y) || !isfinite(x) || !isfinite(y)) {
            box[0] = box[1] = 0, box[2] = f->w, box[3] = f->h;
            return;
        }
        x0 = fminf(x0, x), y0 = fminf(y0, y), x1 = fmaxf(x1, x), y1 = fmaxf(y1, y);
    }
    x0 = fmaxf(floorf(x0) - 2, 0), y0 = fmaxf(floorf(y0) - 2, 0);
    x1 = fminf(ceilf(x1) + 2, (float)f->w), y1 = fminf(ceilf(y1) + 2, (float)f->h);
    box[0] = (int)x0, box[1] = (int)y0;
    box[2] = x1 > x0 ? (int)(x1 - x0) : 0, box[3] = y1 > y0 ? (int)(y1 - y0) : 0;
}

static void run_under(void *u)
{
    r_game *r = u;
    fx_water_state *w = WATER(r);
    const frame *f = r_fx_frame(r);
    ensure_targets(w, f->w, f->h);
    gl.BindFramebuffer(GL_FRAMEBUFFER, w->under_fbo);
    gl.Viewport(0, 0, f->w, f->h);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.Disable(GL_SCISSOR_TEST);
    const float zero[4] = {0, 0, 0, 0}; /* alpha 0: nothing under the water */
    gl.ClearBufferfv(GL_COLOR, 0, zero);
    int box[4];
    water_box(r, ring_half(r), box);
    gl.Enable(GL_SCISSOR_TEST);
    gl.Scissor(box[0], box[1], box[2], box[3]);
    GLuint p = w->prog[W_UNDER];
    gl.UseProgram(p);
    r_fx_gl core = r_fx_core_gl(r);
    r_bind_tex(p, "u_hdr", 0, GL_TEXTURE_2D, core.hdr_tex);
    r_bind_tex(p, "u_depth", 1, GL_TEXTURE_2D, core.depth_tex);
    r_bind_tex(p, "u_diffuse_on", 8, GL_TEXTURE_CUBE_MAP, core.diffuse_on);
    gl.UniformMatrix4fv(r_loc(p, "u_inv_view_proj"), 1, GL_FALSE, f->inv_vp.m);
    gl.Uniform3f(r_loc(p, "u_eye"), f->eye.x, f->eye.y, f->eye.z);
    gl.Uniform2f(r_loc(p, "u_size"), (float)f->w, (float)f->h);
    gl.Uniform1f(r_loc(p, "u_level"), R_WATER_LEVEL);
    float half = ring_half(r);
    gl.Uniform2f(r_loc(p, "u_half"), half, half);
    gl.Uniform3fv(r_loc(p, "u_wall_color"), 1, r_fx_stage(r)->ring_color);
    gl.Uniform1f(r_loc(p, "u_fog_base"), FOG_BASE);
    gl.Uniform1f(r_loc(p, "u_fog_depth"), FOG_DEPTH);
    gl.Uniform3fv(r_loc(p, "u_fog_color"), 1, fog_color);
    r_fullscreen(r);
    gl.Disable(GL_SCISSOR_TEST);
    RGL_CHECK("water_under");
}

static void run_surface(void *u)
{
    r_game *r = u;
    fx_water_state *w = WATER(r);
    const frame *f = r_fx_frame(r);
    float half = ring_half(r);
    r_fx_gl core = r_fx_core_gl(r);
    gl.BindFramebuffer(GL_FRAMEBUFFER, core.hdr_fbo);
    gl.Viewport(0, 0, f->w, f->h);
    gl.Enable(GL_DEPTH_TEST); /* opaque: tested and written like any surface */
    gl.DepthFunc(GL_LESS);
    gl.DepthMask(GL_TRUE);
    gl.Disable(GL_CULL_FACE);
    gl.Disable(GL_BLEND);
    GLuint p = w->prog[W_SURFACE];
    r_camera_uniforms(r, p);
    r_bind_tex(p, "u_diffuse_on", 8, GL_TEXTURE_CUBE_MAP, core.diffuse_on);
    r_bind_tex(p, "u_state", 0, GL_TEXTURE_2D, w->sim_tex[w->cur]);
    r_bind_tex(p, "u_normal_map", 1, GL_TEXTURE_2D, w->normal_tex);
    r_bind_tex(p, "u_under", 2, GL_TEXTURE_2D, w->under_tex);
    r_bind_tex(p, "u_refl", 3, GL_TEXTURE_2D, w->refl_tex);
    r_bind_tex(p, "u_shallow", 4, GL_TEXTURE_2D, w->shallow_tex);
    r_bind_tex(p, "u_deep", 5, GL_TEXTURE_2D, w->deep_tex);
    gl.Uniform2f(r_loc(p, "u_half"), half, half);
    gl.Uniform1f(r_loc(p, "u_level"), R_WATER_LEVEL);
    gl.Uniform1f(r_loc(p, "u_h_max"), w->prm.h_max);
    gl.Uniform2f(r_loc(p, "u_size"), (float)f->w, (float)f->h);
    gl.Uniform1f(r_loc(p, "u_refract"), REFRACT);
    gl.Uniform1f(r_loc(p, "u_distort"), DISTORT);
    gl.Uniform1f(r_loc(p, "u_turb_base"), TURB_BASE);
    gl.Uniform1f(r_loc(p, "u_turb_range"), TURB_RANGE);
    gl.Uniform1f(r_loc(p, "u_tile"), TURB_TILE);
    gl.BindVertexArray(w->mesh_vao);
    gl.DrawElements(GL_TRIANGLES, w->mesh_count, GL_UNSIGNED_INT, NULL);
    RGL_CHECK("water_surface");
}

/* ---- for tests (fx_water_sim.h) ---- */

const fx_water_sim_params *fx_water_params(r_game *r)
{
    return WATER(r) && WATER(r)->built ? &WATER(r)->prm : NULL;
}

bool fx_water_gpu_steps(r_game *r, const fx_water_sim_splat *s, int ns, int steps)
{
    fx_water_state *w = WATER(r);
    if (!w || !w->built || ns < 0 || ns > MAX_SPLATS)
        return false;
    gpu_steps(r, w, s, ns, steps);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindVertexArray(0);
    return true;
}

bool fx_water_read(r_game *r, float *grid)
{
    fx_water_state *w = WATER(r);
    if (w && w->built && w->cpu) {
        memcpy(grid, w->grid[w->cur], (size_t)R_WATER_N * R_WATER_N * 2 * sizeof *grid);
        return true;
    }
    float *px = w && w->built ? malloc((size_t)R_WATER_N * R_WATER_N * 4 * sizeof *px) : NULL;
    if (!px)
        return false;
    gl.BindTexture(GL_TEXTURE_2D, w->sim_tex[w->cur]);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.GetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, px);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    for (size_t k = 0; k < (size_t)R_WATER_N * R_WATER_N; k++)
        grid[2 * k] = px[4 * k], grid[2 * k + 1] = px[4 * k + 1];
    free(px);
    return true;
}

bool fx_water_write(r_game *r, const float *grid)
{
    fx_water_state *w = WATER(r);
    if (w && w->built && w->cpu) {
        memcpy(w->grid[w->cur], grid, (size_t)R_WATER_N * R_WATER_N * 2 * sizeof *grid);
        return true;
    }
    float *px = w && w->built ? calloc((size_t)R_WATER_N * R_WATER_N * 4, sizeof *px) : NULL;
    if (!px)
        return false;
    for (size_t k = 0; k < (size_t)R_WATER_N * R_WATER_N; k++)
        px[4 * k] = grid[2 * k], px[4 * k + 1] = grid[2 * k + 1];
    gl.BindTexture(GL_TEXTURE_2D, w->sim_tex[w->cur]);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, R_WATER_N, R_WATER_N, GL_RGBA, GL_FLOAT, px);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    free(px);
    return true;
}

bool fx_water_set_cpu(r_game *r, bool cpu, bool *was)
{
    fx_water_state *w = WATER(r);
    if (!w || !w->built)
        return false;
    if (was)
        *was = w->cpu;
    if (cpu != w->cpu) { /* the state goes with it */
        float *g = malloc((size_t)R_WATER_N * R_WATER_N * 2 * sizeof *g);
        if (!g || !fx_water_read(r, g)) {
            free(g);
            return false;
        }
        w->cpu = cpu;
        fx_water_write(r, g);
        free(g);
    }
    return true;
}

int fx_water_last_splats(r_game *r)
{
    return WATER(r) ? WATER(r)->nsplat : 0;
}

/* ---- the module ---- */

static const r_pass pre[] = {
    {"water_sim", RES_WATER, RES_WATER, need_water, run_sim, 0},
    {"water_reflect", RES_ENV, RES_WATER_REFL, need_water, run_reflect, 0},
};
static const r_pass surface[] = {
    {"water_under", RES_ENV | RES_HDR | RES_DEPTH, RES_WATER_UNDER, need_water, run_under, 0},
    {"water_surface", RES_ENV | RES_WATER | RES_WATER_REFL | RES_WATER_UNDER | RES_DEPTH, RES_HDR | RES_DEPTH,
     need_water, run_surface, 0},
};

/* History: the wave automaton (heights now and a tick ago, sim_tex) and
 * the normal map made from it: cleared on a reset, then one step per
 * tick with that tick's splats.  The waves are damped but never exactly
 * zero again, so every tick since the reset counts.  water_advance is the
 * water_sim pass's steps without the normal map (the drawn frame makes it
 * from the heights): it draws into the automaton's own targets only. */
static void water_advance(r_game *r)
{
    if (need_water(r))
        step_sim(r);
}

static int water_warmup(r_game *r)
{
    return need_water(r) ? R_FX_FROM_START : R_FX_STATELESS;
}

const r_fx_module fx_water_module = {
    .name = "water", .create = create, .destroy = destroy, .load = load,
    .pass = {pre, surface, NULL}, .npass = {2, 2, 0},
    .res = {{RES_WATER, "water", true}, {RES_WATER_REFL, "water reflection", false},
            {RES_WATER_UNDER, "under water", false}},
    .warmup = water_warmup, .advance = water_advance,
};
