#include "r_target.h"

#include <string.h>

#include "../util/rs_img.h"
#include "r_err.h"

bool r_target_create(r_target *t, int w, int h, rs_err *err)
{
    memset(t, 0, sizeof *t);
    t->w = w;
    t->h = h;
    gl.GenTextures(1, &t->tex);
    gl.BindTexture(GL_TEXTURE_2D, t->tex);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.GenRenderbuffers(1, &t->depth);
    gl.BindRenderbuffer(GL_RENDERBUFFER, t->depth);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, w, h);
    gl.GenFramebuffers(1, &t->fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t->tex, 0);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, t->depth);
    GLenum st = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.BindRenderbuffer(GL_RENDERBUFFER, 0);
    if (st != GL_FRAMEBUFFER_COMPLETE) {
        r_target_destroy(t);
        return rs_fail(err, R_ERR_TARGET, "%dx%d render target incomplete (%s)", w, h, rgl_enum_name(st));
    }
    return true;
}

void r_target_destroy(r_target *t)
{
    if (t->fbo)
        gl.DeleteFramebuffers(1, &t->fbo);
    if (t->tex)
        gl.DeleteTextures(1, &t->tex);
    if (t->depth)
        gl.DeleteRenderbuffers(1, &t->depth);
    memset(t, 0, sizeof *t);
}

void r_read_pixels(GLuint fbo, int w, int h, int channels, uint8_t *px)
{
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    if (!fbo)
        gl.ReadBuffer(GL_BACK);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, w, h, channels == 3 ? GL_RGB : GL_RGBA, GL_UNSIGNED_BYTE, px);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    rs_flip_rows(px, w, h, channels);
}
