/* The front's messages: formatting values as Python's repr() does, log categories, delivery to the
 * host's logger (through the version layer's emit), fmi2SetDebugLogging and fmi3SetDebugLogging. */
#include "rst_instance.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MESSAGE_SIZE 2048

enum { CAT_WARNING = 1, CAT_DISCARD = 2, CAT_ERROR = 4, CAT_FATAL = 8, CAT_ALL = 16 };
static const char *const CATEGORY_NAMES[] = {"logStatusWarning", "logStatusDiscard", "logStatusError",
                                             "logStatusFatal", "logAll"};
#define N_CATEGORIES 5

void rst_format_double(double x, char *out, size_t size)
{
    char buf[40], digits[24];
    int precision, exponent = 0, n_digits = 0, i;
    const char *p;
    if (isnan(x)) {
        snprintf(out, size, "nan");
        return;
    }
    if (isinf(x)) {
        snprintf(out, size, x > 0 ? "inf" : "-inf");
        return;
    }
    if (x == 0.0) {
        snprintf(out, size, signbit(x) ? "-0.0" : "0.0");
        return;
    }
    /* the shortest digit string that reads back as x (what repr() uses) */
    for (precision = 1; precision <= 17; precision++) {
        snprintf(buf, sizeof buf, "%.*e", precision - 1, x);
        if (strtod(buf, NULL) == x)
            break;
    }
    /* buf: [-]d[<decimal point>ddd]e(+|-)XX, whatever the locale's decimal point */
    for (p = buf; *p && *p != 'e'; p++)
        if (*p >= '0' && *p <= '9' && n_digits < (int)sizeof digits - 1)
            digits[n_digits++] = *p;
    digits[n_digits] = '\0';
    if (*p == 'e')
        exponent = atoi(p + 1);
    while (n_digits > 1 && digits[n_digits - 1] == '0')
        digits[--n_digits] = '\0';
    {
        char text[64];
        size_t k = 0;
        if (x < 0)
            text[k++] = '-';
        if (exponent >= -4 && exponent < 16) { /* positional, always with a fractional part */
            if (exponent < 0) {
                text[k++] = '0';
                text[k++] = '.';
                for (i = 0; i < -exponent - 1; i++)
                    text[k++] = '0';
                for (i = 0; i < n_digits; i++)
                    text[k++] = digits[i];
            } else {
                for (i = 0; i <= exponent; i++)
                    text[k++] = i < n_digits ? digits[i] : '0';
                text[k++] = '.';
                if (n_digits > exponent + 1)
                    for (i = exponent + 1; i < n_digits; i++)
                        text[k++] = digits[i];
                else
                    text[k++] = '0';
            }
            text[k] = '\0';
        } else { /* d[.ddd]e+XX with at least two exponent digits */
            text[k++] = digits[0];
            if (n_digits > 1) {
                text[k++] = '.';
                for (i = 1; i < n_digits; i++)
                    text[k++] = digits[i];
            }
            snprintf(text + k, sizeof text - k, "e%c%02d", exponent < 0 ? '-' : '+', exponent < 0 ? -exponent : exponent);
        }
        snprintf(out, size, "%s", text);
    }
}

static unsigned int category_of(rst_status status)
{
    switch (status) {
    case RST_WARNING: return CAT_WARNING;
    case RST_DISCARD: return CAT_DISCARD;
    case RST_ERROR: return CAT_ERROR;
    case RST_FATAL: return CAT_FATAL;
    default: return CAT_ALL;
    }
}

static const char *category_name(unsigned int bit)
{
    int i;
    for (i = 0; i < N_CATEGORIES; i++)
        if (bit == (1u << i))
            return CATEGORY_NAMES[i];
    return "logAll";
}

/* During a call (the instance locked) the message waits until the call has released the lock
 * (front_unlock); otherwise, in instantiation and freeing, it goes to the logger at once. */
static void deliver(rst_instance *inst, rst_status status, const char *category, const char *text)
{
    size_t k, n_category;
    rst_message *message;
    if (inst->host_logger == NULL)
        return;
    if (status == RST_OK) {
        unsigned int bit = CAT_ALL;
        int i;
        for (i = 0; category && i < N_CATEGORIES; i++)
            if (strcmp(category, CATEGORY_NAMES[i]) == 0)
                bit = 1u << i;
        if (!inst->logging_on || !(inst->categories & bit))
            return;
    }
    if (!inst->in_call) {
        inst->api->emit(inst->host_logger, inst->environment, inst->name, status, category, text);
        return;
    }
    k = strlen(text);
    n_category = strlen(category);
    message = (rst_message *)inst->allocate(1, sizeof *message + k + n_category + 1);
    if (message == NULL)
        return; /* out of memory: the call's status still tells the host what happened */
    memcpy(message->text, text, k + 1);
    memcpy(message->text + k + 1, category, n_category + 1);
    message->category = message->text + k + 1;
    message->status = status;
    message->next = NULL;
    *inst->pending_end = message;
    inst->pending_end = &message->next;
}

rst_message *front_take_messages(rst_instance *inst)
{
    rst_message *messages = inst->pending;
    inst->pending = NULL;
    inst->pending_end = &inst->pending;
    return messages;
}

/* Called without the lock: the logger may call this instance again. */
void front_deliver_messages(rst_instance *inst, rst_message *messages)
{
    const rst_api *api = inst->api;
    void (*logger)(void) = inst->host_logger;
    void *environment = inst->environment;
    rst_release_fn release = inst->release;
    const char *name = inst->name;
    while (messages != NULL) {
        rst_message *next = messages->next;
        api->emit(logger, environment, name, messages->status, messages->category, messages->text);
        release(messages);
        messages = next;
    }
}

void rst_log_text(rst_instance *inst, rst_status status, const char *category, const char *text)
{
    deliver(inst, status, category ? category : category_name(category_of(status)), text ? text : "");
}

void rst_log(rst_instance *inst, rst_status status, const char *format, ...)
{
    char message[MESSAGE_SIZE];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    deliver(inst, status, category_name(category_of(status)), message);
}

rst_status front_set_debug_logging(void *c, const char *function, int logging_on, size_t n,
                                   const char *const categories[])
{
    size_t i;
    unsigned int bits = 0;
    int k;
    ENTER(function, ANY_LIVE_MODE)
    if (n > 0 && categories == NULL) {
        rst_log(inst, RST_ERROR, "%s: %u categories but a NULL array", function, (unsigned int)n);
        LEAVE(RST_ERROR);
    }
    for (i = 0; i < n; i++) {
        int found = 0;
        for (k = 0; categories[i] != NULL && k < N_CATEGORIES; k++)
            if (strcmp(categories[i], CATEGORY_NAMES[k]) == 0) {
                bits |= 1u << k;
                found = 1;
            }
        if (!found) {
            rst_log(inst, RST_ERROR, "%s: unknown log category %s (this FMU has logStatusWarning, "
                    "logStatusDiscard, logStatusError, logStatusFatal and logAll)", function,
                    categories[i] ? categories[i] : "(NULL)");
            LEAVE(RST_ERROR);
        }
    }
    inst->logging_on = logging_on != 0;
    inst->categories = n > 0 ? bits : RST_ALL_CATEGORIES;
    LEAVE(RST_OK);
}
