#include "g_ai.h"

#include <string.h>

#include "g_local.h"

static uint32_t ai_rand(g_ai *ai) /* xorshift64* */
{
    uint64_t x = ai->rng;
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    ai->rng = x;
    return (uint32_t)((x * 0x2545f4914f6cdd1dull) >> 32);
}

static int pct(g_ai *ai)
{
    return (int)(ai_rand(ai) % 100);
}

static int between(g_ai *ai, int lo, int hi)
{
    return lo + (int)(ai_rand(ai) % (uint32_t)(hi - lo + 1));
}

void g_ai_init(g_ai *ai, int player, int level, uint64_t seed)
{
    memset(ai, 0, sizeof *ai);
    ai->player = player;
    ai->level = level < 0 ? 0 : level > 3 ? 3 : level;
    ai->rng = seed ^ (0x9e3779b97f4a7c15ull * (uint64_t)(player + 1));
    if (!ai->rng)
        ai->rng = 1;
}

static void plan(g_ai *ai, g_input in, int ticks)
{
    if (ai->nplan < 8) {
        ai->plan[ai->nplan] = in;
        ai->plan_ticks[ai->nplan++] = ticks;
    }
}

/* Chooses the next few inputs.  Button presses are followed by a release so
 * the next press is a new press. */
static void decide(g_ai *ai, const g_state *st)
{
    const g_fighter *me = &st->f[ai->player], *op = &st->f[1 - ai->player];
    g_input fwd = me->facing > 0 ? G_IN_RIGHT : G_IN_LEFT, back = me->facing > 0 ? G_IN_LEFT : G_IN_RIGHT;
    fx dist = fx_abs(op->x - me->x);
    fx edge = g_stages[st->stage].ring_half;
    bool my_back_to_edge = fx_abs(me->x) > edge - FX(0.8) && ((me->x > 0) == (me->facing < 0));
    const g_move *om = &g_moves[op->move];
    bool threat = om->hit_bones && op->frame < om->active_end && dist < FX(1.4);
    ai->nplan = ai->at = 0;

    if (threat && pct(ai) < 25 + 15 * ai->level) {
        plan(ai, (g_input)(G_IN_GUARD | (om->level == 2 ? G_IN_DOWN : 0)), between(ai, 8, 16));
    } else if (dist > FX(1.05)) {
        int r = pct(ai);
        if (r < 70 || my_back_to_edge)
            plan(ai, fwd, between(ai, 6, 18));
        else if (r < 78)
            plan(ai, (g_input)(G_IN_UP | fwd), 2), plan(ai, 0, 40);
        else if (r < 90)
            plan(ai, back, between(ai, 4, 10));
        else
            plan(ai, 0, between(ai, 4, 12));
    } else {
        int r = pct(ai);
        if (r < 28)
            plan(ai, G_IN_PUNCH, 2), plan(ai, 0, between(ai, 6, 16));
        else if (r < 50)
            plan(ai, G_IN_KICK, 2), plan(ai, 0, between(ai, 12, 24));
        else if (r < 63)
            plan(ai, (g_input)(G_IN_DOWN | G_IN_KICK), 2), plan(ai, G_IN_DOWN, between(ai, 10, 20));
        else if (r < 75) { /* the special: 2, 3, 6 + P */
            plan(ai, G_IN_DOWN, 3);
            plan(ai, (g_input)(G_IN_DOWN | fwd), 3);
            plan(ai, (g_input)(fwd | G_IN_PUNCH), 2);
            plan(ai, 0, between(ai, 24, 36));
        } else if (r < 82)
            plan(ai, (g_input)(G_IN_DOWN | G_IN_PUNCH), 2), plan(ai, G_IN_DOWN, between(ai, 6, 12));
        else if (r < 88)
            plan(ai, (g_input)(G_IN_UP | fwd), 2), plan(ai, G_IN_KICK, 8), plan(ai, 0, 30);
        else if (r < 95 && !my_back_to_edge)
            plan(ai, back, between(ai, 8, 16));
        else
            plan(ai, G_IN_GUARD, between(ai, 8, 20));
    }
}

g_input g_ai_input(g_ai *ai, const g_state *st)
{
    if (st->phase != G_PHASE_FIGHT) {
        ai->nplan = ai->at = 0;
        return 0;
    }
    /* react to a sudden threat even in the middle of a plan */
    const g_fighter *me = &st->f[ai->player], *op = &st->f[1 - ai->player];
    if (g_moves[op->move].hit_bones && op->frame == 1 && g_moves[me->move].hit_bones == 0 && pct(ai) < 10 * ai->level)
        ai->nplan = 0;
    while (ai->at < ai->nplan && ai->plan_ticks[ai->at] <= 0)
        ai->at++;
    if (ai->at >= ai->nplan)
        decide(ai, st);
    ai->plan_ticks[ai->at]--;
    return ai->plan[ai->at];
}
