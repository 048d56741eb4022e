/* SPDX-License-Identifier: MIT */
/* Tangled from literate/csv.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/csv.org::CSV Includes][CSV Includes]] */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "foldest/csv.h"
#include "foldest/error.h"
#include "csv_private.h"

/* The split's fast path: SSE2, which every x86-64 processor has, with a
   compiler that offers its intrinsics and __builtin_ctzll; FE_CSV_PORTABLE
   builds without it. */
#if defined(__SSE2__) && defined(__GNUC__) && !defined(FE_CSV_PORTABLE)
#include <emmintrin.h>
#define FE__CSV_SSE2 1
#else
#define FE__CSV_SSE2 0
#endif
/* CSV Includes ends here */
/* [[file:../literate/csv.org::Read one line][Read one line]] */
int fe_csv_reader_init(fe_csv_reader *r, int fd, char *buffer, size_t cap)
{
    if (r == NULL || fd < 0 || buffer == NULL || cap < 2)
        return FE_EINVAL;
    r->fd = fd;
    r->read = NULL;
    r->read_ctx = NULL;
    r->buf = buffer;
    r->cap = cap;
    r->len = r->pos = 0;
    r->line = 0;
    r->eof = 0;
    r->skipping = 0;
    return FE_OK;
}

int fe_csv_reader_init_read(fe_csv_reader *r, fe_csv_read_fn *fn, void *ctx,
                            char *buffer, size_t cap)
{
    int rc;
    if (fn == NULL)
        return FE_EINVAL;
    rc = fe_csv_reader_init(r, 0, buffer, cap);
    if (rc == FE_OK) {
        r->fd = -1;
        r->read = fn;
        r->read_ctx = ctx;
    }
    return rc;
}

/* Move the unread bytes to the front and read until the buffer is full
   or the input ends. */
static int fe__csv_refill(fe_csv_reader *r)
{
    size_t left = r->len - r->pos;
    if (left > 0 && r->pos > 0)
        memmove(r->buf, r->buf + r->pos, left);
    r->len = left;
    r->pos = 0;
    while (!r->eof && r->len < r->cap - 1) {
        ssize_t got = r->read != NULL
                          ? (ssize_t)r->read(r->read_ctx, r->buf + r->len, r->cap - 1 - r->len)
                          : read(r->fd, r->buf + r->len, r->cap - 1 - r->len);
        if (got < 0) {
            if (errno == EINTR)
                continue;
            return FE_EIO;
        }
        if (got == 0)
            r->eof = 1;
        r->len += (size_t)got;
        if (memchr(r->buf + r->len - (size_t)got, '\n', (size_t)got) != NULL)
            break;
    }
    return FE_OK;
}

int fe_csv_next_line(fe_csv_reader *r, char **line, size_t *len)
{
    char *start, *nl;
    size_t n;

    if (r == NULL || line == NULL || len == NULL)
        return FE_EINVAL;
    while (r->skipping) {       /* the tail of a line reported too long */
        nl = memchr(r->buf + r->pos, '\n', r->len - r->pos);
        if (nl != NULL) {
            r->pos = (size_t)(nl - r->buf) + 1;
            r->skipping = 0;
        } else {
            int rc;
            r->pos = r->len;            /* all of it is the tail: dropped */
            rc = fe__csv_refill(r);     /* at the end of the input: nothing */
            if (rc != FE_OK)
                return rc;
            if (r->len == 0)            /* the input ended inside the line */
                r->skipping = 0;
        }
    }
    nl = memchr(r->buf + r->pos, '\n', r->len - r->pos);
    if (nl == NULL) {
        int rc = fe__csv_refill(r);
        if (rc != FE_OK)
            return rc;
        nl = memchr(r->buf + r->pos, '\n', r->len - r->pos);
        if (nl == NULL && r->len == 0)
            return FE_END;
        if (nl == NULL && !r->eof) {
            r->line++;
            r->pos = r->len = 0;        /* drop what we could not hold */
            r->skipping = 1;
            return FE_ESIZE;
        }
    }
    r->line++;
    start = r->buf + r->pos;
    n = nl != NULL ? (size_t)(nl - start) : r->len - r->pos;
    r->pos += n + (nl != NULL);
    start[n] = '\0';            /* the newline's place, or the spare byte */
    if (n > 0 && start[n - 1] == '\r')
        start[--n] = '\0';
    /* A UTF-8 byte-order mark (EF BB BF) before the first line. */
    if (r->line == 1 && n >= 3 && memcmp(start, "\xEF\xBB\xBF", 3) == 0) {
        start += 3;
        n -= 3;
    }
    if (memchr(start, '\0', n) != NULL)
        return FE_EPARSE;
    *line = start;
    *len = n;
    return FE_OK;
}
/* Read one line ends here */
/* [[file:../literate/csv.org::Split a line into fields][Split a line into fields]] */
char fe_csv_guess_delimiter(const char *line)
{
    if (strchr(line, ';') != NULL)
        return ';';
    if (strchr(line, ',') != NULL)
        return ',';
    if (strchr(line, '\t') != NULL)
        return '\t';
    return FE_CSV_WHITESPACE;
}

static int fe__csv_blank(char c)
{
    return c == ' ' || c == '\t';
}

/* Find the delimiters sixty-four bytes a step (csv.org) */
#if FE__CSV_SSE2
/* Bit i set when q[i] is the delimiter (d: it in every byte), for the 16
   bytes at q. */
static uint64_t fe__csv_bits16(const char *q, __m128i d)
{
    __m128i x = _mm_loadu_si128((const __m128i *)(const void *)q);
    return (uint64_t)(unsigned)_mm_movemask_epi8(_mm_cmpeq_epi8(x, d));
}

/* The same for the 64 bytes at q, or for the bytes from q to the line's
   end if fewer (bits past the end clear); `tail` holds the bits of the
   line's last 16 bytes, when it has 16. */
static uint64_t fe__csv_bits64(const char *q, const char *line, const char *end, char delimiter,
                               __m128i d, uint64_t tail)
{
    size_t n = (size_t)(end - q), i = 0;
    uint64_t m = 0;
    if (n >= 64)
        return fe__csv_bits16(q, d) | fe__csv_bits16(q + 16, d) << 16
               | fe__csv_bits16(q + 32, d) << 32 | fe__csv_bits16(q + 48, d) << 48;
    for (; i + 16 <= n; i += 16)
        m |= fe__csv_bits16(q + i, d) << i;
    if (i < n && end - line >= 16) {
        m |= tail >> (16 - (n - i)) << i;       /* the last n - i of the 16 */
    } else {
        for (; i < n; i++)
            m |= (uint64_t)(q[i] == delimiter) << i;
    }
    return m;
}
#endif

/* The split; `simd` asks for the fast path over plain fields where it is
   compiled (the tests ask for both). */
static int fe__csv_split(char *line, char delimiter, fe_csv_field *fields,
                         size_t max, size_t *count, size_t *bad_column, int simd)
{
    char *p = line, *end;
    size_t k = 0;
    int ws = delimiter == FE_CSV_WHITESPACE;
#if FE__CSV_SSE2
    __m128i d = _mm_set1_epi8(delimiter);
    uint64_t tail = 0, m = 0;
    char *base = line;
#endif

    if (line == NULL || count == NULL || (fields == NULL && max > 0))
        return FE_EINVAL;
    *count = 0;
    end = line + strlen(line);
#if FE__CSV_SSE2
    simd = simd && !ws;
    if (simd) {                 /* before any byte of the line is written */
        tail = end - line >= 16 ? fe__csv_bits16(end - 16, d) : 0;
        m = fe__csv_bits64(line, line, end, delimiter, d, tail);
    }
#else
    (void)simd;
#endif
    if (ws) {
        while (fe__csv_blank(*p))
            p++;
        if (*p == '\0')
            return FE_OK;
    }
    for (;;) {
        char *out, *field_start;
#if FE__CSV_SSE2
        if (simd) {
            /* Split the plain fields at the bits of the delimiter mask (csv.org) */
            size_t off = (size_t)(p - base);
            if (off < 64) {
                m = m >> off << off;
            } else {
                base = p;
                m = fe__csv_bits64(base, line, end, delimiter, d, tail);
            }
            while (!fe__csv_blank(*p) && *p != '"') {
                char *q;
                while (m == 0 && end - base > 64) {
                    base += 64;
                    m = fe__csv_bits64(base, line, end, delimiter, d, tail);
                }
                q = m != 0 ? base + __builtin_ctzll(m) : end;
                if (q > p && fe__csv_blank(q[-1]))
                    break;                          /* a blank to trim: not plain */
                if (k == max) {
                    *count = max + 1;
                    return FE_ESIZE;
                }
                fields[k].text = p;
                fields[k].column = (size_t)(p - line) + 1;
                k++;
                if (q == end) {
                    *count = k;
                    return FE_OK;
                }
                *q = '\0';
                p = q + 1;
                m &= m - 1;
            }
            *count = k;
        }
#endif
        while (!ws && fe__csv_blank(*p))
            p++;
        field_start = p;
        out = p;
        if (*p == '"') {                /* quoted: copy, undoubling "" */
            p++;
            for (;;) {
                if (*p == '\0') {
                    if (bad_column != NULL)
                        *bad_column = (size_t)(field_start - line) + 1;
                    return FE_EPARSE;
                }
                if (*p == '"' && p[1] == '"') {
                    *out++ = '"';
                    p += 2;
                } else if (*p == '"') {
                    p++;
                    break;
                } else {
                    *out++ = *p++;
                }
            }
            while (fe__csv_blank(*p))
                p++;
            if (*p != '\0' && *p != delimiter && !ws) {
                if (bad_column != NULL)
                    *bad_column = (size_t)(p - line) + 1;
                return FE_EPARSE;
            }
        } else {
            if (!ws) {                  /* memchr: many bytes a step */
                char *dl = memchr(p, delimiter, (size_t)(end - p));
                p = dl != NULL ? dl : end;
            } else {
                while (*p != '\0' && !fe__csv_blank(*p))
                    p++;
            }
            out = p;
            while (out > field_start && fe__csv_blank(out[-1]))
                out--;
        }
        if (k == max) {
            *count = max + 1;
            return FE_ESIZE;
        }
        fields[k].text = field_start;
        fields[k].column = (size_t)(field_start - line) + 1;
        k++;
        if (ws)
            while (fe__csv_blank(*p))
                p++;
        {
            char c = *p;
            *out = '\0';
            *count = k;
            if (c == '\0')
                return FE_OK;
            if (!ws)
                p++;                    /* past the delimiter */
            else if (*p == '\0')
                return FE_OK;
        }
    }
}

int fe_csv_split(char *line, char delimiter, fe_csv_field *fields,
                 size_t max, size_t *count, size_t *bad_column)
{
    return fe__csv_split(line, delimiter, fields, max, count, bad_column, 1);
}

int fe__csv_split_portable(char *line, char delimiter, fe_csv_field *fields,
                           size_t max, size_t *count, size_t *bad_column)
{
    return fe__csv_split(line, delimiter, fields, max, count, bad_column, 0);
}
/* Split a line into fields ends here */
/* [[file:../literate/csv.org::Parse a field as a number][Parse a field as a number]] */
/* 10^0 .. 10^22: every one a double exactly. */
static const double fe__csv_pow10[23] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* w * 10^n plus the n digits at s, two a step; s past them.  s[1] is read
   only when s[0] is a digit, so never a byte past the NUL. */
static const char *fe__csv_digits(const char *s, uint64_t *w)
{
    uint64_t v = *w;
    for (;;) {
        unsigned d0 = (unsigned)(unsigned char)s[0] - '0', d1;
        if (d0 > 9)
            break;
        d1 = (unsigned)(unsigned char)s[1] - '0';
        if (d1 > 9) {
            v = 10 * v + d0;
            s++;
            break;
        }
        v = 100 * v + (10 * d0 + d1);
        s += 2;
    }
    *w = v;
    return s;
}

/* The plain decimal at s with w <= 2^53 and |q| <= 22 (see the text),
   ended by the NUL or by `end`: *value, and the byte that ends it.
   Otherwise NULL, and strtod decides.  At most 19 digits in all keep w
   below 10^19 < 2^64, so the digits are read without a test for
   overflow; w <= 2^53 is asked once, at the end. */
#if defined(__GNUC__)
#define FE__CSV_INLINE static inline __attribute__((always_inline))
#else
#define FE__CSV_INLINE static inline
#endif
FE__CSV_INLINE const char *fe__csv_fast_span(const char *s, char end, double *value)
{
    static const double sign[2] = {1.0, -1.0};
    uint64_t w = 0;
    int q = 0, neg = *s == '-';
    const char *first, *point;
    double v;
    s += neg | (*s == '+');                     /* no branch on the sign */
    first = s;
    s = point = fe__csv_digits(s, &w);
    if (*point == '.') {
        s = fe__csv_digits(point + 1, &w);
        q = -(int)(s - point - 1);
    }
    if ((size_t)(s - first) - (*point == '.') - 1 > 18)
        return NULL;                            /* no digit, or over 19 */
    if (*s != '\0' && *s != end) {
        int e = 0, eneg = 0;
        if (*s != 'e' && *s != 'E')
            return NULL;
        s++;
        if (*s == '+' || *s == '-')
            eneg = *s++ == '-';
        if ((unsigned)(*s - '0') >= 10u)
            return NULL;
        for (; (unsigned)(*s - '0') < 10u; s++)
            if (e < 10000)
                e = 10 * e + (*s - '0');
        if (*s != '\0' && *s != end)
            return NULL;
        q += eneg ? -e : e;
    }
    if (w > (UINT64_C(1) << 53))
        return NULL;
    if (w == 0) {
        *value = sign[neg] * 0.0;
        return s;
    }
    if (q < -22 || q > 22)
        return NULL;
    v = (double)(int64_t)w;                     /* w <= 2^53: exact */
    v = q < 0 ? v / fe__csv_pow10[-q] : v * fe__csv_pow10[q];
    *value = sign[neg] * v;
    return s;
}

/* A whole field that the fast path takes: *value, and 1; otherwise 0.
   The fast path is inlined here and in fe_csv_numbers, so that this copy
   asks for the NUL alone (one copy out of line cost the field parser 9 ns
   of its 108 a record). */
static int fe__csv_fast_number(const char *s, double *value)
{
    return fe__csv_fast_span(s, '\0', value) != NULL;
}

/* Is s entirely a plain decimal with `point` as its decimal mark? */
static int fe__csv_plain(const char *s, char point)
{
    int digits = 0;
    if (*s == '+' || *s == '-')
        s++;
    for (; *s >= '0' && *s <= '9'; s++)
        digits++;
    if (*s == point)
        for (s++; *s >= '0' && *s <= '9'; s++)
            digits++;
    if (digits == 0)
        return 0;
    if (*s == 'e' || *s == 'E') {
        s++;
        if (*s == '+' || *s == '-')
            s++;
        if (!(*s >= '0' && *s <= '9'))
            return 0;
        while (*s >= '0' && *s <= '9')
            s++;
    }
    return *s == '\0';
}

/* "nan", "inf", "infinity", signed or not, in any case. */
static int fe__csv_nonfinite_word(const char *s)
{
    static const char *const words[] = {"nan", "inf", "infinity"};
    if (*s == '+' || *s == '-')
        s++;
    for (size_t w = 0; w < sizeof words / sizeof words[0]; w++) {
        size_t i = 0;
        while (words[w][i] != '\0' && (s[i] | 0x20) == words[w][i])
            i++;
        if (words[w][i] == '\0' && s[i] == '\0')
            return 1;
    }
    return 0;
}

/* The decimal mark of the calling thread's locale as printf writes it
   ("." in the C locale, "," in many others), into mark (at most len - 1
   bytes, NUL-terminated); its length, 0 if it cannot be told. */
static size_t fe__csv_decimal_mark(char *mark, size_t len)
{
    char text[16];
    int n = snprintf(text, sizeof text, "%.1f", 1.5);  /* "1" mark "5" */
    size_t k = n > 2 && (size_t)n < sizeof text ? (size_t)n - 2 : 0;
    if (k == 0 || k >= len || text[0] != '1' || text[n - 1] != '5')
        return 0;
    memcpy(mark, text + 1, k);
    mark[k] = '\0';
    return k;
}

/* *out <- s written for strtod in the calling thread's locale: s itself
   when the mark is '.' or s has no point, else a copy in buf with the
   point made the locale's mark.  FE_EPARSE when the copy does not fit or
   the mark cannot be told. */
static int fe__csv_c_locale(const char *s, char *buf, size_t len, const char **out)
{
    char mark[8];
    size_t k = fe__csv_decimal_mark(mark, sizeof mark), at, n;
    const char *point = strchr(s, '.');
    *out = s;
    if (point == NULL || (k == 1 && mark[0] == '.'))
        return FE_OK;
    n = strlen(s);
    if (k == 0 || n + k > len)
        return FE_EPARSE;
    at = (size_t)(point - s);
    memcpy(buf, s, at);
    memcpy(buf + at, mark, k);
    memcpy(buf + at + k, point + 1, n - at);      /* the rest and its NUL */
    *out = buf;
    return FE_OK;
}

int fe_csv_format_double(double v, char *buf, size_t len)
{
    char mark[8], *at;
    size_t k;
    if (buf == NULL)
        return FE_EINVAL;
    if (len < FE_CSV_DOUBLE_TEXT)
        return FE_ESIZE;
    buf[0] = '\0';
    if (!isfinite(v))
        return FE_ENONFINITE;
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(buf, len, "%.*g", digits, v);
        if (strtod(buf, NULL) == v)     /* in the same locale as the text */
            break;
    }
    k = fe__csv_decimal_mark(mark, sizeof mark);
    if (k > 0 && !(k == 1 && mark[0] == '.') && (at = strstr(buf, mark)) != NULL) {
        *at = '.';
        memmove(at + 1, at + k, strlen(at + k) + 1);
    }
    return FE_OK;
}

/* fe_csv_number past the fast path: the grammar, the words, strtod. */
static int fe__csv_number_slow(const char *s, double *value)
{
    char *end, copy[FE_CSV_NUMBER_MAX];
    double v;
    if (*s == '\0')
        return FE_EPARSE;
    if (!fe__csv_plain(s, '.'))
        return fe__csv_nonfinite_word(s) ? FE_ENONFINITE : FE_EPARSE;
    if (fe__csv_c_locale(s, copy, sizeof copy, &s) != FE_OK)
        return FE_EPARSE;
    errno = 0;
    v = strtod(s, &end);
    if (end == s || *end != '\0')
        return FE_EPARSE;
    if (!isfinite(v))
        return FE_ENONFINITE;
    if (errno == ERANGE && fabs(v) > 1.0)
        return FE_ENONFINITE;   /* overflow; an underflow to 0 or a denormal is kept */
    *value = v;
    return FE_OK;
}

int fe_csv_number(const fe_csv_field *field, double *value)
{
    if (field == NULL || field->text == NULL || value == NULL)
        return FE_EINVAL;
    if (fe__csv_fast_number(field->text, value))
        return FE_OK;
    return fe__csv_number_slow(field->text, value);
}

int fe_csv_number_comma(const fe_csv_field *field, double *value)
{
    char copy[256];
    fe_csv_field f;
    size_t n;
    char *comma;

    if (field == NULL || field->text == NULL || value == NULL)
        return FE_EINVAL;
    n = strlen(field->text);
    if (n >= sizeof copy)
        return FE_EPARSE;
    memcpy(copy, field->text, n + 1);
    if (strchr(copy, '.') != NULL)
        return FE_EPARSE;
    comma = strchr(copy, ',');
    if (comma != NULL)
        *comma = '.';
    f.text = copy;
    f.column = field->column;
    return fe_csv_number(&f, value);
}
/* Parse a field as a number ends here */
/* [[file:../literate/csv.org::Read a line of plain numbers in one pass][Read a line of plain numbers in one pass]] */
int fe_csv_numbers(const char *line, char delimiter, double *values, size_t max,
                   size_t *count)
{
    size_t k = 0;
    if (line == NULL || values == NULL || count == NULL)
        return FE_EINVAL;
    if (delimiter == FE_CSV_WHITESPACE || delimiter == '\0'
        || strchr("0123456789+-.eE", delimiter) != NULL)
        return FE_EINVAL;
    for (;;) {
        double v;
        const char *end = fe__csv_fast_span(line, delimiter, &v);
        if (end == NULL) {
            *count = k;
            return FE_EPARSE;
        }
        if (k == max) {
            *count = max + 1;
            return FE_ESIZE;
        }
        values[k++] = v;
        if (*end == '\0')
            break;
        line = end + 1;
    }
    *count = k;
    return FE_OK;
}
/* Read a line of plain numbers in one pass ends here */
