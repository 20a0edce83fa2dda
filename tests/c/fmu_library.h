/* The FMU binary a C harness loads (dlopen, or LoadLibrary on Windows),
 * and its functions by name. The path "-" is the harness itself, with
 * source FMUs linked in (exported: -rdynamic), their functions named with
 * function_prefix (FMI2_FUNCTION_PREFIX, FMI3_FUNCTION_PREFIX). */
#ifndef FMU_LIBRARY_H
#define FMU_LIBRARY_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _WIN32
#include <windows.h>
#else
#include <dlfcn.h>
#endif

typedef void (*AnyFunction)(void);

static const char *function_prefix = "";

/* prefix and name: the function's name in the binary */
static const char *full_name(const char *name) {
    static char full[200];
    if (strlen(function_prefix) + strlen(name) >= sizeof full) {
        fprintf(stderr, "function name too long: %s%s\n", function_prefix, name);
        exit(2);
    }
    strcpy(full, function_prefix);
    return strcat(full, name);
}

#ifdef _WIN32
static HMODULE library;

static int open_library(const char *path) {
    library = strcmp(path, "-") == 0 ? GetModuleHandleA(NULL) : LoadLibraryA(path);
    if (!library) fprintf(stderr, "cannot load %s (error %lu)\n", path, (unsigned long)GetLastError());
    return library != NULL;
}

static AnyFunction function(const char *name) {
    name = full_name(name);
    FARPROC f = GetProcAddress(library, name);
    if (!f) {
        fprintf(stderr, "%s not exported\n", name);
        exit(2);
    }
    return (AnyFunction)f;
}
#else
static void *library;

static int open_library(const char *path) {
    library = dlopen(strcmp(path, "-") == 0 ? NULL : path, RTLD_NOW | RTLD_LOCAL);
    if (!library) fprintf(stderr, "%s\n", dlerror());
    return library != NULL;
}

static void *symbol(const char *name) {
    name = full_name(name);
    void *s = dlsym(library, name);
    if (!s) {
        fprintf(stderr, "%s not exported\n", name);
        exit(2);
    }
    return s;
}

static AnyFunction function(const char *name) {
    void *s = symbol(name);
    AnyFunction f;
    memcpy(&f, &s, sizeof f); /* dlsym's object pointer as a function pointer (ISO C has no cast) */
    return f;
}
#endif

#endif
