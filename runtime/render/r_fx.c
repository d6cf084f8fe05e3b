/* Stage effects: what the core does with the modules (r_fx.h): their
 * states, texture units, scene hooks and history; and what the modules
 * share (contacts).  The module table is runtime/fx/fx_table.c. */
#include "r_fx.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../game/g_game.h"
#include "r_local.h"

static int index_of(const r_fx_module *m)
{
    for (int i = 0; i < r_fx_nmodules; i++)
        if (r_fx_modules[i] == m)
            return i;
    return -1;
}

void *r_fx_state(const r_game *r, const r_fx_module *m)
{
    int i = index_of(m);
    return i >= 0 ? r->fx_state[i] : NULL;
}

void r_fx_set_state(r_game *r, const r_fx_module *m, void *state)
{
    int i = index_of(m);
    if (i >= 0)
        r->fx_state[i] = state;
}

const frame *r_fx_frame(const r_game *r)
{
    return &r->f;
}

const r_stage *r_fx_stage(const r_game *r)
{
    return &r->stage;
}

int r_fx_stage_game(const r_game *r)
{
    return r->stage_game;
}

const float *r_fx_key_dir(const r_game *r)
{
    return r->key_dir;
}

const r_quality *r_fx_quality(const r_game *r)
{
    return &r->opts.q;
}

int r_fx_mesh_lod(const r_game *r)
{
    return (int)(r->fighter - r->fighter_lod);
}

r_fx_gl r_fx_core_gl(const r_game *r)
{
    r_fx_gl g = {
        .hdr_fbo = r->hdr_fbo,
        .hdr_tex = r->hdr_tex,
        .depth_tex = r->depth_tex,
        .sil_tex = r->sil_tex,
        .sky_tex = r->sky_tex,
        .diffuse_on = r->ibl_tex[R_IBL_DIFFUSE][R_IBL_KEY_ON],
        .empty_vao = r->empty_vao,
        .fighter_vao = r->fighter->vao,
        .ring_vao = r->ring_vao,
        .fighter_count = r->fighter->count,
        .ring_count = r->ring_count,
        .prog_depth = r->prog[P_DEPTH],
        .prog_sky = r->prog[P_SKY],
    };
    memcpy(g.fighter_bone_first, r->fighter->bone_first, sizeof g.fighter_bone_first);
    g.whole_meshes = r->opts.whole_meshes;
    return g;
}

int r_fx_units(void)
{
    int n = 0;
    for (int i = 0; i < r_fx_nmodules; i++)
        n += r_fx_modules[i]->bind ? r_fx_modules[i]->units : 0;
    return n;
}

void r_fx_bind(r_game *r, GLuint p, int what)
{
    int unit = R_FX_UNIT_FIRST;
    for (int i = 0; i < r_fx_nmodules; i++) {
        const r_fx_module *m = r_fx_modules[i];
        if (!m->bind)
            continue;
        m->bind(r, p, unit, what);
        unit += m->units;
    }
}

bool r_fx_scene_cleared(r_game *r)
{
    for (int i = 0; i < r_fx_nmodules; i++)
        if (r_fx_modules[i]->scene_cleared && r_fx_modules[i]->scene_cleared(r))
            return true;
    return false;
}

bool r_fx_draw_ring(r_game *r)
{
    for (int i = 0; i < r_fx_nmodules; i++)
        if (r_fx_modules[i]->draw_ring && r_fx_modules[i]->draw_ring(r))
            return true;
    return false;
}

void r_fx_scene_depth(r_game *r, GLuint depth_prog)
{
    for (int i = 0; i < r_fx_nmodules; i++)
        if (r_fx_modules[i]->scene_depth)
            r_fx_modules[i]->scene_depth(r, depth_prog);
}

int r_fx_warmup(r_game *r, const r_fx_module *m)
{
    return m->warmup ? m->warmup(r) : R_FX_STATELESS;
}

int64_t r_fx_history(r_game *r)
{
    int64_t most = 0;
    for (int i = 0; i < r_fx_nmodules; i++) {
        int w = r_fx_warmup(r, r_fx_modules[i]);
        if (w == R_FX_FROM_START)
            return R_FX_FROM_START;
        if (w > most)
            most = w;
    }
    return most;
}

bool r_fx_needs_frame(r_game *r, uint64_t ahead)
{
    for (int i = 0; i < r_fx_nmodules; i++) {
        const r_fx_module *m = r_fx_modules[i];
        if (!m->needs_frame)
            continue;
        int w = r_fx_warmup(r, m);
        bool in_window = w == R_FX_FROM_START || (w > 0 && ahead <= (uint64_t)w);
        if (in_window && m->needs_frame(r))
            return true;
    }
    return false;
}

void r_fx_advance(r_game *r)
{
    for (int i = 0; i < r_fx_nmodules; i++)
        if (r_fx_modules[i]->advance)
            r_fx_modules[i]->advance(r);
}

static int deeper_first(const void *a, const void *b)
{
    const r_fx_contact *x = a, *y = b;
    return (x->depth < y->depth) - (x->depth > y->depth);
}

int r_fx_contacts(const r_fx_capsule caps[2][G_BONES], const r_fx_capsule prev[2][G_BONES], float level, r_fx_contact *out,
                  int max)
{
    r_fx_contact all[2 * G_BONES];
    int n = 0;
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < G_BONES; k++) {
            const r_fx_capsule *c = &caps[i][k], *p = &prev[i][k];
            /* the lowest point of the segment: an end, or either (a flat bone) */
            float t = c->a[1] <= c->b[1] ? 0.0f : 1.0f;
            float y = c->a[1] + (c->b[1] - c->a[1]) * t;
            float depth = level - (y - c->r);
            if (!(depth > 0)) /* also NaN */
                continue;
            r_fx_contact *o = &all[n++];
            float cur[3], old[3];
            for (int a = 0; a < 3; a++) {
                cur[a] = c->a[a] + (c->b[a] - c->a[a]) * t;
                old[a] = p->a[a] + (p->b[a] - p->a[a]) * t;
                o->vel[a] = (cur[a] - old[a]) * (float)G_HZ; /* one tick apart */
            }
            o->x = cur[0], o->z = cur[2];
            o->depth = depth > 2 * c->r ? 2 * c->r : depth;
            o->radius = c->r;
            o->speed = sqrtf(o->vel[0] * o->vel[0] + o->vel[1] * o->vel[1] + o->vel[2] * o->vel[2]);
            if (!isfinite(o->speed))
                o->speed = 0, memset(o->vel, 0, sizeof o->vel);
            o->fighter = i, o->bone = k;
        }
    if (n > max) {
        qsort(all, (size_t)n, sizeof all[0], deeper_first);
        n = max;
    }
    if (n > 0)
        memcpy(out, all, (size_t)n * sizeof *out);
    return n < 0 ? 0 : n;
}
