/* The states of FMI 2.0's call sequences (§3.2.3 Model Exchange, §4.2.4
 * co-simulation) that an instance can be in, as bits, so that each function
 * names the set of states it may be called in: fmi2_cosim.c's functions
 * and fmi2_me.c's. There is no stepFailed, error or fatal state: a refused
 * call changes nothing, and a step that fails (fmi2Error) keeps the model
 * at the start of the step, so the master may retry with a shorter step,
 * restore a state, reset, or terminate. */
#ifndef FRACCONTACT_FMI2_STATES_H
#define FRACCONTACT_FMI2_STATES_H

enum {
    INSTANTIATED = 1 << 0,
    INITIALIZATION_MODE = 1 << 1,
    STEP_COMPLETE = 1 << 2,
    TERMINATED = 1 << 4,
    EVENT_MODE = 1 << 5,          /* Model Exchange's */
    CONTINUOUS_TIME_MODE = 1 << 6 /* Model Exchange's */
};

/* Model Exchange's states after initialization (co-simulation's is
 * STEP_COMPLETE). */
#define ME_RUNNING (EVENT_MODE | CONTINUOUS_TIME_MODE)

#endif
