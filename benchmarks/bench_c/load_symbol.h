/* load_symbol.h - LOAD(target, name) for the benchmark hosts in this folder: a function pointer from
 * dlsym into ``target`` without the object-to-function pointer cast ISO C forbids. The including file
 * defines ``symbol(f, name)`` (its FMU handle ``f`` in scope; a missing symbol ends the program its way). */
#ifndef LOAD_SYMBOL_H
#define LOAD_SYMBOL_H

#include <string.h>

#define LOAD(target, name)                 \
    do {                                   \
        void *p_ = symbol(f, name);        \
        memcpy(&(target), &p_, sizeof p_); \
    } while (0)

#endif
