/* Destruction holes (docs/effects.md, "Destruction holes") as game state:
 * where heavy hits leave craters in the ring floor of a destructible
 * stage.  The renderer draws them with stencil (runtime/fx/fx_holes.c); here
 * they are only placed, kept from overlapping and capped, in fixed point, so
 * a replay makes the same holes on every machine. */
#include "g_local.h"

bool g_holes_overlap(const g_hole *a, const g_hole *b)
{
    /* the spheres that cut them (r; the rim at the floor is 0.92 r), with
     * 5 cm between: no two hole volumes ever intersect, above the floor
     * or below it */
    int64_t dx = (int64_t)a->x - b->x, dz = (int64_t)a->z - b->z;
    int64_t reach = (int64_t)a->r + b->r + FX(0.05);
    return dx * dx + dz * dz < reach * reach;
}

/* The camera of r_game_camera_parts: eye (mid, 1.7, dist), looking at
 * (mid, 1, 0), dist = 4.2 + 0.9 gap, vertical field of view 0.75 rad, 16:9.
 * A point p = (x, 0, z): its depth along the view axis a = (0, -0.7, -dist)
 * / L is (1.19 + dist (dist - z)) / L, its height in the view
 * (-dist - 0.7 z) / L and its side offset x - mid.  Everything is compared
 * times L (L ~ dist + 0.245 / dist), so there is no square root. */
bool g_hole_in_view(const g_state *st, const g_hole *h)
{
    fx x0 = st->f[0].x, x1 = st->f[1].x;
    fx mid = x0 / 2 + x1 / 2, gap = fx_abs(x1 - x0);
    fx dist = FX(4.2) + fx_mul(gap, FX(0.9));
    fx dz = dist - h->z;
    if (dz < FX(0.2))
        return false; /* beside or behind the eye */
    fx L = dist + fx_div(FX(0.245), dist);
    fx depth_L = FX(1.19) + fx_mul(dist, dz);
    fx side_L = fx_mul(fx_abs(h->x - mid) - h->r, L);
    fx up_L = fx_abs(-dist - fx_mul(FX(0.7), h->z)) - fx_mul(h->r, L);
    /* tan(0.375) = 0.39265; times 16/9 = 0.69805 */
    return side_L <= fx_mul(FX(0.69805), depth_L) && up_L <= fx_mul(FX(0.39265), depth_L);
}

bool g_hole_add(g_state *st, fx x, fx z, fx r)
{
    if (st->stage < 0 || st->stage >= G_STAGES || r <= 0)
        return false;
    fx half = g_stages[st->stage].ring_half;
    fx lim = half - fx_mul(r, FX(0.92)) - FX(0.05); /* the rim stays on the ring top */
    if (lim <= 0)
        return false;
    /* candidates: the spot, then further and further across the ring */
    static const fx across[] = {0, FX(0.9), FX(-0.9), FX(1.8), FX(-1.8), FX(2.7), FX(-2.7)};
    g_hole h = {fx_clamp(x, -lim, lim), 0, r, 0};
    int n = st->nholes < 0 ? 0 : st->nholes > G_MAX_HOLES ? G_MAX_HOLES : st->nholes;
    bool found = false;
    for (size_t c = 0; c < sizeof across / sizeof across[0] && !found; c++) {
        h.z = fx_clamp(z + across[c], -lim, lim);
        found = true;
        for (int k = 0; k < n && found; k++)
            found = !g_holes_overlap(&h, &st->holes[k]);
    }
    if (!found)
        return false;
    if (n == G_MAX_HOLES) { /* full: the oldest out of sight goes, else the oldest */
        int victim = 0;
        for (int k = 0; k < n; k++)
            if (!g_hole_in_view(st, &st->holes[k])) {
                victim = k;
                break;
            }
        for (int k = victim; k + 1 < n; k++) /* keep creation order */
            st->holes[k] = st->holes[k + 1];
        n--;
    }
    h.id = ++st->hole_seq;
    st->holes[n++] = h;
    st->nholes = n;
    return true;
}
