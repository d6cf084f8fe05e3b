/* runtime/render/r_lspsm: Light Space Perspective Shadow Maps, CPU side
 * (techniques C): the light's matrices, the fallback to uniform shadow
 * mapping, the depth auto-focus, the fade, caster culling, the fighters'
 * box-exit lookup and the static layers' matrices. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/render/r_lspsm.h"
#include "t.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180)

/* ---- helpers ---- */

/* xorshift64, seeded by each randomized case (the same points with T_NOFORK=1) */
static uint64_t rng;
static void seed(void) { rng = 0x9e3779b97f4a7c15ull; }
static double urand(void) /* [0, 1) */
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (double)(rng >> 11) / 9007199254740992.0;
}
static double urange(double a, double b) { return a + (b - a) * urand(); }
static r_vec3 rand_unit(void)
{
    for (;;) {
        r_vec3 v = r_v3((float)urange(-1, 1), (float)urange(-1, 1), (float)urange(-1, 1));
        float l = r_dot(v, v);
        if (l > 0.01f && l <= 1)
            return r_norm(v);
    }
}
static r_vec3 add(r_vec3 a, r_vec3 b) { return r_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static r_vec3 scale(r_vec3 a, double s) { return r_v3((float)(a.x * s), (float)(a.y * s), (float)(a.z * s)); }
static r_vec3 mix3(r_vec3 a, double ca, r_vec3 b, double cb) { return add(scale(a, ca), scale(b, cb)); }

static bool mat_finite(const r_mat4 *m)
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(m->m[i]))
            return false;
    return true;
}

/* clip coordinates of p under m, in double */
static void clip(const r_mat4 *m, r_vec3 p, double c[4])
{
    for (int r = 0; r < 4; r++)
        c[r] = (double)m->m[r] * p.x + (double)m->m[4 + r] * p.y + (double)m->m[8 + r] * p.z + m->m[12 + r];
}

/* Camera basis as r_lspsm_build sees it (up made perpendicular). */
typedef struct { r_vec3 v, u, r; } basis;
static basis cam_basis(const r_lspsm_camera *c)
{
    basis b;
    b.v = r_norm(c->dir);
    b.u = r_norm(r_sub(c->up, scale(b.v, r_dot(c->up, b.v))));
    b.r = r_cross(b.v, b.u);
    return b;
}

/* A point of the body (the frustum between s->near and s->far):
 * a, b in -1..1 across, c in 0..1 from near to far. */
static r_vec3 body_point(const r_lspsm_camera *cam, const r_lspsm *s, double a, double b, double c)
{
    basis k = cam_basis(cam);
    double z = s->near + c * (s->far - s->near), hy = z * tan(cam->fovy / 2), hx = hy * cam->aspect;
    return add(add(add(cam->eye, scale(k.v, z)), scale(k.u, b * hy)), scale(k.r, a * hx));
}

/* The game camera's framing (r_game_camera): 1.7 m high, 6 m back. */
static r_lspsm_camera game_cam(void)
{
    r_mat4 view = r_look_at(r_v3(0, 1.7f, 6), r_v3(0, 1, 0), r_v3(0, 1, 0));
    return r_lspsm_camera_from(view, r_perspective(0.75f, 16.0f / 9, 0.1f, 200));
}

/* The light gamma from the view direction, turned towards the camera's up. */
static r_vec3 light_at(const r_lspsm_camera *c, double gamma)
{
    basis b = cam_basis(c);
    return mix3(b.v, cos(gamma), b.u, sin(gamma));
}

/* Checks the body (corners and random points) and the casters above it land
 * in the unit cube, and the fit is tight on x and y. */
static void check_cube(const r_lspsm_desc *d, const char *what)
{
    r_lspsm s;
    r_lspsm_build(d, &s);
    T_ASSERTF(mat_finite(&s.light_vp) && mat_finite(&s.shadow), "%s: matrix not finite", what);
    T_ASSERTF(isfinite(s.gamma) && isfinite(s.warp) && s.warp >= 0, "%s: gamma %g warp %g", what, s.gamma, s.warp);
    const double eps = 2e-4; /* float rounding: a tenth of a texel (2 / 1024 in NDC) */
    double reach = d->caster_reach > 0 ? d->caster_reach : R_LSPSM_CASTER_REACH, xmax = 0, ymax = 0;
    r_vec3 L = r_norm(d->to_light);
    for (int k = 0; k < 8 + 40; k++) {
        double zr = 0;
        r_vec3 p = k < 8 ? body_point(&d->cam, &s, k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : 0)
                         : body_point(&d->cam, &s, urange(-1, 1), urange(-1, 1), urand());
        for (int e = 0; e < 3; e++) {
            /* e = 1, 2: a caster above the point, up to caster_reach */
            r_vec3 q = e == 0 ? p : add(p, scale(L, e == 1 ? reach : reach * urand()));
            double c[4];
            clip(&s.light_vp, q, c);
            T_ASSERTF(c[3] > 0, "%s: point %d (%d) behind the warp: w %g", what, k, e, c[3]);
            double x = c[0] / c[3], y = c[1] / c[3], z = c[2] / c[3];
            T_ASSERTF(fabs(x) <= 1 + eps && fabs(y) <= 1 + eps && fabs(z) <= 1 + eps,
                      "%s: point %d (caster %d) maps to %.6f %.6f %.6f (gamma %.9f, warp %g)", what, k, e, x, y, z,
                      s.gamma, s.warp);
            if (e == 0 && k < 8)
                xmax = fmax(xmax, fabs(x)), ymax = fmax(ymax, fabs(y));
            if (e == 0)
                zr = z;
            else /* a caster lies nearer the light than what it shades: less depth */
                T_ASSERTF(z <= zr + 1e-6, "%s: caster depth %.6f behind its receiver's %.6f", what, z, zr);
            if (e == 0 && k >= 8 && k < 12) {
                /* the receivers' matrix is the same map in 0..1 */
                double t[4];
                clip(&s.shadow, q, t);
                T_ASSERTF(fabs(t[0] / t[3] - (x + 1) / 2) < 1e-4 && fabs(t[1] / t[3] - (y + 1) / 2) < 1e-4 &&
                              fabs(t[2] / t[3] - (z + 1) / 2) < 1e-4,
                          "%s: shadow matrix disagrees with light_vp", what);
            }
        }
    }
    T_ASSERTF(xmax > 1 - eps && ymax > 1 - eps, "%s: fit not tight: %.4f %.4f", what, xmax, ymax);
}

/* ---- the light's matrices ---- */

static void t_unit_cube_random(void)
{
    seed();
    char what[160];
    for (int i = 0; i < 4000; i++) {
        r_lspsm_desc d = {0};
        d.cam.eye = r_v3((float)urange(-60, 60), (float)urange(0, 30), (float)urange(-60, 60));
        d.cam.dir = rand_unit();
        d.cam.up = urand() < 0.5 ? r_v3(0, 1, 0) : rand_unit();
        d.cam.fovy = (float)urange(0.2, 1.6);
        d.cam.aspect = (float)urange(0.5, 2.5);
        d.cam.near = (float)urange(0.05, 1);
        d.cam.far = (float)urange(d.cam.near * 20, 400);
        double pick = urand();
        /* light: anywhere, or within a few degrees of (anti-)parallel */
        if (pick < 0.5)
            d.to_light = rand_unit();
        else {
            r_vec3 side = r_norm(r_cross(d.cam.dir, rand_unit()));
            double g = pick < 0.7 ? urange(0, 25 * DEG) : pick < 0.9 ? PI - urange(0, 25 * DEG) : urange(0, 1e-5);
            d.to_light = mix3(r_norm(d.cam.dir), cos(g), side, sin(g));
        }
        if (urand() < 0.5)
            d.far = (float)urange(d.cam.near * 3, 120);
        d.uniform = urand() < 0.1;
        if (urand() < 0.2)
            d.caster_reach = (float)urange(1, 300);
        snprintf(what, sizeof what, "case %d", i);
        check_cube(&d, what);
    }
}

static void t_unit_cube_degenerate(void)
{
    seed();
    r_lspsm_camera g = game_cam();
    basis b = cam_basis(&g);
    struct {
        const char *what;
        r_vec3 eye, dir, up, light;
    } cases[] = {
        {"parallel", g.eye, g.dir, g.up, b.v},
        {"anti-parallel", g.eye, g.dir, g.up, scale(b.v, -1)},
        {"1e-6 rad", g.eye, g.dir, g.up, mix3(b.v, cos(1e-6), b.u, sin(1e-6))},
        {"pi - 1e-6 rad", g.eye, g.dir, g.up, mix3(b.v, -cos(1e-6), b.u, sin(1e-6))},
        {"1e-6 rad sideways", g.eye, g.dir, g.up, mix3(b.v, cos(1e-6), b.r, sin(1e-6))},
        {"light straight down", g.eye, g.dir, g.up, r_v3(0, 1, 0)},
        {"camera straight down, light straight down", r_v3(3, 20, 2), r_v3(0, -1, 0), r_v3(0, 0, -1), r_v3(0, 1, 0)},
        {"camera straight down, tilted light", r_v3(3, 20, 2), r_v3(0, -1, 0), r_v3(0, 0, -1), r_norm(r_v3(1, 3, 0))},
        {"camera straight up, light straight down", r_v3(0, 2, 0), r_v3(0, 1, 0), r_v3(1, 0, 0), r_v3(0, 1, 0)},
        {"up parallel to dir", g.eye, r_v3(0, -1, 0), r_v3(0, 1, 0), r_v3(0, 1, 0)},
        {"zero light", g.eye, g.dir, g.up, r_v3(0, 0, 0)},
        {"zero dir", g.eye, r_v3(0, 0, 0), g.up, r_v3(0, 1, 0)},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        for (int u = 0; u < 2; u++) {
            r_lspsm_desc d = {.cam = g, .to_light = cases[i].light, .uniform = u};
            d.cam.eye = cases[i].eye, d.cam.dir = cases[i].dir, d.cam.up = cases[i].up;
            r_lspsm s;
            r_lspsm_build(&d, &s);
            T_ASSERTF(mat_finite(&s.light_vp) && mat_finite(&s.shadow), "%s: not finite", cases[i].what);
            if (r_dot(d.cam.dir, d.cam.dir) == 0 || r_dot(d.to_light, d.to_light) == 0)
                continue; /* the defaults stand in: finite is all we ask */
            if (i < 9)
                check_cube(&d, cases[i].what);
            if (i < 2 || i == 6)
                T_ASSERTF(s.warp == 0 && isinf(s.n), "%s: warp %g", cases[i].what, s.warp);
        }
    }
}

/* ---- texel density: more near the camera, the same as uniform in the fallback ---- */

/* LSPSM over uniform texels per metre at 2 m (and 50 m) on the view axis,
 * the light gamma from the view, turned towards `towards` (0 = the camera's
 * up, 1 = its right, 2 = the diagonal) */
static double near_ratio_cam(r_lspsm_camera cam, double gamma, int towards, double *far_ratio)
{
    r_lspsm_desc d = {.cam = cam};
    basis b = cam_basis(&d.cam);
    r_vec3 side = towards == 0 ? b.u : towards == 1 ? b.r : r_norm(add(b.u, b.r));
    d.to_light = mix3(b.v, cos(gamma), side, sin(gamma));
    r_lspsm ls, un;
    r_lspsm_build(&d, &ls);
    d.uniform = true;
    r_lspsm_build(&d, &un);
    r_vec3 pn = add(d.cam.eye, scale(b.v, 2)), pf = add(d.cam.eye, scale(b.v, 50));
    if (far_ratio)
        *far_ratio = r_lspsm_texels_per_metre(&ls, pf, R_LSPSM_MAP) / r_lspsm_texels_per_metre(&un, pf, R_LSPSM_MAP);
    return r_lspsm_texels_per_metre(&ls, pn, R_LSPSM_MAP) / r_lspsm_texels_per_metre(&un, pn, R_LSPSM_MAP);
}
static double near_ratio(double gamma, double *far_ratio) { return near_ratio_cam(game_cam(), gamma, 0, far_ratio); }

static void t_density(void)
{
    double fr, r90 = near_ratio(90 * DEG, &fr);
    printf("  light perpendicular: LSPSM / uniform texels per metre = %.2f at 2 m, %.3f at 50 m\n", r90, fr);
    T_ASSERTF(r90 > 3, "near ratio %.3f", r90);
    T_ASSERTF(fr < 1, "far ratio %.3f: the warp should spend the texels near", fr);
    /* near the camera never below uniform, whichever way the light turns;
     * towards the camera's up the gain grows with the angle */
    for (int towards = 0; towards < 3; towards++) {
        double prev = 1;
        for (int a = 0; a <= 180; a++) {
            double r = near_ratio_cam(game_cam(), a * DEG, towards, NULL);
            T_ASSERTF(r >= 1 - 1e-4, "%d deg (towards %d): near ratio %.4f", a, towards, r);
            if (towards == 0 && a <= 90)
                T_ASSERTF(r >= prev * (1 - 1e-4), "%d deg: near ratio %.4f after %.4f", a, r, prev);
            prev = r;
        }
    }
    /* at the band's end and beyond: uniform, parallel and anti-parallel */
    static const double flat[] = {R_LSPSM_BAND_END, 4 * DEG, 1 * DEG, 1e-6, 0, PI, PI - 1e-6, PI - 3 * DEG,
                                  PI - R_LSPSM_BAND_END};
    r_lspsm_camera narrow = game_cam();
    narrow.fovy = 0.1f, narrow.aspect = 1; /* the frustum's edges keep the warp on down to the band */
    for (size_t i = 0; i < sizeof flat / sizeof flat[0]; i++) {
        for (int c = 0; c < 2; c++) {
            double r = near_ratio_cam(c ? narrow : game_cam(), flat[i], 0, &fr);
            T_ASSERTF(fabs(r - 1) < 1e-3 && fabs(fr - 1) < 1e-3, "gamma %.6f rad: ratio %.5f near, %.5f far", flat[i],
                      r, fr);
        }
    }
    /* a narrow view: the angle band alone; just inside it, some warp */
    double in = near_ratio_cam(narrow, R_LSPSM_BAND_END + 2 * DEG, 0, NULL);
    double full = near_ratio_cam(narrow, R_LSPSM_BAND_START, 0, NULL);
    T_ASSERTF(in > 1.001 && in < full, "2 deg into the band: %.4f (%.4f at its start)", in, full);
}

/* ---- no pop: a sweep of the angle moves the map continuously ---- */

enum { NPTS = 240 };

/* Largest NDC move of the points that lie in the map at both steps. */
static double step_change(const r_lspsm *a, const r_lspsm *b, const r_vec3 *pts, int *inside)
{
    double worst = 0;
    *inside = 0;
    for (int i = 0; i < NPTS; i++) {
        double ca[4], cb[4];
        clip(&a->light_vp, pts[i], ca);
        clip(&b->light_vp, pts[i], cb);
        if (!(ca[3] > 0 && cb[3] > 0))
            continue;
        double m = 0;
        for (int k = 0; k < 3; k++) {
            double va = ca[k] / ca[3], vb = cb[k] / cb[3];
            if (!(fabs(va) <= 1.01 && fabs(vb) <= 1.01))
                m = -1;
            else if (m >= 0)
                m = fmax(m, fabs(va - vb));
        }
        if (m < 0)
            continue;
        (*inside)++;
        worst = fmax(worst, m);
    }
    return worst;
}

/* Sweeps gamma from 90 deg to `to` deg (0 or 180) in 0.01 deg steps, turning
 * the light (camera fixed) or the camera (light fixed, camera pitching with
 * its up leaning towards the light).  Returns the largest NDC move per
 * radian; fails on NaN. */
static double sweep(r_lspsm_camera g, double to_deg, bool turn_camera, const char *what)
{
    basis b = cam_basis(&g);
    r_vec3 sun = r_norm(r_v3(0.3f, 1, 0.4f)), P = r_norm(r_cross(sun, r_v3(1, 0, 0))); /* P perpendicular to sun */
    r_vec3 pts[NPTS];
    seed();
    for (int i = 0; i < NPTS; i++) {
        /* where the view passes: round the camera's path, or ahead of it */
        double phi = urange(0, PI);
        r_vec3 path = add(mix3(sun, cos(phi), P, sin(phi)), scale(r_cross(sun, P), urange(-0.04, 0.04)));
        r_vec3 dir = turn_camera ? path : add(b.v, add(scale(b.u, urange(-0.3, 0.3)), scale(b.r, urange(-0.6, 0.6))));
        pts[i] = add(g.eye, scale(r_norm(dir), urange(0.5, 95)));
    }
    const double step = 0.01 * DEG;
    int n = (int)lround(fabs(to_deg - 90) / 0.01), seen = 0;
    double worst = 0, worst_at = 0;
    r_lspsm prev = {0};
    for (int i = 0; i <= n; i++) {
        double gm = (90 + (to_deg > 90 ? 1 : -1) * 0.01 * i) * DEG;
        if (i == n)
            gm = to_deg * DEG; /* exactly */
        r_lspsm_desc d = {.cam = g};
        if (turn_camera) {
            d.to_light = sun;
            d.cam.dir = mix3(sun, cos(gm), P, sin(gm));
            d.cam.up = mix3(sun, sin(gm), P, -cos(gm));
        } else {
            d.to_light = light_at(&g, gm);
        }
        r_lspsm s;
        r_lspsm_build(&d, &s);
        T_ASSERTF(mat_finite(&s.light_vp) && isfinite(s.warp), "%s: NaN at %.4f deg", what, gm / DEG);
        if (i > 0) {
            int in;
            double c = step_change(&prev, &s, pts, &in) / step;
            seen += in > 0;
            if (c > worst)
                worst = c, worst_at = gm / DEG;
            T_ASSERTF(c < 30, "%s: points moved %.3f NDC per radian between %.2f and %.4f deg", what, c,
                      gm / DEG + (to_deg > 90 ? -0.01 : 0.01), gm / DEG);
        }
        prev = s;
    }
    T_ASSERTF(seen > n * 9 / 10, "%s: only %d of %d steps had points in the map", what, seen, n);
    printf("  %s: at most %.3f NDC per radian (at %.2f deg)\n", what, worst, worst_at);
    return worst;
}

static void t_no_pop(void)
{
    /* The natural rate: the warp grows over the angle bands (15 deg, and 10
     * deg of the frustum's edge) and moves points by up to ~1 NDC over them,
     * ~14 NDC per radian at most; the bound is 30 (2.7 texels per 0.01 deg
     * step).  A warp switched on or off at once moves points by ~0.1 NDC in
     * one step: hundreds per radian. */
    r_lspsm_camera g = game_cam(), narrow = g;
    narrow.fovy = 0.1f, narrow.aspect = 1; /* the angle band alone (the edges' band is the game view's) */
    sweep(g, 0, false, "light to parallel");
    sweep(g, 180, false, "light to anti-parallel");
    sweep(g, 0, true, "camera to parallel");
    sweep(g, 180, true, "camera to anti-parallel");
    sweep(narrow, 0, false, "narrow view, light to parallel");
    sweep(narrow, 180, true, "narrow view, camera to anti-parallel");
}

/* ---- auto-focus ---- */

static void t_focus_pattern(void)
{
    static const int sizes[][2] = {{640, 360}, {1280, 720}, {320, 320}, {1920, 1080}, {401, 333}, {40, 30}, {20, 16}};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        int w = sizes[s][0], h = sizes[s][1];
        static bool col[2000], row[2000], cell[R_LSPSM_FOCUS_N];
        memset(col, 0, sizeof col), memset(row, 0, sizeof row), memset(cell, 0, sizeof cell);
        int ncol = 0, nrow = 0;
        static int px[R_LSPSM_FOCUS_N], py[R_LSPSM_FOCUS_N];
        for (int k = 0; k < R_LSPSM_FOCUS_N; k++) {
            int x, y;
            r_lspsm_focus_point(k, w, h, &x, &y);
            T_ASSERTF(x >= 0 && x < w && y >= 0 && y < h, "%dx%d: sample %d at %d,%d", w, h, k, x, y);
            px[k] = x, py[k] = y;
            ncol += !col[x], nrow += !row[y];
            col[x] = row[y] = true;
            /* the cell holding the pixel's centre (from 320 pixels up a
             * sample's pixel centre stays in its cell) */
            int c = (int)((2L * y + 1) * R_LSPSM_FOCUS_H / (2L * h)) * R_LSPSM_FOCUS_W +
                    (int)((2L * x + 1) * R_LSPSM_FOCUS_W / (2L * w));
            T_ASSERTF(!cell[c] || w < R_LSPSM_FOCUS_N || h < R_LSPSM_FOCUS_N, "%dx%d: two samples in cell %d", w, h, c);
            cell[c] = true;
        }
        if (w >= R_LSPSM_FOCUS_N && h >= R_LSPSM_FOCUS_N) {
            /* tilted: no two samples share a column or a row */
            T_ASSERTF(ncol == R_LSPSM_FOCUS_N && nrow == R_LSPSM_FOCUS_N, "%dx%d: %d columns, %d rows", w, h, ncol,
                      nrow);
            /* so a horizontal edge (the horizon) moving up one row at a time
             * changes the count above it by at most one sample, where a
             * square 20x16 grid jumps by 20 */
            for (int axis = 0; axis < 2; axis++) {
                const int *pc = axis ? py : px;
                int prev = R_LSPSM_FOCUS_N;
                for (int e = 1; e <= (axis ? h : w); e++) {
                    int beyond = 0;
                    for (int k = 0; k < R_LSPSM_FOCUS_N; k++)
                        beyond += pc[k] >= e;
                    T_ASSERTF(prev - beyond <= 1, "%dx%d: edge at %s %d: %d -> %d", w, h, axis ? "row" : "column", e,
                              prev, beyond);
                    prev = beyond;
                }
            }
        } else if (w >= R_LSPSM_FOCUS_W * 2 && h >= R_LSPSM_FOCUS_H * 2) {
            T_ASSERTF(ncol > R_LSPSM_FOCUS_W && nrow > R_LSPSM_FOCUS_H, "%dx%d: %d columns, %d rows", w, h, ncol, nrow);
        }
    }
    /* gather reads those pixels */
    enum { W = 64, H = 48 };
    static float buf[W * H];
    for (int i = 0; i < W * H; i++)
        buf[i] = (float)i;
    float out[R_LSPSM_FOCUS_N];
    r_lspsm_focus_gather(buf, W, H, out);
    for (int k = 0; k < R_LSPSM_FOCUS_N; k++) {
        int x, y;
        r_lspsm_focus_point(k, W, H, &x, &y);
        T_ASSERT(out[k] == (float)(y * W + x));
    }
}

/* The game camera's last frame, and window depths of a wall at view depth D
 * (0: sky) at every sample. */
typedef struct { r_mat4 vp, inv; int w, h; } frame_cam;
static frame_cam focus_cam(void)
{
    frame_cam f = {.w = 640, .h = 360};
    r_mat4 view = r_look_at(r_v3(0, 1.7f, 6), r_v3(0, 1, 0), r_v3(0, 1, 0));
    f.vp = r_mul(r_perspective(0.75f, 16.0f / 9, 0.1f, 200), view);
    f.inv = r_invert(f.vp);
    return f;
}
static void wall(float depth[R_LSPSM_FOCUS_N], double D)
{
    const double n = 0.1, fa = 200;
    double z = (fa + n) / (fa - n) - 2 * fa * n / ((fa - n) * D);
    for (int k = 0; k < R_LSPSM_FOCUS_N; k++)
        depth[k] = D > 0 ? (float)(0.5 * z + 0.5) : 1.0f;
}
/* The farthest sample's distance, worked out here on its own. */
static double farthest_of(const frame_cam *f, const float depth[R_LSPSM_FOCUS_N])
{
    double far = 0;
    for (int k = 0; k < R_LSPSM_FOCUS_N; k++) {
        if (!(depth[k] >= 0 && depth[k] <= 1))
            continue;
        if (depth[k] == 1)
            return R_LSPSM_LIMIT;
        int x, y;
        r_lspsm_focus_point(k, f->w, f->h, &x, &y);
        r_vec3 ndc = r_v3((x + 0.5f) / f->w * 2 - 1, (y + 0.5f) / f->h * 2 - 1, depth[k] * 2 - 1);
        double c[4];
        clip(&f->inv, ndc, c);
        r_vec3 p = r_v3((float)(c[0] / c[3]), (float)(c[1] / c[3]), (float)(c[2] / c[3]));
        r_vec3 e = r_sub(p, r_v3(0, 1.7f, 6));
        far = fmax(far, sqrt(r_dot(e, e)));
    }
    return fmin(far, R_LSPSM_LIMIT);
}

/* the invariants after every update */
static void focus_ok(const r_lspsm_focus *f, double prev, const char *what)
{
    double target = fmin(fmax(f->farthest * (1 + R_LSPSM_MARGIN), R_LSPSM_MIN_RANGE), R_LSPSM_LIMIT);
    T_ASSERTF(isfinite(f->range) && f->range <= R_LSPSM_LIMIT && f->range >= R_LSPSM_MIN_RANGE, "%s: range %g", what,
              f->range);
    T_ASSERTF(f->range >= target * (1 - 1e-6), "%s: range %g short of the farthest point %g * (1 + margin)", what,
              f->range, f->farthest);
    T_ASSERTF(f->range >= prev * (1 - R_LSPSM_SHRINK) * (1 - 1e-6), "%s: shrank from %g to %g in one frame", what,
              prev, f->range);
    if (target >= prev)
        T_ASSERTF(fabs(f->range - target) <= target * 1e-6, "%s: grew to %g, not at once to %g", what, f->range,
                  target);
}

static void t_focus_grow_shrink(void)
{
    seed();
    frame_cam c = focus_cam();
    float depth[R_LSPSM_FOCUS_N];
    r_lspsm_focus f = {0};
    /* a wall 20 m ahead: from the limit the range shrinks slowly */
    wall(depth, 20);
    double far20 = farthest_of(&c, depth), prev = R_LSPSM_LIMIT;
    T_ASSERTF(far20 > 20 && far20 < 20 * 1.3, "farthest %g", far20);
    int frames = 0;
    do {
        r_lspsm_focus_update(&f, depth, c.w, c.h, c.inv);
        focus_ok(&f, prev, "wall 20 m");
        T_ASSERTF(fabs(f.farthest - far20) < far20 * 1e-4, "farthest %g, want %g", f.farthest, far20);
        T_ASSERTF(f.range <= prev, "grew from %g to %g on the same wall", prev, f.range);
        T_EQ(f.used, R_LSPSM_FOCUS_N);
        if (frames == 0)
            T_ASSERTF(f.range > 0.95 * R_LSPSM_LIMIT, "dropped from the limit to %g at once", f.range);
        prev = f.range;
    } while (++frames < 1000 && f.range > far20 * (1 + R_LSPSM_MARGIN) * 1.0001);
    T_ASSERTF(frames > 30 && frames < 100, "settled in %d frames", frames);
    /* it settles just beyond the wall */
    T_ASSERTF(fabs(f.range - far20 * 1.1) < 1e-3, "settled at %g", f.range);
    /* the wall moves out to 60 m: grows at once */
    wall(depth, 60);
    r_lspsm_focus_update(&f, depth, c.w, c.h, c.inv);
    focus_ok(&f, prev, "wall 60 m");
    T_ASSERTF(f.range > 60 * 1.1 && f.range >= f.farthest * 1.1 * (1 - 1e-6), "range %g for a wall at 60 m", f.range);
    /* sky somewhere: the limit, at once */
    prev = f.range;
    wall(depth, 10);
    depth[123] = 1;
    r_lspsm_focus_update(&f, depth, c.w, c.h, c.inv);
    focus_ok(&f, prev, "sky");
    T_ASSERTF(f.range == R_LSPSM_LIMIT && f.farthest == R_LSPSM_LIMIT, "sky: range %g", f.range);
    /* very near: never below the minimum */
    wall(depth, 0.2);
    for (int i = 0; i < 400; i++) {
        prev = f.range;
        r_lspsm_focus_update(&f, depth, c.w, c.h, c.inv);
        focus_ok(&f, prev, "near wall");
    }
    T_ASSERTF(fabs(f.range - R_LSPSM_MIN_RANGE) < 1e-6, "range %g", f.range);
    /* a random walk of the wall: the invariants hold throughout */
    for (int i = 0; i < 2000; i++) {
        prev = f.range;
        wall(depth, urand() < 0.05 ? 0 : urange(0.5, 150));
        r_lspsm_focus_update(&f, depth, c.w, c.h, c.inv);
        focus_ok(&f, prev, "random walk");
    }
}

/* r_lspsm_focus_memory: a range rebuilt from a reset with the last M
 * frames' samples equals, bit for bit, the range after any longer history
 * (render --ticks A:B draws those M frames before A); and M is tight: M - 1
 * frames of a near wall after a far view are not enough. */
static void t_focus_memory(void)
{
    seed();
    frame_cam c = focus_cam();
    r_lspsm_focus def = {0};
    int m = r_lspsm_focus_memory(&def);
    /* the limit shrinking 2 % a frame reaches the minimum (1 m of 100 m) */
    int want = (int)ceil(log(R_LSPSM_MIN_RANGE / R_LSPSM_LIMIT) / log(1 - R_LSPSM_SHRINK));
    T_ASSERTF(m >= want && m <= want + 2, "memory %d frames, want about %d", m, want);
    enum { HIST = 900 };
    static float depth[HIST][R_LSPSM_FOCUS_N];
    for (int trial = 0; trial < 60; trial++) {
        int n = m + (int)(urand() * (HIST - m)); /* frames of history */
        for (int i = 0; i < n; i++) {
            double u = urand();
            /* walls near and far, sky now and then, and long near stretches at the end
               (the slowest case for the rebuilt range: it must shrink all the way) */
            double d = i > n - m / 2 && trial % 3 == 0 ? 0.2 : u < 0.05 ? 0 : urange(0.2, 150);
            wall(depth[i], d);
        }
        r_lspsm_focus full = {0}, rebuilt = {0};
        for (int i = 0; i < n; i++)
            r_lspsm_focus_update(&full, depth[i], c.w, c.h, c.inv);
        for (int i = n - m; i < n; i++)
            r_lspsm_focus_update(&rebuilt, depth[i], c.w, c.h, c.inv);
        T_ASSERTF(full.range == rebuilt.range, "trial %d: %d frames of history give %.9g, the last %d give %.9g", trial,
                  n, full.range, m, rebuilt.range);
    }
    /* tight: the sky, then a near wall for m frames */
    float sky[R_LSPSM_FOCUS_N], near[R_LSPSM_FOCUS_N];
    wall(sky, 0);
    wall(near, 0.2);
    r_lspsm_focus full = {0}, rebuilt = {0};
    r_lspsm_focus_update(&full, sky, c.w, c.h, c.inv);
    for (int i = 0; i < 2 * m; i++)
        r_lspsm_focus_update(&full, near, c.w, c.h, c.inv);
    for (int i = 0; i < m - 1; i++)
        r_lspsm_focus_update(&rebuilt, near, c.w, c.h, c.inv);
    T_ASSERTF(full.range != rebuilt.range, "%d frames already rebuild the range (%.9g): the memory is not tight", m - 1,
              rebuilt.range);
    r_lspsm_focus_update(&rebuilt, near, c.w, c.h, c.inv);
    T_ASSERTF(full.range == rebuilt.range, "%d frames: %.9g, want %.9g", m, rebuilt.range, full.range);
}

static void t_focus_nan(void)
{
    frame_cam c = focus_cam();
    float clean[R_LSPSM_FOCUS_N], dirty[R_LSPSM_FOCUS_N];
    r_lspsm_focus a = {0}, b = {0};
    for (int frame = 0; frame < 100; frame++) {
        double D = frame < 50 ? 15 : 40;
        wall(clean, D);
        /* every other sample is the wall; the rest something near (clean)
         * or garbage (dirty), which must count for nothing */
        wall(dirty, D);
        float floor_depth[R_LSPSM_FOCUS_N];
        wall(floor_depth, 0.5);
        for (int k = 1; k < R_LSPSM_FOCUS_N; k += 2) {
            float bad[] = {NAN, -NAN, -0.5f, 1.5f, INFINITY, -INFINITY};
            dirty[k] = bad[k % 6];
            clean[k] = floor_depth[k]; /* near: the same farthest either way */
        }
        r_lspsm_focus_update(&a, clean, c.w, c.h, c.inv);
        r_lspsm_focus_update(&b, dirty, c.w, c.h, c.inv);
        T_ASSERTF(isfinite(b.range) && isfinite(b.farthest), "frame %d: %g %g", frame, b.range, b.farthest);
        T_ASSERTF(b.used == R_LSPSM_FOCUS_N / 2, "frame %d: %d used", frame, b.used);
        T_ASSERTF(fabs(a.range - b.range) <= a.range * 1e-5, "frame %d: %g with garbage, %g without", frame, b.range,
                  a.range);
    }
    /* nothing usable: the state stays */
    r_lspsm_focus keep = b;
    for (int k = 0; k < R_LSPSM_FOCUS_N; k++)
        dirty[k] = NAN;
    r_lspsm_focus_update(&b, dirty, c.w, c.h, c.inv);
    T_ASSERT(b.range == keep.range && b.farthest == keep.farthest && b.used == 0);
    /* a broken matrix: the state stays */
    r_mat4 bad = c.inv;
    bad.m[5] = NAN;
    wall(clean, 3);
    r_lspsm_focus_update(&b, clean, c.w, c.h, bad);
    T_ASSERT(b.range == keep.range && isfinite(b.range));
    bad = c.inv;
    bad.m[11] = NAN;
    r_lspsm_focus_update(&b, clean, c.w, c.h, bad);
    T_ASSERT(b.range == keep.range);
    /* a garbage state recovers */
    b.range = NAN;
    r_lspsm_focus_update(&b, clean, c.w, c.h, c.inv);
    T_ASSERTF(isfinite(b.range) && b.range <= R_LSPSM_LIMIT, "range %g", b.range);
}

/* ---- fade ---- */

static void t_fade(void)
{
    r_lspsm_desc d = {.cam = game_cam(), .to_light = r_v3(0.2f, 1, 0.3f)};
    basis b = cam_basis(&d.cam);
    for (int pass = 0; pass < 2; pass++) {
        d.far = pass ? 30 : 0;
        r_lspsm s;
        r_lspsm_build(&d, &s);
        double start = pass ? 30 / 1.1 : 80, end = pass ? 30 : 100;
        T_ASSERTF(fabs(s.fade[0] - start) < 1e-3 && fabs(s.fade[1] - end) < 1e-3, "fade %g..%g", s.fade[0], s.fade[1]);
        double prev = 1;
        for (int i = 0; i <= 12000; i++) {
            double dist = i * 0.01;
            /* distance from the eye in any direction, not view depth */
            r_vec3 dir = i % 3 == 0 ? b.v : i % 3 == 1 ? r_norm(add(b.v, b.r)) : r_norm(add(b.u, b.r));
            float f = r_lspsm_fade(&s, add(d.cam.eye, scale(dir, dist)));
            T_ASSERTF(f >= 0 && f <= 1 && f <= prev + 1e-5 && prev - f < 0.01, "%g m: %g after %g", dist, f, prev);
            if (dist <= start - 0.01)
                T_ASSERTF(f == 1, "%g m: %g", dist, f);
            if (dist >= end + 0.01)
                T_ASSERTF(f == 0, "%g m: %g", dist, f);
            prev = f;
        }
        T_ASSERTF(fabs(r_lspsm_fade(&s, add(d.cam.eye, scale(b.v, (start + end) / 2))) - 0.5) < 1e-3, "midpoint");
    }
    r_lspsm s;
    r_lspsm_build(&d, &s);
    T_ASSERT(r_lspsm_fade(&s, r_v3(NAN, 0, 0)) == 0);
}

/* ---- fighters: where the ray to the light leaves the box ---- */

static bool in_box(r_vec3 p, r_vec3 lo, r_vec3 hi, double tol)
{
    return p.x >= lo.x - tol && p.x <= hi.x + tol && p.y >= lo.y - tol && p.y <= hi.y + tol && p.z >= lo.z - tol &&
           p.z <= hi.z + tol;
}

static void t_box_exit(void)
{
    seed();
    for (int i = 0; i < 20000; i++) {
        float c[3], e[3], pc[3], dc[3];
        for (int a = 0; a < 3; a++) {
            c[a] = (float)urange(-5, 5), e[a] = (float)urange(0.1, 2);
            double pick = urand();
            /* inside, or on a face (so edges and corners too) */
            pc[a] = pick < 0.15 ? c[a] - e[a] : pick < 0.3 ? c[a] + e[a] : (float)(c[a] + urange(-1, 1) * e[a]);
            dc[a] = urand() < 0.25 ? (urand() < 0.5 ? 0.0f : -0.0f) : (float)urange(-1, 1);
        }
        r_vec3 lo = r_v3(c[0] - e[0], c[1] - e[1], c[2] - e[2]), hi = r_v3(c[0] + e[0], c[1] + e[1], c[2] + e[2]);
        r_vec3 p = r_v3(pc[0], pc[1], pc[2]), d = r_v3(dc[0], dc[1], dc[2]);
        r_vec3 x = r_lspsm_box_exit(p, d, lo, hi);
        T_ASSERTF(isfinite(x.x) && isfinite(x.y) && isfinite(x.z), "case %d: not finite", i);
        double dl = sqrt(r_dot(d, d));
        if (dl == 0) {
            T_ASSERT(x.x == p.x && x.y == p.y && x.z == p.z);
            continue;
        }
        /* brute force: march until the point leaves the closed box */
        double dt = 1e-3 / dl, t = 0;
        while (in_box(add(p, scale(d, t + dt)), lo, hi, 1e-6))
            t += dt;
        r_vec3 m = add(p, scale(d, t));
        double err = sqrt(r_dot(r_sub(x, m), r_sub(x, m)));
        T_ASSERTF(err < 2e-3, "case %d: exit %.5f %.5f %.5f, march %.5f %.5f %.5f", i, x.x, x.y, x.z, m.x, m.y, m.z);
        T_ASSERTF(in_box(x, lo, hi, 1e-4), "case %d: exit outside the box", i);
    }
    /* axis directions from the centre and from faces: exact */
    r_vec3 lo = r_v3(-1, 0, -0.5f), hi = r_v3(1, 2, 0.5f), o = r_v3(0, 1, 0);
    r_vec3 x = r_lspsm_box_exit(o, r_v3(0, 1, 0), lo, hi);
    T_ASSERT(x.x == 0 && x.y == 2 && x.z == 0);
    x = r_lspsm_box_exit(o, r_v3(-0.0f, -3, 0), lo, hi);
    T_ASSERT(x.x == 0 && x.y == 0 && x.z == 0);
    x = r_lspsm_box_exit(r_v3(1, 1, 0), r_v3(0, 0, 1), lo, hi); /* along the +x face */
    T_ASSERT(x.x == 1 && x.y == 1 && x.z == 0.5f);
    x = r_lspsm_box_exit(r_v3(1, 1, 0), r_v3(1, 0, 0), lo, hi); /* out through the face it is on */
    T_ASSERT(x.x == 1 && x.y == 1 && x.z == 0);
    x = r_lspsm_box_exit(hi, r_v3(1, 1, 1), lo, hi); /* corner, outwards */
    T_ASSERT(x.x == hi.x && x.y == hi.y && x.z == hi.z);
    x = r_lspsm_box_exit(hi, r_v3(-2, -2, -1), lo, hi); /* corner, inwards: the first slab */
    T_ASSERT(fabs(x.z + 0.5f) < 1e-6 && fabs(x.x + 1) < 1e-6 && fabs(x.y) < 1e-6);
    x = r_lspsm_box_exit(o, r_v3(0, 0, 0), lo, hi);
    T_ASSERT(x.x == o.x && x.y == o.y && x.z == o.z);
    /* a fighter: a point on its chest, sun overhead and behind */
    x = r_lspsm_box_exit(r_v3(0.1f, 1.3f, 0.2f), r_v3(0, 0.8f, -0.6f), r_v3(-0.4f, 0, -0.4f), r_v3(0.4f, 1.9f, 0.4f));
    T_ASSERTF(x.y == 1.9f && fabs(x.z + 0.25f) < 1e-6 && x.x == 0.1f, "%g %g %g", x.x, x.y, x.z); /* the top */
}

/* ---- casters culled from the light's view ---- */

static bool box_visible(const r_lspsm *s, r_vec3 c, float e)
{
    return r_lspsm_caster_visible(s, r_v3(c.x - e, c.y - e, c.z - e), r_v3(c.x + e, c.y + e, c.z + e));
}

static void t_cull(void)
{
    seed();
    r_lspsm_desc d = {.cam = game_cam(), .to_light = r_norm(r_v3(0.3f, 1, 0.2f))};
    r_lspsm s;
    r_lspsm_build(&d, &s);
    basis b = cam_basis(&d.cam);
    r_vec3 L = r_norm(d.to_light), mid = add(d.cam.eye, scale(b.v, 20));
    T_ASSERT(box_visible(&s, mid, 0.5f));                                   /* in the body */
    T_ASSERT(box_visible(&s, add(mid, scale(L, 60)), 2));                   /* above it, towards the light */
    /* towards the light the frustum ends caster_reach beyond the body's
     * nearest corner (further at the far side: the warp tilts that plane) */
    T_ASSERT(box_visible(&s, add(body_point(&d.cam, &s, 0, 1, 0), scale(L, R_LSPSM_CASTER_REACH - 3)), 2));
    T_ASSERT(!box_visible(&s, add(mid, scale(L, 40 * R_LSPSM_CASTER_REACH)), 2));
    T_ASSERT(!box_visible(&s, add(mid, scale(L, -300)), 2));                /* far under the body */
    T_ASSERT(!box_visible(&s, add(d.cam.eye, scale(b.v, -60)), 2));         /* behind the camera */
    T_ASSERT(!box_visible(&s, add(mid, scale(b.r, 200)), 5));               /* far to the side */
    T_ASSERT(!box_visible(&s, add(d.cam.eye, scale(b.v, 300)), 5));         /* past the far end */
    T_ASSERT(box_visible(&s, d.cam.eye, 1000));                             /* around everything */
    /* straddling: a long wall from far outside into the body */
    T_ASSERT(r_lspsm_caster_visible(&s, r_v3(-500, 0, -10), r_v3(0, 3, -9)));
    /* random boxes: never culled while a point of them maps into the map;
     * and culling does happen */
    int culled = 0;
    for (int i = 0; i < 5000; i++) {
        r_vec3 c = add(d.cam.eye, r_v3((float)urange(-150, 150), (float)urange(-100, 150), (float)urange(-150, 150)));
        r_vec3 e = r_v3((float)urange(0.1, 20), (float)urange(0.1, 20), (float)urange(0.1, 20));
        r_vec3 lo = r_sub(c, e), hi = add(c, e);
        bool vis = r_lspsm_caster_visible(&s, lo, hi);
        culled += !vis;
        if (vis)
            continue;
        for (int k = 0; k < 125; k++) {
            r_vec3 q = r_v3(lo.x + (hi.x - lo.x) * (k % 5) / 4.0f, lo.y + (hi.y - lo.y) * (k / 5 % 5) / 4.0f,
                            lo.z + (hi.z - lo.z) * (k / 25) / 4.0f);
            double cc[4];
            clip(&s.light_vp, q, cc);
            T_ASSERTF(!(cc[3] > 0 && fabs(cc[0]) <= cc[3] && fabs(cc[1]) <= cc[3] && fabs(cc[2]) <= cc[3]),
                      "box %d culled, yet point %d maps into the map", i, k);
        }
    }
    T_ASSERTF(culled > 1000, "only %d of 5000 random boxes culled", culled);
}

/* ---- the rest ---- */

static void t_camera_from(void)
{
    r_vec3 eye = r_v3(3, 1.7f, 6), at = r_v3(-1, 1, 0);
    r_mat4 view = r_look_at(eye, at, r_v3(0, 1, 0)), proj = r_perspective(0.75f, 16.0f / 9, 0.1f, 200);
    r_lspsm_camera c = r_lspsm_camera_from(view, proj);
    r_vec3 f = r_norm(r_sub(at, eye)), de = r_sub(c.eye, eye), dd = r_sub(c.dir, f);
    T_ASSERT(r_dot(de, de) < 1e-8 && r_dot(dd, dd) < 1e-10);
    T_ASSERT(fabs(r_dot(c.up, f)) < 1e-6 && c.up.y > 0.9f);
    T_ASSERT(fabsf(c.fovy - 0.75f) < 1e-5 && fabsf(c.aspect - 16.0f / 9) < 1e-5);
    T_ASSERTF(fabsf(c.near - 0.1f) < 1e-4 && fabsf(c.far - 200) < 0.5f, "near %g far %g", c.near, c.far);
}

static void t_density_rows(void)
{
    char *buf = NULL, *cbuf = NULL;
    size_t n = 0, cn = 0;
    FILE *f = open_memstream(&buf, &n), *cf = open_memstream(&cbuf, &cn);
    T_ASSERT(f && cf);
    r_lspsm_density_rows(f, cf);
    fclose(f), fclose(cf);
    fputs(buf, stdout);
    T_CONTAINS(buf, "ratio 2m");
    T_ASSERT(!strstr(buf, "nan") && !strstr(buf, "inf") && !strstr(cbuf, "nan"));
    int lines = 0;
    for (char *p = cbuf; *p; p++)
        lines += *p == '\n';
    T_EQ(lines, 6);
    T_CONTAINS(cbuf, "\n90,");
    T_CONTAINS(cbuf, "\n0,inf"); /* no warp: n is infinite */
    free(buf), free(cbuf);
}

/* Texels per metre along the warp axis (map y) at p. */
static double axis_density(const r_lspsm *s, r_vec3 p)
{
    double a[4], b[4], h = 1e-3;
    clip(&s->light_vp, add(p, scale(s->axis[1], -h)), a);
    clip(&s->light_vp, add(p, scale(s->axis[1], h)), b);
    return R_LSPSM_MAP / 2.0 * fabs(b[1] / b[3] - a[1] / a[3]) / (2 * h);
}

/* The warp is chosen for warp_near (2 m), not the camera's 0.1 m: with the
 * light across the game camera's view, 80 m away the texels along the view
 * were 2 m long (the far shadow edges a staircase); now they are a third
 * of that, and at 3 m, the nearest ground in view, still denser than
 * uniform.  warp_near below the body's near is the near. */
static void t_warp_near(void)
{
    r_lspsm_desc d = {.cam = game_cam()};
    basis b = cam_basis(&d.cam);
    d.to_light = b.u; /* 90 deg */
    r_lspsm now, old, un, low;
    r_lspsm_build(&d, &now);
    d.warp_near = 0.1f;
    r_lspsm_build(&d, &old);
    d.warp_near = 0.01f;
    r_lspsm_build(&d, &low);
    d.warp_near = 0, d.uniform = true;
    r_lspsm_build(&d, &un);
    r_vec3 p3 = add(d.cam.eye, scale(b.v, 3)), p80 = add(d.cam.eye, scale(b.v, 80));
    double f_now = axis_density(&now, p80), f_old = axis_density(&old, p80), f_un = axis_density(&un, p80);
    double n_now = r_lspsm_texels_per_metre(&now, p3, R_LSPSM_MAP), n_un = r_lspsm_texels_per_metre(&un, p3, R_LSPSM_MAP);
    printf("  along the view at 80 m: %.2f texels/m (warp near 0.1 m: %.2f, uniform %.2f); at 3 m %.1fx uniform; n %.2f m (was %.2f)\n",
           f_now, f_old, f_un, n_now / n_un, (double)now.n, (double)old.n);
    T_ASSERTF(f_now > 3 * f_old, "80 m: %.3f texels/m, %.3f with the camera's near", f_now, f_old);
    T_ASSERTF(n_now > 3 * n_un, "3 m: %.2f texels/m, uniform %.2f", n_now, n_un);
    T_ASSERT(low.warp == old.warp && memcmp(&low.light_vp, &old.light_vp, sizeof low.light_vp) == 0);
}

/* ---- the static layers ---- */

static void mat_apply(const r_mat4 *m, const float p[3], double out[4])
{
    for (int r = 0; r < 4; r++)
        out[r] = m->m[r] * p[0] + m->m[4 + r] * p[1] + m->m[8 + r] * p[2] + m->m[12 + r];
}

/* r_lspsm_static_build: random lights (and straight up, straight down, a
 * zero vector) and boxes.  The last layer's (u, v, depth) puts the outer
 * box in 0..1 exactly (corners on both ends of each axis); each layer's
 * fit puts its own box in 0..1 the same way; each layer's clip matrix is
 * 2 (u, v, depth) - 1 of its own texture coordinates; depth falls towards
 * the light. */
static void t_static_layers(void)
{
    seed();
    for (int k = 0; k < 400; k++) {
        r_vec3 L = k == 0 ? r_v3(0, 1, 0) : k == 1 ? r_v3(0, -1, 0) : k == 2 ? r_v3(0, 0, 0) : rand_unit();
        float box[R_LSPSM_LAYERS][2][3];
        for (int l = R_LSPSM_LAYERS - 1; l >= 0; l--)
            for (int a = 0; a < 3; a++) {
                double h = l == R_LSPSM_LAYERS - 1 ? urange(20, 150) : urange(1, 15);
                box[l][0][a] = (float)(-h + urange(-2, 2)), box[l][1][a] = (float)(h + urange(-2, 2));
            }
        r_lspsm_static st;
        r_lspsm_static_build(L, (const float(*)[2][3])box, &st);
        T_ASSERTF(isfinite(st.depth_m) && st.depth_m > 0, "light %d: depth range %g m", k, st.depth_m);
        for (int l = 0; l < R_LSPSM_LAYERS; l++) {
            double lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
            for (int c = 0; c < 8; c++) {
                const float p[3] = {box[l][c & 1][0], box[l][(c >> 1) & 1][1], box[l][(c >> 2) & 1][2]};
                double t[4], clip[4];
                mat_apply(&st.shadow, p, t);
                T_ASSERTF(fabs(t[3] - 1) < 1e-6, "w %g", t[3]);
                if (l < R_LSPSM_LAYERS - 1)
                    for (int a = 0; a < 2; a++)
                        t[a] = t[a] * st.fit[l][a] + st.fit[l][2 + a];
                mat_apply(&st.light_vp[l], p, clip);
                for (int a = 0; a < 3; a++) {
                    lo[a] = fmin(lo[a], t[a]), hi[a] = fmax(hi[a], t[a]);
                    T_ASSERTF(fabs(clip[a] - (2 * t[a] - 1)) < 1e-4, "light %d layer %d: clip %g, texture %g", k, l, clip[a],
                              t[a]);
                }
            }
            for (int a = 0; a < (l == R_LSPSM_LAYERS - 1 ? 3 : 2); a++)
                T_ASSERTF(fabs(lo[a]) < 1e-4 && fabs(hi[a] - 1) < 1e-4, "light %d layer %d axis %d: %g..%g", k, l, a, lo[a],
                          hi[a]);
            T_ASSERT(st.extent[l][0] > 0 && st.extent[l][1] > 0 && isfinite(st.extent[l][0]));
        }
        /* a metre towards the light: nearer by a metre */
        r_vec3 Ln = r_dot(L, L) > 0 ? r_norm(L) : r_v3(0, 1, 0);
        const float p[3] = {0, 0, 0}, q[3] = {Ln.x, Ln.y, Ln.z};
        double tp[4], tq[4];
        mat_apply(&st.shadow, p, tp);
        mat_apply(&st.shadow, q, tq);
        T_ASSERTF(fabs((tp[2] - tq[2]) * st.depth_m - 1) < 1e-3, "light %d: a metre towards it is %g m", k,
                  (tp[2] - tq[2]) * st.depth_m);
        T_ASSERTF(fabs(tp[0] - tq[0]) < 1e-5 && fabs(tp[1] - tq[1]) < 1e-5, "light %d: the light's ray moved in u, v", k);
    }
}

T_MAIN({"unit_cube_random", t_unit_cube_random}, {"static_layers", t_static_layers}, {"unit_cube_degenerate", t_unit_cube_degenerate},
       {"density", t_density}, {"no_pop", t_no_pop}, {"focus_pattern", t_focus_pattern},
       {"focus_grow_shrink", t_focus_grow_shrink}, {"focus_memory", t_focus_memory}, {"focus_nan", t_focus_nan}, {"fade", t_fade},
       {"box_exit", t_box_exit}, {"cull", t_cull}, {"camera_from", t_camera_from}, {"density_rows", t_density_rows},
       {"warp_near", t_warp_near})
