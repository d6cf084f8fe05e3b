#include "r_game.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../gl/rgl.h"
#include "r_font.h"
#include "r_mesh.h"
#include "r_shader.h"

const float r_fighter_color[2][3] = {{0.80f, 0.16f, 0.12f}, {0.14f, 0.32f, 0.85f}};
static const float skin[3] = {0.85f, 0.66f, 0.52f};
static const float stage_sky[G_STAGES][3] = {{0.20f, 0.14f, 0.10f}, {0.10f, 0.13f, 0.18f}, {0.28f, 0.16f, 0.20f}};
static const float stage_ring[G_STAGES][3] = {{0.55f, 0.42f, 0.28f}, {0.35f, 0.38f, 0.40f}, {0.62f, 0.58f, 0.50f}};

#define HUD_MAX_QUADS 4096

typedef struct hud_vertex {
    float x, y, u, v, r, g, b, a;
} hud_vertex;

struct r_game {
    GLuint prog, hud_prog;
    GLuint fighter_vao, fighter_vbo, fighter_ibo;
    GLsizei fighter_count;
    GLuint ring_vao, ring_vbo, ring_ibo;
    GLsizei ring_count;
    GLuint hud_vao, hud_vbo, font_tex;
    GLint u_view_proj, u_bones, u_bone_color, u_color, u_eye, u_flash, u_specular, u_screen, u_font;
    hud_vertex *hud;
    int nhud;
    int ring_stage; /* the ring mesh is sized for this stage */
};

static void upload_mesh(const r_mesh_data *m, GLuint *vao, GLuint *vbo, GLuint *ibo)
{
    gl.GenVertexArrays(1, vao);
    gl.BindVertexArray(*vao);
    gl.GenBuffers(1, vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, *vbo);
    gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(m->nv * sizeof(r_vertex)), m->v, GL_STATIC_DRAW);
    gl.GenBuffers(1, ibo);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, *ibo);
    gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(m->ni * sizeof(unsigned)), m->idx, GL_STATIC_DRAW);
    const GLsizei st = sizeof(r_vertex);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, st, (void *)offsetof(r_vertex, pos));
    gl.EnableVertexAttribArray(1);
    gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, st, (void *)offsetof(r_vertex, normal));
    gl.EnableVertexAttribArray(2);
    gl.VertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, st, (void *)offsetof(r_vertex, tangent));
    gl.EnableVertexAttribArray(3);
    gl.VertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, st, (void *)offsetof(r_vertex, uv));
    gl.EnableVertexAttribArray(4);
    gl.VertexAttribPointer(4, 1, GL_FLOAT, GL_FALSE, st, (void *)offsetof(r_vertex, bone));
    gl.BindVertexArray(0);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
}

static bool build_ring(r_game *r, int stage, rs_err *err)
{
    if (r->ring_vao) {
        gl.DeleteVertexArrays(1, &r->ring_vao);
        gl.DeleteBuffers(1, &r->ring_vbo);
        gl.DeleteBuffers(1, &r->ring_ibo);
    }
    float e = fx_to_float(g_stages[stage].ring_half);
    r_mesh_data m = {0};
    const float lo[3] = {-e, -0.6f, -e}, hi[3] = {e, 0.0f, e};
    const float glo[3] = {-40, -3.3f, -40}, ghi[3] = {40, -3.0f, 40}; /* the ground far below */
    if (!r_mesh_box(&m, lo, hi) || !r_mesh_box(&m, glo, ghi)) {
        r_mesh_free(&m);
        return rs_fail(err, 1, "out of memory for the ring mesh");
    }
    upload_mesh(&m, &r->ring_vao, &r->ring_vbo, &r->ring_ibo);
    r->ring_count = (GLsizei)m.ni;
    r->ring_stage = stage;
    r_mesh_free(&m);
    return true;
}

static GLuint build_font(void)
{
    /* one row of 6x8 cells (a blank column and row between glyphs) */
    enum { CW = 6, CH = 8 };
    int w = CW * R_FONT_GLYPHS;
    uint8_t *px = calloc((size_t)w * CH, 1);
    if (!px)
        return 0;
    for (int g = 0; g < R_FONT_GLYPHS; g++)
        for (int y = 0; y < R_FONT_H; y++)
            for (int x = 0; x < R_FONT_W; x++)
                if (r_font_glyphs[g].rows[y] & (0x10 >> x))
                    px[(size_t)y * w + g * CW + x] = 255;
    GLuint t;
    gl.GenTextures(1, &t);
    gl.BindTexture(GL_TEXTURE_2D, t);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_R8, w, CH, 0, GL_RED, GL_UNSIGNED_BYTE, px);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    free(px);
    return t;
}

r_game *r_game_create(rs_err *err)
{
    r_game *r = calloc(1, sizeof *r);
    if (!r || !(r->hud = malloc(HUD_MAX_QUADS * 6 * sizeof(hud_vertex)))) {
        free(r);
        rs_fail(err, 1, "out of memory");
        return NULL;
    }
    r->ring_stage = -1;
    r->prog = r_program(&(r_program_desc){.vs = "game.vert", .fs = "game.frag"}, err);
    if (r->prog)
        r->hud_prog = r_program(&(r_program_desc){.vs = "hud.vert", .fs = "hud.frag"}, err);
    if (!r->prog || !r->hud_prog) {
        r_game_destroy(r);
        return NULL;
    }
    r->u_view_proj = gl.GetUniformLocation(r->prog, "u_view_proj");
    r->u_bones = gl.GetUniformLocation(r->prog, "u_bones");
    r->u_bone_color = gl.GetUniformLocation(r->prog, "u_bone_color");
    r->u_color = gl.GetUniformLocation(r->prog, "u_color");
    r->u_eye = gl.GetUniformLocation(r->prog, "u_eye");
    r->u_flash = gl.GetUniformLocation(r->prog, "u_flash");
    r->u_specular = gl.GetUniformLocation(r->prog, "u_specular");
    r->u_screen = gl.GetUniformLocation(r->hud_prog, "u_screen");
    r->u_font = gl.GetUniformLocation(r->hud_prog, "u_font");

    r_mesh_data m = {0};
    if (!r_mesh_fighter(&m)) {
        r_mesh_free(&m);
        rs_fail(err, 1, "out of memory for the fighter mesh");
        r_game_destroy(r);
        return NULL;
    }
    upload_mesh(&m, &r->fighter_vao, &r->fighter_vbo, &r->fighter_ibo);
    r->fighter_count = (GLsizei)m.ni;
    r_mesh_free(&m);

    gl.GenVertexArrays(1, &r->hud_vao);
    gl.BindVertexArray(r->hud_vao);
    gl.GenBuffers(1, &r->hud_vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, r->hud_vbo);
    gl.BufferData(GL_ARRAY_BUFFER, HUD_MAX_QUADS * 6 * sizeof(hud_vertex), NULL, GL_STREAM_DRAW);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(hud_vertex), (void *)0);
    gl.EnableVertexAttribArray(1);
    gl.VertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, sizeof(hud_vertex), (void *)(2 * sizeof(float)));
    gl.EnableVertexAttribArray(2);
    gl.VertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(hud_vertex), (void *)(4 * sizeof(float)));
    gl.BindVertexArray(0);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
    r->font_tex = build_font();
    if (!r->font_tex) {
        rs_fail(err, 1, "out of memory for the font");
        r_game_destroy(r);
        return NULL;
    }
    RGL_CHECK("r_game_create");
    return r;
}

void r_game_destroy(r_game *r)
{
    if (!r)
        return;
    GLuint vaos[3] = {r->fighter_vao, r->ring_vao, r->hud_vao};
    GLuint bufs[5] = {r->fighter_vbo, r->fighter_ibo, r->ring_vbo, r->ring_ibo, r->hud_vbo};
    gl.DeleteVertexArrays(3, vaos);
    gl.DeleteBuffers(5, bufs);
    gl.DeleteTextures(1, &r->font_tex);
    gl.DeleteProgram(r->prog);
    gl.DeleteProgram(r->hud_prog);
    free(r->hud);
    free(r);
}

r_mat4 r_game_camera(const g_state *st, int w, int h, r_vec3 *eye_out)
{
    float x0 = fx_to_float(st->f[0].x), x1 = fx_to_float(st->f[1].x);
    float mid = (x0 + x1) / 2, gap = x1 > x0 ? x1 - x0 : x0 - x1;
    float dist = 4.2f + gap * 0.9f;
    r_vec3 at = r_v3(mid, 1.0f, 0), eye = r_v3(mid, 1.7f, dist);
    if (eye_out)
        *eye_out = eye;
    return r_mul(r_perspective(0.75f, (float)w / (float)h, 0.1f, 200.0f), r_look_at(eye, at, r_v3(0, 1, 0)));
}

/* Bone matrices for fighter i, between prev and cur. */
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

/* ---- HUD ---- */
static void quad(r_game *r, float x, float y, float w, float h, const float c[4], float u0, float v0, float u1, float v1)
{
    if (r->nhud + 6 > HUD_MAX_QUADS * 6)
        return;
    hud_vertex q[4] = {{x, y, u0, v0, c[0], c[1], c[2], c[3]},
                       {x + w, y, u1, v0, c[0], c[1], c[2], c[3]},
                       {x + w, y + h, u1, v1, c[0], c[1], c[2], c[3]},
                       {x, y + h, u0, v1, c[0], c[1], c[2], c[3]}};
    const int order[6] = {0, 1, 2, 0, 2, 3};
    for (int k = 0; k < 6; k++)
        r->hud[r->nhud++] = q[order[k]];
}

static void rect(r_game *r, float x, float y, float w, float h, const float c[4])
{
    quad(r, x, y, w, h, c, -1, -1, -1, -1);
}

static float text_width(const char *s, float px)
{
    return (float)strlen(s) * 6 * px - px;
}

/* Text with a drop shadow; px is the size of one font pixel. */
static void text(r_game *r, const char *s, float x, float y, float px, const float c[4])
{
    static const float shadow[4] = {0, 0, 0, 1};
    for (int pass = 0; pass < 2; pass++) {
        float cx = x + (pass ? 0 : px * 0.6f), cy = y + (pass ? 0 : px * 0.6f);
        for (const char *p = s; *p; p++, cx += 6 * px) {
            int g = -1;
            for (int k = 0; k < R_FONT_GLYPHS; k++)
                if (r_font_glyphs[k].c == *p)
                    g = k;
            if (g < 0 || *p == ' ')
                continue;
            float u0 = (float)(g * 6) / (6 * R_FONT_GLYPHS), u1 = (float)(g * 6 + 6) / (6 * R_FONT_GLYPHS);
            quad(r, cx, cy, 6 * px, 8 * px, pass ? c : shadow, u0, 0, u1, 1);
        }
    }
}

static void centered(r_game *r, const char *s, int w, float y, float px, const float c[4])
{
    text(r, s, (w - text_width(s, px)) / 2, y, px, c);
}

static void build_hud(r_game *r, const g_state *st, int w, int h)
{
    r->nhud = 0;
    float unit = h / 100.0f; /* HUD sizes scale with the window height */
    const float back[4] = {0.05f, 0.05f, 0.07f, 1}, white[4] = {1, 1, 1, 1}, gold[4] = {1, 0.8f, 0.2f, 1};
    float bar_w = w * 0.36f, bar_h = 3.2f * unit, top = 3 * unit;
    for (int i = 0; i < 2; i++) {
        float x = i == 0 ? w * 0.05f : w * 0.95f - bar_w;
        float frac = (float)st->f[i].health / G_MAX_HEALTH;
        float fill[4] = {1.0f, 0.25f + 0.6f * frac, 0.1f, 1};
        rect(r, x - 0.4f * unit, top - 0.4f * unit, bar_w + 0.8f * unit, bar_h + 0.8f * unit, back);
        float fw = bar_w * frac;
        rect(r, i == 0 ? x + bar_w - fw : x, top, fw, bar_h, fill); /* bars drain towards the centre */
        const float *col = r_fighter_color[i];
        const float name_c[4] = {col[0] + 0.2f, col[1] + 0.2f, col[2] + 0.2f, 1};
        text(r, i == 0 ? "P1" : "P2", i == 0 ? x : x + bar_w - text_width("P2", 0.5f * unit), top + bar_h + 1.2f * unit,
             0.5f * unit, name_c);
        for (int k = 0; k < G_ROUNDS_TO_WIN; k++) { /* round wins */
            float px = i == 0 ? x + bar_w - (k + 1) * 3 * unit : x + k * 3 * unit;
            rect(r, px, top + bar_h + 1.2f * unit, 2.2f * unit, 2.2f * unit, k < st->f[i].rounds_won ? gold : back);
        }
    }
    char buf[32];
    int secs = (st->round_timer + G_HZ - 1) / G_HZ;
    snprintf(buf, sizeof buf, "%02d", secs > 99 ? 99 : secs);
    centered(r, buf, w, 1.5f * unit, 0.9f * unit, white);

    const char *msg = NULL;
    switch (st->phase) {
    case G_PHASE_INTRO:
        snprintf(buf, sizeof buf, st->phase_ticks < 60 ? "ROUND %d" : "FIGHT!", st->round);
        msg = buf;
        break;
    case G_PHASE_ROUND_END:
        msg = st->round_result == G_RES_KO         ? "K.O."
              : st->round_result == G_RES_RING_OUT ? "RING OUT"
              : st->round_result == G_RES_TIME     ? (st->round_winner ? "TIME" : "DRAW")
                                                   : "DRAW";
        break;
    case G_PHASE_MATCH_END:
        if (st->match_winner > 0)
            snprintf(buf, sizeof buf, "P%d WINS", st->match_winner);
        else
            snprintf(buf, sizeof buf, "DRAW GAME");
        msg = buf;
        break;
    default: break;
    }
    if (msg)
        centered(r, msg, w, 38 * unit, 1.6f * unit, gold);
}

void r_game_draw(r_game *r, const g_state *prev, const g_state *cur, float alpha, int w, int h)
{
    if (r->ring_stage != cur->stage && !build_ring(r, cur->stage, NULL))
        return;
    const float *sky = stage_sky[cur->stage];
    float flash = cur->flash > 0 ? cur->flash / 8.0f : 0.0f;
    gl.Viewport(0, 0, w, h);
    gl.ClearColor(sky[0] + flash * 0.5f, sky[1] + flash * 0.5f, sky[2] + flash * 0.6f, 1);
    gl.ClearDepth(1.0);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_BACK);
    gl.Disable(GL_BLEND);

    r_vec3 eye;
    r_mat4 vp = r_game_camera(cur, w, h, &eye);
    gl.UseProgram(r->prog);
    gl.UniformMatrix4fv(r->u_view_proj, 1, GL_FALSE, vp.m);
    gl.Uniform3f(r->u_eye, eye.x, eye.y, eye.z);
    gl.Uniform1f(r->u_flash, flash);

    /* ring and ground */
    gl.Uniform1f(r->u_specular, 0.05f);
    gl.Uniform3fv(r->u_color, 1, stage_ring[cur->stage]);
    gl.BindVertexArray(r->ring_vao);
    gl.DrawElements(GL_TRIANGLES, r->ring_count, GL_UNSIGNED_INT, NULL);

    /* fighters */
    gl.Uniform1f(r->u_specular, 0.35f);
    gl.BindVertexArray(r->fighter_vao);
    for (int i = 0; i < 2; i++) {
        float bones[16][16], colors[16][3];
        bone_matrices(prev, cur, i, alpha, bones);
        for (int k = 0; k < G_BONES; k++) {
            bool is_skin = k == G_HEAD || k == G_NECK || k == G_L_FOREARM || k == G_R_FOREARM;
            memcpy(colors[k], is_skin ? skin : r_fighter_color[i], sizeof colors[k]);
        }
        gl.UniformMatrix4fv(r->u_bones, G_BONES, GL_FALSE, &bones[0][0]);
        gl.Uniform3fv(r->u_bone_color, G_BONES, &colors[0][0]);
        gl.DrawElements(GL_TRIANGLES, r->fighter_count, GL_UNSIGNED_INT, NULL);
    }

    /* HUD */
    build_hud(r, cur, w, h);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    gl.UseProgram(r->hud_prog);
    gl.Uniform2f(r->u_screen, (float)w, (float)h);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, r->font_tex);
    gl.Uniform1i(r->u_font, 0);
    gl.BindVertexArray(r->hud_vao);
    gl.BindBuffer(GL_ARRAY_BUFFER, r->hud_vbo);
    gl.BufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(r->nhud * sizeof(hud_vertex)), r->hud);
    gl.DrawArrays(GL_TRIANGLES, 0, r->nhud);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
    gl.BindVertexArray(0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.UseProgram(0);
    RGL_CHECK("r_game_draw");
}
