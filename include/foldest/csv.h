/* SPDX-License-Identifier: MIT */
/* Tangled from literate/csv.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/csv.org::CSV Reader Declarations][CSV Reader Declarations]] */
#ifndef FOLDEST_CSV_H
#define FOLDEST_CSV_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Where a reader gets its bytes, when not from a file descriptor: like
   read(2), up to n bytes into buf; returns the count, 0 at the end, or -1
   with errno set (EINTR: called again). */
typedef long fe_csv_read_fn(void *ctx, char *buf, size_t n);

/* A line reader over a file descriptor or a read function, through a
   caller buffer. */
typedef struct fe_csv_reader {
    int fd;
    fe_csv_read_fn *read;       /* NULL: read(2) from fd */
    void *read_ctx;
    char *buf;
    size_t cap, len, pos;
    size_t line;                /* number of the line last returned, from 1 */
    int eof;
    int skipping;               /* discarding the rest of a too-long line */
} fe_csv_reader;

/* fe_csv_reader_init: read from `fd` (the caller's to close) through
   `buffer` of `cap` bytes; `cap` - 2 bytes is the longest line accepted
   (a CR before its LF counted: `cap` - 3 characters of a CRLF line).  A
   UTF-8 byte-order mark at the start of the input is skipped. */
int fe_csv_reader_init(fe_csv_reader *r, int fd, char *buffer, size_t cap);

/* fe_csv_reader_init_read: the same, reading through `fn(ctx, ...)` (a
   decompressor, say) instead of a file descriptor.  FE_EINVAL for NULL. */
int fe_csv_reader_init_read(fe_csv_reader *r, fe_csv_read_fn *fn, void *ctx,
                            char *buffer, size_t cap);

/* fe_csv_next_line: point *line at the next line, NUL-terminated, without
   its line end (LF or CRLF); *len is its length.  The line lives in the
   reader's buffer until the next call and may be modified (fe_csv_split
   does).  Returns FE_OK, FE_END at end of input, FE_ESIZE for a line longer
   than the buffer, FE_EPARSE for a NUL byte (binary input), FE_EIO for a
   read error.  r->line is the line's number in every case. */
int fe_csv_next_line(fe_csv_reader *r, char **line, size_t *len);
/* CSV Reader Declarations ends here */
/* [[file:../../literate/csv.org::CSV Field Declarations][CSV Field Declarations]] */
/* FE_CSV_WHITESPACE as a delimiter: split at runs of spaces and tabs. */
#define FE_CSV_WHITESPACE ' '

typedef struct fe_csv_field {
    char *text;                 /* NUL-terminated, inside the line */
    size_t column;              /* byte column where the field starts, from 1 */
} fe_csv_field;

/* fe_csv_guess_delimiter: ';' if the line has one, else ',' or '\t' (the
   first the line contains), else FE_CSV_WHITESPACE. */
char fe_csv_guess_delimiter(const char *line);

/* fe_csv_split: split `line` in place into at most `max` fields.
   *count receives the number of fields.  Errors: FE_ESIZE when the line
   has more than `max` fields (*count is then max + 1), FE_EPARSE for an
   unterminated quote or text after a closing quote (*bad_column receives
   its column, if bad_column is not NULL). */
int fe_csv_split(char *line, char delimiter, fe_csv_field *fields,
                 size_t max, size_t *count, size_t *bad_column);

/* fe_csv_number: parse a whole field as a finite double: a plain decimal,
   [+-] digits [. digits] [(e|E) [+-] digits] with at least one digit
   before the exponent.  FE_EPARSE when it is empty or anything else
   (hexadecimal, text, spaces inside); FE_ENONFINITE for "nan", "inf",
   "infinity" (any case, signed or not) and values that overflow. */
int fe_csv_number(const fe_csv_field *field, double *value);

/* fe_csv_number_comma: the same with a decimal comma: "1,5" is 1.5 and a
   point is not accepted.  A field of more than 255 bytes is FE_EPARSE. */
int fe_csv_number_comma(const fe_csv_field *field, double *value);

/* fe_csv_numbers: a line that holds nothing but plain decimals, as
   fe_csv_number's fast path reads them (at most 19 digits, an exponent
   within 10^22), separated by `delimiter`, read in one pass: values[0 ..
   *count - 1], the line unchanged.  FE_EPARSE as soon as a field is
   anything else (empty, quoted, padded with spaces, a word, more digits):
   *count is then the number of fields read before it, and the caller
   splits the line and reads it field by field (fe_csv_split,
   fe_csv_number), which gives the same values where both succeed, and
   says what is wrong.  FE_ESIZE when a number follows the max-th field
   (*count is then max + 1): the first fault in the line decides.
   FE_EINVAL for a NULL argument, or a delimiter
   that is FE_CSV_WHITESPACE, the NUL, or a byte a number may hold (a
   digit, a sign, the point, 'e' or 'E'). */
int fe_csv_numbers(const char *line, char delimiter, double *values, size_t max,
                   size_t *count);

/* Both read the same numbers whatever locale the calling program set
   (setlocale's LC_NUMERIC): a recording's decimal mark is the file's, not
   the reader's.  In a locale whose decimal mark is not '.', a decimal
   that the fast path does not take (over 19 digits, or an exponent past
   10^22) and that does not fit in FE_CSV_NUMBER_MAX bytes with that mark
   for its point and a NUL (FE_CSV_NUMBER_MAX - 1 characters for a
   one-byte mark) is FE_EPARSE. */
#define FE_CSV_NUMBER_MAX 512

/* fe_csv_format_double: v as the shortest of 15, 16 and 17 significant
   digits (printf's %.*g) that reads back as v, with '.' as its decimal
   mark whatever the locale: the text a JSON document or a CSV file needs.
   buf holds at least FE_CSV_DOUBLE_TEXT bytes.  FE_EINVAL for a NULL buf,
   FE_ESIZE for a shorter one, FE_ENONFINITE for NaN or an infinity (buf
   then holds ""). */
#define FE_CSV_DOUBLE_TEXT 32
int fe_csv_format_double(double v, char *buf, size_t len);

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_CSV_H */
/* CSV Field Declarations ends here */
