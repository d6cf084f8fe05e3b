#include "r_mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int reserve(r_mesh_data *m, size_t nv, size_t ni)
{
    if (m->nv + nv > m->capv) {
        size_t cap = m->capv ? m->capv * 2 : 1024;
        while (cap < m->nv + nv)
            cap *= 2;
        r_vertex *v = realloc(m->v, cap * sizeof *v);
        if (!v)
            return 0;
        m->v = v;
        m->capv = cap;
    }
    if (m->ni + ni > m->capi) {
        size_t cap = m->capi ? m->capi * 2 : 4096;
        while (cap < m->ni + ni)
            cap *= 2;
        unsigned *ix = realloc(m->idx, cap * sizeof *ix);
        if (!ix)
            return 0;
        m->idx = ix;
        m->capi = cap;
    }
    return 1;
}

/* Two triangles per quad between consecutive rows of seg + 1 vertices
 * from base on (a capsule's or a sphere's bands), counter-clockwise
 * seen from outside. */
static void band_indices(r_mesh_data *m, size_t base, int rows, int seg)
{
    for (int row = 0; row + 1 < rows; row++)
        for (int s = 0; s < seg; s++) {
            unsigned a = (unsigned)(base + (size_t)row * (seg + 1) + s), b = a + (unsigned)seg + 1;
            unsigned q[6] = {a, a + 1, b, a + 1, b + 1, b};
            memcpy(m->idx + m->ni, q, sizeof q);
            m->ni += 6;
        }
}

int r_mesh_capsule(r_mesh_data *m, float length, float r, int bone, int seg, int rings)
{
    /* a cylinder with two hemispherical caps, rows from the -x pole to the
     * +x pole; u runs around the axis, v along it */
    int rows = 2 * rings + 2;
    if (!reserve(m, (size_t)(rows * (seg + 1)), (size_t)((rows - 1) * seg * 6)))
        return 0;
    size_t base = m->nv;
    const float pi = 3.14159265f;
    for (int row = 0; row < rows; row++) {
        /* polar angle from the -x pole; the two middle rows share an angle */
        int k = row <= rings ? row : row - 1;
        float phi = pi * k / (2 * rings); /* 0 .. pi */
        float cx = row <= rings ? 0.0f : length;
        float ax = -cosf(phi), rad = sinf(phi);
        for (int s = 0; s <= seg; s++) {
            float th = 2 * pi * s / seg, cy = cosf(th), sz = sinf(th);
            r_vertex *v = &m->v[m->nv++];
            memset(v, 0, sizeof *v);
            v->normal[0] = ax;
            v->normal[1] = rad * cy;
            v->normal[2] = rad * sz;
            v->pos[0] = cx + r * ax;
            v->pos[1] = r * v->normal[1];
            v->pos[2] = r * v->normal[2];
            /* tangent: direction of increasing u (around the axis) */
            v->tangent[0] = 0;
            v->tangent[1] = -sz;
            v->tangent[2] = cy;
            v->tangent[3] = 1;
            v->uv[0] = (float)s / seg;
            v->uv[1] = (v->pos[0] + r) / (length + 2 * r);
            v->bone = (float)bone;
        }
    }
    band_indices(m, base, rows, seg);
    return 1;
}

int r_mesh_sphere_rows(r_mesh_data *m, int bone, int seg, const float *phi, int rows)
{
    /* the capsule's rows turned from the x axis to y ((x, y, z) -> (y, z, x)):
     * a rotation, so the same index pattern faces outwards */
    if (rows < 2 || !reserve(m, (size_t)(rows * (seg + 1)), (size_t)((rows - 1) * seg * 6)))
        return 0;
    size_t base = m->nv;
    const float pi = 3.14159265f;
    for (int row = 0; row < rows; row++) {
        float ay = -cosf(phi[row]), rad = sinf(phi[row]);
        for (int s = 0; s <= seg; s++) {
            float th = 2 * pi * s / seg, cy = cosf(th), sz = sinf(th);
            r_vertex *v = &m->v[m->nv++];
            memset(v, 0, sizeof *v);
            v->normal[0] = rad * sz, v->normal[1] = ay, v->normal[2] = rad * cy;
            memcpy(v->pos, v->normal, sizeof v->pos);
            v->tangent[0] = cy, v->tangent[1] = 0, v->tangent[2] = -sz, v->tangent[3] = 1;
            v->uv[0] = (float)s / seg;
            v->uv[1] = phi[row] / pi;
            v->bone = (float)bone;
        }
    }
    band_indices(m, base, rows, seg);
    return 1;
}

int r_mesh_box(r_mesh_data *m, const float lo[3], const float hi[3])
{
    if (!reserve(m, 24, 36))
        return 0;
    static const int axes[6][3] = {{0, 1, 2}, {0, 1, 2}, {1, 2, 0}, {1, 2, 0}, {2, 0, 1}, {2, 0, 1}};
    for (int f = 0; f < 6; f++) {
        int n = axes[f][2], u = axes[f][0], w = axes[f][1];
        float side = (f & 1) ? 1.0f : -1.0f;
        size_t base = m->nv;
        for (int k = 0; k < 4; k++) {
            r_vertex *v = &m->v[m->nv++];
            memset(v, 0, sizeof *v);
            float cu = (k == 1 || k == 2) ? 1.0f : 0.0f, cw = (k >= 2) ? 1.0f : 0.0f;
            v->pos[n] = side > 0 ? hi[n] : lo[n];
            v->pos[u] = lo[u] + cu * (hi[u] - lo[u]);
            v->pos[w] = lo[w] + cw * (hi[w] - lo[w]);
            v->normal[n] = side;
            v->tangent[u] = 1;
            v->tangent[3] = 1;
            v->uv[0] = v->pos[u];
            v->uv[1] = v->pos[w];
            v->bone = -1;
        }
        /* counter-clockwise seen from outside: the triangle's normal must
         * agree with the face normal, else swap the winding */
        unsigned b = (unsigned)base;
        unsigned q[6] = {b, b + 1, b + 2, b, b + 2, b + 3};
        const float *p0 = m->v[b].pos, *p1 = m->v[b + 1].pos, *p2 = m->v[b + 2].pos;
        float e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        float cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        if (cr[n] * side < 0) {
            q[1] = b + 2, q[2] = b + 1, q[4] = b + 3, q[5] = b + 2;
        }
        memcpy(m->idx + m->ni, q, sizeof q);
        m->ni += 6;
    }
    return 1;
}

int r_mesh_fighter(r_mesh_data *m, int lod)
{
    bool fine = lod == R_FIGHTER_FINE;
    for (int i = 0; i < G_BONES; i++) {
        const g_bone_def *b = &g_bones[i];
        int seg = b->radius > FX(0.1) ? (fine ? 20 : 14) : (fine ? 14 : 10);
        if (!r_mesh_capsule(m, fx_to_float(b->length), fx_to_float(b->radius), i, seg, fine ? 5 : 4))
            return 0;
    }
    return 1;
}

void r_mesh_free(r_mesh_data *m)
{
    free(m->v);
    free(m->idx);
    memset(m, 0, sizeof *m);
}
