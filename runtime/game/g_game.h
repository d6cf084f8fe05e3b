/* The game: a deterministic two-fighter simulation stepped at 60 Hz.
 *
 * Contract (the loop, replay, capture and tests all use only this):
 *   g_init(&st, stage, seed)            a new match
 *   g_step(&st, in[2], &events)         one tick: inputs -> new state
 *   g_hash(&st)                         64-bit hash of the canonical state
 * All state lives in g_state: a plain struct with no pointers, no floating
 * point and the RNG inside, so copying it saves the game (GGPO-style
 * rollback, tests) and the same inputs always give the same hashes.
 * Nothing here reads a clock: time is the tick counter. */
#ifndef G_GAME_H
#define G_GAME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "g_fixed.h"
#include "g_skel.h"

#define G_HZ 60

/* The game's rules version: bumped whenever a change to the simulation can
 * change the state hash of any replay (moves, physics, AI, stages, the
 * serialisation).  Replays record it (docs/replay-format.md), so a replay
 * of other rules is told apart from a damaged or desynced one;
 * tests/test_replay.c pins a short match's hash to it and fails when the
 * rules change and this number does not. */
#define G_GAME_VERSION 1

/* One player's arcade panel for one tick: 8-way stick + 3 buttons + start.
 * A stick with both up and down (or left and right) is not a valid input:
 * input devices resolve it to neutral on that axis, the replay reader
 * rejects it. */
enum {
    G_IN_UP = 1 << 0,
    G_IN_DOWN = 1 << 1,
    G_IN_LEFT = 1 << 2,
    G_IN_RIGHT = 1 << 3,
    G_IN_PUNCH = 1 << 4,
    G_IN_KICK = 1 << 5,
    G_IN_GUARD = 1 << 6,
    G_IN_START = 1 << 7,
};
typedef uint8_t g_input;

static inline bool g_input_valid(g_input in)
{
    return (in & (G_IN_UP | G_IN_DOWN)) != (G_IN_UP | G_IN_DOWN) &&
           (in & (G_IN_LEFT | G_IN_RIGHT)) != (G_IN_LEFT | G_IN_RIGHT);
}

/* Resolves opposite directions to neutral (what a real stick cannot do). */
static inline g_input g_input_clean(g_input in)
{
    if ((in & (G_IN_UP | G_IN_DOWN)) == (G_IN_UP | G_IN_DOWN))
        in &= (g_input)~(G_IN_UP | G_IN_DOWN);
    if ((in & (G_IN_LEFT | G_IN_RIGHT)) == (G_IN_LEFT | G_IN_RIGHT))
        in &= (g_input)~(G_IN_LEFT | G_IN_RIGHT);
    return in;
}

/* Rules (see docs/game.md) */
#define G_MAX_HEALTH 200
#define G_ROUND_TICKS (45 * G_HZ)
#define G_ROUNDS_TO_WIN 2
#define G_MAX_ROUNDS 5
#define G_INTRO_TICKS 90      /* "ROUND n" 0..59, "FIGHT" 60..89; no control */
#define G_ROUND_END_TICKS 150 /* KO / ring-out / time announcement */
#define G_MATCH_END_TICKS 240 /* winner announcement; then the next match */

typedef enum g_phase { G_PHASE_INTRO, G_PHASE_FIGHT, G_PHASE_ROUND_END, G_PHASE_MATCH_END } g_phase;
typedef enum g_result { G_RES_NONE, G_RES_KO, G_RES_RING_OUT, G_RES_TIME, G_RES_DRAW } g_result;

typedef enum g_move_id {
    G_MV_IDLE, G_MV_WALK_F, G_MV_WALK_B, G_MV_CROUCH, G_MV_JUMP,
    G_MV_PUNCH, G_MV_KICK, G_MV_LOW_KICK, G_MV_CROUCH_PUNCH, G_MV_JUMP_KICK, G_MV_SPECIAL,
    G_MV_GUARD, G_MV_CROUCH_GUARD, G_MV_HITSTUN, G_MV_BLOCKSTUN, G_MV_KNOCKDOWN, G_MV_GETUP,
    G_MV_KO, G_MV_WIN,
    G_MV_COUNT
} g_move_id;

#define G_HIST 8 /* stick directions remembered for motion inputs */

typedef struct g_fighter {
    fx x, y, vx, vy;
    int32_t facing;      /* +1: faces +x */
    int32_t move;        /* g_move_id */
    int32_t frame;       /* ticks into the move */
    int32_t health;
    int32_t stun;        /* hit/block stun ticks left */
    int32_t hit_done;    /* this attack already connected */
    int32_t rounds_won;
    int32_t prev_input;
    int32_t hits, specials; /* statistics for the match */
    /* motion input history: direction (numpad, relative to facing) and age */
    int32_t hist_dir[G_HIST];
    int32_t hist_age[G_HIST];
} g_fighter;

/* A destruction hole (docs/effects.md, "Destruction holes"): a crater in the
 * ring floor, centred at (x, z) on the ring top, `r` the radius of the sphere
 * that cuts it (centred 0.4 r above the floor: 0.6 r deep, 0.92 r wide at the
 * top). Holes are decoration: the fighters still stand on a flat floor. */
#define G_MAX_HOLES 30
typedef struct g_hole {
    fx x, z, r;
    int32_t id; /* order of creation in the match, from 1 */
} g_hole;

typedef struct g_state {
    uint64_t tick;
    uint64_t rng;
    /* FNV-1a of every input so far: the state hash then certifies the input
     * history too, so an input that changed nothing on screen (a button in
     * the round intro) still shows at the next checkpoint */
    uint64_t input_digest;
    int32_t stage;
    int32_t phase;        /* g_phase */
    int32_t phase_ticks;
    int32_t round;        /* 1-based */
    int32_t round_timer;  /* ticks left */
    int32_t round_result; /* g_result of the last finished round */
    int32_t round_winner; /* 0 none/draw, 1 or 2 */
    int32_t match_winner; /* of the last finished match: -1 none yet, 0 draw, 1, 2 */
    int32_t matches;      /* finished matches */
    int32_t flash_in;     /* ticks to the next lightning (storm stages), 0 = none */
    int32_t flash;        /* ticks of flash left */
    g_fighter f[2];
    /* destructible stages only (else always empty, and not in the hash):
     * craters that heavy hits leave in the ring floor, for the match */
    int32_t nholes;
    int32_t hole_seq;     /* holes made so far in the match */
    g_hole holes[G_MAX_HOLES];
} g_state;

typedef enum g_event_type {
    G_EV_ROUND, G_EV_FIGHT, G_EV_HIT, G_EV_BLOCK, G_EV_SPECIAL, G_EV_KNOCKDOWN, G_EV_KO, G_EV_RING_OUT,
    G_EV_TIME_UP, G_EV_ROUND_WIN, G_EV_DRAW, G_EV_MATCH_WIN, G_EV_LIGHTNING,
    G_EV_COUNT
} g_event_type;

typedef struct g_event {
    int type;   /* g_event_type */
    int player; /* 1 or 2, 0 when not about one player */
    int value;  /* damage, round number, ... */
} g_event;

#define G_MAX_EVENTS 16
typedef struct g_events {
    int n;
    g_event ev[G_MAX_EVENTS];
} g_events;

typedef struct g_stage_def {
    const char *name;
    fx ring_half;  /* ring edge at x = +-ring_half */
    bool storm;    /* random lightning flashes */
    bool destructible; /* heavy hits leave holes in the ring floor */
} g_stage_def;

#define G_STAGES 8
extern const g_stage_def g_stages[G_STAGES];

void g_init(g_state *st, int stage, uint64_t seed);
/* One tick.  events may be NULL.  Invalid inputs are cleaned, not trusted. */
void g_step(g_state *st, const g_input in[2], g_events *events);

/* Canonical little-endian serialisation (no padding, fixed field order);
 * returns the size; buf needs G_STATE_BYTES. */
#define G_STATE_BYTES 1024
size_t g_serialize(const g_state *st, uint8_t *buf);
uint64_t g_hash(const g_state *st);

/* Pose of fighter i right now, and its world capsules (for hits, rendering,
 * effects).  Pure functions of the state. */
void g_fighter_pose(const g_state *st, int i, g_pose *pose);
void g_fighter_capsules(const g_state *st, int i, g_capsule out[G_BONES]);

const char *g_move_name(int move);
const char *g_event_name(int type);

/* Destruction holes (g_holes.c).  g_hole_add places a crater of radius r
 * near (x, z): the first of a few candidate spots across the ring that
 * overlaps no hole and lies inside the ring; none: false, nothing changes.
 * With G_MAX_HOLES already there, one goes first: the oldest that the
 * camera cannot see (g_hole_in_view), else the oldest. */
bool g_hole_add(g_state *st, fx x, fx z, fx r);
/* Whether the crater lies in the game camera's view (r_game_camera's
 * framing, at the cabinet's 16:9), from the state alone. */
bool g_hole_in_view(const g_state *st, const g_hole *h);
bool g_holes_overlap(const g_hole *a, const g_hole *b);

/* 64-bit FNV-1a, used for the state hash. */
uint64_t g_fnv1a(uint64_t h, const void *data, size_t n);
#define G_FNV_OFFSET 0xcbf29ce484222325ull

#endif
