/* The tone curve (docs/renderer.md, "Tone map, bloom, flare"): luminance Y is mapped with
 *     Y' = ((1 - exp(-x^2))^1.5)^(1/gamma),   x = exposure * Y
 * (gamma folded in: the output is display-encoded), then CbCr is scaled by
 * Y'/Y.  The curve is built on the CPU into a float lookup table whenever
 * gamma changes.
 *
 * The table is indexed by u = (x / R_TONE_X_MAX)^(1/m) (flat beyond: the
 * curve is within 1e-7 of 1 there), m = r_tone_index_power(gamma): 2 (a
 * square root) up to gamma 4, gamma/2 above.  That spends entries where
 * the curve bends: near 0 it goes like x^(3/gamma), i.e. like u^(3m/gamma),
 * which stays smooth (exponent >= 1.5) for every gamma in 0.1..10.  The shader interpolates two
 * texelFetch results itself instead of using the texture unit's linear
 * filter: GPUs filter with 8-bit fractional weights, which alone costs
 * more than the table's own error.  bench accuracy measures both. */
#ifndef R_TONE_H
#define R_TONE_H

#define R_TONE_X_MAX 4.0
#define R_TONE_LUT_DEFAULT 256
#define R_TONE_LUT_MIN 2
#define R_TONE_LUT_MAX 65536

/* The analytic curve, in double. */
double r_tone_curve(double x, double gamma);
/* The index power m for a gamma (see above). */
double r_tone_index_power(double gamma);
/* Fills lut[0..n-1]; entry k holds the curve at x = (k/(n-1))^m * X_MAX. */
void r_tone_lut(float *lut, int n, double gamma);
/* What the shader computes for x (the same arithmetic, in double);
 * weight_bits > 0 quantises the interpolation weight like a texture unit
 * (8 on current GPUs), 0 keeps it exact. */
double r_tone_lookup(const float *lut, int n, double gamma, double x, int weight_bits);
/* Largest |lookup - curve| over x in [0, 1.25 X_MAX], sampled densely. */
double r_tone_max_error(int n, double gamma, int weight_bits);

#endif
