#include "fmu_instance.h"

#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fixed_values.h"
#include "guid.h"
#include "serial.h"

static const char *const log_categories[FI_CATEGORIES] = {"logEvents", "logCalls", "logStatusWarning",
                                                          "logStatusError"};

static int category_index(const char *category)
{
    int i;
    for (i = 0; i < FI_CATEGORIES; i++)
        if (strcmp(category, log_categories[i]) == 0)
            return i;
    return -1;
}

void fi_log(const fmu_instance *in, fi_status status, const char *category, const char *message)
{
    int i = category_index(category);
    if (status == FI_ERROR || status == FI_WARNING || (in->logging_on && i >= 0 && in->category_on[i]))
        in->sink(in, status, category, message);
}

fi_status fi_fail(const fmu_instance *in, const char *fmt, ...)
{
    char message[512];
    va_list args;
    va_start(args, fmt);
    vsnprintf(message, sizeof message, fmt, args);
    va_end(args);
    fi_log(in, FI_ERROR, "logStatusError", message);
    return FI_ERROR;
}

static void report_from_model(void *env, fm_status status, const char *category, const char *message)
{
    fi_log((const fmu_instance *)env, (fi_status)status, category, message);
}

void fi_probe(fmu_instance *in, const char *name, fi_sink sink)
{
    memset(in, 0, sizeof *in);
    in->name = (char *)(name ? name : FMU_MODEL_IDENTIFIER);
    in->sink = sink;
    in->stop_time = INFINITY;
}

int fi_init(fmu_instance *in, const char *name, fi_sink sink, int logging_on, int state)
{
    fi_probe(in, name, sink);
    in->name = malloc(strlen(name) + 1);
    in->fm = in->name ? fm_new(report_from_model, in) : NULL;
    if (!in->fm) {
        free(in->name);
        fi_probe(in, name, sink);
        fi_fail(in, "%s: out of memory", name);
        return 0;
    }
    strcpy(in->name, name);
    in->logging_on = logging_on;
    memset(in->category_on, 1, sizeof in->category_on);
    in->state = state;
    return 1;
}

void fi_release(fmu_instance *in)
{
    fv_free(in);
    fm_free(in->fm);
    free(in->name);
}

static const char *state_name(int state)
{
    int i;
    for (i = 0; i < FI_STATE_BITS; i++)
        if (state == 1 << i && fi_state_names[i])
            return fi_state_names[i];
    return "unknown";
}

/* "Instantiated, Initialization Mode or Step Mode": the states of the mask. */
static void state_list(int states, char *text, size_t len)
{
    int i, left = 0;
    size_t used = 0;
    text[0] = '\0';
    for (i = 0; i < FI_STATE_BITS; i++)
        left += (states >> i & 1) && fi_state_names[i];
    for (i = 0; i < FI_STATE_BITS && used < len; i++) {
        if (!(states >> i & 1) || !fi_state_names[i])
            continue;
        left--;
        used += (size_t)snprintf(text + used, len - used, "%s%s", fi_state_names[i],
                                 left > 1 ? ", " : left == 1 ? " or " : "");
    }
}

int fi_allowed(fmu_instance *in, int states, const char *name)
{
    char allowed[160];
    if (!in)
        return 0;
    if (!(in->state & states)) {
        state_list(states, allowed, sizeof allowed);
        if (allowed[0])
            fi_fail(in, "%s: illegal call sequence: called in state %s, allowed only in %s", name,
                    state_name(in->state), allowed);
        else
            fi_fail(in, "%s: illegal call sequence: called in state %s, allowed in no state of this FMU", name,
                    state_name(in->state));
        return 0;
    }
    fi_log(in, FI_OK, "logCalls", name);
    return 1;
}

int fi_null_arrays(const fmu_instance *in, size_t n, const void *a, const void *b, const char *name)
{
    if (n > 0 && (!a || !b)) {
        fi_fail(in, "%s: a NULL array with %lu values", name, (unsigned long)n);
        return 1;
    }
    return 0;
}

fi_status fi_set_debug_logging(fmu_instance *in, int logging_on, size_t n, const char *const categories[],
                               const char *name)
{
    size_t i;
    if (fi_null_arrays(in, n, categories, categories, name))
        return FI_ERROR;
    for (i = 0; i < n; i++)
        if (!categories[i] || category_index(categories[i]) < 0)
            return fi_fail(in, "%s: unknown log category \"%.60s\"", name, categories[i] ? categories[i] : "(null)");
    in->logging_on = logging_on;
    if (n == 0)
        memset(in->category_on, 1, sizeof in->category_on);
    else {
        memset(in->category_on, 0, sizeof in->category_on);
        for (i = 0; i < n; i++)
            in->category_on[category_index(categories[i])] = 1;
    }
    return FI_OK;
}

fi_status fi_check_step(const fmu_instance *in, double t, double H, int zero_allowed, const char *name)
{
    double now;
    if (!isfinite(t) || !isfinite(H) || H < 0.0 || (H == 0.0 && !zero_allowed))
        return fi_fail(in, "%s: currentCommunicationPoint = %.17g, communicationStepSize = %.17g: "
                           "both must be finite and the step size %s", name, t, H, zero_allowed ? ">= 0" : "> 0");
    /* Masters accumulate time with rounding: a mismatch below a millionth
     * of the step is theirs, and the model takes their time. */
    now = fm_time(in->fm);
    if (fabs(t - now) > 1e-6 * H + 1e-12 * fabs(t))
        return fi_fail(in, "%s: currentCommunicationPoint = %.17g does not match the FMU's time %.17g", name, t, now);
    return FI_OK;
}

double fi_advance(double t, double H)
{
    return t + H == t ? 0.0 : H;
}

/* ------------------------------------------------------------ FMU state */

/* The bytes: "FCST", format, CRC-32 of the GUID (or instantiation token),
 * payload length, CRC-32 of the payload, then the payload: the instance's
 * mode and start time, then the model's state (fm_state_write). All
 * integers little-endian. */
#define STATE_MAGIC "FCST"
#define STATE_FORMAT 4u
#define STATE_HEADER 20u
#define STATE_INSTANCE 12u /* mode (u32), start time (f64) */

struct fi_state {
    size_t size;
    unsigned char bytes[1]; /* size bytes follow */
};

static size_t bytes_of(const fmu_instance *in)
{
    return STATE_HEADER + STATE_INSTANCE + fm_state_size(in->fm);
}

static uint32_t token_crc(void)
{
    return serial_crc32((const unsigned char *)FMU_GUID, strlen(FMU_GUID));
}

/* A state of `size` bytes: `reuse` if it has that size, else a new one
 * (and `reuse` freed). */
static fi_state *state_of_size(fi_state *reuse, size_t size)
{
    fi_state *state;
    if (reuse && reuse->size == size)
        return reuse;
    state = malloc(offsetof(fi_state, bytes) + size);
    if (state) {
        state->size = size;
        free(reuse);
    }
    return state;
}

static void write_state(const fmu_instance *in, unsigned char *b)
{
    size_t payload = bytes_of(in) - STATE_HEADER;
    unsigned char *p = b + STATE_HEADER;
    serial_put_u32(p, (uint32_t)in->state);
    serial_put_double(p + 4, in->start_time);
    fm_state_write(in->fm, p + STATE_INSTANCE);
    memcpy(b, STATE_MAGIC, 4);
    serial_put_u32(b + 4, STATE_FORMAT);
    serial_put_u32(b + 8, token_crc());
    serial_put_u32(b + 12, (uint32_t)payload);
    serial_put_u32(b + 16, serial_crc32(p, payload));
}

/* NULL when the bytes are a whole, undamaged state of this FMU and format;
 * otherwise what is wrong with them. */
static const char *state_problem(const unsigned char *b, size_t size)
{
    size_t payload;
    if (size < STATE_HEADER || memcmp(b, STATE_MAGIC, 4) != 0)
        return "not a " FMU_MODEL_IDENTIFIER " FMU state";
    if (serial_get_u32(b + 4) != STATE_FORMAT)
        return "an FMU state of another format version";
    if (serial_get_u32(b + 8) != token_crc())
        return "an FMU state of another FMU (its GUID or instantiation token differs)";
    payload = serial_get_u32(b + 12);
    if (payload < STATE_INSTANCE || size != STATE_HEADER + payload)
        return "an FMU state of the wrong length (truncated, or of another version)";
    if (serial_get_u32(b + 16) != serial_crc32(b + STATE_HEADER, payload))
        return "a corrupted FMU state (its checksum does not match)";
    return NULL;
}

fi_status fi_get_state(fmu_instance *in, fi_state **state, const char *name)
{
    fi_state *s;
    if (!state)
        return fi_fail(in, "%s: FMUState is NULL", name);
    s = state_of_size(*state, bytes_of(in)); /* a given state is overwritten */
    if (!s)
        return fi_fail(in, "%s: out of memory", name);
    write_state(in, s->bytes);
    *state = s;
    return FI_OK;
}

fi_status fi_set_state(fmu_instance *in, const fi_state *state, int modes, const char *name)
{
    const char *problem;
    uint32_t mode;
    if (!state)
        return fi_fail(in, "%s: FMUState is NULL", name);
    problem = state_problem(state->bytes, state->size);
    mode = serial_get_u32(state->bytes + STATE_HEADER);
    /* one bit of the modes this version's states may hold */
    if (!problem && (mode == 0 || (mode & (mode - 1)) != 0 || !(mode & (uint32_t)modes)))
        problem = "an FMU state with an impossible mode";
    if (problem)
        return fi_fail(in, "%s: %s", name, problem);
    if (fm_state_read(in->fm, state->bytes + STATE_HEADER + STATE_INSTANCE,
                      state->size - STATE_HEADER - STATE_INSTANCE) != FM_OK)
        return FI_ERROR;
    in->start_time = serial_get_double(state->bytes + STATE_HEADER + 4);
    in->state = (int)mode;
    return FI_OK;
}

void fi_free_state(fi_state **state)
{
    if (state) {
        free(*state);
        *state = NULL;
    }
}

fi_status fi_state_size(const fmu_instance *in, const fi_state *state, size_t *size, const char *name)
{
    if (!state || !size)
        return fi_fail(in, "%s: FMUState or size is NULL", name);
    *size = state->size;
    return FI_OK;
}

fi_status fi_serialize(const fmu_instance *in, const fi_state *state, unsigned char *bytes, size_t size,
                       const char *name)
{
    if (!state || !bytes)
        return fi_fail(in, "%s: FMUState or serializedState is NULL", name);
    if (size < state->size)
        return fi_fail(in, "%s: size = %lu, but the state takes %lu bytes", name, (unsigned long)size,
                       (unsigned long)state->size);
    memcpy(bytes, state->bytes, state->size);
    return FI_OK;
}

fi_status fi_deserialize(const fmu_instance *in, const unsigned char *bytes, size_t size, fi_state **state,
                         const char *name)
{
    const char *problem;
    fi_state *s;
    if (!bytes || !state)
        return fi_fail(in, "%s: serializedState or FMUState is NULL", name);
    problem = state_problem(bytes, size);
    if (problem)
        return fi_fail(in, "%s: %s (%lu bytes)", name, problem, (unsigned long)size);
    s = state_of_size(*state, size);
    if (!s)
        return fi_fail(in, "%s: out of memory", name);
    memcpy(s->bytes, bytes, size);
    *state = s;
    return FI_OK;
}

/* Whether an array of n values matches what the FMU has (after logging an error). */
int fi_wrong_count(fmu_instance *in, const void *array, size_t n, size_t expected, const char *what,
                   const char *name)
{
    if (fi_null_arrays(in, n, array, array, name))
        return 1;
    if (n != expected) {
        fi_fail(in, "%s: %s = %lu, but this FMU has %lu (modelDescription.xml)", name, what, (unsigned long)n,
                (unsigned long)expected);
        return 1;
    }
    return 0;
}
