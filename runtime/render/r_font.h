/* The HUD's bitmap font: 5x7 glyphs. */
#ifndef R_FONT_H_INCLUDED
#define R_FONT_H_INCLUDED

#include <stdint.h>

#define R_FONT_W 5
#define R_FONT_H 7
#define R_FONT_GLYPHS 41

typedef struct r_glyph {
    char c;
    uint8_t rows[R_FONT_H];
} r_glyph;

extern const r_glyph r_font_glyphs[R_FONT_GLYPHS];

#endif
