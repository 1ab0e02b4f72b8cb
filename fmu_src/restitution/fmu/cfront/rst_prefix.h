/* Source FMUs compiled into one simulator binary with FMI2_FUNCTION_PREFIX (FMI 2.0) or
 * FMI3_FUNCTION_PREFIX (FMI 3.0): the standard FMI headers then prefix the FMI functions, and
 * RST_PREFIXED does the same for every other external symbol of this project's C files (each header
 * renames its own), so several FMUs of this project link into one executable. Without a prefix the
 * names stay as written. */
#ifndef RST_PREFIX_H
#define RST_PREFIX_H

#if defined(FMI2_FUNCTION_PREFIX) || defined(FMI3_FUNCTION_PREFIX)
#define RST_PASTE_(a, b) a##b
#define RST_PASTE(a, b) RST_PASTE_(a, b)
#if defined(FMI2_FUNCTION_PREFIX)
#define RST_PREFIXED(name) RST_PASTE(FMI2_FUNCTION_PREFIX, name)
#else
#define RST_PREFIXED(name) RST_PASTE(FMI3_FUNCTION_PREFIX, name)
#endif
#endif

#endif
