/* Live input: keyboard for both players and GLFW gamepads / arcade sticks.
 *
 * Default keys (docs/game.md):
 *   player 1: W A S D stick, J punch, K kick, L guard, 1 start
 *   player 2: arrow keys stick, numpad 1/2/3 or , . / for punch, kick, guard, 2 start
 *   Escape quits.
 * Gamepad 1 drives player 1 and gamepad 2 player 2, together with the keys:
 * d-pad or left stick, X/Square punch, A/Cross kick, B/Circle or a shoulder
 * guard, Start start.  Opposite directions cancel (what a real stick can't do). */
#ifndef INPUT_H
#define INPUT_H

#include <stdbool.h>

#include "game/g_game.h"

/* window: the GLFWwindow * from plat_window(). */
g_input in_read(void *window, int player);
bool in_quit(void *window);

#endif
