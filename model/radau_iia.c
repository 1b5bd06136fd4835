/* Radau IIA with five stages, the springpot's error-controlled steps
 * (docs/model.md §12): order 9 and stage order 5, so that the memory's
 * stiff modes cost it little order, where an ESDIRK integrates them to its
 * stage order 2 (docs/numerics.md). The modes are linear, so they are
 * eliminated in the eigenbasis of the method's matrix A: per mode and
 * trial three reciprocals of 1 + h b lambda (kept for the modes' update
 * once the trial is accepted), and the stages' unknowns are
 * the five elastic indentations, solved together by the simplified Newton
 * iteration in the same eigenbasis (E. Hairer and G. Wanner, Solving
 * Ordinary Differential Equations II, IV.5 and IV.8; Guglielmi and Hairer
 * integrate fractional ODEs as such stiff augmented systems with Radau IIA). */
#include <float.h>
#include <math.h>
#include <string.h>

#include "contact_internal.h"

#define STAGES 5
#define BLOCKS 3 /* A's eigenvalues: one real, two complex pairs */

/* The collocation points, roots of d^4/dx^4 [x^4 (x - 1)^5], and
 * A_ij = the integral of the j-th Lagrange polynomial on them from 0 to
 * c_i; b, the weights, are A's last row (stiffly accurate). Computed to
 * 50 digits; tests/test_contact.c checks the order conditions. */
static const double radau_c[STAGES] = {0.057104196114517683, 0.2768430136381238, 0.58359043236891683,
                                       0.86024013565621948, 1.0};
static const double radau_a[STAGES][STAGES] = {
    {0.072998864317903325, -0.02673533110794557, 0.018676929763984353, -0.01287910609330644, 0.0050428392338820148},
    {0.15377523147918246, 0.14621486784749352, -0.036444568905128087, 0.021233063119304719, -0.007935579902728777},
    {0.14006304568480987, 0.29896712949128346, 0.16758507013524895, -0.033969101686617743, 0.010944288744192253},
    {0.14489430810953477, 0.2765000687601592, 0.32579792291042103, 0.12875675325490976, -0.015708917378805327},
    {0.14371356079122594, 0.28135601514946207, 0.31182652297574126, 0.22310390108357075, 0.04}};

/* A = T B T^-1 with B block diagonal: lambda_0, then [[re, im], [-im, re]]
 * for each complex pair lambda_l = re + i im. A vector's coordinates are
 * zeta_0 = (T^-1 x)_0 and zeta_l = (T^-1 x)_(2l-1) - i (T^-1 x)_(2l), on
 * which any function of A acts as that function of lambda_l; the
 * eigenvectors are scaled so that the vector of ones has every zeta 1. */
static const double radau_lambda[BLOCKS][2] = {
    {0.15906584442746913, 0.0}, {0.13317907701829959, 0.074994511835818525},
    {0.065065778545743622, 0.11646852774031707}};
static const double radau_t[STAGES][STAGES] = {
    {0.59031650558899051, 0.51441981250440572, 0.75343357980300607, -0.10473631809339626, 0.36049927283828764},
    {0.070345631821262938, 0.49274793822320861, -1.2058078883068759, 0.43690642995552847, -0.69695291339467547},
    {3.4417503088721513, -0.6151696790367216, -4.1878747925368085, -1.8265806298354299, 0.66255230655653741},
    {17.924721804569497, -19.571316494066576, -11.798905007960075, 2.6465946894970793, 3.7910402183761827},
    {43.479581157478997, -50.158904417980807, -4.3745045874999935, 7.6793232605018105, 0.54714077253093052}};
static const double radau_t_inverse[STAGES][STAGES] = {
    {0.63702761246401196, 0.29400784393493457, 0.073793015049813379, -0.021883614950261514, 0.017055143501501606},
    {0.63891143898260794, 0.36056128700872742, 0.0067098404943595697, 0.0061359004852347965, -0.012318466970929759},
    {0.22740458813972847, -0.16193962965671202, -0.037588070025649151, -0.047685461016696643, 0.019808572559329343},
    {0.65780527250968102, 0.63194417290698202, -0.38375611281535438, 0.12519519604682511, -0.0311885286481338},
    {0.53493931080422219, -0.47389635647989797, -0.16334567709750378, 0.16311306633786865, -0.060810343564689069}};

/* The embedded solution of order 5 (Hairer and Wanner IV.8): with
 * gamma_0 = lambda_0, y_n + h (gamma_0 f(y_n) + sum bhat_j f(Y_j)), whose
 * difference from the step's end is gamma_0 h f(y_n) + e . (Y - y_n),
 * e = (bhat - b) A^-1; e's products with T's columns (its coordinates'
 * weights) and its sum. */
static const double radau_e[STAGES] = {-4.4189977167963814, 0.57923485225667004, -0.19923756095346801,
                                       0.094167483691945483, -0.031813168885493827};
static const double radau_e_t[STAGES] = {-2.9488838958995656, -2.1125062207358409, -4.1653916053844142,
                                         1.0847440059486784, -1.789163750822806};
#define RADAU_E_SUM (-3.9766461106867279)

/* The passes over the modes and the trial's own arithmetic, compiled for
 * the CPU's widest vectors (and its three-operand instructions, which spare
 * the copies of registers the scalar arithmetic of SSE2 needs) and chosen
 * at run time where GCC or Clang build for x86-64 (not for Windows, where
 * GCC does not align the stack for 32-byte vectors). Every version gives
 * the same bits (memory_sums_in_lanes, modes_to_last_stage; C99 contracts
 * no multiply-add, so the FMA of AVX-512 CPUs changes none). */
#if defined(__GNUC__) && defined(__x86_64__) && !defined(_WIN32) && !defined(CONTACT_NARROW_VECTORS)
#define ALWAYS_INLINE __attribute__((always_inline))
/* name(lanes one vector holds, args...) for each CPU */
#define CPU_WIDTH_VERSIONS(name, params, ...)                                                 \
    static void name##_sse2 params { name(2, __VA_ARGS__); }                                  \
    __attribute__((target("avx"))) static void name##_avx params { name(4, __VA_ARGS__); } \
    __attribute__((target("avx512f"))) static void name##_avx512 params { name(8, __VA_ARGS__); }
#define CPU_WIDTH_VERSION(name, width, ...)                                                                    \
    (__builtin_cpu_supports("avx512f") ? name##_avx512(__VA_ARGS__)                                           \
     : __builtin_cpu_supports("avx")   ? name##_avx(__VA_ARGS__)                                              \
                                       : name##_sse2(__VA_ARGS__))
#else
#define ALWAYS_INLINE
#define CPU_WIDTH_VERSIONS(name, params, ...)
#define CPU_WIDTH_VERSION(name, width, ...) name(width, __VA_ARGS__)
#endif

typedef struct {
    double re, im;
} complex_pair;

static inline complex_pair times(complex_pair a, complex_pair b)
{
    complex_pair p = {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re};
    return p;
}

static inline complex_pair reciprocal(complex_pair a)
{
    const double n = 1.0 / (a.re * a.re + a.im * a.im);
    complex_pair r = {a.re * n, -a.im * n};
    return r;
}

/* Block 0, A's real eigenvalue, has coordinates of no imaginary part
 * (to_blocks): its arithmetic is real, and the imaginary parts of its
 * pairs are neither set nor read. 1 / x there, with reciprocal()'s
 * arithmetic, so that it gives the bits of a pair of zero imaginary part. */
static inline double real_reciprocal(double x)
{
    return x * (1.0 / (x * x));
}

/* h lambda_l. */
static inline complex_pair h_lambda(double h, int l)
{
    complex_pair z = {h * radau_lambda[l][0], h * radau_lambda[l][1]};
    return z;
}

/* The weights a row vector w puts on the coordinates: w . x = Re sum_l
 * weight_l zeta_l (w . T's columns, each pair as one complex number). */
static inline complex_pair coordinate_weight(const double w_t[STAGES], int l)
{
    complex_pair z = {w_t[l == 0 ? 0 : 2 * l - 1], l == 0 ? 0.0 : w_t[2 * l]};
    return z;
}

/* A stage vector's coordinates, and back. */
static void to_blocks(const double x[STAGES], complex_pair z[BLOCKS])
{
    double y[STAGES];
    int i, k;
    for (i = 0; i < STAGES; i++) {
        y[i] = 0.0;
        for (k = 0; k < STAGES; k++)
            y[i] += radau_t_inverse[i][k] * x[k];
    }
    z[0].re = y[0];
    z[0].im = 0.0;
    z[1].re = y[1];
    z[1].im = -y[2];
    z[2].re = y[3];
    z[2].im = -y[4];
}

static double from_blocks_at(const complex_pair z[BLOCKS], int i)
{
    return radau_t[i][0] * z[0].re + radau_t[i][1] * z[1].re - radau_t[i][2] * z[1].im + radau_t[i][3] * z[2].re
           - radau_t[i][4] * z[2].im;
}

static void from_blocks(const complex_pair z[BLOCKS], double x[STAGES])
{
    int i;
    for (i = 0; i < STAGES; i++)
        x[i] = from_blocks_at(z, i);
}

/* The compressed memory's sums a trial needs, one pass over the modes:
 * with d_l = 1/(1 + h b lambda_l) for each mode,
 *     p_l = sum a phi d_l,  q_l = sum a d_l  (the stages' memory),
 *     pp_0 = sum a phi d_0^2,  qq_0 = sum a d_0^2,  relaxed = sum a phi (1 - d_0)
 * (the error estimate's, filtered through (I - gamma_0 h J)^-1, which
 * needs d_0 d_l too: for l > 0 that is (lambda_0 d_0 - lambda_l d_l) /
 * (lambda_0 - lambda_l), from p_0 and p_l). The three reciprocals by one
 * division of their product, whose size, (h b)^5 at most, stays far from
 * overflowing for any step and mode; the pass keeps them in radau_d (d_0,
 * and for each pair the real part of d_l and minus its imaginary part), so
 * that the sums of a phi d and the update of the modes need no more than
 * products with them. */
typedef struct {
    complex_pair p[BLOCKS], q[BLOCKS];
    double pp0, qq0, relaxed;
} memory_sums;

/* The sums in CONTACT_MODE_LANES lanes: lane k sums the modes j = k mod
 * lanes in their order, and the lanes are added in a fixed order after, so
 * that a CPU's vector width changes no bit of them (C99 contracts no
 * multiply-add). The modes are padded to whole lanes with a = b = phi = 0,
 * which add exact zeros. The lanes that one vector holds (width of them,
 * from first) are summed in two passes over their modes, the sums of a d
 * and then those of a phi d, so that each pass's sums stay in the vector
 * registers. */
enum { SUM_P0, SUM_Q0, SUM_PP0, SUM_QQ0, SUM_RELAXED, SUM_P1R, SUM_P1I, SUM_Q1R, SUM_Q1I, SUM_P2R, SUM_P2I,
       SUM_Q2R, SUM_Q2I, SUMS };

static inline ALWAYS_INLINE void memory_sums_in_vector(const int width, int first, contact_modes *m, double h,
                                                        double sum[SUMS][CONTACT_MODE_LANES])
{
    const double l0 = radau_lambda[0][0], r1 = radau_lambda[1][0], i1 = radau_lambda[1][1];
    const double r2 = radau_lambda[2][0], i2 = radau_lambda[2][1];
    /* the arrays apart, as the compiler cannot tell them from their pointers */
    const double *restrict const mode_a = m->a, *restrict const mode_b = m->b, *restrict const mode_phi = m->phi;
    double *restrict const d0_of = RADAU_RECIPROCAL(m, 0), *restrict const c1r_of = RADAU_RECIPROCAL(m, 1);
    double *restrict const c1i_of = RADAU_RECIPROCAL(m, 2), *restrict const c2r_of = RADAU_RECIPROCAL(m, 3);
    double *restrict const c2i_of = RADAU_RECIPROCAL(m, 4);
    double lane[SUMS][CONTACT_MODE_LANES];
    size_t j;
    int k, n;
    for (n = 0; n < SUMS; n++)
        for (k = 0; k < width; k++)
            lane[n][k] = 0.0;
    for (j = first; j < m->modes; j += CONTACT_MODE_LANES) { /* the reciprocals and the sums of a d */
#pragma omp simd
        for (k = 0; k < width; k++) {
            const double x = h * mode_b[j + k], a = mode_a[j + k];
            const double D0 = 1.0 + x * l0;
            const double u1 = 1.0 + x * r1, v1 = x * i1, N1 = u1 * u1 + v1 * v1;
            const double u2 = 1.0 + x * r2, v2 = x * i2, N2 = u2 * u2 + v2 * v2;
            const double inv = 1.0 / (D0 * (N1 * N2));
            const double d0 = (N1 * N2) * inv, k1 = (D0 * N2) * inv, k2 = (D0 * N1) * inv;
            const double ad = a * d0, c1r = k1 * u1, c1i = k1 * v1, c2r = k2 * u2, c2i = k2 * v2;
            d0_of[j + k] = d0;
            c1r_of[j + k] = c1r;
            c1i_of[j + k] = c1i;
            c2r_of[j + k] = c2r;
            c2i_of[j + k] = c2i;
            lane[SUM_Q0][k] += ad;
            lane[SUM_QQ0][k] += ad * d0;
            lane[SUM_Q1R][k] += a * c1r;
            lane[SUM_Q1I][k] -= a * c1i;
            lane[SUM_Q2R][k] += a * c2r;
            lane[SUM_Q2I][k] -= a * c2i;
        }
    }
    for (j = first; j < m->modes; j += CONTACT_MODE_LANES) { /* the sums of a phi d, from the reciprocals */
#pragma omp simd
        for (k = 0; k < width; k++) {
            const double x = h * mode_b[j + k], ap = mode_a[j + k] * mode_phi[j + k];
            const double d0 = d0_of[j + k];
            const double apd = ap * d0;
            lane[SUM_RELAXED][k] += apd * (x * l0);
            lane[SUM_P0][k] += apd;
            lane[SUM_PP0][k] += apd * d0;
            lane[SUM_P1R][k] += ap * c1r_of[j + k];
            lane[SUM_P1I][k] -= ap * c1i_of[j + k];
            lane[SUM_P2R][k] += ap * c2r_of[j + k];
            lane[SUM_P2I][k] -= ap * c2i_of[j + k];
        }
    }
    for (n = 0; n < SUMS; n++)
        for (k = 0; k < width; k++)
            sum[n][first + k] = lane[n][k];
}

static inline ALWAYS_INLINE void memory_sums_in_lanes(const int width, contact_modes *m, double h,
                                                      double sum[SUMS])
{
    double lanes[SUMS][CONTACT_MODE_LANES];
    int first, k, n;
    for (first = 0; first < CONTACT_MODE_LANES; first += width)
        memory_sums_in_vector(width, first, m, h, lanes);
    for (n = 0; n < SUMS; n++) {
        sum[n] = lanes[n][0];
        for (k = 1; k < CONTACT_MODE_LANES; k++)
            sum[n] += lanes[n][k];
    }
}

static inline ALWAYS_INLINE void memory_sums_of(const int width, contact_modes *m, double h, memory_sums *s)
{
    double sum[SUMS];
    memory_sums_in_lanes(width, m, h, sum);
    m->radau_h = h;
    s->p[0].re = sum[SUM_P0], s->p[0].im = 0.0, s->q[0].re = sum[SUM_Q0], s->q[0].im = 0.0;
    s->p[1].re = sum[SUM_P1R], s->p[1].im = sum[SUM_P1I], s->q[1].re = sum[SUM_Q1R], s->q[1].im = sum[SUM_Q1I];
    s->p[2].re = sum[SUM_P2R], s->p[2].im = sum[SUM_P2I], s->q[2].re = sum[SUM_Q2R], s->q[2].im = sum[SUM_Q2I];
    s->pp0 = sum[SUM_PP0], s->qq0 = sum[SUM_QQ0], s->relaxed = sum[SUM_RELAXED];
}

/* sum a d_0 d_l y for l > 0 from the sums of a d_0 y and a d_l y. */
static complex_pair with_d0(int l, double sum0, complex_pair sum_l)
{
    const complex_pair lam = {radau_lambda[l][0], radau_lambda[l][1]};
    const complex_pair difference = {radau_lambda[0][0] - lam.re, -lam.im};
    complex_pair num = times(lam, sum_l);
    num.re = radau_lambda[0][0] * sum0 - num.re;
    num.im = -num.im;
    return times(num, reciprocal(difference));
}

/* The spring's force at an elastic indentation, and its slope there,
 * n F / X for F = K X^n (for the Hertz sphere's n = 1.5, 1.5 K sqrt(X),
 * without the division). */
static inline double force_and_slope(const contact_model *cm, double K, double X, double *slope)
{
    const double n = cm->p.spring_exponent;
    double F;
    if (!(X > 0.0)) {
        *slope = 0.0;
        return 0.0;
    }
    F = spring_force(cm, K, X);
    *slope = n == 1.5 ? 1.5 * K * sqrt(X) : n * F / X;
    return F;
}

/* The simplified Newton iteration contracts by a factor theta each time,
 * so that after a change d the indentations are within theta / (1 - theta)
 * d of the root: it stops when that is below NEWTON_SETTLED times the
 * tolerance of the largest indentation, far inside the step's error (Hairer
 * and Wanner's kappa Tol, IV.8), and a trial whose iteration grows or needs
 * more than NEWTON_LIMIT is rejected, and the step shrinks. */
#define NEWTON_SETTLED 1e-2
#define NEWTON_LIMIT 30

/* The stages' elastic indentations X from X + G F(X) = r, G = T diag(mu)
 * T^-1, from the start's motion r (its coordinates rho) and a first guess
 * X (its coordinates xi): Newton's method with the Jacobian
 * I + G diag(F'(X)) taken as I + sigma G, sigma the mean slope of F at the
 * first guess, which A's eigenbasis inverts as 1 / (1 + sigma mu_l),
 * coordinate by coordinate: no linear system. Where the slopes differ
 * little across the step, as everywhere but at an onset, it converges
 * nearly as fast as Newton's method. 0 when it did not converge. */
static inline ALWAYS_INLINE int stage_indentations(const contact_model *cm, double K, const complex_pair mu[BLOCKS],
                                                    const complex_pair rho[BLOCKS], complex_pair xi[BLOCKS],
                                                    double X[STAGES], double F[STAGES])
{
    complex_pair inverse[BLOCKS];
    const double settled = NEWTON_SETTLED * cm->p.tolerance;
    double slope, sigma = 0.0, previous = INFINITY;
    int i, l, it;
    for (i = 0; i < STAGES; i++) {
        F[i] = force_and_slope(cm, K, X[i], &slope);
        sigma += slope;
    }
    sigma *= 1.0 / STAGES;
    inverse[0].re = real_reciprocal(1.0 + sigma * mu[0].re);
    for (l = 1; l < BLOCKS; l++) {
        const complex_pair jacobian = {1.0 + sigma * mu[l].re, sigma * mu[l].im};
        inverse[l] = reciprocal(jacobian);
    }
    for (it = 0; it < NEWTON_LIMIT; it++) { /* F is the spring's force at X */
        complex_pair Ft[BLOCKS];
        double change = 0.0, scale = DBL_MIN;
        to_blocks(F, Ft);
        xi[0].re += (rho[0].re - xi[0].re - mu[0].re * Ft[0].re) * inverse[0].re;
        for (l = 1; l < BLOCKS; l++) {
            const complex_pair muF = times(mu[l], Ft[l]);
            const complex_pair residual = {rho[l].re - xi[l].re - muF.re, rho[l].im - xi[l].im - muF.im};
            const complex_pair step = times(residual, inverse[l]);
            xi[l].re += step.re;
            xi[l].im += step.im;
        }
        for (i = 0; i < STAGES; i++) {
            const double next = from_blocks_at(xi, i);
            change = larger(change, fabs(next - X[i]));
            scale = larger(scale, fabs(next));
            X[i] = next;
            F[i] = spring_force(cm, K, larger(next, 0.0));
        }
        /* theta = change / previous, and theta / (1 - theta) change below
         * the bound, without a division on the iteration's path; the first
         * iteration (previous infinite) cannot stop */
        if (!(change < previous))
            return 0;
        if (it > 0 && !(change * change > settled * scale * (previous - change)))
            return 1;
        previous = change;
    }
    return 0;
}

/* The embedded error estimate (see radau_e), filtered through
 * (I - gamma_0 h J)^-1 with the Jacobian at the step's start, J's modes
 * eliminated as in the stages: the errors of x1, v, x2 and of the memory's
 * force sum a phi, to be set against error_length and error_speed. */
typedef struct {
    double x1, v, x2, memory;
} radau_errors;

/* e . (Y - y_n) for x1, v and x2 (radau_e). */
typedef struct {
    double x1, v, x2;
} stage_differences;

static inline ALWAYS_INLINE radau_errors filtered_errors(const contact_model *cm, const contact_state *in, double h,
                                                         double K, const memory_sums *s, stage_differences d,
                                                         const complex_pair W[BLOCKS])
{
    const double w = radau_lambda[0][0] * h, inv_c_alpha = 1.0 / cm->p.c_alpha, inv_m = cm->inv_m, z_n = in->x2_rate;
    const double r_x1 = w * (in->v - z_n) + d.x1, r_v = w * (cm->accel - inv_m * in->F) + d.v;
    const double r_x2 = w * z_n + d.x2;
    double rho, kk, slope, ex1, dz;
    radau_errors e;
    int l;
    /* sum a d_0 r_phi with r_phi = w (z_n - b phi) + e . (Phi - phi) */
    rho = w * z_n * s->q[0].re - s->relaxed - RADAU_E_SUM * s->p[0].re;
    rho += radau_e_t[0] * (W[0].re * s->qq0 + s->pp0);
    for (l = 1; l < BLOCKS; l++) {
        const complex_pair e_l = coordinate_weight(radau_e_t, l);
        const complex_pair pp = with_d0(l, s->p[0].re, s->p[l]), qq = with_d0(l, s->q[0].re, s->q[l]);
        complex_pair sum = times(W[l], qq);
        sum.re += pp.re;
        sum.im += pp.im;
        rho += times(e_l, sum).re;
    }
    kk = 1.0 / (cm->modes.eta + w * s->q[0].re);
    force_and_slope(cm, K, in->x1, &slope);
    ex1 = (r_x1 + w * kk * rho + w * r_v) / (1.0 + w * kk * slope * inv_c_alpha + w * w * slope * inv_m);
    dz = kk * (slope * ex1 * inv_c_alpha - rho);
    e.x1 = ex1;
    e.v = r_v - w * slope * inv_m * ex1;
    e.x2 = r_x2 + w * dz;
    /* the memory's force error as the travel it drives over the step
     * through the stage's viscosity c_alpha / kk */
    e.memory = h * kk * (rho + w * dz * s->q[0].re);
    return e;
}

/* Re sum_l w_l z_l: a row vector's product with the vector of coordinates z
 * (coordinate_weight). */
static double weighted(const double w_t[STAGES], const complex_pair z[BLOCKS])
{
    double sum = w_t[0] * z[0].re;
    int l;
    for (l = 1; l < BLOCKS; l++)
        sum += times(coordinate_weight(w_t, l), z[l]).re;
    return sum;
}

static inline ALWAYS_INLINE void radau_trial(const int width, contact_model *cm, const contact_state *in, double h,
                                             double K, contact_state *out, double *J)
{
    const double inv_c_alpha = 1.0 / cm->p.c_alpha, eta = cm->modes.eta, inv_m = cm->inv_m, accel = cm->accel;
    const double x1 = in->x1, v = in->v, slide = in->v - in->x2_rate;
    memory_sums s;
    complex_pair ell[BLOCKS], mu[BLOCKS], rho[BLOCKS], xi[BLOCKS], Ft[BLOCKS], Zt[BLOCKS], W[BLOCKS], AFt[BLOCKS];
    double X[STAGES], F[STAGES], Z[STAGES];
    double impulse = 0.0, work = 0.0, error, e_X = 0.0; /* e . (X - x1) */
    stage_differences d;
    radau_errors e;
    int i, l;
    memory_sums_of(width, &cm->modes, h, &s);
    /* The start's motion r = x1 + c h v + c^2 h^2 accel / 2 + the memory's
     * pull, and the first guess x1 + c h (v - x2'), in the coordinates,
     * where the vectors 1, c = A 1 and c^2 = 2 A c (the collocation
     * conditions) have the coordinates 1, lambda_l and 2 lambda_l^2. */
    {
        const double hl = h * radau_lambda[0][0], hl2 = hl * hl, ell0 = real_reciprocal(hl * s.q[0].re + eta);
        const double hl_ell = hl * ell0;
        ell[0].re = ell0;
        mu[0].re = hl2 * inv_m + hl_ell * inv_c_alpha;
        rho[0].re = x1 + hl * v + hl2 * accel + hl_ell * s.p[0].re;
        xi[0].re = x1 + hl * slide;
    }
    for (l = 1; l < BLOCKS; l++) {
        const complex_pair hl = h_lambda(h, l), hl2 = times(hl, hl);
        complex_pair den = times(hl, s.q[l]), hl_ell, pull;
        den.re += eta;
        ell[l] = reciprocal(den);
        hl_ell = times(hl, ell[l]);
        mu[l].re = hl2.re * inv_m + hl_ell.re * inv_c_alpha;
        mu[l].im = hl2.im * inv_m + hl_ell.im * inv_c_alpha;
        pull = times(hl_ell, s.p[l]);
        rho[l].re = x1 + hl.re * v + hl2.re * accel + pull.re;
        rho[l].im = hl.im * v + hl2.im * accel + pull.im;
        xi[l].re = x1 + hl.re * slide;
        xi[l].im = hl.im * slide;
    }
    for (i = 0; i < STAGES; i++)
        X[i] = x1 + radau_c[i] * h * slide;
    carry_state(out, in);
    out->t = in->t + h;
    out->step = h;
    if (!stage_indentations(cm, K, mu, rho, xi, X, F)) {
        out->error = INFINITY;
        *J = 0.0;
        return;
    }
    to_blocks(F, Ft);
    Zt[0].re = ell[0].re * (Ft[0].re * inv_c_alpha - s.p[0].re);
    W[0].re = h * radau_lambda[0][0] * Zt[0].re;
    AFt[0].re = h * radau_lambda[0][0] * Ft[0].re;
    for (l = 1; l < BLOCKS; l++) {
        const complex_pair hl = h_lambda(h, l);
        complex_pair force = {Ft[l].re * inv_c_alpha - s.p[l].re, Ft[l].im * inv_c_alpha - s.p[l].im};
        Zt[l] = times(ell[l], force);
        W[l] = times(hl, Zt[l]);
        AFt[l] = times(hl, Ft[l]);
    }
    from_blocks(Zt, Z);
    for (i = 0; i < STAGES; i++) {
        impulse += h * radau_a[STAGES - 1][i] * F[i];
        work += h * radau_a[STAGES - 1][i] * F[i] * Z[i];
        e_X += radau_e[i] * (X[i] - x1);
    }
    /* e . (V - v) with V = v + h (c accel - A F / m), h A F's coordinates
     * h lambda_l times F's, and e . c = sum (bhat - b) = -gamma_0 (c = A 1,
     * and the embedded weights with gamma_0 sum to 1); the travel's
     * e . h A Z; the last stage's v is v + h accel - the impulse / m
     * (c_5 = 1) */
    d.x1 = e_X;
    d.v = -h * accel * radau_lambda[0][0] - inv_m * weighted(radau_e_t, AFt);
    d.x2 = weighted(radau_e_t, W);
    e = filtered_errors(cm, in, h, K, &s, d, W);
    out->x1 = X[STAGES - 1];
    out->v = v + h * accel - inv_m * impulse;
    out->F = F[STAGES - 1];
    out->x2 = in->x2 + from_blocks_at(W, STAGES - 1);
    out->E_diss = in->E_diss + work;
    out->x2_rate1 = Z[0];
    memcpy(out->x2_rate_inner, Z + 1, sizeof out->x2_rate_inner);
    memcpy(out->x1_inner, X, sizeof out->x1_inner);
    out->x2_rate = Z[STAGES - 1];
    error = larger(larger(fabs(e.x1), fabs(e.x2)), fabs(e.memory)) / error_length(cm, in, K, out);
    out->error = larger(error, fabs(e.v) / error_speed(in, out)) / cm->p.tolerance;
    *J = impulse;
}

CPU_WIDTH_VERSIONS(radau_trial,
                   (contact_model * cm, const contact_state *in, double h, double K, contact_state *out, double *J),
                   cm, in, h, K, out, J)

/* One trial step of length h from *in into *out (its error ratio in
 * out->error, INFINITY where the stages' iteration failed): its impulse. */
double radau_step(contact_model *cm, const contact_state *in, double h, double K, contact_state *out)
{
    double J;
    CPU_WIDTH_VERSION(radau_trial, 2, cm, in, h, K, out, &J);
    return J;
}

/* Each mode to the last stage's value, elementwise from the reciprocals the
 * trial's pass kept: any vector width gives the same bits. */
static inline ALWAYS_INLINE void modes_to_last_stage(contact_modes *m, const complex_pair tau[BLOCKS],
                                                      const complex_pair tau_W[BLOCKS])
{
    const double t0 = tau[0].re, t1r = tau[1].re, t1i = tau[1].im, t2r = tau[2].re, t2i = tau[2].im;
    const double w0 = tau_W[0].re, w1r = tau_W[1].re, w1i = tau_W[1].im, w2r = tau_W[2].re, w2i = tau_W[2].im;
    const double *restrict const d0_of = RADAU_RECIPROCAL(m, 0), *restrict const c1r_of = RADAU_RECIPROCAL(m, 1);
    const double *restrict const c1i_of = RADAU_RECIPROCAL(m, 2), *restrict const c2r_of = RADAU_RECIPROCAL(m, 3);
    const double *restrict const c2i_of = RADAU_RECIPROCAL(m, 4);
    double *restrict const phi_of = m->phi;
    size_t j;
#pragma omp simd
    for (j = 0; j < m->modes; j++) {
        /* Re(tau (phi + W) d) coordinate by coordinate */
        const double phi = phi_of[j];
        const double n0 = phi * t0 + w0;
        const double n1 = (phi * t1r + w1r) * c1r_of[j] + (phi * t1i + w1i) * c1i_of[j];
        const double n2 = (phi * t2r + w2r) * c2r_of[j] + (phi * t2i + w2i) * c2i_of[j];
        phi_of[j] = n0 * d0_of[j] + (n1 + n2);
    }
}

/* The modes after an accepted step: the last stage's (stiffly accurate),
 * Phi = (I + h b A)^-1 (phi_n 1 + h A Z) in the coordinates, from the
 * trial's stage rates Z. */
static inline ALWAYS_INLINE void accepted_modes(const int width, contact_model *cm, const contact_state *trial)
{
    contact_modes *m = &cm->modes;
    const double h = trial->step;
    double Z[STAGES];
    complex_pair Zt[BLOCKS], tau[BLOCKS], tau_W[BLOCKS];
    int l;
    if (m->radau_h != h) { /* another trial came after it (an event's search) */
        memory_sums unused;
        memory_sums_of(width, m, h, &unused);
    }
    Z[0] = trial->x2_rate1;
    memcpy(Z + 1, trial->x2_rate_inner, sizeof trial->x2_rate_inner);
    Z[STAGES - 1] = trial->x2_rate;
    to_blocks(Z, Zt);
    for (l = 0; l < BLOCKS; l++) { /* the last row's weights on each coordinate, and on h lambda Z~ */
        tau[l] = coordinate_weight(radau_t[STAGES - 1], l);
        tau_W[l] = times(tau[l], times(h_lambda(h, l), Zt[l]));
    }
    modes_to_last_stage(m, tau, tau_W);
}

CPU_WIDTH_VERSIONS(accepted_modes, (contact_model * cm, const contact_state *trial), cm, trial)

void radau_advance_modes(contact_model *cm, const contact_state *trial)
{
    CPU_WIDTH_VERSION(accepted_modes, 2, cm, trial);
}

/* The dense output: the polynomial through (theta_i, y_i) at the nodes
 * theta = 0 and c has the coefficients M y, M the inverse of the nodes'
 * Vandermonde matrix, M_ki the coefficient of theta^k in the i-th Lagrange
 * polynomial (computed in exact rational arithmetic on the nodes' doubles;
 * tests/test_contact.c checks that it interpolates). */
static const double radau_dense[STAGES + 1][STAGES + 1] = {
    {1.0, 0.0, 0.0, 0.0, 0.0, 0.0},
    {-25.0, 27.78093394406464, -3.641478498049213, 1.2525477211691185, -0.5920031671845428, 0.20000000000000004},
    {150.0, -208.02785730090133, 77.88337605511782, -29.16741431782969, 14.111895563613205, -4.800000000000002},
    {-350.0, 524.1878839694918, -264.89491356822634, 137.90290440413474, -72.39587480540027, 25.200000000000006},
    {350.0, -543.8283560361325, 317.67586907995275, -202.09087094360737, 123.04335789978718, -44.80000000000001},
    {-126.0, 199.88739542347736, -127.02285306879499, 92.1028331361332, -64.16737549081559, 25.200000000000006}};

/* x1 over a trial from *s to *trial as a polynomial in theta = tau / h,
 * p[0] + p[1] theta + ... + p[5] theta^5: the collocation polynomial
 * through x1 at the step's start and at the five stages, Radau IIA's dense
 * output (of the stage order 5). */
void radau_indentation_polynomial(const contact_state *s, const contact_state *trial, double p[STAGES + 1])
{
    double y[STAGES + 1];
    int i, k;
    y[0] = s->x1;
    for (i = 0; i < STAGES; i++)
        y[i + 1] = i < STAGES - 1 ? trial->x1_inner[i] : trial->x1;
    for (k = 0; k <= STAGES; k++) {
        p[k] = 0.0;
        for (i = 0; i <= STAGES; i++)
            p[k] += radau_dense[k][i] * y[i];
    }
}

const contact_method_record radau_iia_method = {
    .method = CONTACT_METHOD_RADAU_IIA,
    .name = "radau_iia",
    .controls_error = 1,
    .springpot_step = radau_step,
    .accept = radau_advance_modes,
    .dense_indentation = radau_indentation_polynomial,
    .dense_degree = STAGES,
};
