/* The CPU opponent: reads the game state, presses the panel like a player.
 *
 * Deterministic: its only randomness is its own RNG, seeded by the caller,
 * so `record --ai` with the same seed records the same match.  It is an
 * input device, not part of the game: the replay stores what it pressed,
 * so replaying never runs the AI again. */
#ifndef G_AI_H
#define G_AI_H

#include "g_game.h"

typedef struct g_ai {
    uint64_t rng;
    int player;  /* 0 or 1 */
    int level;   /* 0 (easy) .. 3 (hard): how often it guards and punishes */
    /* the plan being executed: inputs with how long to hold each */
    g_input plan[8];
    int plan_ticks[8];
    int nplan, at;
} g_ai;

void g_ai_init(g_ai *ai, int player, int level, uint64_t seed);
g_input g_ai_input(g_ai *ai, const g_state *st);

#endif
