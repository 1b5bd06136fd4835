/* The rheological contact model of MODEL.md §2 and §4: a striker pushing on a
 * Hertz spring in series with a linear dashpot. Knows nothing of FMI; the FMU
 * and the solver both drive it through this interface. C99, libc and libm. */
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
    CONTACT_SCHEME_SDIRK2 = 1,  /* L-stable implicit, second order, events located (default) */
    CONTACT_SCHEME_CENTRAL = 2  /* the paper's explicit central differences (MODEL.md §5) */
};

/* Events at which contact_advance_until can stop, as bits. */
enum contact_event {
    CONTACT_ONSET = 1,      /* the striker meets the specimen */
    CONTACT_SEPARATION = 2  /* the force returns to zero: an impact has ended */
};

enum contact_scene {
    CONTACT_SCENE_DROP = 1,   /* the model owns a free striker */
    CONTACT_SCENE_DRIVEN = 2  /* the caller prescribes the indentation rate */
};

typedef struct {
    double R;            /* striker tip radius [m] */
    double E_i, nu_i;    /* indenter Young's modulus [Pa] and Poisson ratio */
    double E_s, nu_s;    /* specimen Young's modulus [Pa] and Poisson ratio */
    double k;            /* Hertz constant [N/m^1.5]; 0: derive from the above */
    double c;            /* dashpot constant [N s/m] */
    double dt_max;       /* largest internal step [s] */
    double g;            /* acceleration of the model's striker towards the specimen [m/s^2] */
    double gap0;         /* gap between striker and specimen at the start [m] */
    int law;             /* enum contact_law */
    int g1_nodes;        /* G1 intervals N; 0: internal steps since contact onset */
    int scene;           /* enum contact_scene */
    int scheme;          /* enum contact_scheme */
} contact_params;

typedef struct {
    double t;         /* time [s] */
    double x1;        /* x - x2: the elastic (Hertz) indentation while >= 0,
                         minus the gap to the dented surface while < 0 [m] */
    double x2;        /* permanent indentation, the dashpot's travel [m] */
    double v;         /* striker velocity towards the specimen [m/s] */
    double F;         /* contact force at the end of the last internal step [N] */
    double F_peak;    /* largest contact force so far [N] */
    double F_peak_contact; /* largest force of the current (or last) contact [N] */
    double E_diss;    /* energy dissipated by the dashpot so far [J] */
    double eps;       /* restitution coefficient of the last finished impact */
    double v_onset;   /* striker velocity at the onset of the current contact */
    double t_onset;   /* time of the onset of the current (or last) contact [s] */
    double t_contact; /* duration of the last finished impact [s] */
    int64_t n;        /* internal steps since the onset of the current contact */
    int64_t steps;    /* internal steps taken */
    double x_prev;    /* central differences: total indentation one step back, */
    double h_prev;    /* and that step (0: not yet known) */
    int64_t impacts;  /* finished impacts */
    int in_contact;
} contact_state;

/* Every field of contact_state, described once: DOUBLE(name) for the doubles,
 * INT64(name) for the counters, INT(name) for the flag. The model's check that
 * a step kept the state finite and whoever saves a state field by field
 * expand it, so that a new field reaches both or neither. */
#define CONTACT_STATE_FIELDS(DOUBLE, INT64, INT)                                                          \
    DOUBLE(t) DOUBLE(x1) DOUBLE(x2) DOUBLE(v) DOUBLE(F) DOUBLE(F_peak) DOUBLE(F_peak_contact) DOUBLE(E_diss) \
    DOUBLE(eps) DOUBLE(v_onset) DOUBLE(t_onset) DOUBLE(t_contact) DOUBLE(x_prev) DOUBLE(h_prev)            \
    INT64(n) INT64(steps) INT64(impacts) INT(in_contact)

typedef struct {
    contact_params p;
    double k;         /* the Hertz constant in use (given, or derived) */
    double inv_c;     /* 1/c */
    double k_fixed;   /* the spring's stiffness when it does not change with the step count */
    double inv_m;     /* 1/m of the striker the model moves; 0: velocity prescribed */
    double accel;     /* the striker's acceleration apart from the contact force */
    contact_state s;
} contact_model;

/* The paper's h20 test (MODEL.md §6, DESIGN.md): the parameters, and the
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

/* A warning when k != 0 is given while a material parameter (R, E_i, nu_i,
 * E_s, nu_s) differs from its default: k wins, and that value has no effect.
 * Returns 1 and the message naming the first such parameter, or 0. */
int contact_unused_material(const contact_params *p, char *msg, size_t len);

/* The same for the striker inputs, velocity v [m/s] and mass m [kg], in
 * `scene` with the parameters *p (which must have passed their check): a
 * run must also be able to hold its energies and powers in doubles. */
int contact_check_striker(const contact_params *p, int scene, double v, double m, char *msg, size_t len);

/* Takes the parameters and the constants derived from them (k, 1/c, a fixed
 * stiffness), leaving the state alone: for a state restored from elsewhere. */
void contact_configure(contact_model *cm, const contact_params *p);

/* Starts at t = 0 with the striker at the gap gap0 moving at v0 (towards the
 * specimen). Parameters and striker must have passed the checks above. */
void contact_start(contact_model *cm, const contact_params *p, double v0, double m);

/* Driven scene: the indentation rate v from now on; m > 0 lets the model move
 * the striker with that inertia until the next call (a proxy striker), m = 0
 * prescribes the rate: v + slope (t - now) (slope 0: v held). The drop test
 * ignores the call: its striker is the model's own. */
void contact_drive(contact_model *cm, double v, double m, double slope);

/* The state's rates now: x1' (0 out of contact), v', and the spring force's
 * F' = 1.5 K sqrt(x1) x1' at the current stiffness. */
void contact_rates(const contact_model *cm, double *x1_rate, double *v_rate, double *F_rate);

/* Advances the model by H >= 0 in equal internal steps of at most dt_max that
 * land exactly on t + H, locating contact onset and separation within a step;
 * free flight is one exact step. Returns the impulse of the contact force
 * over the interval [N s]; on a numerical failure (a non-finite state)
 * returns NaN and leaves the state as it was at the start of the advance. */
double contact_advance(contact_model *cm, double H);

/* The same, but it stops right after the first event of the mask stop_at
 * (enum contact_event bits) inside the interval: cm->s.t then tells where. */
double contact_advance_until(contact_model *cm, double H, unsigned stop_at);

/* Whether the striker is out of contact and its free flight never reaches
 * the specimen again (it moves away, or rests, and nothing accelerates it
 * back): nothing changes from then on. */
int contact_never_returns(const contact_model *cm);

/* Outputs derived from the state. */
double contact_elastic_indentation(const contact_model *cm);  /* x1 >= 0 */
double contact_total_indentation(const contact_model *cm);    /* x = x1 + x2 */
double contact_semi_integral(const contact_model *cm);        /* the D^(-1/2) x1 used for F */
double contact_semi_integral_per_force(const contact_model *cm); /* 1/(Gamma(5/2) k): F to it */

/* The spring's stiffness K, its force being K x1^(3/2): k for the Hertz law,
 * k Gamma(N+3/2)/(Gamma(N) N^(3/2)) for the G1 law on N intervals (MODEL.md §4)
 * with N = g1_nodes, or n_steps (internal steps since onset) when that is 0;
 * the extrapolated G1 law replaces that ratio by g1_line_ratio_extrapolated. */
double contact_spring_stiffness(const contact_model *cm, long n_steps);

#endif
