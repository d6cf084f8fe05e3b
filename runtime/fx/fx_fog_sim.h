/* The fog map's mist (docs/effects.md, "Fog map"), CPU side: particles lying over the
 * stage, moved once per game tick by a global wind plus local wind fields
 * that fast limbs leave behind them.  Pure C, no GL: fx_fog.c draws the
 * particles into the fog map each frame.
 *
 * Space is the top-down (x, z) plane: x along the ring, z towards the
 * camera, metres.  The mist covers the square |x|, |z| <= half and wraps
 * round it (a torus), so the global wind never blows it away; particles
 * also live a few seconds each and are born again at a random place, so
 * the holes and clumps that kicks make fade back into an even mist.
 *
 * Local wind: a grid of velocities over the same square.  A limb point
 * that moved faster than the speed threshold over the last tick pulls the
 * cells within `radius` towards its (horizontal) velocity; every cell
 * decays towards calm with time constant `decay_s`.  A particle moves
 * with the global wind plus `gain` times the grid's velocity where it is.
 *
 * Determinism: the state is a function of the seed, the tick it was reset
 * at and the limb points it was given; the random numbers are a private
 * xorshift stream, the arithmetic is plain float (doubles where a value
 * could overflow) with sqrt, floor and fmod; expf only of a constant.  Two
 * runs give the same bits.
 *
 * Robustness: NaN or infinite inputs (a corrupted state, parameters from
 * a fuzzer) never reach the particles: limb points that are not finite
 * are ignored (so are points outside the square, and jumps faster than
 * cut_speed: a round's reset puts fighters back without a gust of wind),
 * velocities are clamped to max_speed, and a particle that still ends up
 * somewhere odd is born again. */
#ifndef R_FX_FOG_SIM_H
#define R_FX_FOG_SIM_H

#include <stdbool.h>
#include <stdint.h>

#define R_FOG_MAX_PARTICLES 65536
#define R_FOG_MAX_CELLS 256 /* per edge of the local wind grid */

/* Zero (or out of range) means the default, given after each field. */
typedef struct fx_fog_sim_desc {
    int count;             /* particles: 3000 */
    float half;            /* the square's half edge, m: 12 */
    uint32_t seed;         /* 0x6d697374 ("mist") */
    float wind[2];         /* global wind (x, z), m/s: 0.5 0.12 (both 0: the default) */
    bool calm;             /* no global wind at all */
    float speed_threshold; /* m/s a limb point must exceed to stir: 2.5 */
    float radius;          /* m round a fast limb point that it stirs: 0.6 */
    float gain;            /* particle speed per unit of local wind: 0.6 (so a kick's wind carries the mist ~1.5 m) */
    float decay_s;         /* time constant of the local wind, s: 0.5 */
    float max_speed;       /* clamp of any limb or particle speed, m/s: 20 */
    float cut_speed;       /* faster than this a point jumped (a round's reset), it did not move: 40 m/s */
    float cell;            /* local wind grid spacing, m: 0.25 */
    float life_s;          /* mean particle life, s: 12 (each +-1/3 at random) */
    float fade_s;          /* fade in and out at birth and death, s: 1 */
    bool immortal;         /* never reborn (tests: pure wrap-around) */
} fx_fog_sim_desc;

typedef struct fx_fog_particle {
    float x, z;
    float weight;   /* 0.5..1.5, picked at birth */
    float age, life; /* seconds */
} fx_fog_particle;

typedef struct fx_fog_sim {
    fx_fog_sim_desc d;      /* with the defaults applied */
    fx_fog_particle *p;
    int n;
    float (*wind)[2];      /* local wind grid, ncell x ncell, row = z */
    int ncell;
    float cell;            /* the grid's actual spacing (2 half / ncell) */
    float decay;           /* per tick factor, exp(-dt / decay_s) */
    uint32_t rng;
    uint64_t tick;         /* ticks simulated since the reset, plus the reset tick */
    int stirred;           /* limb points that stirred in the last fx_fog_sim_stir */
    bool active;           /* some local wind is blowing (else the grid is all zero) */
} fx_fog_sim;

/* Fills in the defaults and clamps every field into its range. */
void fx_fog_sim_defaults(fx_fog_sim_desc *d);

/* Allocates and resets (tick 0).  false when out of memory. */
bool fx_fog_sim_init(fx_fog_sim *s, const fx_fog_sim_desc *d);
void fx_fog_sim_free(fx_fog_sim *s);

/* Back to the seeded layout, calm local wind.  The layout is shifted by
 * the global wind over `tick` ticks, so a replay seeked to a tick finds
 * the mist drifted about as far as it would have drifted since tick 0. */
void fx_fog_sim_reset(fx_fog_sim *s, uint64_t tick);

/* Local wind from limb points: cur[i] is a point of a bone now, prev[i]
 * the same point one tick earlier (x, y, z metres; speed = distance x
 * G_HZ).  Returns how many stirred. */
int fx_fog_sim_stir(fx_fog_sim *s, const float (*cur)[3], const float (*prev)[3], int n);

/* One game tick (1 / G_HZ s): local wind decays, particles move, age,
 * wrap round the square and are born again when their life ends. */
void fx_fog_sim_step(fx_fog_sim *s);

/* A particle's weight now: its birth weight times the fade envelope. */
float fx_fog_sim_weight(const fx_fog_sim *s, const fx_fog_particle *p);

/* The local wind (m/s) at (x, z), bilinear and wrapping like the mist. */
void fx_fog_sim_wind_at(const fx_fog_sim *s, float x, float z, float out[2]);

#endif
