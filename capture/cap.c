/* DESIGN: who owns what
 *
 * The game thread owns the GL context and everything GL here (FBOs,
 * textures, the PBO ring and its fences) and calls cap_frame once per
 * rendered frame.  Frame bytes cross to the writer thread only through
 * cap_writer slots (cap_writer.c): the game thread copies a mapped PBO (or
 * its CPU result) into a slot it acquired, then submits it; from then on
 * the writer owns that slot until it returns it to the free list.
 *
 * Where the game thread may block, on purpose:
 *   - map_oldest(): only after a non-blocking fence check failed, waiting
 *     for the GPU to finish the readback that is now ring-size frames old;
 *   - cap_writer_acquire(): when the queue holds `queue` frames (the cap);
 *   - sequential path: glReadPixels into client memory waits for the GPU. */
#include "cap.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/render/r_shader.h"
#include "../runtime/util/rs_progress.h"
#include "cap_scale.h"
#include "cap_writer.h"

typedef struct target {
    GLuint fbo, tex[2];
    int w, h;
} target;

struct cap {
    cap_desc d;
    cap_sink *sink;
    cap_writer *writer;
    size_t frame_bytes;
    cap_pixfmt fmt;    /* what the sink takes: I420 planes or RGBA */
    bool gpu;          /* GPU downscale + convert */
    bool same_size;    /* I420 at the render size: the conversion reads the frame itself (no scaler pass) */
    bool failed;
    /* GPU stage */
    cap_scaler *scaler;
    GLuint vao, prog_luma, prog_chroma;
    GLint u_rgb_luma, u_rgb_chroma, u_size_chroma, u_flip_luma, u_flip_chroma;
    target rgb;
    target planes;     /* I420 as one R8 image of w x 3h/2: Y rows, then Cb and Cr packed (gpu_setup) */
    GLuint read_fbo;   /* to read the source texture (CPU path) */
    /* PBO ring (async) */
    GLuint pbo[CAP_MAX_PBO];
    GLsync fence[CAP_MAX_PBO];
    uint64_t issued, mapped; /* frames read into the ring / taken out of it */
    /* CPU path buffers */
    uint8_t *full, *small, *direct;
    cap_stats st;
    rs_err err; /* GL-side failure (the writer keeps its own) */
};

bool cap_check_sizes(int sw, int sh, int w, int h, rs_err *err)
{
    return cap_check_sizes_for(CAP_I420, sw, sh, w, h, err);
}

bool cap_check_sizes_for(cap_pixfmt fmt, int sw, int sh, int w, int h, rs_err *err)
{
    if (w <= 0 || h <= 0 || sw <= 0 || sh <= 0)
        return rs_fail(err, CAP_ERR_SIZE, "sizes must be positive (render %dx%d, output %dx%d)", sw, sh, w, h);
    if (fmt == CAP_I420 && ((w | h) & 1))
        return rs_fail(err, CAP_ERR_SIZE, "output size %dx%d: width and height must be even for 4:2:0 video", w, h);
    if (w > sw || h > sh)
        return rs_fail(err, CAP_ERR_SIZE, "output size %dx%d is larger than the render size %dx%d (downscale only)", w, h, sw,
                       sh);
    if (sw > w * CAP_MAX_SCALE || sh > h * CAP_MAX_SCALE)
        return rs_fail(err, CAP_ERR_SIZE, "render size %dx%d is more than %d times the output size %dx%d", sw, sh, CAP_MAX_SCALE,
                       w, h);
    return true;
}

static bool make_target(target *t, int w, int h, int n, GLenum ifmt, GLenum fmt, rs_err *err)
{
    t->w = w;
    t->h = h;
    gl.GenFramebuffers(1, &t->fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    gl.GenTextures(n, t->tex);
    GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    for (int i = 0; i < n; i++) {
        gl.BindTexture(GL_TEXTURE_2D, t->tex[i]);
        gl.TexImage2D(GL_TEXTURE_2D, 0, ifmt, w, h, 0, fmt, GL_UNSIGNED_BYTE, NULL);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, bufs[i], GL_TEXTURE_2D, t->tex[i], 0);
    }
    gl.DrawBuffers(n, bufs);
    GLenum st = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    if (st != GL_FRAMEBUFFER_COMPLETE)
        return rs_fail(err, CAP_ERR_GL, "capture: %dx%d target incomplete (%s)", w, h, rgl_enum_name(st));
    return true;
}

static void free_target(target *t)
{
    if (t->fbo) {
        gl.DeleteFramebuffers(1, &t->fbo);
        gl.DeleteTextures(2, t->tex);
    }
}

static bool gpu_setup(cap *c, rs_err *err)
{
    /* at 1:1 every filter is the identity: the Y and CbCr draws read the
     * rendered frame, flipped, instead of a copy of it (the same bytes, one
     * full-frame pass less; the default job writes at the render size) */
    c->same_size = c->fmt == CAP_I420 && c->d.src_w == c->d.w && c->d.src_h == c->d.h;
    if (!c->same_size && !(c->scaler = cap_scaler_create(c->d.filter, c->d.src_w, c->d.src_h, c->d.w, c->d.h, err)))
        return false;
    c->prog_luma = r_program(&(r_program_desc){.vs = "cap_fullscreen.vert", .fs = "cap_luma.frag"}, err);
    if (c->prog_luma)
        c->prog_chroma = r_program(&(r_program_desc){.vs = "cap_fullscreen.vert", .fs = "cap_chroma.frag"}, err);
    if (!c->prog_chroma)
        return false;
    c->u_rgb_luma = gl.GetUniformLocation(c->prog_luma, "u_rgb");
    c->u_rgb_chroma = gl.GetUniformLocation(c->prog_chroma, "u_rgb");
    c->u_size_chroma = gl.GetUniformLocation(c->prog_chroma, "u_size");
    c->u_flip_luma = gl.GetUniformLocation(c->prog_luma, "u_flip");
    c->u_flip_chroma = gl.GetUniformLocation(c->prog_chroma, "u_flip");
    gl.GenVertexArrays(1, &c->vao);
    int w = c->d.w, h = c->d.h;
    if (c->fmt == CAP_RGBA)
        return make_target(&c->rgb, w, h, 1, GL_RGBA8, GL_RGBA, err);
    /* The three planes in one R8 image whose bytes, read bottom row first,
     * are the I420 frame itself: rows 0..h-1 the Y plane; rows h..3h/2-1,
     * w bytes each, the Cb plane and then the Cr plane, each (w/2)(h/2)
     * bytes, packed across row ends (cap_chroma.frag).  One glReadPixels at
     * offset 0 of one single-attachment target: reading three planes from
     * two targets into offsets of one PBO took NVIDIA's driver 17-20 ms of
     * CPU a frame at 640x360 (a slow pack path in the two chroma reads),
     * where this single read costs what the luma read alone did. */
    if (h + h / 2 > glcaps.max_texture_size)
        return rs_fail(err, CAP_ERR_SIZE, "capture: output %dx%d needs a %dx%d plane image, over this GL's %d limit", w, h, w,
                       h + h / 2, glcaps.max_texture_size);
    return (c->same_size || make_target(&c->rgb, w, h, 1, GL_RGBA8, GL_RGBA, err)) &&
           make_target(&c->planes, w, h + h / 2, 1, GL_R8, GL_RED, err);
}

/* Downscale src into rgb, then Y, Cb, Cr planes; nothing is read back here. */
static void gpu_convert(cap *c, GLuint src)
{
    if (!c->same_size)
        cap_scaler_run(c->scaler, src, c->rgb.fbo);
    if (c->fmt == CAP_RGBA)
        return; /* image sequences take the downscaled RGBA as it is */
    /* u_flip: the source's height when it is the rendered frame (bottom-up), else 0 */
    int flip = c->same_size ? c->d.src_h : 0;
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.Disable(GL_CULL_FACE);
    gl.BindVertexArray(c->vao);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, c->same_size ? src : c->rgb.tex[0]);
    gl.BindFramebuffer(GL_FRAMEBUFFER, c->planes.fbo);
    gl.Viewport(0, 0, c->d.w, c->d.h);
    gl.UseProgram(c->prog_luma);
    gl.Uniform1i(c->u_rgb_luma, 0);
    gl.Uniform1i(c->u_flip_luma, flip);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);

    gl.Viewport(0, c->d.h, c->d.w, c->d.h / 2);
    gl.UseProgram(c->prog_chroma);
    gl.Uniform1i(c->u_rgb_chroma, 0);
    gl.Uniform2i(c->u_size_chroma, c->d.w, c->d.h);
    gl.Uniform1i(c->u_flip_chroma, flip);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);

    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.BindVertexArray(0);
    gl.UseProgram(0);
}

/* The frame into `dst`: a client pointer, or an offset into the bound
 * GL_PIXEL_PACK_BUFFER.  One read either way: the RGBA image, or the plane
 * image, whose rows are the I420 planes back to back (gpu_setup). */
static void read_planes(cap *c, uint8_t *dst)
{
    const target *t = c->fmt == CAP_RGBA ? &c->rgb : &c->planes;
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo);
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl.ReadPixels(0, 0, t->w, t->h, c->fmt == CAP_RGBA ? GL_RGBA : GL_RED, GL_UNSIGNED_BYTE, dst);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
}

/* Takes the oldest frame out of the ring into a writer slot. */
static bool map_oldest(cap *c)
{
    int i = (int)(c->mapped % (uint64_t)c->d.pbo);
    double t0 = rs_now();
    GLenum r = gl.ClientWaitSync(c->fence[i], 0, 0); /* non-blocking check */
    if (r == GL_TIMEOUT_EXPIRED) {
        /* the GPU has not finished this readback yet: block here, on purpose */
        c->st.fence_waits++;
        do
            r = gl.ClientWaitSync(c->fence[i], GL_SYNC_FLUSH_COMMANDS_BIT, 100000000); /* 100 ms */
        while (r == GL_TIMEOUT_EXPIRED);
    }
    c->st.ms_fence_wait += (rs_now() - t0) * 1e3;
    gl.DeleteSync(c->fence[i]);
    c->fence[i] = 0;
    c->mapped++;
    if (r == GL_WAIT_FAILED) {
        rs_fail(&c->err, CAP_ERR_GL, "capture: waiting for a readback fence failed (GL error)");
        return false;
    }
    uint8_t *slot = cap_writer_acquire(c->writer); /* may wait on a full queue: the writer counts it */
    if (!slot)
        return false;
    double t1 = rs_now();
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, c->pbo[i]);
    const void *p = gl.MapBufferRange(GL_PIXEL_PACK_BUFFER, 0, (GLsizeiptr)c->frame_bytes, GL_MAP_READ_BIT);
    if (p) {
        memcpy(slot, p, c->frame_bytes);
        gl.UnmapBuffer(GL_PIXEL_PACK_BUFFER);
    }
    gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    c->st.ms_map_copy += (rs_now() - t1) * 1e3;
    if (!p) { /* never hand a stale slot to the writer */
        cap_writer_cancel(c->writer, slot);
        rs_fail(&c->err, CAP_ERR_GL, "capture: mapping a pixel buffer of %zu bytes failed (GL error)", c->frame_bytes);
        return false;
    }
    return cap_writer_submit(c->writer, slot);
}

cap *cap_open(const cap_desc *desc, cap_sink *sink, rs_err *err)
{
    cap *c = calloc(1, sizeof *c);
    if (!c) {
        rs_fail(err, CAP_ERR_NOMEM, "out of memory");
        return NULL;
    }
    c->d = *desc;
    if (!c->d.pbo)
        c->d.pbo = CAP_DEFAULT_PBO;
    if (!c->d.queue)
        c->d.queue = CAP_DEFAULT_QUEUE;
    if (!c->d.downscale)
        c->d.downscale = c->d.mode == CAP_SEQUENTIAL ? CAP_DS_CPU : CAP_DS_GPU;
    if (c->d.mode == CAP_SEQUENTIAL)
        c->d.no_writer = true; /* everything on the game thread */
    c->gpu = c->d.downscale == CAP_DS_GPU;
    c->sink = sink;
    c->fmt = sink->fmt;
    c->frame_bytes = cap_frame_bytes(c->fmt, c->d.w, c->d.h);
    if (!cap_check_sizes_for(c->fmt, c->d.src_w, c->d.src_h, c->d.w, c->d.h, err))
        goto fail;
    if (c->d.pbo < 1 || c->d.pbo > CAP_MAX_PBO) {
        rs_fail(err, CAP_ERR_ARG, "PBO ring of %d: expected 1..%d", c->d.pbo, CAP_MAX_PBO);
        goto fail;
    }
    if (c->gpu && !gpu_setup(c, err))
        goto fail;
    if (!c->gpu || c->d.mode == CAP_SEQUENTIAL) {
        c->full = malloc((size_t)c->d.src_w * c->d.src_h * 4);
        c->small = malloc((size_t)c->d.w * c->d.h * 4);
        c->direct = malloc(c->frame_bytes);
        if (!c->full || !c->small || !c->direct) {
            rs_fail(err, CAP_ERR_NOMEM, "out of memory for capture buffers");
            goto fail;
        }
        gl.GenFramebuffers(1, &c->read_fbo);
    }
    if (c->d.mode == CAP_ASYNC) {
        gl.GenBuffers(c->d.pbo, c->pbo);
        for (int i = 0; i < c->d.pbo; i++) {
            gl.BindBuffer(GL_PIXEL_PACK_BUFFER, c->pbo[i]);
            gl.BufferData(GL_PIXEL_PACK_BUFFER, (GLsizeiptr)c->frame_bytes, NULL, GL_STREAM_READ);
        }
        gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    }
    if (!sink->ops->open(sink, err)) {
        sink->ops->close(sink, false, NULL); /* a half-open sink cleans up too */
        goto fail;
    }
    c->writer = cap_writer_start(sink, c->frame_bytes, c->d.no_writer ? 0 : c->d.queue, c->d.hashes, err);
    if (!c->writer) {
        sink->ops->close(sink, false, NULL);
        goto fail;
    }
    return c;
fail:
    c->sink = NULL;
    cap_close(c, false, NULL, NULL);
    return NULL;
}

/* The original path: full frame to client memory, then the CPU works. */
static bool cpu_frame(cap *c, GLuint src)
{
    double t0 = rs_now();
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, c->read_fbo);
    gl.FramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, src, 0);
    gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, c->d.src_w, c->d.src_h, GL_RGBA, GL_UNSIGNED_BYTE, c->full); /* waits for the GPU */
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    double t1 = rs_now();
    c->st.ms_readback += (t1 - t0) * 1e3;
    cap_cpu_downscale(c->full, c->d.src_w, c->d.src_h, c->small, c->d.w, c->d.h);
    c->st.ms_downscale += (rs_now() - t1) * 1e3;
    uint8_t *slot = cap_writer_acquire(c->writer); /* inline queue: never waits */
    if (!slot)
        return false;
    t1 = rs_now();
    if (c->fmt == CAP_RGBA)
        memcpy(slot, c->small, c->frame_bytes);
    else
        cap_cpu_rgba_to_i420(c->small, c->d.w, c->d.h, slot);
    c->st.ms_downscale += (rs_now() - t1) * 1e3;
    return cap_writer_submit(c->writer, slot);
}

bool cap_frame(cap *c, GLuint src, rs_err *err)
{
    (void)err;
    if (c->failed)
        return false;
    bool ok;
    if (!c->gpu) {
        ok = cpu_frame(c, src);
    } else {
        double t0 = rs_now();
        gpu_convert(c, src);
        double t1 = rs_now();
        c->st.ms_downscale += (t1 - t0) * 1e3;
        if (c->d.mode == CAP_SEQUENTIAL) {
            uint8_t *slot = cap_writer_acquire(c->writer);
            ok = slot != NULL;
            if (ok) {
                read_planes(c, slot); /* client memory: waits for the GPU */
                c->st.ms_readback += (rs_now() - t1) * 1e3;
                ok = cap_writer_submit(c->writer, slot);
            }
        } else {
            /* read this frame into the next PBO of the ring (its previous
             * frame was taken out last time), then take out the oldest once
             * the ring is full: with 2 PBOs, frame N-1 while frame N is in
             * flight, as in the seed; with 1, this frame right away */
            double t2 = rs_now();
            int i = (int)(c->issued % (uint64_t)c->d.pbo);
            gl.BindBuffer(GL_PIXEL_PACK_BUFFER, c->pbo[i]);
            read_planes(c, NULL); /* offsets into the PBO: returns at once */
            gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
            c->fence[i] = gl.FenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
            gl.Flush(); /* start the transfer now, not at the next sync */
            c->issued++;
            c->st.ms_readback += (rs_now() - t2) * 1e3;
            ok = c->issued - c->mapped < (uint64_t)c->d.pbo || map_oldest(c);
        }
    }
    if (ok)
        c->st.frames++;
    else
        c->failed = true;
    return ok;
}

bool cap_close(cap *c, bool ok, cap_stats *stats, rs_err *err)
{
    /* drain the ring in order */
    while (ok && !c->failed && c->mapped < c->issued)
        if (!map_oldest(c))
            c->failed = true;
    for (int i = 0; i < CAP_MAX_PBO; i++)
        if (c->fence[i])
            gl.DeleteSync(c->fence[i]);
    rs_err werr = {0};
    bool wok = true;
    cap_writer_stats ws = {0};
    if (c->writer)
        wok = cap_writer_finish(c->writer, &ws, &werr);
    /* the hash list belongs to this output: it must be whole before the output is committed */
    const char *hname = c->d.hashes_name ? c->d.hashes_name : "the frame hash list";
    errno = 0;
    if (wok && c->d.hashes && (fflush(c->d.hashes) != 0 || ferror(c->d.hashes))) {
        wok = false;
        rs_fail(&werr, CAP_ERR_WRITE, "%s: write failed: %s", hname, errno ? strerror(errno) : "I/O error");
    } else if (!wok && c->d.hashes_name && !strncmp(werr.msg, "writing the frame hash list", 27))
        rs_err_prefix(&werr, "%s", hname);
    bool good = ok && !c->failed && wok;
    rs_err cerr = {0};
    bool cok = true;
    if (c->sink)
        cok = c->sink->ops->close(c->sink, good, &cerr);
    if (err && !err->msg[0]) {
        if (!wok)
            *err = werr;
        else if (c->failed && c->err.msg[0])
            *err = c->err;
        else if (good && !cok)
            *err = cerr;
        else if (!good || !cok)
            rs_fail(err, CAP_ERR_FAILED, "capture failed");
    }
    c->st.high_water = ws.high_water;
    c->st.ms_write = ws.write_ms;
    c->st.ms_queue_wait += ws.wait_ms;
    c->st.full_waits = ws.full_waits;
    if (stats)
        *stats = c->st;
    if (c->d.mode == CAP_ASYNC && c->pbo[0])
        gl.DeleteBuffers(c->d.pbo, c->pbo);
    free_target(&c->rgb);
    free_target(&c->planes);
    if (c->read_fbo)
        gl.DeleteFramebuffers(1, &c->read_fbo);
    if (c->vao)
        gl.DeleteVertexArrays(1, &c->vao);
    cap_scaler_destroy(c->scaler);
    gl.DeleteProgram(c->prog_luma);
    gl.DeleteProgram(c->prog_chroma);
    free(c->full);
    free(c->small);
    free(c->direct);
    free(c);
    return good && cok;
}
