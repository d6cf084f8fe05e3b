/* rgl: the one GL function loader, shared by every platform backend.
 *
 * All GL calls in ringside go through the `gl` table: gl.Clear(...),
 * gl.BindBuffer(...).  A table instead of global glClear symbols keeps our
 * pointers from colliding with the gl* functions libOSMesa exports.
 *
 * Contract: after a backend makes its context current, plat.c calls
 * rgl_load() with that backend's get-proc-address; the table then serves the
 * current context.  One context is current per process at a time (tests
 * switching backends reload).  rgl_load also fills glcaps.
 *
 * Error checking: with a debug context (plat_desc.debug, RINGSIDE_GL_DEBUG=1
 * or a debug build) and KHR_debug, a callback logs every GL error and
 * counts it; rgl_check() polls glGetError where there is no KHR_debug. */
#ifndef RGL_H
#define RGL_H

#include <GL/glcorearb.h>
#include <stdbool.h>

#include "../util/rs_err.h"

typedef struct rgl_api {
#define GLF(req, U, N) PFNGL##U##PROC N;
#include "rgl_funcs.h"
#undef GLF
} rgl_api;

extern rgl_api gl;

typedef struct rgl_caps {
    int major, minor;            /* context version actually obtained */
    bool core;                   /* core profile */
    bool debug_ctx;              /* context has GL_CONTEXT_FLAG_DEBUG_BIT */
    const char *vendor, *renderer, *version, *glsl;
    int max_texture_size;
    bool float_rt;               /* RGBA16F colour attachment is complete */
    bool fences;                 /* glFenceSync / glClientWaitSync */
    bool timer_query;            /* GL_TIME_ELAPSED with > 0 counter bits */
    bool buffer_storage;         /* glBufferStorage: GL 4.4 or ARB_buffer_storage */
    bool texture_storage;        /* glTexStorage2D: GL 4.2 or ARB_texture_storage */
    bool khr_debug;              /* glDebugMessageCallback */
} rgl_caps;

extern rgl_caps glcaps;

typedef void *(*rgl_getproc)(void *user, const char *name);

enum { RGL_ERR_MISSING = 1, RGL_ERR_VERSION, RGL_ERR_PROFILE };

/* Loads every function, fills glcaps, checks the context is a core >= 3.3
 * (or min_major.min_minor) context, and installs the debug callback when
 * `debug`.  Fails naming the first missing function or the wrong version. */
bool rgl_load(rgl_getproc getproc, void *user, int min_major, int min_minor, bool debug, rs_err *err);

bool rgl_has_extension(const char *name);

/* The current context draws on the CPU (Mesa's llvmpipe or softpipe):
 * every fragment and triangle costs a core's time, so some work is
 * cheaper done in plain C, and passes are timed with glFinish. */
bool rgl_is_software(void);

/* GL errors seen by the debug callback or rgl_check since the last reset. */
unsigned rgl_error_count(void);
void rgl_error_reset(void);
/* Drains glGetError; logs "gl: <where>: <error>" per error and counts it.
 * Cheap enough for tests; call sites use RGL_CHECK (debug builds only). */
bool rgl_check(const char *where);
#ifdef RS_DEBUG
#define RGL_CHECK(where) rgl_check(where)
#else
#define RGL_CHECK(where) ((void)0)
#endif

const char *rgl_enum_name(GLenum e);

#endif
