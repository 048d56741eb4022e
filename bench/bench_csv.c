/* SPDX-License-Identifier: MIT */
/* Reading a recording, in one run (issue 16, item 2): a CSV of 8 numeric
   columns of six or seven significant digits ("2201.72", "-0.764163"),
   N records written to a temporary file and read once so that it is
   cached, then, best of NS runs each:
     - the read floor: read(2) through a 64 KiB buffer and memchr for the
       line ends, nothing else;
     - fe_csv_next_line alone;
     - fe_csv_next_line + fe_csv_split;
     - fe_csv_next_line + fe_csv_split + fe_csv_number on every field;
     - fe_csv_next_line + fe_csv_numbers, the one pass over a line of
       plain numbers, with the split and the field parser for a line it
       declines (the header): what the commands do for each row.
   Prints ns per record, MB/s and the ratio against the read floor (the
   goal: parsing at 450 MB/s or more, 100 ns a record), and how busy the
   machine was.  The two whole parses must give the same sum, bit for
   bit.  The
   file is removed at the end. */
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench.h"
#include "foldest.h"

enum { N = 1000000, COLS = 8, NS = 5, BUF = 1 << 16 };

/* The read floor: the bytes and the line ends, nothing else. */
static long read_floor(const char *path, char *buf)
{
    int fd = open(path, O_RDONLY);
    long lines = 0;
    ssize_t got;
    if (fd < 0)
        return -1;
    while ((got = read(fd, buf, BUF)) > 0) {
        const char *p = buf, *end = buf + got;
        while ((p = memchr(p, '\n', (size_t)(end - p))) != NULL) {
            lines++;
            p++;
        }
    }
    close(fd);
    return lines;
}

/* Lines (stage 0), split (1), numbers (2), one pass (3); returns the
   records read, the sum of the numbers in *sum. */
static long read_csv(const char *path, char *buf, int stage, double *sum)
{
    fe_csv_reader r;
    fe_csv_field f[COLS + 1];
    char *line;
    size_t len, nf;
    long rows = 0;
    int fd = open(path, O_RDONLY);
    *sum = 0.0;
    if (fd < 0 || fe_csv_reader_init(&r, fd, buf, BUF) != FE_OK)
        return -1;
    while (fe_csv_next_line(&r, &line, &len) == FE_OK) {
        double v[COLS];
        rows++;
        if (stage == 3 && fe_csv_numbers(line, ',', v, COLS, &nf) == FE_OK) {
            for (size_t i = 0; i < nf; i++)
                *sum += v[i];
            continue;
        }
        if (stage == 0 || fe_csv_split(line, ',', f, COLS + 1, &nf, NULL) != FE_OK || stage == 1
            || rows == 1)
            continue;
        for (size_t i = 0; i < nf; i++) {
            double v;
            if (fe_csv_number(&f[i], &v) == FE_OK)
                *sum += v;
        }
    }
    close(fd);
    return rows;
}

int main(void)
{
    char path[] = "/tmp/foldest-bench-csv-XXXXXX";
    char *buf = malloc(BUF);
    double busy = fe_bench_busy_fraction(), t_floor, t[4], sum[4] = {0}, bytes;
    long lines = 0, rows[4] = {0, 0, 0, 0};
    const char *stage_name[4] = {"lines (fe_csv_next_line)", "+ fields (fe_csv_split)",
                                 "+ numbers (fe_csv_number)", "one pass (fe_csv_numbers)"};
    int fd = mkstemp(path);
    FILE *out;
    if (buf == NULL || fd < 0 || (out = fdopen(fd, "w")) == NULL)
        return 1;
    bytes = fe_bench_write_table8(out, N, 1);
    fclose(out);
    read_floor(path, buf);                              /* into the cache */
    FE_BENCH_BEST(t_floor, NS, lines = read_floor(path, buf));
    for (int s = 0; s < 4; s++)
        FE_BENCH_BEST(t[s], NS, rows[s] = read_csv(path, buf, s, &sum[s]));
    fe_bench_keep(sum[2]);
    remove(path);
    free(buf);
    if (lines != N + 1 || rows[0] != N + 1 || rows[2] != N + 1 || rows[3] != N + 1
        || memcmp(&sum[2], &sum[3], sizeof sum[2]) != 0)
        return 1;
    printf("bench_csv: %d records of %d numeric columns, %.1f MB cached; machine busy %.0f%% "
           "before the run\n", N, COLS, bytes / 1e6, 100.0 * busy);
    printf("%-30s %12s %10s %10s\n", "pass", "ns/record", "MB/s", "ratio");
    printf("%-30s %12.1f %10.0f %10.2f\n", "read floor (read + memchr)", 1e9 * t_floor / N,
           bytes / 1e6 / t_floor, 1.0);
    for (int s = 0; s < 4; s++)
        printf("%-30s %12.1f %10.0f %10.2f\n", stage_name[s], 1e9 * t[s] / N, bytes / 1e6 / t[s],
               t[s] / t_floor);
    printf("goal: the whole parse as the commands do it (one pass) at 450 MB/s or more, "
           "100 ns a record or less: %s\n",
           bytes / 1e6 / t[3] >= 450.0 && 1e9 * t[3] / N <= 100.0 ? "met" : "not met");
    return 0;
}
