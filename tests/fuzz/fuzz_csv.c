/* SPDX-License-Identifier: MIT */
/* libFuzzer harness: the CSV reader.  The input is written to a memory
   file and read back line by line through a buffer whose size the first
   byte chooses (2 to 257 bytes, so long lines and refills are common);
   every line is split with the delimiter the reader guesses and with each
   fixed one, and every field parsed as a number.  Checked: lines fit the
   buffer and hold no NUL, line numbers increase by one, fields lie inside
   their line with columns that match, numbers are finite, and the reader
   always reaches the end. */
#define _GNU_SOURCE
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "foldest.h"

#include "fuzz_require.h"

static void split_all(const char *line, size_t len, char delimiter)
{
    static char copy[300];
    fe_csv_field fields[8];
    size_t count = 0, bad = 0;
    int rc;
    memcpy(copy, line, len + 1);
    rc = fe_csv_split(copy, delimiter, fields, 8, &count, &bad);
    if (rc == FE_EPARSE) {
        REQUIRE(bad >= 1 && bad <= len + 1);
        return;
    }
    if (rc == FE_ESIZE) {
        REQUIRE(count == 9);
        return;
    }
    REQUIRE(rc == FE_OK && count <= 8);
    for (size_t i = 0; i < count; i++) {
        double v;
        REQUIRE(fields[i].text >= copy && fields[i].text <= copy + len);
        REQUIRE(fields[i].column == (size_t)(fields[i].text - copy) + 1);
        REQUIRE(strlen(fields[i].text) <= len);
        rc = fe_csv_number(&fields[i], &v);
        REQUIRE(rc == FE_OK || rc == FE_EPARSE || rc == FE_ENONFINITE);
        if (rc == FE_OK) {
            /* The fast path and strtod agree to the bit, and what is
               accepted is a plain decimal: no hexadecimal, inf or nan. */
            char *end;
            double w = strtod(fields[i].text, &end);
            REQUIRE(isfinite(v));
            REQUIRE(*end == '\0' && memcmp(&v, &w, sizeof v) == 0);
            REQUIRE(strpbrk(fields[i].text, "xXpPnNiI") == NULL);
        }
        /* The decimal comma: a number is the one with the comma made a
           point, and a field with a point is never one. */
        rc = fe_csv_number_comma(&fields[i], &v);
        REQUIRE(rc == FE_OK || rc == FE_EPARSE || rc == FE_ENONFINITE);
        if (rc == FE_OK) {
            char point[300], *c;
            double w;
            REQUIRE(isfinite(v) && strchr(fields[i].text, '.') == NULL);
            strcpy(point, fields[i].text);
            if ((c = strchr(point, ',')) != NULL)
                *c = '.';
            w = strtod(point, &c);
            REQUIRE(*c == '\0' && memcmp(&v, &w, sizeof v) == 0);
        }
    }
}

/* Bytes from memory in chunks of `step`: the reader's read-function path. */
struct chunks { const uint8_t *p; size_t left, step; };

static long read_chunks(void *ctx, char *buf, size_t n)
{
    struct chunks *c = ctx;
    size_t k = c->left < c->step ? c->left : c->step;
    if (k > n)
        k = n;
    memcpy(buf, c->p, k);
    c->p += k;
    c->left -= k;
    return (long)k;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char buffer[258];
    fe_csv_reader r;
    size_t cap, last = 0, calls = 0;
    int fd;
    if (size == 0)
        return 0;
    cap = 2 + data[0];
    fd = memfd_create("fuzz_csv", 0);
    REQUIRE(fd >= 0);
    REQUIRE(write(fd, data + 1, size - 1) == (ssize_t)(size - 1));
    REQUIRE(lseek(fd, 0, SEEK_SET) == 0);
    /* An odd first byte reads through a function, in chunks of 1 to 7. */
    struct chunks ch = {data + 1, size - 1, 1 + (size_t)(data[0] >> 1) % 7};
    if (data[0] & 1)
        REQUIRE(fe_csv_reader_init_read(&r, read_chunks, &ch, buffer, cap) == FE_OK);
    else
        REQUIRE(fe_csv_reader_init(&r, fd, buffer, cap) == FE_OK);
    for (;;) {
        char *line;
        size_t len;
        int rc = fe_csv_next_line(&r, &line, &len);
        REQUIRE(++calls <= size + 1);           /* always progresses */
        if (rc == FE_END)
            break;
        REQUIRE(r.line == last + 1);
        last = r.line;
        if (rc != FE_OK) {
            REQUIRE(rc == FE_ESIZE || rc == FE_EPARSE);
            continue;
        }
        REQUIRE(len < cap && line >= buffer && line + len < buffer + cap);
        REQUIRE(line[len] == '\0' && strlen(line) == len);
        split_all(line, len, fe_csv_guess_delimiter(line));
        split_all(line, len, ',');
        split_all(line, len, ';');
        split_all(line, len, FE_CSV_WHITESPACE);
    }
    close(fd);
    return 0;
}
