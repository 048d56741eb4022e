/* SPDX-License-Identifier: MIT */
/* Discovery when the missing physics changes the motion, from C.

   A pendulum (length 0.5 m) is driven by a torque.  Our model of it,

       theta'' = -(g/L) sin(theta) + tau / (m L^2),

   has no air drag; the real pendulum (simulated here with a drag
   -k omega |omega|, k = 0.001 per radian, and its angle measured with 1 mrad of
   coloured noise) swings a little less, and the two trajectories part.
   We give the model as a C function, let the library differentiate it for
   the Jacobian, carry every candidate term through the linearised model
   to its signature at the measured angle, fold the signatures with the
   engine's noise model, and select; then one Gauss-Newton step about the
   corrected trajectory (the deviation integrated through our own model).

   Build against an installed foldest:
     cc discover_dynamics.c $(pkg-config --cflags --libs foldest) -o discover_dynamics */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <foldest.h>

enum { ROWS = 6000, BLOCKS = 20 };
static const double G_L = 9.81 / 0.5, INERTIA = 0.2 * 0.5 * 0.5, K_DRAG = -0.001, DT = 0.005;

static double torque(double t)
{
    return 0.4 * sin(2.0 * 3.14159265 * 0.37 * t) + 0.25 * sin(2.0 * 3.14159265 * 1.3 * t + 1.0);
}

/* Our model: theta'' from the sample's position (angle), velocity and
   input (torque). */
static int pendulum(const fe_sample *s, double *deriv, void *user)
{
    (void)user;
    *deriv = -G_L * sin(s->position) + s->input / INERTIA;
    return 0;
}

/* The world: the model plus the drag it lacks, by RK4 at ten substeps. */
static double world(double x, double v, double t, double k)
{
    return -G_L * sin(x) + torque(t) / INERTIA + k * v * fabs(v);
}

static void simulate(double k, fe_sample *rows)
{
    double x = 0.3, v = 0.0, h = DT / 10.0;
    for (size_t i = 0; i < ROWS; i++) {
        double t = (double)i * DT;
        memset(&rows[i], 0, sizeof rows[i]);
        rows[i].t = t;
        rows[i].position = rows[i].sim = x;
        rows[i].velocity = v;
        rows[i].input = torque(t);
        for (int j = 0; j < 10; j++, t += h) {
            double k1x = v, k1v = world(x, v, t, k);
            double k2x = v + h / 2 * k1v, k2v = world(x + h / 2 * k1x, v + h / 2 * k1v, t + h / 2, k);
            double k3x = v + h / 2 * k2v, k3v = world(x + h / 2 * k2x, v + h / 2 * k2v, t + h / 2, k);
            double k4x = v + h * k3v, k4v = world(x + h * k3x, v + h * k3v, t + h, k);
            x += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
            v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
        }
    }
}

/* The forcing of the deviation: the discovered terms times their
   coefficients (theta, over the catalog's terms). */
typedef struct forcing {
    const fe_catalog *c;
    const double *theta;
} forcing;

static int force(const fe_sample *s, double *g, void *user)
{
    const forcing *f = user;
    double phi[FE_DISCOVER_MAX_COLUMNS];
    int rc = fe_catalog_eval(f->c, s, phi);
    *g = 0.0;
    for (size_t j = 1; rc == FE_OK && j < f->c->count; j++)
        *g += f->theta[j] * phi[j];
    return rc;
}

/* One fold of every row: signatures about the trajectory corrected by
   theta (zero: the simulation itself), the residual as pseudo-observation,
   then selection with the sensor's offset as the base. */
static int fold_and_select(const fe_sample *sim, const double *real, const fe_catalog *c,
                           const double *theta, fe_discover_result *res, double *storage,
                           size_t nst, double *work, size_t nwork)
{
    fe_dynamics_sens sn;
    fe_dynamics_deviation dv;
    fe_discover_acc acc;
    fe_discover_group groups[FE_DISCOVER_MAX_GROUPS];
    fe_discover_options opt = fe_discover_default_options();
    forcing f = {c, theta};
    size_t base = FE_DYNAMICS_OFFSET;
    int rc;
    if ((rc = fe_dynamics_sens_init(&sn, 2, c->count - 1)) != FE_OK
        || (rc = fe_dynamics_deviation_init(&dv, 2)) != FE_OK
        || (rc = fe_discover_acc_init(&acc, c->count, BLOCKS, ROWS * 4 / 5, 0, storage, nst))
               != FE_OK)
        return rc;
    for (size_t i = 0; i < ROWS; i++) {
        fe_sample s = sim[i];
        double a[2], d[2], phi[FE_DISCOVER_MAX_COLUMNS], col[FE_DISCOVER_MAX_COLUMNS], r;
        if ((rc = fe_dynamics_jacobian_fd(pendulum, NULL, 2, &s, a)) != FE_OK
            || (rc = fe_dynamics_deviation_step(&dv, &s, a, pendulum, NULL, force, &f, d)) != FE_OK)
            return rc;
        s.position += d[0];                     /* the corrected trajectory */
        s.velocity += d[1];
        if ((rc = fe_dynamics_jacobian_fd(pendulum, NULL, 2, &s, a)) != FE_OK
            || (rc = fe_catalog_eval(c, &s, phi)) != FE_OK
            || (rc = fe_dynamics_sens_step(&sn, s.t, a, phi + 1, col + 1, NULL)) != FE_OK)
            return rc;
        col[FE_DYNAMICS_OFFSET] = phi[FE_DYNAMICS_OFFSET];
        r = real[i] - sim[i].sim - d[0];
        for (size_t j = 1; j < c->count; j++)
            r += theta[j] * col[j];
        if ((rc = fe_discover_add(&acc, col, r)) != FE_OK)
            return rc;
    }
    fe_catalog_groups(c, groups);
    opt.base = &base;
    opt.nbase = 1;
    return fe_discover_select(&acc, groups, c->count, &opt, res, work, nwork);
}

int main(void)
{
    fe_sample *sim = malloc(ROWS * sizeof *sim), *truth = malloc(ROWS * sizeof *truth);
    double *real = malloc(ROWS * sizeof *real), theta[FE_DISCOVER_MAX_GROUPS] = {0};
    fe_discover_result *res = malloc(sizeof *res);
    fe_catalog c;
    fe_catalog_scale sc;
    fe_rng rng = fe_rng_seed(42);
    double e = 0.0, *storage = NULL, *work = NULL;
    size_t nst, nwork;
    int rc = FE_EINVAL;
    if (sim == NULL || truth == NULL || real == NULL || res == NULL)
        goto out;
    simulate(0.0, sim);             /* our model */
    simulate(K_DRAG, truth);        /* the world */
    for (size_t i = 0; i < ROWS; i++) {
        e = 0.7 * e + sqrt(1.0 - 0.49) * 1e-3 * fe_rng_normal(&rng);
        real[i] = truth[i].position + e;
    }
    memset(&sc, 0, sizeof sc);
    for (size_t i = 0; i < ROWS; i++)
        fe_catalog_scale_add(&sc, &sim[i]);
    if ((rc = fe_dynamics_catalog_init(&c, 2, FE_ROLE_POSITION | FE_ROLE_VELOCITY | FE_ROLE_INPUT,
                                       &sc)) != FE_OK)
        goto out;
    nst = fe_discover_acc_doubles(c.count, BLOCKS);
    nwork = fe_discover_workspace_doubles(c.count, BLOCKS);
    storage = malloc(nst * sizeof *storage);
    work = malloc(nwork * sizeof *work);
    if (storage == NULL || work == NULL)
        goto out;
    for (int it = 0; it < 3; it++) {    /* the first fold, then Gauss-Newton */
        if ((rc = fold_and_select(sim, real, &c, theta, res, storage, nst, work, nwork)) != FE_OK)
            goto out;
        memset(theta, 0, sizeof theta);
        for (size_t j = 0; j < res->ncols; j++)
            if (res->cols[j] != FE_DYNAMICS_OFFSET)
                theta[res->cols[j]] = res->coef[j];
        printf("fold %d:", it + 1);
        for (size_t s = 0; s < res->steps; s++)
            printf(" %s", c.terms[res->added[s]].name);
        printf("%s\n", res->steps ? "" : " nothing named");
    }
    for (size_t s = 0; s < res->steps; s++)
        for (size_t j = 0; j < res->ncols; j++)
            if (res->cols[j] == res->added[s]) {
                char words[256];
                fe_dynamics_explain(c.terms[res->added[s]].name, 2, res->coef[j], res->stderr_[j],
                                    words, sizeof words);
                printf("  %s\n", words);
            }
    printf("truth: quadratic drag k = %.4g (per unit angle); held-out RMS %.3g -> %.3g rad\n",
           -K_DRAG, res->baseline.heldout_rms, res->final.heldout_rms);
out:
    if (rc != FE_OK)
        fprintf(stderr, "discover_dynamics: %s\n", fe_strerror(rc));
    free(sim);
    free(truth);
    free(real);
    free(res);
    free(storage);
    free(work);
    return rc == FE_OK ? 0 : 1;
}
