#include "g_skel.h"

const g_bone_def g_bones[G_BONES] = {
    [G_PELVIS] = {"pelvis", -1, FX(0.16), FX(0.14), 0},
    [G_SPINE] = {"spine", G_PELVIS, FX(0.22), FX(0.14), 0},
    [G_CHEST] = {"chest", G_SPINE, FX(0.22), FX(0.17), 0},
    [G_NECK] = {"neck", G_CHEST, FX(0.07), FX(0.05), 0},
    [G_HEAD] = {"head", G_NECK, FX(0.20), FX(0.11), 0},
    [G_L_UPPERARM] = {"l_upperarm", G_CHEST, FX(0.28), FX(0.055), FX(0.21)},
    [G_L_FOREARM] = {"l_forearm", G_L_UPPERARM, FX(0.28), FX(0.05), FX(0.21)},
    [G_R_UPPERARM] = {"r_upperarm", G_CHEST, FX(0.28), FX(0.055), FX(-0.21)},
    [G_R_FOREARM] = {"r_forearm", G_R_UPPERARM, FX(0.28), FX(0.05), FX(-0.21)},
    [G_L_THIGH] = {"l_thigh", -1, FX(0.44), FX(0.08), FX(0.1)},
    [G_L_SHIN] = {"l_shin", G_L_THIGH, FX(0.44), FX(0.06), FX(0.1)},
    [G_L_FOOT] = {"l_foot", G_L_SHIN, FX(0.17), FX(0.045), FX(0.1)},
    [G_R_THIGH] = {"r_thigh", -1, FX(0.44), FX(0.08), FX(-0.1)},
    [G_R_SHIN] = {"r_shin", G_R_THIGH, FX(0.44), FX(0.06), FX(-0.1)},
    [G_R_FOOT] = {"r_foot", G_R_SHIN, FX(0.17), FX(0.045), FX(-0.1)},
};

void g_skel_solve(const g_pose *pose, fx x, fx y, int facing, g_capsule out[G_BONES])
{
    /* parents come before children in the table, so one pass suffices */
    fx hx = pose->root_dx, hy = G_HIP_HEIGHT + pose->root_dy;
    for (int i = 0; i < G_BONES; i++) {
        const g_bone_def *b = &g_bones[i];
        fang abs = pose->ang[i];
        fx sx = hx, sy = hy;
        if (b->parent >= 0) {
            sx = out[b->parent].bx;
            sy = out[b->parent].by;
        }
        out[i].angle = abs;
        out[i].ax = sx;
        out[i].ay = sy;
        out[i].bx = sx + fx_mul(b->length, fx_cos(abs));
        out[i].by = sy + fx_mul(b->length, fx_sin(abs));
        out[i].r = b->radius;
        out[i].z = b->z;
    }
    /* to world: mirror by facing, then translate (after the chain, so the
     * chain itself is solved once in the fighter's own frame) */
    for (int i = 0; i < G_BONES; i++) {
        out[i].ax = x + (facing < 0 ? -out[i].ax : out[i].ax);
        out[i].bx = x + (facing < 0 ? -out[i].bx : out[i].bx);
        out[i].ay += y;
        out[i].by += y;
    }
}

void g_skel_waist(const g_capsule caps[G_BONES], fx *x, fx *y)
{
    *x = caps[G_PELVIS].bx;
    *y = caps[G_PELVIS].by;
}

static int64_t clamp_t(int64_t num, int64_t den)
{
    /* parameter t = num/den clamped to [0,1], as Q16 */
    if (den <= 0 || num <= 0)
        return 0;
    if (num >= den)
        return 65536;
    return (num * 65536) / den;
}

static int64_t pt_seg_dist2(fx px, fx py, fx ax, fx ay, fx bx, fx by)
{
    int64_t ux = (int64_t)bx - ax, uy = (int64_t)by - ay;
    int64_t wx = (int64_t)px - ax, wy = (int64_t)py - ay;
    int64_t t = clamp_t(wx * ux + wy * uy, ux * ux + uy * uy);
    int64_t cx = ax + ((ux * t) >> 16), cy = ay + ((uy * t) >> 16);
    int64_t dx = px - cx, dy = py - cy;
    /* positions stay within a few metres (|d| < 2^22 in Q16), so d*d fits */
    const int64_t lim = (int64_t)1 << 30;
    if (dx > lim || dx < -lim || dy > lim || dy < -lim)
        return INT64_MAX / 4;
    return (dx * dx + dy * dy) >> 16;
}

static int orient(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t cx, int64_t cy)
{
    /* inputs are Q16 metres bounded by the ring: products fit in int64 */
    int64_t v = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
    return (v > 0) - (v < 0);
}

int64_t g_seg_dist2(fx ax, fx ay, fx bx, fx by, fx cx, fx cy, fx dx, fx dy)
{
    /* crossing segments touch */
    int o1 = orient(ax, ay, bx, by, cx, cy), o2 = orient(ax, ay, bx, by, dx, dy);
    int o3 = orient(cx, cy, dx, dy, ax, ay), o4 = orient(cx, cy, dx, dy, bx, by);
    if (o1 * o2 < 0 && o3 * o4 < 0)
        return 0;
    int64_t m = pt_seg_dist2(ax, ay, cx, cy, dx, dy), d;
    if ((d = pt_seg_dist2(bx, by, cx, cy, dx, dy)) < m)
        m = d;
    if ((d = pt_seg_dist2(cx, cy, ax, ay, bx, by)) < m)
        m = d;
    if ((d = pt_seg_dist2(dx, dy, ax, ay, bx, by)) < m)
        m = d;
    return m;
}

bool g_capsules_touch(const g_capsule *a, const g_capsule *b)
{
    int64_t r = (int64_t)a->r + b->r;
    return g_seg_dist2(a->ax, a->ay, a->bx, a->by, b->ax, b->ay, b->bx, b->by) <= (r * r) >> 16;
}
