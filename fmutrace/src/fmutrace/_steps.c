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

#ifdef _WIN32
#define FMUTRACE_EXPORT __declspec(dllexport)
#else
#define FMUTRACE_EXPORT __attribute__((visibility("default")))
#endif

static int values_call(int fmi3, const fmutrace_calls *c, void *component, size_t row)
{
    char *values = c->rows + (ptrdiff_t)row * c->row_bytes;
    return fmi3 ? ((fmi3_values)c->function)(component, c->vrs, c->count, values, c->count)
                : ((fmi2_values)c->function)(component, c->vrs, c->count, values);
}

/* Runs steps from times[k] by sizes[k]: before step k, if set_at[k] >= 0,
 * every setter with its row set_at[k]; then doStep; then every getter into
 * its row k. Statuses are OR-ed per step as the Python loop does; a status
 * above Warning (or an FMI 3 step asking to terminate or returning early)
 * stops the loop. Returns the number of steps done (steps if all were). */
FMUTRACE_EXPORT size_t fmutrace_steps(int fmi3, any_function do_step, void *component, const double *times,
                                      const double *sizes, size_t steps, const long long *set_at,
                                      const fmutrace_calls *setters, size_t n_setters,
                                      const fmutrace_calls *getters, size_t n_getters)
{
    bool event = false, terminate = false, early = false;
    double last = 0.0;
    for (size_t k = 0; k < steps; k++) {
        int status = 0;
        if (set_at[k] >= 0) {
            for (size_t i = 0; i < n_setters; i++)
                status |= values_call(fmi3, &setters[i], component, (size_t)set_at[k]);
            if (status > 1)
                return k;
        }
        status = fmi3 ? ((fmi3_do_step)do_step)(component, times[k], sizes[k], true, &event, &terminate, &early,
                                                &last)
                      : ((fmi2_do_step)do_step)(component, times[k], sizes[k], 1);
        for (size_t i = 0; i < n_getters; i++)
            status |= values_call(fmi3, &getters[i], component, k);
        if (status > 1 || terminate || early)
            return k;
    }
    return steps;
}

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_steps", "fmutrace's step loop (called through cffi)",
                                    -1, NULL, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__steps(void)
{
    return PyModule_Create(&module);
}
