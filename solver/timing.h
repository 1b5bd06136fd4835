/* CPU time for the solver's and the benchmark's measurements. */
#ifndef FRACCONTACT_TIMING_H
#define FRACCONTACT_TIMING_H

/* CPU time of this process [s], to the nanosecond (clock() ticks in us). */
double cpu_seconds(void);

/* The median of x[0..n-1] (n >= 1); sorts x. */
double median(double *x, int n);

#endif
