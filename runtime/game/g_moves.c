/* Frame data and keyframed animation for every move.
 *
 * Angles are absolute in the fighter's frame, in degrees (0 = forward,
 * 90 = up, -90 = down); "l" bones are the lead side (near the opponent).
 * Frame data follows arcade conventions: startup, active frames
 * [active_start, active_end), recovery; stun in ticks. */
#include "g_local.h"

/* P(dx, dy, pelvis, spine, chest, neck, head, l_upperarm, l_forearm, r_upperarm,
 *   r_forearm, l_thigh, l_shin, l_foot, r_thigh, r_shin, r_foot) */
#define P(f, dx, dy, a0, a1, a2, a3, a4, a5, a6, a7, a8, a9, a10, a11, a12, a13, a14)                              \
    {f, FX(dx), FX(dy), {DEG(a0), DEG(a1), DEG(a2), DEG(a3), DEG(a4), DEG(a5), DEG(a6), DEG(a7), DEG(a8), DEG(a9),     \
                         DEG(a10), DEG(a11), DEG(a12), DEG(a13), DEG(a14)}}
/* the fighting stance, shared by many moves */
#define STANCE(f, dy) P(f, 0, dy, 90, 85, 80, 85, 90, -70, 50, -100, 30, -80, -95, 0, -105, -90, 0)
#define CROUCHED(f) P(f, 0, -0.40, 80, 70, 70, 80, 85, -60, 60, -90, 40, -20, -120, 0, -50, -140, 0)
#define KEYS(a) .keys = a, .nkeys = (int)(sizeof a / sizeof a[0])

static const g_key k_idle[] = {STANCE(0, -0.05), P(30, 0, -0.07, 90, 84, 78, 84, 90, -72, 48, -102, 28, -80, -95, 0, -105, -90, 0),
                               STANCE(60, -0.05)};
static const g_key k_walk_f[] = {
    P(0, 0, -0.05, 90, 85, 80, 85, 90, -70, 50, -100, 30, -70, -95, 0, -110, -95, 0),
    P(8, 0, -0.03, 90, 85, 80, 85, 90, -72, 48, -98, 32, -90, -80, 0, -90, -100, 0),
    P(16, 0, -0.05, 90, 85, 80, 85, 90, -70, 50, -100, 30, -110, -95, 0, -70, -95, 0),
    P(24, 0, -0.03, 90, 85, 80, 85, 90, -68, 52, -102, 28, -90, -100, 0, -90, -80, 0),
    P(32, 0, -0.05, 90, 85, 80, 85, 90, -70, 50, -100, 30, -70, -95, 0, -110, -95, 0),
};
static const g_key k_walk_b[] = {
    P(0, 0, -0.05, 90, 87, 83, 85, 90, -70, 50, -100, 30, -70, -95, 0, -110, -95, 0),
    P(8, 0, -0.03, 90, 87, 83, 85, 90, -68, 52, -102, 28, -90, -100, 0, -90, -80, 0),
    P(16, 0, -0.05, 90, 87, 83, 85, 90, -70, 50, -100, 30, -110, -95, 0, -70, -95, 0),
    P(24, 0, -0.03, 90, 87, 83, 85, 90, -72, 48, -98, 32, -90, -80, 0, -90, -100, 0),
    P(32, 0, -0.05, 90, 87, 83, 85, 90, -70, 50, -100, 30, -70, -95, 0, -110, -95, 0),
};
static const g_key k_crouch[] = {STANCE(0, -0.05), CROUCHED(4)};
static const g_key k_jump[] = {
    P(0, 0, -0.15, 90, 80, 75, 85, 90, -60, 60, -90, 40, -60, -110, 0, -80, -120, 0),
    P(6, 0, 0.05, 90, 88, 85, 88, 90, -30, 80, -40, 90, -30, -120, -20, -40, -130, -20),
    P(30, 0, 0.05, 90, 88, 85, 88, 90, -30, 80, -40, 90, -30, -120, -20, -40, -130, -20),
    P(40, 0, -0.10, 90, 85, 80, 85, 90, -70, 50, -100, 30, -80, -95, 0, -105, -90, 0),
};
static const g_key k_punch[] = {
    STANCE(0, -0.05),
    P(4, 0.04, -0.06, 90, 80, 72, 80, 88, -8, -4, -105, 35, -75, -95, 0, -110, -90, 0),
    P(8, 0.04, -0.06, 90, 80, 72, 80, 88, -8, -4, -105, 35, -75, -95, 0, -110, -90, 0),
    P(13, 0.02, -0.05, 90, 84, 78, 84, 90, -50, 40, -100, 30, -78, -95, 0, -106, -90, 0),
    STANCE(18, -0.05),
};
static const g_key k_kick[] = {
    STANCE(0, -0.05),
    P(6, 0, -0.04, 90, 95, 95, 92, 90, -60, 60, -110, 20, -85, -95, 0, -30, -110, -40),
    P(10, 0, -0.03, 95, 105, 105, 100, 95, -50, 70, -120, 10, -85, -95, 0, 8, 6, 10),
    P(14, 0, -0.03, 95, 105, 105, 100, 95, -50, 70, -120, 10, -85, -95, 0, 8, 6, 10),
    P(20, 0, -0.04, 90, 95, 92, 90, 90, -60, 60, -110, 20, -85, -95, 0, -50, -120, -20),
    STANCE(28, -0.05),
};
static const g_key k_low_kick[] = {
    CROUCHED(0),
    P(5, 0, -0.42, 75, 65, 68, 80, 85, -60, 60, -90, 40, -28, -18, 0, -50, -140, 0),
    P(10, 0, -0.42, 75, 65, 68, 80, 85, -60, 60, -90, 40, -28, -18, 0, -50, -140, 0),
    CROUCHED(16), CROUCHED(24),
};
static const g_key k_crouch_punch[] = {
    CROUCHED(0),
    P(3, 0.03, -0.40, 80, 65, 62, 75, 85, 2, 6, -90, 40, -20, -120, 0, -50, -140, 0),
    P(6, 0.03, -0.40, 80, 65, 62, 75, 85, 2, 6, -90, 40, -20, -120, 0, -50, -140, 0),
    CROUCHED(16),
};
static const g_key k_jump_kick[] = {
    P(0, 0, 0.05, 90, 88, 85, 88, 90, -30, 80, -40, 90, -30, -120, -20, -40, -130, -20),
    P(4, 0, 0.05, 95, 100, 100, 95, 92, -20, 70, -60, 80, -25, -25, -15, -60, -130, -20),
    P(40, 0, 0.05, 95, 100, 100, 95, 92, -20, 70, -60, 80, -25, -25, -15, -60, -130, -20),
};
static const g_key k_special[] = {
    STANCE(0, -0.05),
    P(8, 0.05, -0.30, 80, 65, 60, 75, 85, -80, 40, -130, -70, -40, -120, 0, -100, -120, 0),
    P(13, 0.12, 0.02, 92, 92, 90, 92, 95, -60, 30, 30, 55, -75, -90, 0, -120, -100, -10),
    P(20, 0.12, 0.02, 92, 92, 90, 92, 95, -60, 30, 30, 55, -75, -90, 0, -120, -100, -10),
    P(30, 0.02, -0.06, 90, 86, 82, 85, 90, -70, 50, -80, 40, -80, -95, 0, -105, -90, 0),
    STANCE(40, -0.05),
};
static const g_key k_guard[] = {STANCE(0, -0.05), P(3, -0.02, -0.07, 90, 90, 88, 88, 90, 25, 95, 12, 100, -80, -95, 0, -105, -90, 0)};
static const g_key k_crouch_guard[] = {CROUCHED(0), P(3, -0.02, -0.42, 85, 80, 80, 85, 88, 25, 95, 12, 100, -20, -120, 0, -50, -140, 0)};
static const g_key k_hitstun[] = {
    STANCE(0, -0.05),
    P(3, -0.05, -0.08, 95, 105, 112, 115, 120, -125, -60, -135, -80, -85, -95, 0, -100, -95, 0),
    P(14, -0.02, -0.06, 92, 92, 90, 92, 95, -90, 20, -110, 10, -82, -95, 0, -103, -92, 0),
    STANCE(24, -0.05),
};
static const g_key k_blockstun[] = {
    P(0, -0.04, -0.08, 90, 92, 92, 92, 92, 25, 95, 12, 100, -80, -95, 0, -105, -90, 0),
    P(6, -0.02, -0.07, 90, 90, 88, 88, 90, 25, 95, 12, 100, -80, -95, 0, -105, -90, 0),
};
static const g_key k_knockdown[] = {
    STANCE(0, -0.05),
    P(8, -0.10, -0.20, 115, 125, 130, 135, 140, -140, -100, -150, -110, -60, -70, 0, -70, -80, 0),
    P(20, -0.20, -0.80, 178, 180, 182, 184, 186, 160, 170, 175, 185, 5, 0, 90, 10, 5, 90),
    P(60, -0.20, -0.80, 178, 180, 182, 184, 186, 160, 170, 175, 185, 5, 0, 90, 10, 5, 90),
};
static const g_key k_getup[] = {
    P(0, -0.20, -0.80, 178, 180, 182, 184, 186, 160, 170, 175, 185, 5, 0, 90, 10, 5, 90),
    P(12, -0.05, -0.45, 110, 100, 95, 95, 95, -60, 60, -120, -40, -20, -120, 0, -60, -140, 0),
    STANCE(26, -0.05),
};
static const g_key k_win[] = {
    STANCE(0, -0.05),
    P(20, 0, -0.03, 90, 90, 92, 95, 100, 80, 100, 100, 80, -85, -92, 0, -98, -90, 0),
};

const g_move g_moves[G_MV_COUNT] = {
    [G_MV_IDLE] = {.name = "idle", .frames = 60, .end = G_END_LOOP, .kind = G_STAND, KEYS(k_idle)},
    [G_MV_WALK_F] = {.name = "walk_forward", .frames = 32, .end = G_END_LOOP, .kind = G_STAND, KEYS(k_walk_f)},
    [G_MV_WALK_B] = {.name = "walk_back", .frames = 32, .end = G_END_LOOP, .kind = G_STAND, KEYS(k_walk_b)},
    [G_MV_CROUCH] = {.name = "crouch", .frames = 5, .end = G_END_HOLD, .kind = G_CROUCHING, KEYS(k_crouch)},
    [G_MV_JUMP] = {.name = "jump", .frames = 40, .end = G_END_HOLD, .kind = G_AIR, KEYS(k_jump)},
    [G_MV_PUNCH] = {.name = "punch", .frames = 18, .end = G_END_IDLE, .kind = G_STAND,
                    .hit_bones = 1u << G_L_FOREARM, .active_start = 4, .active_end = 8, .damage = 10,
                    .hitstun = 14, .blockstun = 8, .level = G_HIGH, .push = FX(0.020), KEYS(k_punch)},
    [G_MV_KICK] = {.name = "kick", .frames = 28, .end = G_END_IDLE, .kind = G_STAND,
                   .hit_bones = 1u << G_R_SHIN | 1u << G_R_FOOT, .active_start = 9, .active_end = 14, .damage = 18,
                   .hitstun = 18, .blockstun = 10, .level = G_MID, .push = FX(0.035), KEYS(k_kick)},
    [G_MV_LOW_KICK] = {.name = "low_kick", .frames = 24, .end = G_END_IDLE, .kind = G_CROUCHING,
                       .hit_bones = 1u << G_L_SHIN | 1u << G_L_FOOT, .active_start = 5, .active_end = 10,
                       .damage = 12, .hitstun = 14, .blockstun = 8, .level = G_LOW, .push = FX(0.020),
                       KEYS(k_low_kick)},
    [G_MV_CROUCH_PUNCH] = {.name = "crouch_punch", .frames = 16, .end = G_END_IDLE, .kind = G_CROUCHING,
                           .hit_bones = 1u << G_L_FOREARM, .active_start = 3, .active_end = 6, .damage = 8,
                           .hitstun = 12, .blockstun = 6, .level = G_MID, .push = FX(0.015), KEYS(k_crouch_punch)},
    [G_MV_JUMP_KICK] = {.name = "jump_kick", .frames = 40, .end = G_END_HOLD, .kind = G_AIR,
                        .hit_bones = 1u << G_L_SHIN | 1u << G_L_FOOT, .active_start = 4, .active_end = 24,
                        .damage = 16, .hitstun = 16, .blockstun = 10, .level = G_MID, .push = FX(0.030),
                        KEYS(k_jump_kick)},
    [G_MV_SPECIAL] = {.name = "rising_palm", .frames = 40, .end = G_END_IDLE, .kind = G_STAND,
                      .hit_bones = 1u << G_R_FOREARM | 1u << G_R_UPPERARM, .active_start = 12, .active_end = 18,
                      .damage = 28, .hitstun = 0, .blockstun = 16, .level = G_MID, .knockdown = 1,
                      .push = FX(0.050), .lunge = FX(0.060), .lunge_start = 4, .lunge_end = 14, KEYS(k_special)},
    [G_MV_GUARD] = {.name = "guard", .frames = 4, .end = G_END_HOLD, .kind = G_STAND, KEYS(k_guard)},
    [G_MV_CROUCH_GUARD] = {.name = "crouch_guard", .frames = 4, .end = G_END_HOLD, .kind = G_CROUCHING,
                           KEYS(k_crouch_guard)},
    [G_MV_HITSTUN] = {.name = "hitstun", .frames = 24, .end = G_END_HOLD, .kind = G_STAND, KEYS(k_hitstun)},
    [G_MV_BLOCKSTUN] = {.name = "blockstun", .frames = 7, .end = G_END_HOLD, .kind = G_STAND, KEYS(k_blockstun)},
    [G_MV_KNOCKDOWN] = {.name = "knockdown", .frames = 61, .end = G_END_HOLD, .kind = G_DOWN, KEYS(k_knockdown)},
    [G_MV_GETUP] = {.name = "getup", .frames = 26, .end = G_END_IDLE, .kind = G_DOWN, KEYS(k_getup)},
    [G_MV_KO] = {.name = "ko", .frames = 61, .end = G_END_HOLD, .kind = G_DOWN, KEYS(k_knockdown)},
    [G_MV_WIN] = {.name = "win", .frames = 21, .end = G_END_HOLD, .kind = G_STAND, KEYS(k_win)},
};

const char *g_move_name(int move)
{
    return move >= 0 && move < G_MV_COUNT ? g_moves[move].name : "?";
}

static fang lerp_angle(fang a, fang b, int32_t t) /* t in Q16, shortest way round */
{
    int32_t d = (int32_t)((((uint32_t)(b - a) + 32768u) & 0xffffu)) - 32768;
    return (fang)(a + (int32_t)(((int64_t)d * t) >> 16));
}

void g_fighter_pose(const g_state *st, int i, g_pose *pose)
{
    const g_fighter *f = &st->f[i];
    const g_move *m = &g_moves[f->move];
    int frame = f->frame;
    const g_key *a = &m->keys[0], *b = a;
    for (int k = 0; k < m->nkeys; k++) {
        if (m->keys[k].frame <= frame)
            a = &m->keys[k];
        if (m->keys[k].frame >= frame) {
            b = &m->keys[k];
            break;
        }
        b = &m->keys[k];
    }
    int32_t t = b->frame > a->frame ? (int32_t)(((int64_t)(frame - a->frame) << 16) / (b->frame - a->frame)) : 0;
    if (t > 65536)
        t = 65536;
    pose->root_dx = a->dx + (fx)(((int64_t)(b->dx - a->dx) * t) >> 16);
    pose->root_dy = a->dy + (fx)(((int64_t)(b->dy - a->dy) * t) >> 16);
    for (int k = 0; k < G_BONES; k++)
        pose->ang[k] = lerp_angle(a->ang[k], b->ang[k], t);
}

void g_fighter_capsules(const g_state *st, int i, g_capsule out[G_BONES])
{
    g_pose pose;
    g_fighter_pose(st, i, &pose);
    g_skel_solve(&pose, st->f[i].x, st->f[i].y, st->f[i].facing, out);
}
