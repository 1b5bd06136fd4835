/* The high-accuracy reference: the contact ODE of MODEL.md §2 solved with
 * GSL's odeiv2 (adaptive Runge-Kutta-Prince-Dormand 8(9), or the implicit
 * multistep BDF where the dashpot makes the problem stiff), with contact
 * onset, the force peak and separation located by root finding. It solves
 * the continuous model: the Hertz law, or for the G1 laws with fixed N the
 * Hertz law with their stiffness; the G1 law with N = steps since onset
 * tends to the Hertz law as its step shrinks. */
#ifndef FRACCONTACT_REFERENCE_H
#define FRACCONTACT_REFERENCE_H

#include "contact.h"

typedef struct {
    double F_peak, eps, t_contact, x_perm, E_diss;
    double t;            /* where the solve stopped [s] */
    double v, x, x1;     /* striker velocity, total and elastic indentation there */
    long impacts;
    long rhs_evaluations;
    int stiff;           /* 1: BDF was used */
} reference_result;

/* Called at every output time with t, F, x (total indentation), x1 (the
 * elastic one), x2, v, E_diss. */
typedef void (*reference_sample)(void *ctx, double t, double F, double x, double x1, double x2, double v,
                                 double E_diss);

/* Solves from t = 0 (striker at gap0, velocity v0, mass m as in
 * contact_start) until `impacts` impacts have ended or t_end, at relative
 * tolerance rtol. Samples every out_dt (0: 1/64 of the contact's time
 * scale; events are located within each such interval). Returns 0, or -1 with a
 * message when GSL fails. */
int reference_solve(const contact_params *p, double v0, double m, double rtol, double t_end,
                    long impacts, double out_dt, reference_sample sample, void *ctx,
                    reference_result *result, char *msg, size_t len);

#endif
