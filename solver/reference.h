/* The high-accuracy reference: the contact ODE of docs/model.md §2 solved with
 * GSL's odeiv2 (adaptive Runge-Kutta-Prince-Dormand 8(9), or the implicit
 * multistep BDF where the dashpot makes the problem stiff), with contact
 * onset, the force peak and separation located by root finding. It solves
 * the continuous model: the Hertz law, or for the G1 laws with fixed N the
 * Hertz law with their stiffness; the G1 law with N = steps since onset
 * tends to the Hertz law as its step shrinks. */
#ifndef FRACCONTACT_REFERENCE_H
#define FRACCONTACT_REFERENCE_H

#include "contact.h"
#include "run.h"

typedef struct {
    fc_outcome outcome;  /* as the library's runs give it; steps: right-hand-side evaluations */
    int stiff;           /* 1: BDF was used */
} reference_result;

/* Called at every output time with t, F, x (total indentation), x1 (the
 * elastic one), x2, v, E_diss. */
typedef void (*reference_sample)(void *ctx, double t, double F, double x, double x1, double x2, double v,
                                 double E_diss);

/* Solves the run *p (striker at gap0, velocity v, mass m as in
 * contact_start) at relative tolerance rtol until p->impacts impacts have
 * ended, p->t_end, or the striker recedes for good, appending each finished
 * impact to *impacts. Events are located within brackets of 1/64 of the
 * contact's time scale, whatever the output: the samples, every out_dt and at
 * every onset and separation (out_dt = 0: at every bracket), are integrated
 * from the last bracket and change no figure. `progress` (or NULL) is
 * called now and then as the library's runs call it; when it asks to stop,
 * the outcome's status is FC_ESTOPPED. Returns 0, or -1 with a message when
 * GSL fails, memory runs out or the run was stopped. */
int reference_solve(const fc_params *p, double rtol, double out_dt, reference_sample sample, void *ctx,
                    fc_progress progress, void *progress_ctx, impact_list *per_impact, reference_result *result,
                    char *msg, size_t len);

#endif
