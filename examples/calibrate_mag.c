/* SPDX-License-Identifier: MIT */
/* Calibrate a magnetometer: fold a recording into the 35 moments of
   degree four, fit a sphere, an axis-aligned ellipsoid and a full
   ellipsoid, print them, and plot raw against calibrated samples.

   The recording is the QMC5883L of ../shared/data (or $FOLDEST_DATA), a
   sensor with strong soft iron; without it, a synthetic one is generated.
   With gnuplot on PATH the plot goes to $FOLDEST_OUT (default build/out).

   Build against an installed foldest:
     cc calibrate_mag.c $(pkg-config --cflags --libs foldest) -o calibrate_mag */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <foldest.h>

enum { MAX_SAMPLES = 100000 };

/* Read "mx,my,mz" rows after the header line of the recording; the number
   of samples, or 0 if the file is missing or malformed. */
static size_t read_recording(const char *path, double *x, size_t max)
{
    char line[256];
    size_t n = 0;
    int header = 0;
    FILE *f = fopen(path, "r");
    if (f == NULL)
        return 0;
    while (n < max && fgets(line, sizeof line, f) != NULL) {
        if (!header) {
            header = strncmp(line, "mx,my,mz", 8) == 0;
            continue;
        }
        if (sscanf(line, "%lf,%lf,%lf", &x[3 * n], &x[3 * n + 1], &x[3 * n + 2]) != 3) {
            n = 0;
            break;
        }
        n++;
    }
    fclose(f);
    return n;
}

/* A synthetic magnetometer: hard iron (6000, 250, 3500) counts, soft iron
   stretching the 1100-count field into an ellipsoid, noise of 3 counts. */
static size_t synthesise(double *x, size_t n)
{
    const double S[9] = {0.66, 0.02, 0.01, 0.02, 1.0, 0.04, 0.01, 0.04, 1.45};
    const double b[3] = {6000, 250, 3500};
    fe_rng g = fe_rng_seed(4);
    for (size_t i = 0; i < n; i++) {
        double v[3];
        fe_rng_unit_vector(&g, v);
        for (int r = 0; r < 3; r++)
            x[3 * i + r] = b[r] + 3.0 * fe_rng_normal(&g)
                         + 1100.0 * (S[3 * r] * v[0] + S[3 * r + 1] * v[1] + S[3 * r + 2] * v[2]);
    }
    return n;
}

static void print_fit(const char *name, int rc, const fe_sphere_fit *f)
{
    if (rc != FE_OK) {
        printf("  %-9s refused: %s (%s)\n", name,
               f->refusal ? fe_sphere_refusal_string(f->refusal) : "", fe_strerror(rc));
        return;
    }
    printf("  %-9s offset (%.1f, %.1f, %.1f) +- (%.2f, %.2f, %.2f), field %.1f,"
           " semi-axes %.1f %.1f %.1f, rms %.2f%%, %d iterations%s\n",
           name, f->offset[0], f->offset[1], f->offset[2], f->se[0], f->se[1], f->se[2],
           f->radius, f->axes[0], f->axes[1], f->axes[2], f->rms_percent, f->iterations,
           f->algebraic ? " (ran away: the algebraic sphere)" : "");
}

static void plot(const double *x, size_t n, const fe_sphere_fit *f)
{
    const char *dir = getenv("FOLDEST_OUT");
    char path[1024], cmd[1200];
    FILE *data, *gp;
    if (system("command -v gnuplot >/dev/null 2>&1") != 0) {
        printf("(no gnuplot on PATH: no plot)\n");
        return;
    }
    if (dir == NULL || *dir == '\0')
        dir = "build/out";
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
    if (system(cmd) != 0)
        return;
    snprintf(path, sizeof path, "%s/calibrate_mag.dat", dir);
    data = fopen(path, "w");
    if (data == NULL)
        return;
    /* Raw samples about the fitted centre, and calibrated ones scaled by
       the field: both in counts, both should be a circle in each view. */
    for (size_t i = 0; i < n; i += n > 4000 ? n / 4000 : 1) {
        double y[3];
        fe_sphere_apply(f, x + 3 * i, y);
        fprintf(data, "%g %g %g %g %g %g\n", x[3 * i] - f->offset[0],
                x[3 * i + 1] - f->offset[1], x[3 * i + 2] - f->offset[2],
                f->radius * y[0], f->radius * y[1], f->radius * y[2]);
    }
    fclose(data);
    gp = popen("gnuplot", "w");
    if (gp == NULL)
        return;
    fprintf(gp, "set terminal pngcairo size 1200,600\n"
                "set output '%s/calibrate_mag.png'\n"
                "set multiplot layout 1,2 title 'Magnetometer: raw (about the fitted centre) and calibrated, counts'\n"
                "set size ratio -1\nset key top left\n"
                "set title 'x-y'\n"
                "plot '%s' u 1:2 w p pt 7 ps 0.2 lc rgb '#c04040' t 'raw', '' u 4:5 w p pt 7 ps 0.2 lc rgb '#2060c0' t 'calibrated'\n"
                "set title 'x-z'\n"
                "plot '%s' u 1:3 w p pt 7 ps 0.2 lc rgb '#c04040' t 'raw', '' u 4:6 w p pt 7 ps 0.2 lc rgb '#2060c0' t 'calibrated'\n"
                "unset multiplot\n",
            dir, path, path);
    if (pclose(gp) == 0)
        printf("plot: %s/calibrate_mag.png\n", dir);
}

int main(void)
{
    static double x[3 * MAX_SAMPLES];
    const char *data = getenv("FOLDEST_DATA");
    char path[1024];
    size_t n;
    fe_quadric q;
    fe_sphere_fit fits[3];
    int rc[3];

    snprintf(path, sizeof path, "%s/qmc5883l_tomisuarez/filtered_raw_data.csv",
             data != NULL && *data != '\0' ? data : "../shared/data");
    n = read_recording(path, x, MAX_SAMPLES);
    if (n > 0) {
        printf("%s: %zu samples\n", path, n);
    } else {
        n = synthesise(x, 20000);
        printf("no recording at %s: %zu synthetic samples\n", path, n);
    }

    /* One pass: the moments.  The samples could be thrown away now. */
    fe_quadric_init(&q, NULL);
    if (fe_quadric_add_many(&q, x, n, NULL) != FE_OK) {
        fprintf(stderr, "a sample is not finite\n");
        return 1;
    }
    printf("folded into %zu bytes; coverage about %.0f%% of the sphere\n", sizeof q,
           100 * fe_quadric_coverage(&q));

    /* Three models from the same moments. */
    for (int m = 0; m < 3; m++) {
        rc[m] = fe_sphere_fit_moments(&q, (fe_sphere_model)m, NULL, &fits[m]);
        print_fit(fe_sphere_model_name(m), rc[m], &fits[m]);
    }
    if (rc[FE_FIT_ELLIPSOID] != FE_OK)
        return 1;
    printf("ellipsoid map M (y = M (x - b) on the unit sphere):\n");
    for (int i = 0; i < 3; i++)
        printf("  %12.5g %12.5g %12.5g\n", fits[2].matrix[3 * i], fits[2].matrix[3 * i + 1],
               fits[2].matrix[3 * i + 2]);
    plot(x, n, &fits[FE_FIT_ELLIPSOID]);
    return 0;
}
