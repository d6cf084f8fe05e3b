/* Private to the game module: move data and helpers shared by g_*.c. */
#ifndef G_LOCAL_H
#define G_LOCAL_H

#include "g_game.h"

enum g_level { G_HIGH, G_MID, G_LOW };
enum g_end { G_END_IDLE, G_END_LOOP, G_END_HOLD }; /* what happens after the last frame */
enum g_kind { G_STAND, G_CROUCHING, G_AIR, G_DOWN };

typedef struct g_key {
    int frame;
    fx dx, dy;
    fang ang[G_BONES];
} g_key;

typedef struct g_move {
    const char *name;
    int frames, end, kind;
    /* attack data; hit_bones == 0 for moves that do not hit */
    unsigned hit_bones;     /* mask of 1 << g_bone */
    int active_start, active_end; /* [start, end) */
    int damage, hitstun, blockstun, level, knockdown;
    fx push;                /* knock-back speed given to the defender, m/tick */
    fx lunge;               /* forward speed of the attacker during [lunge_start, lunge_end) */
    int lunge_start, lunge_end;
    const g_key *keys;
    int nkeys;
} g_move;

extern const g_move g_moves[G_MV_COUNT];

static inline bool g_is_attack(int move)
{
    return g_moves[move].hit_bones != 0;
}

#endif
