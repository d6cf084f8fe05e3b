/* The holes effect's hook for tests (fx_holes.c). */
#ifndef FX_HOLES_H
#define FX_HOLES_H

struct r_game;

/* How many holes the frame drawn last cut into the ring. */
int fx_holes_drawn(struct r_game *r);

#endif
