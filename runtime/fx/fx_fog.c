/* Fog map (docs/effects.md, "Fog map"): mist particles laid over the stage,
 * moved by a global wind plus the local wind that fast limbs stir up
 * (fx_fog_sim.c, once per game tick), are drawn each frame as soft
 * sprites into a top-down density map; the scene's vertex shaders read it
 * as height-fog density (shaders/fog_common.glsl), so the fog varies at
 * equal height, with none of the sorting or clipping troubles of layered
 * translucent fog sheets.
 *
 * One pass, "fog_map" (phase R_FX_PRE, writes RES_FOGMAP), on stages with
 * `fog = yes` only:
 *   1. the simulation follows the game: restart on frame.reset, stir with
 *      the bone capsules' end points (frame.caps against frame.caps_prev),
 *      then frame.steps ticks;
 *   2. the particles (and the copies of those that cross the map's edge:
 *      the mist wraps round) are drawn additively into an R16F map of
 *      size x size texels over x, z in +-half metres, normalised so that
 *      its mean is 1: as instanced sprites on a GPU, in plain C and one
 *      upload on a software rasteriser (splat_cpu);
 *   3. optionally a blur.
 * fog_bind (its r_fx_module bind hook) then hands the map and the fog's light to the scene's
 * programs (scene.vert/.frag and lens.frag include fog_common.glsl). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../game/g_game.h"
#include "../util/rs_progress.h"
#include "fx_fog.h"
#include "fx_fog_sim.h"
#include "fx_local.h"
#include "../render/r_shader.h"

extern const r_fx_module fx_fog_module;
#define FOG(r) ((struct fx_fog_state *)r_fx_state((r), &fx_fog_module))

/* What the fog looks like (no reference numbers; these suit mistvale). */
typedef struct fog_look {
    int map_size;     /* the map's edge, texels */
    float sprite_m;   /* a particle's sprite radius, m (at most half the map's half edge) */
    bool blur;        /* blur the map once (9 taps each way) */
    float density;    /* extinction per metre where the map reads 1, at the base height */
    float base;       /* m: the mist is densest at and below this height (the ring floor) */
    float height;     /* m: scale height of the density above the base */
    float brightness; /* the fog's sky light = the stage's sky_horizon x this */
    float albedo;     /* share of the key light the mist scatters */
    float g;          /* Henyey-Greenstein asymmetry: forward scattering towards the key */
} fog_look;

static const fog_look default_look = {
    .map_size = 128, .sprite_m = 1.0f, .blur = false, .density = 0.15f, .base = 0.0f, .height = 0.9f,
    .brightness = 1.0f, .albedo = 0.9f, .g = 0.35f,
};

struct fx_fog_state {
    fog_look look;
    fx_fog_sim sim;
    GLuint prog;          /* fog_splat.vert/.frag */
    GLuint vao, vbo;
    float *inst;          /* x, z, weight per sprite, wrapped copies included */
    int cap;              /* sprites inst and vbo have room for */
    int size;             /* the map's edge now */
    GLuint tex, fbo;      /* the fog map */
    bool cpu;             /* splat on the CPU (a software rasteriser; a test hook may set it) */
    float *map;           /* size x size: splat_cpu's sums */
    GLuint tmp_tex, tmp_fbo; /* the blur's half-way image */
};

/* ---- the map ---- */

static void free_map(struct fx_fog_state *fg)
{
    GLuint tex[2] = {fg->tex, fg->tmp_tex}, fbo[2] = {fg->fbo, fg->tmp_fbo};
    gl.DeleteTextures(2, tex);
    gl.DeleteFramebuffers(2, fbo);
    fg->tex = fg->tmp_tex = fg->fbo = fg->tmp_fbo = 0;
    free(fg->map);
    fg->map = NULL;
    fg->size = 0;
}

static bool make_map(struct fx_fog_state *fg, int size, rs_err *err)
{
    if (fg->size == size)
        return true;
    free_map(fg);
    /* REPEAT: the mist wraps round, and beyond the map the ground far
     * below sees the same mist again rather than a smeared edge */
    fg->tex = r_tex2d(GL_R16F, size, size, GL_RED, GL_FLOAT, NULL, GL_LINEAR, GL_REPEAT);
    fg->fbo = r_fbo_for(fg->tex, 0, 0);
    GLenum st = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    fg->tmp_tex = r_tex2d(GL_R16F, size, size, GL_RED, GL_FLOAT, NULL, GL_LINEAR, GL_REPEAT);
    fg->tmp_fbo = r_fbo_for(fg->tmp_tex, 0, 0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    fg->size = size;
    if (st != GL_FRAMEBUFFER_COMPLETE) {
        free_map(fg);
        return rs_fail(err, R_ERR_TARGET, "fog map: %dx%d R16F target incomplete (%s)", size, size, rgl_enum_name(st));
    }
    if (!(fg->map = malloc((size_t)size * (size_t)size * sizeof *fg->map))) {
        free_map(fg);
        return rs_fail(err, R_ERR_NOMEM, "fog map: out of memory for a %dx%d map", size, size);
    }
    return true;
}

/* Step 2 in plain C: what the sprites of fog_splat.vert/.frag give, summed
 * in float at the same texel centres ((i + 0.5, j + 0.5) in the map's
 * texels; a sprite's centre at (x + half) x size / (2 half)), then one
 * upload.  On llvmpipe the 3,000 instanced quads into the R16F map, about
 * 130 blended fragments each, cost 4-7 ms of a 640x360 frame on one
 * core; this sum about 1.5 ms and the upload 0.3.  The sums are float where
 * the blend rounds each to half float, so the two differ by about fp16's
 * rounding (test_fx_fog/map_cpu_matches_sprites). */
static void splat_cpu(struct fx_fog_state *fg, int n, float h, float R, float amp)
{
    const int S = fg->size;
    float *m = fg->map, scale = (float)S / (2 * h), rad = R * scale, inv = 1 / rad;
    memset(m, 0, (size_t)S * (size_t)S * sizeof *m);
    for (int k = 0; k < n; k++) {
        const float *q = fg->inst + 3 * (size_t)k;
        float cx = (q[0] + h) * scale, cz = (q[1] + h) * scale, w = q[2] * amp;
        /* the texels whose centres lie within the sprite's square */
        int i0 = (int)ceilf(cx - rad - 0.5f), i1 = (int)floorf(cx + rad - 0.5f);
        int j0 = (int)ceilf(cz - rad - 0.5f), j1 = (int)floorf(cz + rad - 0.5f);
        i0 = i0 < 0 ? 0 : i0, j0 = j0 < 0 ? 0 : j0, i1 = i1 > S - 1 ? S - 1 : i1, j1 = j1 > S - 1 ? S - 1 : j1;
        for (int j = j0; j <= j1; j++) {
            float dz = ((float)j + 0.5f - cz) * inv, dz2 = dz * dz, *row = m + (size_t)j * S;
            if (dz2 >= 1)
                continue;
            /* this row's chord of the disc: t > 0 inside it (a texel its
             * rounding takes in or leaves out gets t^2 ~ 1e-12: nothing) */
            float half_w = rad * sqrtf(1 - dz2);
            int a = (int)ceilf(cx - half_w - 0.5f), b = (int)floorf(cx + half_w - 0.5f);
            a = a < i0 ? i0 : a, b = b > i1 ? i1 : b;
            float room = 1 - dz2, dx = ((float)a + 0.5f - cx) * inv;
            for (int i = a; i <= b; i++, dx += inv) {
                float t = room - dx * dx;
                row[i] += w * t * t;
            }
        }
    }
    gl.BindTexture(GL_TEXTURE_2D, fg->tex);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, S, S, GL_RED, GL_FLOAT, m);
    gl.BindTexture(GL_TEXTURE_2D, 0);
}

/* Step 2 on the GL: the n sprites of fg->inst as instanced quads, blended
 * into the cleared map (fog_splat.vert/.frag). */
static void splat_gl(struct fx_fog_state *fg, int n, float h, float R, float amp)
{
    gl.BindFramebuffer(GL_FRAMEBUFFER, fg->fbo);
    gl.Viewport(0, 0, fg->size, fg->size);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    gl.ClearColor(0, 0, 0, 0);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    if (n == 0)
        return;
    gl.Enable(GL_BLEND);
    gl.BlendFunc(GL_ONE, GL_ONE);
    gl.UseProgram(fg->prog);
    gl.Uniform1f(r_loc(fg->prog, "u_half"), h);
    gl.Uniform1f(r_loc(fg->prog, "u_radius"), R);
    gl.Uniform1f(r_loc(fg->prog, "u_amp"), amp);
    gl.BindVertexArray(fg->vao);
    gl.BindBuffer(GL_ARRAY_BUFFER, fg->vbo);
    gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(fg->cap * 3 * sizeof(float)), NULL, GL_STREAM_DRAW); /* orphan */
    gl.BufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)((size_t)n * 3 * sizeof(float)), fg->inst);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
    gl.DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, n);
    gl.Disable(GL_BLEND);
}

/* Step 2: the particles as sprites into the map, on the GL or (fg->cpu)
 * in C; returns the sprites drawn. */
static int draw_map(r_game *r, struct fx_fog_state *fg)
{
    const fx_fog_sim *s = &fg->sim;
    float h = s->d.half, R = fminf(fg->look.sprite_m, s->d.half / 2), sum = 0;
    int n = 0;
    for (int i = 0; i < s->n; i++) {
        const fx_fog_particle *p = &s->p[i];
        float w = fx_fog_sim_weight(s, p);
        if (!(w > 0 && w < 1e6f && fabsf(p->x) < 2 * h && fabsf(p->z) < 2 * h)) /* also NaN, Inf: never */
            continue;
        sum += w;
        /* the copies on the far side of each edge the sprite crosses */
        float ox[2] = {0, p->x < -h + R ? 2 * h : p->x > h - R ? -2 * h : 0};
        float oz[2] = {0, p->z < -h + R ? 2 * h : p->z > h - R ? -2 * h : 0};
        for (int a = 0; a < (ox[1] != 0 ? 2 : 1); a++)
            for (int b = 0; b < (oz[1] != 0 ? 2 : 1); b++) {
                float *q = fg->inst + 3 * (size_t)n++;
                q[0] = p->x + ox[a], q[1] = p->z + oz[b], q[2] = w;
            }
    }
    /* the mean over the map is 1: each sprite holds pi R^2 / 3 x amp x w.
     * No texel can exceed amp x sum (the kernel peaks at 1, a particle's
     * copies are 2 half apart): kept under fp16's range, the blend never
     * makes an Inf however the mist piles up */
    float amp = sum > 0 ? 4 * h * h * 3 / (3.14159265f * R * R * sum) : 0;
    if (amp * sum > 60000.0f)
        amp = 60000.0f / sum;
    if (fg->cpu)
        splat_cpu(fg, n, h, R, amp);
    else
        splat_gl(fg, n, h, R, amp);
    /* step 3: a blur, wrapping like the map */
    if (fg->look.blur) {
        r_blur_into(r, fg->tmp_fbo, fg->tex, 0, fg->size, fg->size, 1, 0);
        r_blur_into(r, fg->fbo, fg->tmp_tex, 0, fg->size, fg->size, 0, 1);
    }
    return n;
}

/* ---- the pass ---- */

static bool need_fog(void *u)
{
    r_game *r = u;
    return r_fx_stage(r)->fog && FOG(r);
}

/* Both fighters' bone end points now and a tick ago (frame.caps*). */
static int limb_points(const frame *f, float cur[][3], float prev[][3])
{
    int n = 0;
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < G_BONES; k++, n += 2) {
            const r_fx_capsule *c = &f->caps[i][k], *p = &f->caps_prev[i][k];
            memcpy(cur[n], c->a, sizeof cur[n]), memcpy(prev[n], p->a, sizeof prev[n]);
            memcpy(cur[n + 1], c->b, sizeof cur[n]), memcpy(prev[n + 1], p->b, sizeof prev[n]);
        }
    return n;
}

/* Step 1, the fog's history: once per frame drawn, or per tick advanced
 * (fog_advance). */
static void sim_follow(r_game *r)
{
    struct fx_fog_state *fg = FOG(r);
    const frame *f = r_fx_frame(r);
    /* step 1: the mist follows the game's ticks, never the frame rate */
    float cur[4 * G_BONES][3], prev[4 * G_BONES][3];
    int n = limb_points(f, cur, prev);
    if (f->reset) { /* a new sequence: the seeded mist, stirred by this tick's motion */
        fx_fog_sim_reset(&fg->sim, f->cur->tick);
        fx_fog_sim_stir(&fg->sim, cur, prev, n);
    } else
        for (int k = 0; k < f->steps; k++) { /* the last tick's motion stands for each tick missed */
            fx_fog_sim_stir(&fg->sim, cur, prev, n);
            fx_fog_sim_step(&fg->sim);
        }
}

static void run_fog_map(void *u)
{
    r_game *r = u;
    sim_follow(r);
    draw_map(r, FOG(r));
}

static void fog_advance(r_game *r)
{
    if (need_fog(r))
        sim_follow(r);
}

static int fog_warmup(r_game *r)
{
    return need_fog(r) ? R_FX_FROM_START : R_FX_STATELESS;
}

static const r_pass fog_passes[] = {
    {"fog_map", 0, RES_FOGMAP, need_fog, run_fog_map, 0},
};

/* ---- the scene's side ---- */

static float half_clamp(float v)
{
    return v > 0 ? (v < R_HALF_MAX ? v : R_HALF_MAX) : 0.0f; /* NaN fails v > 0 */
}

/* The scene's programs (fog_common.glsl): u_fog_on and the map when the
 * fog_map pass ran this frame, and the fog's light. */
static void fog_bind(r_game *r, GLuint p, int unit, int what)
{
    (void)what;
    struct fx_fog_state *fg = FOG(r);
    bool on = fg && r_fx_stage(r)->fog && r_ran(r_fx_frame(r), r, "fog_map");
    gl.UseProgram(p);
    gl.Uniform1i(r_loc(p, "u_fog_on"), on);
    r_bind_tex(p, "u_fog_map", unit, GL_TEXTURE_2D, on ? fg->tex : 0);
    if (!on)
        return;
    const fog_look *lk = &fg->look;
    const r_stage *st = r_fx_stage(r);
    const frame *f = r_fx_frame(r);
    gl.Uniform3f(r_loc(p, "u_fog_eye"), f->eye.x, f->eye.y, f->eye.z);
    gl.Uniform1f(r_loc(p, "u_fog_half"), fg->sim.d.half);
    gl.Uniform1f(r_loc(p, "u_fog_density"), lk->density);
    gl.Uniform1f(r_loc(p, "u_fog_base"), lk->base);
    gl.Uniform1f(r_loc(p, "u_fog_height"), lk->height);
    /* the fog's light, consistent with the stage's: the sky at the horizon
     * (so distant fog meets the sky there), lightning as the sky gets it,
     * and the key light (the sun, else the painted key) scattered forward */
    static const float flash[3] = {1.5f, 1.6f, 2.0f}; /* sky.frag's */
    float c[3], e[3], dir[3] = {0, 1, 0};
    const r_paint_light *key = &st->key;
    double omega = 2 * 3.14159265358979 * (1 - cos(key->size_deg * 3.14159265358979 / 180));
    for (int k = 0; k < 3; k++) {
        c[k] = half_clamp(st->sky_horizon[k] * lk->brightness + f->flash * flash[k] * lk->albedo);
        if (st->sun) /* its irradiance */
            e[k] = half_clamp(st->sun_intensity * st->sun_color[k] * lk->albedo);
        else /* a painted disc of radiance intensity x (1 - smoothstep): 0.3 of it over its solid angle */
            e[k] = half_clamp((float)(0.3 * key->intensity * key->color[k] * omega) * lk->albedo);
    }
    const float *d = st->sun ? st->sun_dir : key->dir;
    float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (len > 1e-6f && isfinite(len))
        dir[0] = d[0] / len, dir[1] = d[1] / len, dir[2] = d[2] / len;
    gl.Uniform3fv(r_loc(p, "u_fog_color"), 1, c);
    gl.Uniform3fv(r_loc(p, "u_fog_sun"), 1, e);
    gl.Uniform3fv(r_loc(p, "u_fog_sun_dir"), 1, dir);
    float g = lk->g;
    gl.Uniform3f(r_loc(p, "u_fog_phase"), (1 - g * g) / (4 * 3.14159265f), 1 + g * g, 2 * g);
}

/* ---- the module ---- */

static void fog_destroy(r_game *r)
{
    struct fx_fog_state *fg = FOG(r);
    if (!fg)
        return;
    free_map(fg);
    if (fg->vao)
        gl.DeleteVertexArrays(1, &fg->vao);
    if (fg->vbo)
        gl.DeleteBuffers(1, &fg->vbo);
    if (fg->prog)
        gl.DeleteProgram(fg->prog);
    fx_fog_sim_free(&fg->sim);
    free(fg->inst);
    free(fg);
    r_fx_set_state(r, &fx_fog_module, NULL);
}

static bool fog_create(r_game *r, rs_err *err)
{
    struct fx_fog_state *fg = calloc(1, sizeof *fg);
    if (!fg)
        return rs_fail(err, R_ERR_NOMEM, "fog: out of memory");
    r_fx_set_state(r, &fx_fog_module, fg);
    fg->look = default_look;
    fg->cpu = rgl_is_software();
    if (!fx_fog_sim_init(&fg->sim, NULL)) {
        fog_destroy(r);
        return rs_fail(err, R_ERR_NOMEM, "fog: out of memory for the mist");
    }
    fg->cap = 4 * fg->sim.n; /* at most four copies each (a corner) */
    if (!(fg->inst = malloc((size_t)fg->cap * 3 * sizeof(float)))) {
        fog_destroy(r);
        return rs_fail(err, R_ERR_NOMEM, "fog: out of memory");
    }
    if (!(fg->prog = r_program(&(r_program_desc){.vs = "fog_splat.vert", .fs = "fog_splat.frag"}, err))) {
        fog_destroy(r);
        return false;
    }
    gl.GenVertexArrays(1, &fg->vao);
    gl.BindVertexArray(fg->vao);
    gl.GenBuffers(1, &fg->vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, fg->vbo);
    gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)((size_t)fg->cap * 3 * sizeof(float)), NULL, GL_STREAM_DRAW);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), (void *)0);
    gl.VertexAttribDivisor(0, 1); /* one particle per instance */
    gl.BindVertexArray(0);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
    /* the quality knob (r_quality.fog_size, range checked at create) or the look's */
    if (!make_map(fg, r_fx_quality(r)->fog_size > 0 ? r_fx_quality(r)->fog_size : fg->look.map_size, err)) {
        fog_destroy(r);
        return false;
    }
    RGL_CHECK("fog create");
    return true;
}

/* History: the mist particles, restarted (seeded by the tick) on a reset,
 * then stirred and stepped once per tick: every tick since the reset
 * counts.  fog_advance is the pass's step 1 without the map. */
static const char *fog_define(const r_game *r)
{
    return r_fx_stage(r)->fog ? "FX_FOG" : NULL;
}

const r_fx_module fx_fog_module = {
    .name = "fog", .create = fog_create, .destroy = fog_destroy,
    .pass = {fog_passes}, .npass = {(int)(sizeof fog_passes / sizeof fog_passes[0])},
    .res = {{RES_FOGMAP, "fog map", false}}, .scene_reads = RES_FOGMAP,
    .units = 1, .bind = fog_bind, .scene_define = fog_define,
    .warmup = fog_warmup, .advance = fog_advance,
};

/* ---- tests and bench accuracy ---- */

fx_fog_sim *fx_fog_get_sim(r_game *r)
{
    return FOG(r) ? &FOG(r)->sim : NULL;
}

bool fx_fog_set_cpu(r_game *r, bool cpu)
{
    struct fx_fog_state *fg = FOG(r);
    if (fg)
        fg->cpu = cpu;
    return fg != NULL;
}

bool fx_fog_read_map(r_game *r, float *out, int *size, float *half)
{
    struct fx_fog_state *fg = FOG(r);
    if (!fg || !fg->tex)
        return false;
    if (size)
        *size = fg->size;
    if (half)
        *half = fg->sim.d.half;
    if (out) {
        gl.BindTexture(GL_TEXTURE_2D, fg->tex);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
        gl.GetTexImage(GL_TEXTURE_2D, 0, GL_RED, GL_FLOAT, out);
        gl.BindTexture(GL_TEXTURE_2D, 0);
    }
    return true;
}

/* CPU bilinear fetch of a size x size map at (x, z), wrapping as GL_REPEAT
 * with GL_LINEAR does (texel centres at (i + 0.5) / size). */
static double map_at(const float *m, int n, float half, double x, double z)
{
    double u = (x / (2.0 * half) + 0.5) * n - 0.5, v = (z / (2.0 * half) + 0.5) * n - 0.5;
    double fu = floor(u), fv = floor(v), tu = u - fu, tv = v - fv;
    int i0 = (((int)fu % n) + n) % n, j0 = (((int)fv % n) + n) % n, i1 = (i0 + 1) % n, j1 = (j0 + 1) % n;
    double lo = m[(size_t)j0 * n + i0] * (1 - tu) + m[(size_t)j0 * n + i1] * tu;
    double hi = m[(size_t)j1 * n + i0] * (1 - tu) + m[(size_t)j1 * n + i1] * tu;
    return lo * (1 - tv) + hi * tv;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#define ACC_REF 1024 /* the reference map's edge */
#define ACC_RUNS 31  /* timed draws per size (the median is reported) */
#define ACC_GRID 61  /* sample points per edge over the ring, |x|, |z| <= 6 m */

/* One map size: the median ms of a fog_map draw (glFinish-timed) and the
 * rms and largest density error at the sample points against ref. */
static void acc_row(r_game *r, struct fx_fog_state *fg, const float *ref, float *map, double out[3])
{
    double ms[ACC_RUNS], se = 0, worst = 0;
    float half = fg->sim.d.half;
    draw_map(r, fg); /* warm: the first draw at a size pays for the allocation */
    for (int k = 0; k < ACC_RUNS; k++) {
        gl.Finish();
        double t0 = rs_now();
        draw_map(r, fg);
        gl.Finish();
        ms[k] = (rs_now() - t0) * 1e3;
    }
    qsort(ms, ACC_RUNS, sizeof ms[0], by_value);
    fx_fog_read_map(r, map, NULL, NULL);
    for (int j = 0; j < ACC_GRID; j++)
        for (int i = 0; i < ACC_GRID; i++) {
            double x = -6.0 + 12.0 * i / (ACC_GRID - 1), z = -6.0 + 12.0 * j / (ACC_GRID - 1);
            double d = map_at(map, fg->size, half, x, z) - map_at(ref, ACC_REF, half, x, z);
            se += d * d;
            worst = fmax(worst, fabs(d));
        }
    out[0] = ms[ACC_RUNS / 2], out[1] = sqrt(se / (ACC_GRID * ACC_GRID)), out[2] = worst;
}

bool fx_fog_accuracy_rows(FILE *out, rs_err *err)
{
    static const int sizes[] = {32, 64, 128, 256, 512};
    r_game *r = r_game_create(err);
    float *ref = malloc((size_t)ACC_REF * ACC_REF * sizeof *ref), *map = malloc((size_t)512 * 512 * sizeof *map);
    double sim_ms[ACC_RUNS];
    bool ok = false;
    if (!r || !ref || !map) {
        if (r)
            rs_fail(err, R_ERR_NOMEM, "fog accuracy: out of memory");
        goto done;
    }
    struct fx_fog_state *fg = FOG(r);
    /* a mist that has drifted for 5 s, with a kick's worth of local wind:
     * a limb point sweeping through the middle at 6 m/s */
    fx_fog_sim_reset(&fg->sim, 0);
    for (int t = 0; t < 300; t++) {
        float cur[1][3] = {{-3.0f + 0.1f * (float)(t % 60), 1.0f, 0}}, prev[1][3] = {{cur[0][0] - 0.1f, 1.0f, 0}};
        double t0 = rs_now();
        fx_fog_sim_stir(&fg->sim, cur, prev, 1);
        fx_fog_sim_step(&fg->sim);
        if (t >= 300 - ACC_RUNS)
            sim_ms[t - (300 - ACC_RUNS)] = (rs_now() - t0) * 1e3;
    }
    qsort(sim_ms, ACC_RUNS, sizeof sim_ms[0], by_value);
    /* the reference: the finest map, unblurred */
    fg->look.blur = false;
    if (!make_map(fg, ACC_REF, err))
        goto done;
    draw_map(r, fg);
    fx_fog_read_map(r, ref, NULL, NULL);
    fprintf(out, "\nFog map (%d particles, sprite radius %.2f m, map over +-%.0f m): size vs a %dx%d map, density at\n"
                 "%dx%d points over the ring (|x|, |z| <= 6 m) in units of the mean density (1), without and with\n"
                 "the optional blur; ms per fog_map draw (sprites, and the blur), glFinish-timed, median of %d;\n"
                 "the simulation's tick: %.3f ms (CPU, median; once per game tick, whatever the size)\n",
            fg->sim.n, fg->look.sprite_m, fg->sim.d.half, ACC_REF, ACC_REF, ACC_GRID, ACC_GRID, ACC_RUNS,
            sim_ms[ACC_RUNS / 2]);
    fprintf(out, "%8s %10s %10s %10s %12s %12s %12s\n", "size", "ms", "rms err", "max err", "blur ms", "blur rms",
            "blur max");
    for (size_t z = 0; z < sizeof sizes / sizeof sizes[0]; z++) {
        double plain[3], blurred[3];
        if (!make_map(fg, sizes[z], err))
            goto done;
        fg->look.blur = false;
        acc_row(r, fg, ref, map, plain);
        fg->look.blur = true;
        acc_row(r, fg, ref, map, blurred);
        fprintf(out, "%8d %10.3f %10.4f %10.4f %12.3f %12.4f %12.4f%s\n", sizes[z], plain[0], plain[1], plain[2],
                blurred[0], blurred[1], blurred[2],
                sizes[z] == default_look.map_size ? (default_look.blur ? "   <- default (blurred)" : "   <- default")
                                                   : "");
    }
    ok = true;
    RGL_CHECK("fog accuracy");
done:
    free(ref);
    free(map);
    r_game_destroy(r);
    return ok;
}
