/* The game's cues: what one tick sounds like, from the game's events and
 * from what changed between two states (for what has no event: whiffs,
 * steps, landings, craters).  A pure function of its arguments; the bank's
 * ids are looked up by name once.
 *
 * Pan follows the fighter's place in the game camera's framing (the
 * framing g_hole_in_view reproduces from the state: the camera centres
 * the two fighters and backs off as they part), so a blow on the left of
 * the picture sounds on the left.  Announcer lines, the bell, thunder and
 * the crowd are centred. */
#include <pthread.h>
#include <string.h>

#include "au_local.h"

enum {
    S_HIT_LIGHT, S_HIT_MEDIUM, S_HIT_HEAVY, S_GUARD, S_WHIFF, S_SPECIAL, S_STEP, S_LAND, S_KNOCKDOWN,
    S_RINGOUT_FALL, S_RINGOUT_SPLASH, S_THUNDER, S_CRATER, S_BELL, S_CROWD_CHEER, S_CROWD_GASP,
    S_V_ROUND1, S_V_ROUND2, S_V_ROUND3, S_V_ROUND4, S_V_ROUND5, S_V_FIGHT, S_V_KO, S_V_RING_OUT, S_V_TIME,
    S_V_DRAW, S_V_P1_WINS, S_V_P2_WINS,
    S_COUNT
};
static const char *const names[S_COUNT] = {
    "hit_light", "hit_medium", "hit_heavy", "guard", "whiff", "special", "step", "land", "knockdown",
    "ringout_fall", "ringout_splash", "thunder", "crater", "bell", "crowd_cheer", "crowd_gasp",
    "voice_round1", "voice_round2", "voice_round3", "voice_round4", "voice_round5", "voice_fight", "voice_ko",
    "voice_ring_out", "voice_time", "voice_draw", "voice_p1_wins", "voice_p2_wins",
};
static int ids[S_COUNT];
static pthread_once_t ids_once = PTHREAD_ONCE_INIT;

static void find_ids(void)
{
    for (int i = 0; i < S_COUNT; i++)
        ids[i] = au_bank_find(names[i]);
}

typedef struct cues {
    au_cue *out;
    int n, max;
} cues;

static void cue(cues *c, int s, float gain, float pan)
{
    if (ids[s] < 0 || c->n >= c->max)
        return;
    c->out[c->n++] = (au_cue){ids[s], 0, gain, pan};
}

/* Where x lies across the picture, -1 (left edge) .. +1 (right edge), in
 * the camera's framing of state st (see g_hole_in_view: the eye is `dist`
 * from the fighters' midpoint; the half-width seen at the fight line is
 * 0.69805 * (1.19 + dist^2) / (dist + 0.245 / dist)).  Scaled by 0.8: a
 * sound at the frame's edge is still heard a little in both ears. */
static float pan_of(const g_state *st, fx x)
{
    double x0 = fx_to_float(st->f[0].x), x1 = fx_to_float(st->f[1].x);
    double mid = (x0 + x1) / 2, gap = x1 > x0 ? x1 - x0 : x0 - x1;
    double dist = 4.2 + 0.9 * gap, half = 0.69805 * (1.19 + dist * dist) / (dist + 0.245 / dist);
    double p = ((double)fx_to_float(x) - mid) / half;
    p = p < -1 ? -1 : p > 1 ? 1 : p;
    return (float)(0.8 * p);
}

static bool attacking(int move)
{
    switch (move) {
    case G_MV_PUNCH: case G_MV_KICK: case G_MV_LOW_KICK: case G_MV_CROUCH_PUNCH: case G_MV_JUMP_KICK:
    case G_MV_SPECIAL:
        return true;
    default:
        return false;
    }
}

/* the stages whose ring stands in water: a ring-out splashes */
static bool water_stage(int stage)
{
    if (stage < 0 || stage >= G_STAGES)
        return false;
    return !strcmp(g_stages[stage].name, "harbor") || !strcmp(g_stages[stage].name, "shallows");
}

static void from_events(const g_state *cur, const g_events *ev, cues *c, bool *struck)
{
    bool gasp = false, cheer = false;
    for (int k = 0; k < ev->n && k < G_MAX_EVENTS; k++) {
        const g_event *e = &ev->ev[k];
        int p = e->player >= 1 && e->player <= 2 ? e->player - 1 : -1;
        float pan = p >= 0 ? pan_of(cur, cur->f[p].x) : 0;
        switch (e->type) {
        case G_EV_ROUND:
            if (e->value >= 1 && e->value <= 5)
                cue(c, S_V_ROUND1 + e->value - 1, 1, 0);
            break;
        case G_EV_FIGHT:
            cue(c, S_BELL, 0.9f, 0);
            cue(c, S_V_FIGHT, 1, 0);
            break;
        case G_EV_HIT: { /* player: the one hit; value: the damage */
            int d = e->value;
            float g = (float)(0.75 + 0.25 * (d > 28 ? 1.0 : d / 28.0));
            cue(c, d <= 10 ? S_HIT_LIGHT : d <= 18 ? S_HIT_MEDIUM : S_HIT_HEAVY, g, pan);
            gasp |= d > 18;
            if (p >= 0)
                struck[1 - p] = true;
            break;
        }
        case G_EV_BLOCK:
            cue(c, S_GUARD, 1, pan);
            if (p >= 0)
                struck[1 - p] = true;
            break;
        case G_EV_SPECIAL: cue(c, S_SPECIAL, 1, pan); break;
        case G_EV_KNOCKDOWN: gasp = true; break;
        case G_EV_KO:
            cue(c, S_V_KO, 1, 0);
            cheer = true;
            break;
        case G_EV_RING_OUT:
            cue(c, S_V_RING_OUT, 1, 0);
            cheer = true;
            break;
        case G_EV_TIME_UP: cue(c, S_V_TIME, 1, 0); break;
        case G_EV_DRAW: cue(c, S_V_DRAW, 1, 0); break;
        case G_EV_MATCH_WIN:
            cue(c, p == 0 ? S_V_P1_WINS : p == 1 ? S_V_P2_WINS : S_V_DRAW, 1, 0);
            cheer = true;
            break;
        case G_EV_LIGHTNING: cue(c, S_THUNDER, 1, 0); break;
        default: break;
        }
    }
    if (cheer)
        cue(c, S_CROWD_CHEER, 1, 0);
    else if (gasp)
        cue(c, S_CROWD_GASP, 0.8f, 0);
}

static void from_states(const g_state *prev, const g_state *cur, const bool struck[2], cues *c)
{
    if (prev->tick + 1 != cur->tick || prev->stage != cur->stage)
        return; /* not one tick of the same match: no differences to hear */
    for (int i = 0; i < 2; i++) {
        const g_fighter *a = &prev->f[i], *b = &cur->f[i];
        float pan = pan_of(cur, b->x);
        /* an attack that ended on its own without connecting */
        if (attacking(a->move) && !a->hit_done && !struck[i] && b->move != a->move &&
            (b->move == G_MV_IDLE || b->move == G_MV_CROUCH || b->move == G_MV_WALK_F || b->move == G_MV_WALK_B))
            cue(c, S_WHIFF, 1, pan);
        /* the walk cycle is 32 ticks, two steps: the first on the first tick */
        if ((b->move == G_MV_WALK_F || b->move == G_MV_WALK_B) && b->y == 0 && b->frame % 16 == 1)
            cue(c, S_STEP, 0.8f, pan);
        if (a->y > 0 && b->y == 0) /* back on the ring floor */
            cue(c, b->move == G_MV_KNOCKDOWN || b->move == G_MV_KO ? S_KNOCKDOWN : S_LAND, 1, pan);
        if (b->y < 0 && a->vy != 0 && b->vy == 0) /* off the ring: the ground (or water) below */
            cue(c, water_stage(cur->stage) ? S_RINGOUT_SPLASH : S_RINGOUT_FALL, 1, pan);
    }
    if (cur->hole_seq > prev->hole_seq && cur->nholes > 0 && cur->nholes <= G_MAX_HOLES)
        cue(c, S_CRATER, 1, pan_of(cur, cur->holes[cur->nholes - 1].x));
}

int au_game_cues(const g_state *prev, const g_state *cur, const g_events *events, au_cue *out, int max)
{
    pthread_once(&ids_once, find_ids);
    cues c = {out, 0, max < 0 ? 0 : max};
    bool struck[2] = {false, false};
    if (events)
        from_events(cur, events, &c, struck);
    if (prev)
        from_states(prev, cur, struck, &c);
    return c.n;
}
