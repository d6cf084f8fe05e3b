/* TEMPORARY skeleton: replaced by the water effect (issue 8). */
#include "r_local.h"

const r_fx_module r_fx_water_module = {"water", NULL, NULL, NULL, {NULL}, {0}};
