/* SPDX-License-Identifier: MIT */
/* Structured least squares, in one run:
     1. the normal-equation fold: ns per row for p = 8, 32, 128 columns,
        blocked (fe_lsq_add_rows) and row by row (fe_lsq_add), against
        LAPACK's QR (dgels) and GSL's gsl_multifit_linear on the same rows,
        with the coefficients compared (ratios: theirs / ours);
     2. scoring every candidate column against a base with one
        factorisation (fe_lsq_scores), against refitting base + candidate
        for each (fe_lsq_solve);
     3. Levenberg-Marquardt on the 2-D bundle adjustment of EJML (10
        cameras, 40 / 400 / 4000 landmarks): time per iteration, dense
        against Schur, and the steps compared.
   Usage: bench_lsq [max_dense_seconds]  (default 60: a dense iteration
   predicted to take longer is not run, and the line says so). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_multifit.h>
#include <lapacke.h>

#include "bench.h"
#include "foldest.h"

/* ------------------------------------------------------------ 1. the fold */

static void bench_fold(size_t p, size_t n)
{
    double *J = malloc(n * p * sizeof *J), *r = malloc(n * sizeof *r);
    double *A = malloc(n * p * sizeof *A), *b = malloc(n * sizeof *b);
    double *g = malloc(fe_lsq_storage(p) * sizeof *g);
    double *work = malloc(fe_lsq_solve_work(p) * sizeof *work);
    double *x = malloc(p * sizeof *x), t_fold, t_rows, t_solve, t_qr, t_gsl, diff = 0, diffg = 0, scale = 0;
    gsl_matrix *X = gsl_matrix_alloc(n, p), *cov = gsl_matrix_alloc(p, p);
    gsl_vector *y = gsl_vector_alloc(n), *c = gsl_vector_alloc(p);
    gsl_multifit_linear_workspace *mw = gsl_multifit_linear_alloc(n, p);
    fe_rng rng = fe_rng_seed(p);
    fe_lsq a;

    for (size_t i = 0; i < n; i++) {
        r[i] = 0.0;
        for (size_t k = 0; k < p; k++) {
            J[i * p + k] = fe_rng_normal(&rng);
            r[i] += J[i * p + k] / (double)(k + 1);
            gsl_matrix_set(X, i, k, J[i * p + k]);
        }
        r[i] += 0.1 * fe_rng_normal(&rng);
        gsl_vector_set(y, i, r[i]);
    }
    fe_lsq_init(&a, p, g);
    FE_BENCH_BEST(t_fold, 3, {
        fe_lsq_reset(&a);
        if (fe_lsq_add_rows(&a, J, p, r, NULL, n, NULL) != FE_OK)
            exit(1);
    });
    FE_BENCH_BEST(t_rows, 1, {
        fe_lsq_reset(&a);
        for (size_t i = 0; i < n; i++)
            if (fe_lsq_add(&a, J + i * p, r[i], 1.0) != FE_OK)
                exit(1);
    });
    fe_lsq_reset(&a);
    fe_lsq_add_rows(&a, J, p, r, NULL, n, NULL);
    FE_BENCH_BEST(t_solve, 3, {
        if (fe_lsq_solve(&a, NULL, p, x, NULL, NULL, work) != FE_OK)
            exit(1);
    });
    FE_BENCH_BEST(t_qr, 3, {
        memcpy(A, J, n * p * sizeof *A);
        memcpy(b, r, n * sizeof *b);
        if (LAPACKE_dgels(LAPACK_ROW_MAJOR, 'N', (lapack_int)n, (lapack_int)p, 1, A,
                          (lapack_int)p, b, 1) != 0)
            exit(1);
    });
    FE_BENCH_BEST(t_gsl, 1, {
        double chisq;
        gsl_multifit_linear(X, y, c, cov, &chisq, mw);
    });
    for (size_t k = 0; k < p; k++) {
        diff = fmax(diff, fabs(x[k] - b[k]));
        diffg = fmax(diffg, fabs(x[k] - gsl_vector_get(c, k)));
        scale = fmax(scale, fabs(b[k]));
    }
    printf("  p = %3zu, %zu rows: fold %6.1f ns/row (row by row %6.1f) + solve %6.1f us | dgels %6.1f ns/row (x%.1f)"
           " | gsl_multifit_linear %7.1f ns/row (x%.1f) | max |dx|/|x| %.1e, %.1e\n",
           p, n, 1e9 * t_fold / (double)n, 1e9 * t_rows / (double)n, 1e6 * t_solve, 1e9 * t_qr / (double)n,
           t_qr / (t_fold + t_solve), 1e9 * t_gsl / (double)n, t_gsl / (t_fold + t_solve),
           diff / scale, diffg / scale);
    free(J); free(r); free(A); free(b); free(g); free(work); free(x);
    gsl_matrix_free(X); gsl_matrix_free(cov); gsl_vector_free(y); gsl_vector_free(c);
    gsl_multifit_linear_free(mw);
}

/* --------------------------------------------------------- 2. the scores */

static void bench_scores(size_t p, size_t qb, size_t n)
{
    double *J = malloc(n * p * sizeof *J), *r = malloc(n * sizeof *r);
    double *g = malloc(fe_lsq_storage(p) * sizeof *g);
    size_t nc = p - qb, *base = malloc(qb * sizeof *base), *cand = malloc(nc * sizeof *cand);
    size_t *cols = malloc((qb + 1) * sizeof *cols);
    double *score = malloc(nc * sizeof *score), *work = malloc(fe_lsq_scores_work(qb, nc) * sizeof *work);
    double *sw = malloc(fe_lsq_solve_work(qb + 1) * sizeof *sw), rss0, t_one, t_refit, worst = 0;
    fe_rng rng = fe_rng_seed(7);
    fe_lsq a;

    for (size_t i = 0; i < n; i++) {
        r[i] = fe_rng_normal(&rng);
        for (size_t k = 0; k < p; k++) {
            J[i * p + k] = fe_rng_normal(&rng);
            r[i] += (k % 7 == 0 ? 1.0 : 0.0) * J[i * p + k];
        }
    }
    fe_lsq_init(&a, p, g);
    fe_lsq_add_rows(&a, J, p, r, NULL, n, NULL);
    for (size_t k = 0; k < qb; k++)
        base[k] = cols[k] = k;
    for (size_t k = 0; k < nc; k++)
        cand[k] = qb + k;
    FE_BENCH_BEST(t_one, 5, {
        if (fe_lsq_scores(&a, base, qb, cand, nc, score, NULL, &rss0, work) != FE_OK)
            exit(1);
    });
    FE_BENCH_BEST(t_refit, 3, {
        for (size_t k = 0; k < nc; k++) {
            double rss1;
            cols[qb] = cand[k];
            if (fe_lsq_solve(&a, cols, qb + 1, NULL, &rss1, NULL, sw) != FE_OK)
                exit(1);
            worst = fmax(worst, fabs(score[k] - (rss0 - rss1)) / rss0);
        }
    });
    printf("  p = %zu, base of %zu, %zu candidates: scores in one factorisation %8.1f us,"
           " refit each %8.1f us (x%.0f); largest |score - RSS drop| / RSS %.1e\n",
           p, qb, nc, 1e6 * t_one, 1e6 * t_refit, t_refit / t_one, worst);
    free(J); free(r); free(g); free(base); free(cand); free(cols); free(score); free(work); free(sw);
}

/* ------------------------------------------- 3. bundle adjustment scaling */

enum { NCAM = 10 };

struct ba {
    size_t nland;
    double cam0[2];
    const double *theta;        /* theta[i * nland + j] */
};

/* Camera 0 held; globals: cameras 1..9; blocks: landmarks. */
static int ba_model(const double *x, fe_lm_sink *s, void *ctx)
{
    const struct ba *b = ctx;
    const double pi = 3.14159265358979323846;
    double jg[2 * NCAM - 2] = {0};
    for (size_t i = 0; i < NCAM; i++) {
        double cx = i == 0 ? b->cam0[0] : x[2 * i - 2];
        double cy = i == 0 ? b->cam0[1] : x[2 * i - 1];
        for (size_t j = 0; j < b->nland; j++) {
            const double *l = x + 2 * NCAM - 2 + 2 * j;
            double dx = l[0] - cx, dy = l[1] - cy, q = dx * dx + dy * dy;
            double f = atan2(dy, dx) - b->theta[i * b->nland + j], jl[2] = {-dy / q, dx / q};
            int rc;
            f -= 2.0 * pi * floor(f / (2.0 * pi) + 0.5);
            if (i > 0) {
                jg[2 * i - 2] = dy / q;
                jg[2 * i - 1] = -dx / q;
            }
            rc = fe_lm_emit(s, f, 1.0, jg, j, jl);
            if (i > 0)
                jg[2 * i - 2] = jg[2 * i - 1] = 0.0;
            if (rc != FE_OK)
                return rc;
        }
    }
    return FE_OK;
}

/* CPU time of this thread: with one BLAS thread it is the work done, and
   it does not count the time other programs on a shared machine take. */
static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Intervals between iteration reports; the first also holds the model
   evaluation at the start, so it is kept apart. */
struct clock { double last, first, sum; int n; };

static int tick(const fe_lm_iteration *it, void *ctx)
{
    struct clock *c = ctx;
    double now = cpu_now();
    (void)it;
    if (c->n == 0)
        c->first = now - c->last;
    else
        c->sum += now - c->last;
    c->n++;
    c->last = now;
    return 0;
}

/* Time `iters` LM iterations from x (copied); per-iteration seconds. */
static double time_lm(const fe_lm_problem *p, int method, const double *x0, double *x,
                      size_t np, int iters, int *rc)
{
    double *w = malloc(fe_lm_work(p, method) * sizeof *w);
    fe_lm_params par = fe_lm_default_params();
    struct clock c = {0, 0, 0, 0};
    if (w == NULL) {
        *rc = FE_ENOMEM;
        return 0;
    }
    memcpy(x, x0, np * sizeof *x);
    par.max_iter = iters;
    c.last = cpu_now();
    *rc = fe_lm_solve(p, method, &par, x, w, tick, &c, NULL);
    free(w);
    return c.n > 1 ? c.sum / (c.n - 1) : c.first;
}

static void bench_ba(double max_dense)
{
    const size_t lands[3] = {40, 400, 4000};
    double ts[3] = {0}, td[3] = {0};
    size_t nps[3];
    printf("3. Levenberg-Marquardt, 2-D bundle adjustment, 10 cameras (camera 0 held),"
           " CPU time per iteration\n   (mean of iterations 2 and 3, best of 5 runs, 1 run for dense 4000; the iterates after 3\n   iterations are compared):\n");
    for (int t = 0; t < 3; t++) {
        size_t L = lands[t], ng = 2 * NCAM - 2, np = ng + 2 * L;
        double *theta = malloc(NCAM * L * sizeof *theta), *x0 = malloc(np * sizeof *x0);
        double *xd = malloc(np * sizeof *xd), *xs = malloc(np * sizeof *xs);
        double cam[NCAM][2], diff = 0, predicted = 0;
        fe_rng rng = fe_rng_seed(42);
        struct ba b = {L, {0, 0}, theta};
        fe_lm_problem prob = {ng, 2, L, ba_model, &b};
        int rcs, rcd = FE_OK, iters = 3;

        nps[t] = np;
        for (int i = 0; i < NCAM; i++) {
            cam[i][0] = 0.0;
            cam[i][1] = 20.0 * fe_rng_uniform(&rng) - 10.0;
        }
        for (size_t j = 0; j < L; j++) {
            double ly = 20.0 * fe_rng_uniform(&rng) - 10.0;
            for (int i = 0; i < NCAM; i++)
                theta[i * L + j] = atan((ly - cam[i][1]) / (20.0 - cam[i][0]));
            x0[ng + 2 * j] = 20.0 + 5.0 * fe_rng_normal(&rng);
            x0[ng + 2 * j + 1] = ly + 5.0 * fe_rng_normal(&rng);
        }
        b.cam0[0] = cam[0][0] + 5.0 * fe_rng_normal(&rng);
        b.cam0[1] = cam[0][1] + 5.0 * fe_rng_normal(&rng);
        for (int i = 1; i < NCAM; i++)
            for (int c = 0; c < 2; c++)
                x0[2 * i - 2 + c] = cam[i][c] + 5.0 * fe_rng_normal(&rng);

        ts[t] = 1e300;
        for (int rep = 0; rep < 5; rep++)        /* best of 5: the machine is shared */
            ts[t] = fmin(ts[t], time_lm(&prob, FE_LM_SCHUR, x0, xs, np, iters, &rcs));
        /* Dense is O(p^3): predict from the previous size before running. */
        if (t > 0 && td[t - 1] > 0)
            predicted = td[t - 1] * pow((double)np / (double)nps[t - 1], 3.0);
        if (predicted <= max_dense) {
            td[t] = 1e300;
            for (int rep = 0; rep < (t == 2 ? 1 : 5); rep++)
                td[t] = fmin(td[t], time_lm(&prob, FE_LM_DENSE, x0, xd, np, iters, &rcd));
            for (size_t k = 0; k < np; k++)
                diff = fmax(diff, fabs(xd[k] - xs[k]));
        }
        if (td[t] > 0)
            printf("  %4zu landmarks (%5zu parameters, %5zu residuals): Schur %9.3f ms, dense %10.3f ms"
                   " (dense / Schur = %.0f); dense and Schur iterates differ by %.1e\n",
                   L, np, NCAM * L, 1e3 * ts[t], 1e3 * td[t], td[t] / ts[t], diff);
        else
            printf("  %4zu landmarks (%5zu parameters, %5zu residuals): Schur %9.3f ms, dense NOT RUN:"
                   " predicted %.0f s per iteration (previous size times the cube of the"
                   " parameter ratio) exceeds the limit of %.0f s; `bench_lsq %.0f` measures it\n",
                   L, np, NCAM * L, 1e3 * ts[t], predicted, max_dense, 1.5 * predicted + 1);
        if (rcs != FE_OK && rcs != FE_ENOCONV)
            printf("  (Schur returned %s)\n", fe_strerror(rcs));
        if (td[t] > 0 && rcd != FE_OK && rcd != FE_ENOCONV)
            printf("  (dense returned %s)\n", fe_strerror(rcd));
        free(theta); free(x0); free(xd); free(xs);
    }
    printf("  growth per 10x landmarks: Schur x%.1f, x%.1f (linear: 10)", ts[1] / ts[0], ts[2] / ts[1]);
    if (td[0] > 0 && td[1] > 0)
        printf("; dense x%.0f (parameters x%.2f, cube x%.0f)", td[1] / td[0],
               (double)nps[1] / nps[0], pow((double)nps[1] / nps[0], 3.0));
    if (td[1] > 0 && td[2] > 0)
        printf(", x%.0f (parameters x%.2f, cube x%.0f)", td[2] / td[1],
               (double)nps[2] / nps[1], pow((double)nps[2] / nps[1], 3.0));
    printf("\n");
}

int main(int argc, char **argv)
{
    double max_dense = argc > 1 ? strtod(argv[1], NULL) : 60.0;
    printf("machine busy %.0f%% before the run (other processes' share of the cores)\n",
           100 * fe_bench_busy_fraction());
    printf("1. normal-equation fold + solve vs batch least squares (best of runs)\n");
    bench_fold(8, 200000);
    bench_fold(32, 100000);
    bench_fold(128, 20000);
    printf("2. one Schur-complement factorisation scores every candidate column\n");
    bench_scores(200, 20, 2000);
    bench_scores(400, 60, 2000);
    bench_ba(max_dense);
    return 0;
}
