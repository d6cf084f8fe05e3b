#include "rgl.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

rgl_api gl;
rgl_caps glcaps;

static unsigned error_count;
static bool callback_on; /* errors are counted by debug_cb, not by rgl_check */

static const struct {
    bool required;
    const char *name;
    size_t offset;
} funcs[] = {
#define GLF(req, U, N) {req, "gl" #N, offsetof(rgl_api, N)},
#include "rgl_funcs.h"
#undef GLF
};

const char *rgl_enum_name(GLenum e)
{
    switch (e) {
    case GL_NO_ERROR: return "GL_NO_ERROR";
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    case GL_FRAMEBUFFER_COMPLETE: return "GL_FRAMEBUFFER_COMPLETE";
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT";
    case GL_FRAMEBUFFER_UNSUPPORTED: return "GL_FRAMEBUFFER_UNSUPPORTED";
    default: return "GL_(unknown)";
    }
}

bool rgl_has_extension(const char *name)
{
    GLint n = 0;
    gl.GetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; i++) {
        const char *e = (const char *)gl.GetStringi(GL_EXTENSIONS, (GLuint)i);
        if (e && strcmp(e, name) == 0)
            return true;
    }
    return false;
}

bool rgl_is_software(void)
{
    const char *r = (const char *)gl.GetString(GL_RENDERER);
    return r && (strstr(r, "llvmpipe") || strstr(r, "softpipe"));
}

static void APIENTRY debug_cb(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                              const GLchar *msg, const void *user)
{
    (void)id, (void)length, (void)user;
    /* compile errors are reported by r_shader with file:line, not here */
    if (source == GL_DEBUG_SOURCE_SHADER_COMPILER)
        return;
    if (type == GL_DEBUG_TYPE_ERROR)
        error_count++;
    if (severity == GL_DEBUG_SEVERITY_NOTIFICATION)
        return;
    const char *kind = type == GL_DEBUG_TYPE_ERROR                 ? "error"
                       : type == GL_DEBUG_TYPE_PERFORMANCE         ? "performance"
                       : type == GL_DEBUG_TYPE_DEPRECATED_BEHAVIOR ? "deprecated"
                       : type == GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR  ? "undefined"
                                                                   : "note";
    fprintf(stderr, "gl: %s: %s\n", kind, msg);
}

/* Float render targets are core in 3.0, but drivers may still refuse some
 * formats: ask the driver by building the FBO we would use. */
static bool probe_float_rt(void)
{
    GLuint tex = 0, fbo = 0;
    GLint old_tex = 0, old_draw = 0, old_read = 0;
    gl.GetIntegerv(GL_TEXTURE_BINDING_2D, &old_tex);
    gl.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &old_draw);
    gl.GetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &old_read);
    gl.GenTextures(1, &tex);
    gl.BindTexture(GL_TEXTURE_2D, tex);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, 4, 4, 0, GL_RGBA, GL_FLOAT, NULL);
    gl.GenFramebuffers(1, &fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    bool ok = gl.CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)old_draw);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, (GLuint)old_read);
    gl.BindTexture(GL_TEXTURE_2D, (GLuint)old_tex);
    gl.DeleteFramebuffers(1, &fbo);
    gl.DeleteTextures(1, &tex);
    return ok;
}

static bool at_least(int major, int minor)
{
    return glcaps.major > major || (glcaps.major == major && glcaps.minor >= minor);
}

bool rgl_load(rgl_getproc getproc, void *user, int min_major, int min_minor, bool debug, rs_err *err)
{
    memset(&gl, 0, sizeof gl);
    memset(&glcaps, 0, sizeof glcaps);
    for (size_t i = 0; i < sizeof funcs / sizeof funcs[0]; i++) {
        void *p = getproc(user, funcs[i].name);
        memcpy((char *)&gl + funcs[i].offset, &p, sizeof p);
        if (!p && funcs[i].required)
            return rs_fail(err, RGL_ERR_MISSING, "GL function %s is missing (driver too old for GL 3.3 core?)",
                           funcs[i].name);
    }
    gl.GetIntegerv(GL_MAJOR_VERSION, &glcaps.major);
    gl.GetIntegerv(GL_MINOR_VERSION, &glcaps.minor);
    glcaps.vendor = (const char *)gl.GetString(GL_VENDOR);
    glcaps.renderer = (const char *)gl.GetString(GL_RENDERER);
    glcaps.version = (const char *)gl.GetString(GL_VERSION);
    glcaps.glsl = (const char *)gl.GetString(GL_SHADING_LANGUAGE_VERSION);
    if (!at_least(min_major, min_minor))
        return rs_fail(err, RGL_ERR_VERSION, "got an OpenGL %d.%d context (%s), need %d.%d or newer", glcaps.major,
                       glcaps.minor, glcaps.version ? glcaps.version : "?", min_major, min_minor);
    GLint mask = 0, flags = 0;
    gl.GetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
    gl.GetIntegerv(GL_CONTEXT_FLAGS, &flags);
    glcaps.core = (mask & GL_CONTEXT_CORE_PROFILE_BIT) != 0;
    glcaps.debug_ctx = (flags & GL_CONTEXT_FLAG_DEBUG_BIT) != 0;
    if (!glcaps.core)
        return rs_fail(err, RGL_ERR_PROFILE, "got a compatibility-profile context (%s); ringside needs core",
                       glcaps.version ? glcaps.version : "?");
    gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &glcaps.max_texture_size);
    glcaps.fences = gl.FenceSync && gl.ClientWaitSync;
    GLint bits = 0;
    gl.GetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
    glcaps.timer_query = bits > 0;
    glcaps.buffer_storage = gl.BufferStorage && (at_least(4, 4) || rgl_has_extension("GL_ARB_buffer_storage"));
    glcaps.texture_storage = gl.TexStorage2D && (at_least(4, 2) || rgl_has_extension("GL_ARB_texture_storage"));
    glcaps.khr_debug = gl.DebugMessageCallback && (at_least(4, 3) || rgl_has_extension("GL_KHR_debug"));
    glcaps.float_rt = probe_float_rt();
    while (gl.GetError() != GL_NO_ERROR) {
        /* a probe above may legitimately fail; start clean */
    }
    if (debug && glcaps.khr_debug) {
        gl.Enable(GL_DEBUG_OUTPUT);
        gl.Enable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
        gl.DebugMessageCallback(debug_cb, NULL);
        gl.DebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, NULL, GL_TRUE);
        callback_on = true;
    } else {
        callback_on = false;
    }
    error_count = 0;
    return true;
}

unsigned rgl_error_count(void)
{
    return error_count;
}

void rgl_error_reset(void)
{
    error_count = 0;
}

bool rgl_check(const char *where)
{
    bool ok = true;
    for (int i = 0; i < 16; i++) {
        GLenum e = gl.GetError();
        if (e == GL_NO_ERROR)
            break;
        ok = false;
        if (callback_on)
            continue;
        fprintf(stderr, "gl: %s: %s\n", where, rgl_enum_name(e));
        error_count++;
    }
    return ok;
}
