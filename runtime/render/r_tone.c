#include "r_tone.h"

#include <math.h>
#include <stdlib.h>

double r_tone_curve(double x, double gamma)
{
    if (!(x > 0)) /* also NaN */
        return 0;
    /* -expm1: 1 - exp(-x^2) without cancellation, which matters at high
     * gamma, where the curve near 0 goes like x^(3/gamma) */
    return pow(pow(-expm1(-x * x), 1.5), 1 / gamma);
}

double r_tone_index_power(double gamma)
{
    return gamma > 4 ? gamma / 2 : 2;
}

void r_tone_lut(float *lut, int n, double gamma)
{
    double m = r_tone_index_power(gamma);
    for (int k = 0; k < n; k++) {
        double u = (double)k / (n - 1);
        lut[k] = (float)r_tone_curve(pow(u, m) * R_TONE_X_MAX, gamma);
    }
}

double r_tone_lookup(const float *lut, int n, double gamma, double x, int weight_bits)
{
    double u = x > 0 ? pow(fmin(x, R_TONE_X_MAX) / R_TONE_X_MAX, 1 / r_tone_index_power(gamma)) : 0;
    double f = u * (n - 1);
    int i = (int)f;
    if (i > n - 2)
        i = n - 2;
    double t = f - i;
    if (weight_bits > 0) {
        double q = (double)(1 << weight_bits);
        t = floor(t * q + 0.5) / q;
    }
    return lut[i] * (1 - t) + lut[i + 1] * t;
}

double r_tone_max_error(int n, double gamma, int weight_bits)
{
    float *lut = malloc((size_t)n * sizeof *lut);
    if (!lut)
        return INFINITY;
    r_tone_lut(lut, n, gamma);
    double worst = 0, top = 1.25 * R_TONE_X_MAX;
    const int samples = 200000;
    for (int s = 0; s <= samples; s++) {
        /* denser near 0, where the curve bends hardest */
        double v = (double)s / samples, x = v * v * top;
        double e = fabs(r_tone_lookup(lut, n, gamma, x, weight_bits) - r_tone_curve(x, gamma));
        if (e > worst)
            worst = e;
    }
    free(lut);
    return worst;
}
