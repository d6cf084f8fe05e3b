/* au_xcorr: how well two stereo float tracks agree, and at what offset.
 * The shell tests compile it on the spot (python3 here has no numpy).
 *
 *   au_xcorr A.f32 B.f32 [FROM COUNT [MAXLAG]]
 *
 * A and B are raw 32-bit float stereo (ffmpeg -f f32le).  Over A's frames
 * FROM..FROM+COUNT (default: all of A), finds the lag in -MAXLAG..MAXLAG
 * frames (default 480, 10 ms at 48 kHz) at which B[i + lag] best matches
 * A[i] (normalized cross-correlation over both channels) and prints
 *   corr C lag L rms_a R rms_b R
 * B frames outside B count as silence.  Exit 2 on bad arguments or files. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static float *load(const char *path, long *frames)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "au_xcorr: %s: cannot open\n", path);
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    float *p = malloc((size_t)n + 8);
    if (!p || fread(p, 1, (size_t)n, f) != (size_t)n) {
        fprintf(stderr, "au_xcorr: %s: cannot read\n", path);
        fclose(f);
        free(p);
        return NULL;
    }
    fclose(f);
    *frames = n / 8;
    return p;
}

int main(int argc, char **argv)
{
    if (argc != 3 && argc != 5 && argc != 6) {
        fprintf(stderr, "usage: au_xcorr A.f32 B.f32 [FROM COUNT [MAXLAG]]\n");
        return 2;
    }
    long na, nb;
    float *a = load(argv[1], &na), *b = load(argv[2], &nb);
    if (!a || !b)
        return 2;
    long from = argc > 3 ? atol(argv[3]) : 0, count = argc > 3 ? atol(argv[4]) : na, maxlag = argc > 5 ? atol(argv[5]) : 480;
    if (from < 0 || count < 1 || from + count > na || maxlag < 0) {
        fprintf(stderr, "au_xcorr: frames %ld..%ld outside A's %ld\n", from, from + count, na);
        return 2;
    }
    double best = -2, ra = 0, rb = 0;
    long best_lag = 0;
    for (long lag = -maxlag; lag <= maxlag; lag++) {
        double ab = 0, aa = 0, bb = 0;
        for (long i = from; i < from + count; i++) {
            long j = i + lag;
            for (int c = 0; c < 2; c++) {
                double x = a[2 * i + c], y = j >= 0 && j < nb ? b[2 * j + c] : 0;
                ab += x * y;
                aa += x * x;
                bb += y * y;
            }
        }
        double r = aa > 0 && bb > 0 ? ab / sqrt(aa * bb) : 0;
        if (r > best) {
            best = r;
            best_lag = lag;
            ra = sqrt(aa / (2.0 * count));
            rb = sqrt(bb / (2.0 * count));
        }
    }
    printf("corr %.6f lag %ld rms_a %.6f rms_b %.6f\n", best, best_lag, ra, rb);
    free(a);
    free(b);
    return 0;
}
