#include "g1_grid.h"

#include <math.h>
#include <stdlib.h>

#include <gsl/gsl_fft_halfcomplex.h>
#include <gsl/gsl_fft_real.h>

#include "g1.h"

/* a *= b for two spectra in GSL's radix-2 half-complex layout:
 * [0] and [P/2] real, then (Re, Im) of bin k at [k] and [P - k]. */
static void multiply_spectra(double *a, const double *b, size_t P)
{
    size_t k;
    a[0] *= b[0];
    a[P / 2] *= b[P / 2];
    for (k = 1; k < P / 2; k++) {
        double re = a[k] * b[k] - a[P - k] * b[P - k];
        double im = a[k] * b[P - k] + a[P - k] * b[k];
        a[k] = re;
        a[P - k] = im;
    }
}

int g1_full_grid(double alpha, const double *f, size_t n_samples, double delta, size_t head, double *out)
{
    size_t i, P = 2, direct = head < n_samples ? head : n_samples;
    double *w = malloc((n_samples ? n_samples : 1) * sizeof *w), *a = NULL, *b = NULL, scale;
    if (!w)
        return -1;
    g1_weights(alpha, n_samples, w);
    for (i = 0; i < direct; i++)
        out[i] = g1_history_sum(alpha, w, f, i + 1, delta);
    if (direct < n_samples) {
        /* A linear, not circular, convolution: pad both to twice the length,
         * or the oldest weights wrap around onto the newest samples. */
        while (P < 2 * n_samples)
            P *= 2;
        a = calloc(P, sizeof *a);
        b = calloc(P, sizeof *b);
        if (!a || !b) {
            free(w);
            free(a);
            free(b);
            return -1;
        }
        for (i = 0; i < n_samples; i++) {
            a[i] = w[i];
            b[i] = f[i];
        }
        gsl_fft_real_radix2_transform(a, 1, P);
        gsl_fft_real_radix2_transform(b, 1, P);
        multiply_spectra(a, b, P);
        gsl_fft_halfcomplex_radix2_inverse(a, 1, P);
        scale = pow(delta, -alpha);
        for (i = direct; i < n_samples; i++)
            out[i] = scale * a[i];
    }
    free(w);
    free(a);
    free(b);
    return 0;
}
