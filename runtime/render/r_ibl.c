/* DESIGN: who owns what (the prefilter in r_ibl_build)
 *
 * The calling thread builds the environment and a read-only table of its
 * texels (direction, radiance x solid angle with and without the key
 * area); workers only read it.  The output is cut into tasks of (map,
 * face, block of rows), each writing only its own rows of its map, both
 * key states at once (they share every lobe weight), so outputs need no
 * lock.  Tasks are handed out by one atomic counter; the calling thread
 * works as well and then joins the others.  Each output texel is summed by
 * one thread in one fixed order, so the maps do not depend on the thread
 * count (the cache relies on it). */
#include "r_ibl_local.h"

#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../util/rs_oiio.h"

#define PI 3.14159265358979323846
/* The cache key does not cover these: change one, bump R_IBL_FORMAT_VERSION. */
#define PROC_SUB 4       /* sub-samples per texel edge of the procedural sky */
#define GROUND_EDGE 2.0  /* degrees of the soft horizon -> ground transition */
#define KEY_EDGE 5.0     /* degrees of the key-area fade */
#define LOBE_CUT 1e-7    /* specular texels below this fraction of the peak are skipped */
#define ROWS_PER_TASK 4
#define MAX_THREADS 64

void r_ibl_default_params(r_ibl_params *p)
{
    *p = (r_ibl_params){.src_size = 32, .out_size = {16, 32, 32}, .threads = 0};
}

float r_ibl_exponent(int map)
{
    return map == R_IBL_SPEC16 ? 16.0f : map == R_IBL_SPEC128 ? 128.0f : 0.0f;
}

/* ---------- cube maps ---------- */

static void face_vec(int face, double s, double t, double v[3])
{
    switch (face) {
    case 0: v[0] = 1, v[1] = -t, v[2] = -s; break;
    case 1: v[0] = -1, v[1] = -t, v[2] = s; break;
    case 2: v[0] = s, v[1] = 1, v[2] = t; break;
    case 3: v[0] = s, v[1] = -1, v[2] = -t; break;
    case 4: v[0] = s, v[1] = -t, v[2] = 1; break;
    default: v[0] = -s, v[1] = -t, v[2] = -1; break;
    }
}

void r_cube_dir(int face, int i, int j, int n, float dir[3])
{
    double v[3];
    face_vec(face, 2.0 * (i + 0.5) / n - 1, 2.0 * (j + 0.5) / n - 1, v);
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int c = 0; c < 3; c++)
        dir[c] = (float)(v[c] / l);
}

/* dir -> face and face coordinates s, t in -1..1 (the inverse of face_vec).
 * A zero, infinite or NaN direction reads as straight up rather than as
 * garbage. */
static int cube_st(const double d[3], double *s, double *t)
{
    double ax = fabs(d[0]), ay = fabs(d[1]), az = fabs(d[2]);
    if (!(ax > 0 || ay > 0 || az > 0) || !isfinite(ax + ay + az)) {
        *s = *t = 0;
        return 2;
    }
    if (ax >= ay && ax >= az) {
        *t = -d[1] / ax;
        *s = d[0] > 0 ? -d[2] / ax : d[2] / ax;
        return d[0] > 0 ? 0 : 1;
    }
    if (ay >= az) {
        *s = d[0] / ay;
        *t = d[1] > 0 ? d[2] / ay : -d[2] / ay;
        return d[1] > 0 ? 2 : 3;
    }
    *t = -d[1] / az;
    *s = d[2] > 0 ? d[0] / az : -d[0] / az;
    return d[2] > 0 ? 4 : 5;
}

static int st_index(double s, int n)
{
    double x = floor((s + 1) * 0.5 * n);
    return !(x > 0) ? 0 : x > n - 1 ? n - 1 : (int)x; /* NaN never reaches the cast */
}

void r_cube_texel(const float dir[3], int n, int *face, int *i, int *j)
{
    double d[3] = {dir[0], dir[1], dir[2]}, s, t;
    *face = cube_st(d, &s, &t);
    *i = st_index(s, n);
    *j = st_index(t, n);
}

/* The solid angle of the face rectangle from (0,0) to (x,y) at distance 1,
 * up to a constant: differences of it give any rectangle exactly. */
static double area_el(double x, double y)
{
    return atan2(x * y, sqrt(x * x + y * y + 1));
}

double r_cube_texel_solid_angle(int i, int j, int n)
{
    double x0 = 2.0 * i / n - 1, x1 = 2.0 * (i + 1) / n - 1;
    double y0 = 2.0 * j / n - 1, y1 = 2.0 * (j + 1) / n - 1;
    return area_el(x0, y0) - area_el(x0, y1) - area_el(x1, y0) + area_el(x1, y1);
}

/* ---------- the environment ---------- */

static double smoothstep(double e0, double e1, double x)
{
    double t = (x - e0) / (e1 - e0);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t * t * (3 - 2 * t);
}

static double dot3(const double a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double angle_deg(double cosine)
{
    return acos(cosine < -1 ? -1 : cosine > 1 ? 1 : cosine) * (180 / PI);
}

static float clamp_half(double v)
{
    return v > 0 ? (v < R_HALF_MAX ? (float)v : R_HALF_MAX) : 0.0f; /* NaN fails v > 0 */
}

typedef enum { SRC_SKY, SRC_EQUIRECT, SRC_STRIP, SRC_CROSS } src_kind;

/* Where radiance comes from while the environment is built. */
typedef struct env_src {
    const r_stage *st;
    src_kind kind;
    int w, h, edge; /* image size; edge: a face's edge in pixels (cube layouts) */
    float *px;      /* RGB, rows top-down, already clamped */
    double rc, rs;  /* cos, sin of the yaw */
    double disc_cos[2]; /* cosine of each painted light's radius: a cheap test before acos */
} env_src;

static void sky_radiance(const env_src *src, const double d[3], double c[3])
{
    const r_stage *st = src->st;
    double h = d[1];
    if (h >= 0) {
        double a = sqrt(h);
        for (int k = 0; k < 3; k++)
            c[k] = st->sky_horizon[k] + (st->sky_zenith[k] - st->sky_horizon[k]) * a;
    } else {
        double b = smoothstep(0, sin(GROUND_EDGE * PI / 180), -h);
        for (int k = 0; k < 3; k++)
            c[k] = st->sky_horizon[k] + (st->ground[k] - st->sky_horizon[k]) * b;
    }
    const r_paint_light *lights[2] = {&st->key, &st->counter};
    for (int l = 0; l < 2; l++) {
        const r_paint_light *L = lights[l];
        double cosine = dot3(d, L->dir);
        if (!(L->intensity > 0) || !(L->size_deg > 0) || cosine < src->disc_cos[l])
            continue;
        double a = angle_deg(cosine);
        if (a >= L->size_deg)
            continue;
        double f = L->intensity * (1 - smoothstep(0, L->size_deg, a));
        for (int k = 0; k < 3; k++)
            c[k] += L->color[k] * f;
    }
}

/* A loaded image: read, checked for a known layout, cleaned up front so
 * that NaN or Inf in user data can never reach an average. */
static bool src_load(env_src *src, const char *path, rs_err *err)
{
    rs_err oerr = {0};
    int w = 0, h = 0;
    float *px = NULL;
    if (!rs_oiio_read_float(path, &w, &h, &px, &oerr))
        return rs_fail(err, R_IBL_ERR_FILE, "%s", oerr.msg);
    if (w == 2 * h) {
        src->kind = SRC_EQUIRECT;
        src->edge = h / 2; /* a quarter turn of latitude, like a face edge */
    } else if (w == 6 * h) {
        src->kind = SRC_STRIP;
        src->edge = h;
    } else if (3 * w == 4 * h) {
        src->kind = SRC_CROSS;
        src->edge = h / 3;
    } else {
        free(px);
        return rs_fail(err, R_IBL_ERR_FORMAT,
                       "%s: %dx%d is not an equirectangular (2:1), 6:1 strip or 4:3 cross image", path, w, h);
    }
    for (size_t k = 0; k < (size_t)w * h * 3; k++)
        px[k] = isfinite(px[k]) ? clamp_half(px[k]) : 0.0f;
    double yaw = isfinite(src->st->env_rotate_deg) ? src->st->env_rotate_deg * (PI / 180) : 0;
    src->rc = cos(yaw);
    src->rs = sin(yaw);
    src->w = w;
    src->h = h;
    src->px = px;
    return true;
}

/* Cross cells of each GL face, in face edges: every face upright as
 * uploaded, which makes the net's seams meet (r_ibl.h). */
static const int cross_cell[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}};

/* The image pixel of face f, texel (i, j) of a strip or a cross. */
static const float *cube_pixel(const env_src *src, int f, int i, int j)
{
    int x = src->kind == SRC_STRIP ? f * src->edge + i : cross_cell[f][0] * src->edge + i;
    int y = src->kind == SRC_STRIP ? j : cross_cell[f][1] * src->edge + j;
    return src->px + ((size_t)y * src->w + x) * 3;
}

/* Radiance towards unit direction d.  A loaded image is turned by the yaw
 * (right-handed about +Y: +90 degrees brings what the file has at +X to
 * -Z), so the image is read at the direction turned back. */
static void src_radiance(const env_src *src, const double d[3], double c[3])
{
    if (src->kind == SRC_SKY) {
        sky_radiance(src, d, c);
        return;
    }
    double v[3] = {d[0] * src->rc - d[2] * src->rs, d[1], d[0] * src->rs + d[2] * src->rc};
    const float *p;
    if (src->kind == SRC_EQUIRECT) {
        double u = 0.5 + atan2(v[2], v[0]) / (2 * PI);
        double t = 0.5 - asin(v[1] < -1 ? -1 : v[1] > 1 ? 1 : v[1]) / PI;
        int x = (int)floor(u * src->w), y = (int)floor(t * src->h);
        x = x < 0 ? 0 : x >= src->w ? x - src->w : x; /* u == 1 is u == 0 */
        y = y < 0 ? 0 : y >= src->h ? src->h - 1 : y;
        p = src->px + ((size_t)y * src->w + x) * 3;
    } else {
        double s, t;
        int f = cube_st(v, &s, &t);
        p = cube_pixel(src, f, st_index(s, src->edge), st_index(t, src->edge));
    }
    for (int k = 0; k < 3; k++)
        c[k] = p[k];
}

static void splat_one(const env_src *src, int size, const double d[3], double dw, const float *L, double *acc)
{
    double v[3] = {d[0] * src->rc + d[2] * src->rs, d[1], -d[0] * src->rs + d[2] * src->rc}; /* the yaw */
    double s, t;
    int f = cube_st(v, &s, &t);
    double *a = acc + (((size_t)f * size + st_index(t, size)) * size + st_index(s, size)) * 4;
    for (int k = 0; k < 3; k++)
        a[k] += L[k] * dw;
    a[3] += dw;
}

/* Downsampling an image: every pixel adds radiance x solid angle to the
 * texel its centre falls in.  Point samples would miss a sun a few pixels
 * wide, or catch it and multiply it; this keeps each pixel's energy.  A
 * pixel is cut into k x k parts first when few pixels cross a texel, so
 * texel borders cut pixels finely enough (16 parts a texel edge).
 * acc: 6 x size x size of (r, g, b, weight). */
static bool splat(const env_src *src, int size, double *acc)
{
    int k = (16 * size + src->edge - 1) / src->edge;
    k = k < 1 ? 1 : k > 8 ? 8 : k;
    if (src->kind == SRC_EQUIRECT) {
        int w = src->w * k, h = src->h * k;
        double *col = malloc((size_t)w * 2 * sizeof *col);
        if (!col)
            return false;
        for (int x = 0; x < w; x++) {
            double lon = 2 * PI * ((x + 0.5) / w - 0.5);
            col[2 * x] = cos(lon);
            col[2 * x + 1] = sin(lon);
        }
        for (int y = 0; y < h; y++) {
            double top = PI * (0.5 - (double)y / h), bottom = PI * (0.5 - (y + 1.0) / h);
            double lat = PI * (0.5 - (y + 0.5) / h), cl = cos(lat), sl = sin(lat);
            double dw = 2 * PI / w * (sin(top) - sin(bottom));
            const float *row = src->px + (size_t)(y / k) * src->w * 3;
            for (int x = 0; x < w; x++) {
                double d[3] = {cl * col[2 * x], sl, cl * col[2 * x + 1]};
                splat_one(src, size, d, dw, row + (size_t)(x / k) * 3, acc);
            }
        }
        free(col);
        return true;
    }
    int e = src->edge * k;
    for (int f = 0; f < 6; f++)
        for (int j = 0; j < e; j++)
            for (int i = 0; i < e; i++) {
                double s = 2 * (i + 0.5) / e - 1, t = 2 * (j + 0.5) / e - 1, d[3];
                face_vec(f, s, t, d);
                double r2 = s * s + t * t + 1, l = sqrt(r2);
                for (int c = 0; c < 3; c++)
                    d[c] /= l;
                splat_one(src, size, d, 4 / ((double)e * e * r2 * l), cube_pixel(src, f, i / k, j / k), acc);
            }
    return true;
}

/* The solid-angle weighted mean of sub x sub samples of one texel. */
static void texel_average(const env_src *src, int f, int i, int j, int n, int sub, double out[3])
{
    double acc[3] = {0, 0, 0}, wsum = 0;
    for (int b = 0; b < sub; b++)
        for (int a = 0; a < sub; a++) {
            double s = 2 * (i + (a + 0.5) / sub) / n - 1, t = 2 * (j + (b + 0.5) / sub) / n - 1;
            double v[3], c[3];
            face_vec(f, s, t, v);
            double r2 = s * s + t * t + 1, l = sqrt(r2), w = 1 / (r2 * l);
            for (int k = 0; k < 3; k++)
                v[k] /= l;
            src_radiance(src, v, c);
            for (int k = 0; k < 3; k++)
                acc[k] += w * c[k];
            wsum += w;
        }
    for (int k = 0; k < 3; k++)
        out[k] = acc[k] / wsum;
}

bool r_env_build(const r_stage *st, int size, r_env *env, rs_err *err)
{
    memset(env, 0, sizeof *env);
    if (size < 1 || size > R_IBL_MAX_SIZE)
        return rs_fail(err, R_IBL_ERR_PARAMS, "environment size %d: expected 1..%d", size, R_IBL_MAX_SIZE);
    env_src src = {.st = st, .kind = SRC_SKY, .rc = 1};
    src.disc_cos[0] = cos(fmin(st->key.size_deg, 180) * (PI / 180)) - 1e-9;
    src.disc_cos[1] = cos(fmin(st->counter.size_deg, 180) * (PI / 180)) - 1e-9;
    int sub = PROC_SUB;
    double scale = 1, *acc = NULL;
    if (st->env_path[0]) {
        if (!src_load(&src, st->env_path, err))
            return false;
        scale = st->env_scale;
        /* upsampling or nearly: enough samples for two a pixel */
        int edge = src.edge > 0 ? src.edge : 1;
        sub = (2 * edge + size - 1) / size;
        sub = sub < 2 ? 2 : sub > 16 ? 16 : sub;
        if (edge >= 2 * size) {
            acc = calloc((size_t)6 * size * size * 4, sizeof *acc);
            if (!acc || !splat(&src, size, acc))
                goto oom;
        }
    }
    for (int f = 0; f < 6; f++)
        if (!(env->face[f] = malloc((size_t)size * size * 3 * sizeof(float))))
            goto oom;
    env->size = size;
    for (int f = 0; f < 6; f++)
        for (int j = 0; j < size; j++)
            for (int i = 0; i < size; i++) {
                size_t o = (size_t)j * size + i;
                const double *a = acc ? acc + ((size_t)f * size * size + o) * 4 : NULL;
                double c[3];
                if (a && a[3] > 0)
                    for (int k = 0; k < 3; k++)
                        c[k] = a[k] / a[3];
                else
                    texel_average(&src, f, i, j, size, sub, c); /* also a texel no pixel centre fell in */
                for (int k = 0; k < 3; k++)
                    env->face[f][o * 3 + k] = clamp_half(c[k] * scale);
            }
    free(acc);
    free(src.px);
    return true;
oom:
    free(acc);
    free(src.px);
    r_env_free(env);
    return rs_fail(err, R_IBL_ERR_MEMORY, "out of memory for a 6 x %d x %d environment", size, size);
}

void r_env_free(r_env *env)
{
    for (int f = 0; f < 6; f++)
        free(env->face[f]);
    memset(env, 0, sizeof *env);
}

/* out = unit(v); false for a zero, NaN or infinite vector */
static bool unit3(const float v[3], float out[3])
{
    double l = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
    if (!(l > 0) || !isfinite(l))
        return false;
    for (int k = 0; k < 3; k++)
        out[k] = (float)(v[k] / l);
    return true;
}

void r_ibl_key_dir(const r_stage *st, const r_env *env, float dir[3])
{
    if (st->sun && unit3(st->sun_dir, dir))
        return;
    if (!st->env_path[0]) {
        if (st->key.intensity > 0 && unit3(st->key.dir, dir))
            return;
        if (st->counter.intensity > 0 && unit3(st->counter.dir, dir))
            return;
    } else if (env && env->size > 0) {
        int n = env->size, bf = -1, bi = 0, bj = 0;
        double best = 0;
        for (int f = 0; f < 6; f++)
            for (int j = 0; j < n; j++)
                for (int i = 0; i < n; i++) {
                    const float *c = env->face[f] + ((size_t)j * n + i) * 3;
                    double y = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                    if (y > best) {
                        best = y;
                        bf = f, bi = i, bj = j;
                    }
                }
        if (bf >= 0) {
            r_cube_dir(bf, bi, bj, n, dir);
            return;
        }
    }
    dir[0] = 0, dir[1] = 1, dir[2] = 0;
}

/* ---------- integration ---------- */

typedef struct lobe {
    int e;       /* cosine power: 1 (diffuse), 16, 128 -- a power of two */
    double norm; /* 1/pi or (e+1)/(2pi): a uniform environment of 1 gives 1 */
    float cut;   /* cosines at or below this add nothing worth counting */
} lobe;

static lobe lobe_of(int map)
{
    if (map == R_IBL_DIFFUSE)
        return (lobe){1, 1 / PI, 0.0f};
    int e = (int)r_ibl_exponent(map);
    return (lobe){e, (e + 1) / (2 * PI), (float)pow(LOBE_CUT, 1.0 / e)};
}

static double lobe_pow(double c, int e)
{
    for (int k = 1; k < e; k *= 2)
        c *= c;
    return c;
}

/* One source texel: its direction and its radiance times solid angle,
 * whole (key on) and faded out over the key area (key off). */
static void texel_entry(const r_env *env, int f, int i, int j, double dw, const float key[3], double area, float d[3],
                        float on[3], float off[3])
{
    int n = env->size;
    r_cube_dir(f, i, j, n, d);
    double dd[3] = {d[0], d[1], d[2]};
    double fade = smoothstep(area, area + KEY_EDGE, angle_deg(dot3(dd, key)));
    const float *L = env->face[f] + ((size_t)j * n + i) * 3;
    for (int k = 0; k < 3; k++) {
        on[k] = (float)(L[k] * dw);
        off[k] = (float)(L[k] * dw * fade);
    }
}

static inline void accumulate(lobe lb, const float r[3], const float d[3], const float on[3], const float off[3],
                              double a_on[3], double a_off[3])
{
    float c = r[0] * d[0] + r[1] * d[1] + r[2] * d[2];
    if (!(c > lb.cut))
        return;
    double w = lobe_pow(c, lb.e);
    for (int k = 0; k < 3; k++) {
        a_on[k] += w * on[k];
        a_off[k] += w * off[k];
    }
}

/* Normalises the sums and adds the procedural sun (key on only): a delta
 * light, so its term is the lobe at the sun direction. */
static void finish(const r_stage *st, lobe lb, const float r[3], double on[3], double off[3])
{
    for (int k = 0; k < 3; k++) {
        on[k] *= lb.norm;
        off[k] *= lb.norm;
    }
    float s[3];
    if (st->env_path[0] || !st->sun || !(st->sun_intensity > 0) || !unit3(st->sun_dir, s))
        return;
    double c = (double)r[0] * s[0] + (double)r[1] * s[1] + (double)r[2] * s[2];
    if (c <= 0)
        return;
    double w = lb.norm * lobe_pow(c, lb.e) * st->sun_intensity;
    for (int k = 0; k < 3; k++)
        on[k] += w * st->sun_color[k];
}

void r_ibl_eval(const r_stage *st, const r_env *env, const float key_dir[3], int map, int key, const float dir[3],
                double rgb[3])
{
    int n = env->size;
    lobe lb = lobe_of(map);
    double *dw = malloc((size_t)n * n * sizeof *dw); /* only a shortcut: NULL computes each */
    if (dw)
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++)
                dw[j * n + i] = r_cube_texel_solid_angle(i, j, n);
    double on[3] = {0, 0, 0}, off[3] = {0, 0, 0};
    for (int f = 0; f < 6; f++)
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                float d[3], ton[3], toff[3];
                double w = dw ? dw[j * n + i] : r_cube_texel_solid_angle(i, j, n);
                texel_entry(env, f, i, j, w, key_dir, st->key_area_deg, d, ton, toff);
                accumulate(lb, dir, d, ton, toff, on, off);
            }
    free(dw);
    finish(st, lb, dir, on, off);
    for (int k = 0; k < 3; k++)
        rgb[k] = key == R_IBL_KEY_ON ? on[k] : off[k];
}

/* ---------- the prefilter ---------- */

#define SEG_LEN 8 /* source texels of one row culled together */

/* A run of source texels in one row, and the cone holding their centres. */
typedef struct seg {
    float axis[3];
    float reach_cos[R_IBL_MAPS]; /* r . axis below this: no texel of the run is inside the map's lobe cut */
    size_t first;
    int len;
} seg;

typedef struct src_tab {
    size_t n, nseg;
    float *dir, *on, *off; /* three floats per texel each (texel_entry) */
    seg *seg;              /* in texel order, so culling keeps r_ibl_eval's order of sums */
} src_tab;

typedef struct task {
    int map, face, row0, rows;
} task;

typedef struct job {
    const r_stage *st;
    const src_tab *tab;
    r_ibl *out;
    task *tasks;
    int ntask;
    atomic_int next;
} job;

static void make_segments(src_tab *tab, int n)
{
    double reach[R_IBL_MAPS];
    for (int m = 0; m < R_IBL_MAPS; m++)
        reach[m] = angle_deg(lobe_of(m).cut);
    size_t g = 0;
    for (size_t row = 0; row < (size_t)6 * n; row++)
        for (int i0 = 0; i0 < n; i0 += SEG_LEN, g++) {
            seg *sg = &tab->seg[g];
            sg->first = row * n + i0;
            sg->len = n - i0 < SEG_LEN ? n - i0 : SEG_LEN;
            double sum[3] = {0, 0, 0}, radius = 0;
            for (int k = 0; k < sg->len; k++)
                for (int c = 0; c < 3; c++)
                    sum[c] += tab->dir[3 * (sg->first + k) + c];
            double l = sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
            for (int c = 0; c < 3; c++)
                sg->axis[c] = (float)(sum[c] / l);
            for (int k = 0; k < sg->len; k++) {
                const float *d = tab->dir + 3 * (sg->first + k);
                double a = angle_deg((double)d[0] * sg->axis[0] + (double)d[1] * sg->axis[1] +
                                     (double)d[2] * sg->axis[2]);
                radius = a > radius ? a : radius;
            }
            /* 0.1 degree of slack covers float rounding: a skipped run must add nothing */
            for (int m = 0; m < R_IBL_MAPS; m++) {
                double a = reach[m] + radius + 0.1;
                sg->reach_cos[m] = a >= 180 ? -2.0f : (float)cos(a * PI / 180);
            }
        }
}

/* accumulate() over texels [k0, k1) with the sums in registers; inlined
 * once per exponent so the power unrolls (the same operations in the same
 * order as accumulate, so the same sums). */
static inline void sum_run(const src_tab *tab, size_t k0, size_t k1, const float r[3], float cut, int e,
                           double a[6])
{
    double on0 = a[0], on1 = a[1], on2 = a[2], off0 = a[3], off1 = a[4], off2 = a[5];
    for (size_t k = k0; k < k1; k++) {
        const float *d = tab->dir + 3 * k;
        float c = r[0] * d[0] + r[1] * d[1] + r[2] * d[2];
        if (!(c > cut))
            continue;
        double w = lobe_pow(c, e);
        const float *on = tab->on + 3 * k, *off = tab->off + 3 * k;
        on0 += w * on[0], on1 += w * on[1], on2 += w * on[2];
        off0 += w * off[0], off1 += w * off[1], off2 += w * off[2];
    }
    a[0] = on0, a[1] = on1, a[2] = on2, a[3] = off0, a[4] = off1, a[5] = off2;
}

static void run_task(job *jb, const task *tk)
{
    const src_tab *tab = jb->tab;
    int n = jb->out->size[tk->map];
    lobe lb = lobe_of(tk->map);
    float *mon = jb->out->map[tk->map][R_IBL_KEY_ON][tk->face];
    float *moff = jb->out->map[tk->map][R_IBL_KEY_OFF][tk->face];
    for (int j = tk->row0; j < tk->row0 + tk->rows; j++)
        for (int i = 0; i < n; i++) {
            float r[3];
            r_cube_dir(tk->face, i, j, n, r);
            double a[6] = {0, 0, 0, 0, 0, 0};
            for (size_t g = 0; g < tab->nseg; g++) {
                const seg *sg = &tab->seg[g];
                double c = (double)r[0] * sg->axis[0] + (double)r[1] * sg->axis[1] + (double)r[2] * sg->axis[2];
                if (c < sg->reach_cos[tk->map])
                    continue;
                size_t k0 = sg->first, k1 = sg->first + (size_t)sg->len;
                if (lb.e == 128)
                    sum_run(tab, k0, k1, r, lb.cut, 128, a);
                else if (lb.e == 16)
                    sum_run(tab, k0, k1, r, lb.cut, 16, a);
                else
                    sum_run(tab, k0, k1, r, lb.cut, 1, a);
            }
            finish(jb->st, lb, r, a, a + 3);
            size_t o = ((size_t)j * n + i) * 3;
            for (int c = 0; c < 3; c++) {
                mon[o + c] = clamp_half(a[c]);
                moff[o + c] = clamp_half(a[3 + c]);
            }
        }
}

static void *worker(void *arg)
{
    job *jb = arg;
    for (;;) {
        int k = atomic_fetch_add(&jb->next, 1);
        if (k >= jb->ntask)
            return NULL;
        run_task(jb, &jb->tasks[k]);
    }
}

static int thread_count(int want)
{
    if (want > 0)
        return want < MAX_THREADS ? want : MAX_THREADS;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > 8 ? 8 : (int)n;
}

static bool prefilter(const r_stage *st, const r_env *env, const r_ibl_params *p, r_ibl *out, rs_err *err)
{
    int n = env->size;
    src_tab tab = {.n = (size_t)6 * n * n, .nseg = (size_t)6 * n * ((n + SEG_LEN - 1) / SEG_LEN)};
    tab.seg = malloc(tab.nseg * sizeof *tab.seg);
    tab.dir = malloc(tab.n * 3 * sizeof(float));
    tab.on = malloc(tab.n * 3 * sizeof(float));
    tab.off = malloc(tab.n * 3 * sizeof(float));
    int ntask = 0;
    for (int m = 0; m < R_IBL_MAPS; m++)
        ntask += 6 * ((out->size[m] + ROWS_PER_TASK - 1) / ROWS_PER_TASK);
    job jb = {.st = st, .tab = &tab, .out = out, .tasks = malloc((size_t)ntask * sizeof(task)), .ntask = ntask};
    bool ok = tab.seg && tab.dir && tab.on && tab.off && jb.tasks;
    if (ok) {
        size_t k = 0;
        for (int f = 0; f < 6; f++)
            for (int j = 0; j < n; j++)
                for (int i = 0; i < n; i++, k++)
                    texel_entry(env, f, i, j, r_cube_texel_solid_angle(i, j, n), out->key_dir, st->key_area_deg,
                                tab.dir + 3 * k, tab.on + 3 * k, tab.off + 3 * k);
        make_segments(&tab, n);
        int t = 0;
        for (int m = 0; m < R_IBL_MAPS; m++)
            for (int f = 0; f < 6; f++)
                for (int j = 0; j < out->size[m]; j += ROWS_PER_TASK) {
                    int rows = out->size[m] - j;
                    jb.tasks[t++] = (task){m, f, j, rows < ROWS_PER_TASK ? rows : ROWS_PER_TASK};
                }
        atomic_init(&jb.next, 0);
        int nthreads = thread_count(p->threads);
        nthreads = nthreads < ntask ? nthreads : ntask;
        pthread_t th[MAX_THREADS];
        int started = 0;
        /* a thread that cannot start only makes the rest slower */
        while (started < nthreads - 1 && pthread_create(&th[started], NULL, worker, &jb) == 0)
            started++;
        worker(&jb);
        for (int k2 = 0; k2 < started; k2++)
            pthread_join(th[k2], NULL);
    }
    free(tab.seg);
    free(tab.dir);
    free(tab.on);
    free(tab.off);
    free(jb.tasks);
    return ok ? true : rs_fail(err, R_IBL_ERR_MEMORY, "out of memory prefiltering a %d x %d environment", n, n);
}

bool r_ibl_alloc_maps(r_ibl *out, rs_err *err)
{
    for (int m = 0; m < R_IBL_MAPS; m++)
        for (int k = 0; k < 2; k++)
            for (int f = 0; f < 6; f++) {
                out->map[m][k][f] = calloc((size_t)out->size[m] * out->size[m] * 3, sizeof(float));
                if (!out->map[m][k][f])
                    return rs_fail(err, R_IBL_ERR_MEMORY, "out of memory for the IBL maps");
            }
    return true;
}

void r_ibl_free(r_ibl *ibl)
{
    for (int m = 0; m < R_IBL_MAPS; m++)
        for (int k = 0; k < 2; k++)
            for (int f = 0; f < 6; f++)
                free(ibl->map[m][k][f]);
    memset(ibl, 0, sizeof *ibl);
}

bool r_ibl_resolve_params(const r_ibl_params *in, r_ibl_params *p, rs_err *err)
{
    r_ibl_default_params(p);
    if (in) {
        p->src_size = in->src_size ? in->src_size : p->src_size;
        for (int m = 0; m < R_IBL_MAPS; m++)
            p->out_size[m] = in->out_size[m] ? in->out_size[m] : p->out_size[m];
        p->threads = in->threads;
    }
    if (p->src_size < 1 || p->src_size > R_IBL_MAX_SIZE)
        return rs_fail(err, R_IBL_ERR_PARAMS, "IBL source size %d: expected 1..%d", p->src_size, R_IBL_MAX_SIZE);
    for (int m = 0; m < R_IBL_MAPS; m++)
        if (p->out_size[m] < 1 || p->out_size[m] > R_IBL_MAX_SIZE)
            return rs_fail(err, R_IBL_ERR_PARAMS, "IBL map size %d: expected 1..%d", p->out_size[m], R_IBL_MAX_SIZE);
    if (p->threads < 0)
        return rs_fail(err, R_IBL_ERR_PARAMS, "IBL threads %d: expected 0 (all CPUs) or more", p->threads);
    return true;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

bool r_ibl_build(const r_stage *st, const r_ibl_params *pin, const char *cache_dir, r_ibl *out, rs_err *err)
{
    memset(out, 0, sizeof *out);
    r_ibl_params p;
    uint64_t hash;
    if (!r_ibl_resolve_params(pin, &p, err) || !r_ibl_hash(st, &p, &hash, err))
        return false;
    out->hash = hash;
    for (int m = 0; m < R_IBL_MAPS; m++)
        out->size[m] = p.out_size[m];
    char path[PATH_MAX + 32] = "";
    if (cache_dir && *cache_dir) {
        snprintf(path, sizeof path, "%s/ibl-%016llx.bin", cache_dir, (unsigned long long)hash);
        if (r_ibl_cache_read(path, &p, hash, out)) {
            out->from_cache = true;
            return true;
        }
        r_ibl_free(out);
        out->hash = hash;
        for (int m = 0; m < R_IBL_MAPS; m++)
            out->size[m] = p.out_size[m];
    }
    double t0 = now_ms();
    r_env env;
    if (!r_env_build(st, p.src_size, &env, err))
        return false;
    r_ibl_key_dir(st, &env, out->key_dir);
    bool ok = r_ibl_alloc_maps(out, err) && prefilter(st, &env, &p, out, err);
    r_env_free(&env);
    if (!ok) {
        r_ibl_free(out);
        return false;
    }
    out->ms = now_ms() - t0;
    if (path[0])
        r_ibl_cache_write(path, &p, out);
    return true;
}

