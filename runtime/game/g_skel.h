/* Fighter skeleton: 15 bones in the fight plane (x forward, y up), each a
 * capsule, plus a fixed lateral offset (z) for the 3D mesh.  A pose is a
 * local angle per bone and a root offset; forward kinematics turns it into
 * world capsules.  All integer (g_fixed.h): the game's hit detection uses
 * these capsules, and so will water, snow, shadows and motion blur. */
#ifndef G_SKEL_H
#define G_SKEL_H

#include <stdbool.h>

#include "g_fixed.h"

enum g_bone {
    G_PELVIS, G_SPINE, G_CHEST, G_NECK, G_HEAD,
    G_L_UPPERARM, G_L_FOREARM, G_R_UPPERARM, G_R_FOREARM,
    G_L_THIGH, G_L_SHIN, G_L_FOOT, G_R_THIGH, G_R_SHIN, G_R_FOOT,
    G_BONES
};

typedef struct g_bone_def {
    const char *name;
    int parent;   /* -1: starts at the root (hip point) */
    fx length, radius;
    fx z;         /* lateral offset for the mesh; + is the fighter's near side */
} g_bone_def;

extern const g_bone_def g_bones[G_BONES];

typedef struct g_pose {
    fx root_dx, root_dy; /* hip point relative to the standing hip height */
    fang ang[G_BONES];   /* bone direction in the fighter's frame */
} g_pose;

/* A capsule in world space: segment a-b with radius r; z for the mesh. */
typedef struct g_capsule {
    fx ax, ay, bx, by, r, z;
    fang angle; /* absolute angle of the bone in the fighter's frame */
} g_capsule;

#define G_HIP_HEIGHT FX(0.95)

/* World capsules for a pose of a fighter standing at (x, y) facing +1/-1. */
void g_skel_solve(const g_pose *pose, fx x, fx y, int facing, g_capsule out[G_BONES]);

/* The waist (top of the pelvis) in world space. */
void g_skel_waist(const g_capsule caps[G_BONES], fx *x, fx *y);

/* Squared distance between two 2D segments, in Q16.16 (metres squared);
 * saturates instead of overflowing for segments far apart. */
int64_t g_seg_dist2(fx ax, fx ay, fx bx, fx by, fx cx, fx cy, fx dx, fx dy);

bool g_capsules_touch(const g_capsule *a, const g_capsule *b);

#endif
