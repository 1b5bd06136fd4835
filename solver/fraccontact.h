/* libfraccontact: the contact model of docs/model.md as a C library, for the
 * solver CLI, the benchmarks and the Python package (GSL's odeiv2 style: a
 * parameter struct with defaults from one function, status codes, no global
 * state). The same model code as the FMU; no GSL, libc and libm only.
 *
 *   fc_params p;
 *   fc_result r;
 *   char why[FC_MESSAGE_SIZE];
 *   fc_params_default(&p);          the paper's h20 drop test
 *   p.model.c = 5000.0;
 *   if (fc_run(&p, FC_NO_ROWS, &r, why, sizeof why) != FC_OK) ...
 *   ... r.outcome.first.F_peak, r.per_impact[i].eps ...
 *   fc_result_free(&r);
 *
 * Names, units and defaults of every parameter: fc_parameter_at(). */
#ifndef FRACCONTACT_H
#define FRACCONTACT_H

#include <stddef.h>
#include <stdint.h>

#include "contact.h"

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32)
#define FC_API __declspec(dllexport)
#else
#define FC_API __attribute__((visibility("default")))
#endif

typedef enum {
    FC_OK = 0,
    FC_EINVAL = 1, /* a parameter breaks its rule: the message names it, its value and the rule */
    FC_EFAIL = 2,  /* the state became non-finite (never for valid parameters; a guard) */
    FC_ENOMEM = 3, /* out of memory for rows or impacts, or more rows than FC_ROWS_MAX */
    FC_ESTOPPED = 4 /* a progress callback asked the run to stop */
} fc_status;

/* Why a run stopped. */
typedef enum {
    FC_STOP_IMPACTS = 1,  /* the requested number of impacts ended */
    FC_STOP_T_END = 2,    /* the time limit came first */
    FC_STOP_RECEDING = 3, /* out of contact, and nothing brings the striker back */
    FC_STOP_RESTING = 4   /* in contact, at rest for good: an overdamped contact that never separates */
} fc_stop;

#define FC_MESSAGE_SIZE 512

/* The FMU's variables by their names, and the run's stop conditions: the
 * library's rows of model/parameters.def, which says what each is
 * (fc_parameter_at tells them at run time). The model's parameters are the
 * member model (p.model.c, p.model.dt_max). */
typedef struct {
#define INPUT_FMU_LIBRARY(name, type, ...) CONTACT_TYPE(type) name;
#include "parameters.def"
    contact_params model;
#define STOP_LIBRARY(name, type, ...) CONTACT_TYPE(type) name;
#include "parameters.def"
} fc_params;

/* The paper's h20 drop test (docs/model.md §1): v = sqrt(2 9.81 0.020), m =
 * 0.7437, k = 3.299e8, c = 6080, dt_max = 0 (fixed steps of 1e-7 s), G1 law; one impact, t_end 1 s. */
FC_API void fc_params_default(fc_params *p);

/* FC_OK, or FC_EINVAL and a message naming the first parameter that breaks
 * its rule, with its value and the rule. */
FC_API fc_status fc_params_check(const fc_params *p, char *msg, size_t len);

/* sqrt(2 g h), g = 9.81 m/s^2: the impact velocity of a drop from height h [m]. */
FC_API double fc_drop_velocity(double height);

/* 1 and a message when a parameter has no effect (a material beside k != 0,
 * the other damper's parameters), else 0. */
FC_API int fc_params_warning(const fc_params *p, char *msg, size_t len);

/* 1 when the run chooses its steps by p->model.tolerance (Kvaerno's ESDIRK 5(4)),
 * 0 when it takes fixed steps of dt_max. */
FC_API int fc_error_controlled(const fc_params *p);

/* The method the run takes, as the model names it (contact_method_name):
 * "gradient", "esdirk54", "radau_iia", "g1_history" or "central". */
FC_API const char *fc_method_name(const fc_params *p);

/* The largest internal step of these parameters [s]: dt_max, or for
 * dt_max = 0 the fixed step of 1e-7 s, or INFINITY where error-controlled
 * steps have no cap. */
FC_API double fc_step_limit(const fc_params *p);

/* What fc_parameter_at tells of each member of fc_params. */
typedef enum { FC_REAL = 0, FC_INTEGER = 1 } fc_kind;

typedef struct {
    const char *name;    /* the member's (and the FMU variable's) name */
    fc_kind kind;        /* double or int */
    size_t offset;       /* offsetof(fc_params, name), of model.name for the model's */
    const char *unit;    /* SI unit, "1" for a number */
    const char *help;    /* one line */
    const char *words;   /* the words an integer's codes 1, 2, ... also take, space-separated ("" for none) */
} fc_parameter;

/* The i-th parameter (0 <= i < fc_parameter_count()), in a fixed order;
 * its default is that member of fc_params_default's. */
FC_API size_t fc_parameter_count(void);
FC_API const fc_parameter *fc_parameter_at(size_t i);

/* The figures of one finished impact. */
typedef struct {
    double t_onset;   /* time of contact onset [s] */
    double v_onset;   /* striker velocity at onset [m/s] */
    double F_peak;    /* largest force of this impact [N] */
    double eps;       /* restitution coefficient -v_end / v_onset */
    double t_contact; /* duration of the contact [s] */
    double x2_end;    /* permanent indentation when it ended (all impacts so far) [m] */
    double E_diss;    /* energy dissipated during this impact [J] */
} fc_impact;

/* A run's outcome: its first impact and where it stopped. */
typedef struct {
    int status;      /* fc_status of this run */
    int stop;        /* fc_stop */
    int64_t impacts; /* finished impacts */
    int64_t steps;   /* internal steps taken */
    fc_impact first; /* the first finished impact (zeros when none ended) */
    double F_peak;   /* the largest force of the run [N] */
    double eps;      /* of the last finished impact (0 when none) */
    double t_contact;/* of the last finished impact [s] */
    double E_diss;   /* energy dissipated in all [J] */
    double t;        /* where the run stopped [s] */
    double x, x1, x2;/* total, elastic and permanent indentation there [m] */
    double v;        /* striker velocity there [m/s] */
    double k;        /* the spring constant used (given, or derived) [N/m^n] */
} fc_outcome;

/* Columns of a row of the time series. */
enum { FC_T, FC_F, FC_X, FC_X1, FC_X2, FC_V, FC_E_DISS, FC_COLUMNS };

/* A run's results; the library allocates the arrays, fc_result_free frees them. */
typedef struct {
    fc_outcome outcome;
    fc_impact *per_impact; /* every finished impact, in order */
    size_t n_impacts;
    double *rows;          /* n_rows * FC_COLUMNS: t, F, x, x1, x2, v, E_diss (SI) */
    size_t n_rows;
} fc_result;

/* Output spacing for fc_run: no rows, or a row after every internal step,
 * or (any positive value) a row every that many seconds; FC_DEFAULT_ROWS
 * picks fc_default_output_interval(). Rows come also at every onset and
 * separation, and each is the model advanced to its time from a copy of the
 * state: no figure depends on the spacing. */
#define FC_NO_ROWS (-1.0)
#define FC_EVERY_STEP 0.0
#define FC_DEFAULT_ROWS (-2.0)

/* What a run may take: internal steps, and rows of its time series (56 B
 * each). fc_run refuses up front a run that would need more (FC_EINVAL, the
 * message naming dt_max or output_interval), estimated from the least it
 * must cover: to its first onset, then its impacts, each at least the
 * elastic Hertz contact time at the first impact's speed (all of them when
 * g brings the striker back), or until t_end if that comes first; and it
 * stops a time series that outgrows its estimate at FC_ROWS_MAX rows
 * (FC_ENOMEM). */
#define FC_STEPS_MAX 1e9
#define FC_ROWS_MAX 10000000

/* FC_OK, or FC_EINVAL and the message of fc_params_check or of the limits
 * above: what fc_run with this output_interval refuses before it starts. */
FC_API fc_status fc_run_check(const fc_params *p, double output_interval, char *msg, size_t len);

/* 1/256 of the elastic Hertz contact time at the impact speed (about 250
 * rows per contact), or t_end / 1000 in the driven scene without mass. */
FC_API double fc_default_output_interval(const fc_params *p);

/* Called now and then during a run with the time reached, the steps taken
 * and the impacts finished; nonzero asks the run to stop there (FC_ESTOPPED).
 * The calls are spaced by work, not steps (a step of the full G1 history
 * costs in proportion to the steps before it): a fraction of a millisecond
 * to a few tens of milliseconds of CPU apart, whatever the parameters. */
typedef int (*fc_progress)(void *ctx, double t, int64_t steps, int64_t impacts);

/* One run from t = 0 until `impacts` impacts have ended, t_end, or the
 * striker recedes for good: in contact one internal step at a time, free
 * flight in one exact step, as the FMU does. FC_OK, FC_EINVAL (nothing run),
 * FC_EFAIL, FC_ENOMEM (r then holds no rows) or FC_ESTOPPED (the progress
 * callback asked to stop: r holds the run so far), with a message; r is
 * filled in every case (free it). fc_run is fc_run_with_progress without a
 * callback. */
FC_API fc_status fc_run(const fc_params *p, double output_interval, fc_result *r, char *msg, size_t len);
FC_API fc_status fc_run_with_progress(const fc_params *p, double output_interval, fc_progress progress,
                                      void *ctx, fc_result *r, char *msg, size_t len);
FC_API void fc_result_free(fc_result *r);

/* n runs in one call, params[i] -> out[i] (no rows, no per-impact lists):
 * FC_OK when all ran; else the status of the first that did not (its
 * out[i].status says which; fc_params_check tells why). */
FC_API fc_status fc_run_batch(size_t n, const fc_params *params, fc_outcome *out);

/* Called after each case of a batch (done = the cases finished) and as
 * often as fc_progress during a case (done unchanged); nonzero asks the
 * batch to stop. */
typedef int (*fc_batch_progress)(void *ctx, size_t done, size_t n);

/* fc_run_batch with a progress callback: FC_ESTOPPED when it asked to stop
 * (the case it stopped has out[i].status FC_ESTOPPED and its figures so
 * far; the cases after it are not run: zeros, status FC_ESTOPPED). */
FC_API fc_status fc_run_batch_with_progress(size_t n, const fc_params *params, fc_outcome *out,
                                            fc_batch_progress progress, void *ctx);

/* The compressed memory's kernel for the parameters' damper_order,
 * memory_tolerance and dt_max (docs/model.md §6): tau^(-alpha)/Gamma(1-alpha) ~
 * eta delta(tau) + sum_i a_i exp(-b_i tau), the last term the lumped spring
 * (b = 0). Writes up to `max` terms and *eta; returns their number M (more
 * than max: none written), or 0 with a message when the parameters fail
 * their check. */
FC_API size_t fc_memory_kernel(const fc_params *p, size_t max, double *a, double *b, double *eta, char *msg,
                               size_t len);

/* sizeof(fc_params) and sizeof(fc_outcome): a binding checks its layout. */
FC_API size_t fc_params_size(void);
FC_API size_t fc_outcome_size(void);

#ifdef __cplusplus
}
#endif

#endif
