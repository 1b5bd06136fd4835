#include "fixed_values.h"

#include <errno.h>
#include <limits.h>
#include <locale.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_vars.h"
#include "guid.h"

#define MAX_PATH_BYTES 4096
#define MAX_TOKEN 64 /* a name's or a value's longest spelling */

/* A line's value, or an output the FMU does not offer (type LEFT_OUT: the
 * line "omit NAME"). */
enum { LEFT_OUT = -1 };
typedef struct {
    double value; /* an Integer's or a Boolean's too: every int is a double exactly */
    unsigned vr;
    int type;     /* a var_type, or LEFT_OUT */
} fixed_value;

/* The values a reset sets again: those that changed the model's start, and
 * the outputs left out. */
struct fv_values {
    const char *context; /* while the file is read, "caller: file line n", put before the model's messages */
    fi_sink sink;        /* the instance's own, which those messages then reach */
    size_t count;
    fixed_value list[];
};

/* What reading the file keeps besides: the line each variable was set on
 * (0: none; by its place in the table), the file's guid and its line. */
typedef struct {
    int *lines;
    char token[MAX_TOKEN + 1];
    int token_line;
} reading;

static void in_context(const fmu_instance *in, fi_status status, const char *category, const char *message)
{
    char text[1024];
    if (!in->fixed->context) {
        in->fixed->sink(in, status, category, message);
        return;
    }
    snprintf(text, sizeof text, "%s: %s", in->fixed->context, message);
    in->fixed->sink(in, status, category, text);
}

static int hex_digit(int c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

static int is_letter(int c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}

/* The path of a file: URI (file:///tmp/x, file:///C:/x, file://localhost/x,
 * file:/x) with its percent escapes decoded; 0 where it is none. */
static int path_of_uri(const char *uri, char *path, size_t len)
{
    const char *p = uri + 5;
    size_t n = 0;
    if (strncmp(uri, "file:", 5) != 0)
        return 0;
    if (strncmp(p, "//", 2) == 0) {
        p += 2;
        if (strncmp(p, "localhost", 9) == 0)
            p += 9;
        if (*p != '/')
            return 0;
    }
    if (p[0] == '/' && is_letter((unsigned char)p[1]) && p[2] == ':')
        p++; /* a Windows drive */
    for (; *p; p++) {
        int c = (unsigned char)*p;
        if (c == '%') {
            int hi = hex_digit((unsigned char)p[1]), lo = hi < 0 ? -1 : hex_digit((unsigned char)p[2]);
            if (lo < 0)
                return 0;
            c = 16 * hi + lo;
            p += 2;
        }
        if (n + 1 >= len)
            return 0;
        path[n++] = (char)c;
    }
    path[n] = '\0';
    return 1;
}

/* The file's path in `file`; 0 where the FMU was given no resources
 * folder it can read (then it has no fixed values). */
static int file_path(const char *resources, int uri, char *file, size_t len)
{
    char folder[MAX_PATH_BYTES];
    size_t n;
    if (!resources || !*resources)
        return 0;
    if (uri ? !path_of_uri(resources, folder, sizeof folder) : strlen(resources) >= sizeof folder)
        return 0;
    if (!uri)
        strcpy(folder, resources);
    n = strlen(folder);
    return snprintf(file, len, "%s%s" FV_FILE, folder,
                    n > 0 && (folder[n - 1] == '/' || folder[n - 1] == '\\') ? "" : "/") < (int)len;
}

/* The variable named `name`, or NULL. */
static const fmu_variable *named(const char *name)
{
    const fmu_variables *vars = fm_variables();
    size_t i;
    for (i = 0; i < vars->count; i++)
        if (strcmp(vars->list[i].name, name) == 0)
            return &vars->list[i];
    return NULL;
}

/* A Real as C writes it, whatever decimal point the host's locale has set. */
static int real_value(const char *text, double *value)
{
    char copy[MAX_TOKEN + 1], *end;
    const char *point = localeconv()->decimal_point;
    size_t i;
    for (i = 0; text[i]; i++)
        copy[i] = text[i] == '.' && point[0] && !point[1] ? point[0] : text[i];
    copy[i] = '\0';
    *value = strtod(copy, &end);
    return *end == '\0';
}

static int integer_value(const char *text, double *value)
{
    char *end;
    long n;
    errno = 0;
    n = strtol(text, &end, 10);
    if (*end != '\0' || errno == ERANGE || n < INT_MIN || n > INT_MAX)
        return 0;
    *value = (double)n;
    return 1;
}

static int boolean_value(const char *text, double *value)
{
    if (strcmp(text, "0") == 0 || strcmp(text, "false") == 0)
        *value = 0.0;
    else if (strcmp(text, "1") == 0 || strcmp(text, "true") == 0)
        *value = 1.0;
    else
        return 0;
    return 1;
}

static const char *const type_rules[] = {"a Real (as C's strtod reads it)", "an Integer (decimal digits)",
                                         "a Boolean (0, 1, false or true)"};

static int (*const type_readers[])(const char *, double *) = {real_value, integer_value, boolean_value};

/* Whether the model holds the value already (its start, where the table's
 * offset says, as fmu_defaults.h reads it): a reset need not set it again. */
static int held(const fmu_model *fm, const fmu_variable *var, double value)
{
    const char *at = (const char *)fm + var->offset;
    double real;
    int n;
    if (var->type == VAR_REAL) {
        memcpy(&real, at, sizeof real);
        return memcmp(&real, &value, sizeof real) == 0;
    }
    memcpy(&n, at, sizeof n);
    return n == (int)value;
}

static fm_status set_value(fmu_model *fm, const fixed_value *v)
{
    if (v->type == LEFT_OUT) {
        fm_leave_out(fm, v->vr);
        return FM_OK;
    }
    if (v->type == VAR_REAL)
        return fm_set_real(fm, v->vr, v->value);
    if (v->type == VAR_INTEGER)
        return fm_set_integer(fm, v->vr, (int)v->value);
    return fm_set_boolean(fm, v->vr, (int)v->value);
}

/* The line's tokens (the first 3 kept, each at most MAX_TOKEN bytes; a '#' starts
 * a comment): their count, or -1 where one is longer. */
static int tokens(char *line, char token[3][MAX_TOKEN + 1])
{
    int count = 0;
    char *p = line;
    while (*p && *p != '#') {
        size_t n = 0;
        if (*p == ' ' || *p == '\t' || *p == '\r') {
            p++;
            continue;
        }
        while (p[n] && p[n] != ' ' && p[n] != '\t' && p[n] != '\r' && p[n] != '#')
            n++;
        if (n > MAX_TOKEN)
            return -1;
        if (count < 3)
            memcpy(token[count], p, n), token[count][n] = '\0';
        count++;
        p += n;
    }
    return count;
}

#define refuse(...) (fi_fail(in, __VA_ARGS__), 0)
#define refuse_file(...) (fi_fail(in, __VA_ARGS__), -1)

/* The line "omit NAME": the output NAME, which the exported FMU does not
 * offer, told to the model (fm_leave_out). */
static int take_omission(fmu_instance *in, reading *r, const char *name, int line, const char *where)
{
    const fmu_variable *var = named(name);
    fixed_value *v = &in->fixed->list[in->fixed->count];
    int *first;
    if (!var || var->causality != VAR_OUTPUT)
        return refuse("%s: omit %s: %s", where, name, var ? "an input or a parameter, which the FMU has to offer"
                                                          : "no variable of this FMU has that name");
    first = &r->lines[var - fm_variables()->list];
    if (*first)
        return refuse("%s: omit %s: already on line %d", where, name, *first);
    *first = line;
    v->vr = var->vr;
    v->type = LEFT_OUT;
    v->value = 0.0;
    in->fixed->count++;
    fm_leave_out(in->fm, var->vr);
    return 1;
}

/* One line's value, read, checked against the earlier lines, and set
 * (or the line "guid TOKEN", kept; or "omit NAME"). */
static int take_line(fmu_instance *in, reading *r, char token[3][MAX_TOKEN + 1], int line, const char *where)
{
    fv_values *fixed = in->fixed;
    const fmu_variable *var = named(token[0]);
    fixed_value *v = &fixed->list[fixed->count];
    int *first;
    if (strcmp(token[0], "guid") == 0) {
        if (r->token_line)
            return refuse("%s: guid is already set on line %d; it takes one line", where, r->token_line);
        strcpy(r->token, token[1]);
        r->token_line = line;
        return 1;
    }
    if (strcmp(token[0], "omit") == 0)
        return take_omission(in, r, token[1], line, where);
    if (!var)
        return refuse("%s: no variable of this FMU is named \"%s\"", where, token[0]);
    if (var->causality == VAR_OUTPUT)
        return refuse("%s: %s is an output, which has no value to fix (\"omit %s\" leaves it out)", where,
                      var->name, var->name);
    first = &r->lines[var - fm_variables()->list];
    if (*first)
        return refuse("%s: %s = %s: %s is already set on line %d; a variable takes one line", where, var->name,
                      token[1], var->name, *first);
    if (!type_readers[var->type](token[1], &v->value))
        return refuse("%s: %s = %s is not %s", where, var->name, token[1], type_rules[var->type]);
    *first = line;
    v->vr = var->vr;
    v->type = (int)var->type;
    if (held(in->fm, var, v->value))
        return 1;
    fixed->context = where;
    if (set_value(in->fm, v) == FM_ERROR)
        return 0; /* the model said why, after `where` */
    fixed->context = NULL;
    fixed->count++;
    return 1;
}

/* Every line of the file's text: its values set, until the line "end". */
static int take_lines(fmu_instance *in, reading *r, char *text, const char *file, const char *caller)
{
    char token[3][MAX_TOKEN + 1], where[MAX_PATH_BYTES + 128];
    int line = 0, ended = 0, count;
    char *next;
    for (; *text; text = next) {
        next = strchr(text, '\n');
        next = next ? (*next = '\0', next + 1) : text + strlen(text);
        snprintf(where, sizeof where, "%s: %s line %d", caller, file, ++line);
        count = tokens(text, token);
        if (count == 0)
            continue;
        if (ended)
            return refuse("%s: text after the line \"end\"", where);
        if (count < 0)
            return refuse("%s: a word longer than %d characters", where, MAX_TOKEN);
        if (count == 1 && strcmp(token[0], "end") == 0)
            ended = 1;
        else if (count == 1)
            return refuse("%s: \"%s\" alone, where a line holds a name and a value (a truncated line?)", where,
                          token[0]);
        else if (count > 2)
            return refuse("%s: %d words, where a line holds a name and a value", where, count);
        else if (!take_line(in, r, token, line, where))
            return 0;
    }
    if (!ended)
        return refuse("%s: %s: truncated: no line \"end\" after line %d", caller, file, line);
    return 1;
}

/* Whether the importer's token (named `what`) is the FMU's: the file's guid,
 * or the full FMU's where the file names none. */
static int token_accepted(const fmu_instance *in, const char *token, const char *file_token, const char *what)
{
    const char *expected = file_token[0] ? file_token : FMU_GUID;
    if (token && strcmp(token, expected) == 0)
        return 1;
    if (!in->fixed) /* an exported FMU whose file was removed lands here too */
        return refuse("%s does not match modelDescription.xml (%s; an exported FMU names its own in "
                      "resources/" FV_FILE ", which this FMU has not)", what, expected);
    return refuse("%s does not match modelDescription.xml (%s)", what, expected);
}

/* The file's text read whole into text (FV_MAX_BYTES + 1 bytes): 1, 0 where
 * there is none, -1 after an error. */
static int read_text(fmu_instance *in, const char *file, char *text, const char *caller)
{
    size_t n;
    int error;
    FILE *f = fopen(file, "rb");
    if (!f)
        return errno == ENOENT || errno == ENOTDIR ? 0 : refuse_file("%s: %s cannot be opened: %s", caller, file,
                                                                     strerror(errno));
    n = fread(text, 1, FV_MAX_BYTES + 1, f);
    error = ferror(f);
    fclose(f);
    if (error)
        return refuse_file("%s: %s cannot be read", caller, file);
    if (n > FV_MAX_BYTES)
        return refuse_file("%s: %s is larger than %d bytes: no file of fixed values is", caller, file,
                           FV_MAX_BYTES);
    if (memchr(text, '\0', n))
        return refuse_file("%s: %s holds a NUL byte: it is no text", caller, file);
    text[n] = '\0';
    return 1;
}

/* The values of the file's text set; in->fixed keeps those a reset sets again. */
static int take_file(fmu_instance *in, reading *r, char *text, const char *file, const char *caller)
{
    const size_t count = fm_variables()->count;
    fv_values *shrunk;
    int ok;
    in->fixed = malloc(sizeof *in->fixed + count * sizeof in->fixed->list[0]);
    r->lines = calloc(count, sizeof *r->lines);
    if (!in->fixed || !r->lines) {
        free(r->lines);
        return refuse("%s: out of memory", caller);
    }
    in->fixed->context = NULL;
    in->fixed->sink = in->sink;
    in->fixed->count = 0;
    in->sink = in_context;
    ok = take_lines(in, r, text, file, caller);
    in->sink = in->fixed->sink;
    free(r->lines);
    shrunk = realloc(in->fixed, sizeof *in->fixed + in->fixed->count * sizeof in->fixed->list[0]);
    in->fixed = shrunk ? shrunk : in->fixed;
    return ok;
}

int fv_load(fmu_instance *in, const char *resources, int uri, const char *caller, const char *token,
            const char *what)
{
    char file[MAX_PATH_BYTES + 32], text[FV_MAX_BYTES + 1];
    reading r = {NULL, "", 0};
    int found = file_path(resources, uri, file, sizeof file) ? read_text(in, file, text, caller) : 0;
    if (found < 0 || (found && !take_file(in, &r, text, file, caller)))
        return 0;
    return token_accepted(in, token, r.token, what);
}

void fv_reset(fmu_instance *in)
{
    size_t i;
    fm_reset(in->fm);
    for (i = 0; in->fixed && i < in->fixed->count; i++)
        set_value(in->fm, &in->fixed->list[i]); /* as at instantiation, from the same start: accepted */
}

void fv_free(fmu_instance *in)
{
    free(in->fixed);
    in->fixed = NULL;
}
