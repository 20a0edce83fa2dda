/* The FMU binary a C harness loads (dlopen, or LoadLibrary on Windows),
 * and its functions by name. */
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

#ifdef _WIN32
static HMODULE library;

static int open_library(const char *path) {
    library = LoadLibraryA(path);
    if (!library) fprintf(stderr, "cannot load %s (error %lu)\n", path, (unsigned long)GetLastError());
    return library != NULL;
}

static AnyFunction function(const char *name) {
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
    library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!library) fprintf(stderr, "%s\n", dlerror());
    return library != NULL;
}

static void *symbol(const char *name) {
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
