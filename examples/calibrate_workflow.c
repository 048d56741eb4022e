/* SPDX-License-Identifier: MIT */
/* A magnetometer calibration from end to end, through the library:

     1. log:       a logger process writes "mx,my,mz" lines into a pipe
                   (here a simulated QMC5883L: 3 counts per milligauss, hard
                   and soft iron, turned by hand, with the odd glitch); we
                   keep a copy of the log as it passes;
     2. calibrate: the samples are folded as they arrive, in constant
                   memory, into moments kept in blocks of time (honest
                   errors) and fitted with the full ellipsoid; two passes
                   over the kept log reject the glitches (a robust scale
                   from the median radial error) and the kept samples are
                   fitted again; the fit is scaled to the known local field,
                   480 mG;
     3. export:    ArduPilot's COMPASS_OFS/DIA/ODI parameters and a C header
                   with float arrays;
     4. apply:     fresh samples from the same sensor corrected the way
                   ArduPilot does (mat (h + ofs)) and the way the header
                   does (float arithmetic), checked against 480 mG.

   The command does the same from the shell:
     logger | tee log.csv | foldest calibrate --model ellipsoid --robust - (flags)
     foldest calibrate --model ellipsoid --robust --field 480 \
                       --export ardupilot --mgauss 0.3333333 log.csv

   Build against an installed foldest:
     cc calibrate_workflow.c $(pkg-config --cflags --libs foldest) -o calibrate_workflow */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <foldest.h>

/* The simulated sensor: counts = G (B + noise) + hard, with B the field in
   milligauss, G a soft-iron matrix in counts per milligauss. */
static const double FIELD = 480.0, COUNTS_PER_MG = 3.0;
static const double HARD[3] = {6200.0, 250.0, 3480.0};
static const double SOFT[9] = {1.00, 0.05, 0.00,
                               0.05, 1.45, 0.04,
                               0.00, 0.04, 0.70};

static void sensor(fe_rng *g, const double dir[3], double counts[3])
{
    for (int i = 0; i < 3; i++) {
        counts[i] = HARD[i];
        for (int j = 0; j < 3; j++)
            counts[i] += COUNTS_PER_MG * SOFT[3 * i + j] * (FIELD * dir[j] + 1.0 * fe_rng_normal(g));
    }
}

/* Fold every sample of the log whose radial error under `fit` is at most
   `threshold` (all when threshold is infinite) into q; fill h (if not NULL)
   with the radial errors.  Returns the number rejected. */
static unsigned long pass(FILE *log, const fe_sphere_fit *fit, double threshold,
                          fe_quadric_blocks *q, fe_radial_hist *h)
{
    char line[256];
    double x[3];
    unsigned long rejected = 0;
    rewind(log);
    if (q != NULL)
        fe_quadric_blocks_init(q);
    while (fgets(line, sizeof line, log) != NULL) {
        double e;
        if (sscanf(line, "%lf,%lf,%lf", &x[0], &x[1], &x[2]) != 3)
            continue;
        e = fe_sphere_radial(fit, x);
        if (h != NULL)
            fe_radial_hist_add(h, e);
        if (fabs(e) > threshold)
            rejected++;
        else if (q != NULL)
            fe_quadric_blocks_add(q, x);
    }
    return rejected;
}

/* 1. The logger: 20000 samples of a hand-turned sensor at 50 Hz (the
   direction wanders), one in 400 a glitch 40 % off. */
static void logger(FILE *out)
{
    fe_rng g = fe_rng_seed(2026);
    double dir[3], x[3];
    fe_rng_unit_vector(&g, dir);
    fprintf(out, "mx,my,mz\n");
    for (int i = 0; i < 20000; i++) {
        double len = 0.0;
        for (int j = 0; j < 3; j++) {
            dir[j] += 0.08 * fe_rng_normal(&g);
            len += dir[j] * dir[j];
        }
        for (int j = 0; j < 3; j++)
            dir[j] /= sqrt(len);
        sensor(&g, dir, x);
        if (i % 400 == 123)
            for (int j = 0; j < 3; j++)
                x[j] = HARD[j] + 1.4 * (x[j] - HARD[j]);
        fprintf(out, "%.1f,%.1f,%.1f\n", x[0], x[1], x[2]);
    }
}

int main(void)
{
    static fe_quadric_blocks q;         /* 13 KB: static, off the stack */
    fe_sphere_fit fit;
    fe_sphere_scaled sc;
    fe_sphere_ardupilot ap;
    fe_rng g = fe_rng_seed(7);
    char line[256];
    int fd[2], status, rc, bad = 0;
    unsigned long n = 0, rejected;
    fe_radial_hist hist;
    double threshold;
    FILE *log = tmpfile();
    double worst_ap = 0.0, worst_c = 0.0;
    float c_offset[3], c_matrix[3][3];
    pid_t pid;
    FILE *in;

    /* 1. Log from a pipe. */
    if (pipe(fd) != 0 || (pid = fork()) < 0) {
        perror("calibrate_workflow");
        return 1;
    }
    if (pid == 0) {
        FILE *out = fdopen(fd[1], "w");
        close(fd[0]);
        if (out == NULL)
            _exit(1);
        logger(out);
        _exit(fclose(out) == 0 ? 0 : 1);
    }
    close(fd[1]);
    in = fdopen(fd[0], "r");
    if (in == NULL || log == NULL)
        return 1;

    /* 2. Calibrate: fold each sample as it arrives, then fit. */
    fe_quadric_blocks_init(&q);
    while (fgets(line, sizeof line, in) != NULL) {
        double x[3];
        if (sscanf(line, "%lf,%lf,%lf", &x[0], &x[1], &x[2]) != 3)
            continue;                   /* the header */
        if (fe_quadric_blocks_add(&q, x) == FE_OK)
            n++;
        fputs(line, log);               /* the log, for the robust passes */
    }
    fclose(in);
    waitpid(pid, &status, 0);
    rc = fe_sphere_fit_blocks(&q, FE_FIT_ELLIPSOID, NULL, &fit);
    if (rc != FE_OK) {
        fprintf(stderr, "fit refused: %s\n", fe_sphere_refusal_string(fit.refusal));
        return 1;
    }
    printf("folded %lu samples from the pipe; ellipsoid fit, rms %.2f %% of the field\n", n,
           fit.rms_percent);
    /* Outliers: the bulk's robust scale under the first fit, then the
       samples within 5 of it folded and fitted again. */
    memset(&hist, 0, sizeof hist);
    pass(log, &fit, INFINITY, NULL, &hist);
    threshold = 5.0 * fe_radial_hist_scale(&hist);
    rejected = pass(log, &fit, threshold, &q, NULL);
    fclose(log);
    rc = fe_sphere_fit_blocks(&q, FE_FIT_ELLIPSOID, NULL, &fit);
    if (rc != FE_OK)
        return 1;
    printf("robust: %lu glitches beyond %.2f %% of the field rejected; refitted, rms %.2f %%\n",
           rejected, 100 * threshold, fit.rms_percent);
    fe_sphere_scale(&fit, FIELD, &sc);  /* calibrated samples in mG */
    printf("offset (counts)   %.2f +- %.2g, %.2f +- %.2g, %.2f +- %.2g  (true %.0f, %.0f, %.0f)\n",
           fit.offset[0], fit.se[0], fit.offset[1], fit.se[1], fit.offset[2], fit.se[2], HARD[0],
           HARD[1], HARD[2]);
    printf("errors from %d blocks in time: %.1f to %.1f times the independent-sample ones\n",
           fit.se_blocks, fmin(fit.se[0] / fit.se_iid[0], fit.se[2] / fit.se_iid[2]),
           fmax(fit.se[0] / fit.se_iid[0], fit.se[2] / fit.se_iid[2]));
    printf("fitted field %.1f counts: gain %.4f counts per mG against the known %.0f mG\n\n",
           fit.radius, sc.gain, FIELD);
    for (int j = 0; j < 3; j++)
        bad |= fabs(fit.offset[j] - HARD[j]) > fmax(5.0 * fit.se[j], 1.0);

    /* 3. Export: ArduPilot's parameters (milligauss: K = 1/3 mG per count),
       and a C header. */
    fe_sphere_to_ardupilot(&fit, FIELD, 1.0 / COUNTS_PER_MG, &ap);
    printf("# ArduPilot parameters\n");
    for (int j = 0; j < 3; j++)
        printf("COMPASS_OFS_%c %.3f\n", 'X' + j, ap.ofs[j]);
    for (int j = 0; j < 3; j++)
        printf("COMPASS_DIA_%c %.6f\n", 'X' + j, ap.dia[j]);
    for (int j = 0; j < 3; j++)
        printf("COMPASS_ODI_%c %.6f\n", 'X' + j, ap.odi[j]);
    printf("\n/* C header */\nstatic const float FOLDEST_CAL_OFFSET[3] = {%#.9gf, %#.9gf, %#.9gf};\n",
           sc.offset[0], sc.offset[1], sc.offset[2]);
    printf("static const float FOLDEST_CAL_MATRIX[3][3] = {\n");
    for (int i = 0; i < 3; i++) {
        printf("    {%#.9gf, %#.9gf, %#.9gf}%s\n", sc.matrix[3 * i], sc.matrix[3 * i + 1],
               sc.matrix[3 * i + 2], i < 2 ? "," : "");
        c_offset[i] = (float)sc.offset[i];
        for (int j = 0; j < 3; j++)
            c_matrix[i][j] = (float)sc.matrix[3 * i + j];
    }
    printf("};\n\n");

    /* 4. Apply to fresh samples, ArduPilot's way and the header's way. */
    for (int k = 0; k < 1000; k++) {
        double dir[3], x[3], h[3], out[3], len_ap, len_c;
        float u[3], yc[3];
        const double mat[9] = {ap.dia[0], ap.odi[0], ap.odi[1], ap.odi[0], ap.dia[1],
                               ap.odi[2], ap.odi[1], ap.odi[2], ap.dia[2]};
        fe_rng_unit_vector(&g, dir);
        sensor(&g, dir, x);
        for (int j = 0; j < 3; j++)
            h[j] = x[j] / COUNTS_PER_MG + ap.ofs[j];       /* driver's mG, offsets added */
        for (int i = 0; i < 3; i++)
            out[i] = mat[3 * i] * h[0] + mat[3 * i + 1] * h[1] + mat[3 * i + 2] * h[2];
        for (int j = 0; j < 3; j++)
            u[j] = (float)x[j] - c_offset[j];
        for (int i = 0; i < 3; i++)
            yc[i] = c_matrix[i][0] * u[0] + c_matrix[i][1] * u[1] + c_matrix[i][2] * u[2];
        len_ap = sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
        len_c = sqrt((double)(yc[0] * yc[0] + yc[1] * yc[1] + yc[2] * yc[2]));
        worst_ap = fmax(worst_ap, fabs(len_ap / FIELD - 1.0));
        worst_c = fmax(worst_c, fabs(len_c / FIELD - 1.0));
    }
    printf("1000 fresh samples corrected: worst |B| off 480 mG by %.2f %% (ArduPilot's way),"
           " %.2f %% (the float header)\n", 100 * worst_ap, 100 * worst_c);
    /* The sensor's noise is 1 mG per axis on 480: a few tenths of a per cent. */
    bad |= worst_ap > 0.01 || worst_c > 0.01 || rejected != 50 || !WIFEXITED(status)
           || WEXITSTATUS(status) != 0;
    if (bad)
        fprintf(stderr, "calibrate_workflow: the calibration is off\n");
    return bad;
}
