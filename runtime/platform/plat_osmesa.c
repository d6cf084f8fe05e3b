/* OSMesa: Mesa's off-screen software renderer, the fallback when EGL cannot
 * give a context.  The context needs a client-memory colour buffer to be
 * current; we give it 1x1 pixels and render into FBOs like EGL.
 *
 * Only <GL/osmesa.h> is included here (it drags in GL/gl.h, which must not
 * meet glcorearb.h in one file); GL calls go through rgl like elsewhere. */
#ifdef RS_HAVE_OSMESA /* configure.sh found the library; otherwise this file is empty */

#include <GL/osmesa.h>
#include <stdio.h>
#include <stdlib.h>

#include "plat_local.h"

typedef struct osm_impl {
    OSMesaContext ctx;
    unsigned char pixel[4 * 4];
} osm_impl;

static bool osm_make_current(plat *p)
{
    osm_impl *im = p->impl;
    return OSMesaMakeCurrent(im->ctx, im->pixel, GL_UNSIGNED_BYTE, 1, 1);
}

static bool osm_create(plat *p, rs_err *err)
{
    osm_impl *im = calloc(1, sizeof *im);
    if (!im)
        return rs_fail(err, PLAT_ERR_CONTEXT, "osmesa: out of memory");
    const int attr[] = {OSMESA_FORMAT,
                        OSMESA_RGBA,
                        OSMESA_DEPTH_BITS,
                        24,
                        OSMESA_STENCIL_BITS,
                        8,
                        OSMESA_ACCUM_BITS,
                        0,
                        OSMESA_PROFILE,
                        OSMESA_CORE_PROFILE,
                        OSMESA_CONTEXT_MAJOR_VERSION,
                        p->desc.gl_major,
                        OSMESA_CONTEXT_MINOR_VERSION,
                        p->desc.gl_minor,
                        0};
    im->ctx = OSMesaCreateContextAttribs(attr, NULL);
    if (!im->ctx) {
        free(im);
        return rs_fail(err, PLAT_ERR_CONTEXT, "osmesa: OSMesaCreateContextAttribs(GL %d.%d core) failed",
                       p->desc.gl_major, p->desc.gl_minor);
    }
    p->impl = im;
    if (!osm_make_current(p)) {
        OSMesaDestroyContext(im->ctx);
        free(im);
        p->impl = NULL;
        return rs_fail(err, PLAT_ERR_CONTEXT, "osmesa: OSMesaMakeCurrent failed");
    }
    snprintf(p->detail, sizeof p->detail, "OSMesa %d.%d", OSMESA_MAJOR_VERSION, OSMESA_MINOR_VERSION);
    return true;
}

static void *osm_proc(plat *p, const char *name)
{
    (void)p;
    return (void *)OSMesaGetProcAddress(name);
}

static void osm_present(plat *p)
{
    (void)p;
}

static bool osm_poll(plat *p)
{
    (void)p;
    return true;
}

static void osm_destroy(plat *p)
{
    osm_impl *im = p->impl;
    if (!im)
        return;
    OSMesaMakeCurrent(NULL, NULL, GL_UNSIGNED_BYTE, 0, 0);
    OSMesaDestroyContext(im->ctx);
    free(im);
    p->impl = NULL;
}

const plat_backend plat_osmesa_backend = {
    .name = "osmesa",
    .create = osm_create,
    .proc = osm_proc,
    .make_current = osm_make_current,
    .present = osm_present,
    .poll = osm_poll,
    .destroy = osm_destroy,
};

#else
typedef int plat_osmesa_not_built; /* ISO C wants something in a file */
#endif
