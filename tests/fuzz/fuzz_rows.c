/* libFuzzer target: arbitrary bytes as the data lines of a plain CSV file,
 * read by fmutrace's reader of plain rows (fmutrace/_rows.c). Its first
 * byte chooses the number of columns (1 to 4). Every row the reader took is
 * checked against the C library's strtod, cell by cell and bit for bit, and
 * where it stopped must be the start of a line. Built with ASan and UBSan,
 * so any memory or undefined-behaviour fault stops the run. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define FMUTRACE_ROWS_ALONE
#include "_rows.c"

static void check_cell(const char *cell, size_t length, double value) {
    char *copy = (char *)malloc(length + 1);
    memcpy(copy, cell, length);
    copy[length] = '\0';
    char *stop = NULL;
    double expected = strtod(copy, &stop);
    if (stop != copy + length || memcmp(&expected, &value, sizeof value) != 0) abort();
    free(copy);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    if (size < 1) return 0;
    size_t columns = 1 + data[0] % 4;
    const char *text = (const char *)data + 1;
    size_t length = size - 1;
    size_t max_rows = 1;
    for (size_t i = 0; i < length; i++) max_rows += text[i] == '\n';
    size_t field_of[4] = { 0, 1, 2, 3 };
    double *rows = (double *)malloc(max_rows * columns * sizeof(double));
    size_t stopped_at = length + 1;
    size_t read = fmutrace_plain_rows(text, length, columns, field_of, rows, max_rows, &stopped_at);
    if (read > max_rows || stopped_at > length ||
        (stopped_at > 0 && stopped_at < length && text[stopped_at - 1] != '\n'))
        abort();
    /* the rows read: the non-empty lines before stopped_at, each of columns cells */
    size_t row = 0;
    const char *line = text, *end = text + stopped_at;
    while (line < end) {
        const char *line_end = (const char *)memchr(line, '\n', (size_t)(end - line));
        if (!line_end) line_end = end;
        const char *content_end = line_end > line && line_end[-1] == '\r' ? line_end - 1 : line_end;
        if (content_end > line) {
            if (row >= read) abort();
            const char *cell = line;
            for (size_t column = 0; column < columns; column++) {
                const char *cell_end = cell;
                while (cell_end < content_end && *cell_end != ',') cell_end++;
                if ((cell_end == content_end) != (column + 1 == columns)) abort();
                check_cell(cell, (size_t)(cell_end - cell), rows[row * columns + column]);
                cell = cell_end + 1;
            }
            row++;
        }
        line = line_end + 1;
    }
    if (row != read) abort();
    free(rows);
    return 0;
}
