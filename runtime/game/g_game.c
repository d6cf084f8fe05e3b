/* The game rules: phases, control, physics, hits, rounds.  See g_game.h
 * for the contract and docs/game.md for the rules in words. */
#include <string.h>

#include "g_local.h"

const g_stage_def g_stages[G_STAGES] = {
    {"dojo", FX(4.0), false, false},
    {"harbor", FX(3.5), true, false},
    {"temple", FX(4.5), false, false},
    {"shallows", FX(4.0), false, false},  /* ankle-deep water over the ring (water) */
    {"snowfield", FX(4.0), false, false}, /* fresh snow on the ring (snow) */
    {"mistvale", FX(4.5), false, false},  /* mist that limbs stir (fog map) */
    {"plaza", FX(4.0), false, false},     /* a city square: buildings cast LSPSM shadows */
    {"quarry", FX(4.0), false, true}, /* heavy hits leave holes in the floor (stencil holes) */
};

#define WALK_F_SPEED FX(0.030)
#define WALK_B_SPEED FX(0.024)
#define JUMP_VY FX(0.050)
#define JUMP_VX FX(0.028)
#define GRAVITY FX(0.0028)
#define MIN_GAP FX(0.55)       /* push boxes: closest two grounded fighters get */
#define START_X FX(1.2)
#define SPECIAL_WINDOW 18      /* ticks for the 2-3-6 motion before the punch */
#define EDGE_MARGIN FX(0.05)   /* walking stops this far inside the ring edge */
#define FALL_FLOOR FX(-3.0)    /* fighters out of the ring fall no further */

static uint64_t rng_next(uint64_t *s) /* splitmix64 */
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static void emit(g_events *ev, int type, int player, int value)
{
    if (ev && ev->n < G_MAX_EVENTS)
        ev->ev[ev->n++] = (g_event){type, player, value};
}

static void set_move(g_fighter *f, int move)
{
    if (f->move == move)
        return;
    f->move = move;
    f->frame = 0;
    f->hit_done = 0;
}

static void reset_fighter(g_fighter *f, int side, bool new_match)
{
    int rounds = new_match ? 0 : f->rounds_won;
    int hits = new_match ? 0 : f->hits, specials = new_match ? 0 : f->specials;
    memset(f, 0, sizeof *f);
    f->x = side == 0 ? -START_X : START_X;
    f->facing = side == 0 ? 1 : -1;
    f->move = G_MV_IDLE;
    f->health = G_MAX_HEALTH;
    f->rounds_won = rounds;
    f->hits = hits;
    f->specials = specials;
    for (int k = 0; k < G_HIST; k++)
        f->hist_age[k] = 1000;
}

static void start_round(g_state *st, bool new_match)
{
    if (new_match) {
        st->round = 1;
        st->nholes = 0, st->hole_seq = 0;
        memset(st->holes, 0, sizeof st->holes);
        st->match_winner = st->matches == 0 ? -1 : st->match_winner;
    } else {
        st->round++;
    }
    reset_fighter(&st->f[0], 0, new_match);
    reset_fighter(&st->f[1], 1, new_match);
    st->phase = G_PHASE_INTRO;
    st->phase_ticks = 0;
    st->round_timer = G_ROUND_TICKS;
    st->round_result = G_RES_NONE;
    st->round_winner = 0;
}

void g_init(g_state *st, int stage, uint64_t seed)
{
    memset(st, 0, sizeof *st);
    st->stage = stage >= 0 && stage < G_STAGES ? stage : 0;
    st->rng = seed;
    st->input_digest = G_FNV_OFFSET;
    st->match_winner = -1;
    if (g_stages[st->stage].storm)
        st->flash_in = 300 + (int32_t)(rng_next(&st->rng) % 900);
    start_round(st, true);
}

/* Stick direction in numpad notation relative to facing (6 = forward). */
static int numpad(g_input in, int facing)
{
    int x = (in & G_IN_RIGHT) ? 1 : (in & G_IN_LEFT) ? -1 : 0;
    int y = (in & G_IN_UP) ? 1 : (in & G_IN_DOWN) ? -1 : 0;
    x *= facing;
    return 5 + x + 3 * y;
}

static void track_motion(g_fighter *f, g_input in)
{
    for (int k = 0; k < G_HIST; k++)
        if (f->hist_age[k] < 1000)
            f->hist_age[k]++;
    int d = numpad(in, f->facing);
    if (d != f->hist_dir[0] || f->hist_age[0] >= 1000) {
        memmove(f->hist_dir + 1, f->hist_dir, sizeof f->hist_dir - sizeof f->hist_dir[0]);
        memmove(f->hist_age + 1, f->hist_age, sizeof f->hist_age - sizeof f->hist_age[0]);
        f->hist_dir[0] = d;
        f->hist_age[0] = 0;
    }
}

/* 2, 3, 6 in that order (the newest entry is 6, possibly still held),
 * all within SPECIAL_WINDOW ticks. */
static bool motion_236(const g_fighter *f)
{
    static const int seq[3] = {6, 3, 2};
    int k = 0;
    for (int h = 0; h < G_HIST && k < 3; h++) {
        if (f->hist_age[h] > SPECIAL_WINDOW)
            return false;
        if (f->hist_dir[h] == seq[k])
            k++;
        else if (k == 0)
            return false;
    }
    return k == 3;
}

static bool actionable(const g_fighter *f)
{
    switch (f->move) {
    case G_MV_IDLE: case G_MV_WALK_F: case G_MV_WALK_B: case G_MV_CROUCH: case G_MV_GUARD: case G_MV_CROUCH_GUARD:
        return f->y == 0 && f->stun == 0;
    default:
        return false;
    }
}

static void control(g_state *st, int i, g_input in, g_events *ev)
{
    g_fighter *f = &st->f[i];
    g_input pressed = (g_input)(in & ~f->prev_input);
    int fwd = f->facing > 0 ? G_IN_RIGHT : G_IN_LEFT, back = f->facing > 0 ? G_IN_LEFT : G_IN_RIGHT;
    if (f->move == G_MV_JUMP && (pressed & G_IN_KICK)) {
        set_move(f, G_MV_JUMP_KICK); /* once per jump: no way back to G_MV_JUMP */
        return;
    }
    if (!actionable(f))
        return;
    if ((pressed & G_IN_PUNCH) && motion_236(f)) {
        set_move(f, G_MV_SPECIAL);
        f->specials++;
        emit(ev, G_EV_SPECIAL, i + 1, 0);
    } else if (pressed & G_IN_PUNCH) {
        set_move(f, (in & G_IN_DOWN) ? G_MV_CROUCH_PUNCH : G_MV_PUNCH);
    } else if (pressed & G_IN_KICK) {
        set_move(f, (in & G_IN_DOWN) ? G_MV_LOW_KICK : G_MV_KICK);
    } else if (in & G_IN_GUARD) {
        set_move(f, (in & G_IN_DOWN) ? G_MV_CROUCH_GUARD : G_MV_GUARD);
    } else if (in & G_IN_UP) {
        set_move(f, G_MV_JUMP);
        f->vy = JUMP_VY;
        f->vx = (in & fwd) ? JUMP_VX * f->facing : (in & back) ? -JUMP_VX * f->facing : 0;
    } else if (in & G_IN_DOWN) {
        set_move(f, G_MV_CROUCH);
    } else if (in & fwd) {
        set_move(f, G_MV_WALK_F);
    } else if (in & back) {
        set_move(f, G_MV_WALK_B);
    } else {
        set_move(f, G_MV_IDLE);
    }
}

static void physics(g_state *st, int i)
{
    g_fighter *f = &st->f[i];
    const g_move *m = &g_moves[f->move];
    fx edge = g_stages[st->stage].ring_half;
    bool voluntary = false;
    if (f->move == G_MV_WALK_F) {
        f->vx = WALK_F_SPEED * f->facing;
        voluntary = true;
    } else if (f->move == G_MV_WALK_B) {
        f->vx = -WALK_B_SPEED * f->facing;
        voluntary = true;
    } else if (m->lunge && f->frame >= m->lunge_start && f->frame < m->lunge_end) {
        f->vx = m->lunge * f->facing;
        voluntary = true;
    } else if (f->y == 0 && f->vy == 0) {
        f->vx -= f->vx / 8; /* ground friction */
        if (fx_abs(f->vx) < 64)
            f->vx = 0;
    }
    f->x += f->vx;
    if (voluntary)
        f->x = fx_clamp(f->x, -edge + EDGE_MARGIN, edge - EDGE_MARGIN);
    bool over_ring = fx_abs(f->x) <= edge;
    if (f->y > 0 || f->vy != 0 || !over_ring) {
        f->vy -= GRAVITY;
        f->y += f->vy;
        if (over_ring && f->y <= 0 && f->vy < 0) { /* landing */
            f->y = 0;
            f->vy = 0;
            if (f->move == G_MV_JUMP || f->move == G_MV_JUMP_KICK)
                set_move(f, G_MV_IDLE);
        }
        if (f->y < FALL_FLOOR) {
            f->y = FALL_FLOOR;
            f->vy = 0;
            f->vx = 0;
        }
    }
}

static void separate(g_state *st)
{
    g_fighter *a = &st->f[0], *b = &st->f[1];
    if (a->y > FX(0.6) || b->y > FX(0.6) || a->y < 0 || b->y < 0)
        return; /* one is jumping over or falling off: no push boxes */
    fx d = b->x - a->x, gap = fx_abs(d);
    if (gap >= MIN_GAP)
        return;
    fx push = (MIN_GAP - gap) / 2 + 1;
    int dir = d > 0 ? 1 : d < 0 ? -1 : (a->facing > 0 ? 1 : -1);
    /* walking into someone never pushes them out of the ring: a fighter
     * at the edge stays, the other takes the whole push */
    fx lim = g_stages[st->stage].ring_half - EDGE_MARGIN;
    fx alim = fx_abs(a->x) > lim ? fx_abs(a->x) : lim, blim = fx_abs(b->x) > lim ? fx_abs(b->x) : lim;
    fx ax = a->x - push * dir, bx = b->x + push * dir;
    if (fx_abs(ax) > alim) {
        fx c = ax > 0 ? alim : -alim;
        bx += c - ax;
        ax = c;
    }
    if (fx_abs(bx) > blim) {
        fx c = bx > 0 ? blim : -blim;
        ax += c - bx;
        bx = c;
    }
    a->x = ax;
    b->x = bx;
}

static void face_each_other(g_state *st)
{
    for (int i = 0; i < 2; i++) {
        g_fighter *f = &st->f[i], *o = &st->f[1 - i];
        if (!actionable(f))
            continue;
        if (o->x > f->x)
            f->facing = 1;
        else if (o->x < f->x)
            f->facing = -1;
    }
}

static bool invulnerable(const g_fighter *f)
{
    return g_moves[f->move].kind == G_DOWN;
}

static bool blocks(const g_fighter *d, int level)
{
    bool standing = d->move == G_MV_GUARD || d->move == G_MV_BLOCKSTUN;
    bool crouching = d->move == G_MV_CROUCH_GUARD;
    return (standing && level != G_LOW) || (crouching && level == G_LOW);
}

/* Does fighter a's attack touch fighter d this tick? */
static bool attack_connects(const g_state *st, int a, int d)
{
    const g_fighter *fa = &st->f[a];
    const g_move *m = &g_moves[fa->move];
    if (!m->hit_bones || fa->hit_done || fa->frame < m->active_start || fa->frame >= m->active_end)
        return false;
    if (invulnerable(&st->f[d]))
        return false;
    if (m->level == G_HIGH && g_moves[st->f[d].move].kind == G_CROUCHING)
        return false; /* high attacks go over a crouching fighter (a rule, as in Virtua Fighter) */
    g_capsule ca[G_BONES], cd[G_BONES];
    g_fighter_capsules(st, a, ca);
    g_fighter_capsules(st, d, cd);
    for (int i = 0; i < G_BONES; i++) {
        if (!(m->hit_bones & (1u << i)))
            continue;
        for (int j = 0; j < G_BONES; j++)
            if (g_capsules_touch(&ca[i], &cd[j]))
                return true;
    }
    return false;
}

/* before: the state as both attacks were tested, so a trade resolves both
 * hits from the moves the fighters were doing, not from the reaction the
 * first hit already put the other into */
static void apply_hit(g_state *st, const g_state *before, int a, int d, g_events *ev)
{
    g_fighter *fa = &st->f[a], *fd = &st->f[d];
    const g_move *m = &g_moves[before->f[a].move];
    fa->hit_done = 1;
    int away = fd->x >= fa->x ? 1 : -1;
    if (blocks(&before->f[d], m->level) && fd->y == 0) {
        set_move(fd, fd->move == G_MV_CROUCH_GUARD ? G_MV_CROUCH_GUARD : G_MV_BLOCKSTUN);
        fd->frame = 0;
        fd->stun = m->blockstun;
        fd->vx = (m->push / 2) * away;
        emit(ev, G_EV_BLOCK, d + 1, 0);
        return;
    }
    fd->health -= m->damage;
    if (fd->health < 0)
        fd->health = 0;
    fa->hits++;
    emit(ev, G_EV_HIT, d + 1, m->damage);
    if (m->knockdown || fd->health == 0 || fd->y > 0) {
        set_move(fd, fd->health == 0 ? G_MV_KO : G_MV_KNOCKDOWN);
        fd->vx = m->push * away;
        fd->vy = FX(0.035);
        fd->stun = 0;
        emit(ev, G_EV_KNOCKDOWN, d + 1, 0);
        if (g_stages[st->stage].destructible) {
            /* a crater where the blow drives the fighter into the floor:
             * bigger for harder blows, a little off the fight line */
            fx r = fx_clamp(FX(0.35) + m->damage * FX(0.012), FX(0.35), FX(0.75));
            int32_t j = (int32_t)((uint32_t)(st->hole_seq + 1) * 2654435761u >> 24) - 128; /* -128..127 */
            g_hole_add(st, fd->x + away * FX(0.7), j * (FX(0.35) / 128), r);
        }
    } else {
        set_move(fd, G_MV_HITSTUN);
        fd->frame = 0;
        fd->stun = m->hitstun;
        fd->vx = m->push * away;
    }
}

static void animate(g_fighter *f)
{
    const g_move *m = &g_moves[f->move];
    f->frame++;
    if (f->stun > 0 && --f->stun == 0 && (f->move == G_MV_HITSTUN || f->move == G_MV_BLOCKSTUN ||
                                           f->move == G_MV_CROUCH_GUARD)) {
        set_move(f, f->move == G_MV_CROUCH_GUARD ? G_MV_CROUCH_GUARD : G_MV_IDLE);
        return;
    }
    if ((f->move == G_MV_HITSTUN || f->move == G_MV_BLOCKSTUN) && f->stun <= 0) {
        set_move(f, G_MV_IDLE); /* never held in a stun state without stun */
        return;
    }
    if (f->frame < m->frames)
        return;
    switch (m->end) {
    case G_END_LOOP: f->frame = 0; break;
    case G_END_HOLD:
        f->frame = m->frames - 1;
        if (f->move == G_MV_KNOCKDOWN && f->y == 0)
            set_move(f, G_MV_GETUP);
        break;
    default: set_move(f, m->kind == G_CROUCHING && (f->prev_input & G_IN_DOWN) ? G_MV_CROUCH : G_MV_IDLE); break;
    }
}

static void end_round(g_state *st, int result, int winner, g_events *ev)
{
    st->phase = G_PHASE_ROUND_END;
    st->phase_ticks = 0;
    st->round_result = result;
    st->round_winner = winner;
    if (winner)
        st->f[winner - 1].rounds_won++;
    if (result == G_RES_KO || result == G_RES_RING_OUT || result == G_RES_TIME)
        emit(ev, result == G_RES_KO ? G_EV_KO : result == G_RES_RING_OUT ? G_EV_RING_OUT : G_EV_TIME_UP, winner, 0);
    emit(ev, winner ? G_EV_ROUND_WIN : G_EV_DRAW, winner, st->round);
}

static void check_round_over(g_state *st, g_events *ev)
{
    fx edge = g_stages[st->stage].ring_half;
    bool ko[2], out[2];
    for (int i = 0; i < 2; i++) {
        ko[i] = st->f[i].health <= 0;
        out[i] = fx_abs(st->f[i].x) > edge;
    }
    if (ko[0] || ko[1]) {
        end_round(st, ko[0] && ko[1] ? G_RES_DRAW : G_RES_KO, ko[0] && ko[1] ? 0 : ko[0] ? 2 : 1, ev);
    } else if (out[0] || out[1]) {
        end_round(st, out[0] && out[1] ? G_RES_DRAW : G_RES_RING_OUT, out[0] && out[1] ? 0 : out[0] ? 2 : 1, ev);
    } else if (st->round_timer <= 0) {
        int h0 = st->f[0].health, h1 = st->f[1].health;
        end_round(st, G_RES_TIME, h0 > h1 ? 1 : h1 > h0 ? 2 : 0, ev);
    }
}

static void after_round(g_state *st, g_events *ev)
{
    int w0 = st->f[0].rounds_won, w1 = st->f[1].rounds_won;
    if (w0 >= G_ROUNDS_TO_WIN || w1 >= G_ROUNDS_TO_WIN || st->round >= G_MAX_ROUNDS) {
        st->phase = G_PHASE_MATCH_END;
        st->phase_ticks = 0;
        st->match_winner = w0 > w1 ? 1 : w1 > w0 ? 2 : 0;
        if (st->match_winner)
            set_move(&st->f[st->match_winner - 1], G_MV_WIN);
        emit(ev, G_EV_MATCH_WIN, st->match_winner, st->matches + 1);
    } else {
        start_round(st, false);
        emit(ev, G_EV_ROUND, 0, st->round);
    }
}

void g_step(g_state *st, const g_input in_raw[2], g_events *ev)
{
    if (ev)
        ev->n = 0;
    g_input in[2] = {g_input_clean(in_raw[0]), g_input_clean(in_raw[1])};
    st->tick++;
    st->input_digest = g_fnv1a(st->input_digest, in, 2);
    st->phase_ticks++;
    if (st->tick == 1)
        emit(ev, G_EV_ROUND, 0, st->round);

    if (st->flash > 0)
        st->flash--;
    if (st->flash_in > 0 && --st->flash_in == 0) {
        st->flash = 8;
        st->flash_in = 300 + (int32_t)(rng_next(&st->rng) % 900);
        emit(ev, G_EV_LIGHTNING, 0, 0);
    }

    for (int i = 0; i < 2; i++)
        track_motion(&st->f[i], in[i]);

    switch (st->phase) {
    case G_PHASE_INTRO:
        if (st->phase_ticks == 60)
            emit(ev, G_EV_FIGHT, 0, st->round);
        if (st->phase_ticks >= G_INTRO_TICKS) {
            st->phase = G_PHASE_FIGHT;
            st->phase_ticks = 0;
        }
        break;
    case G_PHASE_FIGHT:
        st->round_timer--;
        for (int i = 0; i < 2; i++)
            control(st, i, in[i], ev);
        break;
    case G_PHASE_ROUND_END:
        if (st->phase_ticks >= G_ROUND_END_TICKS) {
            after_round(st, ev);
            goto done;
        }
        break;
    case G_PHASE_MATCH_END:
        if (st->phase_ticks >= G_MATCH_END_TICKS) {
            st->matches++;
            start_round(st, true);
            emit(ev, G_EV_ROUND, 0, st->round);
            goto done;
        }
        break;
    }

    for (int i = 0; i < 2; i++)
        physics(st, i);
    separate(st);
    if (st->phase == G_PHASE_FIGHT) {
        /* both attacks are tested before either lands: trades are fair */
        bool hit0 = attack_connects(st, 0, 1), hit1 = attack_connects(st, 1, 0);
        if (hit0 || hit1) {
            g_state before = *st;
            if (hit0)
                apply_hit(st, &before, 0, 1, ev);
            if (hit1)
                apply_hit(st, &before, 1, 0, ev);
        }
    }
    for (int i = 0; i < 2; i++)
        animate(&st->f[i]);
    face_each_other(st);
    if (st->phase == G_PHASE_FIGHT)
        check_round_over(st, ev);
done:
    for (int i = 0; i < 2; i++)
        st->f[i].prev_input = in[i];
}

/* --- canonical serialisation and hash --- */

static uint8_t *put32(uint8_t *p, int32_t v)
{
    uint32_t u = (uint32_t)v;
    for (int k = 0; k < 4; k++)
        *p++ = (uint8_t)(u >> (8 * k));
    return p;
}

static uint8_t *put64(uint8_t *p, uint64_t v)
{
    for (int k = 0; k < 8; k++)
        *p++ = (uint8_t)(v >> (8 * k));
    return p;
}

size_t g_serialize(const g_state *st, uint8_t *buf)
{
    uint8_t *p = buf;
    p = put64(p, st->tick);
    p = put64(p, st->rng);
    const int32_t top[] = {st->stage, st->phase, st->phase_ticks, st->round, st->round_timer, st->round_result,
                           st->round_winner, st->match_winner, st->matches, st->flash_in, st->flash};
    for (size_t k = 0; k < sizeof top / sizeof top[0]; k++)
        p = put32(p, top[k]);
    p = put64(p, st->input_digest);
    for (int i = 0; i < 2; i++) {
        const g_fighter *f = &st->f[i];
        const int32_t v[] = {f->x, f->y, f->vx, f->vy, f->facing, f->move, f->frame, f->health, f->stun, f->hit_done,
                             f->rounds_won, f->prev_input, f->hits, f->specials};
        for (size_t k = 0; k < sizeof v / sizeof v[0]; k++)
            p = put32(p, v[k]);
        for (int k = 0; k < G_HIST; k++) {
            p = put32(p, f->hist_dir[k]);
            p = put32(p, f->hist_age[k]);
        }
    }
    /* holes exist only on destructible stages: every other stage's hashes
     * (and its replays' checkpoints) stay what they were */
    if (st->stage >= 0 && st->stage < G_STAGES && g_stages[st->stage].destructible) {
        int n = st->nholes < 0 ? 0 : st->nholes > G_MAX_HOLES ? G_MAX_HOLES : st->nholes;
        p = put32(p, st->nholes);
        p = put32(p, st->hole_seq);
        for (int k = 0; k < n; k++) {
            p = put32(p, st->holes[k].x);
            p = put32(p, st->holes[k].z);
            p = put32(p, st->holes[k].r);
            p = put32(p, st->holes[k].id);
        }
    }
    return (size_t)(p - buf);
}

uint64_t g_fnv1a(uint64_t h, const void *data, size_t n)
{
    const uint8_t *p = data;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

uint64_t g_hash(const g_state *st)
{
    uint8_t buf[G_STATE_BYTES];
    size_t n = g_serialize(st, buf);
    return g_fnv1a(G_FNV_OFFSET, buf, n);
}

const char *g_event_name(int type)
{
    static const char *const names[G_EV_COUNT] = {"round", "fight", "hit", "block", "special", "knockdown", "ko",
                                                  "ring_out", "time_up", "round_win", "draw", "match_win",
                                                  "lightning"};
    return type >= 0 && type < G_EV_COUNT ? names[type] : "?";
}
