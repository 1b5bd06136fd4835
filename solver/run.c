#include "run.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void series_add(series *s, const double row[FC_COLUMNS])
{
    if (s->failed || (s->n > 0 && !(row[FC_T] > s->rows[(s->n - 1) * FC_COLUMNS + FC_T])))
        return;
    if (s->n >= (size_t)FC_ROWS_MAX) {
        s->failed = 1;
        return;
    }
    if (s->n == s->cap) {
        size_t cap = s->cap ? (s->cap < (size_t)FC_ROWS_MAX / 2 ? 2 * s->cap : (size_t)FC_ROWS_MAX) : 1024;
        double *grown = realloc(s->rows, cap * FC_COLUMNS * sizeof *grown);
        if (!grown) {
            s->failed = 1;
            return;
        }
        s->rows = grown;
        s->cap = cap;
    }
    memcpy(s->rows + s->n++ * FC_COLUMNS, row, FC_COLUMNS * sizeof *row);
}

int impact_list_add(impact_list *l, const fc_impact *f)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 16;
        fc_impact *grown = realloc(l->list, cap * sizeof *grown);
        if (!grown)
            return -1;
        l->list = grown;
        l->cap = cap;
    }
    l->list[l->n++] = *f;
    return 0;
}

void contact_scales(const contact_params *p, double K, double v0, double m, double *x_ref, double *t_ref,
                    double *x_small)
{
    double g = p->scene == CONTACT_SCENE_DROP || m > 0.0 ? p->g : 0.0;
    double v2 = v0 * v0 + 2.0 * g * p->gap0, v = v2 > 0.0 ? sqrt(v2) : 0.0, x_dashpot;
    *x_ref = *t_ref = *x_small = 0.0;
    if (!(v > 0.0 && (v0 > 0.0 || g > 0.0)))
        return;
    /* K x^n = c v, and K x^(n+1)/(n+1) = m v^2/2 */
    x_dashpot = pow(v * p->c / K, 1.0 / p->spring_exponent);
    *x_ref = m > 0.0 ? pow(0.5 * (p->spring_exponent + 1.0) * m * v * v / K, 1.0 / (p->spring_exponent + 1.0))
                     : x_dashpot;
    *t_ref = *x_ref / v;
    *x_small = fmin(*x_ref, x_dashpot);
}
