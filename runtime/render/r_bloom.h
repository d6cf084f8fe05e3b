/* Bloom's blurs and glow on the CPU (docs/renderer.md, "Tone map, bloom,
 * flare"), for a software rasteriser: r_post.c reads the bright pass's
 * level back as floats, this makes the glow the tone map adds, and
 * r_post.c uploads it.  The arithmetic is the GL chain's (r_post.c,
 * run_bloom_blur; blur.frag's REACH 4 blurs, downsample.frag's halving,
 * the GLOW variant), in float where the GL keeps its levels as RGBE in
 * RGBA8: on llvmpipe those passes cost 3.4 ms a 640x360 frame on one
 * thread, this 0.7 ms (a loop bench of the 320x180 level), the reads and
 * the upload as much again.  No GL here. */
#ifndef R_BLOOM_H
#define R_BLOOM_H

#include <stdbool.h>
#include <stddef.h>

typedef struct r_bloom_cpu {
    int w4, h4;      /* the first level (the bright pass's target) */
    int w8, h8;      /* the second, half of it (level2) */
    float kw[5];     /* the blur's texel weights, centre first (r_blur_kernel(1)) */
    bool level2;     /* r_quality.bloom_levels != 1 */
    float bloom;     /* the stage's bloom strength */
    const float *flare; /* RGBA, fw x fh, added bilinearly; NULL: none */
    int fw, fh;
} r_bloom_cpu;

/* Floats of scratch r_bloom_glow needs. */
size_t r_bloom_scratch_floats(const r_bloom_cpu *b);
/* bright: RGBA, w4 x h4, rows bottom up as GL reads them; glow: the same
 * layout, alpha 1, each channel at most 65504 (half float's largest). */
void r_bloom_glow(const r_bloom_cpu *b, const float *bright, float *scratch, float *glow);

#endif
