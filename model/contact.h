/* The rheological contact model of docs/model.md §2, §4 and §5: a striker pushing
 * on a spring k x1^n in series with a damper, a linear dashpot or a springpot
 * c_alpha D^alpha x2 whose memory is kept either as the literal G1 history or
 * as a sum of exponentials (soe.h). Knows nothing of FMI; the FMU and the
 * solver both drive it through this interface. C99, libc and libm. */
#ifndef FRACCONTACT_CONTACT_H
#define FRACCONTACT_CONTACT_H

#include <stddef.h>
#include <stdint.h>

enum contact_law {
    CONTACT_LAW_G1 = 1,              /* G1 history sum of D^(-1/2) x1, times Gamma(5/2) k */
    CONTACT_LAW_HERTZ = 2,           /* closed form k x1^(3/2) */
    CONTACT_LAW_G1_EXTRAPOLATED = 3  /* G1 with Richardson extrapolation: second order in 1/N */
};

enum contact_scheme {
    CONTACT_SCHEME_GRADIENT = 1, /* the implicit discrete gradient: never creates energy, second order, events located (default) */
    CONTACT_SCHEME_CENTRAL = 2  /* the paper's explicit central differences (docs/model.md §15) */
};

/* Events at which contact_advance_until can stop, as bits. */
enum contact_event {
    CONTACT_ONSET = 1,       /* the striker meets the specimen */
    CONTACT_SEPARATION = 2,  /* the force returns to zero: an impact has ended */
    /* Out of contact a recovering springpot's flight is one advance of many
     * steps: stop after each of them (for a caller that retraces them). */
    CONTACT_FLIGHT_STEP = 4
};

/* Called, when set, at every CONTACT_POLL_STEPS-th internal step (counted
 * in s.steps) of such a flight, for a caller that must hear from a long
 * advance: nonzero stops the advance there. */
typedef int (*contact_poll)(void *ctx);
#define CONTACT_POLL_STEPS 4096

enum contact_damper {
    CONTACT_DAMPER_DASHPOT = 1,  /* F = c x2' */
    CONTACT_DAMPER_SPRINGPOT = 2 /* F = c_alpha D^alpha x2 (Caputo from t = 0), docs/model.md §5 */
};

enum contact_memory {
    CONTACT_MEMORY_G1 = 1,        /* the springpot's literal G1 history sum: uniform steps, O(N) each */
    CONTACT_MEMORY_COMPRESSED = 2 /* a sum of exponentials: M modes, any step (docs/model.md §6) */
};

/* The compressed memory's largest number of modes, and the span over which
 * its kernel holds the tolerance: from dt_max to CONTACT_MEMORY_SPAN, or
 * with error-controlled steps (which go far below dt_max) from the smaller
 * of dt_max and CONTACT_MEMORY_FLOOR (parameters.c says why that floor). */
#define CONTACT_MAX_MODES 160
#define CONTACT_MEMORY_SPAN 1e3
#define CONTACT_MEMORY_FLOOR 1e-9
/* The smallest springpot order the compressed memory takes: its kernel's
 * bounds (soe.c) are checked from here to 1 (test_springpot); towards 0 the
 * kernel's terms lose their accuracy and the full G1 memory serves. */
#define CONTACT_MEMORY_MIN_ORDER 1e-3

/* The fixed step of dt_max = 0, the default: the paper's h20 step [s]. */
#define CONTACT_DEFAULT_STEP 1e-7

/* A fixed step resolves an impact when at least this many of them fit in
 * the time the spring takes to stop the striker (resolution.c,
 * turnaround_time); a contact that dt_max does not resolve is stepped at
 * CONTACT_REFINED steps in that time instead: about the resolution the
 * default step gives the paper's h20 impact. */
#define CONTACT_RESOLUTION 6
#define CONTACT_REFINED 4000

/* The full G1 history keeps x2 at every step of the run: at most this many
 * steps (8 MiB of history, and as much for the G1 weights). */
#define CONTACT_G1_HISTORY_MAX 1048576

/* A step of the full G1 history sums over every step before it: it costs
 * about one unit of work (an internal step of the compressed memory, the
 * dearest step but this one) more per this many of them. */
#define CONTACT_HISTORY_PER_UNIT 64

/* The method a configuration runs, each in a file named for it: decided by
 * contact_method alone, and named by contact_method_name. */
enum contact_method {
    CONTACT_METHOD_GRADIENT = 1,   /* fixed steps: the discrete gradient (gradient.c) */
    CONTACT_METHOD_ESDIRK54 = 2,   /* error-controlled steps of the dashpot, tolerance > 0: ESDIRK 5(4) (esdirk54.c) */
    CONTACT_METHOD_G1_HISTORY = 3, /* the springpot's full G1 history, BDF2 on a uniform grid (g1_history.c) */
    CONTACT_METHOD_CENTRAL = 4,    /* the paper's central differences on a uniform grid (central.c) */
    CONTACT_METHOD_RADAU_IIA = 5   /* error-controlled steps of the compressed springpot: Radau IIA (radau_iia.c) */
};

/* A method's record (contact_internal.h), one at the end of its file. */
typedef struct contact_method_record contact_method_record;

enum contact_scene {
    CONTACT_SCENE_DROP = 1,   /* the model owns a free striker */
    CONTACT_SCENE_DRIVEN = 2  /* the caller prescribes the indentation rate */
};

/* The C type of a table row's type (parameters.def). */
#define CONTACT_TYPE_Real double
#define CONTACT_TYPE_Integer int
#define CONTACT_TYPE(type) CONTACT_TYPE_##type

/* The model's parameters, a member each (parameters.def says what each
 * is): the rows of MODEL, the enumerations' codes those of the enums above;
 * dt_max = 0 means fixed steps of CONTACT_DEFAULT_STEP and no cap on
 * error-controlled steps (contact_step_limit). */
typedef struct {
#define PARAMETER_MODEL_FMU_LIBRARY(name, type, ...) CONTACT_TYPE(type) name;
#define PARAMETER_MODEL_LIBRARY(name, type, ...) CONTACT_TYPE(type) name;
#include "parameters.def"
} contact_params;

typedef struct {
    double t;         /* time [s] */
    double x1;        /* x - x2: the elastic (Hertz) indentation while >= 0,
                         minus the gap to the dented surface while < 0 [m] */
    double x2;        /* the damper's travel: the dent [m] */
    double v;         /* striker velocity towards the specimen [m/s] */
    double F;         /* contact force at the end of the last internal step [N] */
    double F_peak;    /* largest contact force so far [N] */
    double F_peak_contact; /* largest force of the current (or last) contact [N] */
    double E_diss;    /* work done on the damper so far, the integral of F dx2 [J] */
    double eps;       /* restitution coefficient of the last finished impact */
    double v_onset;   /* striker velocity at the onset of the current contact */
    double t_onset;   /* time of the onset of the current (or last) contact [s] */
    double t_contact; /* duration of the last finished impact [s] */
    int64_t n;        /* internal steps since the onset of the current contact */
    int64_t steps;    /* internal steps taken */
    double x_prev;    /* central differences and the full G1 history's BDF2: */
    double h_prev;    /* total indentation one step back, and that step (0: restart) */
    int64_t impacts;  /* finished impacts */
    double h_next;    /* the error control's next step (tolerance > 0; 0: none yet) */
    int in_contact;
    double x2_rate;   /* the damper's rate x2' at the end of the last internal step (the springpot's memory
                         saves it, not the list below) [m/s] */
    /* Not part of the state carried from step to step (so not listed
     * below, and not copied from one state to the next: the fields above
     * are, contact_internal.h's carry_state): what a trial step leaves for
     * accepting it, its length and the damper's rate x2' at its stages
     * before the last (x2_rate is the end's), and an error-controlled
     * step's error over the tolerance: a fixed step's mean rate in x2_rate1
     * (x2_rate its end's), a springpot's Radau IIA step's five in x2_rate1,
     * x2_rate_inner and x2_rate, and its elastic indentations at the first
     * four stages (x1 is the fifth's) for its dense output. */
    double step, x2_rate1, error;
    double x2_rate_inner[3], x1_inner[4];
} contact_state;

/* Every field of contact_state carried from step to step, described once: DOUBLE(name) for the doubles,
 * INT64(name) for the counters, INT(name) for the flag. The model's check that
 * a step kept the state finite and whoever saves a state field by field
 * expand it, so that a new field reaches both or neither. */
#define CONTACT_STATE_FIELDS(DOUBLE, INT64, INT)                                                          \
    DOUBLE(t) DOUBLE(x1) DOUBLE(x2) DOUBLE(v) DOUBLE(F) DOUBLE(F_peak) DOUBLE(F_peak_contact) DOUBLE(E_diss) \
    DOUBLE(eps) DOUBLE(v_onset) DOUBLE(t_onset) DOUBLE(t_contact) DOUBLE(x_prev) DOUBLE(h_prev)            \
    INT64(n) INT64(steps) INT64(impacts) DOUBLE(h_next) INT(in_contact)

/* The compressed memory (a springpot with memory = 2): the kernel's modes,
 * their state, and the coefficients of one step length, in arrays of
 * `room` values each (the modes padded to whole lanes) that share one block
 * the model owns: allocated when a run is configured, none for the other
 * dampers and memories (contact_release frees it). */
typedef struct {
    size_t modes;                 /* M, the last one the lumped spring (b = 0) */
    size_t room;                  /* the arrays' length (0: no block): the arrays below are one block */
    double eta;                   /* the lumped dashpot */
    double *a, *b;                /* a: the block's start */
    double *phi;                  /* the modes' state: the Maxwell springs' stretch [m] */
    double h;                     /* the step length of the coefficients below (0: none yet) */
    double sum_q, sum_rate;       /* sum_i of the mean pull's viscous part, and of a_i rate_i */
    double *p, *q;                /* a mu d, the mean pull's (gradient.c); a keep, the springs' after the step */
    double *keep, *rate;          /* the update */
    double radau_h; /* the step length of radau_d (0: none yet) */
    double *radau_d; /* Radau IIA's 1/(1 + h b lambda_l), five arrays (RADAU_RECIPROCAL): lambda_0's, the pairs' re, -im */
} contact_modes; /* a new field: copy it in contact_copy too */

/* The full G1 history (a springpot with memory = 1): x2 at every step since
 * t = 0 and the G1 weights, grown geometrically. */
typedef struct {
    double *x2, *w;
    size_t capacity;  /* of both */
    size_t weights;   /* w[0..weights-1] hold the weights of order w_alpha */
    double w_alpha;
    double v_prev;    /* BDF2's second value back: v one step back (x_prev of the state holds x) */
    double G_prev;    /* h^alpha times the G1 value of D^alpha x2 one step back */
} contact_history;

typedef struct {
    contact_params p;
    double k;         /* the spring constant in use (given, or derived) */
    double n_gamma;   /* Gamma(n + 1): x1^n = Gamma(n + 1) D^(-(n-1)) x1 */
    double inv_c;     /* 1/c */
    double k_fixed;   /* the spring's stiffness when it does not change with the step count */
    double inv_m;     /* 1/m of the striker the model moves; 0: velocity prescribed */
    double accel;     /* the striker's acceleration apart from the contact force */
    const contact_method_record *method; /* the record of contact_method(&p) */
    double series_limit;    /* an implicit stage's root is its series while (beta^2 r) is below this (stage_root):
                               its error, 20 u^7, is then within 1e-3 of the tolerance; 0: to rounding */
    double peak_force_seen, peak_length; /* error control's cache: a force and its elastic indentation */
    contact_poll poll;        /* NULL (contact_start), or the caller's */
    void *poll_ctx;
    contact_state s;
    double h_max;           /* contact_step_limit(&p) */
    double contact_step;    /* the fixed step in the current contact: h_max, or shorter to resolve it */
    int64_t max_steps;      /* the most internal steps one advance may take; 0: no limit */
    int exceeded;           /* set by an advance that fails: whether it stopped at max_steps */
    float viscous_share;    /* for the step length modes.h (gradient.c's blend): the viscous part of the
                               springpot's step resistance; a float, in the padding before modes, so that the
                               model keeps its size */
    contact_modes modes;      /* a springpot's compressed memory (owned: contact_release) */
    contact_history history;  /* a springpot's full G1 history (owned: contact_release) */
} contact_model;

/* The energy account of a proxy striker's coupling (passivity.c, docs/model.md
 * §17), over the intervals of the communication steps: from the bodies'
 * approach speed u and acceleration a apart from the contact (g + a - a2)
 * at each interval's ends, the force F they take over it, and the proxy's
 * motion over it, the energy the coupling creates and does not return when
 * the contact's force does. */
typedef struct {
    double created;      /* over the closed intervals [J]; > 0: energy created */
    double rounding;     /* the sizes of the terms the account added [J] (ACCOUNT_ROUNDING of it is rounding) */
    double H, u, a;      /* the open interval: its length, the bodies' u and a at its start */
    double a_rate;       /* a's rate over the last closed interval (0 before one) */
    double a_unseen;     /* the bodies' mean acceleration over it that neither a nor F explains: a force
                            the inputs do not show (0 where a holds all the other forces) */
    double F;            /* the force the bodies take over the open interval [N] */
    double u0, u1;       /* the proxy's velocity at its start and end, any impulse owed to the bodies included */
    double F_end;        /* the proxy's contact force at its end [N] */
    double dx;           /* the proxy's own displacement over it [m] */
    double scale;        /* the size of its terms [J] */
    double lag;          /* over the closed intervals since the contact began: the proxy's own work less
                            what `created` counted of it, energy the contact holds until it ends [J] */
    int open;            /* an interval whose end the next inputs tell */
    int ends_free;       /* the proxy is out of contact at its end */
} coupling_energy;

/* Opens an interval of length H from the bodies' u and a under the force
 * F; the proxy's motion over it, from *from to *to of the model *cm with
 * the impulse J, w0 and w1 the velocities the impulse owed to the bodies
 * at its start and end gives them (0 but under Jacobi); closes it from the
 * bodies' u and a at its end, adding what it created and taking a's rate
 * and the unseen acceleration (nothing when none is open). */
void coupling_energy_open(coupling_energy *e, double H, double u, double a, double F);
void coupling_energy_proxy(coupling_energy *e, const contact_model *cm, const contact_state *from,
                           const contact_state *to, double J, double w0, double w1);
void coupling_energy_close(coupling_energy *e, double m, double u, double a);

/* The proxy restarted from the bodies' velocity, dv from where its last
 * interval ended, with the impulse `owed` not yet given to them: the
 * energy that moves between the proxy and the bodies (0 under
 * Gauss-Seidel, which owes nothing). */
void coupling_energy_restart(coupling_energy *e, double owed, double dv);

/* The account with the open interval closed where the bodies are predicted
 * to end it (from its start, a, a's rate and the acceleration the inputs
 * did not show), u and a that end's. */
coupling_energy coupling_energy_predicted(const coupling_energy *e, double m);

/* The change to the force F held over the open interval that brings the
 * energy created, with the interval's own, to 0 where it is > 0 beyond
 * the account's rounding: only ever taking more energy from the bodies; 0
 * otherwise. On bodies that separate it pulls: a force >= 0 could only
 * give them more. */
double coupling_energy_correction(const coupling_energy *e, double m);

/* The paper's h20 test (docs/model.md §1): the parameters, and the
 * striker's impact velocity v [m/s] and mass m [kg]. */
void contact_default_params(contact_params *p);
void contact_default_striker(double *v, double *m);

/* k = (4/3) E* sqrt(R), 1/E* = (1 - nu_i^2)/E_i + (1 - nu_s^2)/E_s. */
double hertz_constant(double R, double E_i, double nu_i, double E_s, double nu_s);

/* 0 when every parameter is usable; otherwise -1 and a message naming the
 * first offending parameter and its value. */
int contact_check_params(const contact_params *p, char *msg, size_t len);

/* Writes "name = value is invalid: rule" (the value as a user would type it)
 * and returns -1: every check's message. */
int contact_reject(char *msg, size_t len, const char *name, double value, const char *rule);

/* A warning for a value without effect: k != 0 given while a material
 * parameter (R, E_i, nu_i, E_s, nu_s) differs from its default (k wins), or
 * a damper's parameter changed while the other damper is selected (c with
 * the springpot; damper_order, c_alpha, memory, memory_tolerance with the
 * dashpot; memory_tolerance with the full G1 history), or tolerance > 0
 * where steps stay fixed (the G1 laws with g1_nodes = 0, the central
 * scheme, the springpot's full G1 history). Returns 1 and the
 * message naming such parameters, or 0. */
int contact_unused_value(const contact_params *p, char *msg, size_t len);

/* The method these parameters run (docs/model.md §16), and its name:
 * "gradient", "esdirk54", "radau_iia", "g1_history" or "central". */
enum contact_method contact_method(const contact_params *p);
const char *contact_method_name(enum contact_method method);

/* 1 when the model chooses its steps by p->tolerance (tolerance > 0 where
 * it applies), 0 when it takes fixed steps of dt_max. */
int contact_error_controlled(const contact_params *p);

/* The largest internal step of these parameters [s]: dt_max; for dt_max = 0
 * the fixed step CONTACT_DEFAULT_STEP, or INFINITY (no cap) where the steps
 * are error-controlled. Fixed steps are of this length (shorter only to
 * land on an interval's end or to resolve a contact, contact_advance). */
double contact_step_limit(const contact_params *p);

/* The fewest internal steps a run or an advance of `span` seconds takes
 * that spends at least `in_contact` of them in contact: steps of at most
 * contact_step_limit over the whole span on a uniform grid, over the
 * contact otherwise (free flight is one step). What a caller refuses
 * before the first step; INFINITY or NaN never pass a limit. */
double contact_least_steps(const contact_params *p, double span, double in_contact);

/* The work of the full G1 history's steps after the before-th up to the
 * after-th, in units of one internal step: each costs
 * 1 + after / CONTACT_HISTORY_PER_UNIT (whole units, as the counts are). */
double contact_history_work(double before, double after);

/* The same for the striker inputs, velocity v [m/s] and mass m [kg], in
 * `scene` with the parameters *p (which must have passed their check): a
 * run must also be able to hold its energies and powers in doubles. */
int contact_check_striker(const contact_params *p, int scene, double v, double m, char *msg, size_t len);

/* The mass of the model's striker between a striker of mass m and a second
 * body of mass m2: the reduced mass m m2/(m + m2) of two free bodies, m
 * where the second is held (m2 = 0) or the rate is prescribed (m = 0). */
double contact_reduced_mass(double m, double m2);

/* contact_check_striker for a striker (v, m) and a second body (v2, m2):
 * each body's own rules (v2 finite; m2 = 0, or positive, finite and not
 * denormal), and the striker's rules for their relative motion, the
 * approach speed v - v2 and the reduced mass (docs/two_bodies.md). */
int contact_check_bodies(const contact_params *p, int scene, double v, double m, double v2, double m2, char *msg,
                         size_t len);

/* Whether a free flight from x1 (< 0: the gap) at the speed v under the
 * acceleration a (towards the specimen) ever makes x1 > 0: a > 0, or v > 0
 * and no deceleration turns it back within the gap. */
int contact_flight_arrives(double x1, double v, double a);

/* A warning where the drop test's striker, at the approach speed v, never
 * reaches the specimen from the gap gap0 under g (docs/model.md §9): 1 and
 * the message naming v, g and gap0, or 0. */
int contact_arrival_warning(const contact_params *p, double v, char *msg, size_t len);

/* Whether the uniform grids (the central scheme, the full G1 history),
 * whose steps cannot shorten in contact, resolve the first impact of a
 * striker of mass m starting at v (the fastest: CONTACT_RESOLUTION steps
 * while the spring stops the striker), and whether the fixed steps that are
 * refined in contact instead can stop it (their first indentation and force
 * normal numbers); and that a dashpot's force c v at the arrival speed is
 * one the spring can carry (c v / k a normal double). 0, or -1 and a
 * message naming dt_max (or m and v, or c), the values and the rule. */
int contact_check_resolution(const contact_params *p, double v, double m, char *msg, size_t len);

/* A warning where fixed steps of dt_max do not resolve that impact and are
 * refined in contact (contact_advance): 1 and the message, or 0. */
int contact_step_warning(const contact_params *p, double v, double m, char *msg, size_t len);

/* Takes the parameters and the constants derived from them (k, 1/c, a fixed
 * stiffness, the compressed memory's kernel, the fixed step of a contact in
 * progress: from the state, inv_m and accel, which must be set), leaving
 * the state and the memory's values alone: for a state restored from
 * elsewhere. The compressed memory's block stays where it holds the
 * kernel's modes; a larger one replaces it. 0, or -1 when memory for the
 * modes runs out (the model as it was). */
int contact_configure(contact_model *cm, const contact_params *p);

/* Starts at t = 0 with the striker at the gap gap0 moving at v0 (towards the
 * specimen). Parameters and striker must have passed the checks above. The
 * model is overwritten: release one that holds memory first. 0, or -1 when
 * memory for the compressed memory's modes runs out (nothing to release). */
int contact_start(contact_model *cm, const contact_params *p, double v0, double m);

/* A compressed memory's kernel and what it was built for (soe.h), kept by a
 * caller that starts many models alike, as a batch of runs does: building
 * it costs more than a dashpot's whole impact. */
typedef struct {
    double damper_order, memory_tolerance, floor; /* floor 0: none yet */
    size_t modes;
    double eta, a[CONTACT_MAX_MODES], b[CONTACT_MAX_MODES];
} contact_kernel;

/* contact_start, taking the kernel from *kernel when it was built for the
 * same damper_order, memory_tolerance and kernel floor (the same bits as
 * building it), and keeping the one it builds there otherwise. */
int contact_start_with(contact_model *cm, const contact_params *p, double v0, double m, contact_kernel *kernel);

/* Frees the memory a model allocates: the compressed memory's block and the
 * full G1 history's buffer; the model may start again. A model copied by
 * contact_copy shares the history's buffer: never advance both. */
void contact_release(contact_model *cm);

/* Frees the compressed memory's block alone: for a copy, whose G1 history
 * is its original's. */
void contact_release_modes(contact_model *cm);

/* Makes *to (released, or zeroed) hold a copy of *from: its own block as
 * large as from's modes, allocated here, not by contact_copy. 0, or -1 when
 * memory for them runs out (to as it was). */
int contact_copy_room(contact_model *to, const contact_model *from);

/* *to = *from into to's own block (contact_copy_room first), the compressed
 * memory's arrays only as far as they hold modes: for a caller that copies
 * a model at every step. The G1 history's buffer is shared. */
void contact_copy(contact_model *to, const contact_model *from);

/* The bytes a model holds: the struct and what it allocated. */
size_t contact_model_bytes(const contact_model *cm);

/* The springpot's memory beside the state, as `count` values for saving and
 * restoring it: the damper's rate x2' first, then the compressed modes'
 * stretches (memory = 2), or BDF2's v one step back, the last G1 sum and
 * x2 at every step since t = 0 (memory = 1, oldest first); none for the
 * dashpot. To restore: the parameters and the state
 * first (contact_configure), then contact_memory_accepts (the count fits
 * them? 0, or -1 and a message), contact_memory_resize (room for the
 * values; -1 when memory runs out, the model unchanged otherwise), and the
 * values by contact_memory_set. */
size_t contact_memory_count(const contact_model *cm);
double contact_memory_get(const contact_model *cm, size_t i);
int contact_memory_accepts(const contact_model *cm, size_t count, char *msg, size_t len);
int contact_memory_resize(contact_model *cm, size_t count);
void contact_memory_set(contact_model *cm, size_t i, double value);

/* Whether an advance by H is possible from here: the full G1 history steps on
 * the grid of dt_max (H a whole multiple of it, to 1e-9) and holds at most
 * CONTACT_G1_HISTORY_MAX steps. 0, or -1 and a message. */
int contact_check_advance(const contact_model *cm, double H, char *msg, size_t len);

/* Whether an advance by H from here takes at most max_steps internal steps
 * by contact_least_steps, with the least time in contact known from the
 * state: from the free flight's onset inside the advance, or from now in
 * contact, until a striker with inertia can have turned back or a
 * prescribed rate reverses (none where nothing bounds it); for the full G1
 * history the work of its steps (contact_history_work) instead; and that
 * refined fixed steps in the coming contact advance the clock and can stop
 * the striker (contact_check_resolution). 0, or -1 and a message naming
 * dt_max, memory or m and v, the values and the rule. */
int contact_check_work(const contact_model *cm, double H, double max_steps, char *msg, size_t len);

/* Whether the full G1 history (memory = 1) holds a run from the start that
 * may go on for `span` [s], named `name` (t_end, stopTime) in the message:
 * at most CONTACT_G1_HISTORY_MAX steps of dt_max. With
 * until_first_separation the run stops at its first separation (a
 * striker of mass m > 0 starting at v): only its flight to the specimen
 * must fit then. 0 (also for the other memories), or -1 and a message. */
int contact_check_history_span(const contact_params *p, double v, double m, double span, int until_first_separation,
                               const char *name, char *msg, size_t len);

/* Whether a model of these parameters steps on a uniform grid of dt_max whatever happens (the
 * central scheme, the full G1 history): a caller advancing step by step
 * should then advance by dt_max. */
int contact_steps_uniformly(const contact_params *p);

/* Driven scene: the indentation rate v from now on; m > 0 lets the model move
 * the striker with that inertia until the next call (a proxy striker), under
 * g + accel besides the contact force (accel: what the caller's other forces
 * give the striker, relative to the specimen), m = 0 prescribes the rate:
 * v + accel (t - now) (accel 0: v held). The drop test ignores the call: its
 * striker is the model's own. */
void contact_drive(contact_model *cm, double v, double m, double accel);

/* The state's rates now: x1' (0 out of contact), v', and the spring force's
 * F' = n K x1^(n-1) x1' at the current stiffness. */
void contact_rates(const contact_model *cm, double *x1_rate, double *v_rate, double *F_rate);

/* The damper's rate x2' now: F/c for the dashpot, the springpot's from its
 * memory (negative while the dent recovers). */
double contact_damper_rate(const contact_model *cm);

/* The dent x2 where the last contact ended, right after the advance that
 * ended it: a uniform grid ends a contact at the step after its separation,
 * and takes x2 back to the separation (the full G1 history continues it
 * from the contact's side, g1_history.c; the others along x2's rate). */
double contact_x2_end(const contact_model *cm);

/* Advances the model by H >= 0 to exactly t + H by the method of
 * contact_method. Out of contact free flight is one exact step (while a
 * springpot recovers, steps growing with the time since separation). In
 * contact the discrete gradient takes equal steps of at most contact_step_limit (shorter
 * where that would not resolve the impact: CONTACT_REFINED), ESDIRK 5(4)
 * the steps its controller chooses for the tolerance, at most
 * contact_step_limit; both locate contact onset and separation within a
 * step. The uniform grids step throughout: central differences in equal
 * steps of at most dt_max, the full G1 history in steps of dt_max
 * (contact_check_advance first); onset and separation fall on their steps.
 * Returns the impulse of the contact force
 * over the interval [N s]; on a numerical failure (a non-finite state)
 * returns NaN and leaves the state as it was at the start of the advance;
 * the same when it would take more than cm->max_steps internal steps
 * (cm->exceeded, set by a failed advance, says which). */
double contact_advance(contact_model *cm, double H);

/* The same, but it stops right after the first event of the mask stop_at
 * (enum contact_event bits) inside the interval: cm->s.t then tells where. */
double contact_advance_until(contact_model *cm, double H, unsigned stop_at);

/* Whether the striker is out of contact and its free flight never reaches
 * the specimen again (it moves away, or rests, and nothing accelerates it
 * back; a recovering springpot's dent, x2 >= 0, only when the striker is
 * clear of the undeformed surface): nothing it feels changes from then on. */
int contact_never_returns(const contact_model *cm);

/* Whether the striker has come to rest in contact for good: nothing loads
 * it (no acceleration apart from the contact force), the damper is the
 * dashpot (a springpot's memory would still move it), and the force and the
 * striker's speed have fallen below the rounding of the contact's peak
 * force and onset speed. An overdamped contact creeps to rest this way and
 * never separates; nothing it reports changes any more. */
int contact_rests(const contact_model *cm);

/* Outputs derived from the state. */
double contact_elastic_indentation(const contact_model *cm);  /* x1 >= 0 */
double contact_total_indentation(const contact_model *cm);    /* x = x1 + x2 */
double contact_semi_integral(const contact_model *cm);        /* the D^(-(n-1)) x1 used for F */
double contact_semi_integral_per_force(const contact_model *cm); /* 1/(Gamma(n+1) k): F to it */

/* The spring's stiffness K, its force being K x1^n: k for the Hertz law,
 * k Gamma(N+n)/(Gamma(N) N^n) for the G1 law on N intervals (docs/model.md §4)
 * with N = g1_nodes, or n_steps (internal steps since onset) when that is 0;
 * the extrapolated G1 law replaces that ratio by g1_line_ratio_extrapolated. */
double contact_spring_stiffness(const contact_model *cm, long n_steps);

/* Model Exchange (rates.c, docs/model_exchange.md): the model as an ODE
 * that a host's solver integrates, for the closed-form force (law 2) with
 * the dashpot or the compressed springpot. The states, in this order: the
 * total indentation x = x1 + x2 (its rate v), the approach speed v (its
 * rate g + a - F/m in the drop test; in the driven scene unused, rate 0:
 * the rate of x is the input, contact_drive), the damper's travel x2, the
 * work on the damper E_diss, then CONTACT_MAX_MODES slots of the
 * springpot's modes (those beyond its kernel's, and all of a dashpot's,
 * stay 0 at rate 0). */
enum { CONTACT_ME_X, CONTACT_ME_V, CONTACT_ME_X2, CONTACT_ME_E_DISS, CONTACT_ME_MODES };
#define CONTACT_ME_STATES (CONTACT_ME_MODES + CONTACT_MAX_MODES)

/* Event indicators: x1 (onset as it rises through 0, separation as it
 * falls), and in contact the indentation's rate x1' (the force's peak as it
 * falls through 0). */
#define CONTACT_ME_INDICATORS 2

/* Whether these parameters run in Model Exchange: law 2, the compressed
 * memory, scheme 1. 0, or -1 and a message naming the parameter, its value
 * and what to take instead. */
int contact_me_check(const contact_params *p, char *msg, size_t len);

/* The states into the model (the force and the damper's rate follow from
 * them: 0, or -1 and the model as it was where those or the damper's power
 * would not be finite) and out of it, CONTACT_ME_STATES values each. */
int contact_me_set_states(contact_model *cm, const double *x);
void contact_me_get_states(const contact_model *cm, double *x);

/* The states' rates at the model's state. */
void contact_me_derivatives(const contact_model *cm, double *dx);

/* The derivatives' change for a change dx of the states and, in the driven
 * scene, dv of the input approach speed v - v2 (the Jacobian times them, in
 * closed form): CONTACT_ME_STATES values each. */
void contact_me_directional(const contact_model *cm, const double *dx, double dv, double *df);

/* The states' nominal values for a striker of mass m (0: the rate
 * prescribed) meeting the specimen at the approach speed v0: the impact's
 * indentation scale for the lengths, the speed, the kinetic energy. */
void contact_me_nominals(const contact_model *cm, double v0, double m, double *nominal);

/* The CONTACT_ME_INDICATORS event indicators at the model's state. */
void contact_me_indicators(const contact_model *cm, double *z);

/* At an event at the model's time: the contact begun or ended where the
 * state says so (the impact's figures eps, t_contact at its end), the peak
 * forces taken. The event's bit (enum contact_event), or 0. */
int contact_me_event(contact_model *cm);

/* At a state the host accepted (and at an event): the peak forces taken. */
void contact_me_accept(contact_model *cm);

#endif
