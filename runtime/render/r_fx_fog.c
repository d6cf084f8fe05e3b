/* TEMPORARY skeleton: replaced by the fog effect (issue 8). */
#include "r_local.h"

const r_fx_module r_fx_fog_module = {"fog", NULL, NULL, NULL, {NULL}, {0}};

void r_fx_fog_bind(r_game *r, GLuint p, int unit)
{
    (void)r, (void)p, (void)unit;
}
