#include "input.h"

#ifdef RS_HAVE_GLFW
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

static bool down(GLFWwindow *w, int key)
{
    return glfwGetKey(w, key) == GLFW_PRESS;
}

static const int keys[2][8] = {
    /* up, down, left, right, punch, kick, guard, start */
    {GLFW_KEY_W, GLFW_KEY_S, GLFW_KEY_A, GLFW_KEY_D, GLFW_KEY_J, GLFW_KEY_K, GLFW_KEY_L, GLFW_KEY_1},
    {GLFW_KEY_UP, GLFW_KEY_DOWN, GLFW_KEY_LEFT, GLFW_KEY_RIGHT, GLFW_KEY_KP_1, GLFW_KEY_KP_2, GLFW_KEY_KP_3,
     GLFW_KEY_2},
};
static const int alt_p2[3] = {GLFW_KEY_COMMA, GLFW_KEY_PERIOD, GLFW_KEY_SLASH};

g_input in_read(void *window, int player)
{
    GLFWwindow *w = window;
    g_input in = 0;
    for (int b = 0; b < 8; b++)
        if (down(w, keys[player][b]))
            in |= (g_input)(1u << b);
    if (player == 1)
        for (int b = 0; b < 3; b++)
            if (down(w, alt_p2[b]))
                in |= (g_input)(G_IN_PUNCH << b);
    GLFWgamepadstate pad;
    int jid = GLFW_JOYSTICK_1 + player;
    if (glfwJoystickIsGamepad(jid) && glfwGetGamepadState(jid, &pad)) {
        const unsigned char *bt = pad.buttons;
        float ax = pad.axes[GLFW_GAMEPAD_AXIS_LEFT_X], ay = pad.axes[GLFW_GAMEPAD_AXIS_LEFT_Y];
        if (bt[GLFW_GAMEPAD_BUTTON_DPAD_UP] || ay < -0.5f)
            in |= G_IN_UP;
        if (bt[GLFW_GAMEPAD_BUTTON_DPAD_DOWN] || ay > 0.5f)
            in |= G_IN_DOWN;
        if (bt[GLFW_GAMEPAD_BUTTON_DPAD_LEFT] || ax < -0.5f)
            in |= G_IN_LEFT;
        if (bt[GLFW_GAMEPAD_BUTTON_DPAD_RIGHT] || ax > 0.5f)
            in |= G_IN_RIGHT;
        if (bt[GLFW_GAMEPAD_BUTTON_X])
            in |= G_IN_PUNCH;
        if (bt[GLFW_GAMEPAD_BUTTON_A])
            in |= G_IN_KICK;
        if (bt[GLFW_GAMEPAD_BUTTON_B] || bt[GLFW_GAMEPAD_BUTTON_RIGHT_BUMPER] || bt[GLFW_GAMEPAD_BUTTON_LEFT_BUMPER])
            in |= G_IN_GUARD;
        if (bt[GLFW_GAMEPAD_BUTTON_START])
            in |= G_IN_START;
    }
    return g_input_clean(in);
}

bool in_quit(void *window)
{
    return down(window, GLFW_KEY_ESCAPE);
}

#else
g_input in_read(void *window, int player)
{
    (void)window, (void)player;
    return 0;
}

bool in_quit(void *window)
{
    (void)window;
    return false;
}
#endif
