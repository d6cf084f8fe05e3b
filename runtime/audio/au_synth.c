/* The synthesis toolkit shared by the bank and the music (au_local.h):
 * RBJ biquads and peak normalization.  Coefficients and state are double:
 * cheap at bank-build time, and the same numbers in every build. */
#include <math.h>

#include "au_local.h"

static void set(au_biquad *f, double b0, double b1, double b2, double a0, double a1, double a2)
{
    f->b0 = b0 / a0;
    f->b1 = b1 / a0;
    f->b2 = b2 / a0;
    f->a1 = a1 / a0;
    f->a2 = a2 / a0;
    f->x1 = f->x2 = f->y1 = f->y2 = 0;
}

void au_bq_lowpass(au_biquad *f, double hz, double q)
{
    double w = 2 * AU_PI * hz / AU_RATE, c = cos(w), al = sin(w) / (2 * q);
    set(f, (1 - c) / 2, 1 - c, (1 - c) / 2, 1 + al, -2 * c, 1 - al);
}

void au_bq_highpass(au_biquad *f, double hz, double q)
{
    double w = 2 * AU_PI * hz / AU_RATE, c = cos(w), al = sin(w) / (2 * q);
    set(f, (1 + c) / 2, -(1 + c), (1 + c) / 2, 1 + al, -2 * c, 1 - al);
}

void au_bq_bandpass(au_biquad *f, double hz, double q)
{
    double w = 2 * AU_PI * hz / AU_RATE, c = cos(w), al = sin(w) / (2 * q);
    set(f, al, 0, -al, 1 + al, -2 * c, 1 - al);
}

double au_bq_run(au_biquad *f, double x)
{
    double y = f->b0 * x + f->b1 * f->x1 + f->b2 * f->x2 - f->a1 * f->y1 - f->a2 * f->y2;
    f->x2 = f->x1;
    f->x1 = x;
    f->y2 = f->y1;
    f->y1 = y;
    return y;
}

void au_normalize_peak(float *buf, size_t n, double peak_dbfs)
{
    float peak = 0;
    for (size_t i = 0; i < n; i++)
        if (fabsf(buf[i]) > peak)
            peak = fabsf(buf[i]);
    if (peak <= 0)
        return;
    double g = pow(10.0, peak_dbfs / 20.0) / peak;
    for (size_t i = 0; i < n; i++)
        buf[i] = (float)(buf[i] * g);
}
