/* What the stage-effect modules (runtime/fx/) share beyond what the render
 * core hands them (runtime/render/r_fx_core.h): the pass-graph bits of
 * their resources.  The contract
 * they implement is runtime/render/r_fx.h; the table that lists them is
 * fx_table.c.  A new effect takes the next free bit here. */
#ifndef FX_LOCAL_H
#define FX_LOCAL_H

#include "../render/r_fx_core.h"

#define FX_RES(k) (1u << (R_RES_FX_FIRST + (k)))
enum {
    RES_FOGMAP = FX_RES(0),      /* fx_fog.c: the fog density map, read by every scene draw */
    RES_WATER = FX_RES(1),       /* fx_water.c: the wave simulation: persistent, steps each tick */
    RES_WATER_REFL = FX_RES(2),
    RES_WATER_UNDER = FX_RES(3),
    RES_SNOW = FX_RES(4),        /* fx_snow.c: the displacement map: persistent */
    RES_SNOW_LIGHT = FX_RES(5),
    RES_LSPSM = FX_RES(6),       /* fx_lspsm.c: the large-world shadow map, read by every scene draw */
};

#endif
