#include "r_smoke.h"

#include <stdlib.h>
#include <string.h>

#include "../gl/rgl.h"
#include "../util/rs_img.h"
#include "r_shader.h"
#include "r_err.h"

/* Geometry in quarter pixels (GL window coordinates, origin bottom-left).
 * Rectangle edges sit on whole pixels (centres are at .5); triangle
 * vertices sit at +1/4 with (x - y) mod 4 distinct per vertex, so every
 * edge function is non-zero at every pixel centre. */
enum { MODE_FLAT, MODE_GRID };

typedef struct shape {
    int mode;
    uint8_t rgba[4];
    int n;            /* 4: rectangle (x0,y0,x1,y1 in v[0..1]); 3: triangle */
    long v[3][2];     /* quarter pixels */
} shape;

static const uint8_t clear_rgba[4] = {16, 20, 40, 255};

static int scene(int w, int h, shape *out)
{
    int n = 0;
    /* ring floor: the grid pattern over the bottom third */
    out[n++] = (shape){MODE_GRID, {0, 0, 96, 255}, 4, {{0, 0}, {4L * w, 4L * (h / 3)}}};
    /* two fighters */
    long fy0 = 4L * (h / 3 - h / 20), fy1 = 4L * (h * 3 / 4);
    out[n++] = (shape){MODE_FLAT, {220, 40, 40, 255}, 4, {{4L * (w / 5), fy0}, {4L * (w * 7 / 20), fy1}}};
    out[n++] = (shape){MODE_FLAT, {40, 90, 230, 255}, 4, {{4L * (w * 13 / 20), fy0}, {4L * (w * 4 / 5), fy1}}};
    /* the sun: a triangle with no pixel centre on its edges */
    shape t = {MODE_FLAT, {250, 210, 60, 255}, 3, {{0}}};
    const int fx[3][2] = {{42, 55}, {58, 55}, {50, 90}}; /* percent of w, h */
    for (int i = 0; i < 3; i++) {
        long x = (long)w * fx[i][0] / 100, y = (long)h * fx[i][1] / 100;
        while ((((x - y) % 4) + 4) % 4 != i) /* residues 0, 1, 2 */
            x++;
        t.v[i][0] = 4 * x + 1;
        t.v[i][1] = 4 * y + 1;
    }
    out[n++] = t;
    return n;
}

static long edge(const long a[2], const long b[2], long px, long py)
{
    return (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0]);
}

static bool covers(const shape *s, long px, long py) /* quarter-pixel centre */
{
    if (s->n == 4)
        return px > s->v[0][0] && px < s->v[1][0] && py > s->v[0][1] && py < s->v[1][1];
    long e0 = edge(s->v[0], s->v[1], px, py), e1 = edge(s->v[1], s->v[2], px, py), e2 = edge(s->v[2], s->v[0], px, py);
    return (e0 > 0 && e1 > 0 && e2 > 0) || (e0 < 0 && e1 < 0 && e2 < 0);
}

void r_smoke_reference(int w, int h, uint8_t *rgba)
{
    shape sh[8];
    int ns = scene(w, h, sh);
    for (int row = 0; row < h; row++) {
        int y = h - 1 - row;
        for (int x = 0; x < w; x++) {
            uint8_t *o = rgba + ((size_t)row * w + x) * 4;
            memcpy(o, clear_rgba, 4);
            for (int i = 0; i < ns; i++) {
                if (!covers(&sh[i], 4L * x + 2, 4L * y + 2))
                    continue;
                memcpy(o, sh[i].rgba, 4);
                if (sh[i].mode == MODE_GRID) {
                    o[0] = (uint8_t)(x % 256);
                    o[1] = (uint8_t)(y % 256);
                }
            }
        }
    }
}

size_t r_smoke_compare(const uint8_t *got, const uint8_t *want, int w, int h, size_t *first)
{
    size_t bad = 0;
    *first = 0;
    for (size_t i = 0; i < (size_t)w * h; i++)
        if (memcmp(got + 4 * i, want + 4 * i, 4) && !bad++)
            *first = i;
    return bad;
}

struct r_smoke {
    int w, h, nshapes;
    shape shapes[8];
    GLuint prog, vao, vbo, fbo, tex;
    GLint u_size, u_color, u_mode;
};

r_smoke *r_smoke_create(int w, int h, rs_err *err)
{
    if (w < R_SMOKE_MIN_SIZE || h < R_SMOKE_MIN_SIZE || w > glcaps.max_texture_size || h > glcaps.max_texture_size) {
        rs_fail(err, R_ERR_SIZE, "smoke scene size %dx%d out of range (expected %d..%d per side)", w, h, R_SMOKE_MIN_SIZE,
                glcaps.max_texture_size);
        return NULL;
    }
    r_smoke *s = calloc(1, sizeof *s);
    if (!s) {
        rs_fail(err, R_ERR_NOMEM, "out of memory");
        return NULL;
    }
    s->w = w;
    s->h = h;
    s->nshapes = scene(w, h, s->shapes);
    s->prog = r_program(&(r_program_desc){.vs = "smoke.vert", .fs = "smoke.frag"}, err);
    if (!s->prog) {
        free(s);
        return NULL;
    }
    s->u_size = gl.GetUniformLocation(s->prog, "u_size");
    s->u_color = gl.GetUniformLocation(s->prog, "u_color");
    s->u_mode = gl.GetUniformLocation(s->prog, "u_mode");

    /* two triangles per rectangle, one per triangle: at most 6 vertices each */
    float verts[8 * 6 * 2];
    int nv = 0;
    for (int i = 0; i < s->nshapes; i++) {
        const shape *sh = &s->shapes[i];
        if (sh->n == 4) {
            float x0 = sh->v[0][0] / 4.0f, y0 = sh->v[0][1] / 4.0f, x1 = sh->v[1][0] / 4.0f, y1 = sh->v[1][1] / 4.0f;
            const float q[12] = {x0, y0, x1, y0, x1, y1, x0, y0, x1, y1, x0, y1};
            memcpy(verts + nv * 2, q, sizeof q);
            nv += 6;
        } else {
            for (int k = 0; k < 3; k++) {
                verts[nv * 2] = sh->v[k][0] / 4.0f;
                verts[nv * 2 + 1] = sh->v[k][1] / 4.0f;
                nv++;
            }
        }
    }
    gl.GenVertexArrays(1, &s->vao);
    gl.BindVertexArray(s->vao);
    gl.GenBuffers(1, &s->vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, s->vbo);
    gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 2 * sizeof(float)), verts, GL_STATIC_DRAW);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, NULL);
    gl.BindVertexArray(0);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);

    gl.GenTextures(1, &s->tex);
    gl.BindTexture(GL_TEXTURE_2D, s->tex);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.GenFramebuffers(1, &s->fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, s->fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, s->tex, 0);
    GLenum st = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    if (st != GL_FRAMEBUFFER_COMPLETE) {
        rs_fail(err, R_ERR_TARGET, "smoke scene: RGBA8 %dx%d framebuffer incomplete (%s)", w, h, rgl_enum_name(st));
        r_smoke_destroy(s);
        return NULL;
    }
    RGL_CHECK("r_smoke_create");
    return s;
}

void r_smoke_draw(r_smoke *s)
{
    gl.BindFramebuffer(GL_FRAMEBUFFER, s->fbo);
    gl.Viewport(0, 0, s->w, s->h);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.ClearColor(clear_rgba[0] / 255.0f, clear_rgba[1] / 255.0f, clear_rgba[2] / 255.0f, clear_rgba[3] / 255.0f);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    gl.UseProgram(s->prog);
    gl.Uniform2f(s->u_size, (float)s->w, (float)s->h);
    gl.BindVertexArray(s->vao);
    int first = 0;
    for (int i = 0; i < s->nshapes; i++) {
        const shape *sh = &s->shapes[i];
        int count = sh->n == 4 ? 6 : 3;
        gl.Uniform4f(s->u_color, sh->rgba[0] / 255.0f, sh->rgba[1] / 255.0f, sh->rgba[2] / 255.0f,
                     sh->rgba[3] / 255.0f);
        gl.Uniform1i(s->u_mode, sh->mode);
        gl.DrawArrays(GL_TRIANGLES, first, count);
        first += count;
    }
    gl.BindVertexArray(0);
    gl.UseProgram(0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    RGL_CHECK("r_smoke_draw");
}

void r_smoke_read(r_smoke *s, uint8_t *rgba)
{
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, s->fbo);
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, s->w, s->h, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    rs_flip_rows(rgba, s->w, s->h, 4);
    RGL_CHECK("r_smoke_read");
}

void r_smoke_destroy(r_smoke *s)
{
    if (!s)
        return;
    gl.DeleteFramebuffers(1, &s->fbo);
    gl.DeleteTextures(1, &s->tex);
    gl.DeleteBuffers(1, &s->vbo);
    gl.DeleteVertexArrays(1, &s->vao);
    gl.DeleteProgram(s->prog);
    free(s);
}
