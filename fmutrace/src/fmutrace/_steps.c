/* fmutrace's step loop in C: the calls runner._steps_python makes, in its
 * order and with its checks, through the FMU's own FMI functions (the
 * pointers the runner takes from the library fmpy loaded). The runner calls
 * fmutrace_steps through cffi; a step costs the FMU's calls and a few
 * loads, where Python's loop costs about 0.6 us.
 *
 * Built as an extension module so that setuptools compiles and installs
 * it beside the package (optional: without a compiler the runner keeps
 * its Python loop, which a test holds equal to this one bit for bit). */
#include <Python.h>
#include <stdbool.h>
#include <stddef.h>

typedef int (*fmi2_values)(void *, const unsigned int *, size_t, void *);
typedef int (*fmi3_values)(void *, const unsigned int *, size_t, void *, size_t);
typedef int (*fmi2_do_step)(void *, double, double, int);
typedef int (*fmi3_do_step)(void *, double, double, bool, bool *, bool *, bool *, double *);
typedef void (*any_function)(void); /* a function pointer of either kind, cast back before the call */

/* One fmi{2,3}{Set,Get}<Type> call per step: its value references and a
 * table of rows, one row of count values per call. */
typedef struct {
    any_function function;
    const unsigned int *vrs;
    size_t count;
    char *rows;          /* row 0 */
    ptrdiff_t row_bytes; /* from a row to the next */
} fmutrace_calls;

/* What FMI 3's doStep returns beside its status. */
typedef struct {
    bool event, terminate, early;
    double last;
} step_flags;

#ifdef _WIN32
#define FMUTRACE_EXPORT __declspec(dllexport)
#else
#define FMUTRACE_EXPORT __attribute__((visibility("default")))
#endif

/* run_steps is compiled once per FMI version, its calls as constants: the
 * version is chosen once per run, not at every call. */
#if defined(_MSC_VER)
#define ALWAYS_INLINE static __forceinline
#elif defined(__GNUC__)
#define ALWAYS_INLINE static inline __attribute__((always_inline))
#else
#define ALWAYS_INLINE static inline
#endif

static int fmi2_values_call(const fmutrace_calls *c, void *component, char *values) {
    return ((fmi2_values)c->function)(component, c->vrs, c->count, values);
}

static int fmi3_values_call(const fmutrace_calls *c, void *component, char *values) {
    return ((fmi3_values)c->function)(component, c->vrs, c->count, values, c->count);
}

static int fmi2_step(any_function do_step, void *component, double t, double h, step_flags *flags) {
    (void)flags;
    return ((fmi2_do_step)do_step)(component, t, h, 1);
}

/* A step that asks to terminate or returns early counts as an Error. */
static int fmi3_step(any_function do_step, void *component, double t, double h, step_flags *f) {
    int status = ((fmi3_do_step)do_step)(component, t, h, true, &f->event, &f->terminate, &f->early, &f->last);
    return f->terminate || f->early ? 3 : status;
}

typedef int (*values_call)(const fmutrace_calls *, void *, char *);
typedef int (*step_call)(any_function, void *, double, double, step_flags *);

/* Runs steps from times[k] by sizes[k]: before step k, if set_at[k] >= 0,
 * every setter with its row set_at[k]; then doStep; then every getter into
 * its row k (a size of 0: no doStep). Statuses are OR-ed per step as the Python loop does; a status
 * above Warning stops the loop. Returns the number of steps done (steps if
 * all were). */
ALWAYS_INLINE size_t run_steps(values_call values, step_call step, any_function do_step, void *component,
                               const double *times, const double *sizes, size_t steps, const long long *set_at,
                               const fmutrace_calls *setters, size_t n_setters, const fmutrace_calls *getters,
                               size_t n_getters) {
    step_flags flags = { false, false, false, 0.0 };
    for (size_t k = 0; k < steps; k++) {
        int status = 0;
        if (set_at[k] >= 0) {
            for (size_t i = 0; i < n_setters; i++)
                status |= values(&setters[i], component, setters[i].rows + (ptrdiff_t)set_at[k] * setters[i].row_bytes);
            if (status > 1) return k;
        }
        /* a size of 0 is a cycle that did not run (recorded cycle lengths): no doStep, the outputs held */
        status = sizes[k] != 0 ? step(do_step, component, times[k], sizes[k], &flags) : 0;
        for (size_t i = 0; i < n_getters; i++)
            status |= values(&getters[i], component, getters[i].rows + (ptrdiff_t)k * getters[i].row_bytes);
        if (status > 1) return k;
    }
    return steps;
}

/* run_steps with the calls of FMI version fmi_version (2 or 3). */
FMUTRACE_EXPORT size_t fmutrace_steps(int fmi_version, any_function do_step, void *component, const double *times,
                                      const double *sizes, size_t steps, const long long *set_at,
                                      const fmutrace_calls *setters, size_t n_setters, const fmutrace_calls *getters,
                                      size_t n_getters) {
    if (fmi_version == 3)
        return run_steps(fmi3_values_call, fmi3_step, do_step, component, times, sizes, steps, set_at, setters,
                         n_setters, getters, n_getters);
    return run_steps(fmi2_values_call, fmi2_step, do_step, component, times, sizes, steps, set_at, setters, n_setters,
                     getters, n_getters);
}

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_steps", "fmutrace's step loop (called through cffi)", -1, NULL, NULL, NULL, NULL, NULL
};

PyMODINIT_FUNC PyInit__steps(void) {
    return PyModule_Create(&module);
}
