/* SPDX-License-Identifier: MIT */
/* The CSV reader: lines (LF, CRLF, no final newline, too long, binary),
   fields (delimiters, quotes, white space) and numbers. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <float.h>
#include <locale.h>
#include <unistd.h>

#include "foldest.h"
#include "testutil.h"
#include "../src/csv_private.h"

/* A reader over `text` through a pipe, with a buffer of `cap` bytes. */
typedef struct { int fd; char buf[64]; fe_csv_reader r; } pipe_reader;

static void open_text(pipe_reader *p, const char *text, size_t cap)
{
    int fds[2];
    size_t n = strlen(text);
    ck_assert_int_eq(pipe(fds), 0);
    ck_assert_int_eq(write(fds[1], text, n), (ssize_t)n);
    close(fds[1]);
    p->fd = fds[0];
    ck_assert_int_eq(fe_csv_reader_init(&p->r, p->fd, p->buf, cap), FE_OK);
}

START_TEST(lines_lf_crlf_and_last_without_newline)
{
    pipe_reader p;
    char *line;
    size_t len;
    open_text(&p, "a,b\r\n1,2\n\n3,4", sizeof p.buf);
    ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "a,b");
    ck_assert_uint_eq(len, 3);
    ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "1,2");
    ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "");
    ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "3,4");
    ck_assert_uint_eq(p.r.line, 4);
    ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_END);
    close(p.fd);
}
END_TEST

START_TEST(too_long_line_is_reported_then_skipped)
{
    pipe_reader p;
    char *line;
    size_t len;
    /* Buffer of 8 bytes: lines of up to 7 characters. */
    open_text(&p, "1,2\n123456789012345678901234567890\n3,4\n", 8);
    ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "1,2");
    ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_ESIZE);
    ck_assert_uint_eq(p.r.line, 2);
    ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "3,4");
    ck_assert_uint_eq(p.r.line, 3);
    ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_END);
    close(p.fd);
}
END_TEST

START_TEST(binary_input_is_refused)
{
    int fds[2];
    char buf[32], *line;
    size_t len;
    fe_csv_reader r;
    ck_assert_int_eq(pipe(fds), 0);
    ck_assert_int_eq(write(fds[1], "1,2\n3\0004\n", 8), 8);
    close(fds[1]);
    fe_csv_reader_init(&r, fds[0], buf, sizeof buf);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_EPARSE);
    ck_assert_uint_eq(r.line, 2);
    close(fds[0]);
}
END_TEST

START_TEST(split_commas_quotes_and_blanks)
{
    char line[] = "\"Time (s)\", x ,\"say \"\"hi\"\"\",,last";
    fe_csv_field f[8];
    size_t n = 0;
    ck_assert_int_eq(fe_csv_guess_delimiter(line), ',');
    ck_assert_int_eq(fe_csv_split(line, ',', f, 8, &n, NULL), FE_OK);
    ck_assert_uint_eq(n, 5);
    ck_assert_str_eq(f[0].text, "Time (s)");
    ck_assert_uint_eq(f[0].column, 1);
    ck_assert_str_eq(f[1].text, "x");
    ck_assert_uint_eq(f[1].column, 13);
    ck_assert_str_eq(f[2].text, "say \"hi\"");
    ck_assert_str_eq(f[3].text, "");
    ck_assert_str_eq(f[4].text, "last");
}
END_TEST

START_TEST(split_white_space_and_errors)
{
    char ws[] = "  0.025\t-0.80  9.6 ";
    char quote[] = "1,\"open";
    char after[] = "1,\"a\"b,3";
    char many[] = "1,2,3,4";
    fe_csv_field f[3];
    size_t n = 0, col = 0;
    ck_assert_int_eq(fe_csv_guess_delimiter(ws), '\t');
    ck_assert_int_eq(fe_csv_split(ws, FE_CSV_WHITESPACE, f, 3, &n, NULL), FE_OK);
    ck_assert_uint_eq(n, 3);
    ck_assert_str_eq(f[0].text, "0.025");
    ck_assert_str_eq(f[2].text, "9.6");
    ck_assert_int_eq(fe_csv_split(quote, ',', f, 3, &n, &col), FE_EPARSE);
    ck_assert_uint_eq(col, 3);
    ck_assert_int_eq(fe_csv_split(after, ',', f, 3, &n, &col), FE_EPARSE);
    ck_assert_uint_eq(col, 6);
    ck_assert_int_eq(fe_csv_split(many, ',', f, 3, &n, NULL), FE_ESIZE);
    ck_assert_uint_eq(n, 4);
}
END_TEST

START_TEST(numbers)
{
    struct { const char *text; int rc; double value; } cases[] = {
        {"1.5", FE_OK, 1.5},        {"-2.372269500E-2", FE_OK, -2.372269500E-2},
        {"15032", FE_OK, 15032},    {"", FE_EPARSE, 0},
        {"x_a", FE_EPARSE, 0},      {"1.5abc", FE_EPARSE, 0},
        {"nan", FE_ENONFINITE, 0},  {"-inf", FE_ENONFINITE, 0},
        {"1e999", FE_ENONFINITE, 0}, {"1e-310", FE_OK, 1e-310},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[32];
        fe_csv_field f = {text, 1};
        double v = 12345;
        strcpy(text, cases[i].text);
        ck_assert_msg(fe_csv_number(&f, &v) == cases[i].rc, "case %s", cases[i].text);
        if (cases[i].rc == FE_OK)
            ck_assert_double_eq(v, cases[i].value);
        else
            ck_assert_double_eq(v, 12345);
    }
}
END_TEST

/* What spreadsheets and loggers write (issue 19): a byte-order mark, a
   semicolon table with decimal commas, a read function instead of a file
   descriptor, and strtod's extensions refused. */
struct chunks { const char *text; size_t at, step; };

static long read_chunks(void *ctx, char *buf, size_t n)
{
    struct chunks *c = ctx;
    size_t left = strlen(c->text) - c->at, k = left < c->step ? left : c->step;
    if (k > n)
        k = n;
    memcpy(buf, c->text + c->at, k);
    c->at += k;
    return (long)k;
}

START_TEST(byte_order_mark_semicolons_and_read_functions)
{
    struct chunks c = {"\xEF\xBB\xBFtime;x\n0;1,5\n\xEF\xBB\xBF" "1;2\n", 0, 3};
    fe_csv_reader r;
    char buf[64], *line;
    size_t len, nf;
    fe_csv_field f[4];
    double v;
    ck_assert_int_eq(fe_csv_reader_init_read(&r, NULL, NULL, buf, sizeof buf), FE_EINVAL);
    ck_assert_int_eq(fe_csv_reader_init_read(&r, read_chunks, &c, buf, sizeof buf), FE_OK);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "time;x");           /* the mark is gone */
    ck_assert_uint_eq(len, 6);
    ck_assert_int_eq(fe_csv_guess_delimiter(line), ';');
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
    ck_assert_int_eq(fe_csv_guess_delimiter(line), ';');   /* "0;1,5" has a comma too */
    ck_assert_int_eq(fe_csv_split(line, ';', f, 4, &nf, NULL), FE_OK);
    ck_assert_uint_eq(nf, 2);
    ck_assert_int_eq(fe_csv_number(&f[1], &v), FE_EPARSE);
    ck_assert_int_eq(fe_csv_number_comma(&f[1], &v), FE_OK);
    ck_assert_double_eq(v, 1.5);
    /* Only at the start of the input. */
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "\xEF\xBB\xBF" "1;2");
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_END);
}
END_TEST

/* The mark's edges: a first line that is the mark and nothing else (an
   empty line, its three bytes gone, with and without a newline after it),
   and first lines of two and three bytes that begin as the mark but are
   not it (returned as they are). */
START_TEST(byte_order_mark_at_its_edges)
{
    static const struct { const char *text; const char *first; size_t len; } cases[] = {
        {"\xEF\xBB\xBF\n" "1;2\n", "", 0},
        {"\xEF\xBB\xBF", "", 0},
        {"\xEF\xBB\xBF\r\n" "1;2\n", "", 0},
        {"\xEF\xBB\n" "1;2\n", "\xEF\xBB", 2},
        {"\xEF\xBBz\n" "1;2\n", "\xEF\xBBz", 3},
        {"\xEF\xBB\xBE\n" "1;2\n", "\xEF\xBB\xBE", 3},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        struct chunks c = {cases[i].text, 0, 64};
        fe_csv_reader r;
        char buf[64], *line;
        size_t len = 99;
        ck_assert_int_eq(fe_csv_reader_init_read(&r, read_chunks, &c, buf, sizeof buf), FE_OK);
        ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
        ck_assert_msg(len == cases[i].len, "case %zu: length %zu", i, len);
        ck_assert_msg(memcmp(line, cases[i].first, len + 1) == 0, "case %zu", i);
        if (strchr(cases[i].text, '1') != NULL) {
            ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
            ck_assert_str_eq(line, "1;2");
            ck_assert_uint_eq(len, 3);
        }
        ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_END);
    }
}
END_TEST

struct number_case { const char *text; int rc; double value; };

/* Each case through `parse`: its status, its value, and an untouched
   value on a refusal. */
static void check_numbers(int (*parse)(const fe_csv_field *, double *),
                          const struct number_case *cases, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        char text[64];
        fe_csv_field f = {text, 1};
        double v = -7.0;
        strcpy(text, cases[i].text);
        ck_assert_msg(parse(&f, &v) == cases[i].rc, "'%s'", cases[i].text);
        ck_assert_double_eq(v, cases[i].rc == FE_OK ? cases[i].value : -7.0);
    }
}

START_TEST(strtod_extensions_are_not_numbers)
{
    static const struct number_case cases[] = {
        {"0x1p3", FE_EPARSE, 0}, {"0x10", FE_EPARSE, 0}, {"-0X1.8P1", FE_EPARSE, 0},
        {"nan", FE_ENONFINITE, 0}, {"NaN", FE_ENONFINITE, 0}, {"-inf", FE_ENONFINITE, 0},
        {"+Infinity", FE_ENONFINITE, 0}, {"nan(123)", FE_EPARSE, 0}, {"infinit", FE_EPARSE, 0},
        {"1e999", FE_ENONFINITE, 0}, {"1e", FE_EPARSE, 0}, {".", FE_EPARSE, 0},
        {"1.5.2", FE_EPARSE, 0}, {"1,5", FE_EPARSE, 0}, {"", FE_EPARSE, 0},
        {"12345678901234567890", FE_OK, 12345678901234567890.0},
        {".5", FE_OK, 0.5}, {"5.", FE_OK, 5.0}, {"-1.25e-3", FE_OK, -1.25e-3},
        {"1e-400", FE_OK, 0.0},
    };
    static const struct number_case comma[] = {
        {"1,5", FE_OK, 1.5}, {"-0,25e2", FE_OK, -25.0}, {"3", FE_OK, 3.0},
        {"1.5", FE_EPARSE, 0}, {"1.234,5", FE_EPARSE, 0}, {"1,2,3", FE_EPARSE, 0},
        {"0x1,8p1", FE_EPARSE, 0}, {"nan", FE_ENONFINITE, 0},
    };
    check_numbers(fe_csv_number, cases, sizeof cases / sizeof cases[0]);
    check_numbers(fe_csv_number_comma, comma, sizeof comma / sizeof comma[0]);
}
END_TEST

START_TEST(numbers_equal_strtod_bit_for_bit)
{
    /* Random decimals in every form a recording or a printf writes (1 to
       19 significant digits, points anywhere, exponents, signs, leading
       zeros), and the edges of the fast path (2^53, 10^22): fe_csv_number
       returns what strtod returns, to the bit. */
    static const char *const edges[] = {
        "9007199254740992", "9007199254740993", "-9007199254740993e-22", "1e22", "1e23",
        "123456789012345678e4", "0.0000000000000000000001", "-0", "-0.0e5", "0e99999",
        "00001.2500", "1.", ".5", "-.5e-3", "4.9e-324", "1.7976931348623157e308",
        "1234567890123456789", "12345678901234567890", "0.1", "2.2250738585072014e-308",
        /* 19 digits in all and one more, with and without a point, and
           past 2^64 (the fast path reads up to 19 without an overflow
           test) */
        "0.000000000000000001", "0.0000000000000000001", "1234567890.123456789",
        "18446744073709551617", "1844674407370955161.7", "99999999999999999999.5",
        "000000000000000000001", "-0000000000000000001.5e1"};
    fe_rng g = fe_rng_seed(11);
    char text[64];
    for (int i = 0; i < 200000 + (int)(sizeof edges / sizeof *edges); i++) {
        fe_csv_field f = {text, 1};
        double v = 0.0, want;
        int rc;
        if (i < (int)(sizeof edges / sizeof *edges)) {
            strcpy(text, edges[i]);
        } else {
            int digits = 1 + (int)(fe_rng_next(&g) % 19), form = (int)(fe_rng_next(&g) % 4);
            double x = ldexp(fe_rng_uniform(&g), (int)(fe_rng_next(&g) % 160) - 80);
            if (fe_rng_next(&g) & 1)
                x = -x;
            if (form == 0)
                snprintf(text, sizeof text, "%.*g", digits, x);
            else if (form == 1)
                snprintf(text, sizeof text, "%.*e", digits - 1, x);
            else if (form == 2)
                snprintf(text, sizeof text, "%.*f", digits % 12, x * 1e6);
            else
                snprintf(text, sizeof text, "%lld%s%lld", (long long)(fe_rng_next(&g) % 100000),
                         fe_rng_next(&g) & 1 ? "." : "e-",
                         (long long)(fe_rng_next(&g) % 1000));
        }
        want = strtod(text, NULL);
        rc = fe_csv_number(&f, &v);
        if (isfinite(want) && !(fabs(want) > 1.7976931348623157e308)) {
            ck_assert_msg(rc == FE_OK, "%s: %d", text, rc);
            ck_assert_msg(memcmp(&v, &want, sizeof v) == 0, "%s: %.17g, strtod %.17g", text, v,
                          want);
        }
    }
}
END_TEST

/* A read function that gives its text in chunks, then fails (-1). */
struct failing { const char *text; size_t at; };

static long read_then_fail(void *ctx, char *buf, size_t n)
{
    struct failing *c = ctx;
    size_t left = strlen(c->text) - c->at, k = left < 3 ? left : 3;
    if (k == 0) {
        errno = EIO;
        return -1;
    }
    if (k > n)
        k = n;
    memcpy(buf, c->text + c->at, k);
    c->at += k;
    return (long)k;
}

/* A line too long whose end is the end of the input (no newline), read
   through a pipe and in chunks of 3 bytes: reported once, then FE_END,
   and FE_END again on every later call; the tail of a long line spread
   over several refills is dropped, whatever is read after its newline is
   a line; a read error while skipping is FE_EIO. */
START_TEST(too_long_line_at_the_end_and_a_read_error_while_skipping)
{
    pipe_reader p;
    char *line, buf[8];
    size_t len;
    fe_csv_reader r;
    struct chunks c = {"1,2\n12345678901234567890\n5,6\n1234567890123456789", 0, 3};
    struct failing f = {"1,2\n123456789012345678", 0};
    open_text(&p, "1,2\n123456789012345678901234567890", 8);
    ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "1,2");
    ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_ESIZE);
    ck_assert_uint_eq(p.r.line, 2);
    for (int i = 0; i < 3; i++)
        ck_assert_int_eq(fe_csv_next_line(&p.r, &line, &len), FE_END);
    ck_assert_uint_eq(p.r.line, 2);
    close(p.fd);
    ck_assert_int_eq(fe_csv_reader_init_read(&r, read_chunks, &c, buf, sizeof buf), FE_OK);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "1,2");
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_ESIZE);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "5,6");
    ck_assert_uint_eq(r.line, 3);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_ESIZE);
    ck_assert_uint_eq(r.line, 4);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_END);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_END);
    ck_assert_int_eq(fe_csv_reader_init_read(&r, read_then_fail, &f, buf, sizeof buf), FE_OK);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_ESIZE);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_EIO);
}
END_TEST

/* A read error while a line is being completed (not while a long line is
   skipped) is FE_EIO, not a line too long nor the end of the input; and a
   line holding only a carriage return is an empty line, at the end of the
   input too. */
START_TEST(a_read_error_inside_a_line_and_a_lone_carriage_return)
{
    char *line, buf[16];
    size_t len = 99;
    fe_csv_reader r;
    struct failing f = {"1,2\n3,", 0};
    struct chunks c = {"a\n\r\nb\n\r", 0, 64};
    ck_assert_int_eq(fe_csv_reader_init_read(&r, read_then_fail, &f, buf, sizeof buf), FE_OK);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "1,2");
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_EIO);
    ck_assert_int_eq(fe_csv_reader_init_read(&r, read_chunks, &c, buf, sizeof buf), FE_OK);
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
    ck_assert_str_eq(line, "a");
    for (int i = 0; i < 3; i++) {
        const char *want = i == 1 ? "b" : "";
        len = 99;
        ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
        ck_assert_str_eq(line, want);
        ck_assert_uint_eq(len, strlen(want));
    }
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_END);
}
END_TEST

/* The reader reads and writes nothing before its buffer: an empty line at
   the buffer's start, first and again after a refill moved the rest to
   the front, is empty though the byte before the buffer is a carriage
   return, and that byte is left as it was. */
START_TEST(an_empty_line_at_the_buffer_start_looks_at_nothing_before_it)
{
    char store[1 + 8], *line;
    size_t len = 99;
    fe_csv_reader r;
    struct chunks c = {"\n1,2\n3\n\n4\n", 0, 64};   /* 7 bytes, then the rest */
    store[0] = '\r';
    ck_assert_int_eq(fe_csv_reader_init_read(&r, read_chunks, &c, store + 1, 8), FE_OK);
    for (int i = 0; i < 5; i++) {
        const char *want[] = {"", "1,2", "3", "", "4"};
        len = 99;
        ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
        ck_assert_str_eq(line, want[i]);
        ck_assert_uint_eq(len, strlen(want[i]));
    }
    ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_END);
    ck_assert_int_eq(store[0], '\r');
}
END_TEST

/* Each missing argument of the two number parsers alone. */
START_TEST(number_parsers_refuse_each_missing_argument)
{
    char text[] = "1,5", dot[] = "2.5";
    fe_csv_field f = {text, 1}, none = {NULL, 1}, g = {dot, 1};
    double v = -7.0;
    ck_assert_int_eq(fe_csv_number_comma(NULL, &v), FE_EINVAL);
    ck_assert_int_eq(fe_csv_number_comma(&none, &v), FE_EINVAL);
    ck_assert_int_eq(fe_csv_number_comma(&f, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_csv_number(NULL, &v), FE_EINVAL);
    ck_assert_int_eq(fe_csv_number(&none, &v), FE_EINVAL);
    ck_assert_int_eq(fe_csv_number(&g, NULL), FE_EINVAL);
    ck_assert_double_eq(v, -7.0);
    ck_assert_int_eq(fe_csv_number_comma(&f, &v), FE_OK);
    ck_assert_double_eq(v, 1.5);
    ck_assert_int_eq(fe_csv_number(&g, &v), FE_OK);
    ck_assert_double_eq(v, 2.5);
}
END_TEST

/* A locale whose decimal mark is a comma, built with localedef into a
   temporary folder `dir` and set for LC_NUMERIC; 0 with a message when
   this machine cannot build one (no localedef or no de_DE source). */
static int set_german_numbers(char *dir)
{
    char cmd[256], one[16];
    if (mkdtemp(dir) == NULL)
        return 0;
    snprintf(cmd, sizeof cmd, "localedef -i de_DE -f UTF-8 %s/de_DE.UTF-8 >/dev/null 2>&1", dir);
    if (system(cmd) == -1 || setenv("LOCPATH", dir, 1) != 0
        || setlocale(LC_NUMERIC, "de_DE.UTF-8") == NULL) {
        printf("numbers_read_and_written_alike_in_any_locale: skipped, no locale with a "
               "decimal comma could be built (localedef -i de_DE; Debian's package locales)\n");
        return 0;
    }
    snprintf(one, sizeof one, "%.1f", 1.5);
    ck_assert_str_eq(one, "1,5");               /* the locale writes a comma */
    ck_assert_double_eq(strtod("1.5", NULL), 1.0);      /* and strtod stops at a point */
    return 1;
}

START_TEST(a_double_is_written_in_the_fewest_of_15_16_and_17_digits)
{
    /* The smallest subnormal reads back from 15 digits (16 would print
       ...465e-324), a third needs 16, 0.1 + 0.2 needs 17. */
    char b[FE_CSV_DOUBLE_TEXT];
    ck_assert_int_eq(fe_csv_format_double(DBL_TRUE_MIN, b, sizeof b), FE_OK);
    ck_assert_str_eq(b, "4.94065645841247e-324");
    ck_assert_int_eq(fe_csv_format_double(1.0 / 3.0, b, sizeof b), FE_OK);
    ck_assert_str_eq(b, "0.3333333333333333");
    ck_assert_int_eq(fe_csv_format_double(0.1 + 0.2, b, sizeof b), FE_OK);
    ck_assert_str_eq(b, "0.30000000000000004");
}
END_TEST

START_TEST(numbers_read_and_written_alike_in_any_locale)
{
    /* A program that links the library may set a locale whose decimal
       mark is a comma.  The fields the fast path leaves to strtod (over
       19 digits, an exponent past 10^22, a value past 2^53), and plain
       ones, read as in the C locale, bit for bit; numbers written for a
       machine (fe_csv_format_double, fe_located_json) keep their point. */
    static const char *const fields[] = {"0.12345678901234567891", "1.7976931348623157e308",
                                         "123456789012345678901.5", "2.5e-30",
                                         "9007199254740993.5", "-0.5", "12", "7e40"};
    static const double figures[] = {0.04, -1.5e-7, 123456.789, 1e300, 0.1, 2.5};
    enum { NF = sizeof fields / sizeof *fields, NG = sizeof figures / sizeof *figures };
    char dir[] = "/tmp/fe_locale_XXXXXX", copy[64], comma[] = "1,5";
    char written[NG][FE_CSV_DOUBLE_TEXT], text[FE_CSV_DOUBLE_TEXT], json[512], cmd[64];
    double want[NF], got, long_want[2];
    char longest[FE_CSV_NUMBER_MAX + 1];
    fe_csv_field lf = {longest, 1};
    fe_csv_field f = {copy, 1}, c = {comma, 1};
    fe_located l;
    memset(&l, 0, sizeof l);
    l.region = FE_REGION_TIME;
    l.test = "residual_mean";
    l.t0 = 1.5;
    l.t1 = 2.5;
    l.p_value = 0.25;
    for (size_t i = 0; i < NF; i++) {
        strcpy(copy, fields[i]);
        ck_assert_int_eq(fe_csv_number(&f, &want[i]), FE_OK);
    }
    for (size_t i = 0; i < NG; i++) {
        ck_assert_int_eq(fe_csv_format_double(figures[i], written[i], sizeof written[i]), FE_OK);
        ck_assert_double_eq(strtod(written[i], NULL), figures[i]);
    }
    ck_assert_str_eq(written[0], "0.04");
    ck_assert_int_eq(fe_csv_format_double(NAN, text, sizeof text), FE_ENONFINITE);
    ck_assert_str_eq(text, "");
    ck_assert_int_eq(fe_csv_format_double(1.0, text, FE_CSV_DOUBLE_TEXT - 1), FE_ESIZE);
    ck_assert_int_eq(fe_csv_format_double(1.0, NULL, FE_CSV_DOUBLE_TEXT), FE_EINVAL);
    memset(longest, '3', sizeof longest - 1);
    longest[1] = '.';
    longest[FE_CSV_NUMBER_MAX - 1] = '\0';
    ck_assert_int_eq(fe_csv_number(&lf, &long_want[0]), FE_OK);
    longest[FE_CSV_NUMBER_MAX - 1] = '3';
    longest[FE_CSV_NUMBER_MAX] = '\0';
    ck_assert_int_eq(fe_csv_number(&lf, &long_want[1]), FE_OK);
    if (!set_german_numbers(dir)) {
        unsetenv("LOCPATH");
        return;
    }
    for (size_t i = 0; i < NF; i++) {
        strcpy(copy, fields[i]);
        got = -1.0;
        ck_assert_msg(fe_csv_number(&f, &got) == FE_OK, "%s", fields[i]);
        ck_assert_msg(memcmp(&got, &want[i], sizeof got) == 0, "%s: %.17g, C locale %.17g",
                      fields[i], got, want[i]);
    }
    ck_assert_int_eq(fe_csv_number_comma(&c, &got), FE_OK);
    ck_assert_double_eq(got, 1.5);
    /* The copy's bound: FE_CSV_NUMBER_MAX - 1 characters read (with the
       NUL, the copy is full), one more refused (the C locale reads both). */
    memset(longest, '3', sizeof longest - 1);
    longest[1] = '.';
    longest[FE_CSV_NUMBER_MAX - 1] = '\0';
    ck_assert_int_eq(fe_csv_number(&lf, &got), FE_OK);
    ck_assert_double_eq(got, long_want[0]);
    longest[FE_CSV_NUMBER_MAX - 1] = '3';
    longest[FE_CSV_NUMBER_MAX] = '\0';
    ck_assert_int_eq(fe_csv_number(&lf, &got), FE_EPARSE);
    for (size_t i = 0; i < NG; i++) {
        ck_assert_int_eq(fe_csv_format_double(figures[i], text, sizeof text), FE_OK);
        ck_assert_str_eq(text, written[i]);
    }
    ck_assert_int_eq(fe_located_json(&l, json, sizeof json), FE_OK);
    ck_assert_msg(strstr(json, "\"start\": 1.5,") != NULL && strstr(json, "\"end\": 2.5")
                  && strstr(json, "\"p_value\": 0.25") != NULL, "%s", json);
    /* The C locale again: under valgrind (CK_FORK=no) the tests after
       this one run in the same process. */
    ck_assert_ptr_nonnull(setlocale(LC_NUMERIC, "C"));
    unsetenv("LOCPATH");
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    ck_assert_int_eq(system(cmd), 0);
}
END_TEST

/* Issue 20: the reader's buffer at its edge.  A buffer of 8 bytes reads
   at most 7, which must hold the line and its newline: 6 characters and
   LF are read, 7 refused (and skipped); with CRLF 5 characters are read
   and 6 refused; a last line without a newline is read at 6 and refused
   at 7, as the buffer cannot tell it from a longer one.  Each input in
   one chunk and one byte at a time. */
START_TEST(a_line_two_bytes_shorter_than_its_buffer_is_the_longest_read)
{
    static const struct { const char *text; int rc; size_t len; } cases[] = {
        {"123456\nab\n", FE_OK, 6},   {"1234567\nab\n", FE_ESIZE, 0},
        {"12345\r\nab\n", FE_OK, 5},  {"123456\r\nab\n", FE_ESIZE, 0},
        {"ab\n123456", FE_OK, 6},     {"ab\n1234567", FE_ESIZE, 0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        for (size_t step = 1; step <= 64; step += 63) {
            struct chunks c = {cases[i].text, 0, step};
            fe_csv_reader r;
            char buf[8], *line;
            size_t len = 99, lineno = cases[i].text[0] == 'a' ? 2 : 1;
            ck_assert_int_eq(fe_csv_reader_init_read(&r, read_chunks, &c, buf, sizeof buf), FE_OK);
            if (lineno == 2) {
                ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
                ck_assert_str_eq(line, "ab");
            }
            ck_assert_msg(fe_csv_next_line(&r, &line, &len) == cases[i].rc, "case %zu", i);
            ck_assert_uint_eq(r.line, lineno);
            if (cases[i].rc == FE_OK) {
                ck_assert_uint_eq(len, cases[i].len);
                ck_assert_uint_eq(strlen(line), cases[i].len);
                ck_assert_int_eq(strncmp(line, "1234567", len), 0);
            }
            if (lineno == 1) {                  /* the next line is read either way */
                ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_OK);
                ck_assert_str_eq(line, "ab");
            }
            ck_assert_int_eq(fe_csv_next_line(&r, &line, &len), FE_END);
        }
}
END_TEST

/* Issue 20: a decimal-comma field of 255 bytes is read, one of 256 is
   FE_EPARSE (a leading run of zeros keeps the value 1.5); fe_csv_number
   reads the same 256 bytes with a point. */
START_TEST(a_decimal_comma_field_of_255_bytes_is_read_and_256_refused)
{
    char text[257];
    fe_csv_field f = {text, 1};
    double v = -1.0;
    memset(text, '0', sizeof text);
    text[252] = '1', text[253] = ',', text[254] = '5', text[255] = '\0';
    ck_assert_uint_eq(strlen(text), 255);
    ck_assert_int_eq(fe_csv_number_comma(&f, &v), FE_OK);
    ck_assert_double_eq(v, 1.5);
    memset(text, '0', sizeof text);
    text[253] = '1', text[254] = ',', text[255] = '5', text[256] = '\0';
    v = -1.0;
    ck_assert_int_eq(fe_csv_number_comma(&f, &v), FE_EPARSE);
    ck_assert_double_eq(v, -1.0);
    text[254] = '.';                            /* the point reader has no such bound */
    ck_assert_int_eq(fe_csv_number(&f, &v), FE_OK);
    ck_assert_double_eq(v, 1.5);
}
END_TEST

/* The split as the chapter states it, one byte at a time and nothing
   else: the oracle for fe_csv_split (its SSE2 fast path over plain fields,
   where compiled) and fe__csv_split_portable (the general loop alone). */
static int ref_blank(char c)
{
    return c == ' ' || c == '\t';
}

static int ref_split(char *line, char delim, fe_csv_field *f, size_t max, size_t *count,
                     size_t *bad)
{
    int ws = delim == FE_CSV_WHITESPACE;
    char *p = line;
    size_t k = 0;
    *count = 0;
    if (ws) {
        while (ref_blank(*p))
            p++;
        if (*p == '\0')
            return FE_OK;
    }
    for (;;) {
        char *start, *out, c;
        while (!ws && ref_blank(*p))
            p++;
        start = out = p;
        if (*p == '"') {
            for (p++;;) {
                if (*p == '\0') {
                    *bad = (size_t)(start - line) + 1;
                    return FE_EPARSE;
                }
                if (p[0] == '"' && p[1] == '"') {
                    *out++ = '"';
                    p += 2;
                } else if (*p == '"') {
                    p++;
                    break;
                } else {
                    *out++ = *p++;
                }
            }
            while (ref_blank(*p))
                p++;
            if (!ws && *p != '\0' && *p != delim) {
                *bad = (size_t)(p - line) + 1;
                return FE_EPARSE;
            }
        } else {
            while (*p != '\0' && (ws ? !ref_blank(*p) : *p != delim))
                p++;
            out = p;
            while (out > start && ref_blank(out[-1]))
                out--;
        }
        if (k == max) {
            *count = max + 1;
            return FE_ESIZE;
        }
        f[k].text = start;
        f[k].column = (size_t)(start - line) + 1;
        *count = ++k;
        while (ws && ref_blank(*p))
            p++;
        c = *p;
        *out = '\0';
        if (c == '\0')
            return FE_OK;
        if (!ws)
            p++;
    }
}

typedef int split_fn(char *, char, fe_csv_field *, size_t, size_t *, size_t *);

/* `text` (n bytes) split by `split` and by the oracle, each on its own
   copy placed `off` bytes into a buffer of exactly off + n + 1 bytes (so
   that AddressSanitizer sees a read past the NUL) whose first bytes are
   delimiters: the same status, count, bad column, fields, columns, and
   the same bytes left in the line. */
static void split_alike(split_fn *split, const char *name, const char *text, size_t n,
                        char delim, size_t max, size_t off)
{
    enum { MAXF = 200 };
    fe_csv_field got[MAXF], want[MAXF];
    size_t ngot = 99, nwant = 99, badgot = 0, badwant = 0;
    char *a = malloc(off + n + 1), *b = malloc(off + n + 1);
    int rgot, rwant;
    if (a == NULL || b == NULL)
        ck_abort_msg("out of memory");
    memset(a, delim == FE_CSV_WHITESPACE ? ' ' : delim, off);
    memset(b, delim == FE_CSV_WHITESPACE ? ' ' : delim, off);
    memcpy(a + off, text, n);
    memcpy(b + off, text, n);
    a[off + n] = b[off + n] = '\0';
    rgot = split(a + off, delim, got, max, &ngot, &badgot);
    rwant = ref_split(b + off, delim, want, max, &nwant, &badwant);
    /* Check's assertions cost a write each: test first, assert on a failure. */
    if (rgot != rwant || ngot != nwant || badgot != badwant)
        ck_abort_msg("%s '%.*s' delimiter '%c' max %zu at offset %zu: status %d count %zu "
                     "bad %zu, oracle %d %zu %zu", name, (int)n, text, delim, max, off, rgot, ngot,
                     badgot, rwant, nwant, badwant);
    for (size_t i = 0; i < nwant && i < max; i++) {
        if (got[i].text - a != want[i].text - b || got[i].column != want[i].column
            || strcmp(got[i].text, want[i].text) != 0)
            ck_abort_msg("%s '%.*s' delimiter '%c' at offset %zu: field %zu '%s' at %zu, "
                         "oracle '%s' at %zu", name, (int)n, text, delim, off, i, got[i].text,
                         got[i].column, want[i].text, want[i].column);
    }
    if (memcmp(a, b, off + n + 1) != 0)
        ck_abort_msg("%s '%.*s': other bytes written", name, (int)n, text);
    free(a);
    free(b);
}

static void split_alike_both(const char *text, size_t n, char delim, size_t max, size_t off)
{
    split_alike(fe_csv_split, "fe_csv_split", text, n, delim, max, off);
    split_alike(fe__csv_split_portable, "fe__csv_split_portable", text, n, delim, max, off);
}

/* Every length up to 80 (across 16, 32 and 64 bytes), plain fields of
   several widths, one quote, blank or delimiter put at every position,
   each line at the offsets 0 to 15 of a 16-byte window in turn.  Under
   valgrind (FE_TEST_QUICK) three widths of the eight. */
START_TEST(split_fast_path_matches_the_oracle_at_every_offset)
{
    static const size_t period[] = {2, 9, 17, 1, 3, 8, 16, 1000};
    static const char special[] = {'"', ' ', '\t', ',', 'x'};
    size_t widths = fe_test_quick() ? 3 : sizeof period / sizeof *period;
    char text[96];
    size_t lines = 0;
    for (size_t n = 0; n <= 80; n++)
        for (size_t w = 0; w < widths; w++)
            for (size_t j = 0; j <= n; j++)
                for (size_t c = 0; c < sizeof special; c++) {
                    for (size_t i = 0; i < n; i++)
                        text[i] = i % period[w] == period[w] - 1 ? ',' : (char)('0' + i % 10);
                    if (j < n)
                        text[j] = special[c];
                    else if (c > 0)
                        continue;               /* j == n: the line as it is, once */
                    split_alike_both(text, n, ',', 100, (n + j + c) % 16);
                    lines++;
                }
    ck_assert_uint_gt(lines, 30000);
}
END_TEST

/* Random lines over small alphabets (dense in quotes and blanks, plain
   numbers, long runs without a delimiter), every delimiter, the white
   space mode, a field limit that is often reached, any offset. */
START_TEST(split_fast_path_matches_the_oracle_on_random_lines)
{
    static const char *const alphabet[] = {"1.-,;\t \"a", "0123456789.,-", "0123456789.-,",
                                           "abcdefghij\"\"  ,", "0123456789;,\t", "\"\",,  \t"};
    static const char delims[] = {',', ';', '\t', FE_CSV_WHITESPACE};
    fe_rng g = fe_rng_seed(16);
    int cases = fe_test_quick() ? 5000 : 200000;
    char text[200];
    for (int t = 0; t < cases; t++) {
        const char *al = alphabet[fe_rng_next(&g) % 6];
        size_t nal = strlen(al), n = fe_rng_next(&g) % 150, max;
        char delim = delims[fe_rng_next(&g) % 4];
        int sparse = fe_rng_next(&g) % 4 == 0;
        for (size_t i = 0; i < n; i++) {
            char c = al[fe_rng_next(&g) % nal];
            if (sparse && (c == ',' || c == ';' || c == '\t') && fe_rng_next(&g) % 16 != 0)
                c = '7';                        /* long fields: chunks with no delimiter */
            text[i] = c;
        }
        max = fe_rng_next(&g) % 3 == 0 ? fe_rng_next(&g) % 12 : 160;
        split_alike_both(text, n, delim, max, fe_rng_next(&g) % 16);
    }
}
END_TEST

/* A plain decimal as the chapter defines it: [+-] digits [. digits]
   [(e|E) [+-] digits], with a digit before the exponent. */
static int ref_plain(const char *s)
{
    int digits = 0;
    if (*s == '+' || *s == '-')
        s++;
    for (; *s >= '0' && *s <= '9'; s++)
        digits++;
    if (*s == '.')
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

/* Text over "0123456789.eE+-" and a stray byte or two, most of it shaped
   like a decimal (sign, 0 to 22 digits, a point, 0 to 22 digits, an
   exponent), NUL-terminated in text (at least 64 bytes); its length. */
static size_t random_decimal(fe_rng *g, char *text)
{
    static const char alphabet[] = "0123456789.eE+-";
    size_t n = 0;
    if (fe_rng_next(g) % 4 == 0) {
        size_t len = fe_rng_next(g) % 24;
        for (; n < len; n++)
            text[n] = alphabet[fe_rng_next(g) % (sizeof alphabet - 1)];
    } else {
        size_t a = fe_rng_next(g) % 23, b = fe_rng_next(g) % 23;
        if (fe_rng_next(g) % 2)
            text[n++] = "+-"[fe_rng_next(g) % 2];
        for (size_t i = 0; i < a; i++)
            text[n++] = (char)('0' + fe_rng_next(g) % 10);
        if (fe_rng_next(g) % 4 != 0)
            text[n++] = '.';
        for (size_t i = 0; i < b; i++)
            text[n++] = (char)('0' + fe_rng_next(g) % 10);
        if (fe_rng_next(g) % 4 == 0) {
            text[n++] = "eE"[fe_rng_next(g) % 2];
            if (fe_rng_next(g) % 2)
                text[n++] = "+-"[fe_rng_next(g) % 2];
            for (size_t i = fe_rng_next(g) % 4; i > 0; i--)
                text[n++] = (char)('0' + fe_rng_next(g) % 10);
        }
        if (fe_rng_next(g) % 16 == 0)
            text[n++] = "x. e1"[fe_rng_next(g) % 5];
    }
    text[n] = '\0';
    return n;
}

/* Random decimals (random_decimal): fe_csv_number says what the grammar
   and strtod say, to the bit, and leaves the value alone when it
   refuses. */
START_TEST(numbers_match_the_grammar_and_strtod_on_random_text)
{
    fe_rng g = fe_rng_seed(17);
    int cases = fe_test_quick() ? 10000 : 300000;
    char text[80];
    for (int t = 0; t < cases; t++) {
        fe_csv_field f = {text, 1};
        double v = -7.0, want = -7.0;
        int rc, rwant;
        random_decimal(&g, text);
        rc = fe_csv_number(&f, &v);
        if (!ref_plain(text)) {
            rwant = FE_EPARSE;
        } else {
            errno = 0;
            want = strtod(text, NULL);
            rwant = !isfinite(want) || (errno == ERANGE && fabs(want) > 1.0) ? FE_ENONFINITE : FE_OK;
            if (rwant != FE_OK)
                want = -7.0;
        }
        if (rc != rwant || memcmp(&v, &want, sizeof v) != 0)
            ck_abort_msg("'%s': %d %.17g, want %d %.17g", text, rc, v, rwant, want);
    }
}
END_TEST

/* Does the fast path take this field, by the chapter's rule, worked out
   here on its own: a plain decimal of 1 to 19 digits whose integer w is
   at most 2^53, and zero or within 10^22 after its exponent. */
static int ref_fast(const char *s)
{
    uint64_t w = 0;
    long q = 0, e = 0;
    int digits = 0, eneg = 0;
    if (!ref_plain(s))
        return 0;
    if (*s == '+' || *s == '-')
        s++;
    for (; *s >= '0' && *s <= '9'; s++, digits++)
        w = digits < 19 ? 10 * w + (uint64_t)(*s - '0') : w;
    if (*s == '.')
        for (s++; *s >= '0' && *s <= '9'; s++, digits++, q--)
            w = digits < 19 ? 10 * w + (uint64_t)(*s - '0') : w;
    if (*s == 'e' || *s == 'E') {
        s++;
        if (*s == '+' || *s == '-')
            eneg = *s++ == '-';
        for (; *s >= '0' && *s <= '9'; s++)
            e = e < 100000 ? 10 * e + (*s - '0') : e;
    }
    q += eneg ? -e : e;
    return digits <= 19 && w <= (UINT64_C(1) << 53) && (w == 0 || (q >= -22 && q <= 22));
}

/* Lines of random fields (random_decimal, now and then an empty field, a
   padded or quoted number or a word) joined by one of four delimiters,
   read by the one pass with a field limit that is often reached: it
   reads the fields up to the first one the fast path does not take, each
   to the bit of strtod's value, says FE_EPARSE there or FE_ESIZE past the
   limit, and leaves the line as it was. */
START_TEST(one_pass_reads_what_the_fast_path_takes_and_stops_at_the_rest)
{
    static const char delims[] = {',', ';', '\t', '|'};
    static const char *const odd[] = {"", " 1.5", "\"2\"", "nan", "abc", "1.5 "};
    fe_rng g = fe_rng_seed(18);
    int cases = fe_test_quick() ? 3000 : 100000;
    for (int t = 0; t < cases; t++) {
        char line[16 * 80], copy[sizeof line], field[16][80];
        double v[16], want;
        size_t nf = 1 + fe_rng_next(&g) % 12, max = fe_rng_next(&g) % 3 == 0
                                                       ? fe_rng_next(&g) % 12 : 16;
        size_t n = 0, count = 99, first_other = nf, expect_count;
        char d = delims[fe_rng_next(&g) % 4];
        int rc, expect;
        for (size_t i = 0; i < nf; i++) {
            if (fe_rng_next(&g) % 8 == 0)
                strcpy(field[i], odd[fe_rng_next(&g) % 6]);
            else if (fe_rng_next(&g) % 2 == 0)
                snprintf(field[i], sizeof field[i], "%.*f", (int)(fe_rng_next(&g) % 8),
                         (fe_rng_uniform(&g) - 0.5) * 2e4);
            else
                random_decimal(&g, field[i]);
            if (first_other == nf && !ref_fast(field[i]))
                first_other = i;
            if (i > 0)
                line[n++] = d;
            memcpy(line + n, field[i], strlen(field[i]) + 1);
            n += strlen(field[i]);
        }
        memcpy(copy, line, n + 1);
        rc = fe_csv_numbers(line, d, v, max, &count);
        if (first_other <= max && first_other < nf) {
            expect = FE_EPARSE;
            expect_count = first_other;
        } else if (nf > max) {
            expect = FE_ESIZE;
            expect_count = max + 1;
        } else {
            expect = FE_OK;
            expect_count = nf;
        }
        ck_assert_msg(rc == expect && count == expect_count, "'%s' (max %zu): %d, %zu fields;"
                      " want %d, %zu", copy, max, rc, count, expect, expect_count);
        ck_assert_msg(memcmp(line, copy, n + 1) == 0, "'%s' changed to '%s'", copy, line);
        for (size_t i = 0; i < expect_count && i < max && i < first_other; i++) {
            want = strtod(field[i], NULL);
            ck_assert_msg(memcmp(&v[i], &want, sizeof want) == 0, "'%s' field %zu: %.17g,"
                          " want %.17g", copy, i, v[i], want);
        }
    }
}
END_TEST

/* The one pass at its edges: the field limit equal to the count and one
   under it (the first fault in the line decides), an empty line, a delimiter at the end, each delimiter it must
   refuse and one it may take, each missing argument. */
START_TEST(one_pass_at_its_edges)
{
    double v[4] = {0};
    size_t count = 99;
    const char *refused = "0123456789+-.eE";
    static const struct { const char *line; char delim; size_t max; int rc; size_t count; } cases[] = {
        {"1,-2.5,3e2", ',', 3, FE_OK, 3}, {"1,-2.5,3e2", ',', 2, FE_ESIZE, 3},
        {"1,2,x", ',', 2, FE_EPARSE, 2},  {"1,x,3", ',', 1, FE_EPARSE, 1},
        {"", ',', 3, FE_EPARSE, 0},       {"1,2,", ',', 3, FE_EPARSE, 2},
        {"7", ',', 0, FE_ESIZE, 1},       {"1:2", ':', 3, FE_OK, 2},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        count = 99;
        ck_assert_msg(fe_csv_numbers(cases[i].line, cases[i].delim, v, cases[i].max, &count)
                      == cases[i].rc && count == cases[i].count, "case %zu: count %zu", i, count);
    }
    ck_assert_int_eq(fe_csv_numbers("1,-2.5,3e2", ',', v, 3, &count), FE_OK);
    ck_assert(v[0] == 1.0 && v[1] == -2.5 && v[2] == 300.0);
    ck_assert_int_eq(fe_csv_numbers("1:2", ':', v, 3, &count), FE_OK);
    ck_assert(v[0] == 1.0 && v[1] == 2.0);
    for (const char *c = refused; *c != '\0'; c++)
        ck_assert_msg(fe_csv_numbers("1,2", *c, v, 3, &count) == FE_EINVAL, "'%c'", *c);
    ck_assert_int_eq(fe_csv_numbers("1,2", '\0', v, 3, &count), FE_EINVAL);
    ck_assert_int_eq(fe_csv_numbers("1 2", FE_CSV_WHITESPACE, v, 3, &count), FE_EINVAL);
    ck_assert_int_eq(fe_csv_numbers(NULL, ',', v, 3, &count), FE_EINVAL);
    ck_assert_int_eq(fe_csv_numbers("1", ',', NULL, 3, &count), FE_EINVAL);
    ck_assert_int_eq(fe_csv_numbers("1", ',', v, 3, NULL), FE_EINVAL);
}
END_TEST

Suite *fe_csv_suite(void)
{
    Suite *s = suite_create("csv");
    TCase *t = tcase_create("core");
    tcase_set_timeout(t, 60);   /* about 1 s (the strtod comparison); more on a busy machine or under ASan */
    tcase_add_test(t, lines_lf_crlf_and_last_without_newline);
    tcase_add_test(t, too_long_line_is_reported_then_skipped);
    tcase_add_test(t, binary_input_is_refused);
    tcase_add_test(t, split_commas_quotes_and_blanks);
    tcase_add_test(t, split_white_space_and_errors);
    tcase_add_test(t, numbers);
    tcase_add_test(t, numbers_equal_strtod_bit_for_bit);
    tcase_add_test(t, byte_order_mark_semicolons_and_read_functions);
    tcase_add_test(t, byte_order_mark_at_its_edges);
    tcase_add_test(t, strtod_extensions_are_not_numbers);
    tcase_add_test(t, too_long_line_at_the_end_and_a_read_error_while_skipping);
    tcase_add_test(t, a_read_error_inside_a_line_and_a_lone_carriage_return);
    tcase_add_test(t, an_empty_line_at_the_buffer_start_looks_at_nothing_before_it);
    tcase_add_test(t, number_parsers_refuse_each_missing_argument);
    tcase_add_test(t, a_double_is_written_in_the_fewest_of_15_16_and_17_digits);
    tcase_add_test(t, numbers_read_and_written_alike_in_any_locale);
    tcase_add_test(t, a_line_two_bytes_shorter_than_its_buffer_is_the_longest_read);
    tcase_add_test(t, a_decimal_comma_field_of_255_bytes_is_read_and_256_refused);
    tcase_add_test(t, split_fast_path_matches_the_oracle_at_every_offset);
    tcase_add_test(t, split_fast_path_matches_the_oracle_on_random_lines);
    tcase_add_test(t, numbers_match_the_grammar_and_strtod_on_random_text);
    tcase_add_test(t, one_pass_reads_what_the_fast_path_takes_and_stops_at_the_rest);
    tcase_add_test(t, one_pass_at_its_edges);
    suite_add_tcase(s, t);
    return s;
}
