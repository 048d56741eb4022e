/* SPDX-License-Identifier: MIT */
/* A vacuum free-fall simulation of each recorded drop, for foldest discover.

   The recordings (../shared/data/freefall-drag/csv/fall_N.csv, or
   $FOLDEST_DATA/freefall-drag/csv) hold a phone's specific force while it
   rests in a hand, falls and is caught.  In a vacuum the accelerometer would
   read g at rest and 0 in free fall; that is the simulation this program
   writes, one file per recording, into $FOLDEST_OUT/freefall (default
   build/out/freefall):

     - the release is where |a| falls through g/2 at the start of the longest
       run of samples below 3 m/s^2; the catch is the end of that run;
     - the simulation covers the free fall, 0.03 s after the release to
       0.04 s before the catch (|a| = 0, velocity -g (t - t_release), height
       -g (t - t_release)^2 / 2); the release and the catch, where the hand
       acts, and the rest in the hand before them are left out (rows
       discover does not compare).  A drop is about 115 rows.

   Usage: freefall_sim [DIR_WITH_fall_N.csv [OUT_DIR]]
   Prints one line per drop, and the discover command for all of them. */
#define _POSIX_C_SOURCE 200809L
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <foldest.h>

#define G 9.80665

/* Read time and |a| (columns 1 and 5) of a phyphox export. */
static int read_drop(const char *path, double **t, double **a, size_t *n)
{
    char buf[4096], *line;
    size_t len, cap = 0;
    fe_csv_reader r;
    fe_csv_field f[8];
    int fd = open(path, O_RDONLY), rc;
    if (fd < 0)
        return FE_EIO;
    fe_csv_reader_init(&r, fd, buf, sizeof buf);
    *n = 0;
    *t = *a = NULL;
    while ((rc = fe_csv_next_line(&r, &line, &len)) == FE_OK) {
        size_t nf;
        double tv, av;
        if (fe_csv_split(line, ',', f, 8, &nf, NULL) != FE_OK || nf != 5
            || fe_csv_number(&f[0], &tv) != FE_OK || fe_csv_number(&f[4], &av) != FE_OK)
            continue;                   /* the header */
        if (*n == cap) {
            cap = cap ? 2 * cap : 1024;
            *t = realloc(*t, cap * sizeof **t);
            *a = realloc(*a, cap * sizeof **a);
            if (*t == NULL || *a == NULL) {
                close(fd);
                return FE_ENOMEM;
            }
        }
        (*t)[*n] = tv;
        (*a)[(*n)++] = av;
    }
    close(fd);
    return rc == FE_END ? FE_OK : rc;
}

int main(int argc, char **argv)
{
    const char *data = getenv("FOLDEST_DATA"), *outdir_env = getenv("FOLDEST_OUT");
    char dir[2048], outdir[2048], cmd[32768];
    size_t cmdlen = 0, drops = 0;
    if (argc > 1)
        snprintf(dir, sizeof dir, "%s", argv[1]);
    else
        snprintf(dir, sizeof dir, "%s/freefall-drag/csv", data ? data : "../shared/data");
    if (argc > 2)
        snprintf(outdir, sizeof outdir, "%s", argv[2]);
    else
        snprintf(outdir, sizeof outdir, "%s/freefall", outdir_env ? outdir_env : "build/out");
    {
        char probe[2100];
        snprintf(probe, sizeof probe, "%s/fall_1.csv", dir);
        if (access(probe, R_OK) != 0) {
            printf("freefall_sim: no recordings in %s (set FOLDEST_DATA); skipped\n", dir);
            return 0;
        }
    }
    mkdir(argc > 2 ? outdir : (outdir_env ? outdir_env : "build/out"), 0777);
    mkdir(outdir, 0777);
    cmdlen += (size_t)snprintf(cmd, sizeof cmd, "foldest discover");
    for (int k = 1; k <= 12; k++) {
        char in[2200], out[2200];
        double *t = NULL, *a = NULL, t_rel = 0, t_catch;
        size_t n, best0 = 0, best1 = 0, i, rows = 0;
        FILE *f;
        snprintf(in, sizeof in, "%s/fall_%d.csv", dir, k);
        if (read_drop(in, &t, &a, &n) != FE_OK || n < 100) {
            free(t);
            free(a);
            continue;
        }
        /* The longest run below 3 m/s^2 is the flight. */
        for (i = 0; i < n;) {
            size_t j = i;
            while (j < n && a[j] < 3.0)
                j++;
            if (j - i > best1 - best0) {
                best0 = i;
                best1 = j;
            }
            i = j + 1;
        }
        if (best1 - best0 < 40 || best0 == 0) {
            printf("fall_%d: no clear flight; skipped\n", k);
            free(t);
            free(a);
            continue;
        }
        /* Release: where |a| crosses g/2 before the run. */
        for (i = best0; i > 0; i--)
            if (a[i - 1] >= G / 2) {
                t_rel = t[i - 1] + (t[i] - t[i - 1]) * (a[i - 1] - G / 2) / (a[i - 1] - a[i]);
                break;
            }
        t_catch = t[best1 - 1];
        snprintf(out, sizeof out, "%s/fall_%d_sim.csv", outdir, k);
        f = fopen(out, "w");
        if (f == NULL) {
            perror(out);
            return 1;
        }
        fprintf(f, "\"Time (s)\",\"Absolute acceleration (m/s^2)\",\"velocity (m/s)\",\"height (m)\"\n");
        for (i = 0; i < n; i++) {
            double dt = t[i] - t_rel;
            if (dt >= 0.03 && t[i] <= t_catch - 0.04) {
                fprintf(f, "%.9f,0,%.6f,%.6f\n", t[i], -G * dt, -0.5 * G * dt * dt);
                rows++;
            }
        }
        fclose(f);
        printf("fall_%-2d release at %.3f s, caught at %.3f s (flight %.2f s): %zu simulated rows\n",
               k, t_rel, t_catch, t_catch - t_rel, rows);
        cmdlen += (size_t)snprintf(cmd + cmdlen, sizeof cmd - cmdlen, " --real %s --sim %s", in, out);
        drops++;
        free(t);
        free(a);
    }
    /* Each drop is a recording of its own (its own offset); analysed alone,
       every row is fitted: a held-out tail would be the fall's fastest
       part, where drag shows most. */
    snprintf(cmd + cmdlen, sizeof cmd - cmdlen,
             " --channel Absolute --time Time --role velocity=velocity --base bias"
             " --holdout 0");
    printf("%zu drops simulated; analyse each alone (one --real/--sim pair) with:\n%s\n", drops,
           cmd);
    return 0;
}
