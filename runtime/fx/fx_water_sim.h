/* Water (docs/effects.md, "Water"): the wave automaton's CPU reference and its
 * parameters.  Plain C, no GL: shaders/water_sim.frag and water_splat.*
 * run the same formulas on the GPU (fx_water.c), and
 * tests/test_fx_water.c holds the two to each other.
 *
 * The grid is n x n cells of two floats, interleaved like the RG channels
 * of the simulation texture: [0] = height h (metres above the rest level),
 * [1] = the height one step earlier.  Cell (i, j) is texel (i, j): i along
 * x, j along z, its centre at (i + 0.5, j + 0.5) in grid units, and the
 * grid spans the ring's top face, x, z in -size/2 .. +size/2.
 *
 * One step is the discrete 2D wave equation (leapfrog in time, 5-point
 * Laplacian in space), damped as a whole:
 *     h' = damping * ((2 h - h_prev) + C^2 * (hL + hR + hD + hU - 4 h))
 * then h' is clamped to +-h_max (NaN -> 0) and the pair becomes (h', h).
 *
 * Heights under R_WATER_H_TINY are zero, wherever they are read or
 * written (the splat's bump too).  Without that a dying ripple reaches the
 * denormal range, where the answer depends on the thread that computes it:
 * llvmpipe's threads flush denormals to zero, not every path does, and a
 * GPU usually flushes them.  With every stored height 0 or above 1e-20 m,
 * no sum, difference or product in a step comes near that range, so a
 * step gives the same bits on any of them (and a render started mid-way,
 * whose warm-up runs the steps without drawing, matches a full render).
 * C = c dt / dx is the Courant number.  The scheme is stable for
 * C <= 1/sqrt(2) (the CFL limit in 2D; at the limit the checkerboard mode
 * only just does not grow), and damping the whole update keeps that limit
 * for any damping in (0, 1], which damping only the velocity would not.
 * The edges reflect (a missing neighbour reads the edge cell itself).
 *
 * Waves come from splats: a cosine bump added to h (not to h_prev: an
 * impulse of vertical velocity) after each step, one per contact of a bone
 * capsule with the surface, its height proportional to the speed of that
 * part of the bone (no motion, no wave). */
#ifndef R_FX_WATER_SIM_H
#define R_FX_WATER_SIM_H

#include <math.h>
#include <stdbool.h>
#include <stdio.h>

#define R_WATER_N 256              /* the game's grid: 256 x 256 RGBA32F (the original) */
#define R_WATER_LEVEL 0.12f        /* the surface at rest, metres over the ring floor */
#define R_WATER_CFL 0.70710678f    /* 1/sqrt(2) */
#define R_WATER_COURANT_MAX 0.706f /* the cap, just below the CFL limit (margin 1.0016) */
#define R_WATER_MAX_STEPS 8        /* steps one frame runs at most (more ticks: the rest are dropped) */
#define R_WATER_H_TINY 1e-20f      /* |height| below this is 0 (water_common.glsl WATER_H_TINY) */

typedef struct fx_water_sim_params {
    /* zero (or NaN) means the default; fx_water_sim_params_fix applies them */
    float courant;  /* C = c dt / dx: 0.58, the shallow-water speed sqrt(g * 0.12 m) = 1.085 m/s
                       at dt = 1/60 s, dx = 8 m / 256; capped at R_WATER_COURANT_MAX */
    float damping;  /* amplitude kept per step: 0.985 (a ripple fades to 1/e in about 1.1 s);
                       0.5 .. 1 */
    float h_max;    /* |height| clamp, m: 0.08 (below the 0.12 m depth) */
    float gain;     /* splat height, m per m/s of contact speed: 0.0015 */
    float amp_max;  /* |splat height| cap, m: 0.012 */
    float splash;   /* splat radius / capsule radius: 1.5 */
    float size;     /* metres the grid spans: 8 (2 x the shallows ring_half) */
} fx_water_sim_params;

/* Fills zeros and NaNs with the defaults above and clamps every value into
 * its range (courant through fx_water_sim_courant_clamp). */
void fx_water_sim_params_fix(fx_water_sim_params *p);
/* The Courant number a step may use: (0, R_WATER_COURANT_MAX]; NaN or <= 0
 * gives the default. */
float fx_water_sim_courant_clamp(float c);

/* One step of the n x n grid, src -> dst (2 n^2 floats each, not
 * overlapping), with p fixed (fx_water_sim_params_fix) first. */
void fx_water_sim_step(const fx_water_sim_params *p, int n, const float *src, float *dst);
/* The same without any check of C or damping: for the stability test and
 * the accuracy table, which show what the cap prevents. */
void fx_water_sim_step_raw(float courant, float damping, float h_max, int n, const float *src, float *dst);

/* A splat in grid units: centre (texel k's centre at k + 0.5), radius in
 * cells, height added at the centre (m). */
typedef struct fx_water_sim_splat {
    float x, y, radius, amp;
} fx_water_sim_splat;

/* The splat for a contact at world (wx, wz) of a capsule of radius
 * cap_radius reaching `depth` under the surface, moving at `speed` m/s:
 * height -gain * speed * immersion (a dent; immersion = depth / 2 radius,
 * at most 1), capped at amp_max, radius splash * cap_radius (1..16 cells).
 * False when the centre is off the grid or the height is 0 or not finite. */
bool fx_water_sim_splat_for(const fx_water_sim_params *p, int n, float wx, float wz, float cap_radius, float depth, float speed,
                       fx_water_sim_splat *out);
/* A height under R_WATER_H_TINY is 0 (above: denormals). */
static inline float fx_water_sim_flush(float v)
{
    return fabsf(v) < R_WATER_H_TINY ? 0.0f : v;
}
/* A simulated height made safe, as water_common.glsl's water_height: NaN
 * -> 0, under R_WATER_H_TINY -> 0, clamped to +-h_max.  Selects, not
 * branches, so a vectorising build can vectorise the loops that use it. */
static inline float fx_water_sim_height(float v, float h_max)
{
    v = fx_water_sim_flush(v);
    v = v < -h_max ? -h_max : v;
    v = v > h_max ? h_max : v;
    return v == v ? v : 0.0f;
}
/* Adds the splat's bump to h: amp * (1 + cos(pi d / radius)) / 2 at the
 * cells whose centres are within radius of its centre. */
void fx_water_sim_add_splat(int n, float *grid, const fx_water_sim_splat *s);
/* The bump's weight at distance d (the shader's formula). */
float fx_water_sim_splat_weight(float d, float radius);

/* The discrete energy: sum (h - h_prev)^2 + C^2 sum over neighbour pairs
 * (h_a - h_b)^2 (double sums; Inf when the grid holds Inf or NaN). */
double fx_water_sim_energy(float courant, int n, const float *grid);

/* A long run with forcing like the game's: two "feet" stepping and
 * sweeping through the water, splatted every step through
 * fx_water_sim_splat_for.  raw: C and damping go to fx_water_sim_step_raw as given
 * (no cap).  e_ref is the energy after ref_steps; e_max the largest over
 * the whole run, sampled every R_WATER_RUN_SAMPLE steps (a damped grid
 * under bounded forcing changes little in that time; the samples halve
 * the run's cost). */
#define R_WATER_RUN_SAMPLE 10
typedef struct fx_water_sim_run {
    double e_ref, e_max, e_last;
    float h_absmax;   /* largest |h| seen */
    bool finite;      /* no NaN or Inf anywhere, ever */
    long steps;
    double ms;        /* wall time of the whole run */
} fx_water_sim_run;
bool fx_water_sim_forced_run(const fx_water_sim_params *p, bool raw, int n, long steps, long ref_steps, fx_water_sim_run *out);

/* `ringside bench accuracy`'s water rows: per Courant number, the
 * stability margin (cap / C), the largest energy over a long forced run
 * against the energy after its first 1000 steps, the worst mode's growth
 * per step (analytic) and the CPU time of a 256 x 256 step.  ~10 s. */
void fx_water_sim_accuracy_rows(FILE *out);

/* ---- the GPU side (fx_water.c), for tests ---- */
struct r_game;
/* The parameters the water passes use (NULL before a water stage loaded). */
const fx_water_sim_params *fx_water_params(struct r_game *r);
/* Runs `steps` steps of the GPU automaton now, injecting the splats after
 * each step as the sim pass does.  Needs a loaded water stage. */
bool fx_water_gpu_steps(struct r_game *r, const fx_water_sim_splat *s, int ns, int steps);
/* The current state, R_WATER_N^2 * 2 floats (height, previous). */
bool fx_water_read(struct r_game *r, float *grid);
/* The automaton and the normal map in C (true: the default on a software
 * rasteriser) or in shaders; the state goes along; was (may be NULL): the
 * way before.  False before a stage with water has loaded. */
bool fx_water_set_cpu(struct r_game *r, bool cpu, bool *was);
/* Replaces the state (tests put NaN and Inf in it). */
bool fx_water_write(struct r_game *r, const float *grid);
/* Splats the sim pass injected per step in the last frame. */
int fx_water_last_splats(struct r_game *r);

#endif
