/* One row of an FMU's interface table: what the C front knows about each variable.
 *
 * The tables themselves (rst_<Model>_interface.h) are generated at build time by
 * restitution.fmu.describe.c_header from the model's interface table; no C code parses XML at run time
 * and no table is edited by hand. Bump RST_VARIABLE_LAYOUT (and interface.TABLE_VERSION) together
 * whenever this struct changes: a generated header of another layout then fails to compile. */
#ifndef RST_VARIABLE_H
#define RST_VARIABLE_H

#define RST_VARIABLE_LAYOUT 3

typedef enum { RST_REAL, RST_INTEGER, RST_BOOLEAN } rst_type;
/* RST_CALCULATEDPARAMETER: computed from the parameters by the backend, read like an output, never set */
typedef enum { RST_PARAMETER, RST_INPUT, RST_OUTPUT, RST_LOCAL, RST_CALCULATEDPARAMETER } rst_causality;
typedef enum { RST_FIXED, RST_TUNABLE, RST_DISCRETE, RST_CONTINUOUS } rst_variability;

typedef struct {
    unsigned int vr;         /* value reference (= index in the table) */
    const char *name;
    rst_type type;
    int enumeration;         /* 1: an Integer whose values are named codes (FMI 3.0: an Enumeration, got and set as Int64) */
    rst_causality causality;
    rst_variability variability;
    int state;               /* 1: part of the FMU state (inputs, parameters and the model's own evolving variables) */
    double start;            /* inputs and parameters; 0 for outputs */
    double low, high;        /* allowed interval of inputs and parameters */
    int low_open, high_open; /* 1: the bound itself is not allowed (an infinite bound always is open) */
    const char *range_text;  /* the allowed range as error messages show it; NULL for outputs */
    const char *unit;        /* NULL: none */
    const char *description;
} rst_variable;

#endif
