/* runtime/render/r_ibl: cube maps, the environment, the prefilter, the cache. */
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../runtime/render/r_ibl.h"
#include "../runtime/util/rs_file.h"
#include "t.h"

#define PI 3.14159265358979323846

/* ---------- helpers ---------- */

/* A procedural stage of one flat colour, no sun, no painted lights. */
static void flat_stage(r_stage *st, float v)
{
    r_stage_defaults(st);
    for (int k = 0; k < 3; k++)
        st->sky_zenith[k] = st->sky_horizon[k] = st->ground[k] = v;
    st->sun = false;
    st->key.intensity = st->counter.intensity = 0;
}

static r_ibl_params params(int src, int o0, int o1, int o2)
{
    r_ibl_params p;
    r_ibl_default_params(&p);
    p.src_size = src;
    p.out_size[0] = o0, p.out_size[1] = o1, p.out_size[2] = o2;
    return p;
}

static double angle_deg(const float a[3], const float b[3])
{
    double c = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
    double la = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
    double lb = sqrt((double)b[0] * b[0] + (double)b[1] * b[1] + (double)b[2] * b[2]);
    c /= la * lb;
    return acos(c < -1 ? -1 : c > 1 ? 1 : c) * 180 / PI;
}

static void unit(float v[3])
{
    double l = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        v[k] = (float)(v[k] / l);
}

static bool ibl_same(const r_ibl *a, const r_ibl *b)
{
    for (int m = 0; m < R_IBL_MAPS; m++) {
        if (a->size[m] != b->size[m])
            return false;
        for (int k = 0; k < 2; k++)
            for (int f = 0; f < 6; f++)
                if (memcmp(a->map[m][k][f], b->map[m][k][f], (size_t)a->size[m] * a->size[m] * 3 * sizeof(float)))
                    return false;
    }
    return memcmp(a->key_dir, b->key_dir, sizeof a->key_dir) == 0 && a->hash == b->hash;
}

static const float *texel(const r_ibl *ibl, int m, int key, int f, int i, int j)
{
    return ibl->map[m][key][f] + ((size_t)j * ibl->size[m] + i) * 3;
}

/* stderr into a file around a call, so a case can read what was said */
static int stderr_to(const char *path)
{
    fflush(stderr);
    int saved = dup(2), fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    T_ASSERT(saved >= 0 && fd >= 0);
    dup2(fd, 2);
    close(fd);
    return saved;
}

static char *stderr_back(int saved, const char *path)
{
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    rs_err e = {0};
    char *s = rs_read_file(path, 1 << 20, NULL, &e);
    T_ASSERTF(s, "%s", e.msg);
    return s;
}

/* the header's face table, written out again independently of r_ibl.c */
static void gl_face_dir(int f, double s, double t, float d[3])
{
    const double v[6][3] = {{1, -t, -s}, {-1, -t, s}, {s, 1, t}, {s, -1, -t}, {s, -t, 1}, {-s, -t, -1}};
    for (int k = 0; k < 3; k++)
        d[k] = (float)v[f][k];
    unit(d);
}

/* ---------- cube maps ---------- */

static void t_cube_round_trip(void)
{
    static const int ns[] = {1, 3, 16};
    for (size_t q = 0; q < sizeof ns / sizeof ns[0]; q++) {
        int n = ns[q];
        for (int f = 0; f < 6; f++)
            for (int j = 0; j < n; j++)
                for (int i = 0; i < n; i++) {
                    float d[3], g[3];
                    r_cube_dir(f, i, j, n, d);
                    gl_face_dir(f, 2.0 * (i + 0.5) / n - 1, 2.0 * (j + 0.5) / n - 1, g);
                    T_ASSERTF(angle_deg(d, g) < 1e-3, "n %d face %d (%d,%d): (%g %g %g), want (%g %g %g)", n, f, i,
                              j, d[0], d[1], d[2], g[0], g[1], g[2]);
                    T_ASSERT(fabs(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - 1) < 1e-6);
                    int f2, i2, j2;
                    r_cube_texel(d, n, &f2, &i2, &j2);
                    T_ASSERTF(f2 == f && i2 == i && j2 == j, "n %d: (%d %d %d) came back as (%d %d %d)", n, f, i, j,
                              f2, i2, j2);
                }
    }
    /* the face centres are the axes, in GL order */
    static const float axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int f = 0; f < 6; f++) {
        float d[3];
        r_cube_dir(f, 0, 0, 1, d);
        T_ASSERTF(angle_deg(d, axes[f]) < 1e-4, "face %d centre", f);
    }
    /* odd directions must not crash or index out of range */
    float zero[3] = {0, 0, 0}, bad[3] = {NAN, 1, 0}, edge[3] = {1, 1, 1}, inf[3] = {INFINITY, 0, -INFINITY};
    int f, i, j;
    r_cube_texel(inf, 8, &f, &i, &j);
    T_ASSERT(f >= 0 && f < 6 && i >= 0 && i < 8 && j >= 0 && j < 8);
    r_cube_texel(zero, 8, &f, &i, &j);
    T_ASSERT(f >= 0 && f < 6 && i >= 0 && i < 8 && j >= 0 && j < 8);
    r_cube_texel(bad, 8, &f, &i, &j);
    T_ASSERT(f >= 0 && f < 6 && i >= 0 && i < 8 && j >= 0 && j < 8);
    r_cube_texel(edge, 8, &f, &i, &j);
    T_ASSERT(f >= 0 && f < 6 && i >= 0 && i < 8 && j >= 0 && j < 8);
}

static void t_solid_angles(void)
{
    static const int ns[] = {1, 2, 3, 16, 64, 255};
    for (size_t q = 0; q < sizeof ns / sizeof ns[0]; q++) {
        int n = ns[q];
        double sum = 0;
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                double w = r_cube_texel_solid_angle(i, j, n);
                T_ASSERT(w > 0);
                sum += 6 * w;
            }
        T_ASSERTF(fabs(sum - 4 * PI) <= 1e-9 * 4 * PI, "n %d: sum %.15g", n, sum);
    }
    T_ASSERT(fabs(r_cube_texel_solid_angle(0, 0, 1) - 4 * PI / 6) < 1e-12);
    /* against a fine midpoint integral of the area element over the texel */
    static const int cases[][3] = {{0, 0, 4}, {1, 2, 4}, {5, 0, 7}};
    for (size_t q = 0; q < sizeof cases / sizeof cases[0]; q++) {
        int i = cases[q][0], j = cases[q][1], n = cases[q][2], m = 400;
        double x0 = 2.0 * i / n - 1, y0 = 2.0 * j / n - 1, h = 2.0 / n / m, sum = 0;
        for (int b = 0; b < m; b++)
            for (int a = 0; a < m; a++) {
                double x = x0 + (a + 0.5) * h, y = y0 + (b + 0.5) * h, r2 = 1 + x * x + y * y;
                sum += h * h / (r2 * sqrt(r2));
            }
        double w = r_cube_texel_solid_angle(i, j, n);
        T_ASSERTF(fabs(w - sum) < 1e-6 * sum, "texel (%d,%d) of %d: %.10g, integral %.10g", i, j, n, w, sum);
    }
}

/* ---------- the prefilter ---------- */

static void t_uniform_environment(void)
{
    r_stage st;
    flat_stage(&st, 1);
    r_env env;
    rs_err e = {0};
    T_ASSERTF(r_env_build(&st, 8, &env, &e), "%s", e.msg);
    for (int f = 0; f < 6; f++)
        for (int k = 0; k < 8 * 8 * 3; k++)
            T_ASSERTF(fabsf(env.face[f][k] - 1) < 1e-6f, "env face %d [%d] = %g", f, k, env.face[f][k]);
    r_env_free(&env);

    r_ibl ibl;
    T_ASSERTF(r_ibl_build(&st, NULL, NULL, &ibl, &e), "%s", e.msg);
    T_ASSERT(!ibl.from_cache && ibl.ms > 0);
    T_EQ(ibl.size[R_IBL_DIFFUSE], 16);
    T_EQ(ibl.size[R_IBL_SPEC16], 32);
    T_EQ(ibl.size[R_IBL_SPEC128], 32);
    /* no sun and no painted light: the key direction is straight up */
    T_ASSERT(ibl.key_dir[0] == 0 && ibl.key_dir[1] == 1 && ibl.key_dir[2] == 0);
    for (int m = 0; m < R_IBL_MAPS; m++)
        for (int f = 0; f < 6; f++)
            for (int j = 0; j < ibl.size[m]; j++)
                for (int i = 0; i < ibl.size[m]; i++) {
                    const float *on = texel(&ibl, m, R_IBL_KEY_ON, f, i, j);
                    for (int c = 0; c < 3; c++)
                        T_ASSERTF(fabsf(on[c] - 1) < 0.01f, "map %d face %d (%d,%d): %g", m, f, i, j, on[c]);
                    /* key off: the area around +Y is gone, the lower half does not see it */
                    const float *off = texel(&ibl, m, R_IBL_KEY_OFF, f, i, j);
                    if (f == 3)
                        T_ASSERTF(fabsf(off[0] - 1) < 0.01f, "key off, map %d -Y (%d,%d): %g", m, i, j, off[0]);
                    if (f == 2 && m == R_IBL_SPEC128 && abs(2 * i + 1 - ibl.size[m]) < 4 &&
                        abs(2 * j + 1 - ibl.size[m]) < 4)
                        T_ASSERTF(off[0] < 0.01f, "key off, spec128 at the key (%d,%d): %g", i, j, off[0]);
                }
    r_ibl_free(&ibl);
}

/* Sun only: every value is the lobe at the sun, known in closed form. */
static void t_sun_only(void)
{
    r_stage st;
    flat_stage(&st, 0);
    st.sun = true;
    st.sun_dir[0] = 0, st.sun_dir[1] = 1, st.sun_dir[2] = 0;
    st.sun_color[0] = st.sun_color[1] = st.sun_color[2] = 1;
    st.sun_intensity = 1;
    r_env env;
    rs_err e = {0};
    T_ASSERTF(r_env_build(&st, 8, &env, &e), "%s", e.msg);
    float key[3];
    r_ibl_key_dir(&st, &env, key);
    T_ASSERT(key[0] == 0 && key[1] == 1 && key[2] == 0);
    const float up[3] = {0, 1, 0}, side[3] = {1, 0, 0}, tilt[3] = {0, 0.5f, 0.8660254f};
    double v[3];
    r_ibl_eval(&st, &env, key, R_IBL_DIFFUSE, R_IBL_KEY_ON, up, v);
    T_ASSERTF(fabs(v[0] - 1 / PI) < 1e-4 && fabs(v[2] - 1 / PI) < 1e-4, "diffuse up %g, want %g", v[0], 1 / PI);
    r_ibl_eval(&st, &env, key, R_IBL_DIFFUSE, R_IBL_KEY_ON, tilt, v);
    T_ASSERTF(fabs(v[1] - 0.5 / PI) < 1e-4, "diffuse at 60 degrees %g, want %g", v[1], 0.5 / PI);
    r_ibl_eval(&st, &env, key, R_IBL_DIFFUSE, R_IBL_KEY_ON, side, v);
    T_ASSERT(fabs(v[0]) < 1e-6);
    r_ibl_eval(&st, &env, key, R_IBL_SPEC128, R_IBL_KEY_ON, up, v);
    T_ASSERTF(fabs(v[0] - 129 / (2 * PI)) < 1e-4, "spec128 at the sun %g, want %g", v[0], 129 / (2 * PI));
    r_ibl_eval(&st, &env, key, R_IBL_SPEC16, R_IBL_KEY_ON, up, v);
    T_ASSERTF(fabs(v[0] - 17 / (2 * PI)) < 1e-4, "spec16 at the sun %g, want %g", v[0], 17 / (2 * PI));
    for (int m = 0; m < R_IBL_MAPS; m++) {
        r_ibl_eval(&st, &env, key, m, R_IBL_KEY_OFF, up, v);
        T_ASSERT(v[0] == 0 && v[1] == 0 && v[2] == 0);
    }
    r_env_free(&env);

    r_ibl ibl;
    r_ibl_params p = params(8, 8, 8, 8);
    T_ASSERTF(r_ibl_build(&st, &p, NULL, &ibl, &e), "%s", e.msg);
    for (int m = 0; m < R_IBL_MAPS; m++) {
        double ex = m == R_IBL_DIFFUSE ? 1 : r_ibl_exponent(m);
        double norm = m == R_IBL_DIFFUSE ? 1 / PI : (ex + 1) / (2 * PI);
        for (int f = 0; f < 6; f++)
            for (int j = 0; j < 8; j++)
                for (int i = 0; i < 8; i++) {
                    float d[3];
                    r_cube_dir(f, i, j, 8, d);
                    double want = d[1] > 0 ? norm * pow(d[1], ex) : 0;
                    const float *on = texel(&ibl, m, R_IBL_KEY_ON, f, i, j);
                    const float *off = texel(&ibl, m, R_IBL_KEY_OFF, f, i, j);
                    T_ASSERTF(fabs(on[0] - want) <= 1e-4 * want + 1e-7, "map %d face %d (%d,%d): %g, want %g", m, f,
                              i, j, on[0], want);
                    T_ASSERT(off[0] == 0 && off[1] == 0 && off[2] == 0);
                }
    }
    r_ibl_free(&ibl);
}

/* Key off differs from key on only where a lobe can reach the key area. */
static void t_key_off_is_local(void)
{
    r_stage st;
    r_stage_defaults(&st);
    st.sun = false;
    rs_err e = {0};
    r_ibl ibl;
    T_ASSERTF(r_ibl_build(&st, NULL, NULL, &ibl, &e), "%s", e.msg);
    float key[3] = {st.key.dir[0], st.key.dir[1], st.key.dir[2]};
    unit(key);
    T_ASSERT(angle_deg(ibl.key_dir, key) < 1e-3);
    /* how far a lobe reaches (its 1e-7 cut; a hemisphere for diffuse), plus the fade's edge and a texel */
    const double reach[R_IBL_MAPS] = {90, 69, 29};
    int same = 0, near = 0;
    for (int m = 0; m < R_IBL_MAPS; m++)
        for (int f = 0; f < 6; f++)
            for (int j = 0; j < ibl.size[m]; j++)
                for (int i = 0; i < ibl.size[m]; i++) {
                    float d[3];
                    r_cube_dir(f, i, j, ibl.size[m], d);
                    double a = angle_deg(d, key);
                    const float *on = texel(&ibl, m, R_IBL_KEY_ON, f, i, j);
                    const float *off = texel(&ibl, m, R_IBL_KEY_OFF, f, i, j);
                    for (int c = 0; c < 3; c++)
                        T_ASSERT(off[c] <= on[c] * 1.000001f + 1e-7f);
                    if (a > st.key_area_deg + 5 + reach[m] + 6) {
                        T_ASSERTF(memcmp(on, off, 3 * sizeof(float)) == 0, "map %d, %.1f deg from the key: %g vs %g",
                                  m, a, on[0], off[0]);
                        same++;
                    }
                    if (a < 8) {
                        /* the painted key (4 x its colour) is most of what these lobes see */
                        T_ASSERTF(off[0] < 0.8f * on[0], "map %d, %.1f deg from the key: on %g off %g", m, a, on[0],
                                  off[0]);
                        near++;
                    }
                }
    T_ASSERT(same > 1000 && near > 10);
    r_ibl_free(&ibl);

    /* with the sun, the key is the sun and key off drops it */
    r_stage_defaults(&st);
    T_ASSERTF(r_ibl_build(&st, NULL, NULL, &ibl, &e), "%s", e.msg);
    T_ASSERT(angle_deg(ibl.key_dir, st.sun_dir) < 1e-3);
    int f, i, j;
    r_cube_texel(st.sun_dir, ibl.size[R_IBL_SPEC128], &f, &i, &j);
    const float *on = texel(&ibl, R_IBL_SPEC128, R_IBL_KEY_ON, f, i, j);
    const float *off = texel(&ibl, R_IBL_SPEC128, R_IBL_KEY_OFF, f, i, j);
    T_ASSERTF(on[0] > 20 && off[0] < 0.05f * on[0], "spec128 at the sun: on %g off %g", on[0], off[0]);
    r_ibl_free(&ibl);
}

/* The maps are r_ibl_eval at each texel, bit for bit, whatever the thread count. */
static void t_prefilter_is_eval(void)
{
    r_stage st;
    r_stage_defaults(&st);
    rs_err e = {0};
    r_ibl_params p = params(16, 8, 16, 16);
    p.threads = 1;
    r_ibl one, three;
    T_ASSERTF(r_ibl_build(&st, &p, NULL, &one, &e), "%s", e.msg);
    p.threads = 3;
    T_ASSERTF(r_ibl_build(&st, &p, NULL, &three, &e), "%s", e.msg);
    T_ASSERT(ibl_same(&one, &three));
    r_env env;
    T_ASSERTF(r_env_build(&st, 16, &env, &e), "%s", e.msg);
    int checked = 0;
    for (int m = 0; m < R_IBL_MAPS; m++)
        for (int key = 0; key < 2; key++)
            for (int f = 0; f < 6; f++)
                for (int k = (m * 7 + key * 3 + f) % 11; k < one.size[m] * one.size[m]; k += 11) {
                    int i = k % one.size[m], j = k / one.size[m];
                    float d[3];
                    r_cube_dir(f, i, j, one.size[m], d);
                    double v[3];
                    r_ibl_eval(&st, &env, one.key_dir, m, key, d, v);
                    const float *t = texel(&one, m, key, f, i, j);
                    for (int c = 0; c < 3; c++)
                        T_ASSERTF(t[c] == (float)v[c],
                                  "map %d key %d face %d (%d,%d): %.9g vs %.9g", m, key, f, i, j, t[c], v[c]);
                    checked++;
                }
    T_ASSERT(checked > 300);
    r_env_free(&env);
    r_ibl_free(&one);
    r_ibl_free(&three);
}

static double smooth(double e0, double e1, double x)
{
    double t = (x - e0) / (e1 - e0);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t * t * (3 - 2 * t);
}

/* r_ibl_eval against the header's definition summed plainly in the test:
 * no lobe cut-off, pow(), the key fade written out. */
static void t_eval_is_the_definition(void)
{
    r_stage st;
    r_stage_defaults(&st);
    rs_err e = {0};
    enum { N = 12 };
    r_env env;
    T_ASSERTF(r_env_build(&st, N, &env, &e), "%s", e.msg);
    float key[3];
    r_ibl_key_dir(&st, &env, key);
    /* directions from the key towards a perpendicular, through the fade band */
    float side[3] = {key[1], -key[0], 0};
    unit(side);
    static const double deg[] = {0, 10, 20, 25, 27.5, 30, 35, 45, 70, 100, 150};
    for (size_t q = 0; q < sizeof deg / sizeof deg[0]; q++) {
        double a = deg[q] * PI / 180;
        float n[3];
        for (int k = 0; k < 3; k++)
            n[k] = (float)(cos(a) * key[k] + sin(a) * side[k]);
        unit(n);
        for (int m = 0; m < R_IBL_MAPS; m++) {
            double ex = m == R_IBL_DIFFUSE ? 1 : r_ibl_exponent(m);
        double norm = m == R_IBL_DIFFUSE ? 1 / PI : (ex + 1) / (2 * PI);
            double want[2][3] = {{0}};
            for (int f = 0; f < 6; f++)
                for (int j = 0; j < N; j++)
                    for (int i = 0; i < N; i++) {
                        float d[3];
                        gl_face_dir(f, 2.0 * (i + 0.5) / N - 1, 2.0 * (j + 0.5) / N - 1, d);
                        double c = (double)n[0] * d[0] + (double)n[1] * d[1] + (double)n[2] * d[2];
                        double w = c > 0 ? norm * pow(c, ex) * r_cube_texel_solid_angle(i, j, N) : 0;
                        double fade = smooth(st.key_area_deg, st.key_area_deg + 5, angle_deg(d, key));
                        for (int k = 0; k < 3; k++) {
                            double L = env.face[f][(j * N + i) * 3 + k];
                            want[R_IBL_KEY_ON][k] += w * L;
                            want[R_IBL_KEY_OFF][k] += w * L * fade;
                        }
                    }
            double cs = (double)n[0] * st.sun_dir[0] + (double)n[1] * st.sun_dir[1] + (double)n[2] * st.sun_dir[2];
            for (int k = 0; k < 3; k++)
                want[R_IBL_KEY_ON][k] += cs > 0 ? norm * pow(cs, ex) * st.sun_intensity * st.sun_color[k] : 0;
            for (int key_on = 0; key_on < 2; key_on++) {
                double v[3];
                r_ibl_eval(&st, &env, key, m, key_on, n, v);
                for (int k = 0; k < 3; k++)
                    T_ASSERTF(fabs(v[k] - want[key_on][k]) <= 5e-5 * want[key_on][k] + 1e-6,
                              "map %d key %d, %.1f deg from the key [%d]: %.8g, want %.8g", m, key_on, deg[q], k, v[k],
                              want[key_on][k]);
            }
        }
    }
    r_env_free(&env);
}

/* The procedural sky: zenith, the sqrt gradient, ground, a painted disc. */
static void t_procedural_sky(void)
{
    r_stage st;
    r_stage_defaults(&st);
    st.counter.intensity = 0;
    rs_err e = {0};
    enum { N = 64 };
    r_env env;
    T_ASSERTF(r_env_build(&st, N, &env, &e), "%s", e.msg);
    struct {
        float d[3];
        double zen, gnd, key; /* weights of zenith, ground, painted key; horizon takes the rest of zen + gnd */
    } probes[] = {
        {{0, 1, 0}, 1, 0, 0},
        {{0.8660254f, 0.5f, 0}, 0.70710678, 0, 0},
        {{0, 0.25f, -0.96824584f}, 0.5, 0, 0},
        {{0, 0.0625f, 0.99804496f}, 0.25, 0, 0},
        {{0, -1, 0}, 0, 1, 0},
        {{0.5f, -0.2f, 0.8426150f}, 0, 1, 0},
        {{st.key.dir[0], st.key.dir[1], st.key.dir[2]}, 0, 0, 1},
    };
    for (size_t q = 0; q < sizeof probes / sizeof probes[0]; q++) {
        unit(probes[q].d);
        int f, i, j;
        r_cube_texel(probes[q].d, N, &f, &i, &j);
        float c[3];
        r_cube_dir(f, i, j, N, c);
        /* the texel centre, not the probe, is what the texel holds */
        double zen = probes[q].zen ? sqrt(c[1] > 0 ? c[1] : 0) : 0, gnd = probes[q].gnd;
        for (int k = 0; k < 3; k++) {
            double want = st.sky_horizon[k] + (st.sky_zenith[k] - st.sky_horizon[k]) * zen +
                          (st.ground[k] - st.sky_horizon[k]) * gnd;
            if (probes[q].key)
                want = st.sky_horizon[k] + (st.sky_zenith[k] - st.sky_horizon[k]) * sqrt(c[1]) +
                       st.key.color[k] * st.key.intensity;
            double got = env.face[f][(j * N + i) * 3 + k];
            T_ASSERTF(fabs(got - want) < 0.01 * want, "probe %zu [%d]: %g, want %g", q, k, got, want);
        }
    }
    /* the painted disc: smoothstep falloff from its centre to its radius, then plain sky */
    float key[3] = {st.key.dir[0], st.key.dir[1], st.key.dir[2]}, side[3] = {key[1], -key[0], 0};
    unit(side);
    static const double deg[] = {3, 6, 9, 11, 14};
    for (size_t q = 0; q < sizeof deg / sizeof deg[0]; q++) {
        double a = deg[q] * PI / 180;
        float d[3], c[3];
        for (int k = 0; k < 3; k++)
            d[k] = (float)(cos(a) * key[k] + sin(a) * side[k]);
        int f, i, j;
        r_cube_texel(d, N, &f, &i, &j);
        r_cube_dir(f, i, j, N, c);
        double ac = angle_deg(c, key), disc = 1 - smooth(0, st.key.size_deg, ac);
        if (deg[q] > st.key.size_deg)
            T_ASSERT(ac > st.key.size_deg + 1); /* the whole texel is outside */
        for (int k = 0; k < 3; k++) {
            double want = st.sky_horizon[k] + (st.sky_zenith[k] - st.sky_horizon[k]) * sqrt(c[1]) +
                          st.key.color[k] * st.key.intensity * disc;
            double got = env.face[f][(j * N + i) * 3 + k];
            T_ASSERTF(fabs(got - want) < 0.01 * want, "%.1f deg from the key [%d]: %g, want %g", ac, k, got, want);
        }
    }
    r_env_free(&env);
}

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;

static double rnd(void)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(rng_state >> 11) / 9007199254740992.0 * 2 - 1;
}

/* Error against a 96-texel reference falls as the source grows. */
static void t_prefilter_converges(void)
{
    r_stage st;
    r_stage_defaults(&st);
    st.sun = false; /* a delta light is exact at any size: leave the sampled part */
    rs_err e = {0};
    enum { NDIR = 64 };
    float dirs[NDIR][3];
    for (int k = 0; k < NDIR; k++) {
        double x, y, z, l2;
        do {
            x = rnd(), y = rnd(), z = rnd();
            l2 = x * x + y * y + z * z;
        } while (l2 > 1 || l2 < 1e-4);
        dirs[k][0] = (float)x, dirs[k][1] = (float)y, dirs[k][2] = (float)z;
        unit(dirs[k]);
    }
    static double ref[R_IBL_MAPS][NDIR][3];
    r_env env;
    T_ASSERTF(r_env_build(&st, 96, &env, &e), "%s", e.msg);
    float key[3];
    r_ibl_key_dir(&st, &env, key);
    for (int m = 0; m < R_IBL_MAPS; m++)
        for (int k = 0; k < NDIR; k++)
            r_ibl_eval(&st, &env, key, m, R_IBL_KEY_ON, dirs[k], ref[m][k]);
    r_env_free(&env);
    static const int sizes[] = {8, 16, 32};
    double err[3][R_IBL_MAPS];
    for (int q = 0; q < 3; q++) {
        T_ASSERTF(r_env_build(&st, sizes[q], &env, &e), "%s", e.msg);
        for (int m = 0; m < R_IBL_MAPS; m++) {
            double sum = 0;
            for (int k = 0; k < NDIR; k++) {
                double v[3];
                r_ibl_eval(&st, &env, key, m, R_IBL_KEY_ON, dirs[k], v);
                for (int c = 0; c < 3; c++)
                    sum += fabs(v[c] - ref[m][k][c]) / (fabs(ref[m][k][c]) + 0.01);
            }
            err[q][m] = sum / (NDIR * 3);
        }
        r_env_free(&env);
    }
    for (int m = 0; m < R_IBL_MAPS; m++) {
        printf("  map %d: mean relative error %.5f (src 8) %.5f (16) %.5f (32)\n", m, err[0][m], err[1][m], err[2][m]);
        T_ASSERTF(err[1][m] < err[0][m] && err[2][m] < err[1][m], "map %d does not converge", m);
        T_ASSERTF(err[2][m] < 0.03, "map %d: %.4f at src 32", m, err[2][m]);
    }
}

static void t_key_dir_choice(void)
{
    r_stage st;
    r_stage_defaults(&st);
    float d[3];
    r_ibl_key_dir(&st, NULL, d);
    T_ASSERT(angle_deg(d, st.sun_dir) < 1e-4);
    st.sun = false;
    r_ibl_key_dir(&st, NULL, d);
    T_ASSERT(angle_deg(d, st.key.dir) < 1e-4);
    st.key.intensity = 0;
    r_ibl_key_dir(&st, NULL, d);
    T_ASSERT(angle_deg(d, st.counter.dir) < 1e-4);
    st.counter.intensity = 0;
    r_ibl_key_dir(&st, NULL, d);
    T_ASSERT(d[0] == 0 && d[1] == 1 && d[2] == 0);
}

/* Absurd stage values stay in half-float range; nothing is NaN. */
static void t_clamped(void)
{
    r_stage st;
    r_stage_defaults(&st);
    st.sky_zenith[0] = 1e30f;
    st.sky_horizon[1] = NAN;
    st.ground[2] = -5;
    st.sun_intensity = 65504;
    st.key.intensity = 65504;
    rs_err e = {0};
    r_ibl ibl;
    r_ibl_params p = params(8, 4, 8, 8);
    T_ASSERTF(r_ibl_build(&st, &p, NULL, &ibl, &e), "%s", e.msg);
    for (int m = 0; m < R_IBL_MAPS; m++)
        for (int k = 0; k < 2; k++)
            for (int f = 0; f < 6; f++)
                for (int i = 0; i < ibl.size[m] * ibl.size[m] * 3; i++) {
                    float v = ibl.map[m][k][f][i];
                    T_ASSERTF(v >= 0 && v <= R_HALF_MAX, "map %d key %d face %d [%d] = %g", m, k, f, i, v);
                }
    r_ibl_free(&ibl);
    p.src_size = 0;
    p.out_size[1] = R_IBL_MAX_SIZE + 1;
    T_ASSERT(!r_ibl_build(&st, &p, NULL, &ibl, &e));
    T_EQ(e.code, R_IBL_ERR_PARAMS);
    T_CONTAINS(e.msg, "513");
}

/* ---------- the cache ---------- */

static void cache_file(const char *dir, uint64_t hash, char *out, size_t n)
{
    snprintf(out, n, "%s/ibl-%016llx.bin", dir, (unsigned long long)hash);
}

static void t_cache_round_trip(void)
{
    char dir[512];
    snprintf(dir, sizeof dir, "%s/cache/a/b", t_tmpdir());
    r_stage st;
    r_stage_defaults(&st);
    r_ibl_params p = params(16, 8, 8, 8);
    rs_err e = {0};
    r_ibl a, b;
    T_ASSERTF(r_ibl_build(&st, &p, dir, &a, &e), "%s", e.msg);
    T_ASSERT(!a.from_cache && a.ms > 0);
    char path[600];
    cache_file(dir, a.hash, path, sizeof path);
    struct stat sb;
    T_ASSERTF(stat(path, &sb) == 0, "no cache file %s", path);
    T_ASSERT(r_ibl_build(&st, &p, dir, &b, &e));
    T_ASSERT(b.from_cache && b.ms == 0);
    T_ASSERT(ibl_same(&a, &b));
    r_ibl_free(&b);
    /* the thread count is not part of the key */
    p.threads = 2;
    T_ASSERT(r_ibl_build(&st, &p, dir, &b, &e));
    T_ASSERT(b.from_cache && ibl_same(&a, &b));
    r_ibl_free(&b);
    r_ibl_free(&a);
}

static void t_cache_corrupt(void)
{
    const char *tmp = t_tmpdir();
    char dir[512], log[512], path[600];
    snprintf(dir, sizeof dir, "%s/cache", tmp);
    snprintf(log, sizeof log, "%s/stderr.txt", tmp);
    r_stage st;
    r_stage_defaults(&st);
    r_ibl_params p = params(8, 4, 8, 8);
    rs_err e = {0};
    r_ibl good;
    T_ASSERTF(r_ibl_build(&st, &p, dir, &good, &e), "%s", e.msg);
    cache_file(dir, good.hash, path, sizeof path);
    size_t len = 0;
    uint8_t *orig = (uint8_t *)rs_read_file(path, 1 << 24, &len, &e);
    T_ASSERT(orig && len > 100);
    struct {
        const char *name;
        size_t keep;  /* bytes kept */
        long flip;    /* byte flipped, -1 none */
        const char *why;
    } cases[] = {
        {"flipped data byte", len, (long)len / 2, "checksum mismatch"},
        {"flipped magic", len, 1, "bad magic"},
        {"flipped version", len, 8, "format version"},
        {"flipped checksum", len, (long)len - 1, "checksum mismatch"},
        {"truncated", len / 2, -1, "expected"},
        {"header only", 30, -1, "shorter than its header"},
        {"empty", 0, -1, "shorter than its header"},
        {"one byte longer", len + 1, -1, "longer than"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        uint8_t *bad = calloc(1, len + 1);
        memcpy(bad, orig, len);
        if (cases[c].flip >= 0)
            bad[cases[c].flip] ^= 0x20;
        FILE *f = fopen(path, "wb");
        T_ASSERT(f && fwrite(bad, 1, cases[c].keep, f) == cases[c].keep && fclose(f) == 0);
        free(bad);
        int saved = stderr_to(log);
        r_ibl again;
        bool ok = r_ibl_build(&st, &p, dir, &again, &e);
        char *said = stderr_back(saved, log);
        T_ASSERTF(ok, "%s: %s", cases[c].name, e.msg);
        T_ASSERTF(!again.from_cache, "%s: read from a corrupt cache", cases[c].name);
        T_ASSERT(ibl_same(&good, &again));
        T_CONTAINS(said, "corrupt IBL cache");
        T_CONTAINS(said, path);
        T_CONTAINS(said, cases[c].why);
        T_CONTAINS(said, "rebuilding");
        T_ASSERTF(strchr(said, '\n') == said + strlen(said) - 1, "%s: not one line: %s", cases[c].name, said);
        free(said);
        r_ibl_free(&again);
        /* rebuilt and rewritten: the next build reads it */
        T_ASSERT(r_ibl_build(&st, &p, dir, &again, &e));
        T_ASSERTF(again.from_cache, "%s: the cache was not rewritten", cases[c].name);
        T_ASSERT(ibl_same(&good, &again));
        r_ibl_free(&again);
    }
    free(orig);
    r_ibl_free(&good);
}

static void t_cache_unwritable(void)
{
    const char *tmp = t_tmpdir();
    char dir[512], log[512];
    t_write(tmp, "plain", "a file where the cache directory should go\n");
    snprintf(dir, sizeof dir, "%s/plain/cache", tmp);
    snprintf(log, sizeof log, "%s/stderr.txt", tmp);
    r_stage st;
    r_stage_defaults(&st);
    r_ibl_params p = params(8, 4, 4, 4);
    rs_err e = {0};
    r_ibl ibl;
    int saved = stderr_to(log);
    bool ok = r_ibl_build(&st, &p, dir, &ibl, &e);
    char *said = stderr_back(saved, log);
    T_ASSERTF(ok, "%s", e.msg);
    T_ASSERT(!ibl.from_cache);
    T_CONTAINS(said, "warning");
    T_CONTAINS(said, "IBL cache not saved");
    free(said);
    r_ibl_free(&ibl);
}

static void t_cache_key(void)
{
    r_stage st, v;
    r_stage_defaults(&st);
    r_ibl_params p, q;
    r_ibl_default_params(&p);
    uint64_t base, h;
    rs_err e = {0};
    T_ASSERT(r_ibl_hash(&st, &p, &base, &e));
    T_ASSERT(r_ibl_hash(&st, NULL, &h, &e) && h == base);
    q = p, q.threads = 5;
    T_ASSERT(r_ibl_hash(&st, &q, &h, &e) && h == base);
    q = (r_ibl_params){0}; /* zeros are the defaults */
    T_ASSERT(r_ibl_hash(&st, &q, &h, &e) && h == base);
#define DIFFERS(what)                                                                    \
    do {                                                                                 \
        T_ASSERT(r_ibl_hash(&v, &q, &h, &e));                                            \
        T_ASSERTF(h != base, "%s does not change the cache key", what);                  \
    } while (0)
    v = st, q = p, q.src_size = 16;
    DIFFERS("src_size");
    v = st, q = p, q.out_size[R_IBL_SPEC128] = 16;
    DIFFERS("out_size");
    q = p;
    v = st, v.sky_zenith[2] = 0.91f;
    DIFFERS("sky_zenith");
    v = st, v.ground[0] = 0.5f;
    DIFFERS("ground");
    v = st, v.key.intensity = 3;
    DIFFERS("key intensity");
    v = st, v.counter.size_deg = 21;
    DIFFERS("counter size");
    v = st, v.sun = false;
    DIFFERS("sun");
    v = st, v.sun_dir[0] = -0.41f;
    DIFFERS("sun_dir");
    v = st, v.key_area_deg = 30;
    DIFFERS("key_area_deg");
    /* tone-map settings are not lighting */
    v = st, v.exposure = 2, v.bloom = 1;
    T_ASSERT(r_ibl_hash(&v, &q, &h, &e) && h == base);
#undef DIFFERS
}

static void t_cache_dir_env(void)
{
    unsetenv("RINGSIDE_CACHE");
    unsetenv("XDG_CACHE_HOME");
    unsetenv("HOME");
    T_ASSERT(r_ibl_cache_dir() == NULL);
    setenv("HOME", "/home/x", 1);
    T_ASSERT(strcmp(r_ibl_cache_dir(), "/home/x/.cache/ringside") == 0);
    setenv("XDG_CACHE_HOME", "/var/xdg", 1);
    T_ASSERT(strcmp(r_ibl_cache_dir(), "/var/xdg/ringside") == 0);
    setenv("RINGSIDE_CACHE", "/tmp/rc", 1);
    T_ASSERT(strcmp(r_ibl_cache_dir(), "/tmp/rc") == 0);
    setenv("RINGSIDE_CACHE", "off", 1);
    T_ASSERT(r_ibl_cache_dir() == NULL);
    setenv("RINGSIDE_CACHE", "", 1);
    T_ASSERT(strcmp(r_ibl_cache_dir(), "/var/xdg/ringside") == 0);
}

/* ---------- loaded environments ---------- */

#ifdef RS_HAVE_OIIO
#define NEED_OIIO()
#else
#define NEED_OIIO() T_SKIP_INSTALL("built without OpenImageIO")
#endif

/* Radiance .hdr, flat (uncompressed) RGBE scanlines. */
static void write_hdr(const char *path, int w, int h, const float *rgb)
{
    FILE *f = fopen(path, "wb");
    T_ASSERT(f);
    fprintf(f, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n", h, w);
    for (int k = 0; k < w * h; k++) {
        const float *c = rgb + 3 * k;
        float mx = c[0] > c[1] ? c[0] : c[1];
        mx = mx > c[2] ? mx : c[2];
        uint8_t b[4] = {0, 0, 0, 0};
        if (mx > 1e-32f) {
            int ex;
            double s = frexp(mx, &ex) * 256.0 / mx;
            b[0] = (uint8_t)(c[0] * s), b[1] = (uint8_t)(c[1] * s), b[2] = (uint8_t)(c[2] * s);
            b[3] = (uint8_t)(ex + 128);
        }
        /* (2,2,x<128) would read as a run-length scanline, (1,1,1) as a repeat */
        T_ASSERT(!(b[0] == 2 && b[1] == 2) && !(b[0] == 1 && b[1] == 1 && b[2] == 1));
        fwrite(b, 1, 4, f);
    }
    T_ASSERT(fclose(f) == 0);
}

/* Portable float map: exact floats, NaN and Inf included; rows bottom-up. */
static void write_pfm(const char *path, int w, int h, const float *rgb)
{
    FILE *f = fopen(path, "wb");
    T_ASSERT(f);
    fprintf(f, "PF\n%d %d\n-1.0\n", w, h); /* negative scale: little-endian (as this host) */
    for (int y = h - 1; y >= 0; y--)
        T_ASSERT(fwrite(rgb + (size_t)y * w * 3, sizeof(float), (size_t)w * 3, f) == (size_t)w * 3);
    T_ASSERT(fclose(f) == 0);
}

/* 64x32 equirect, 0.25 everywhere, a bright 2x2 block at u 0.75, v 0.25: +Z, 45 degrees up */
static void bright_equirect(const char *path, float bright)
{
    float *px = malloc(64 * 32 * 3 * sizeof(float));
    for (int k = 0; k < 64 * 32 * 3; k++)
        px[k] = 0.25f;
    for (int y = 7; y <= 8; y++)
        for (int x = 47; x <= 48; x++)
            for (int c = 0; c < 3; c++)
                px[(y * 64 + x) * 3 + c] = bright;
    write_hdr(path, 64, 32, px);
    free(px);
}

static void t_load_equirect(void)
{
    NEED_OIIO();
    const char *tmp = t_tmpdir();
    r_stage st;
    r_stage_defaults(&st);
    st.sun = false;
    snprintf(st.env_path, sizeof st.env_path, "%s/sky.hdr", tmp);
    bright_equirect(st.env_path, 8);
    rs_err e = {0};
    r_ibl_params p = params(16, 4, 8, 8);
    r_ibl ibl;
    T_ASSERTF(r_ibl_build(&st, &p, NULL, &ibl, &e), "%s", e.msg);
    const float want[3] = {0, 0.70710678f, 0.70710678f};
    T_ASSERTF(angle_deg(ibl.key_dir, want) < 6, "brightest at (%g %g %g), want (0 0.707 0.707)", ibl.key_dir[0],
              ibl.key_dir[1], ibl.key_dir[2]);
    r_ibl_free(&ibl);

    /* +90 degrees of yaw: +Z goes to +X */
    st.env_rotate_deg = 90;
    T_ASSERTF(r_ibl_build(&st, &p, NULL, &ibl, &e), "%s", e.msg);
    const float turned[3] = {0.70710678f, 0.70710678f, 0};
    T_ASSERTF(angle_deg(ibl.key_dir, turned) < 6, "turned: brightest at (%g %g %g), want (0.707 0.707 0)",
              ibl.key_dir[0], ibl.key_dir[1], ibl.key_dir[2]);
    r_ibl_free(&ibl);

    /* the image's values, scaled; the ground straight down is the plain 0.25 */
    st.env_rotate_deg = 0;
    r_env one, two;
    T_ASSERTF(r_env_build(&st, 16, &one, &e), "%s", e.msg);
    st.env_scale = 2;
    T_ASSERTF(r_env_build(&st, 16, &two, &e), "%s", e.msg);
    for (int f = 0; f < 6; f++)
        for (int k = 0; k < 16 * 16 * 3; k++)
            T_ASSERT(two.face[f][k] == 2 * one.face[f][k]);
    const float down[3] = {0, -1, 0};
    int f, i, j;
    r_cube_texel(down, 16, &f, &i, &j);
    T_ASSERT(fabsf(one.face[f][(j * 16 + i) * 3] - 0.25f) < 1e-6f);
    /* a loaded sky has no delta sun even when the stage has one */
    st.sun = true;
    float key[3];
    r_ibl_key_dir(&st, &one, key);
    T_ASSERT(angle_deg(key, st.sun_dir) < 1e-4);
    double v[3], w[3];
    r_ibl_eval(&st, &one, key, R_IBL_SPEC128, R_IBL_KEY_ON, key, v);
    st.sun = false;
    r_ibl_eval(&st, &one, key, R_IBL_SPEC128, R_IBL_KEY_ON, key, w);
    T_ASSERT(v[0] == w[0]);
    r_env_free(&one);
    r_env_free(&two);
}

/* A sun of 2x2 pixels in a 1024x512 image keeps its energy at any size. */
static void t_load_small_sun(void)
{
    NEED_OIIO();
    enum { W = 1024, H = 512 };
    float *px = calloc((size_t)W * H * 3, sizeof(float));
    double energy = 0;
    for (int y = 100; y <= 101; y++) {
        double top = PI * (0.5 - (double)y / H), bottom = PI * (0.5 - (y + 1.0) / H);
        for (int x = 300; x <= 301; x++) {
            for (int c = 0; c < 3; c++)
                px[(y * W + x) * 3 + c] = 1000;
            energy += 1000 * 2 * PI / W * (sin(top) - sin(bottom));
        }
    }
    r_stage st;
    r_stage_defaults(&st);
    st.sun = false;
    snprintf(st.env_path, sizeof st.env_path, "%s/sun.hdr", t_tmpdir());
    write_hdr(st.env_path, W, H, px);
    free(px);
    static const int sizes[] = {4, 16, 64};
    for (size_t q = 0; q < sizeof sizes / sizeof sizes[0]; q++) {
        int n = sizes[q];
        rs_err e = {0};
        r_env env;
        T_ASSERTF(r_env_build(&st, n, &env, &e), "%s", e.msg);
        double got = 0;
        for (int f = 0; f < 6; f++)
            for (int j = 0; j < n; j++)
                for (int i = 0; i < n; i++)
                    got += env.face[f][(j * n + i) * 3 + 1] * r_cube_texel_solid_angle(i, j, n);
        T_ASSERTF(fabs(got - energy) < 0.005 * energy, "size %d: energy %g, want %g", n, got, energy);
        /* and it is where the image has it: u 0.294, v 0.197 */
        float key[3], want[3];
        r_ibl_key_dir(&st, &env, key);
        double lon = 2 * PI * (301.0 / W - 0.5), lat = PI * (0.5 - 101.0 / H);
        want[0] = (float)(cos(lat) * cos(lon)), want[1] = (float)sin(lat), want[2] = (float)(cos(lat) * sin(lon));
        T_ASSERTF(angle_deg(key, want) < 100.0 / n, "size %d: sun at %.1f deg from where it is", n,
                  angle_deg(key, want));
        r_env_free(&env);
    }
}

/* A face-by-face picture of g(d) = 0.5 + 0.4 d in a strip or a cross. */
static const int cross_cell[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}};

static float *cube_picture(int c, bool cross, int *w, int *h, float (**dirs)[3])
{
    *w = cross ? 4 * c : 6 * c;
    *h = cross ? 3 * c : c;
    float *px = calloc((size_t)*w * *h * 3, sizeof(float));
    *dirs = calloc((size_t)*w * *h, sizeof **dirs);
    for (int f = 0; f < 6; f++)
        for (int j = 0; j < c; j++)
            for (int i = 0; i < c; i++) {
                int x = cross ? cross_cell[f][0] * c + i : f * c + i, y = cross ? cross_cell[f][1] * c + j : j;
                float *d = (*dirs)[y * *w + x];
                gl_face_dir(f, 2.0 * (i + 0.5) / c - 1, 2.0 * (j + 0.5) / c - 1, d);
                for (int k = 0; k < 3; k++)
                    px[(y * *w + x) * 3 + k] = 0.5f + 0.4f * d[k];
            }
    return px;
}

static void t_load_strip_and_cross(void)
{
    NEED_OIIO();
    const char *tmp = t_tmpdir();
    enum { C = 8 };
    for (int cross = 0; cross < 2; cross++) {
        int w, h;
        float (*dirs)[3];
        float *px = cube_picture(C, cross, &w, &h, &dirs);
        if (cross) {
            /* the layout itself: every seam of the net joins neighbouring directions */
            int seams = 0;
            for (int y = C; y < 2 * C; y++)
                for (int k = 1; k <= 4; k++) {
                    T_ASSERT(angle_deg(dirs[y * w + k * C - 1], dirs[y * w + (k * C) % w]) < 12);
                    seams++;
                }
            for (int x = C; x < 2 * C; x++) {
                T_ASSERT(angle_deg(dirs[(C - 1) * w + x], dirs[C * w + x]) < 12);
                T_ASSERT(angle_deg(dirs[(2 * C - 1) * w + x], dirs[2 * C * w + x]) < 12);
                seams += 2;
            }
            T_EQ(seams, 6 * C);
        }
        r_stage st;
        r_stage_defaults(&st);
        st.sun = false;
        snprintf(st.env_path, sizeof st.env_path, "%s/%s.pfm", tmp, cross ? "cross" : "strip");
        write_pfm(st.env_path, w, h, px);
        rs_err e = {0};
        r_env env;
        T_ASSERTF(r_env_build(&st, C, &env, &e), "%s", e.msg);
        for (int f = 0; f < 6; f++)
            for (int j = 0; j < C; j++)
                for (int i = 0; i < C; i++) {
                    float d[3];
                    r_cube_dir(f, i, j, C, d);
                    const float *v = env.face[f] + (j * C + i) * 3;
                    for (int k = 0; k < 3; k++)
                        T_ASSERTF(fabsf(v[k] - (0.5f + 0.4f * d[k])) < 1e-5f, "%s face %d (%d,%d)[%d]: %g, want %g",
                                  cross ? "cross" : "strip", f, i, j, k, v[k], 0.5f + 0.4f * d[k]);
                }
        r_env_free(&env);
        /* half the size: area averages of the same picture */
        T_ASSERTF(r_env_build(&st, C / 2, &env, &e), "%s", e.msg);
        for (int f = 0; f < 6; f++)
            for (int k = 0; k < (C / 2) * (C / 2); k++) {
                float d[3];
                r_cube_dir(f, k % (C / 2), k / (C / 2), C / 2, d);
                T_ASSERT(fabsf(env.face[f][k * 3 + 1] - (0.5f + 0.4f * d[1])) < 0.03f);
            }
        r_env_free(&env);
        free(px);
        free(dirs);
    }
}

/* NaN, Inf and negative pixels read as 0, huge ones as 65504. */
static void t_load_bad_values(void)
{
    NEED_OIIO();
    float px[8 * 4 * 3];
    for (int k = 0; k < 8 * 4 * 3; k++)
        px[k] = k % 4 == 0 ? NAN : k % 4 == 1 ? INFINITY : k % 4 == 2 ? -5.0f : 1e30f;
    r_stage st;
    r_stage_defaults(&st);
    snprintf(st.env_path, sizeof st.env_path, "%s/bad.pfm", t_tmpdir());
    write_pfm(st.env_path, 8, 4, px);
    rs_err e = {0};
    r_env env;
    T_ASSERTF(r_env_build(&st, 4, &env, &e), "%s", e.msg);
    for (int f = 0; f < 6; f++)
        for (int k = 0; k < 4 * 4 * 3; k++)
            T_ASSERT(env.face[f][k] >= 0 && env.face[f][k] <= R_HALF_MAX);
    r_env_free(&env);
    r_ibl ibl;
    r_ibl_params p = params(4, 4, 4, 4);
    T_ASSERTF(r_ibl_build(&st, &p, NULL, &ibl, &e), "%s", e.msg);
    for (int m = 0; m < R_IBL_MAPS; m++)
        for (int k = 0; k < 4 * 4 * 3; k++)
            T_ASSERT(ibl.map[m][1][0][k] >= 0 && ibl.map[m][1][0][k] <= R_HALF_MAX);
    r_ibl_free(&ibl);
}

static void t_load_errors(void)
{
    NEED_OIIO();
    const char *tmp = t_tmpdir();
    r_stage st;
    r_stage_defaults(&st);
    rs_err e = {0};
    r_env env;
    float px[30 * 20 * 3];
    for (int k = 0; k < 30 * 20 * 3; k++)
        px[k] = 0.5f;
    snprintf(st.env_path, sizeof st.env_path, "%s/wrong.hdr", tmp);
    write_hdr(st.env_path, 30, 20, px);
    T_ASSERT(!r_env_build(&st, 8, &env, &e));
    T_EQ(e.code, R_IBL_ERR_FORMAT);
    T_CONTAINS(e.msg, st.env_path);
    T_CONTAINS(e.msg, ": 30x20 is not an equirectangular (2:1), 6:1 strip or 4:3 cross image");
    r_ibl ibl;
    T_ASSERT(!r_ibl_build(&st, NULL, NULL, &ibl, &e));
    T_EQ(e.code, R_IBL_ERR_FORMAT);

    t_write(tmp, "junk.hdr", "#?RADIANCE but then nothing an image needs\n\x01\x02garbage");
    snprintf(st.env_path, sizeof st.env_path, "%s/junk.hdr", tmp);
    T_ASSERT(!r_env_build(&st, 8, &env, &e));
    T_EQ(e.code, R_IBL_ERR_FILE);
    T_CONTAINS(e.msg, st.env_path);
    T_ASSERT(!strchr(e.msg, '\n'));

    snprintf(st.env_path, sizeof st.env_path, "%s/missing.exr", tmp);
    T_ASSERT(!r_env_build(&st, 8, &env, &e));
    T_EQ(e.code, R_IBL_ERR_FILE);
    T_CONTAINS(e.msg, st.env_path);
    T_ASSERT(!r_ibl_build(&st, NULL, tmp, &ibl, &e));
    T_EQ(e.code, R_IBL_ERR_FILE);
    T_CONTAINS(e.msg, "missing.exr: cannot open");
}

/* A loaded environment's key is its file's bytes: edit the file, rebuild. */
static void t_load_cache(void)
{
    NEED_OIIO();
    const char *tmp = t_tmpdir();
    char dir[512];
    snprintf(dir, sizeof dir, "%s/cache", tmp);
    r_stage st;
    r_stage_defaults(&st);
    snprintf(st.env_path, sizeof st.env_path, "%s/sky.hdr", tmp);
    bright_equirect(st.env_path, 8);
    r_ibl_params p = params(8, 4, 8, 8);
    rs_err e = {0};
    r_ibl a, b;
    T_ASSERTF(r_ibl_build(&st, &p, dir, &a, &e), "%s", e.msg);
    T_ASSERT(!a.from_cache);
    T_ASSERT(r_ibl_build(&st, &p, dir, &b, &e) && b.from_cache && ibl_same(&a, &b));
    r_ibl_free(&b);
    uint64_t h0 = a.hash, h;
    r_stage v = st;
    v.env_rotate_deg = 10;
    T_ASSERT(r_ibl_hash(&v, &p, &h, &e) && h != h0);
    v = st, v.env_scale = 3;
    T_ASSERT(r_ibl_hash(&v, &p, &h, &e) && h != h0);
    v = st, v.sky_zenith[0] = 5; /* the procedural sky does not matter here */
    T_ASSERT(r_ibl_hash(&v, &p, &h, &e) && h == h0);
    bright_equirect(st.env_path, 16);
    T_ASSERT(r_ibl_build(&st, &p, dir, &b, &e));
    T_ASSERT(!b.from_cache && b.hash != h0);
    r_ibl_free(&b);
    r_ibl_free(&a);
}

T_MAIN({"cube_round_trip", t_cube_round_trip}, {"solid_angles", t_solid_angles},
       {"uniform_environment", t_uniform_environment}, {"sun_only", t_sun_only},
       {"key_off_is_local", t_key_off_is_local}, {"prefilter_is_eval", t_prefilter_is_eval},
       {"eval_is_the_definition", t_eval_is_the_definition}, {"procedural_sky", t_procedural_sky},
       {"prefilter_converges", t_prefilter_converges}, {"key_dir_choice", t_key_dir_choice}, {"clamped", t_clamped},
       {"cache_round_trip", t_cache_round_trip}, {"cache_corrupt", t_cache_corrupt},
       {"cache_unwritable", t_cache_unwritable}, {"cache_key", t_cache_key}, {"cache_dir_env", t_cache_dir_env},
       {"load_equirect", t_load_equirect}, {"load_strip_and_cross", t_load_strip_and_cross},
       {"load_small_sun", t_load_small_sun},
       {"load_bad_values", t_load_bad_values}, {"load_errors", t_load_errors}, {"load_cache", t_load_cache})
