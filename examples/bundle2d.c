/* SPDX-License-Identifier: MIT */
/* Two-dimensional bundle adjustment, after EJML's "Non-Linear Least
   Squares: Sparse Schur Complement" example.

   10 cameras on the line x = 0 (y uniform in +-10) see 40 landmarks at
   depth x = 20 (y uniform in +-10).  Each camera measures the bearing of
   every landmark, theta_ij = atan((ly - cy) / (lx - cx)), without noise.
   Starting from the truth plus N(0, 5^2) on every coordinate, Levenberg-
   Marquardt recovers the configuration, with a dense solve and with the
   Schur complement (cameras global, one 2-parameter block per landmark).
   The model compares directions (atan2, wrapped to +-pi): a camera sees
   which way a landmark lies, not only the line through it.

   Gauge: bearings do not change when the whole scene is translated or
   scaled, so the cost has a 3-dimensional valley of minima.  Here it has a
   fourth flat direction at the truth: the cameras lie on one line and the
   landmarks on another, a degenerate conic, and a complete bipartite
   framework on a conic has one more infinitesimal motion (Bolker and Roth,
   1980).  The example measures the rank of J'J at the truth with the
   library's Schur-complement scores (lsq.h) to show it.  The solver copes
   with all of it by Marquardt's damping: the damped normal equations are
   definite, and the gradient has no component along the flat directions.
   We hold camera 0 fixed (the translation, at no cost: any translate of a
   solution is a solution) and leave scale and flex to the damping.
   Holding a scale at a value read off the noisy start does not work: the
   start can imply a scale of the wrong sign, which no solution has.

   Usage: bundle2d [seeds]   (default 200)

   Build against an installed foldest:
     cc bundle2d.c $(pkg-config --cflags --libs foldest) -lm -o bundle2d */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <foldest.h>

enum { NCAM = 10, NLAND = 40 };

struct scene {
    double cam[NCAM][2], land[NLAND][2];
};

/* The problem: observed bearings, which camera coordinates are free and,
   for the fixed ones, their values. */
struct ba {
    int ncam, nland;
    const double *theta;        /* theta[i * nland + j] */
    int free_index[NCAM][2];    /* index among the globals, or -1: fixed */
    double fixed[NCAM][2];
    size_t ng;
};

static const double PI = 3.14159265358979323846;

static void make_scene(fe_rng *r, struct scene *s)
{
    for (int i = 0; i < NCAM; i++) {
        s->cam[i][0] = 0.0;
        s->cam[i][1] = 20.0 * fe_rng_uniform(r) - 10.0;
    }
    for (int j = 0; j < NLAND; j++) {
        s->land[j][0] = 20.0;
        s->land[j][1] = 20.0 * fe_rng_uniform(r) - 10.0;
    }
}

static void bearings(const struct scene *s, double *theta)
{
    for (int i = 0; i < NCAM; i++)
        for (int j = 0; j < NLAND; j++)
            theta[i * NLAND + j] = atan((s->land[j][1] - s->cam[i][1])
                                        / (s->land[j][0] - s->cam[i][0]));
}

/* The model: one residual per camera and landmark, the bearing error
   wrapped into (-pi/2, pi/2]. */
static int ba_model(const double *x, fe_lm_sink *sink, void *ctx)
{
    const struct ba *b = ctx;
    int want = fe_lm_wants_jacobian(sink);
    double jg[2 * NCAM] = {0};

    for (int i = 0; i < b->ncam; i++) {
        const int *fi = b->free_index[i];
        double cx = fi[0] >= 0 ? x[fi[0]] : b->fixed[i][0];
        double cy = fi[1] >= 0 ? x[fi[1]] : b->fixed[i][1];
        for (int j = 0; j < b->nland; j++) {
            const double *l = x + b->ng + 2 * j;
            double dx = l[0] - cx, dy = l[1] - cy, q = dx * dx + dy * dy;
            double f = atan2(dy, dx) - b->theta[i * b->nland + j];
            double jl[2] = {-dy / q, dx / q};
            int rc;
            f -= 2.0 * PI * floor(f / (2.0 * PI) + 0.5);
            if (want) {
                if (fi[0] >= 0)
                    jg[fi[0]] = dy / q;
                if (fi[1] >= 0)
                    jg[fi[1]] = -dx / q;
            }
            rc = fe_lm_emit(sink, f, 1.0, jg, (size_t)j, jl);
            if (fi[0] >= 0)
                jg[fi[0]] = 0.0;
            if (fi[1] >= 0)
                jg[fi[1]] = 0.0;
            if (rc != FE_OK)
                return rc;
        }
    }
    return FE_OK;
}

/* Set up the parameters from a starting scene: hold camera 0 at its
   starting position (fix = 1), or nothing (fix = 0). */
static void setup(struct ba *b, const struct scene *start, int fix, double *x)
{
    size_t k = 0;
    for (int i = 0; i < NCAM; i++)
        for (int c = 0; c < 2; c++) {
            int fixed = fix && i == 0;
            b->fixed[i][c] = start->cam[i][c];
            b->free_index[i][c] = fixed ? -1 : (int)k;
            if (!fixed)
                x[k++] = start->cam[i][c];
        }
    b->ng = k;
    for (int j = 0; j < NLAND; j++) {
        x[k++] = start->land[j][0];
        x[k++] = start->land[j][1];
    }
}

/* Map the estimate back to a scene. */
static void estimate(const struct ba *b, const double *x, struct scene *s)
{
    for (int i = 0; i < NCAM; i++)
        for (int c = 0; c < 2; c++)
            s->cam[i][c] = b->free_index[i][c] >= 0 ? x[b->free_index[i][c]]
                                                    : b->fixed[i][c];
    for (int j = 0; j < NLAND; j++) {
        s->land[j][0] = x[b->ng + 2 * j];
        s->land[j][1] = x[b->ng + 2 * j + 1];
    }
}

/* Largest distance between the estimate and the truth mapped by the best
   similarity p -> s p + t (least squares, scale and translation). */
static double similarity_error(const struct scene *truth, const struct scene *est)
{
    const double *P[NCAM + NLAND], *Q[NCAM + NLAND];
    double mp[2] = {0, 0}, mq[2] = {0, 0}, spq = 0, spp = 0, s, worst = 0;
    int n = NCAM + NLAND;
    for (int i = 0; i < NCAM; i++) {
        P[i] = truth->cam[i];
        Q[i] = est->cam[i];
    }
    for (int j = 0; j < NLAND; j++) {
        P[NCAM + j] = truth->land[j];
        Q[NCAM + j] = est->land[j];
    }
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 2; c++) {
            mp[c] += P[i][c] / n;
            mq[c] += Q[i][c] / n;
        }
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 2; c++) {
            spq += (P[i][c] - mp[c]) * (Q[i][c] - mq[c]);
            spp += (P[i][c] - mp[c]) * (P[i][c] - mp[c]);
        }
    s = spq / spp;
    for (int i = 0; i < n; i++) {
        double ex = s * (P[i][0] - mp[0]) + mq[0] - Q[i][0];
        double ey = s * (P[i][1] - mp[1]) + mq[1] - Q[i][1];
        worst = fmax(worst, sqrt(ex * ex + ey * ey));
    }
    return worst;
}

static int print_row(const fe_lm_iteration *it, void *ctx)
{
    (void)ctx;
    printf("%5d  %11.4e  %11.4e  %10.3e  %9.3f  %9.2e  %s\n", it->iteration,
           it->cost, it->change, it->step, it->ratio, it->lambda,
           it->accepted ? "yes" : "no");
    return 0;
}

struct run {
    int rc, iterations;
    double cost, sim_err;
    double x[2 * NCAM + 2 * NLAND];
};

static void run(const struct scene *truth, const struct scene *start, int fix,
                int method, fe_lm_report_fn *report, double *work, struct run *out)
{
    struct ba b;
    double theta[NCAM * NLAND];
    fe_lm_problem prob;
    fe_lm_result res;
    struct scene est;

    bearings(truth, theta);
    b.ncam = NCAM;
    b.nland = NLAND;
    b.theta = theta;
    setup(&b, start, fix, out->x);
    prob = (fe_lm_problem){b.ng, 2, NLAND, ba_model, &b};
    out->rc = fe_lm_solve(&prob, method, NULL, out->x, work, report, NULL, &res);
    out->iterations = res.iterations;
    out->cost = res.cost;
    estimate(&b, out->x, &est);
    out->sim_err = similarity_error(truth, &est);
}

static int cmp_int(const void *a, const void *b)
{
    return *(const int *)a - *(const int *)b;
}

/* The rank of J'J at a scene, column by column: a column joins the basis
   when the part of it the basis does not explain (its Schur complement
   s_j) is more than FE_LSQ_RANK_TOL of it.  One fe_lsq_scores call per
   column; p = 100. */
static int gram_rank(const struct scene *s)
{
    enum { P = 2 * NCAM + 2 * NLAND };
    static double g[(P + 1) * (P + 1)], work[P * P + 2 * P];
    size_t basis[P], nb = 0;
    fe_lsq a;
    fe_lsq_init(&a, P, g);
    for (int i = 0; i < NCAM; i++)
        for (int j = 0; j < NLAND; j++) {
            double dx = s->land[j][0] - s->cam[i][0], dy = s->land[j][1] - s->cam[i][1];
            double q = dx * dx + dy * dy;
            size_t idx[4] = {2 * (size_t)i, 2 * (size_t)i + 1, 2 * NCAM + 2 * (size_t)j,
                             2 * NCAM + 2 * (size_t)j + 1};
            double val[4] = {dy / q, -dx / q, -dy / q, dx / q};
            if (fe_lsq_add_sparse(&a, idx, val, 4, 0.0, 1.0) != FE_OK)
                return -1;
        }
    for (size_t j = 0; j < P; j++) {
        double score, schur;
        if (fe_lsq_scores(&a, basis, nb, &j, 1, &score, &schur, NULL, work) != FE_OK)
            return -1;
        if (schur > FE_LSQ_RANK_TOL * fe_lsq_gram(&a, j, j))
            basis[nb++] = j;
    }
    return (int)nb;
}

static void start_of(int seed, struct scene *truth, struct scene *start)
{
    fe_rng r = fe_rng_seed((uint64_t)seed);
    make_scene(&r, truth);
    *start = *truth;
    for (int i = 0; i < NCAM; i++)
        for (int c = 0; c < 2; c++)
            start->cam[i][c] += 5.0 * fe_rng_normal(&r);
    for (int j = 0; j < NLAND; j++)
        for (int c = 0; c < 2; c++)
            start->land[j][c] += 5.0 * fe_rng_normal(&r);
}

/* Many seeds with one gauge choice: convergence, iterations, agreement. */
static void many_seeds(int seeds, int fix, double *work, int *iters)
{
    int converged = 0, agree = 0;
    double worst_cost = 0, worst_diff = 0, worst_sim = 0;
    for (int seed = 1; seed <= seeds; seed++) {
        struct scene truth, start;
        struct run dense, schur;
        double diff = 0;
        start_of(seed, &truth, &start);
        run(&truth, &start, fix, FE_LM_SCHUR, NULL, work, &schur);
        run(&truth, &start, fix, FE_LM_DENSE, NULL, work, &dense);
        for (size_t k = 0; k < 2 * NCAM + 2 * NLAND - 2 * (size_t)fix; k++)
            diff = fmax(diff, fabs(dense.x[k] - schur.x[k]));
        iters[seed - 1] = schur.iterations;
        if (schur.rc == FE_OK && schur.cost < 1e-20 && dense.rc == FE_OK && dense.cost < 1e-20) {
            converged++;
            worst_cost = fmax(worst_cost, fmax(schur.cost, dense.cost));
            worst_sim = fmax(worst_sim, schur.sim_err);
        }
        if (dense.rc == schur.rc && dense.iterations == schur.iterations) {
            agree++;
            worst_diff = fmax(worst_diff, diff);
        }
    }
    qsort(iters, (size_t)seeds, sizeof *iters, cmp_int);
    printf("%s:\n", fix ? "camera 0 held, scale and flex left to the damping"
                        : "nothing held, damping only");
    printf("  dense and Schur both reach cost < 1e-20: %d of %d seeds (largest final cost %.2e)\n",
           converged, seeds, worst_cost);
    printf("  iterations (Schur): min %d, median %d, 90th percentile %d, max %d\n", iters[0],
           iters[seeds / 2], iters[(seeds * 9) / 10], iters[seeds - 1]);
    printf("  dense and Schur take the same number of steps: %d of %d seeds;"
           " parameters differ by at most %.2e\n", agree, seeds, worst_diff);
    printf("  distance of the solution to the truth up to a similarity: at most %.2e\n",
           worst_sim);
}

int main(int argc, char **argv)
{
    int seeds = argc > 1 ? atoi(argv[1]) : 200;
    fe_lm_problem shape = {2 * NCAM, 2, NLAND, ba_model, NULL};
    size_t nwork = fe_lm_work(&shape, FE_LM_DENSE);
    double *work;
    int *iters;
    struct scene truth, start;
    struct run dense, schur;

    if (fe_lm_work(&shape, FE_LM_SCHUR) > nwork)
        nwork = fe_lm_work(&shape, FE_LM_SCHUR);
    work = malloc(nwork * sizeof *work);
    iters = malloc((seeds > 0 ? (size_t)seeds : 1) * sizeof *iters);
    if (work == NULL || iters == NULL || seeds < 1) {
        fprintf(stderr, "bundle2d: bad argument or out of memory\n");
        return 1;
    }

    /* One run, verbose. */
    start_of(1, &truth, &start);
    printf("seed 1, Schur complement (18 free camera coordinates, 40 landmark blocks)\n"
           " iter         cost       change      |step|      ratio     lambda  taken\n");
    run(&truth, &start, 1, FE_LM_SCHUR, print_row, work, &schur);
    printf("-> %s after %d iterations, cost %.3e\n\n", fe_strerror(schur.rc),
           schur.iterations, schur.cost);
    printf("seed 1, dense (98 x 98 normal equations)\n"
           " iter         cost       change      |step|      ratio     lambda  taken\n");
    run(&truth, &start, 1, FE_LM_DENSE, print_row, work, &dense);
    printf("-> %s after %d iterations, cost %.3e\n\n", fe_strerror(dense.rc),
           dense.iterations, dense.cost);

    /* The gauge, measured. */
    {
        struct scene bent = truth;
        fe_rng r = fe_rng_seed(99);
        for (int i = 0; i < NCAM; i++)
            bent.cam[i][0] += fe_rng_normal(&r);
        for (int j = 0; j < NLAND; j++)
            bent.land[j][0] += fe_rng_normal(&r);
        printf("rank of J'J (100 parameters) at the truth: %d; with cameras and landmarks\n"
               "moved off their lines by N(0,1) in x: %d  (3 = translation and scale;\n"
               "the 4th flat direction is the flex of two lines)\n\n",
               gram_rank(&truth), gram_rank(&bent));
    }

    many_seeds(seeds, 1, work, iters);
    many_seeds(seeds, 0, work, iters);
    free(work);
    free(iters);
    return 0;
}
