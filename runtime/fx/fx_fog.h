/* The fog map effect's hooks for tests and bench accuracy (fx_fog.c; the
 * effect itself is reached only through its r_fx_module row). */
#ifndef FX_FOG_H
#define FX_FOG_H

#include <stdbool.h>
#include <stdio.h>

#include "../util/rs_err.h"

struct r_game;
struct fx_fog_sim;

/* The mist simulation (NULL when the module was not created). */
struct fx_fog_sim *fx_fog_get_sim(struct r_game *r);
/* Splat the map on the CPU (the default on a software rasteriser) or as
 * sprites on the GL (elsewhere); false when the module was not created. */
bool fx_fog_set_cpu(struct r_game *r, bool cpu);
/* The map of the frame drawn last: size x size floats, row = z, covering
 * x, z in +-half metres; out NULL asks the size only. */
bool fx_fog_read_map(struct r_game *r, float *out, int *size, float *half);
/* The "fog-map resolution vs time" table of bench accuracy (needs a
 * current GL context). */
bool fx_fog_accuracy_rows(FILE *out, rs_err *err);

#endif
