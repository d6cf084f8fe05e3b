/* TEMPORARY skeleton: replaced by the snow effect (issue 8). */
#include "r_local.h"

const r_fx_module r_fx_snow_module = {"snow", NULL, NULL, NULL, {NULL}, {0}};
