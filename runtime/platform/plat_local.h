/* Private to the platform layer: the contract each backend file fills.
 * Adding a backend is adding a file with one plat_backend and a line in
 * plat.c's table. */
#ifndef PLAT_LOCAL_H
#define PLAT_LOCAL_H

#include "plat.h"

typedef struct plat_backend {
    const char *name;
    /* Creates the context and makes it current; fills p->impl and p->detail. */
    bool (*create)(plat *p, rs_err *err);
    void *(*proc)(plat *p, const char *name);
    bool (*make_current)(plat *p);
    void (*present)(plat *p);
    bool (*poll)(plat *p);
    void (*size)(const plat *p, int *w, int *h);
    void (*destroy)(plat *p);
} plat_backend;

struct plat {
    const plat_backend *be;
    plat_desc desc; /* defaults applied */
    void *impl;
    void *window;   /* GLFWwindow * (glfw only) */
    char detail[256];
    char fallback[512];
};

extern const plat_backend plat_egl_backend;
extern const plat_backend plat_osmesa_backend;
extern const plat_backend plat_glfw_backend;

#endif
