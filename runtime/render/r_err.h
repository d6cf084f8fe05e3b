/* The renderer's error ids (rs_err.h): the render core (runtime/render)
 * and the stage effects (runtime/fx) fail with these.  Errors of the
 * modules the renderer calls (a stage file's R_STAGE_ERR_*, a shader's,
 * the IBL's) keep their own ids on the way up. */
#ifndef R_ERR_H
#define R_ERR_H

#include "../util/rs_err.h"

#define R_ERRORS(X)                                                                                   \
    X(NOMEM, "out of memory")                                                                         \
    X(TARGET, "a render target is incomplete, or its format cannot be drawn into on this driver")     \
    X(SIZE, "a frame or scene size out of range")                                                    \
    X(QUALITY, "a quality setting out of range")                                                     \
    X(OPTIONS, "render options that do not go together")                                             \
    X(LOOK, "the look's shader defines do not fit")                                                  \
    X(EFFECTS, "the effect table does not fit the core (too many effects, resource bits or texture units)") \
    X(GRAPH, "the pass graph is malformed (too many passes, a name twice, a read before any write)")

typedef enum r_error {
    R_ERR_BASE = RS_ERR_BASE(RS_ERR_MOD_R),
#define X(id, text) R_ERR_##id,
    R_ERRORS(X)
#undef X
        R_ERR_END
} r_error;

const char *r_error_text(int code);

#endif
