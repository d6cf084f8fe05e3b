#define _GNU_SOURCE /* dl_iterate_phdr, RTLD_NODELETE: sanitizer builds only */
#include "plat.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../gl/rgl.h"
#include "plat_local.h"

static const plat_backend *const backends[] = {
#ifdef RS_HAVE_EGL
    &plat_egl_backend,
#endif
#ifdef RS_HAVE_OSMESA
    &plat_osmesa_backend,
#endif
#ifdef RS_HAVE_GLFW
    &plat_glfw_backend,
#endif
};
#define NBACKENDS (sizeof backends / sizeof backends[0])

static const char *const known[] = {"egl", "osmesa", "glfw"};

const char *plat_error_text(plat_error e)
{
    static const char *const text[] = {
#define X(id, t) t,
        PLAT_ERRORS(X)
#undef X
    };
    return (unsigned)e < PLAT_ERR_COUNT ? text[e] : "?";
}

const char *plat_built_backends(void)
{
    static char names[64];
    names[0] = 0;
    for (size_t i = 0; i < NBACKENDS; i++) {
        size_t l = strlen(names);
        snprintf(names + l, sizeof names - l, "%s%s", l ? " " : "", backends[i]->name);
    }
    return names;
}

static const plat_backend *find(const char *name)
{
    for (size_t i = 0; i < NBACKENDS; i++)
        if (strcmp(backends[i]->name, name) == 0)
            return backends[i];
    return NULL;
}

bool plat_backend_built(const char *name)
{
    return find(name) != NULL;
}

#ifdef RS_SANITIZE
#include <dlfcn.h>
#include <link.h>
/* GL drivers are dlclose()d at eglTerminate, before LeakSanitizer reports at
 * exit; their leaks then show as "<unknown module>" and no suppression by
 * library name can match them.  Pin every loaded object so reports name it. */
static int pin_one(struct dl_phdr_info *info, size_t size, void *data)
{
    (void)size, (void)data;
    if (info->dlpi_name && info->dlpi_name[0])
        dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
    return 0;
}
static void pin_modules(void)
{
    dl_iterate_phdr(pin_one, NULL);
}
#else
static void pin_modules(void)
{
}
#endif

static void *getproc(void *user, const char *name)
{
    plat *p = user;
    return p->be->proc(p, name);
}

/* One backend, start to finish: context, current, GL table, version check. */
static plat *try_backend(const plat_backend *be, const plat_desc *d, rs_err *err)
{
    plat *p = calloc(1, sizeof *p);
    if (!p) {
        rs_fail(err, PLAT_ERR_CONTEXT, "out of memory");
        return NULL;
    }
    p->be = be;
    p->desc = *d;
    if (!be->create(p, err)) {
        free(p);
        return NULL;
    }
    pin_modules();
    if (!rgl_load(getproc, p, d->gl_major, d->gl_minor, d->debug, err)) {
        err->code = PLAT_ERR_GL;
        rs_err_prefix(err, "%s", be->name);
        be->destroy(p);
        free(p);
        return NULL;
    }
    return p;
}

plat *plat_create(const plat_desc *desc, rs_err *err)
{
    rs_err local;
    if (!err)
        err = &local;
    plat_desc d = desc ? *desc : (plat_desc){0};
    if (!d.width || !d.height) {
        d.width = 1280;
        d.height = 720;
    }
    if (!d.title)
        d.title = "ringside";
    if (!d.gl_major) {
        d.gl_major = 3;
        d.gl_minor = 3;
    }
#ifdef RS_DEBUG
    d.debug = true;
#endif
    const char *dbg = getenv("RINGSIDE_GL_DEBUG");
    if (dbg && *dbg && strcmp(dbg, "0") != 0)
        d.debug = true;
    const char *name = d.backend && *d.backend ? d.backend : "auto";
    if (strcmp(name, "auto") != 0) {
        const plat_backend *be = find(name);
        if (!be) {
            for (size_t i = 0; i < sizeof known / sizeof known[0]; i++)
                if (strcmp(known[i], name) == 0) {
                    rs_fail(err, PLAT_ERR_NOT_BUILT, "backend '%s' is not built into this binary (built: %s)", name,
                            plat_built_backends());
                    return NULL;
                }
            rs_fail(err, PLAT_ERR_UNKNOWN_BACKEND, "unknown backend '%s' (expected egl, osmesa or glfw)", name);
            return NULL;
        }
        return try_backend(be, &d, err);
    }

    /* auto: headless EGL, then OSMesa; remember why EGL was passed over */
    char why[512] = "";
    const plat_backend *egl = find("egl"), *osm = find("osmesa");
    if (egl) {
        plat *p = try_backend(egl, &d, err);
        if (p)
            return p;
        snprintf(why, sizeof why, "%s", err->msg);
    }
    if (osm) {
        plat *p = try_backend(osm, &d, err);
        if (p) {
            snprintf(p->fallback, sizeof p->fallback, "%s", why[0] ? why : "egl not built in");
            return p;
        }
        if (why[0])
            rs_err_prefix(err, "%s; then", why);
    }
    if (!egl && !osm)
        rs_fail(err, PLAT_ERR_NO_BACKEND, "no headless backend built in (built: %s)", plat_built_backends());
    else
        err->code = PLAT_ERR_NO_BACKEND;
    return NULL;
}

void plat_destroy(plat *p)
{
    if (!p)
        return;
    p->be->destroy(p);
    free(p);
}

const char *plat_backend_name(const plat *p) { return p->be->name; }
const char *plat_detail(const plat *p) { return p->detail; }
const char *plat_fallback_reason(const plat *p) { return p->fallback; }
void *plat_proc(plat *p, const char *name) { return p->be->proc(p, name); }
bool plat_make_current(plat *p) { return p->be->make_current(p); }
void plat_present(plat *p) { p->be->present(p); }
bool plat_poll(plat *p) { return p->be->poll(p); }
void *plat_window(const plat *p) { return p->window; }

void plat_size(const plat *p, int *w, int *h)
{
    *w = *h = 0;
    if (p->be->size)
        p->be->size(p, w, h);
}
