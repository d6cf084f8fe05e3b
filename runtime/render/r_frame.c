/* Per-frame set-up: the camera, the bones (interpolated for drawing,
 * whole ticks for the stage effects), the key light's projection, the
 * fighters' screen box, flash and sun visibility: everything the passes
 * read from r->f (r_local.h's frame). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../game/g_game.h"
#include "r_local.h"

const float r_fighter_color[2][3] = {{0.80f, 0.16f, 0.12f}, {0.14f, 0.32f, 0.85f}};
static const float skin[3] = {0.85f, 0.66f, 0.52f};

static void bone_matrices(const g_state *prev, const g_state *cur, int i, float alpha, float out[16][16])
{
    g_capsule a[G_BONES], b[G_BONES];
    g_fighter_capsules(cur, i, b);
    if (prev && prev->tick + 1 == cur->tick)
        g_fighter_capsules(prev, i, a);
    else
        memcpy(a, b, sizeof a);
    float facing = (float)cur->f[i].facing;
    for (int k = 0; k < G_BONES; k++) {
        float ax = fx_to_float(a[k].ax) + (fx_to_float(b[k].ax) - fx_to_float(a[k].ax)) * alpha;
        float ay = fx_to_float(a[k].ay) + (fx_to_float(b[k].ay) - fx_to_float(a[k].ay)) * alpha;
        float bx = fx_to_float(a[k].bx) + (fx_to_float(b[k].bx) - fx_to_float(a[k].bx)) * alpha;
        float by = fx_to_float(a[k].by) + (fx_to_float(b[k].by) - fx_to_float(a[k].by)) * alpha;
        r_vec3 d = r_norm(r_v3(bx - ax, by - ay, 0));
        if (d.x == 0 && d.y == 0)
            d = r_v3(1, 0, 0);
        float *m = out[k];
        memset(m, 0, 16 * sizeof(float));
        m[0] = d.x, m[1] = d.y;   /* x axis: along the bone */
        m[4] = -d.y, m[5] = d.x;  /* y axis */
        m[10] = 1;                /* z axis */
        m[12] = ax, m[13] = ay, m[14] = fx_to_float(b[k].z) * facing;
        m[15] = 1;
    }
}

void r_game_camera_parts(const g_state *st, int w, int h, r_mat4 *view, r_mat4 *proj, r_vec3 *eye_out)
{
    float x0 = fx_to_float(st->f[0].x), x1 = fx_to_float(st->f[1].x);
    float mid = (x0 + x1) / 2, gap = x1 > x0 ? x1 - x0 : x0 - x1;
    float dist = 4.2f + gap * 0.9f;
    r_vec3 at = r_v3(mid, 1.0f, 0), eye = r_v3(mid, 1.7f, dist);
    if (eye_out)
        *eye_out = eye;
    *proj = r_perspective(0.75f, (float)w / (float)h, 0.1f, 200.0f);
    *view = r_look_at(eye, at, r_v3(0, 1, 0));
}

r_mat4 r_game_camera(const g_state *st, int w, int h, r_vec3 *eye_out)
{
    r_mat4 view, proj;
    r_game_camera_parts(st, w, h, &view, &proj, eye_out);
    return r_mul(proj, view);
}

/* The screen rectangle the fighters can cover: the world box round their
 * bones (each bone's origin +-0.4 m, which holds the longest limb's far
 * end too) projected, plus MASK_REACH pixels.  The shadow mask is 1
 * (lit) outside it, so its passes draw only inside (a scissor). */
#define MASK_REACH 8 /* grow 1 px + blur 4 px at 720 rows (they scale with the height), with room to spare */
static void fighter_box(frame *f, const float lo[3], const float hi[3])
{
    float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
    bool whole = false;
    for (int k = 0; k < 8 && !whole; k++) {
        r_vec3 c = r_v3(k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]);
        float x, y;
        if (!r_project(f->vp, c, f->w, f->h, &x, &y)) {
            whole = true; /* a corner behind the camera: no safe bound */
            break;
        }
        x0 = fminf(x0, x), y0 = fminf(y0, y), x1 = fmaxf(x1, x), y1 = fmaxf(y1, y);
    }
    if (whole || !(x0 <= x1) || !(y0 <= y1)) {
        f->fig_box[0] = f->fig_box[1] = 0, f->fig_box[2] = f->w, f->fig_box[3] = f->h;
        return;
    }
    float reach = ceilf(MASK_REACH * fmaxf(1.0f, (float)f->h / R_REF_ROWS));
    float bx0 = fmaxf(floorf(x0) - reach, 0), by0 = fmaxf(floorf(y0) - reach, 0);
    float bx1 = fminf(ceilf(x1) + reach, (float)f->w), by1 = fminf(ceilf(y1) + reach, (float)f->h);
    f->fig_box[0] = (int)bx0, f->fig_box[1] = (int)by0;
    f->fig_box[2] = bx1 > bx0 ? (int)(bx1 - bx0) : 0, f->fig_box[3] = by1 > by0 ? (int)(by1 - by0) : 0;
}

/* The key light's orthographic projection, fitted round both fighters. */
static void light_setup(r_game *r, frame *f)
{
    /* the direction the IBL's key-light area is centred on (the sun, or
     * the brightest light of the environment): shadows take away exactly
     * the light the key-on/key-off maps differ by */
    const float *key = r->key_dir;
    float len = sqrtf(key[0] * key[0] + key[1] * key[1] + key[2] * key[2]);
    r_vec3 L = len > 1e-6f && isfinite(len) ? r_v3(key[0] / len, key[1] / len, key[2] / len) : r_v3(0, 1, 0);
    if (L.y < 0.05f) /* a key at or below the horizon: lift it so the shadow still lands */
        L = r_norm(r_v3(L.x, 0.05f, L.z));
    f->light_dir = L;
    float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f};
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < G_BONES; k++) {
            const float *m = f->bones[i][k];
            float p[3] = {m[12], m[13], m[14]};
            for (int a = 0; a < 3; a++) {
                lo[a] = fminf(lo[a], p[a] - 0.4f);
                hi[a] = fmaxf(hi[a], p[a] + 0.4f);
            }
        }
    fighter_box(f, lo, hi);
    r_vec3 c = r_v3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
    float rad = 0.5f * sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                             (hi[2] - lo[2]) * (hi[2] - lo[2]));
    r_vec3 up = fabsf(L.y) > 0.95f ? r_v3(0, 0, 1) : r_v3(0, 1, 0);
    r_vec3 from = r_v3(c.x + L.x * 20, c.y + L.y * 20, c.z + L.z * 20);
    /* depth range reaches the far ground so the silhouette projects onto it */
    f->light = r_mul(r_ortho(-rad, rad, -rad, rad, 20 - rad - 1, 20 + 40), r_look_at(from, c, up));
}

static void world_capsules(const g_state *st, int i, r_fx_capsule out[G_BONES])
{
    g_capsule c[G_BONES];
    g_fighter_capsules(st, i, c);
    float facing = (float)st->f[i].facing;
    for (int k = 0; k < G_BONES; k++) {
        float z = fx_to_float(c[k].z) * facing;
        out[k] = (r_fx_capsule){{fx_to_float(c[k].ax), fx_to_float(c[k].ay), z},
                                {fx_to_float(c[k].bx), fx_to_float(c[k].by), z},
                                fx_to_float(c[k].r)};
    }
}

/* What the stage effects see (r_fx.h): whole ticks, and how many passed. */
static void fx_setup(r_game *r, frame *f)
{
    const g_state *cur = f->cur, *prev = f->prev && f->prev->tick + 1 == cur->tick ? f->prev : cur;
    for (int i = 0; i < 2; i++) {
        world_capsules(cur, i, f->caps[i]);
        world_capsules(prev, i, f->caps_prev[i]);
        bone_matrices(NULL, prev, i, 1.0f, f->bones_prev[i]);
        bone_matrices(NULL, cur, i, 1.0f, f->bones_tick[i]);
    }
    r_mat4 proj;
    r_game_camera_parts(prev, f->out_w, f->out_h, &f->view_prev, &proj, NULL); /* the output's aspect */
    r_game_camera_parts(cur, f->out_w, f->out_h, &f->view, &f->proj, NULL);
    uint64_t t = cur->tick;
    if (!r->have_last || t < r->last_tick || t - r->last_tick > R_FX_MAX_GAP)
        f->reset = true, f->steps = 1;
    else
        f->steps = (int)(t - r->last_tick);
    r->have_last = true;
    r->last_tick = t;
}

void r_frame_setup(r_game *r, frame *f)
{
    const g_state *cur = f->cur;
    f->vp = r_game_camera(cur, f->out_w, f->out_h, &f->eye); /* the output's aspect: a scaled scene is not stretched */
    f->inv_vp = r_invert(f->vp);
    for (int i = 0; i < 2; i++) {
        bone_matrices(f->prev, cur, i, f->alpha, f->bones[i]);
        for (int k = 0; k < G_BONES; k++) {
            bool is_skin = k == G_HEAD || k == G_NECK || k == G_L_FOREARM || k == G_R_FOREARM;
            memcpy(f->colors[i][k], is_skin ? skin : r_fighter_color[i], 3 * sizeof(float));
            f->colors[i][k][3] = is_skin ? 0.25f : 1.0f;
        }
        g_capsule caps[G_BONES];
        g_fighter_capsules(cur, i, caps);
        fx wx, wy;
        g_skel_waist(caps, &wx, &wy);
        f->waist[i] = r_v3(fx_to_float(wx), fx_to_float(wy), 0);
    }
    light_setup(r, f);
    fx_setup(r, f);
    /* lightning and the KO moment drop saturation for a flash */
    float flash = cur->flash > 0 ? (float)cur->flash / 8.0f : 0.0f;
    if (cur->phase == G_PHASE_ROUND_END && cur->round_result == G_RES_KO && cur->phase_ticks < 10)
        flash = fmaxf(flash, 1.0f - (float)cur->phase_ticks / 10.0f);
    f->flash = flash > 1 ? 1 : flash;
    f->saturation = r->stage.saturation * (1 - f->flash);
    f->exposure = r->stage.exposure;
    /* is the sun on screen? */
    f->sun_on_screen = false;
    if (r->stage.sun && r->stage.flare && r->stage.sun_intensity > 0) {
        r_vec3 s = r_v3(f->eye.x + r->stage.sun_dir[0] * 150, f->eye.y + r->stage.sun_dir[1] * 150,
                        f->eye.z + r->stage.sun_dir[2] * 150);
        float x, y;
        if (r_project(f->vp, s, f->w, f->h, &x, &y) && x >= 0 && y >= 0 && x < f->w && y < f->h) {
            f->sun_on_screen = true;
            f->sun_px[0] = x, f->sun_px[1] = y;
        }
    }
}

bool r_ran(const frame *f, r_game *r, const char *name)
{
    (void)f;
    int i = r_graph_find(&r->graph, name);
    return i >= 0 && (r->graph.ran_now & ((r_graph_mask)1 << i));
}
