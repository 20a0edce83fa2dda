/* fmutrace's reader of plain CSV rows in C: the data lines of the plain
 * dialect (numbers separated by ',') into a table of doubles, for
 * traces.trace_chunks. pyarrow's reader costs about 0.2 ms a call whatever
 * the size, most of a short case's reading; this costs the numbers.
 *
 * It takes the common form only: each cell a decimal number
 * [+-]digits[.digits][(e|E)[+-]digits] (a digit before or after the
 * point), lines ended by \n or \r\n, empty lines skipped. At anything else
 * it stops and says where, and the caller gives the block to pyarrow. A
 * number is correctly rounded, as pyarrow's and Python's are: exactly
 * representable digits by Clinger's fast path (one rounding), the others
 * by the C library's strtod, whose stop must be the cell's end (a locale
 * with another decimal point stops it early: the block goes to pyarrow).
 *
 * Built as an extension module so that setuptools compiles and installs it
 * beside the package; called through cffi (optional: without it, pyarrow
 * reads every block, the same values). */
#ifndef FMUTRACE_ROWS_ALONE /* (the fuzzer builds the reader without Python) */
#include <Python.h>
#endif
#include <float.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#ifdef _WIN32
#define FMUTRACE_EXPORT __declspec(dllexport)
#else
#define FMUTRACE_EXPORT __attribute__((visibility("default")))
#endif

/* Clinger's fast path needs doubles evaluated as doubles, not in wider registers (x87). */
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0
#define EXACT_DOUBLES 1
#else
#define EXACT_DOUBLES 0
#endif

/* Powers of ten that are exact doubles (10^22 is the last). */
static const double exact_powers[] = { 1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                       1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22 };

static int is_digit(char c) {
    return c >= '0' && c <= '9';
}

/* The number in text[0, end) into *value; 0 if the cell is not of the
 * common form (or strtod does not take it whole). */
static int cell_value(const char *text, const char *end, double *value) {
    const char *p = text;
    int negative = 0;
    if (p < end && (*p == '+' || *p == '-')) negative = *p++ == '-';
    /* (counts in 64 bits: a cell may be longer than an int counts) */
    uint64_t digits = 0;     /* the significant digits, while they are at most 19 */
    int64_t significant = 0; /* how many: leading zeros do not count */
    int64_t shift = 0;       /* the power of ten of the digits' last one */
    int64_t seen = 0;        /* digits before or after the point */
    for (; p < end && is_digit(*p); p++, seen++) {
        if (significant || *p != '0') {
            if (++significant <= 19) digits = digits * 10 + (uint64_t)(*p - '0');
            else shift++;
        }
    }
    if (p < end && *p == '.') {
        for (p++; p < end && is_digit(*p); p++, seen++) {
            if (significant || *p != '0') {
                if (++significant <= 19) {
                    digits = digits * 10 + (uint64_t)(*p - '0');
                    shift--;
                }
            } else {
                shift--;
            }
        }
    }
    if (!seen) return 0;
    int exponent = 0;
    int64_t exponent_digits = 0;
    if (p < end && (*p == 'e' || *p == 'E')) {
        p++;
        int exponent_negative = 0;
        if (p < end && (*p == '+' || *p == '-')) exponent_negative = *p++ == '-';
        for (; p < end && is_digit(*p); p++)
            if (++exponent_digits <= 6) exponent = exponent * 10 + (*p - '0');
        if (!exponent_digits) return 0;
        if (exponent_negative) exponent = -exponent;
    }
    if (p != end) return 0;
    /* exact digits times an exact power of ten: one rounding, correctly rounded */
    if (EXACT_DOUBLES && significant <= 15 && exponent_digits <= 6) {
        int64_t power = digits ? shift + exponent : 0; /* (zero times any power is zero) */
        if (power >= -22 && power <= 22) {
            double magnitude = (double)digits;
            if (power > 0) magnitude *= exact_powers[power];
            else if (power < 0) magnitude /= exact_powers[-power];
            *value = negative ? -magnitude : magnitude;
            return 1;
        }
    }
    char copy[64]; /* strtod wants a terminated string: a cell's own copy */
    size_t length = (size_t)(end - text);
    char *stop = NULL;
    if (length < sizeof copy) {
        for (size_t i = 0; i < length; i++) copy[i] = text[i];
        copy[length] = '\0';
        *value = strtod(copy, &stop);
        return stop == copy + length;
    }
    char *long_copy = (char *)malloc(length + 1);
    if (!long_copy) return 0;
    for (size_t i = 0; i < length; i++) long_copy[i] = text[i];
    long_copy[length] = '\0';
    *value = strtod(long_copy, &stop);
    int whole = stop == long_copy + length;
    free(long_copy);
    return whole;
}

/* Reads the lines of text[0, length) into rows: row r's value of column c
 * at rows[r * columns + field_of[c]]; at most max_rows rows. Returns the
 * number of rows read; *stopped_at is length when every line was read,
 * else the offset of the line it could not read (a cell that is not of the
 * common form, a line of another number of cells, more than max_rows). */
FMUTRACE_EXPORT size_t fmutrace_plain_rows(const char *text, size_t length, size_t columns, const size_t *field_of,
                                           double *rows, size_t max_rows, size_t *stopped_at) {
    const char *end = text + length, *line = text;
    size_t row = 0;
    while (line < end) {
        const char *line_end = line;
        while (line_end < end && *line_end != '\n') line_end++;
        const char *content_end = line_end > line && line_end[-1] == '\r' ? line_end - 1 : line_end;
        if (content_end > line) { /* (an empty line is skipped, as pyarrow skips it) */
            if (row == max_rows) break;
            double *values = rows + row * columns;
            const char *cell = line;
            int whole = 0; /* every column's cell read, and no more cells */
            for (size_t column = 0; column < columns; column++) {
                const char *cell_end = cell;
                while (cell_end < content_end && *cell_end != ',') cell_end++;
                if (!cell_value(cell, cell_end, &values[field_of[column]])) break;
                if (cell_end == content_end) {
                    whole = column + 1 == columns;
                    break;
                }
                cell = cell_end + 1;
            }
            if (!whole) break;
            row++;
        }
        line = line_end < end ? line_end + 1 : end;
    }
    *stopped_at = line < end ? (size_t)(line - text) : length;
    return row;
}

#ifndef FMUTRACE_ROWS_ALONE
static struct PyModuleDef module = { PyModuleDef_HEAD_INIT,
                                     "_rows",
                                     "fmutrace's reader of plain CSV rows (called through cffi)",
                                     -1,
                                     NULL,
                                     NULL,
                                     NULL,
                                     NULL,
                                     NULL };

PyMODINIT_FUNC PyInit__rows(void) {
    return PyModule_Create(&module);
}
#endif
