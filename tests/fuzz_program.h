/* The byte language the FMI fuzz harnesses (fuzz_fmi2.c, fuzz_fmi3.c) read
 * their calls in: bytes, doubles (raw, or one of the interesting values) and
 * value references. Both harnesses probe the same numbers and references. */
#ifndef FRACCONTACT_FUZZ_PROGRAM_H
#define FRACCONTACT_FUZZ_PROGRAM_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

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
                                     21, 22, 30, 31, 32, 40, 0, 99, 0xFFFFFFFFu, 23, 24, 25, 26, 33, 34, 28, 35};
    return known[byte(p) % (sizeof known / sizeof known[0])];
}

#endif
