/* Stage effects: the module list and what the modules share (r_fx.h). */
#include "r_fx.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../game/g_game.h"

extern const r_fx_module r_fx_water_module, r_fx_snow_module, r_fx_fog_module, r_fx_afterimage_module,
    r_fx_lspsm_module, r_fx_holes_module;

const r_fx_module *const r_fx_modules[] = {
    &r_fx_fog_module,   /* first: the fog map is read by every later scene draw */
    &r_fx_lspsm_module, /* the shadow map, read by every later scene draw */
    &r_fx_holes_module, /* before the other surfaces: it clears the frame (steps 1-3 of D) */
    &r_fx_water_module,
    &r_fx_snow_module,
    &r_fx_afterimage_module,
};
const int r_fx_nmodules = (int)(sizeof r_fx_modules / sizeof r_fx_modules[0]);

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
