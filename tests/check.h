/* A minimal check harness for the C tests: each failed check prints where
 * and why; main returns the number of failures (ctest sees non-zero). */
#ifndef FRACCONTACT_CHECK_H
#define FRACCONTACT_CHECK_H

#include <math.h>
#include <stdio.h>

static int check_failures = 0;
static int check_count = 0;

#define CHECK(cond, ...)                                                      \
    do {                                                                      \
        check_count++;                                                        \
        if (!(cond)) {                                                        \
            check_failures++;                                                 \
            fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                     \
            fputc('\n', stderr);                                              \
        }                                                                     \
    } while (0)

/* |actual - expected| <= rel |expected| */
#define CHECK_REL(actual, expected, rel, what)                                \
    do {                                                                      \
        double a_ = (actual), e_ = (expected);                                \
        CHECK(fabs(a_ - e_) <= (rel) * fabs(e_), "%s: %.17g vs %.17g (rel. error %.3g, allowed %.3g)", \
              (what), a_, e_, fabs(a_ - e_) / fabs(e_), (double)(rel));       \
    } while (0)

static int check_summary(const char *name)
{
    printf("%s: %d passed, %d failed\n", name, check_count - check_failures, check_failures);
    return check_failures != 0;
}

#endif
