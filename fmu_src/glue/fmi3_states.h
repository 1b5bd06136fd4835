/* The states of FMI 3.0's call sequences (§3.2 Model Exchange, §4.2
 * co-simulation) that an instance can be in, as bits: fmi3_cosim.c's
 * functions and fmi3_me.c's. As in the FMI 2.0 glue a refused call changes
 * nothing, and a failed step keeps the model at the start of that step
 * (there is no error state). */
#ifndef FRACCONTACT_FMI3_STATES_H
#define FRACCONTACT_FMI3_STATES_H

enum {
    INSTANTIATED = 1 << 0,
    INITIALIZATION_MODE = 1 << 1,
    CONTINUOUS_TIME_MODE = 1 << 2, /* Model Exchange's */
    EVENT_MODE = 1 << 5,
    STEP_MODE = 1 << 6,            /* co-simulation's */
    TERMINATED = 1 << 7
};

/* Model Exchange's states after initialization. */
#define ME_RUNNING (EVENT_MODE | CONTINUOUS_TIME_MODE)

#endif
