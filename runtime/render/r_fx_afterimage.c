/* TEMPORARY skeleton: replaced by the afterimage effect (issue 8). */
#include "r_local.h"

const r_fx_module r_fx_afterimage_module = {"afterimage", NULL, NULL, NULL, {NULL}, {0}};
