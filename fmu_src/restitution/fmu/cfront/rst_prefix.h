/* Source FMUs compiled into one simulator binary with FMI2_FUNCTION_PREFIX: the standard FMI 2.0
 * headers then prefix the fmi2 functions, and RST_PREFIXED does the same for every other external
 * symbol of this project's C files (each header renames its own), so several FMUs of this project
 * link into one executable. Without FMI2_FUNCTION_PREFIX the names stay as written. */
#ifndef RST_PREFIX_H
#define RST_PREFIX_H

#if defined(FMI2_FUNCTION_PREFIX)
#define RST_PASTE_(a, b) a##b
#define RST_PASTE(a, b) RST_PASTE_(a, b)
#define RST_PREFIXED(name) RST_PASTE(FMI2_FUNCTION_PREFIX, name)
#endif

#endif
