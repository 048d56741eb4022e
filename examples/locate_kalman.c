/* SPDX-License-Identifier: MIT */
/* Where does a Kalman filter's model stop being right?

   A cart coasts at about 10 m/s; a position sensor reads it every 0.1 s
   with 1 m of noise, and a constant-velocity Kalman tracker follows it.
   For one minute in the middle of the run a drag a = -c v|v| acts on the
   cart; the tracker's model knows nothing of it.  Every step's report
   (NIS and whitened innovation) is folded into fe_innovations, twenty time
   blocks; at the end the blocks where the NIS is too large or the
   innovations are correlated are located, as windows in the format of
   `foldest discover --json`.

   Build against an installed foldest:
     cc locate_kalman.c $(pkg-config --cflags --libs foldest) -o locate_kalman */
#include <math.h>
#include <stdio.h>

#include <foldest.h>

enum { STEPS = 4000, BLOCKS = 20, DRAG_ON = 1700, DRAG_OFF = 2300 };

int main(void)
{
    const double dt = 0.1, sa = 0.05, sz = 1.0, c = 0.0005;
    const double Phi[4] = {1, dt, 0, 1};
    const double G[2] = {dt * dt / 2, dt};
    const double A[2] = {1, 0};
    const double Z[1] = {sz * sz};
    const double x0[2] = {0.0, 10.0}, P0[4] = {4.0, 0, 0, 1.0};
    double Xi[4], truth[2] = {0.5, 10.3}, mem[64], w, z;
    fe_kalman k;
    fe_innovations inn;
    fe_located loc[8];
    fe_rng rng = fe_rng_seed(2);
    size_t n;
    int rc;

    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            Xi[i * 2 + j] = sa * sa * G[i] * G[j];   /* the random acceleration */
    if ((rc = fe_kalman_init(&k, 2, 1, mem, sizeof mem / sizeof mem[0])) != FE_OK
        || (rc = fe_kalman_set_prior(&k, x0, P0)) != FE_OK
        || (rc = fe_innovations_init(&inn, BLOCKS, STEPS, 0)) != FE_OK) {
        fprintf(stderr, "locate_kalman: %s\n", fe_strerror(rc));
        return 1;
    }
    for (int s = 0; s < STEPS; s++) {
        fe_kalman_report rep = {0, 0, 0, NULL, &w, NULL};
        fe_kalman_track_obs o = {{Phi, NULL, NULL, 0, Xi}, {1, A, &z, Z}};
        double a = sa * fe_rng_normal(&rng);
        if (s >= DRAG_ON && s < DRAG_OFF)
            a -= c * truth[1] * fabs(truth[1]);       /* what the model misses */
        truth[0] += dt * truth[1] + G[0] * a;
        truth[1] += G[1] * a;
        z = truth[0] + sz * fe_rng_normal(&rng);
        if ((rc = fe_kalman_track_fast(&k, &o, &rep)) != FE_OK
            || (rc = fe_innovations_add(&inn, (s + 1) * dt, &rep)) != FE_OK) {
            fprintf(stderr, "locate_kalman: step %d: %s\n", s, fe_strerror(rc));
            return 1;
        }
    }
    if ((rc = fe_innovations_locate(&inn, 0.05, loc, 8, &n)) != FE_OK) {
        fprintf(stderr, "locate_kalman: %s\n", fe_strerror(rc));
        return 1;
    }
    printf("the drag acted from t = %.1f s to t = %.1f s\n", (DRAG_ON + 1) * dt, DRAG_OFF * dt);
    printf("located windows (family-wise level 0.05 over %d blocks):\n", BLOCKS);
    if (n == 0)
        printf("  none: the model explains the innovations everywhere\n");
    for (size_t i = 0; i < n && i < 8; i++) {
        char json[512];
        printf("  t = %.1f to %.1f s: mean NIS %.2f per degree of freedom (1 if right), "
               "lag-one autocorrelation %.2f (0 if right), found by %s, p = %.2g\n",
               loc[i].t0, loc[i].t1, loc[i].mean_nis, loc[i].lag1, loc[i].test,
               loc[i].p_value);
        fe_located_json(&loc[i], json, sizeof json);
        printf("  %s\n", json);
    }
    return 0;
}
