/* The FMU binary a C harness loads (dlopen), and its functions by name. */
#ifndef FMU_LIBRARY_H
#define FMU_LIBRARY_H

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void *library;

static void *symbol(const char *name) {
    void *s = dlsym(library, name);
    if (!s) {
        fprintf(stderr, "%s not exported\n", name);
        exit(2);
    }
    return s;
}

typedef void (*AnyFunction)(void);

static AnyFunction function(const char *name) {
    void *s = symbol(name);
    AnyFunction f;
    memcpy(&f, &s, sizeof f); /* dlsym's object pointer as a function pointer (ISO C has no cast) */
    return f;
}

#endif
