/* The front's FMU states: snapshots of the store's state variables, the communication point, the mode
 * and the interface; getting, setting and freeing them and their serialization (versioned, checksummed,
 * little-endian, the same bytes whatever the FMI version). Every state is checked before it is restored
 * or becomes a state (check_snapshot): exactly one mode of its interface, the instance's interface,
 * finite times, every Real finite and every input and parameter as a set call would check it. */
#include "rst_instance.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* Serialized layout version (see front_serialize); 2: the interface is recorded. Only this one is read. */
#define RST_STATE_FORMAT 2u

/* The modes a state of each interface may hold (exactly one of them); co-simulation also event mode
 * where the instance was instantiated with eventModeUsed (FMI 3.0). */
#define CS_STATE_MODES (RST_MODE_INSTANTIATED | RST_MODE_INITIALIZATION | RST_MODE_STEP_COMPLETE | \
                        RST_MODE_STEP_FAILED | RST_MODE_TERMINATED | RST_MODE_ERROR)
#define ME_STATE_MODES (RST_MODE_INSTANTIATED | RST_MODE_INITIALIZATION | ME_MODES | RST_MODE_TERMINATED | \
                        RST_MODE_ERROR)

void front_free_states(rst_instance *inst)
{
    while (inst->states != NULL) {
        rst_state *next = inst->states->next;
        inst->states->magic = 0;
        inst->release(inst->states);
        inst->states = next;
    }
}

/* ------------------------------------------------------------------------------------------------ */
/* FMU states                                                                                       */
/* ------------------------------------------------------------------------------------------------ */
/* The size of one state of this instance: the struct and its n_state values. */
static size_t state_bytes(const rst_instance *inst)
{
    return sizeof(rst_state) + (inst->n_state ? inst->n_state - 1 : 0) * sizeof(double);
}

static rst_state *find_state(rst_instance *inst, const void *pointer)
{
    rst_state *s;
    for (s = inst->states; s != NULL; s = s->next)
        if ((const void *)s == pointer)
            return s;
    return NULL;
}

static rst_state *new_state(rst_instance *inst)
{
    rst_state *s = (rst_state *)inst->allocate(1, state_bytes(inst));
    if (s == NULL)
        return NULL;
    s->magic = RST_STATE_MAGIC;
    s->next = inst->states;
    inst->states = s;
    return s;
}

static void unlink_state(rst_instance *inst, rst_state *state)
{
    rst_state **link;
    for (link = &inst->states; *link != NULL; link = &(*link)->next)
        if (*link == state) {
            *link = state->next;
            state->magic = 0;
            inst->release(state);
            return;
        }
}

/* `*pointer`: NULL (a new state) or one of ours (overwritten). Logs and returns NULL otherwise. */
static rst_state *target_state(rst_instance *inst, const char *function, void **pointer)
{
    rst_state *s;
    if (pointer == NULL) {
        rst_log(inst, RST_ERROR, "%s: the FMUstate pointer is NULL", function);
        return NULL;
    }
    if (*pointer == NULL) {
        s = new_state(inst);
        if (s == NULL)
            rst_log(inst, RST_ERROR, "%s: out of memory", function);
        return s;
    }
    s = find_state(inst, *pointer);
    if (s == NULL)
        rst_log(inst, RST_ERROR, "%s: *FMUstate is neither NULL nor a state of this instance", function);
    return s;
}

rst_status front_get_state(void *c, const char *function, void **FMUstate)
{
    rst_state *s;
    size_t i, k = 0;
    rst_status status = RST_OK;
    ENTER(function, ANY_LIVE_MODE)
    if (inst->model->save_state != NULL) {
        status = front_backend_status(inst, inst->model->save_state(inst));
        if (status >= RST_ERROR)
            LEAVE(status);
    }
    s = target_state(inst, function, FMUstate);
    if (s == NULL)
        LEAVE(RST_ERROR);
    s->mode = (unsigned int)inst->mode;
    s->model_exchange = inst->model_exchange != 0;
    s->has_start = inst->has_start != 0;
    s->has_time = inst->has_time != 0;
    s->start_time = inst->start_time;
    s->next_time = inst->next_time;
    s->last_time = inst->last_time;
    for (i = 0; i < inst->model->n_variables; i++)
        if (inst->model->variables[i].state)
            s->values[k++] = inst->head.store[i];
    *FMUstate = s;
    LEAVE(status);
}

/* Is a snapshot a state of this instance: one mode of its interface, the instance's interface, finite
 * times, every value one the instance could hold? (A deserialized state passes here before it becomes a
 * state, a state before it is restored; values checked as a set call would, plus every Real finite and
 * the types of the other variables.) Logs one line and returns 0 when not. */
static int check_snapshot(rst_instance *inst, const char *function, const rst_state *s)
{
    size_t i, k = 0;
    char text[40];
    unsigned int modes;
    if (s->model_exchange > 1u) {
        rst_log(inst, RST_ERROR, "%s: the state's interface word %u is neither co-simulation (0) nor model "
                "exchange (1)", function, s->model_exchange);
        return 0;
    }
    if ((s->model_exchange != 0) != (inst->model_exchange != 0)) {
        rst_log(inst, RST_ERROR, "%s: the state was taken from a %s instance; this one is %s", function,
                s->model_exchange ? "model-exchange" : "co-simulation",
                inst->model_exchange ? "model exchange" : "co-simulation");
        return 0;
    }
    modes = inst->model_exchange ? ME_STATE_MODES
                                 : CS_STATE_MODES | (inst->event_mode_used ? (unsigned int)RST_MODE_EVENT : 0u);
    if (s->mode == 0 || (s->mode & (s->mode - 1u)) != 0 || (s->mode & modes) == 0) {
        rst_log(inst, RST_ERROR, "%s: the state's mode word 0x%x is not one mode of the %s state machine",
                function, s->mode, inst->model_exchange ? "model-exchange" : "co-simulation");
        return 0;
    }
    if (s->has_start > 1u || s->has_time > 1u || !isfinite(s->start_time) || !isfinite(s->next_time) ||
        !isfinite(s->last_time)) {
        rst_log(inst, RST_ERROR, "%s: the state's times are not finite or its time flags are not 0 or 1",
                function);
        return 0;
    }
    for (i = 0; i < inst->model->n_variables; i++) {
        const rst_variable *var = &inst->model->variables[i];
        double value;
        if (!var->state)
            continue;
        value = s->values[k++];
        front_describe_value(var->type, value, text, sizeof text);
        if (var->causality == RST_INPUT || var->causality == RST_PARAMETER) {
            if (!front_in_range(var, value) ||
                (var->type == RST_INTEGER && value != floor(value))) {
                rst_log(inst, RST_ERROR, "%s: the state has %s = %s, outside the allowed range: %s", function,
                        var->name, text, var->range_text ? var->range_text : "finite");
                return 0;
            }
            if (inst->model->accept != NULL && inst->model->accept(inst, var, value) != RST_OK)
                return 0;
        } else if ((var->type == RST_REAL && !isfinite(value)) ||
                   (var->type == RST_BOOLEAN && value != 0.0 && value != 1.0) ||
                   (var->type == RST_INTEGER &&
                    !(value == floor(value) && value >= -2147483648.0 && value <= 2147483647.0))) {
            rst_log(inst, RST_ERROR, "%s: the state has %s = %s, not a %s %s", function, var->name, text,
                    var->type == RST_REAL ? "finite" : "valid", front_type_name(var->type));
            return 0;
        }
    }
    return 1;
}

rst_status front_set_state(void *c, const char *function, void *FMUstate)
{
    rst_state *s;
    size_t i, k = 0;
    rst_status status = RST_OK;
    ENTER(function, ANY_LIVE_MODE)
    s = find_state(inst, FMUstate);
    if (s == NULL) {
        rst_log(inst, RST_ERROR, "%s: the FMUstate is not a state of this instance (states are made by "
                "%s or %s of the same instance)", function, inst->api->get_state, inst->api->deserialize_state);
        LEAVE(RST_ERROR);
    }
    if (!check_snapshot(inst, function, s)) /* the host may have written over it: nothing changes */
        LEAVE(RST_ERROR);
    for (i = 0; i < inst->model->n_variables; i++)
        if (inst->model->variables[i].state)
            inst->head.store[i] = s->values[k++];
    inst->mode = (rst_mode)s->mode;
    inst->has_start = (int)s->has_start;
    inst->has_time = (int)s->has_time;
    inst->start_time = s->start_time;
    inst->next_time = s->next_time;
    inst->last_time = s->last_time;
    inst->last_step_status = RST_OK;
    if (inst->model->restore_state != NULL)
        status = front_backend_status(inst, inst->model->restore_state(inst));
    LEAVE(status);
}

rst_status front_free_state(void *c, const char *function, void **FMUstate)
{
    rst_state *s;
    ENTER(function, ANY_LIVE_MODE)
    if (FMUstate == NULL || *FMUstate == NULL)
        LEAVE(RST_OK); /* nothing to free */
    s = find_state(inst, *FMUstate);
    if (s == NULL) {
        rst_log(inst, RST_ERROR, "%s: the FMUstate is not a state of this instance", function);
        LEAVE(RST_ERROR);
    }
    unlink_state(inst, s);
    *FMUstate = NULL;
    LEAVE(RST_OK);
}

/* Serialized layout (little-endian whatever the platform):
 *   "RSTFMUST" | u32 format (2) | u32 len + model identifier | u32 len + GUID | u32 number of state
 *   variables | u32 mode (one rst_mode bit) | u32 has_start | u32 has_time | f64 start_time
 *   | f64 next_time | f64 last_time | per state variable: u32 value reference, u32 type, f64 value
 *   | u32 interface (0 co-simulation, 1 model exchange) | u64 FNV-1a of everything before.
 * Format 1 (no interface word) and any other version are refused. */
#define SERIAL_MAGIC "RSTFMUST"

static size_t serialized_size(const rst_instance *inst)
{
    return 8 + 4 + 4 + strlen(inst->model->identifier) + 4 + strlen(inst->model->guid) + 4 + 3 * 4 + 3 * 8 +
           inst->n_state * (4 + 4 + 8) + 4 + 8;
}

static void put_u32(unsigned char **p, uint32_t x)
{
    int i;
    for (i = 0; i < 4; i++)
        *(*p)++ = (unsigned char)(x >> (8 * i));
}

static void put_u64(unsigned char **p, uint64_t x)
{
    int i;
    for (i = 0; i < 8; i++)
        *(*p)++ = (unsigned char)(x >> (8 * i));
}

static void put_f64(unsigned char **p, double x)
{
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    put_u64(p, bits);
}

static void put_text(unsigned char **p, const char *text)
{
    size_t n = strlen(text);
    put_u32(p, (uint32_t)n);
    memcpy(*p, text, n);
    *p += n;
}

static uint64_t fnv1a(const unsigned char *bytes, size_t n)
{
    uint64_t hash = 14695981039346656037ull;
    size_t i;
    for (i = 0; i < n; i++) {
        hash ^= bytes[i];
        hash *= 1099511628211ull;
    }
    return hash;
}

rst_status front_serialized_size(void *c, const char *function, void *FMUstate, size_t *size)
{
    ENTER(function, ANY_LIVE_MODE)
    if (size == NULL || find_state(inst, FMUstate) == NULL) {
        rst_log(inst, RST_ERROR, "%s: %s", function, size == NULL ? "size is NULL"
                : "the FMUstate is not a state of this instance");
        LEAVE(RST_ERROR);
    }
    *size = serialized_size(inst);
    LEAVE(RST_OK);
}

rst_status front_serialize(void *c, const char *function, void *FMUstate, unsigned char serializedState[], size_t size)
{
    rst_state *s;
    unsigned char *p;
    size_t i, k = 0;
    ENTER(function, ANY_LIVE_MODE)
    s = find_state(inst, FMUstate);
    if (s == NULL || serializedState == NULL || size < serialized_size(inst)) {
        rst_log(inst, RST_ERROR, "%s: %s%s%s", function,
                s == NULL ? "the FMUstate is not a state of this instance"
                : serializedState == NULL ? "the byte array is NULL"
                : "the byte array is smaller than ", s != NULL && serializedState != NULL ?
                inst->api->serialized_state_size : "", s != NULL && serializedState != NULL ? " says" : "");
        LEAVE(RST_ERROR);
    }
    p = (unsigned char *)serializedState;
    memcpy(p, SERIAL_MAGIC, 8);
    p += 8;
    put_u32(&p, RST_STATE_FORMAT);
    put_text(&p, inst->model->identifier);
    put_text(&p, inst->model->guid);
    put_u32(&p, (uint32_t)inst->n_state);
    put_u32(&p, (uint32_t)s->mode);
    put_u32(&p, (uint32_t)s->has_start);
    put_u32(&p, (uint32_t)s->has_time);
    put_f64(&p, s->start_time);
    put_f64(&p, s->next_time);
    put_f64(&p, s->last_time);
    for (i = 0; i < inst->model->n_variables; i++)
        if (inst->model->variables[i].state) {
            put_u32(&p, (uint32_t)i);
            put_u32(&p, (uint32_t)inst->model->variables[i].type);
            put_f64(&p, s->values[k++]);
        }
    put_u32(&p, s->model_exchange);
    put_u64(&p, fnv1a((const unsigned char *)serializedState, (size_t)(p - (unsigned char *)serializedState)));
    LEAVE(RST_OK);
}

/* A reader that never goes past the end of the bytes. */
typedef struct {
    const unsigned char *p, *end;
    int ok;
} reader;

static uint64_t get_uint(reader *r, int n_bytes)
{
    uint64_t x = 0;
    int i;
    if (!r->ok || r->end - r->p < n_bytes) {
        r->ok = 0;
        return 0;
    }
    for (i = 0; i < n_bytes; i++)
        x |= (uint64_t)(*r->p++) << (8 * i);
    return x;
}

static double get_f64(reader *r)
{
    uint64_t bits = get_uint(r, 8);
    double x;
    memcpy(&x, &bits, sizeof x);
    return x;
}

static int get_text_equal(reader *r, const char *expected)
{
    uint64_t n = get_uint(r, 4);
    size_t m = strlen(expected);
    int equal;
    if (!r->ok || n > (uint64_t)(r->end - r->p)) {
        r->ok = 0;
        return 0;
    }
    equal = n == m && memcmp(r->p, expected, m) == 0;
    r->p += n;
    return equal;
}

/* Reads serialized bytes into the snapshot `s` (room for n_state values); NULL, or what is wrong (a
 * constant, or written into `why`). */
static const char *read_snapshot(const rst_instance *inst, const unsigned char bytes[], size_t size, rst_state *s,
                                 char *why, size_t why_size)
{
    reader r;
    size_t i, k = 0;
    uint64_t format;
    r.p = (const unsigned char *)bytes;
    r.end = r.p + size;
    r.ok = 1;
    if (size < 8 + 8 || memcmp(r.p, SERIAL_MAGIC, 8) != 0)
        return "these bytes are not a serialized state of this FMU (no RSTFMUST header)";
    r.p += size - 8;
    if (get_uint(&r, 8) != fnv1a((const unsigned char *)bytes, size - 8))
        return "the checksum does not match (truncated or corrupted bytes)";
    r.p = (const unsigned char *)bytes + 8;
    r.end = (const unsigned char *)bytes + size - 8;
    format = get_uint(&r, 4);
    if (format != RST_STATE_FORMAT && r.ok) {
        snprintf(why, why_size, "the state was written in another format version (%lu); this FMU reads only "
                 "format %u, which records the interface (take the state again with this FMU)",
                 (unsigned long)format, RST_STATE_FORMAT);
        return why;
    }
    if (!get_text_equal(&r, inst->model->identifier) && r.ok)
        return "the state belongs to another model";
    if (!get_text_equal(&r, inst->model->guid) && r.ok)
        return "the state belongs to another interface or version of this model (GUID differs)";
    if (get_uint(&r, 4) != inst->n_state && r.ok)
        return "the state has another number of variables";
    s->mode = (unsigned int)get_uint(&r, 4); /* the words as they are: check_snapshot judges them */
    s->has_start = (unsigned int)get_uint(&r, 4);
    s->has_time = (unsigned int)get_uint(&r, 4);
    s->start_time = get_f64(&r);
    s->next_time = get_f64(&r);
    s->last_time = get_f64(&r);
    for (i = 0; r.ok && i < inst->model->n_variables; i++) {
        if (!inst->model->variables[i].state)
            continue;
        if (get_uint(&r, 4) != i || get_uint(&r, 4) != (uint64_t)inst->model->variables[i].type)
            return r.ok ? "the state's variable list differs from this FMU's" : "the state is truncated";
        s->values[k++] = get_f64(&r);
    }
    s->model_exchange = (unsigned int)get_uint(&r, 4);
    if (!r.ok)
        return "the state is truncated";
    return r.p == r.end ? NULL : "the state has trailing bytes";
}

rst_status front_deserialize(void *c, const char *function, const unsigned char serializedState[], size_t size,
                             void **FMUstate)
{
    rst_state *s, *target;
    const char *problem;
    char why[256];
    ENTER(function, ANY_LIVE_MODE)
    if (serializedState == NULL || FMUstate == NULL) {
        rst_log(inst, RST_ERROR, "%s: NULL %s", function, serializedState == NULL ? "bytes" : "FMUstate pointer");
        LEAVE(RST_ERROR);
    }
    if (*FMUstate != NULL && find_state(inst, *FMUstate) == NULL) {
        rst_log(inst, RST_ERROR, "%s: *FMUstate is neither NULL nor a state of this instance", function);
        LEAVE(RST_ERROR);
    }
    s = (rst_state *)inst->allocate(1, state_bytes(inst));
    if (s == NULL) {
        rst_log(inst, RST_ERROR, "%s: out of memory", function);
        LEAVE(RST_ERROR);
    }
    problem = read_snapshot(inst, serializedState, size, s, why, sizeof why);
    if (problem != NULL)
        rst_log(inst, RST_ERROR, "%s: %s; nothing was changed", function, problem);
    /* checked like a set call before it may become a state */
    if (problem != NULL || !check_snapshot(inst, function, s) ||
        (target = target_state(inst, function, FMUstate)) == NULL) {
        inst->release(s);
        LEAVE(RST_ERROR);
    }
    s->magic = RST_STATE_MAGIC;
    s->next = target->next;
    memcpy(target, s, state_bytes(inst));
    inst->release(s);
    *FMUstate = target;
    LEAVE(RST_OK);
}
