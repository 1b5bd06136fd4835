/* The speed anchor: one drop-test impact of docs/model.md §2 (the
 * closed-form Hertz spring in series with a dashpot, no gravity) integrated
 * by GSL's rk8pd as a competent user would script it: adaptive steps, the
 * force peak and the separation located by secant iterations on single
 * steps re-integrated from the start of the step that crossed them. Not the
 * reference (reference.c brackets its events to the last bit): a yardstick
 * for the cost of an impact at a given accuracy. Measured against the
 * reference (tests/test_anchor.py): the h20 impact meets 1e-6 in F_peak,
 * eps, t_contact and x2_end from rtol 1e-6 on (about 300 right-hand sides);
 * a soft dashpot (c = 50, v0 = 3) meets it over its first 10 ms from
 * rtol 3e-6, but its separation, after 290 ms of creep with v falling to
 * 5e-9 m/s, only at rtol 3e-12. */
#ifndef FRACCONTACT_ANCHOR_H
#define FRACCONTACT_ANCHOR_H

typedef struct {
    double k, c, m; /* Hertz constant [N/m^1.5], dashpot [N s/m], striker mass [kg] */
    double v0;      /* impact velocity [m/s], > 0: contact begins at t = 0 */
    double t_end;   /* stop here if the striker has not separated [s] */
    double rtol;    /* relative tolerance of the step control */
} anchor_problem;

typedef struct {
    int separated;          /* 1: the figures below are the impact's */
    double F_peak;          /* largest force: at the located peak, else of the accepted steps [N] */
    double eps, t_contact;  /* -v / v0 and the time at separation */
    double x2_end;          /* permanent indentation at separation [m] */
    double t, x1, x2, v, F; /* the last state: at separation (x1 = 0), else at t_end */
    long evaluations;       /* right-hand sides, event location included */
    long steps, rejected;   /* accepted and rejected adaptive steps */
} anchor_result;

/* Integrates *p into *r. Returns 0, or a GSL status when GSL fails. */
int anchor_impact(const anchor_problem *p, anchor_result *r);

#endif
