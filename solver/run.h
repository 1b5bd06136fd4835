/* What the library's runs and the GSL reference share: the per-impact list
 * and the scales of a contact. */
#ifndef FRACCONTACT_RUN_H
#define FRACCONTACT_RUN_H

#include <stddef.h>

#include "contact.h"
#include "fraccontact.h"

typedef struct {
    fc_impact *list;
    size_t n, cap;
} impact_list;

/* Rows of a time series, FC_COLUMNS doubles each, grown geometrically. */
typedef struct {
    double *rows;
    size_t n, cap;
    int failed; /* memory ran out: rows since are lost */
} series;

/* Appends a row, unless it repeats the last one's time (an event on an
 * output time); at most FC_ROWS_MAX of them. */
void series_add(series *s, const double row[FC_COLUMNS]);

/* FC_OK, or FC_EINVAL and a message when a time series with rows every
 * `interval` (0: every internal step, of which the run takes at least
 * `steps`) would hold more than FC_ROWS_MAX rows. */
fc_status run_rows_check(const fc_params *p, double interval, double steps, char *msg, size_t len);

/* The model's striker of a run: the relative motion of the striker and the
 * second body, at the approach speed v - v2 with the reduced mass
 * (docs/two_bodies.md). */
void fc_striker(const fc_params *p, double *v, double *m);

/* Appends; -1 when memory runs out (the list is unchanged). */
int impact_list_add(impact_list *l, const fc_impact *f);

/* The scales of a contact with spring stiffness K, for a striker of mass m
 * arriving at speed v (v0, or where it falls through the gap gap0 under g,
 * sqrt(v0^2 + 2 g gap0)): the elastic Hertz maximum x_max = (5 m v^2 /
 * (4 K))^(2/5), and the indentation (v c / K)^(2/3) at which the dashpot
 * takes over the rate v. *x_ref is the first (the second without inertia,
 * m = 0), *t_ref = x_ref / v the time to get there, and *x_small the smaller
 * of the two: where the contact first changes character, the scale for an
 * absolute tolerance. All 0 when nothing moves towards the specimen. */
void contact_scales(const contact_params *p, double K, double v0, double m, double *x_ref, double *t_ref,
                    double *x_small);

#endif
