/* Frames onto textures, three ways, and the conversion draw (mv_up.h). */
#include "mv_up.h"

#include <stdlib.h>
#include <string.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/render/r_shader.h"
#include "../runtime/util/rs_progress.h"

#define SLOT_ALIGN 256

struct mv_up {
    mv_info info;
    int mode, nslots;
    size_t ny, nc, bytes, stride; /* plane sizes; frame bytes; slot stride */
    GLuint tex[3];
    GLuint pbo[2];
    int next;          /* PBO: the buffer the next copy goes into */
    int staged;        /* PBO: the buffer holding a staged frame, -1 none */
    GLuint ring;       /* PERSISTENT */
    uint8_t *mapped;
    GLsync fence[16];
    uint8_t *mem[16];  /* DIRECT / PBO: client slots */
    GLuint prog, vao;
    GLint u_m, u_offset, u_luma_size, u_chroma_size, u_chroma_sub, u_chroma_pos;
    mv_csp csp;
    mv_up_stats st;
};

static const char *names[MV_UP_COUNT] = {"pbo", "direct", "persistent"};

const char *mv_up_name(int mode)
{
    return mode >= 0 && mode < MV_UP_COUNT ? names[mode] : "?";
}

int mv_up_parse(const char *name)
{
    for (int i = 0; i < MV_UP_COUNT; i++)
        if (!strcmp(name, names[i]))
            return i;
    return -1;
}

static GLuint make_tex(int w, int h)
{
    GLuint t;
    gl.GenTextures(1, &t);
    gl.BindTexture(GL_TEXTURE_2D, t);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_R8, w, h, 0, GL_RED, GL_UNSIGNED_BYTE, NULL);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

mv_up *mv_up_create(const mv_info *info, int mode, int nslots, rs_err *err)
{
    if (mode < 0 || mode >= MV_UP_COUNT || nslots < 1 || nslots > 16) {
        rs_fail(err, MV_ERR_UNSUPPORTED, "upload: bad mode %d or %d slots", mode, nslots);
        return NULL;
    }
    if (mode == MV_UP_PERSISTENT && !(glcaps.buffer_storage && gl.BufferStorage)) {
        rs_fail(err, MV_ERR_UNSUPPORTED,
                "upload persistent needs glBufferStorage (GL 4.4 or ARB_buffer_storage); this context is GL %d.%d",
                glcaps.major, glcaps.minor);
        return NULL;
    }
    if (info->w > glcaps.max_texture_size || info->h > glcaps.max_texture_size) {
        rs_fail(err, MV_ERR_UNSUPPORTED, "%dx%d frames are larger than this GL's textures (%d)", info->w, info->h,
                glcaps.max_texture_size);
        return NULL;
    }
    mv_up *u = calloc(1, sizeof *u);
    if (!u) {
        rs_fail(err, MV_ERR_NOMEM, "upload: out of memory");
        return NULL;
    }
    u->info = *info;
    u->mode = mode;
    u->nslots = nslots;
    u->ny = (size_t)info->w * info->h;
    u->nc = (size_t)info->cw * info->ch;
    u->bytes = mv_frame_bytes(info);
    u->stride = (u->bytes + SLOT_ALIGN - 1) / SLOT_ALIGN * SLOT_ALIGN;
    u->staged = -1;

    u->prog = r_program(&(r_program_desc){.vs = "movie.vert", .fs = "movie.frag",
                                           .defines = info->mono ? "#define MONO 1\n" : NULL},
                        err);
    if (!u->prog)
        goto fail;
    gl.UseProgram(u->prog);
    gl.Uniform1i(gl.GetUniformLocation(u->prog, "u_y"), 0);
    gl.Uniform1i(gl.GetUniformLocation(u->prog, "u_cb"), 1);
    gl.Uniform1i(gl.GetUniformLocation(u->prog, "u_cr"), 2);
    u->u_m = gl.GetUniformLocation(u->prog, "u_m");
    u->u_offset = gl.GetUniformLocation(u->prog, "u_offset");
    u->u_luma_size = gl.GetUniformLocation(u->prog, "u_luma_size");
    u->u_chroma_size = gl.GetUniformLocation(u->prog, "u_chroma_size");
    u->u_chroma_sub = gl.GetUniformLocation(u->prog, "u_chroma_sub");
    u->u_chroma_pos = gl.GetUniformLocation(u->prog, "u_chroma_pos");
    gl.UseProgram(0);
    gl.GenVertexArrays(1, &u->vao);

    u->tex[0] = make_tex(info->w, info->h);
    if (!info->mono) {
        u->tex[1] = make_tex(info->cw, info->ch);
        u->tex[2] = make_tex(info->cw, info->ch);
    }
    gl.BindTexture(GL_TEXTURE_2D, 0);

    if (mode == MV_UP_PERSISTENT) {
        GLbitfield flags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
        gl.GenBuffers(1, &u->ring);
        gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, u->ring);
        gl.BufferStorage(GL_PIXEL_UNPACK_BUFFER, (GLsizeiptr)(u->stride * nslots), NULL, flags);
        u->mapped = gl.MapBufferRange(GL_PIXEL_UNPACK_BUFFER, 0, (GLsizeiptr)(u->stride * nslots), flags);
        gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        if (!u->mapped) {
            rs_fail(err, MV_ERR_NOMEM, "upload persistent: mapping %zu bytes failed", u->stride * nslots);
            goto fail;
        }
    } else {
        for (int i = 0; i < nslots; i++)
            if (!(u->mem[i] = malloc(u->bytes))) {
                rs_fail(err, MV_ERR_NOMEM, "upload: out of memory for %d frames of %zu bytes", nslots, u->bytes);
                goto fail;
            }
        if (mode == MV_UP_PBO) {
            gl.GenBuffers(2, u->pbo);
            for (int i = 0; i < 2; i++) {
                gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, u->pbo[i]);
                gl.BufferData(GL_PIXEL_UNPACK_BUFFER, (GLsizeiptr)u->bytes, NULL, GL_STREAM_DRAW);
            }
            gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        }
    }
    mv_up_set_csp(u, info->matrix, info->full_range);
    return u;
fail:
    mv_up_destroy(u);
    return NULL;
}

void mv_up_destroy(mv_up *u)
{
    if (!u)
        return;
    for (int i = 0; i < 16; i++) {
        if (u->fence[i])
            gl.DeleteSync(u->fence[i]);
        free(u->mem[i]);
    }
    if (u->ring) {
        gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, u->ring);
        if (u->mapped)
            gl.UnmapBuffer(GL_PIXEL_UNPACK_BUFFER);
        gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        gl.DeleteBuffers(1, &u->ring);
    }
    if (u->pbo[0])
        gl.DeleteBuffers(2, u->pbo);
    for (int i = 0; i < 3; i++)
        if (u->tex[i])
            gl.DeleteTextures(1, &u->tex[i]);
    if (u->vao)
        gl.DeleteVertexArrays(1, &u->vao);
    if (u->prog)
        gl.DeleteProgram(u->prog);
    free(u);
}

int mv_up_mode(const mv_up *u)
{
    return u->mode;
}

uint8_t *mv_up_slot(mv_up *u, int slot)
{
    if (slot < 0 || slot >= u->nslots)
        return NULL;
    return u->mode == MV_UP_PERSISTENT ? u->mapped + u->stride * (size_t)slot : u->mem[slot];
}

void mv_up_set_csp(mv_up *u, int matrix, bool full_range)
{
    mv_csp_make(matrix, full_range, &u->csp);
    u->info.matrix = matrix;
    u->info.full_range = full_range;
}

/* Defines the three textures from `src`: a client pointer, or an offset
 * into the bound unpack buffer (integer arithmetic: no offsets from NULL). */
static void define(mv_up *u, uintptr_t src)
{
    const mv_info *i = &u->info;
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    gl.BindTexture(GL_TEXTURE_2D, u->tex[0]);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, i->w, i->h, GL_RED, GL_UNSIGNED_BYTE, (const void *)src);
    if (!i->mono) {
        gl.BindTexture(GL_TEXTURE_2D, u->tex[1]);
        gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, i->cw, i->ch, GL_RED, GL_UNSIGNED_BYTE, (const void *)(src + u->ny));
        gl.BindTexture(GL_TEXTURE_2D, u->tex[2]);
        gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, i->cw, i->ch, GL_RED, GL_UNSIGNED_BYTE, (const void *)(src + u->ny + u->nc));
    }
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    u->st.uploads++;
}

/* PBO: map the next buffer (orphaning its old storage), copy, unmap. */
static bool fill(mv_up *u, int slot, int *which)
{
    int b = u->next;
    u->next ^= 1;
    double t0 = rs_now();
    gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, u->pbo[b]);
    uint8_t *dst = gl.MapBufferRange(GL_PIXEL_UNPACK_BUFFER, 0, (GLsizeiptr)u->bytes,
                                     GL_MAP_WRITE_BIT | GL_MAP_INVALIDATE_BUFFER_BIT);
    double t1 = rs_now();
    if (!dst) {
        gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        return false;
    }
    memcpy(dst, u->mem[slot], u->bytes);
    double t2 = rs_now();
    gl.UnmapBuffer(GL_PIXEL_UNPACK_BUFFER);
    gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    double t3 = rs_now();
    u->st.copy_ms += (t2 - t1) * 1e3;
    u->st.upload_ms += (t1 - t0 + t3 - t2) * 1e3;
    *which = b;
    return true;
}

static void define_from_pbo(mv_up *u, int b)
{
    double t0 = rs_now();
    gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, u->pbo[b]);
    define(u, 0);
    gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    u->st.upload_ms += (rs_now() - t0) * 1e3;
}

void mv_up_upload(mv_up *u, int slot)
{
    if (slot < 0 || slot >= u->nslots)
        return;
    double t0 = rs_now();
    switch (u->mode) {
    case MV_UP_DIRECT:
        define(u, (uintptr_t)u->mem[slot]);
        u->st.upload_ms += (rs_now() - t0) * 1e3;
        break;
    case MV_UP_PBO: {
        int b;
        u->staged = -1;
        if (fill(u, slot, &b))
            define_from_pbo(u, b);
        else
            define(u, (uintptr_t)u->mem[slot]); /* mapping failed: the slow path still shows it */
        break;
    }
    case MV_UP_PERSISTENT:
        gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, u->ring);
        define(u, (uintptr_t)(u->stride * (size_t)slot));
        gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        if (u->fence[slot])
            gl.DeleteSync(u->fence[slot]);
        u->fence[slot] = gl.FenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
        u->st.upload_ms += (rs_now() - t0) * 1e3;
        break;
    }
}

bool mv_up_stage(mv_up *u, int slot)
{
    if (u->mode != MV_UP_PBO || slot < 0 || slot >= u->nslots)
        return false;
    int b;
    if (!fill(u, slot, &b)) {
        u->staged = -1;
        return false;
    }
    u->staged = b;
    u->st.staged++;
    return true;
}

bool mv_up_has_staged(const mv_up *u)
{
    return u->staged >= 0;
}

void mv_up_commit(mv_up *u)
{
    if (u->staged < 0)
        return;
    define_from_pbo(u, u->staged);
    u->staged = -1;
}

bool mv_up_busy(mv_up *u, int slot, bool wait)
{
    if (u->mode != MV_UP_PERSISTENT || slot < 0 || slot >= u->nslots || !u->fence[slot])
        return false;
    GLenum r = gl.ClientWaitSync(u->fence[slot], GL_SYNC_FLUSH_COMMANDS_BIT, wait ? 1000000000ull : 0);
    if (r == GL_TIMEOUT_EXPIRED)
        return true;
    gl.DeleteSync(u->fence[slot]); /* signalled, or the wait failed: do not spin on it */
    u->fence[slot] = 0;
    return false;
}

void mv_up_draw(mv_up *u, int vw, int vh)
{
    const mv_info *i = &u->info;
    /* display aspect = (w * sar) / h; fit inside vw x vh */
    double dar = (double)i->w * i->sar_num / ((double)i->h * i->sar_den);
    int w = vw, h = (int)(vw / dar + 0.5);
    if (h > vh) {
        h = vh;
        w = (int)(vh * dar + 0.5);
    }
    if (w < 1)
        w = 1;
    if (h < 1)
        h = 1;
    int x = (vw - w) / 2, y = (vh - h) / 2;
    gl.Viewport(0, 0, vw, vh);
    if (w != vw || h != vh) {
        gl.ClearColor(0, 0, 0, 1);
        gl.Clear(GL_COLOR_BUFFER_BIT);
    }
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.Disable(GL_CULL_FACE);
    gl.Disable(GL_STENCIL_TEST);
    gl.Viewport(x, y, w, h);
    gl.UseProgram(u->prog);
    int sx = 1 << i->sx, sy = 1 << i->sy;
    double px = 0, py = 0;
    switch (i->chroma_loc) {
    case MV_CHROMA_CENTER: px = (sx - 1) / 2.0; py = (sy - 1) / 2.0; break;
    case MV_CHROMA_LEFT: px = 0; py = (sy - 1) / 2.0; break;
    default: break; /* TOPLEFT: 0, 0 */
    }
    gl.UniformMatrix3fv(u->u_m, 1, GL_FALSE, u->csp.m);
    gl.Uniform3fv(u->u_offset, 1, u->csp.offset);
    gl.Uniform2f(u->u_luma_size, (float)i->w, (float)i->h);
    gl.Uniform2f(u->u_chroma_size, (float)(i->cw ? i->cw : 1), (float)(i->ch ? i->ch : 1));
    gl.Uniform2f(u->u_chroma_sub, (float)sx, (float)sy);
    gl.Uniform2f(u->u_chroma_pos, (float)px, (float)py);
    for (int t = 0; t < 3; t++) {
        gl.ActiveTexture(GL_TEXTURE0 + (GLenum)t);
        gl.BindTexture(GL_TEXTURE_2D, u->tex[t] ? u->tex[t] : u->tex[0]);
    }
    gl.BindVertexArray(u->vao);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    gl.BindVertexArray(0);
    for (int t = 2; t >= 0; t--) {
        gl.ActiveTexture(GL_TEXTURE0 + (GLenum)t);
        gl.BindTexture(GL_TEXTURE_2D, 0);
    }
    gl.UseProgram(0);
    gl.Viewport(0, 0, vw, vh);
}

void mv_up_stats_get(const mv_up *u, mv_up_stats *st)
{
    *st = u->st;
}
