/* SPDX-License-Identifier: MIT */
/* The falling object of Kalman Folding 2, tracked by a fold.

   State: height and vertical speed.  Each step of 0.1 s the object falls
   under gravity (the control input) plus a small random acceleration, and
   a sensor reads its height with 1 m of noise.  The tracker folds one
   predict-and-update per reading; the innovation monitor folds the
   tracker's reports.  Prints truth, estimate and 1-sigma bounds every
   second, the monitor's verdict, and, when gnuplot is on PATH, writes
   kalman_tracker.png into $FOLDEST_OUT (default build/out).

   Build against an installed foldest:
     cc kalman_tracker.c $(pkg-config --cflags --libs foldest) -o kalman_tracker */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <foldest.h>

enum { STEPS = 120 };

/* mkdir -p */
static int make_dirs(const char *path)
{
    char buf[4096];
    size_t len = strlen(path);
    if (len == 0 || len >= sizeof buf)
        return -1;
    memcpy(buf, path, len + 1);
    for (size_t i = 1; i <= len; i++)
        if (buf[i] == '/' || buf[i] == '\0') {
            char c = buf[i];
            buf[i] = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return -1;
            buf[i] = c;
        }
    return 0;
}

int main(void)
{
    const double dt = 0.1, g = -9.8, sa = 0.5, sz = 1.0;
    const double Phi[4] = {1, dt, 0, 1};
    const double Gamma[2] = {dt * dt / 2, dt};
    const double u[1] = {g};
    const double A[2] = {1, 0};
    const double Z[1] = {sz * sz};
    const double x0[2] = {1000.0, 0.0};           /* the filter's prior */
    const double P0[4] = {25.0, 0, 0, 4.0};
    double Xi[4], truth[2] = {1003.0, 1.5};       /* the truth starts elsewhere */
    static double rows[STEPS][7];
    double mem[64], w;
    fe_kalman k;
    fe_kalman_monitor mon;
    fe_rng rng = fe_rng_seed(1);
    double lo, hi;
    int rc;

    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            Xi[i * 2 + j] = sa * sa * Gamma[i] * Gamma[j];
    if (fe_kalman_doubles(2, 1) > sizeof mem / sizeof mem[0]
        || (rc = fe_kalman_init(&k, 2, 1, mem, sizeof mem / sizeof mem[0])) != FE_OK
        || (rc = fe_kalman_set_prior(&k, x0, P0)) != FE_OK
        || (rc = fe_kalman_monitor_init(&mon, NULL)) != FE_OK) {
        fprintf(stderr, "kalman_tracker: setup failed\n");
        return 1;
    }

    printf("%6s %10s %10s %8s %10s %10s %8s\n", "t (s)", "height", "estimate",
           "1 sigma", "speed", "estimate", "1 sigma");
    for (int s = 0; s < STEPS; s++) {
        /* The world moves, the sensor reads. */
        double a = g + sa * fe_rng_normal(&rng), z;
        fe_kalman_report rep = {0, 0, 0, NULL, &w, NULL};
        fe_kalman_track_obs t = {{Phi, Gamma, u, 1, Xi}, {1, A, &z, Z}};
        truth[0] += dt * truth[1] + Gamma[0] * a;
        truth[1] += Gamma[1] * a;
        z = truth[0] + sz * fe_rng_normal(&rng);
        /* The fold: one tracker step, one monitor step. */
        if ((rc = fe_kalman_track_fast(&k, &t, &rep)) != FE_OK
            || (rc = fe_kalman_monitor_add(&mon, &rep)) != FE_OK) {
            fprintf(stderr, "kalman_tracker: step %d: %s\n", s, fe_strerror(rc));
            return 1;
        }
        rows[s][0] = (s + 1) * dt;
        rows[s][1] = truth[0];
        rows[s][2] = z;
        rows[s][3] = k.x[0];
        rows[s][4] = fe_kalman_sigma(&k, 0);
        rows[s][5] = k.x[1] - truth[1];
        rows[s][6] = fe_kalman_sigma(&k, 1);
        if ((s + 1) % 10 == 0)
            printf("%6.1f %10.3f %10.3f %8.3f %10.3f %10.3f %8.3f\n", (s + 1) * dt,
                   truth[0], k.x[0], rows[s][4], truth[1], k.x[1], rows[s][6]);
    }
    fe_kalman_monitor_nis_band(&mon, 0.95, &lo, &hi);
    printf("mean NIS %.3f (95%% band for a right model: [%.3f, %.3f]); "
           "lag-1 autocorrelation %.3f; CUSUM alarms %llu\n",
           fe_kalman_monitor_mean_nis(&mon), lo, hi,
           fe_kalman_monitor_autocorr(&mon, 1, NULL), (unsigned long long)mon.alarms);

    /* A plot, when gnuplot is here. */
    if (system("command -v gnuplot >/dev/null 2>&1") == 0) {
        const char *out = getenv("FOLDEST_OUT");
        char data[4200], png[4200];
        FILE *f, *gp;
        if (out == NULL || *out == '\0')
            out = "build/out";
        snprintf(data, sizeof data, "%s/kalman_tracker.dat", out);
        snprintf(png, sizeof png, "%s/kalman_tracker.png", out);
        if (make_dirs(out) != 0 || (f = fopen(data, "w")) == NULL) {
            fprintf(stderr, "kalman_tracker: cannot write into %s\n", out);
            return 1;
        }
        for (int s = 0; s < STEPS; s++)
            fprintf(f, "%g %.6f %.6f %.6f %.6f %.6f %.6f\n", rows[s][0], rows[s][1],
                    rows[s][2], rows[s][3], rows[s][4], rows[s][5], rows[s][6]);
        fclose(f);
        gp = popen("gnuplot", "w");
        if (gp == NULL) {
            fprintf(stderr, "kalman_tracker: cannot run gnuplot\n");
            return 1;
        }
        fprintf(gp,
                "set terminal pngcairo size 900,900\n"
                "set output '%s'\n"
                "set multiplot layout 3,1 title 'Falling object tracked by a Kalman fold'\n"
                "set xlabel 't (s)'\n"
                "set ylabel 'height (m)'\n"
                "plot '%s' u 1:3 w p pt 7 ps 0.3 t 'measured', '' u 1:2 w l t 'truth',"
                " '' u 1:4 w l t 'estimate'\n"
                "set ylabel 'height error (m)'\n"
                "plot '%s' u 1:(-$5):5 w filledcurves lc rgb '#cce0ff' t '+-1 sigma',"
                " '' u 1:($4-$2) w l lw 2 t 'estimate - truth'\n"
                "set ylabel 'speed error (m/s)'\n"
                "plot '%s' u 1:(-$7):7 w filledcurves lc rgb '#cce0ff' t '+-1 sigma',"
                " '' u 1:6 w l lw 2 t 'estimate - truth'\n"
                "unset multiplot\n",
                png, data, data, data);
        if (pclose(gp) != 0) {
            fprintf(stderr, "kalman_tracker: gnuplot failed\n");
            return 1;
        }
        printf("plot: %s\n", png);
    }
    return 0;
}
