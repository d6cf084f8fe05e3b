/* Destruction holes with stencil (docs/effects.md, "Destruction holes").
 *
 * The game places the craters (g_holes.c: heavy hits on a destructible
 * stage; part of the game state, so replays reproduce them).  The ring
 * mesh never changes: each hole is a separate sphere, cut into the floor
 * with the stencil buffer the way shadow volumes are.  One pass, "holes"
 * (phase R_FX_PRE, on stages with `holes = yes` and frames with at least
 * one hole), does the technique's steps 1-3; `scene` does 4-6:
 *
 *   1. the depth of the destructible terrain (the ring top), no colour;
 *   2. per hole, nearest first: its volume into the stencil (front faces
 *      that pass the depth test +1, back faces -1): non-zero where the
 *      ring top lies inside the sphere;
 *   3. the hole's inside (the sphere's inner surface) where the stencil is
 *      set and the depth test fails against the ring top (GL_GREATER: the
 *      part under the floor), writing its depth, so the fighters, the
 *      shadows and everything after follow the crater's shape; the
 *      stencil goes back to zero there, so a farther hole never shows
 *      through a nearer one;
 *   4. the fighters (scene), 5. the ring's sides and the ground,
 *   6. the ring top's colour where its depth is still its own (GL_EQUAL:
 *      scene.vert's gl_Position is invariant across programs).
 * Shadows (7, 8) are the silhouette and mask passes, read by 3 and 6; the
 * translucent passes (9, 10) come after the sky as before.
 *
 * Stencil: the low 7 bits; bit 0x80 stays the fighters' (R_STENCIL_FIGHTER). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../game/g_game.h"
#include "fx_local.h"
#include "fx_holes.h"

extern const r_fx_module fx_holes_module;
#define HOLES(r) ((struct fx_holes *)r_fx_state((r), &fx_holes_module))

#define LIFT 0.4f /* the sphere's centre stands 0.4 r above the floor */
/* The crater's sphere (crater_mesh), in two levels of detail chosen as
 * the fighters' mesh is (r_fx_mesh_lod: coarse below 540 rows drawn).  Round
 * the vertical axis, SEG segments; below the floor, where its inside is
 * seen, BELOW bands from the bottom pole to a row exactly on the floor, so
 * the rim is a polygon on the true circle; above the floor, where it only
 * closes the stencil's volume and is never drawn in colour, ABOVE bands.
 * The sphere they replaced was a capsule round the x axis, 32 segments
 * and 8 rings a cap: 1,088 triangles, where the fine level has 512 and
 * the coarse 240; on llvmpipe each of a crater's three draws pays per
 * triangle.  At 640x360 the coarse crater's 24-gon rim is within 0.7
 * pixels of the circle on the largest craters. */
static const struct crater_lod {
    int seg, below, above;
} crater_lod[R_FIGHTER_LODS] = {[R_FIGHTER_COARSE] = {24, 4, 1}, [R_FIGHTER_FINE] = {32, 6, 2}};
#define STENCIL_HOLES 0x7F

struct fx_holes {
    GLuint vao[R_FIGHTER_LODS], vbo[R_FIGHTER_LODS], ibo[R_FIGHTER_LODS]; /* crater_lod's levels */
    GLsizei count[R_FIGHTER_LODS];
    int drawn; /* holes drawn in the frame drawn last */
};

static bool need_holes(void *u)
{
    r_game *r = u;
    return HOLES(r) && r_fx_stage(r)->holes && r_fx_frame(r)->cur->nholes > 0;
}

static void model(const g_hole *h, float m[16])
{
    float rad = fx_to_float(h->r);
    memset(m, 0, 16 * sizeof(float));
    m[0] = m[5] = m[10] = rad;
    m[12] = fx_to_float(h->x), m[13] = LIFT * rad, m[14] = fx_to_float(h->z);
    m[15] = 1;
}

typedef struct order {
    float d2;
    int i;
} order;

static int nearer_first(const void *a, const void *b)
{
    const order *x = a, *y = b;
    if (x->d2 != y->d2)
        return x->d2 < y->d2 ? -1 : 1;
    return x->i - y->i;
}

static void run_holes(void *u)
{
    r_game *r = u;
    struct fx_holes *hs = HOLES(r);
    const frame *f = r_fx_frame(r);
    const g_state *st = f->cur;
    bool prepass = r_ran(f, r, "z_prepass");
    r_fx_gl core = r_fx_core_gl(r);
    gl.BindFramebuffer(GL_FRAMEBUFFER, core.hdr_fbo);
    gl.Viewport(0, 0, f->w, f->h);
    gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    gl.DepthMask(GL_TRUE);
    gl.StencilMask(0xFF);
    gl.ClearColor(0, 0, 0, 0);
    gl.Clear(GL_COLOR_BUFFER_BIT | (prepass ? 0 : GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT));
    gl.Disable(GL_BLEND);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_BACK);

    /* 1: the destructible terrain's depth */
    GLuint pd = core.prog_depth;
    gl.ColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    r_camera_uniforms(r, pd);
    gl.BindVertexArray(core.ring_vao);
    gl.DrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_INT, (const void *)(R_RING_TOP_FIRST * sizeof(unsigned)));

    /* nearest first */
    order o[G_MAX_HOLES];
    int n = st->nholes > G_MAX_HOLES ? G_MAX_HOLES : st->nholes;
    for (int i = 0; i < n; i++) {
        float dx = fx_to_float(st->holes[i].x) - f->eye.x, dz = fx_to_float(st->holes[i].z) - f->eye.z;
        o[i] = (order){dx * dx + f->eye.y * f->eye.y + dz * dz, i};
    }
    qsort(o, (size_t)n, sizeof o[0], nearer_first);

    GLuint ps = r_stage_program(r, R_MAT_HOLE); /* the crater's inside */
    gl.Enable(GL_STENCIL_TEST);
    gl.StencilMask(STENCIL_HOLES);
    int lod = r_fx_mesh_lod(r);
    GLsizei count = hs->count[lod];
    gl.BindVertexArray(hs->vao[lod]);
    for (int k = 0; k < n; k++) {
        float m[16];
        model(&st->holes[o[k].i], m);
        /* 2: the volume: +1 for front faces in front of the ring top, -1 for back faces */
        gl.ColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        gl.DepthMask(GL_FALSE);
        gl.DepthFunc(GL_LESS);
        gl.StencilFunc(GL_ALWAYS, 0, STENCIL_HOLES);
        gl.UseProgram(pd);
        gl.UniformMatrix4fv(r_loc(pd, "u_bones"), 1, GL_FALSE, m);
        gl.CullFace(GL_BACK);
        gl.StencilOp(GL_KEEP, GL_KEEP, GL_INCR_WRAP);
        gl.DrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, NULL);
        gl.CullFace(GL_FRONT);
        gl.StencilOp(GL_KEEP, GL_KEEP, GL_DECR_WRAP);
        gl.DrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, NULL);
        /* 3: the inside, under the floor, depth forced; stencil back to 0 */
        gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        gl.DepthMask(GL_TRUE);
        gl.DepthFunc(GL_GREATER);
        gl.StencilFunc(GL_NOTEQUAL, 0, STENCIL_HOLES);
        gl.StencilOp(GL_KEEP, GL_ZERO, GL_ZERO);
        gl.UseProgram(ps);
        gl.UniformMatrix4fv(r_loc(ps, "u_bones"), 1, GL_FALSE, m);
        gl.DrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, NULL); /* back faces: the inner surface */
    }
    hs->drawn = n;
    gl.Disable(GL_STENCIL_TEST);
    gl.StencilMask(0xFF);
    gl.StencilFunc(GL_ALWAYS, 0, 0xFF);
    gl.StencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    gl.CullFace(GL_BACK);
    gl.DepthFunc(GL_LESS);
    gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

static const r_pass holes_passes[] = {
    {"holes", RES_ENV, RES_HDR | RES_DEPTH, need_holes, run_holes, RES_MASK | RES_SIL | RES_FOGMAP | RES_LSPSM},
};

/* The unit sphere's rows at one of crater_lod's levels: the floor,
 * y = -LIFT, at the polar angle acos(LIFT) from the bottom pole. */
static int crater_mesh(r_mesh_data *m, const struct crater_lod *l)
{
    const float pi = 3.14159265f, floor_phi = acosf(LIFT);
    float phi[16];
    int n = 0;
    for (int k = 0; k <= l->below; k++)
        phi[n++] = floor_phi * (float)k / (float)l->below;
    for (int k = 1; k <= l->above; k++)
        phi[n++] = floor_phi + (pi - floor_phi) * (float)k / (float)l->above;
    return r_mesh_sphere_rows(m, 0, l->seg, phi, n);
}

static void holes_destroy(r_game *r)
{
    struct fx_holes *hs = HOLES(r);
    if (!hs)
        return;
    for (int k = 0; k < R_FIGHTER_LODS; k++)
        r_free_mesh(&hs->vao[k], &hs->vbo[k], &hs->ibo[k]);
    free(hs);
    r_fx_set_state(r, &fx_holes_module, NULL);
}

static bool holes_create(r_game *r, rs_err *err)
{
    struct fx_holes *hs = calloc(1, sizeof *hs);
    if (!hs)
        return rs_fail(err, R_ERR_NOMEM, "holes: out of memory");
    r_fx_set_state(r, &fx_holes_module, hs);
    /* the unit sphere on bone 0: u_bones[0] places it */
    for (int k = 0; k < R_FIGHTER_LODS; k++) {
        r_mesh_data m = {0};
        if (!crater_mesh(&m, &crater_lod[k])) {
            r_mesh_free(&m);
            holes_destroy(r);
            return rs_fail(err, R_ERR_NOMEM, "holes: out of memory");
        }
        r_upload_mesh(&m, &hs->vao[k], &hs->vbo[k], &hs->ibo[k]);
        hs->count[k] = (GLsizei)m.ni;
        r_mesh_free(&m);
    }
    RGL_CHECK("holes create");
    return true;
}

/* Inside "scene": the holes pass cleared the HDR target and drew already */
static bool holes_scene_cleared(r_game *r)
{
    return r_ran(r_fx_frame(r), r, "holes");
}

/* Steps 5 and 6 (scene has bound the stage program and the ring's VAO):
 * the indestructible parts, then the ring top's colour only where its own
 * depth is still there (the holes pass put the craters' depth in the rest). */
static bool holes_draw_ring(r_game *r)
{
    if (!r_ran(r_fx_frame(r), r, "holes"))
        return false;
    gl.DrawElements(GL_TRIANGLES, R_RING_TOP_FIRST, GL_UNSIGNED_INT, NULL);
    gl.DrawElements(GL_TRIANGLES, r_fx_core_gl(r).ring_count - R_RING_TOP_FIRST - 6, GL_UNSIGNED_INT,
                    (const void *)((R_RING_TOP_FIRST + 6) * sizeof(unsigned)));
    gl.DepthFunc(GL_EQUAL);
    gl.DrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_INT, (const void *)(R_RING_TOP_FIRST * sizeof(unsigned)));
    gl.DepthFunc(GL_LESS);
    return true;
}

/* History: none.  The craters are game state (g_holes.c); a frame draws
 * those of the state it is given. */
const r_fx_module fx_holes_module = {
    .name = "holes", .create = holes_create, .destroy = holes_destroy,
    .pass = {holes_passes}, .npass = {(int)(sizeof holes_passes / sizeof holes_passes[0])},
    .scene_cleared = holes_scene_cleared, .draw_ring = holes_draw_ring,
};

int fx_holes_drawn(r_game *r)
{
    return HOLES(r) ? HOLES(r)->drawn : 0;
}
