/* GPU downscale filters.  Each writes an RGBA8 image of the output size
 * whose GL row 0 is the picture's top row (so readback comes out top-down).
 *
 *   box       area average of the exact footprint (one bilinear tap at 2x)
 *   bilinear  glBlitFramebuffer with GL_LINEAR (one tap: aliases past 2x)
 *   nearest   glBlitFramebuffer with GL_NEAREST (aliases)
 *   lanczos3  separable two-pass Lanczos-3 stretched by the scale
 * `ringside bench accuracy` measures them against OpenImageIO's resize;
 * docs/capture.md has the table and why box is the default. */
#ifndef CAP_SCALE_H
#define CAP_SCALE_H

#include <stdbool.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/util/rs_err.h"

typedef enum cap_filter { CAP_FILTER_BOX, CAP_FILTER_BILINEAR, CAP_FILTER_NEAREST, CAP_FILTER_LANCZOS3, CAP_FILTERS } cap_filter;

const char *cap_filter_name(cap_filter f);
bool cap_filter_parse(const char *s, cap_filter *f);

typedef struct cap_scaler cap_scaler;

cap_scaler *cap_scaler_create(cap_filter f, int sw, int sh, int w, int h, rs_err *err);
/* src: RGBA8 texture, sw x sh, bottom-up.  Draws into dst_fbo (w x h). */
void cap_scaler_run(cap_scaler *s, GLuint src, GLuint dst_fbo);
void cap_scaler_destroy(cap_scaler *s);

#endif
