/* The stage effects (contract: runtime/render/r_fx.h), in the order their
 * passes run within each phase.  Adding an effect: its file, and a row. */
#include "fx_local.h"

extern const r_fx_module fx_fog_module, fx_lspsm_module, fx_holes_module, fx_water_module, fx_snow_module,
    fx_afterimage_module;

const r_fx_module *const r_fx_modules[] = {
    &fx_fog_module,   /* first: the fog map is read by every later scene draw */
    &fx_lspsm_module, /* the shadow map, read by every later scene draw */
    &fx_holes_module, /* before the other surfaces: it clears the frame (docs/effects.md,
                         "Destruction holes", steps 1-3) */
    &fx_water_module,
    &fx_snow_module,
    &fx_afterimage_module,
};
const int r_fx_nmodules = (int)(sizeof r_fx_modules / sizeof r_fx_modules[0]);
