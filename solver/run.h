/* What a solve of the contact model produces besides its time series, and
 * the scales it is measured in; shared by the model's solve and the GSL
 * reference (fraccontact-solve). */
#ifndef FRACCONTACT_RUN_H
#define FRACCONTACT_RUN_H

#include <stddef.h>

#include "contact.h"

/* The figures of one finished impact. */
typedef struct {
    double t_onset;   /* time of contact onset [s] */
    double v_onset;   /* striker velocity at onset, towards the specimen [m/s] */
    double F_peak;    /* largest force of this impact [N] */
    double eps;       /* restitution coefficient -v_end / v_onset */
    double t_contact; /* duration of the contact [s] */
    double x2_end;    /* permanent indentation when it ended (all impacts so far) [m] */
    double E_diss;    /* energy dissipated during this impact [J] */
} impact_figures;

typedef struct {
    impact_figures *list;
    size_t n, cap;
} impact_list;

/* Appends; -1 when memory runs out (the list is unchanged). */
int impact_list_add(impact_list *l, const impact_figures *f);
void impact_list_free(impact_list *l);

/* Why a solve stopped. */
enum run_stop {
    RUN_STOP_IMPACTS = 1,  /* the requested number of impacts ended */
    RUN_STOP_T_END = 2,    /* the time limit came first */
    RUN_STOP_RECEDING = 3  /* out of contact, and nothing brings the striker back */
};
const char *run_stop_name(int stop); /* "impacts", "t_end", "receding" */

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
