/* The byte language the FMI fuzz harnesses (fuzz_fmi2.c, fuzz_fmi3.c) read
 * their calls in: bytes, doubles (raw, or one of the interesting values) and
 * value references. Both harnesses probe the same numbers and references. */
#ifndef FRACCONTACT_FUZZ_PROGRAM_H
#define FRACCONTACT_FUZZ_PROGRAM_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "contact.h"

typedef struct {
    const uint8_t *at, *end;
} program;

static int more(const program *p, size_t n)
{
    return (size_t)(p->end - p->at) >= n;
}

static uint8_t byte(program *p)
{
    return more(p, 1) ? *p->at++ : 0;
}

static const double interesting[] = {0.0, -0.0, 1.0, -1.0, 0.5, 1e-7, 1e-5, 1e-4, 1e-3, 3e-3, 1.0,
                                     0.626418, 0.7437, 3.299e8, 6080.0, 6.35e-3, 2.64e9, 210e9, 0.3, 0.4,
                                     9.81, 1e-15, 1e3, 1e300, -1e300, 5e-324, 2.2250738585072014e-308};

static double value(program *p)
{
    uint8_t b = byte(p);
    if (b & 0x80 && more(p, 8)) {
        double d;
        memcpy(&d, p->at, 8);
        p->at += 8;
        return d;
    }
    return interesting[b % (sizeof interesting / sizeof interesting[0])];
}

/* The FMU's references (0 = FMI 3.0's time, 1..40) most of the time,
 * anything else too; new ones only at the end, so that the corpus keeps its
 * meaning. */
static uint32_t reference(program *p)
{
    static const uint32_t known[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20,
                                     21, 22, 30, 31, 32, 40, 0, 99, 0xFFFFFFFFu, 23, 24, 25, 26, 33, 34, 28, 35,
                                     27, 36, 37, 38, 39};
    return known[byte(p) % (sizeof known / sizeof known[0])];
}

/* What one input may make the FMU compute, so that no input runs long and
 * the fuzzer keeps the rate its tests ask (tests/fuzz_rate.py; long runs are
 * the soak's): internal steps in all its DoSteps, and the terms of a full
 * G1 history's sums, where every internal step sums the whole history so
 * far (a run of N steps, N^2 / 2 terms). */
#define BUDGET_STEPS 1024.0
#define BUDGET_TERMS 262144.0

typedef struct {
    double steps, terms; /* spent */
} budget;

/* The internal step of a run whose parameter dt_max reads dt_max: the
 * FMU's default step where it is 0 (or not yet valid). */
static double internal_step(double dt_max)
{
    return dt_max > 0.0 ? dt_max : CONTACT_DEFAULT_STEP;
}

/* The most a step should take: at most 1e-4 s, and no more internal steps
 * of dt (the FMU's fixed step; with error control, the cap of its steps)
 * than the input has left. */
static double affordable(const budget *b, double H, double dt)
{
    if (H > 1e-4)
        H = 1e-4;
    if (H > (BUDGET_STEPS - b->steps) * dt)
        H = (BUDGET_STEPS - b->steps) * dt;
    return H;
}

/* Whether the input can pay for a step of H, from a run of `done` internal
 * steps of dt (the history a full G1 history sums, when it keeps one); if
 * so, it pays. */
static int pay(budget *b, double H, double dt, double done, int full_history)
{
    const double n = H > 0.0 ? ceil(H / dt) : 0.0, terms = full_history ? n * (done + 0.5 * n) : 0.0;
    if (!(b->steps + n <= BUDGET_STEPS && b->terms + terms <= BUDGET_TERMS))
        return 0;
    b->steps += n;
    b->terms += terms;
    return 1;
}

#endif
