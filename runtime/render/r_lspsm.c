/* Light Space Perspective Shadow Maps: the light's matrices, the fallback to
 * uniform shadow mapping, the depth auto-focus, the fade and the fighters'
 * box-exit lookup (docs/effects.md, "Shadows in a large world").  Pure
 * arithmetic, no GL: the matrices are built in double and handed over as
 * floats.
 *
 * The light frame: z towards the light, y = the view direction with its
 * component along the light removed (the warp axis), x = y cross z; origin at
 * the eye.  The body B (the view frustum between near and far) is put in
 * that frame and warped by a perspective along y whose centre sits n metres
 * before B's nearest y (Wimmer et al. 2004).  We write the warp as
 * w = 1 + t y' with t = 1/n and y' measured from B's nearest y: that is
 * Wimmer's frustum up to an affine map (which the unit-cube fit absorbs), and
 * t -> 0 turns it continuously into the identity, i.e. into uniform shadow
 * mapping, which t = 0 is exactly. */
#include "r_lspsm.h"

#include <math.h>

#define PI 3.14159265358979323846
#define EDGE_BAND (10 * PI / 180) /* see the warp in r_lspsm_build */

typedef struct { double x, y, z; } dv3;

static dv3 dv(r_vec3 v) { return (dv3){v.x, v.y, v.z}; }
static r_vec3 fv(dv3 v) { return r_v3((float)v.x, (float)v.y, (float)v.z); }
static dv3 d_add(dv3 a, dv3 b) { return (dv3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static dv3 d_sub(dv3 a, dv3 b) { return (dv3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static dv3 d_scale(dv3 a, double s) { return (dv3){a.x * s, a.y * s, a.z * s}; }
static double d_dot(dv3 a, dv3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static double d_len(dv3 a) { return sqrt(d_dot(a, a)); }
static dv3 d_cross(dv3 a, dv3 b)
{
    return (dv3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static bool d_finite(dv3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

/* Unit a, or fallback when a is zero, tiny or not finite. */
static dv3 d_unit(dv3 a, dv3 fallback)
{
    double l = d_len(a);
    return l > 1e-12 && isfinite(l) ? d_scale(a, 1 / l) : fallback;
}

/* a with its component along unit n removed. */
static dv3 d_perp(dv3 a, dv3 n) { return d_sub(a, d_scale(n, d_dot(a, n))); }

/* Some unit vector perpendicular to unit n: the world axis least along it. */
static dv3 d_any_perp(dv3 n)
{
    dv3 ax = fabs(n.x) <= fabs(n.y) && fabs(n.x) <= fabs(n.z) ? (dv3){1, 0, 0}
             : fabs(n.y) <= fabs(n.z)                         ? (dv3){0, 1, 0}
                                                              : (dv3){0, 0, 1};
    return d_unit(d_perp(ax, n), (dv3){0, 0, 1});
}

static double pick(double v, double def) { return v > 0 && isfinite(v) ? v : def; }

r_lspsm_camera r_lspsm_camera_from(r_mat4 view, r_mat4 proj)
{
    const float *m = view.m;
    dv3 s = {m[0], m[4], m[8]}, u = {m[1], m[5], m[9]}, b = {m[2], m[6], m[10]};
    dv3 eye = d_scale(d_add(d_add(d_scale(s, m[12]), d_scale(u, m[13])), d_scale(b, m[14])), -1);
    const float *p = proj.m;
    r_lspsm_camera c = {fv(eye), fv(d_scale(b, -1)), fv(u), 0, 0, 0, 0};
    c.fovy = (float)(2 * atan(1.0 / p[5]));
    c.aspect = (float)((double)p[5] / p[0]);
    c.near = (float)((double)p[14] / (p[10] - 1.0));
    c.far = (float)((double)p[14] / (p[10] + 1.0));
    return c;
}

/* A row of a projective map: value = r[0] x + r[1] y + r[2] z + r[3]. */
typedef struct { double r[4]; } row4;

static row4 row_of(dv3 a, double c) { return (row4){{a.x, a.y, a.z, c}}; }
static row4 row_mix(row4 a, double sa, row4 b, double sb)
{
    row4 o;
    for (int i = 0; i < 4; i++)
        o.r[i] = a.r[i] * sa + b.r[i] * sb;
    return o;
}
static r_mat4 mat_of(const row4 rows[4])
{
    r_mat4 m;
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            m.m[c * 4 + r] = (float)rows[r].r[c];
    return m;
}

void r_lspsm_build(const r_lspsm_desc *d, r_lspsm *out)
{
    /* defaults, in one place */
    const r_lspsm_camera *cam = &d->cam;
    double limit = pick(d->limit, R_LSPSM_LIMIT);
    double near = pick(d->near, pick(cam->near, 0.1));
    double far = fmin(pick(d->far, limit), limit);
    if (cam->far > near && isfinite(cam->far))
        far = fmin(far, cam->far);
    far = fmax(far, near * 1.01);
    double band_end = pick(d->band_end, R_LSPSM_BAND_END);
    double band_start = fmax(pick(d->band_start, R_LSPSM_BAND_START), band_end + 1e-6);
    double reach = pick(d->caster_reach, R_LSPSM_CASTER_REACH);
    double margin = pick(d->margin, R_LSPSM_MARGIN), fade = fmin(pick(d->fade, R_LSPSM_FADE), 1);
    double fovy = fmin(pick(cam->fovy, 0.75), 3.0), aspect = pick(cam->aspect, 1);
    double wnear = fmin(fmax(pick(d->warp_near, R_LSPSM_WARP_NEAR), near), far);

    dv3 eye = d_finite(dv(cam->eye)) ? dv(cam->eye) : (dv3){0, 0, 0};
    dv3 view = d_unit(dv(cam->dir), (dv3){0, 0, -1});
    dv3 cup = d_unit(d_perp(dv(cam->up), view), d_any_perp(view));
    dv3 cright = d_cross(view, cup);
    dv3 L = d_unit(dv(d->to_light), (dv3){0, 1, 0});

    /* the body: the frustum's corners at view depths near and far */
    dv3 body[8];
    for (int k = 0; k < 8; k++) {
        double z = k & 4 ? far : near, hy = z * tan(fovy / 2), hx = hy * aspect;
        body[k] = d_add(d_add(d_add(eye, d_scale(view, z)), d_scale(cup, k & 2 ? hy : -hy)),
                        d_scale(cright, k & 1 ? hx : -hx));
    }

    /* the light frame.  Exactly along the light the view direction gives no
     * warp axis; the camera's up does, signed so that it continues the axis
     * a camera approaching that direction had, when its up leans towards the
     * light (a 180 deg turn otherwise, which samples the very same texels:
     * there the map is uniform). */
    double cosg = d_dot(view, L);
    dv3 pv = d_perp(view, L);
    double sing = d_len(pv);
    dv3 y_axis;
    if (sing > 1e-9)
        y_axis = d_scale(pv, 1 / sing);
    else
        y_axis = d_unit(d_scale(d_perp(cup, L), cosg < 0 ? 1 : -1), d_any_perp(L));
    dv3 x_axis = d_cross(y_axis, L);
    double gamma = atan2(sing, cosg);

    /* The warp, t = 1 / (distance of its centre behind the body's nearest
     * y) = blend * edge / n_opt, with Wimmer's n_opt = (near + sqrt(near *
     * far)) / sin(gamma): sin(gamma) lands in the numerator, nothing divides
     * by zero.  Its near is warp_near, not the camera's: n_opt balances
     * the error at the two ends of near..far, and the nearest receiver the
     * game's camera shows is the ground a few metres away.  blend: 1 out of the angle band, smoothly 0 at its end.
     * edge: where the view frustum's edges point backwards along y (small
     * gamma with a wide view, worst along the diagonals) the body reaches
     * behind the eye, and a warp would spend its texels on the body's far
     * edge instead of the eye's surroundings (less than uniform there); so
     * the warp also fades as the outermost edge turns to within EDGE_BAND of
     * perpendicular to y.  Both are continuous: no pop. */
    double ge = fmin(gamma, PI - gamma), t = 0;
    if (!d->uniform && ge > band_end) {
        double x = fmin((ge - band_end) / (band_start - band_end), 1), blend = x * x * (3 - 2 * x);
        double emin = 1;
        for (int k = 4; k < 8; k++)
            emin = fmin(emin, d_dot(d_unit(d_sub(body[k], eye), y_axis), y_axis));
        double e = fmin(emin / sin(EDGE_BAND), 1);
        if (e > 0)
            t = blend * e * e * (3 - 2 * e) * sing / (wnear + sqrt(wnear * far));
    }

    /* the body in the frame, warped by w = 1 + t (y - ymin); x, y fit round
     * the body, depth round the body and the body moved `reach` towards the
     * light (the casters) */
    double q[8][3], ymin = INFINITY;
    for (int k = 0; k < 8; k++) {
        dv3 r = d_sub(body[k], eye);
        q[k][0] = d_dot(r, x_axis), q[k][1] = d_dot(r, y_axis), q[k][2] = d_dot(r, L);
        ymin = fmin(ymin, q[k][1]);
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int k = 0; k < 8; k++) {
        double yl = q[k][1] - ymin, w = 1 + t * yl;
        double v[4] = {q[k][0] / w, yl / w, q[k][2] / w, (q[k][2] + reach) / w};
        for (int a = 0; a < 4; a++) {
            int i = a < 3 ? a : 2;
            lo[i] = fmin(lo[i], v[a]), hi[i] = fmax(hi[i], v[a]);
        }
    }

    /* rows: x, y' (from ymin), z in the frame, then w, then the fit */
    row4 rx = row_of(x_axis, -d_dot(x_axis, eye));
    row4 ry = row_of(y_axis, -d_dot(y_axis, eye) - ymin);
    row4 rz = row_of(L, -d_dot(L, eye));
    row4 one = {{0, 0, 0, 1}};
    row4 rw = row_mix(one, 1, ry, t);
    row4 rows[4];
    double ext[3];
    for (int i = 0; i < 3; i++)
        ext[i] = fmax(hi[i] - lo[i], 1e-9);
    rows[0] = row_mix(rx, 2 / ext[0], rw, -(hi[0] + lo[0]) / ext[0]);
    rows[1] = row_mix(ry, 2 / ext[1], rw, -(hi[1] + lo[1]) / ext[1]);
    rows[2] = row_mix(rz, -2 / ext[2], rw, (hi[2] + lo[2]) / ext[2]); /* nearest the light: -1 */
    rows[3] = rw;
    out->light_vp = mat_of(rows);
    for (int i = 0; i < 3; i++)
        rows[i] = row_mix(rows[i], 0.5, rw, 0.5);
    out->shadow = mat_of(rows);

    out->fade[1] = (float)far;
    out->fade[0] = (float)fmin(fmin(far / (1 + margin), limit * (1 - fade)), far * 0.999);
    out->near = (float)near, out->far = (float)far;
    out->gamma = (float)gamma;
    out->warp = (float)t;
    out->n = t > 0 ? (float)(1 / t) : INFINITY;
    out->eye = fv(eye);
    out->axis[0] = fv(x_axis), out->axis[1] = fv(y_axis), out->axis[2] = fv(L);
}

/* The light-frame bounds of a world box: its 8 corners on x, y and z. */
static void frame_bounds(const dv3 ax[3], const float lo[3], const float hi[3], double b[3][2])
{
    for (int a = 0; a < 3; a++)
        b[a][0] = INFINITY, b[a][1] = -INFINITY;
    for (int k = 0; k < 8; k++) {
        dv3 p = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        for (int a = 0; a < 3; a++) {
            double v = d_dot(p, ax[a]);
            b[a][0] = fmin(b[a][0], v), b[a][1] = fmax(b[a][1], v);
        }
    }
    for (int a = 0; a < 3; a++) /* an empty or flat box: a metre, so nothing divides by zero */
        if (!(b[a][1] - b[a][0] >= 1e-3)) {
            double c = isfinite(b[a][0] + b[a][1]) ? 0.5 * (b[a][0] + b[a][1]) : 0;
            b[a][0] = c - 0.5, b[a][1] = c + 0.5;
        }
}

void r_lspsm_static_build(r_vec3 to_light, const float box[R_LSPSM_LAYERS][2][3], r_lspsm_static *out)
{
    dv3 L = d_unit(dv(to_light), (dv3){0, 1, 0});
    /* map y: the world's up with the light's part removed (the vertical
     * across the light), or any axis when the light is straight up */
    dv3 y = d_perp((dv3){0, 1, 0}, L);
    y = d_len(y) > 1e-3 ? d_unit(y, (dv3){0, 0, 1}) : d_any_perp(L);
    dv3 x = d_cross(y, L);
    const dv3 ax[3] = {x, y, L};
    double b[R_LSPSM_LAYERS][3][2];
    for (int l = 0; l < R_LSPSM_LAYERS; l++)
        frame_bounds(ax, box[l][0], box[l][1], b[l]);
    const double(*ob)[2] = b[R_LSPSM_LAYERS - 1];
    /* depth 0 at the side towards the light, 1 away from it: every layer */
    double z0 = ob[2][1], dz = ob[2][1] - ob[2][0];
    double ow = ob[0][1] - ob[0][0], oh = ob[1][1] - ob[1][0];
    for (int l = 0; l < R_LSPSM_LAYERS; l++) {
        double w = b[l][0][1] - b[l][0][0], h = b[l][1][1] - b[l][1][0], sx = 1 / w, sy = 1 / h;
        /* clip: x, y in -1..1 over the layer, z = 2 depth - 1 */
        row4 rows[4] = {row_of(d_scale(x, 2 * sx), -2 * sx * b[l][0][0] - 1),
                        row_of(d_scale(y, 2 * sy), -2 * sy * b[l][1][0] - 1),
                        row_of(d_scale(L, -2 / dz), 2 * z0 / dz - 1), row_of((dv3){0, 0, 0}, 1)};
        out->light_vp[l] = mat_of(rows);
        out->extent[l][0] = (float)w, out->extent[l][1] = (float)h;
        if (l < R_LSPSM_LAYERS - 1) { /* u = (p.x - b0) / w = (u_last ow + ob0 - b0) / w */
            out->fit[l][0] = (float)(ow / w), out->fit[l][1] = (float)(oh / h);
            out->fit[l][2] = (float)((ob[0][0] - b[l][0][0]) / w), out->fit[l][3] = (float)((ob[1][0] - b[l][1][0]) / h);
        }
    }
    row4 tex[4] = {row_of(d_scale(x, 1 / ow), -ob[0][0] / ow), row_of(d_scale(y, 1 / oh), -ob[1][0] / oh),
                   row_of(d_scale(L, -1 / dz), z0 / dz), row_of((dv3){0, 0, 0}, 1)};
    out->shadow = mat_of(tex);
    out->depth_m = (float)dz;
    out->axis[0] = fv(x), out->axis[1] = fv(y), out->axis[2] = fv(L);
}

float r_lspsm_fade(const r_lspsm *s, r_vec3 p)
{
    double dist = d_len(d_sub(dv(p), dv(s->eye))), a = s->fade[0], b = s->fade[1];
    if (!(dist > a))
        return dist <= a ? 1.0f : 0.0f; /* NaN: no shadow */
    if (dist >= b)
        return 0;
    double x = (dist - a) / (b - a);
    return (float)(1 - x * x * (3 - 2 * x));
}

bool r_lspsm_caster_visible(const r_lspsm *s, r_vec3 lo, r_vec3 hi)
{
    const float *m = s->light_vp.m;
    for (int i = 0; i < 6; i++) {
        /* clip-space -w <= c_i <= w as a world plane: row w +- row i */
        double sg = i & 1 ? -1 : 1, pl[4];
        for (int c = 0; c < 4; c++)
            pl[c] = (double)m[c * 4 + 3] + sg * m[c * 4 + i / 2];
        /* the box corner furthest along the plane's normal */
        double v = pl[3] + pl[0] * (pl[0] > 0 ? hi.x : lo.x) + pl[1] * (pl[1] > 0 ? hi.y : lo.y) +
                   pl[2] * (pl[2] > 0 ? hi.z : lo.z);
        if (v < 0)
            return false;
    }
    return true;
}

/* float throughout, as the shader has it (see the header's GLSL) */
r_vec3 r_lspsm_box_exit(r_vec3 p, r_vec3 dir, r_vec3 lo, r_vec3 hi)
{
    float pp[3] = {p.x, p.y, p.z}, dd[3] = {dir.x, dir.y, dir.z};
    float ll[3] = {lo.x, lo.y, lo.z}, hh[3] = {hi.x, hi.y, hi.z}, te = 1e30f;
    for (int i = 0; i < 3; i++) {
        float t = dd[i] == 0 ? 1e30f : ((dd[i] >= 0 ? hh[i] : ll[i]) - pp[i]) / dd[i];
        te = fminf(te, t);
    }
    te = fmaxf(te, 0);
    if (te >= 1e30f)
        return p;
    return r_v3(p.x + dir.x * te, p.y + dir.y * te, p.z + dir.z * te);
}

/* NDC x, y of p under m, in double. */
static void ndc_xy(const r_mat4 *m, dv3 p, double *x, double *y)
{
    const float *a = m->m;
    double c[4];
    for (int r = 0; r < 4; r++)
        c[r] = (double)a[r] * p.x + (double)a[4 + r] * p.y + (double)a[8 + r] * p.z + a[12 + r];
    *x = c[0] / c[3], *y = c[1] / c[3];
}

double r_lspsm_texels_per_metre(const r_lspsm *s, r_vec3 p, int map_size)
{
    const double h = 1e-3;
    double j[2][2];
    for (int a = 0; a < 2; a++) {
        dv3 e = d_scale(dv(s->axis[a]), h);
        double x0, y0, x1, y1;
        ndc_xy(&s->light_vp, d_sub(dv(p), e), &x0, &y0);
        ndc_xy(&s->light_vp, d_add(dv(p), e), &x1, &y1);
        j[a][0] = (x1 - x0) / (2 * h), j[a][1] = (y1 - y0) / (2 * h);
    }
    /* NDC spans 2 per map edge */
    return map_size / 2.0 * sqrt(fabs(j[0][0] * j[1][1] - j[0][1] * j[1][0]));
}

void r_lspsm_density_rows(FILE *out, FILE *csv)
{
    static const int angles[] = {90, 60, 30, 10, 0};
    static const double dists[2] = {2, 50};
    /* the game camera's framing (r_game_camera: 1.7 m high, looking at 1 m) */
    r_mat4 view = r_look_at(r_v3(0, 1.7f, 6), r_v3(0, 1, 0), r_v3(0, 1, 0));
    r_mat4 proj = r_perspective(0.75f, 16.0f / 9, 0.1f, 200);
    r_lspsm_desc d = {.cam = r_lspsm_camera_from(view, proj)};
    dv3 v = d_unit(dv(d.cam.dir), (dv3){0, 0, -1}), u = d_unit(d_perp(dv(d.cam.up), v), (dv3){0, 1, 0});
    fprintf(out,
            "\nLSPSM shadow-map texel density (%dx%d map, view depths %.1f..%.0f m, game camera framing, light\n"
            "turned from the camera's up towards its view direction): texels per metre across the light at 2 m\n"
            "and 50 m along the view axis, LSPSM vs uniform shadow mapping.  The warp blends out between %.0f and\n"
            "%.0f deg, and sooner where the view's edges near the light (this 16:9 view: about 32 to 22 deg)\n",
            R_LSPSM_MAP, R_LSPSM_MAP, d.cam.near, (double)R_LSPSM_LIMIT, R_LSPSM_BAND_START * 180 / PI,
            R_LSPSM_BAND_END * 180 / PI);
    fprintf(out, "%6s %9s %11s %11s %11s %11s %9s %9s\n", "angle", "n (m)", "lspsm 2m", "unif 2m", "lspsm 50m",
            "unif 50m", "ratio 2m", "ratio 50m");
    if (csv)
        fprintf(csv, "angle_deg,n_m,lspsm_near,uniform_near,lspsm_far,uniform_far,ratio_near,ratio_far\n");
    for (size_t a = 0; a < sizeof angles / sizeof angles[0]; a++) {
        double g = angles[a] * PI / 180;
        d.to_light = fv(d_add(d_scale(v, cos(g)), d_scale(u, sin(g))));
        r_lspsm ls, un;
        d.uniform = false;
        r_lspsm_build(&d, &ls);
        d.uniform = true;
        r_lspsm_build(&d, &un);
        double dl[2], du[2];
        for (int k = 0; k < 2; k++) {
            r_vec3 p = fv(d_add(dv(d.cam.eye), d_scale(v, dists[k])));
            dl[k] = r_lspsm_texels_per_metre(&ls, p, R_LSPSM_MAP);
            du[k] = r_lspsm_texels_per_metre(&un, p, R_LSPSM_MAP);
        }
        char n[16] = "-"; /* uniform: no warp */
        if (isfinite(ls.n))
            snprintf(n, sizeof n, "%.2f", (double)ls.n);
        fprintf(out, "%6d %9s %11.2f %11.2f %11.3f %11.3f %9.2f %9.3f\n", angles[a], n, dl[0], du[0], dl[1], du[1],
                dl[0] / du[0], dl[1] / du[1]);
        if (csv)
            fprintf(csv, "%d,%.4f,%.4f,%.4f,%.5f,%.5f,%.4f,%.5f\n", angles[a], (double)ls.n, dl[0], du[0], dl[1],
                    du[1], dl[0] / du[0], dl[1] / du[1]);
    }
}

/* ---- auto-focus ---- */

void r_lspsm_focus_point(int k, int w, int h, int *x, int *y)
{
    /* cell (i, j) of the 20x16 grid; inside it the sample is offset by j/16
     * of a cell across and i/20 of a cell up: a grid sheared both ways (a
     * rotation of about 3 deg), every x and every y used once in 320 */
    long i = k % R_LSPSM_FOCUS_W, j = k / R_LSPSM_FOCUS_W;
    *x = (int)(((R_LSPSM_FOCUS_H * i + j) * 2 + 1) * (long)w / (2 * R_LSPSM_FOCUS_N));
    *y = (int)(((R_LSPSM_FOCUS_W * j + i) * 2 + 1) * (long)h / (2 * R_LSPSM_FOCUS_N));
}

void r_lspsm_focus_gather(const float *depth, int w, int h, float out[R_LSPSM_FOCUS_N])
{
    for (int k = 0; k < R_LSPSM_FOCUS_N; k++) {
        int x, y;
        r_lspsm_focus_point(k, w, h, &x, &y);
        out[k] = depth[(size_t)y * (size_t)w + (size_t)x];
    }
}

float r_lspsm_focus_update(r_lspsm_focus *f, const float depth[R_LSPSM_FOCUS_N], int w, int h, r_mat4 inv_vp)
{
    double limit = pick(f->limit, R_LSPSM_LIMIT), margin = pick(f->margin, R_LSPSM_MARGIN);
    double shrink = fmin(pick(f->shrink, R_LSPSM_SHRINK), 1);
    double min_range = fmin(pick(f->min_range, R_LSPSM_MIN_RANGE), limit);
    if (!(f->range > 0 && f->range <= limit)) /* first frame, bad state or a lower limit */
        f->range = (float)limit;
    f->used = 0;
    const float *m = inv_vp.m;
    /* the eye: clip (0, 0, 1, 0) (where every view ray meets) back in the world */
    dv3 eye = d_scale((dv3){m[8], m[9], m[10]}, 1.0 / m[11]);
    if (!d_finite(eye) || w <= 0 || h <= 0)
        return f->range;
    double farthest = 0;
    for (int k = 0; k < R_LSPSM_FOCUS_N; k++) {
        double z = depth[k], dist;
        if (!(z >= 0 && z <= 1))
            continue; /* NaN, or not a window depth */
        if (z >= 1) {
            dist = limit; /* sky */
        } else {
            int px, py;
            r_lspsm_focus_point(k, w, h, &px, &py);
            double c[4] = {2 * (px + 0.5) / w - 1, 2 * (py + 0.5) / h - 1, 2 * z - 1, 1}, o[4];
            for (int r = 0; r < 4; r++)
                o[r] = m[r] * c[0] + m[4 + r] * c[1] + m[8 + r] * c[2] + m[12 + r] * c[3];
            dist = d_len(d_sub(d_scale((dv3){o[0], o[1], o[2]}, 1 / o[3]), eye));
            if (!isfinite(dist))
                continue;
            dist = fmin(dist, limit);
        }
        farthest = fmax(farthest, dist);
        f->used++;
    }
    if (!f->used)
        return f->range;
    f->farthest = (float)farthest;
    double target = fmin(fmax(farthest * (1 + margin), min_range), limit);
    double range = f->range;
    range = target >= range ? target : fmax(target, range * (1 - shrink));
    f->range = (float)range;
    return f->range;
}

int r_lspsm_focus_memory(const r_lspsm_focus *f)
{
    double limit = pick(f->limit, R_LSPSM_LIMIT), shrink = fmin(pick(f->shrink, R_LSPSM_SHRINK), 1);
    double min_range = fmin(pick(f->min_range, R_LSPSM_MIN_RANGE), limit);
    /* the shrinking chain exactly as r_lspsm_focus_update computes it */
    float range = (float)limit;
    int n = 0;
    while (range > min_range && n < 1 << 20) {
        range = (float)fmax(min_range, (double)range * (1 - shrink));
        n++;
    }
    return n;
}
