/* SPDX-License-Identifier: MIT */
/* Levenberg-Marquardt: known minima (Rosenbrock, a linear model against
   the normal-equation solve), the 2-D bundle adjustment of EJML with the
   dense and Schur paths agreeing, the iteration report, failures of the
   model handled, multi-session magnetometer calibration on synthetic
   sessions with known truth and on real recordings split into sessions. */
#define _POSIX_C_SOURCE 200809L  /* mmap, mprotect, sysconf: a page no one may read */

#include <fcntl.h>
#include <float.h>
#include <stdint.h>
#include <sys/mman.h>
#include <unistd.h>

#include "foldest.h"
#include "testutil.h"

static double *lm_work(const fe_lm_problem *p, int method)
{
    double *w = malloc(fe_lm_work(p, method) * sizeof *w);
    ck_assert_ptr_nonnull(w);
    return w;
}

/* ------------------------------------------------------------ Rosenbrock */

static int rosenbrock(const double *x, fe_lm_sink *s, void *ctx)
{
    const double j1[2] = {-20.0 * x[0], 10.0}, j2[2] = {-1.0, 0.0};
    (void)ctx;
    fe_lm_emit(s, 10.0 * (x[1] - x[0] * x[0]), 1.0, j1, FE_SCHUR_NONE, NULL);
    return fe_lm_emit(s, 1.0 - x[0], 1.0, j2, FE_SCHUR_NONE, NULL);
}

START_TEST(rosenbrock_dense_and_schur)
{
    fe_lm_problem p = {2, 0, 0, rosenbrock, NULL};
    for (int method = FE_LM_DENSE; method <= FE_LM_SCHUR; method++) {
        double x[2] = {-1.2, 1.0}, *w = lm_work(&p, method);
        fe_lm_result r;
        ck_assert_int_eq(fe_lm_solve(&p, method, NULL, x, w, NULL, NULL, &r), FE_OK);
        ck_assert_double_lt(r.cost, 1e-20);
        ck_assert_double_eq_tol(x[0], 1.0, 1e-10);
        ck_assert_double_eq_tol(x[1], 1.0, 1e-10);
        ck_assert_double_eq_tol(r.initial_cost, 0.5 * (4.4 * 4.4 + 2.2 * 2.2), 1e-12);
        ck_assert_int_gt(r.iterations, 1);
        free(w);
    }
}
END_TEST

/* The workspace is read only up to its end: fe_lm_work(prob, method)
   doubles placed at the end of a page whose next page may not be read, so
   a read one past them stops the test with a segmentation fault.  Seed
   10223's lm:586 (the loop that forms the last two steps, d = xt - xa,
   run to k <= p) read one double past the workspace (xa is its last p
   doubles) and wrote it over xa[0], which the next line sets: every
   result the same, so only such a page shows it.  Rosenbrock from
   (-1.2, 1) by both methods: the same point, bit for bit, and the same
   counts as with a workspace from malloc. */
START_TEST(the_workspace_is_read_only_up_to_its_end)
{
    fe_lm_problem p = {2, 0, 0, rosenbrock, NULL};
    long pg = sysconf(_SC_PAGESIZE);
    for (int method = FE_LM_DENSE; method <= FE_LM_SCHUR; method++) {
        size_t n = fe_lm_work(&p, method), pages = (n * sizeof(double) + (size_t)pg - 1) / (size_t)pg;
        double x[2] = {-1.2, 1.0}, y[2] = {-1.2, 1.0}, *w = lm_work(&p, method), *edge;
        fe_lm_result r, q;
        unsigned char *map;
        int fd = open("/dev/zero", O_RDWR);
        ck_assert_int_gt(pg, 0);
        ck_assert_int_ge(fd, 0);
        map = mmap(NULL, (pages + 1) * (size_t)pg, PROT_READ | PROT_WRITE, MAP_PRIVATE, fd, 0);
        ck_assert_ptr_ne(map, MAP_FAILED);
        close(fd);
        ck_assert_int_eq(mprotect(map + pages * (size_t)pg, (size_t)pg, PROT_NONE), 0);
        edge = (double *)(void *)(map + pages * (size_t)pg) - n;
        ck_assert_int_eq(fe_lm_solve(&p, method, NULL, x, edge, NULL, NULL, &r), FE_OK);
        ck_assert_int_eq(fe_lm_solve(&p, method, NULL, y, w, NULL, NULL, &q), FE_OK);
        ck_assert_int_gt(r.accepted, 2);
        ck_assert_mem_eq(x, y, sizeof x);
        ck_assert_int_eq(r.iterations, q.iterations);
        ck_assert_int_eq(r.evaluations, q.evaluations);
        ck_assert_int_eq(r.accelerated, q.accelerated);
        ck_assert_double_eq_tol(x[0], 1.0, 1e-10);
        ck_assert_double_eq_tol(x[1], 1.0, 1e-10);
        ck_assert_int_eq(munmap(map, (pages + 1) * (size_t)pg), 0);
        free(w);
    }
}
END_TEST

/* ------------------------------------------------- a linear model */

enum { LN = 60, LP = 4 };
struct linear { double J[LN][LP], y[LN]; };

static int linear_model(const double *x, fe_lm_sink *s, void *ctx)
{
    const struct linear *L = ctx;
    for (int i = 0; i < LN; i++) {
        double f = -L->y[i];
        for (int k = 0; k < LP; k++)
            f += L->J[i][k] * x[k];
        fe_lm_emit(s, f, 1.0, L->J[i], FE_SCHUR_NONE, NULL);
    }
    return FE_OK;
}

START_TEST(linear_model_matches_normal_equations)
{
    static struct linear L;
    fe_rng g = fe_rng_seed(3);
    double gram[(LP + 1) * (LP + 1)], sw[(LP + 1) * (LP + 1)], want[LP], rss, x[LP] = {0};
    fe_lsq a;
    fe_lm_problem p = {LP, 0, 0, linear_model, &L};
    double *w = lm_work(&p, FE_LM_DENSE);
    fe_lm_result r;

    fe_lsq_init(&a, LP, gram);
    for (int i = 0; i < LN; i++) {
        for (int k = 0; k < LP; k++)
            L.J[i][k] = fe_rng_normal(&g) + (double)k;
        L.y[i] = 1.0 + 2.0 * L.J[i][1] + 0.1 * fe_rng_normal(&g);
        fe_lsq_add(&a, L.J[i], L.y[i], 1.0);
    }
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, LP, want, &rss, NULL, sw), FE_OK);
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, NULL, x, w, NULL, NULL, &r), FE_OK);
    for (int k = 0; k < LP; k++)
        ck_assert_double_eq_tol(x[k], want[k], 1e-10 * (1.0 + fabs(want[k])));
    FE_ASSERT_REL(2.0 * r.cost, rss, 1e-9);
    free(w);
}
END_TEST

/* Both methods solve p from zero to the normal-equation solution want (n
   parameters, residual sum of squares rss): every parameter within 1e-10
   of the largest, the cost rss / 2. */
static void dense_and_schur_solve_as(const fe_lm_problem *p, const double *want, size_t n,
                                     double rss)
{
    double worst = 0.0, scale = 0.0;
    for (size_t k = 0; k < n; k++)
        scale = fmax(scale, fabs(want[k]));
    for (int method = FE_LM_DENSE; method <= FE_LM_SCHUR; method++) {
        double *x = calloc(n, sizeof *x), *w = lm_work(p, method);
        fe_lm_result r;
        ck_assert_ptr_nonnull(x);
        ck_assert_int_eq(fe_lm_solve(p, method, NULL, x, w, NULL, NULL, &r), FE_OK);
        for (size_t k = 0; k < n; k++)
            worst = fmax(worst, fabs(x[k] - want[k]));
        FE_ASSERT_REL(2.0 * r.cost, rss, 1e-9);
        free(x);
        free(w);
    }
    ck_assert_double_le(worst, 1e-10 * scale);
}

/* Wide rows (more nonzeros than the dense sink folds sparsely): the dense
   and Schur paths still give the normal-equation solution. */
enum { WN = 200, WP = 80 };
struct wide { double J[WN][WP], y[WN]; };

static int wide_model(const double *x, fe_lm_sink *s, void *ctx)
{
    const struct wide *L = ctx;
    for (int i = 0; i < WN; i++) {
        double f = -L->y[i];
        for (int k = 0; k < WP; k++)
            f += L->J[i][k] * x[k];
        fe_lm_emit(s, f, 1.0, L->J[i], FE_SCHUR_NONE, NULL);
    }
    return FE_OK;
}

START_TEST(wide_linear_model_dense_and_schur)
{
    static struct wide L;
    static double gram[(WP + 1) * (WP + 1)], sw[(WP + 1) * (WP + 1)];
    double want[WP], rss;
    fe_rng g = fe_rng_seed(4);
    fe_lsq a;
    fe_lm_problem p = {WP, 0, 0, wide_model, &L};

    fe_lsq_init(&a, WP, gram);
    for (int i = 0; i < WN; i++) {
        for (int k = 0; k < WP; k++)
            L.J[i][k] = fe_rng_normal(&g);
        L.y[i] = L.J[i][3] - 0.5 * L.J[i][70] + 0.1 * fe_rng_normal(&g);
        fe_lsq_add(&a, L.J[i], L.y[i], 1.0);
    }
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, WP, want, &rss, NULL, sw), FE_OK);
    dense_and_schur_solve_as(&p, want, WP, rss);
}
END_TEST

/* Wide rows with blocks: 60 globals and 8 locals of one of 2 blocks on
   every row, 68 nonzeros where the dense sink folds 64 sparsely; the
   sparse fold must look at the globals and the locals together.  Dense
   and Schur give the normal-equation solution of all 76 columns. */
enum { WBN = 240, WBG = 60, WBL = 8, WBB = 2, WBP = WBG + WBB * WBL };
struct wide_blocks { double J[WBN][WBG + WBL], y[WBN]; };

static int wide_blocks_model(const double *x, fe_lm_sink *s, void *ctx)
{
    const struct wide_blocks *L = ctx;
    for (int i = 0; i < WBN; i++) {
        size_t b = (size_t)(i % WBB);
        double f = -L->y[i];
        for (int k = 0; k < WBG; k++)
            f += L->J[i][k] * x[k];
        for (int k = 0; k < WBL; k++)
            f += L->J[i][WBG + k] * x[WBG + b * WBL + (size_t)k];
        fe_lm_emit(s, f, 1.0, L->J[i], b, L->J[i] + WBG);
    }
    return FE_OK;
}

START_TEST(wide_rows_with_blocks_dense_and_schur)
{
    static struct wide_blocks L;
    static double gram[(WBP + 1) * (WBP + 1)], sw[(WBP + 1) * (WBP + 1)], row[WBP];
    double want[WBP], rss;
    fe_rng g = fe_rng_seed(6);
    fe_lsq a;
    fe_lm_problem p = {WBG, WBL, WBB, wide_blocks_model, &L};

    fe_lsq_init(&a, WBP, gram);
    for (int i = 0; i < WBN; i++) {
        size_t b = (size_t)(i % WBB);
        memset(row, 0, sizeof row);
        for (int k = 0; k < WBG + WBL; k++)
            L.J[i][k] = fe_rng_normal(&g);
        L.y[i] = L.J[i][3] - 0.5 * L.J[i][WBG + 2] + 0.1 * fe_rng_normal(&g);
        memcpy(row, L.J[i], WBG * sizeof *row);
        memcpy(row + WBG + b * WBL, L.J[i] + WBG, WBL * sizeof *row);
        fe_lsq_add(&a, row, L.y[i], 1.0);
    }
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, WBP, want, &rss, NULL, sw), FE_OK);
    dense_and_schur_solve_as(&p, want, WBP, rss);
}
END_TEST

/* ------------------------------------------------ 2-D bundle adjustment */

enum { NC = 10, NLM = 40, BAP = 2 * NC + 2 * NLM };
struct ba {
    double cam[NC][2], land[NLM][2], theta[NC][NLM], cam0[2];
    int hold;                    /* camera 0 held at cam0 */
};

/* The bearing residual of camera i and landmark j at x, wrapped into
   (-pi, pi]; jl gets its gradient with respect to the landmark (that with
   respect to the camera is -jl); *cam is the index of camera i's x among
   the parameters, or -1 when the camera is held.  Globals: the free
   cameras (1..9, or all 10); blocks: landmarks. */
static double ba_residual(const struct ba *b, const double *x, int i, int j, double jl[2],
                          int *cam)
{
    const double pi = 3.14159265358979323846;
    int h = b->hold ? 2 : 0, free_cam = !(b->hold && i == 0);
    double cx = free_cam ? x[2 * i - h] : b->cam0[0];
    double cy = free_cam ? x[2 * i + 1 - h] : b->cam0[1];
    const double *l = x + 2 * NC - h + 2 * j;
    double dx = l[0] - cx, dy = l[1] - cy, q = dx * dx + dy * dy;
    double f = atan2(dy, dx) - b->theta[i][j];
    jl[0] = -dy / q;
    jl[1] = dx / q;
    *cam = free_cam ? 2 * i - h : -1;
    return f - 2.0 * pi * floor(f / (2.0 * pi) + 0.5);
}

static int ba_model(const double *x, fe_lm_sink *s, void *ctx)
{
    const struct ba *b = ctx;
    double jg[2 * NC] = {0};
    for (int i = 0; i < NC; i++)
        for (int j = 0; j < NLM; j++) {
            double jl[2];
            int cam, rc;
            double f = ba_residual(b, x, i, j, jl, &cam);
            if (cam >= 0) {
                jg[cam] = -jl[0];
                jg[cam + 1] = -jl[1];
            }
            rc = fe_lm_emit(s, f, 1.0, jg, (size_t)j, jl);
            if (cam >= 0)
                jg[cam] = jg[cam + 1] = 0.0;
            if (rc != FE_OK)
                return rc;
        }
    return FE_OK;
}

/* Truth and the start (truth + N(0, 5^2)) for one seed; x gets the start
   of the free parameters.  The bearings get N(0, noise^2) from a generator
   of their own, so that the start does not depend on the noise. */
static void ba_setup(uint64_t seed, int hold, double noise, struct ba *b, double *x)
{
    fe_rng r = fe_rng_seed(seed);
    int h = hold ? 2 : 0;
    b->hold = hold;
    for (int i = 0; i < NC; i++) {
        b->cam[i][0] = 0.0;
        b->cam[i][1] = 20.0 * fe_rng_uniform(&r) - 10.0;
    }
    for (int j = 0; j < NLM; j++) {
        b->land[j][0] = 20.0;
        b->land[j][1] = 20.0 * fe_rng_uniform(&r) - 10.0;
    }
    for (int i = 0; i < NC; i++)
        for (int j = 0; j < NLM; j++)
            b->theta[i][j] = atan((b->land[j][1] - b->cam[i][1]) / (b->land[j][0] - b->cam[i][0]));
    for (int i = 0; i < NC; i++)
        for (int c = 0; c < 2; c++) {
            double v = b->cam[i][c] + 5.0 * fe_rng_normal(&r);
            if (hold && i == 0)
                b->cam0[c] = v;
            else
                x[2 * i + c - h] = v;
        }
    for (int j = 0; j < NLM; j++)
        for (int c = 0; c < 2; c++)
            x[2 * NC - h + 2 * j + c] = b->land[j][c] + 5.0 * fe_rng_normal(&r);
    if (noise > 0.0) {
        fe_rng e = fe_rng_seed(seed + 1000003);
        for (int i = 0; i < NC; i++)
            for (int j = 0; j < NLM; j++)
                b->theta[i][j] += noise * fe_rng_normal(&e);
    }
}

START_TEST(bundle_adjustment_dense_and_schur_agree)
{
    /* Camera 0 held (hold = 1), or nothing held: the damping alone copes
       with the gauge (lm.org). */
    static struct ba b;
    int seeds = fe_test_quick() ? 2 : 15, bad = 0, max_iter = 0;
    double worst_cost = 0.0, worst_diff = 0.0;

    for (int hold = 1; hold >= 0; hold--) {
        fe_lm_problem p = {2 * NC - (hold ? 2 : 0), 2, NLM, ba_model, &b};
        double *wd = lm_work(&p, FE_LM_DENSE), *ws = lm_work(&p, FE_LM_SCHUR);
        for (int seed = 1; seed <= seeds; seed++) {
            double xd[BAP], xs[BAP];
            fe_lm_result rd, rs;
            int cd, cs;
            ba_setup((uint64_t)seed, hold, 0.0, &b, xd);
            memcpy(xs, xd, sizeof xd);
            cd = fe_lm_solve(&p, FE_LM_DENSE, NULL, xd, wd, NULL, NULL, &rd);
            cs = fe_lm_solve(&p, FE_LM_SCHUR, NULL, xs, ws, NULL, NULL, &rs);
            bad += cd != FE_OK || cs != FE_OK || rd.iterations != rs.iterations;
            worst_cost = fmax(worst_cost, fmax(rd.cost, rs.cost));
            for (size_t k = 0; k < p.ng + 2 * NLM; k++)
                worst_diff = fmax(worst_diff, fabs(xd[k] - xs[k]));
            max_iter = rs.iterations > max_iter ? rs.iterations : max_iter;
        }
        free(wd);
        free(ws);
    }
    ck_assert_int_eq(bad, 0);
    ck_assert_double_lt(worst_cost, 1e-20);
    ck_assert_double_lt(worst_diff, 1e-8);
    ck_assert_int_le(max_iter, 30);
}
END_TEST

/* The cost (1/2) sum f^2 at x, and (when g is not NULL) its gradient
   g = J'f and the diagonal of J'J, computed here from the bearings, not by
   the solver. */
static double ba_cost(const struct ba *b, const double *x, double *g, double *diag)
{
    int np = 2 * NC - (b->hold ? 2 : 0) + 2 * NLM;
    long double cost = 0.0L;
    if (g != NULL)
        for (int k = 0; k < np; k++)
            g[k] = diag[k] = 0.0;
    for (int i = 0; i < NC; i++)
        for (int j = 0; j < NLM; j++) {
            double jl[2];
            int cam, kl = np - 2 * NLM + 2 * j;
            double f = ba_residual(b, x, i, j, jl, &cam);
            cost += 0.5L * (long double)f * f;
            for (int c = 0; c < 2 && g != NULL; c++) {
                g[kl + c] += f * jl[c];
                diag[kl + c] += jl[c] * jl[c];
                if (cam >= 0) {
                    g[cam + c] -= f * jl[c];
                    diag[cam + c] += jl[c] * jl[c];
                }
            }
        }
    return (double)cost;
}

START_TEST(bundle_adjustment_noisy_ends_at_the_optimum)
{
    /* The 2-D example with landmarks on a line and 1e-3 rad of noise on
       every bearing: a flat, nearly degenerate valley of minima with a
       non-zero cost, where a solver without a relative cost test and a
       damping floor wandered until max_iter (issue 19).  It must end
       converged, at a point the gradient and a brute-force search around
       it both call a minimum. */
    static struct ba b;
    int seeds = fe_test_quick() ? 2 : 10, runs = 0;
    double worst_cos = 0.0, worst_gain = 0.0;

    for (int hold = 1; hold >= 0; hold--) {
        fe_lm_problem p = {2 * NC - (hold ? 2 : 0), 2, NLM, ba_model, &b};
        size_t np = p.ng + 2 * NLM;
        for (int method = FE_LM_DENSE; method <= FE_LM_SCHUR; method++) {
            double *w = lm_work(&p, method);
            for (int seed = 1; seed <= seeds; seed++) {
                double x[BAP], g[BAP], d[BAP], y[BAP], cost;
                fe_lm_result r;
                fe_rng dir = fe_rng_seed((uint64_t)seed + 77);
                int rc;
                ba_setup((uint64_t)seed, hold, 1e-3, &b, x);
                rc = fe_lm_solve(&p, method, NULL, x, w, NULL, NULL, &r);
                ck_assert_msg(rc == FE_OK, "seed %d hold %d method %d: %s after %d iterations (stop %d)",
                              seed, hold, method, fe_strerror(rc), r.iterations, r.stop);
                cost = ba_cost(&b, x, g, d);
                FE_ASSERT_REL(r.cost, cost, 1e-12);
                /* The noise leaves a cost of about (1/2) 400 (1e-3)^2 minus
                   what the 96 free parameters absorb. */
                ck_assert_double_gt(cost, 0.5 * 200 * 1e-6);
                ck_assert_double_lt(cost, 0.5 * 800 * 1e-6);
                /* Gradient: how far each parameter is from its own
                   minimum, g_k / A_kk, in units of its standard error
                   sigma / sqrt(A_kk), sigma^2 = 2 cost / (n - p). */
                for (size_t k = 0; k < np; k++)
                    worst_cos = fmax(worst_cos, fabs(g[k]) / sqrt(d[k] * 2.0 * cost / (double)(NC * NLM - np)));
                /* Brute force: no step along a coordinate or along 40
                   random directions, of length 1e-2 to 1e-7, lowers the
                   cost beyond its rounding. */
                for (int t = 0; t < (int)np + 40; t++) {
                    double u[BAP] = {0};
                    if (t < (int)np) {
                        u[t] = 1.0;
                    } else {
                        double n2 = 0.0;
                        for (size_t k = 0; k < np; k++) {
                            u[k] = fe_rng_normal(&dir);
                            n2 += u[k] * u[k];
                        }
                        for (size_t k = 0; k < np; k++)
                            u[k] /= sqrt(n2);
                    }
                    for (double step = 1e-2; step >= 1e-7; step *= 0.1)
                        for (int sgn = -1; sgn <= 1; sgn += 2) {
                            for (size_t k = 0; k < np; k++)
                                y[k] = x[k] + sgn * step * u[k];
                            worst_gain = fmax(worst_gain, (cost - ba_cost(&b, y, NULL, NULL)) / cost);
                        }
                }
                runs++;
            }
            free(w);
        }
    }
    fprintf(stderr, "noisy bundle adjustment: %d runs, largest gradient %.3g standard errors, "
            "best brute-force gain %.3g of the cost\n", runs, worst_cos, worst_gain);
    ck_assert_double_lt(worst_cos, 1e-4);
    ck_assert_double_lt(worst_gain, 1e-12);
}
END_TEST

/* ------------------------------------------------------ the report */

struct table { int rows, accepted, stop_at; double last_cost; int increasing; };

static int record(const fe_lm_iteration *it, void *ctx)
{
    struct table *t = ctx;
    t->rows++;
    t->accepted += it->accepted;
    if (it->iteration != t->rows)
        t->increasing = 1;
    /* The cost never rises, except within its rounding (lm.org). */
    if (it->cost > t->last_cost * (1.0 + 64 * DBL_EPSILON))
        t->increasing = 1;
    if (!it->accepted && it->change > 0.0 && it->ratio > 0.0)
        t->increasing = 1;
    t->last_cost = it->cost;
    return t->stop_at > 0 && t->rows >= t->stop_at;
}

START_TEST(report_table_and_stop)
{
    static struct ba b;
    fe_lm_problem p = {2 * NC - 2, 2, NLM, ba_model, &b};
    double *w = lm_work(&p, FE_LM_SCHUR), x[BAP];
    struct table t = {0, 0, 0, INFINITY, 0};
    fe_lm_result r;
    fe_lm_params par = fe_lm_default_params();

    ba_setup(7, 1, 0.0, &b, x);
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_SCHUR, NULL, x, w, record, &t, &r), FE_OK);
    ck_assert_int_eq(t.rows, r.iterations);
    ck_assert_int_eq(t.accepted, r.accepted);
    ck_assert_int_eq(t.increasing, 0);
    ck_assert_double_eq(t.last_cost, r.cost);
    /* One evaluation at the start, one per trial point, one per accepted
       step; at most one more per line search; at most two, and one more
       when it moves, per search along the last two steps (after every
       accepted step but the first). */
    ck_assert_int_le(r.accelerated, r.accepted - 1);
    ck_assert_int_ge(r.evaluations, 1 + r.iterations + r.accepted + r.accelerated);
    ck_assert_int_le(r.evaluations, 1 + 2 * r.iterations + r.accepted + 2 * (r.accepted - 1) + r.accelerated);
    ck_assert(r.stop == FE_LM_XTOL || r.stop == FE_LM_FTOL);
    /* A callback that says stop after two rows. */
    ba_setup(7, 1, 0.0, &b, x);
    t = (struct table){0, 0, 2, INFINITY, 0};
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_SCHUR, NULL, x, w, record, &t, &r), FE_ESTOPPED);
    ck_assert_int_eq(r.iterations, 2);
    ck_assert_int_eq(r.stop, FE_LM_STOPPED);
    /* Too few iterations allowed. */
    ba_setup(7, 1, 0.0, &b, x);
    par.max_iter = 2;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_SCHUR, &par, x, w, NULL, NULL, &r), FE_ENOCONV);
    ck_assert_int_eq(r.stop, FE_LM_MAXITER);
    ck_assert_int_eq(r.iterations, 2);
    ck_assert_double_lt(r.cost, r.initial_cost);
    free(w);
}
END_TEST

/* ------------------------------------------------ failures of the model */

/* f = sqrt(x) - sqrt(2): the Gauss-Newton step from x = 100 lands at a
   negative x, where the model fails (NaN); LM must reject it and go on. */
static int sqrt_model(const double *x, fe_lm_sink *s, void *ctx)
{
    double j = 0.5 / sqrt(x[0]);
    (void)ctx;
    return fe_lm_emit(s, sqrt(x[0]) - sqrt(2.0), 1.0, &j, FE_SCHUR_NONE, NULL);
}

static int silent_model(const double *x, fe_lm_sink *s, void *ctx)
{
    (void)x;
    (void)s;
    (void)ctx;
    return FE_OK;
}

static int bad_block_model(const double *x, fe_lm_sink *s, void *ctx)
{
    const double jg[1] = {1.0}, jl[1] = {1.0};
    (void)ctx;
    fe_lm_emit(s, x[0], 1.0, jg, 5, jl);     /* block 5 of 2: ignored error */
    return FE_OK;
}

/* The rows of a report, as given. */
struct all_rows { int n; fe_lm_iteration row[64]; };

static int keep_all_rows(const fe_lm_iteration *it, void *ctx)
{
    struct all_rows *t = ctx;
    if (t->n < 64)
        t->row[t->n] = *it;
    t->n++;
    return 0;
}

/* f = x - 2, whose gradient is 1 at the start x = 100 and NaN anywhere
   else: the cost can be had at every point, the Jacobian only at the
   start. */
static int gradient_only_at_the_start(const double *x, fe_lm_sink *s, void *ctx)
{
    double j = x[0] == 100.0 ? 1.0 : NAN;
    (void)ctx;
    return fe_lm_emit(s, x[0] - 2.0, 1.0, &j, FE_SCHUR_NONE, NULL);
}

START_TEST(model_failures_are_handled)
{
    fe_lm_problem p = {1, 0, 0, sqrt_model, NULL};
    double w[64], x[3] = {100.0, 0, 0};
    fe_lm_params par = fe_lm_default_params();
    fe_lm_result r;
    static struct all_rows t;

    par.lambda0 = 1e-9;                      /* take the bold step first */
    ck_assert_uint_le(fe_lm_work(&p, FE_LM_DENSE), 64);
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, keep_all_rows, &t, &r), FE_OK);
    ck_assert_double_eq_tol(x[0], 2.0, 1e-9);
    ck_assert_int_gt(r.iterations, r.accepted);  /* at least one rejection */
    /* The first step, h = -(10 - sqrt 2) / (1/20) = -171.7 from 100, lands
       where the model fails: rejected, and its row shows no gain (a
       positive ratio is a step taken, lm.org).  No rejected row has one. */
    ck_assert_int_eq(t.n, r.iterations);
    ck_assert_int_eq(t.row[0].accepted, 0);
    ck_assert_double_le(t.row[0].ratio, 0.0);
    for (int i = 0; i < t.n && i < 64; i++)
        ck_assert_msg(t.row[i].accepted || t.row[i].ratio <= 0.0, "row %d: ratio %g rejected",
                      i + 1, t.row[i].ratio);
    /* Failure at the start is returned. */
    x[0] = -1.0;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_ENONFINITE);
    ck_assert_double_eq(x[0], -1.0);
    /* A model that fails at a step already taken, when the solver asks
       it for the Jacobian there (seed 9915's lm:600): the first step, from
       100 with lambda 1e-9 to about 2, lowers the cost when only the cost
       is wanted, is taken, and the Jacobian at the new point is NaN.  The
       model's error stops the solver and is returned (lm.h). */
    p.model = gradient_only_at_the_start;
    x[0] = 100.0;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_ENONFINITE);
    ck_assert_double_ne(x[0], 100.0);
    /* No residuals; a bad block index even if the model ignores it. */
    p.model = silent_model;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, NULL, x, w, NULL, NULL, &r), FE_ETOOFEW);
    p = (fe_lm_problem){1, 1, 2, bad_block_model, NULL};
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_SCHUR, NULL, x, w, NULL, NULL, &r), FE_EINVAL);
    /* Bad arguments. */
    ck_assert_int_eq(fe_lm_solve(&p, 7, NULL, x, w, NULL, NULL, &r), FE_EINVAL);
    ck_assert_uint_eq(fe_lm_work(&p, 7), 0);
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_SCHUR, NULL, x, NULL, NULL, NULL, &r), FE_EINVAL);
    p = (fe_lm_problem){0, 0, 0, sqrt_model, NULL};
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, NULL, x, w, NULL, NULL, &r), FE_EINVAL);
    par = fe_lm_default_params();
    par.lambda0 = 0.0;
    p = (fe_lm_problem){1, 0, 0, sqrt_model, NULL};
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_EINVAL);
}
END_TEST

/* A quantised measurement, f = floor(x) - 1/2 with the gradient of x: from
   x = 1/4 every step h = (1/2) / (1 + lambda) stays in [0, 1), where the
   cost is exactly 1/8, so every gain ratio is exactly 0 and no step is
   taken.  The damping grows as lambda <- nu lambda, nu <- 2 nu: row k is
   solved with 1e-3 2^(k(k-1)/2).  The step falls under xtol (|h| <=
   1e-12 (1/4 + 1e-12)) first at lambda = 1e-3 2^55 = 3.6e13, the 11th
   step, so the iteration ends there after 10 rows, at x = 1/4.  A
   relative tolerance of 1e-6, met by the predicted reduction 0.125 (1 + 2
   lambda) / (1 + lambda)^2 from the 9th row on (lambda = 6.9e7), does not
   end it: rtol counts only a step taken (lm.h). */
static int quantised(const double *x, fe_lm_sink *s, void *ctx)
{
    const double j = 1.0;
    (void)ctx;
    return fe_lm_emit(s, floor(x[0]) - 0.5, 1.0, &j, FE_SCHUR_NONE, NULL);
}

START_TEST(a_flat_cost_is_not_a_relative_convergence)
{
    fe_lm_problem p = {1, 0, 0, quantised, NULL};
    double w[64], x[1] = {0.25};
    fe_lm_params par = fe_lm_default_params();
    fe_lm_result r;
    static struct all_rows t;

    par.rtol = 1e-6;
    ck_assert_uint_le(fe_lm_work(&p, FE_LM_DENSE), 64);
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, keep_all_rows, &t, &r), FE_OK);
    ck_assert_int_eq(r.stop, FE_LM_XTOL);
    ck_assert_int_eq(r.iterations, 10);
    ck_assert_int_eq(r.accepted, 0);
    ck_assert_double_eq(x[0], 0.25);
    ck_assert_double_eq(r.cost, 0.125);
    ck_assert_int_eq(t.n, 10);
    for (int k = 1; k <= 10; k++) {
        ck_assert_double_eq(t.row[k - 1].lambda, ldexp(1e-3, k * (k - 1) / 2));
        ck_assert_double_eq(t.row[k - 1].ratio, 0.0);
        ck_assert_int_eq(t.row[k - 1].accepted, 0);
    }
}
END_TEST

/* --------------------------------- multi-session magnetometer calibration */

static int magcal_fit(const fe_sessions *c, double *x, fe_lm_result *res)
{
    double *w = malloc(fe_sessions_work(c) * sizeof *w);
    int rc;
    if (w == NULL)
        return FE_ENOMEM;
    rc = fe_sessions_fit(c, x, w, res);
    free(w);
    return rc;
}

START_TEST(sessions_count_their_parameters)
{
    /* Six entries of the symmetric S, then three per offset: one offset
       per session, or one for all. */
    fe_sessions c = {0};
    for (size_t k = 1; k <= 5; k++) {
        c.count = k;
        c.one_offset = 0;
        ck_assert_uint_eq(fe_sessions_params(&c), 6 + 3 * k);
        c.one_offset = 1;
        ck_assert_uint_eq(fe_sessions_params(&c), 9);
    }
}
END_TEST

/* One residual x^2 - 4 of one parameter; rows of the iteration table. */
static int square_model(const double *x, fe_lm_sink *s, void *ctx)
{
    double j = 2.0 * x[0];
    (void)ctx;
    return fe_lm_emit(s, x[0] * x[0] - 4.0, 1.0, &j, FE_SCHUR_NONE, NULL);
}

struct rows { int n; fe_lm_iteration row[8]; };

static int keep_rows(const fe_lm_iteration *it, void *ctx)
{
    struct rows *r = ctx;
    if (r->n < 8)
        r->row[r->n++] = *it;
    return 0;
}

START_TEST(first_step_is_extended_along_its_line)
{
    /* The first iteration from x = 1, done here by hand as lm.org states
       it: cost (1/2) f^2, A = J^2, b = -J f, h = b / (A (1 + lambda0)),
       predicted reduction (1/2) h (b + lambda0 A h), gain ratio rho =
       (cost - cost(x + h)) / predicted.  rho is about 0.44, more than
       0.25 from 1, so the step goes to the minimum t* of the parabola
       through the cost at 0 (slope -b h) and at 1, and t* h is the step
       reported when the cost is lower there. */
    fe_lm_problem p = {1, 0, 0, square_model, NULL};
    double *w = lm_work(&p, FE_LM_DENSE), x = 1.0;
    struct rows t = {0};
    fe_lm_result r;
    const double lambda = fe_lm_default_params().lambda0;
    double f0 = x * x - 4.0, J = 2.0 * x, cost = 0.5 * f0 * f0, A = J * J, b = -J * f0;
    double h = b / (A * (1.0 + lambda)), pred = 0.5 * h * (b + lambda * A * h);
    double f1 = (x + h) * (x + h) - 4.0, cost1 = 0.5 * f1 * f1, rho = (cost - cost1) / pred;
    double slope = h * b, c = cost1 - cost + slope, ts = fmin(slope / (2.0 * c), 64.0);
    double fe = (x + ts * h) * (x + ts * h) - 4.0, coste = 0.5 * fe * fe;
    ck_assert_double_lt(fabs(rho - 1.0), 0.75);          /* the premises */
    ck_assert_double_gt(fabs(rho - 1.0), 0.25);
    ck_assert_double_lt(coste, cost1);
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, NULL, &x, w, keep_rows, &t, &r), FE_OK);
    ck_assert_int_ge(t.n, 2);
    FE_ASSERT_REL(t.row[0].ratio, rho, 1e-12);
    FE_ASSERT_REL(t.row[0].step, fabs(ts * h), 1e-12);
    FE_ASSERT_REL(t.row[0].change, cost - coste, 1e-12);   /* the step taken */
    FE_ASSERT_REL(t.row[0].cost, coste, 1e-12);
    ck_assert_double_eq(t.row[0].lambda, lambda);
    ck_assert_int_eq(t.row[0].accepted, 1);
    ck_assert_int_ge(r.extended, 1);
    FE_ASSERT_REL(r.initial_cost, cost, 1e-15);
    ck_assert_double_eq_tol(x, 2.0, 1e-9);
    free(w);
}
END_TEST

/* f1 = 2 + x (weight 1) and f2 = 4 x^2 (weight 3/4): at x = 0 the second
   has no slope, so the Gauss-Newton model sees only the first.  Each call
   is counted in *ctx (an int) when ctx is given. */
static int line_min_at_one_model(const double *x, fe_lm_sink *s, void *ctx)
{
    double j1 = 1.0, j2 = 8.0 * x[0];
    if (ctx != NULL)
        ++*(int *)ctx;
    fe_lm_emit(s, 2.0 + x[0], 1.0, &j1, FE_SCHUR_NONE, NULL);
    return fe_lm_emit(s, 4.0 * x[0] * x[0], 0.75, &j2, FE_SCHUR_NONE, NULL);
}

START_TEST(a_step_already_at_its_parabolas_minimum_is_not_extended)
{
    /* The first iteration from x = 0 with lambda0 = 3, by hand, every
       number a short binary fraction: cost (1/2)(2^2) = 2, A = 1, b = -2,
       h = b / (A (1 + 3)) = -1/2; at x + h, f = (3/2, 1) and the cost is
       (1/2)(9/4 + 3/4) = 3/2; predicted reduction (1/2) h (b + 3 A h) =
       7/8, so rho = (1/2) / (7/8) = 4/7, more than 0.25 from 1: the line
       is looked at.  The parabola through the cost at 0 (2, slope
       -b h = -1) and at 1 (3/2) is 2 - t + t^2/2, whose minimum is at
       t* = 1 exactly: the trial point is that minimum, the step is not
       extended, and the row reports |h| = 1/2; the point t* h, which is
       the trial point, is not evaluated again, nor counted: the result
       counts the model's calls, three (the start with its Jacobian, the
       trial point, and the accepted point's Jacobian) or two. */
    int calls = 0;
    fe_lm_problem p = {1, 0, 0, line_min_at_one_model, &calls};
    fe_lm_params par = fe_lm_default_params();
    double *w = lm_work(&p, FE_LM_DENSE), x = 0.0;
    struct rows t = {0};
    fe_lm_result r;
    const double cost = 2.0, b = -2.0, h = -0.5, cost1 = 1.5, pred = 0.875;
    const double slope = h * b, c = cost1 - cost + slope;
    ck_assert_double_eq(slope / (2.0 * c), 1.0);          /* the premises */
    ck_assert_double_gt(fabs((cost - cost1) / pred - 1.0), 0.25);
    par.lambda0 = 3.0;
    par.max_iter = 1;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, &x, w, keep_rows, &t, &r), FE_ENOCONV);
    ck_assert_int_eq(t.n, 1);
    ck_assert_double_eq(t.row[0].lambda, 3.0);
    FE_ASSERT_REL(t.row[0].ratio, 4.0 / 7.0, 1e-15);
    ck_assert_double_eq(t.row[0].step, 0.5);
    ck_assert_double_eq(t.row[0].change, cost - cost1);
    ck_assert_double_eq(t.row[0].cost, cost1);
    ck_assert_int_eq(t.row[0].accepted, 1);
    ck_assert_int_eq(r.extended, 0);
    ck_assert_int_eq(r.accepted, 1);
    ck_assert_int_eq(r.evaluations, calls);
    ck_assert_double_eq(r.initial_cost, cost);
    ck_assert_double_eq(x, h);
    free(w);
}
END_TEST

/* sigma (x^2 - 4): the cost of the scaled square; its gradient. */
static int scaled_square_model(const double *x, fe_lm_sink *s, void *ctx)
{
    double sg = *(const double *)ctx, j = sg * 2.0 * x[0];
    return fe_lm_emit(s, sg * (x[0] * x[0] - 4.0), 1.0, &j, FE_SCHUR_NONE, NULL);
}

/* The same, its sigma and a count of the model's calls in ctx. */
struct counted_square { double sg; int calls; };

static int counted_square_model(const double *x, fe_lm_sink *s, void *ctx)
{
    struct counted_square *c = ctx;
    c->calls++;
    return scaled_square_model(x, s, &c->sg);
}

static double sq_cost(double sg, double x)
{
    double f = sg * (x * x - 4.0);
    return 0.5 * f * f;
}

START_TEST(second_step_searches_along_the_last_two)
{
    /* The first two iterations of lm.org's algorithm, done here by hand
       for the one residual sigma (x^2 - 4) from x = 1: the damped step, its
       gain ratio, the parabola along a step whose ratio is more than 0.25
       from 1, the damping's update lambda max(1/3, 1 - (2 rho - 1)^3), and
       after the second accepted step the search along d = x2 - x0 (the
       last two steps): the cost at x2 + d, the minimum t* of the parabola
       through cost(x2) (slope b'd) and cost(x2 + d), or 64 when it opens
       downwards, kept if lower than at x2 + d, and the move if lower than
       at x2.  From x = 3 the second step lands short of the root and the
       search moves it nearer; sigma = 0.01 puts the parabola's curvature
       term under 1. */
    double sg = 0.01;
    fe_lm_problem p = {1, 0, 0, scaled_square_model, &sg};
    double *w = lm_work(&p, FE_LM_DENSE), x = 3.0, y = 3.0, ya = 0.0;
    double lambda = fe_lm_default_params().lambda0, nu = 2.0, rowcost[2];
    struct rows t = {0};
    fe_lm_result r;
    int have = 0, accelerated = 0, extended = 0, parabola = 0;
    int evals = 1;                                  /* the start, with its Jacobian */
    for (int it = 0; it < 2; it++) {
        double f = sg * (y * y - 4.0), J = sg * 2.0 * y, A = J * J, b = -J * f;
        double cost = sq_cost(sg, y), h = b / (A * (1.0 + lambda));
        double pred = 0.5 * h * (b + lambda * A * h), slope = h * b;
        double yt = y + h, ct = sq_cost(sg, yt), rho = (cost - ct) / pred;
        evals++;                                    /* the trial point */
        if (rho > 0.0 && fabs(rho - 1.0) > 0.25) {
            double c = ct - cost + slope;
            if (c > 0.0 && slope > 0.0) {
                double ts = fmin(slope / (2.0 * c), 64.0);
                evals += ts > 0.0 && ts != 1.0;     /* the point along the step */
                if (ts > 0.0 && ts != 1.0 && sq_cost(sg, y + ts * h) < ct) {
                    yt = y + ts * h;
                    ct = sq_cost(sg, yt);
                    extended++;
                }
            }
        }
        ck_assert_double_gt(rho, 0.0);              /* both are taken */
        {
            double d = yt - ya, tt = 2.0 * rho - 1.0;
            ya = y;
            y = yt;
            cost = ct;
            evals++;                                /* the step taken, with its Jacobian */
            if (have) {
                double f2 = sg * (y * y - 4.0), b2 = -(sg * 2.0 * y) * f2, sl = b2 * d;
                if (sl > 0.0) {
                    double c1 = sq_cost(sg, y + d), c = c1 - cost + sl, ta, cta;
                    evals++;                        /* x + d */
                    ta = c > 0.0 ? fmin(sl / (2.0 * c), 64.0) : 64.0;
                    cta = c1;
                    if (ta != 1.0) {
                        cta = sq_cost(sg, y + ta * d);
                        evals++;                    /* x + t* d */
                        parabola++;
                        if (!(cta < c1)) {
                            ta = 1.0;
                            cta = c1;
                        }
                    }
                    ck_assert_double_lt(c, 1.0);    /* the premise */
                    if (cta < cost) {
                        y += ta * d;
                        cost = sq_cost(sg, y);
                        accelerated++;
                        evals++;                    /* the move, with its Jacobian */
                    }
                }
            }
            have = 1;
            lambda = fmax(1e-10, lambda * fmax(1.0 / 3.0, 1.0 - tt * tt * tt));
            nu = 2.0;
        }
        rowcost[it] = cost;
    }
    (void)nu;
    ck_assert_int_eq(accelerated, 1);               /* the search moved */
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, NULL, &x, w, keep_rows, &t, &r), FE_OK);
    ck_assert_int_ge(t.n, 3);
    FE_ASSERT_REL(t.row[0].cost, rowcost[0], 1e-12);
    FE_ASSERT_REL(t.row[1].cost, rowcost[1], 1e-12);
    ck_assert_int_ge(r.accelerated, 1);
    ck_assert_int_eq(extended, 0);
    ck_assert_double_eq_tol(x, 2.0, 1e-9);
    {
        /* The same two iterations alone (seed 10117's lm:309): the result
           counts every call of the model (lm.h), the search's point
           x + t* d among them, as the count by hand does. */
        struct counted_square cs = {sg, 0};
        fe_lm_problem pc = {1, 0, 0, counted_square_model, &cs};
        fe_lm_params par = fe_lm_default_params();
        int rc;
        x = 3.0;
        par.max_iter = 2;
        ck_assert_int_eq(parabola, 1);              /* the premise: t* != 1 */
        rc = fe_lm_solve(&pc, FE_LM_DENSE, &par, &x, w, NULL, NULL, &r);
        ck_assert(rc == FE_ENOCONV || rc == FE_OK);
        ck_assert_int_eq(r.iterations, 2);
        ck_assert_int_eq(r.accelerated, 1);
        ck_assert_int_eq(cs.calls, evals);
        ck_assert_int_eq(r.evaluations, evals);
        FE_ASSERT_REL(r.cost, rowcost[1], 1e-12);
    }
    free(w);
}
END_TEST

/* Two residuals sigma (x0^2 - 4) and sigma (x1^2 - 9): the Jacobian is
   diagonal, so (A + lambda diag A) h = b is solved entry by entry, h_i =
   b_i / (A_ii (1 + lambda)), and the two parameters share only the
   damping and the gain ratio. */
static int two_squares_model(const double *x, fe_lm_sink *s, void *ctx)
{
    const double sg = *(const double *)ctx, a[2] = {4.0, 9.0};
    for (int i = 0; i < 2; i++) {
        double j[2] = {0.0, 0.0};
        int rc;
        j[i] = sg * 2.0 * x[i];
        rc = fe_lm_emit(s, sg * (x[i] * x[i] - a[i]), 1.0, j, FE_SCHUR_NONE, NULL);
        if (rc != FE_OK)
            return rc;
    }
    return FE_OK;
}

static double two_sq_cost(double sg, const double *x)
{
    const double a[2] = {4.0, 9.0};
    double c = 0.0;
    for (int i = 0; i < 2; i++)
        c += 0.5 * sg * sg * (x[i] * x[i] - a[i]) * (x[i] * x[i] - a[i]);
    return c;
}

START_TEST(the_search_along_the_last_two_steps_moves_every_parameter)
{
    /* second_step_searches_along_the_last_two with two parameters, by
       hand: the damped step, its gain ratio, the parabola along a step
       whose ratio is more than 0.25 from 1, the damping's update, and
       after the second accepted step the search along d = x2 - x0, every
       entry of it: the slope b'd, the cost at x2 + d, the parabola's
       minimum t* (64 when it opens downwards), and the move when it lowers
       the cost.  From (3, 4.5) the second step lands short of (2, 3) and
       the search moves it nearer.  Seed 10223's lm:587 (the loop that
       forms d counting down from 0) formed only d's first entry and left
       the second as the workspace held it; with one parameter that is the
       whole of d. */
    double sg = 0.01, x[2] = {3.0, 4.5}, y[2] = {3.0, 4.5}, ya[2] = {0.0, 0.0};
    fe_lm_problem p = {2, 0, 0, two_squares_model, &sg};
    double *w = lm_work(&p, FE_LM_DENSE), lambda = fe_lm_default_params().lambda0;
    double rowcost[2] = {0.0, 0.0};
    const double a[2] = {4.0, 9.0};
    fe_lm_params par = fe_lm_default_params();
    fe_lm_result r;
    int have = 0, accelerated = 0, evals = 1, rc;
    for (int it = 0; it < 2; it++) {
        double b[2], A[2], h[2], yt[2], cost = two_sq_cost(sg, y), pred = 0.0, slope = 0.0;
        double ct, rho;
        for (int i = 0; i < 2; i++) {
            double f = sg * (y[i] * y[i] - a[i]), J = sg * 2.0 * y[i];
            A[i] = J * J;
            b[i] = -J * f;
            h[i] = b[i] / (A[i] * (1.0 + lambda));
            pred += h[i] * (b[i] + lambda * A[i] * h[i]);
            slope += h[i] * b[i];
            yt[i] = y[i] + h[i];
        }
        pred *= 0.5;
        ct = two_sq_cost(sg, yt);
        rho = (cost - ct) / pred;
        evals++;                                    /* the trial point */
        ck_assert_double_gt(rho, 0.0);              /* both are taken */
        if (fabs(rho - 1.0) > 0.25) {
            double c = ct - cost + slope;
            if (c > 0.0 && slope > 0.0) {
                double ts = fmin(slope / (2.0 * c), 64.0), ye[2];
                if (ts > 0.0 && ts != 1.0) {
                    evals++;                        /* the point along the step */
                    for (int i = 0; i < 2; i++)
                        ye[i] = y[i] + ts * h[i];
                    if (two_sq_cost(sg, ye) < ct) {
                        memcpy(yt, ye, sizeof yt);
                        ct = two_sq_cost(sg, yt);
                    }
                }
            }
        }
        {
            double d[2], tt = 2.0 * rho - 1.0;
            for (int i = 0; i < 2; i++)
                d[i] = yt[i] - ya[i];
            memcpy(ya, y, sizeof ya);
            memcpy(y, yt, sizeof y);
            cost = ct;
            evals++;                                /* the step taken, with its Jacobian */
            if (have) {
                double sl = 0.0, y1[2], c1, c, ta, cta;
                for (int i = 0; i < 2; i++) {
                    double f2 = sg * (y[i] * y[i] - a[i]);
                    sl += -(sg * 2.0 * y[i]) * f2 * d[i];
                    y1[i] = y[i] + d[i];
                }
                ck_assert_double_gt(sl, 0.0);       /* the premise: a search */
                c1 = two_sq_cost(sg, y1);
                evals++;                            /* x + d */
                c = c1 - cost + sl;
                ta = c > 0.0 ? fmin(sl / (2.0 * c), 64.0) : 64.0;
                cta = c1;
                ck_assert_double_ne(ta, 1.0);       /* the premise: x + t* d */
                {
                    double yt2[2];
                    for (int i = 0; i < 2; i++)
                        yt2[i] = y[i] + ta * d[i];
                    cta = two_sq_cost(sg, yt2);
                    evals++;                        /* x + t* d */
                    if (!(cta < c1)) {
                        ta = 1.0;
                        cta = c1;
                    }
                }
                ck_assert_double_lt(cta, cost);     /* the premise: the search moves */
                for (int i = 0; i < 2; i++)
                    y[i] += ta * d[i];
                cost = two_sq_cost(sg, y);
                accelerated++;
                evals++;                            /* the move, with its Jacobian */
            }
            have = 1;
            lambda = fmax(1e-10, lambda * fmax(1.0 / 3.0, 1.0 - tt * tt * tt));
        }
        rowcost[it] = cost;
    }
    ck_assert_int_eq(accelerated, 1);
    par.max_iter = 2;
    rc = fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r);
    ck_assert(rc == FE_ENOCONV || rc == FE_OK);
    ck_assert_int_eq(r.iterations, 2);
    ck_assert_int_eq(r.accelerated, 1);
    ck_assert_int_eq(r.evaluations, evals);
    FE_ASSERT_REL(r.cost, rowcost[1], 1e-12);
    FE_ASSERT_REL(x[0], y[0], 1e-12);
    FE_ASSERT_REL(x[1], y[1], 1e-12);
    free(w);
}
END_TEST

/* A method that is neither FE_LM_DENSE nor FE_LM_SCHUR, and a null
   workspace, are refused (lm.h: FE_EINVAL for a bad method) on a problem
   that would otherwise solve, x left as it was.  model_failures_are_handled
   asks the same of a problem whose model emits a stray block, which is
   refused in any case; seed 10223's lm:391 (the method's test joined to
   the workspace's by && instead of ||) let the method through there. */
START_TEST(a_bad_method_or_no_workspace_is_refused_on_a_good_problem)
{
    fe_lm_problem p = {1, 0, 0, sqrt_model, NULL};
    double w[64], x = 100.0;
    fe_lm_result r;
    const int bad[3] = {-1, 2, 7};
    ck_assert_uint_le(fe_lm_work(&p, FE_LM_DENSE), 64);
    ck_assert_uint_le(fe_lm_work(&p, FE_LM_SCHUR), 64);
    for (int i = 0; i < 3; i++) {
        ck_assert_int_eq(fe_lm_solve(&p, bad[i], NULL, &x, w, NULL, NULL, &r), FE_EINVAL);
        ck_assert_double_eq(x, 100.0);
    }
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, NULL, &x, NULL, NULL, NULL, &r), FE_EINVAL);
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_SCHUR, NULL, &x, NULL, NULL, NULL, &r), FE_EINVAL);
    ck_assert_double_eq(x, 100.0);
    /* The same problem with a good method and workspace solves: x = 2. */
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, NULL, &x, w, NULL, NULL, &r), FE_OK);
    ck_assert_double_eq_tol(x, 2.0, 1e-9);
}
END_TEST

/* Two parameters whose columns are S (1, 1) and S K (1 + d, 1 - d),
   K = 1000: the second diagonal entry is K times the off-diagonal one. */
struct collinear { double d; };

static int collinear_model(const double *x, fe_lm_sink *s, void *ctx)
{
    const struct collinear *c = ctx;
    const double S = 1e4;
    for (int i = 0; i < 2; i++) {
        double j[2] = {S, S * 1e3 * (1.0 + (i ? -c->d : c->d))};
        int rc = fe_lm_emit(s, j[0] * x[0] + j[1] * x[1] - S * (1.0 + i), 1.0, j,
                            FE_SCHUR_NONE, NULL);
        if (rc != FE_OK)
            return rc;
    }
    return FE_OK;
}

static int stop_at_once(const fe_lm_iteration *it, void *ctx)
{
    *(fe_lm_iteration *)ctx = *it;
    return 1;
}

START_TEST(undamped_rank_test_is_relative_to_the_diagonal)
{
    /* Without damping (lambda0 = 1e-300) the Cholesky pivot of the second
       column is its distance from the first: pivot^2 / A22 = d^2 / (1 +
       d^2), 1e-14 for d = 1e-7, under the rank tolerance 1e-12 of the
       diagonal A22 = 2e14 (though above 1e-12 of the off-diagonal entry
       A12 = 2e11, or of A11 = 2e8): the system is singular, no step (step
       0, not accepted).  For d = 1e-4 (1e-8) the step is the exact
       solution of the 2 x 2 system. */
    struct collinear c = {1e-7};
    fe_lm_problem p = {2, 0, 0, collinear_model, &c};
    double *w = lm_work(&p, FE_LM_DENSE), x[2] = {0, 0};
    fe_lm_params par = fe_lm_default_params();
    fe_lm_iteration row;
    fe_lm_result r;
    par.lambda0 = 1e-300;           /* 1 + lambda0 is 1: no damping */
    par.lambda_min = 0.0;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, stop_at_once, &row, &r),
                     FE_ESTOPPED);
    ck_assert_double_eq(row.step, 0.0);
    ck_assert_int_eq(row.accepted, 0);
    ck_assert_double_eq(x[0], 0.0);
    ck_assert_double_eq(x[1], 0.0);
    c.d = 1e-4;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, stop_at_once, &row, &r),
                     FE_ESTOPPED);
    ck_assert_int_eq(row.accepted, 1);
    /* x0 + K x1 (1 + d) = 1, x0 + K x1 (1 - d) = 2: x1 = -1/(2dK),
       x0 = 1 - K x1 (1 + d). */
    {
        double x1 = -1.0 / (2.0 * c.d * 1e3), x0 = 1.0 - 1e3 * x1 * (1.0 + c.d);
        FE_ASSERT_REL(x[1], x1, 1e-6);
        FE_ASSERT_REL(x[0], x0, 1e-6);
        FE_ASSERT_REL(row.step, hypot(x0, x1), 1e-6);
    }
    /* At the tolerance's edge: pivot^2 / A22 = 1.01e-12 is solved and
       0.99e-12 is refused (the pivot is computed to about 1e-4 of itself,
       so the two cannot trade places by rounding). */
    x[0] = x[1] = 0.0;
    c.d = sqrt(1.01e-12 / (1.0 - 1.01e-12));
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, stop_at_once, &row, &r),
                     FE_ESTOPPED);
    ck_assert_int_eq(row.accepted, 1);
    FE_ASSERT_REL(x[1], -1.0 / (2.0 * c.d * 1e3), 1e-3);
    x[0] = x[1] = 0.0;
    c.d = sqrt(0.99e-12 / (1.0 - 0.99e-12));
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, stop_at_once, &row, &r),
                     FE_ESTOPPED);
    ck_assert_double_eq(row.step, 0.0);
    ck_assert_int_eq(row.accepted, 0);
    free(w);
}
END_TEST

/* The session residual rho - 1, rho = |S (m - o)|, computed here. */
static double session_residual(const double *x, const double *m)
{
    double S[3][3], d[3] = {m[0] - x[6], m[1] - x[7], m[2] - x[8]}, r = 0.0;
    fe_sessions_matrix(x, S);
    for (int k = 0; k < 3; k++) {
        double h = S[k][0] * d[0] + S[k][1] * d[1] + S[k][2] * d[2];
        r += h * h;
    }
    return sqrt(r) - 1.0;
}

START_TEST(sessions_first_step_from_a_numerical_jacobian)
{
    /* One session of 40 readings on the ellipsoid |S (m - o)| = 1, and a
       start 1e-3 off in every parameter.  The first damped Gauss-Newton
       step, (A + lambda0 diag A) h = -J'f with J by central differences of
       the residual computed here, is the step the solver reports in its
       first row: the model's analytic gradients are those of its
       residuals (an error in one of them moves |h| by far more than the
       differences' 1e-8). */
    enum { N = 40, P = 9 };
    static double m[3 * N];
    const double truth[P] = {1.1, 0.05, -0.02, 0.9, 0.03, 1.0, 0.3, -0.2, 0.5};
    double x[P], A[P][P + 1] = {{0}}, J[N][P], f[N], h[P], hn = 0.0, w[4096];
    fe_rng g = fe_rng_seed(8);
    fe_sessions c;
    fe_lm_problem prob;
    fe_lm_params par = fe_lm_default_params();
    fe_lm_result r;
    static struct all_rows t;
    for (int i = 0; i < N; i++) {
        double S[3][3], d[3], len = 0.0;
        fe_sessions_matrix(truth, S);
        fe_rng_unit_vector(&g, d);
        for (int k = 0; k < 3; k++) {
            double hk = S[k][0] * d[0] + S[k][1] * d[1] + S[k][2] * d[2];
            len += hk * hk;
        }
        for (int k = 0; k < 3; k++)
            m[3 * i + k] = truth[6 + k] + d[k] / sqrt(len);
    }
    memset(&c, 0, sizeof c);
    c.count = 1;
    c.m[0] = m;
    c.n[0] = N;
    for (int k = 0; k < P; k++)
        x[k] = truth[k] + (k % 2 ? 1e-3 : -1e-3);
    for (int i = 0; i < N; i++) {
        f[i] = session_residual(x, m + 3 * i);
        for (int k = 0; k < P; k++) {
            double xp[P], xm[P], e = 1e-6;
            memcpy(xp, x, sizeof xp);
            memcpy(xm, x, sizeof xm);
            xp[k] += e;
            xm[k] -= e;
            J[i][k] = (session_residual(xp, m + 3 * i) - session_residual(xm, m + 3 * i))
                      / (xp[k] - xm[k]);
        }
    }
    for (int k = 0; k < P; k++) {
        for (int l = 0; l < P; l++)
            for (int i = 0; i < N; i++)
                A[k][l] += J[i][k] * J[i][l];
        for (int i = 0; i < N; i++)
            A[k][P] -= J[i][k] * f[i];
    }
    for (int k = 0; k < P; k++)
        A[k][k] *= 1.0 + par.lambda0;
    for (int k = 0; k < P; k++)                 /* Gauss-Jordan, pivots on the diagonal */
        for (int i = 0; i < P; i++)
            if (i != k) {
                double q = A[i][k] / A[k][k];
                for (int l = k; l <= P; l++)
                    A[i][l] -= q * A[k][l];
            }
    for (int k = 0; k < P; k++) {
        h[k] = A[k][P] / A[k][k];
        hn += h[k] * h[k];
    }
    hn = sqrt(hn);
    prob = fe_sessions_problem(&c);
    ck_assert_uint_le(fe_lm_work(&prob, FE_LM_DENSE), sizeof w / sizeof w[0]);
    t.n = 0;
    ck_assert_int_eq(fe_lm_solve(&prob, FE_LM_DENSE, &par, x, w, keep_all_rows, &t, &r), FE_OK);
    ck_assert_int_ge(t.n, 1);
    ck_assert_int_eq(t.row[0].accepted, 1);
    ck_assert_double_le(fabs(t.row[0].ratio - 1.0), 0.25);     /* not extended */
    ck_assert_double_eq(t.row[0].lambda, par.lambda0);
    ck_assert_msg(fabs(t.row[0].step - hn) <= 1e-6 * hn, "step %.10g, want %.10g",
                  t.row[0].step, hn);
    for (int k = 0; k < P; k++)
        ck_assert_double_eq_tol(x[k], truth[k], 1e-9);
}
END_TEST

START_TEST(sessions_start_at_the_centroids)
{
    /* Two sessions of four points (different counts would weight the mean
       distance by sample; equal here so the hand figures stay short):
       session 0 at the corners of a square of half-side 1 about (1, 2, 3)
       in the z = 3 plane, session 1 at the corners of a square of half-diagonal 2 about
       (-4, 0, 5).  Centroids (1, 2, 3) and (-4, 0, 5); distances sqrt(2)
       four times and 2 four times; S = I * 8 / (4 sqrt(2) + 8). */
    static const double a[12] = {2, 3, 3, 0, 3, 3, 0, 1, 3, 2, 1, 3};
    static const double b[12] = {-2, 0, 5, -6, 0, 5, -4, 2, 5, -4, -2, 5};
    fe_sessions c = {2, {a, b}, {4, 4}, 0};
    double x[12], s = 8.0 / (4.0 * sqrt(2.0) + 8.0);
    for (int k = 0; k < 12; k++)
        x[k] = 99.0;
    fe_sessions_start(&c, x);
    ck_assert_double_eq_tol(x[0], s, 1e-15);
    ck_assert_double_eq_tol(x[3], s, 1e-15);
    ck_assert_double_eq_tol(x[5], s, 1e-15);
    ck_assert_double_eq(x[1], 0.0);
    ck_assert_double_eq(x[2], 0.0);
    ck_assert_double_eq(x[4], 0.0);
    ck_assert_double_eq_tol(x[6], 1.0, 1e-15);
    ck_assert_double_eq_tol(x[7], 2.0, 1e-15);
    ck_assert_double_eq_tol(x[8], 3.0, 1e-15);
    ck_assert_double_eq_tol(x[9], -4.0, 1e-15);
    ck_assert_double_eq_tol(x[10], 0.0, 1e-15);
    ck_assert_double_eq_tol(x[11], 5.0, 1e-15);
    /* One offset for both: the mean of the centroids, (-1.5, 1, 4); the
       start is 9 numbers, and what follows them is not written. */
    c.one_offset = 1;
    for (int k = 9; k < 12; k++)
        x[k] = 99.0;
    fe_sessions_start(&c, x);
    ck_assert_double_eq_tol(x[0], s, 1e-15);
    ck_assert_double_eq_tol(x[6], -1.5, 1e-15);
    ck_assert_double_eq_tol(x[7], 1.0, 1e-15);
    ck_assert_double_eq_tol(x[8], 4.0, 1e-15);
    for (int k = 9; k < 12; k++)
        ck_assert_double_eq(x[k], 99.0);
}
END_TEST

START_TEST(magnetometer_sessions_synthetic)
{
    enum { NS = 4, PER = 500 };
    /* Truth: a soft-iron matrix A (readings = A u + o_s + noise, |u| = 1);
       the calibration S is A^{-1}, symmetric when A is. */
    const double A[3][3] = {{1.3, 0.2, -0.1}, {0.2, 0.8, 0.15}, {-0.1, 0.15, 1.1}};
    const double off[NS][3] = {{0.3, -0.2, 0.5}, {1.5, 0.1, -0.4}, {-0.7, 0.9, 0.2}, {0.0, -1.2, 0.8}};
    static double m[NS][PER * 3];
    double x[6 + 3 * NS], S[3][3], err_off = 0.0, err_S = 0.0;
    fe_sessions c = {NS, {0}, {0}, 0};
    fe_rng g = fe_rng_seed(21);
    fe_lm_result r;

    for (int noisy = 0; noisy < 2; noisy++) {
        double sd = noisy ? 0.01 : 0.0;
        for (int b = 0; b < NS; b++) {
            for (int i = 0; i < PER; i++) {
                double u[3], n;
                do {
                    for (int k = 0; k < 3; k++)
                        u[k] = fe_rng_normal(&g);
                    n = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
                } while (n < 1e-9);
                for (int k = 0; k < 3; k++)
                    m[b][3 * i + k] = off[b][k] + sd * fe_rng_normal(&g)
                                      + (A[k][0] * u[0] + A[k][1] * u[1] + A[k][2] * u[2]) / n;
            }
            c.m[b] = m[b];
            c.n[b] = PER;
        }
        ck_assert_int_eq(magcal_fit(&c, x, &r), FE_OK);
        /* S A = I and the offsets, to rounding (noise free) or to the
           noise's reach (sd = 0.01, 2000 readings). */
        fe_sessions_matrix(x, S);
        err_S = err_off = 0.0;
        for (int k = 0; k < 3; k++)
            for (int l = 0; l < 3; l++) {
                double sa = S[k][0] * A[0][l] + S[k][1] * A[1][l] + S[k][2] * A[2][l];
                err_S = fmax(err_S, fabs(sa - (k == l ? 1.0 : 0.0)));
            }
        for (int b = 0; b < NS; b++)
            for (int k = 0; k < 3; k++)
                err_off = fmax(err_off, fabs(x[6 + 3 * b + k] - off[b][k]));
        if (!noisy) {
            ck_assert_double_lt(r.cost, 1e-20);
            ck_assert_double_lt(err_S, 1e-9);
            ck_assert_double_lt(err_off, 1e-9);
        } else {
            ck_assert_double_lt(err_S, 0.01);
            ck_assert_double_lt(err_off, 0.01);
            ck_assert_double_gt(err_off, 0.0);
        }
    }
}
END_TEST

/* Read a QMC5883L recording: 3 header lines, then mx,my,mz; the first
   3000 rows are static and skipped. */
static double *read_qmc(const char *dir, const char *name, size_t *n)
{
    char path[4096], line[256];
    size_t cap = 30000, k = 0, row = 0;
    double *m = malloc(cap * 3 * sizeof *m);
    FILE *f;
    snprintf(path, sizeof path, "%s/qmc5883l_tomisuarez/%s", dir, name);
    f = fopen(path, "r");
    if (f == NULL || m == NULL) {
        if (f != NULL)
            fclose(f);
        free(m);
        return NULL;
    }
    while (fgets(line, sizeof line, f) != NULL) {
        double a, b, c;
        if (sscanf(line, "%lf,%lf,%lf", &a, &b, &c) != 3)
            continue;
        if (row++ < 3000 || k == cap)
            continue;
        m[3 * k] = a;
        m[3 * k + 1] = b;
        m[3 * k + 2] = c;
        k++;
    }
    fclose(f);
    *n = k;
    return m;
}

START_TEST(magnetometer_sessions_real)
{
    const char *dir = fe_test_data_dir("magnetometer_sessions_real");
    double *m1, *m2, xj[12], xc[12], xs[2][12], rms_joint[2], rms_sep[2], rms_common[2];
    size_t n1 = 0, n2 = 0;
    fe_sessions joint = {2, {0}, {0}, 0}, common, one;
    fe_lm_result r;

    if (dir == NULL)
        return;
    m1 = read_qmc(dir, "filtered_raw_data.csv", &n1);
    m2 = read_qmc(dir, "noisy_raw_data.csv", &n2);
    ck_assert_ptr_nonnull(m1);
    ck_assert_ptr_nonnull(m2);
    ck_assert_uint_gt(n1, 15000);
    ck_assert_uint_gt(n2, 15000);
    if (fe_test_quick()) {           /* valgrind: every tenth reading */
        for (size_t i = 0; 10 * i < n1; i++)
            memmove(m1 + 3 * i, m1 + 30 * i, 3 * sizeof *m1);
        for (size_t i = 0; 10 * i < n2; i++)
            memmove(m2 + 3 * i, m2 + 30 * i, 3 * sizeof *m2);
        n1 = (n1 + 9) / 10;
        n2 = (n2 + 9) / 10;
    }
    joint.m[0] = m1;
    joint.n[0] = n1;
    joint.m[1] = m2;
    joint.n[1] = n2;
    common = joint;
    common.one_offset = 1;
    /* The joint fit: one soft-iron matrix, one offset per session. */
    ck_assert_int_eq(magcal_fit(&joint, xj, &r), FE_OK);
    /* Each session alone: its own matrix and offset (9 parameters each). */
    for (int b = 0; b < 2; b++) {
        one = (fe_sessions){1, {joint.m[b]}, {joint.n[b]}, 0};
        ck_assert_int_eq(magcal_fit(&one, xs[b], &r), FE_OK);
        rms_sep[b] = fe_sessions_rms(&one, xs[b], 0);
        rms_joint[b] = fe_sessions_rms(&joint, xj, (size_t)b);
    }
    /* One matrix and one offset for both. */
    ck_assert_int_eq(magcal_fit(&common, xc, &r), FE_OK);
    for (int b = 0; b < 2; b++)
        rms_common[b] = fe_sessions_rms(&common, xc, (size_t)b);
    fprintf(stderr, "magnetometer sessions (QMC5883L filtered / noisy): radial RMS "
                    "separate %.4f / %.4f, shared matrix %.4f / %.4f, shared matrix and offset "
                    "%.4f / %.4f\n", rms_sep[0], rms_sep[1], rms_joint[0], rms_joint[1],
            rms_common[0], rms_common[1]);
    /* More parameters fit at least as well; the shared matrix costs little;
       a shared offset costs more than the per-session offsets. */
    for (int b = 0; b < 2; b++) {
        ck_assert_double_le(rms_sep[b], rms_joint[b] * (1.0 + 1e-9));
        ck_assert_double_lt(rms_joint[b], 1.5 * rms_sep[b]);
    }
    /* The per-session offsets are real: the two recordings' offsets differ
       by more than twice as much as those of the halves of either one. */
    {
        double between = 0.0, within = 0.0;
        for (int k = 0; k < 3; k++)
            between += (xj[6 + k] - xj[9 + k]) * (xj[6 + k] - xj[9 + k]);
        for (int b = 0; b < 2; b++) {
            size_t n = joint.n[b], h = n / 2;
            fe_sessions halves = {2, {joint.m[b], joint.m[b] + 3 * h}, {h, n - h}, 0};
            double xh[12], d = 0.0;
            ck_assert_int_eq(magcal_fit(&halves, xh, &r), FE_OK);
            for (int k = 0; k < 3; k++)
                d += (xh[6 + k] - xh[9 + k]) * (xh[6 + k] - xh[9 + k]);
            within = fmax(within, sqrt(d));
        }
        between = sqrt(between);
        fprintf(stderr, "  offsets (counts): filtered (%.1f, %.1f, %.1f), noisy (%.1f, %.1f, %.1f):"
                        " %.1f apart; halves of one recording at most %.1f apart\n",
                xj[6], xj[7], xj[8], xj[9], xj[10], xj[11], between, within);
        ck_assert_double_gt(between, 2.0 * within);
    }
    free(m1);
    free(m2);
}
END_TEST

/* fe_lm_emit at its edges, inside a model: weight 0 and the last block
   accepted, a weight one step below 0 and the block one past the last
   refused (FE_EINVAL); a residual of 1e150 accepted (w f^2 = 1e300) and
   1e200 refused (w f^2 overflows), as a NaN is (FE_ENONFINITE).  The sink
   remembers the first refusal, so fe_lm_solve returns it even though the
   model returns FE_OK.  `ctx` selects the refusal; it is not modified. */
static int emit_edges(const double *x, fe_lm_sink *s, void *ctx)
{
    const int *which = ctx;
    const double jg[1] = {1.0}, jl[1] = {1.0};
    (void)x;
    ck_assert_int_eq(fe_lm_emit(s, 1.0, 0.0, jg, 1, jl), FE_OK);
    ck_assert_int_eq(fe_lm_emit(s, 1e150, 1.0, jg, 0, jl), FE_OK);
    ck_assert_int_eq(fe_lm_emit(s, 1.0, 1.0, jg, FE_SCHUR_NONE, NULL), FE_OK);
    if (*which == 0)
        ck_assert_int_eq(fe_lm_emit(s, 1.0, -DBL_TRUE_MIN, jg, 0, jl), FE_EINVAL);
    else if (*which == 1)
        ck_assert_int_eq(fe_lm_emit(s, 1.0, 1.0, jg, 2, jl), FE_EINVAL);
    else if (*which == 2)
        ck_assert_int_eq(fe_lm_emit(s, NAN, 1.0, jg, 0, jl), FE_ENONFINITE);
    else
        ck_assert_int_eq(fe_lm_emit(s, 1e200, 1.0, jg, 0, jl), FE_ENONFINITE);
    return FE_OK;
}

/* fe_sessions_model at a point whose offset is a reading: refused. */
static int sessions_at_a_reading(const double *x, fe_lm_sink *s, void *ctx)
{
    ck_assert_int_eq(fe_sessions_model(x, s, ctx), FE_ENONFINITE);
    return FE_ENONFINITE;
}

START_TEST(emit_and_sessions_refusals_at_their_edges)
{
    static const int expect[4] = {FE_EINVAL, FE_EINVAL, FE_ENONFINITE, FE_ENONFINITE};
    const double reading[3] = {1, 2, 3};
    double *w, x[9] = {1, 0, 0, 1, 0, 1, 1, 2, 3};
    fe_sessions c;
    fe_lm_problem sp;
    for (int which = 0; which < 4; which++) {
        fe_lm_problem p = {1, 1, 2, emit_edges, NULL};
        double y[3] = {0, 0, 0};
        p.ctx = (void *)&which;
        w = lm_work(&p, FE_LM_SCHUR);
        ck_assert_int_eq(fe_lm_solve(&p, FE_LM_SCHUR, NULL, y, w, NULL, NULL, NULL),
                         expect[which]);
        free(w);
    }
    memset(&c, 0, sizeof c);
    c.count = 1;
    c.m[0] = reading;
    c.n[0] = 1;
    sp = fe_sessions_problem(&c);
    sp.model = sessions_at_a_reading;
    w = lm_work(&sp, FE_LM_SCHUR);
    ck_assert_int_eq(fe_lm_solve(&sp, FE_LM_SCHUR, NULL, x, w, NULL, NULL, NULL),
                     FE_ENONFINITE);
    /* The session count: 0 and FE_SESSIONS_MAX + 1 are refused. */
    c.count = 0;
    ck_assert_int_eq(fe_sessions_fit(&c, x, w, NULL), FE_EINVAL);
    c.count = FE_SESSIONS_MAX + 1;
    ck_assert_int_eq(fe_sessions_fit(&c, x, w, NULL), FE_EINVAL);
    c.count = 1;
    ck_assert_int_eq(fe_sessions_fit(NULL, x, w, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_sessions_fit(&c, NULL, w, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_sessions_fit(&c, x, NULL, NULL), FE_EINVAL);
    free(w);
}
END_TEST

/* The sink's own refusals, where only the cost is wanted (no Jacobian
   goes to the Schur or dense accumulation that could refuse a row in its
   stead): at every cost-only evaluation, weight 0 and the last block
   (1 of 2) are taken, a weight one step below 0 and the block one past
   the last (2 of 2) refused with FE_EINVAL (lm.h); the count of such
   evaluations is kept in a static, as ctx may not be modified.  Then the
   residuals x_0 - 3 and, for each block b, x_{1+b} - 1.  The refusal
   fails the trial point, which the solver rejects (lm.h), so no step is
   ever taken: the damping grows as in `quantised` above, 1e-3
   2^(k(k-1)/2) at row k, past 1e16 at the 12th, long before a step of
   about 3 / (1 + lambda) from x = 0 falls under xtol (1e-24 there), so
   the solver gives up as stuck (FE_ENOCONV) with x and the cost of the
   start. */
static int cost_only_evaluations;

static int cost_only_edges(const double *x, fe_lm_sink *s, void *ctx)
{
    const double j[1] = {1.0}, zero[1] = {0.0};
    (void)ctx;
    if (!fe_lm_wants_jacobian(s)) {
        cost_only_evaluations++;
        ck_assert_int_eq(fe_lm_emit(s, 1.0, 0.0, NULL, 1, NULL), FE_OK);
        ck_assert_int_eq(fe_lm_emit(s, 1.0, -DBL_TRUE_MIN, NULL, FE_SCHUR_NONE, NULL),
                         FE_EINVAL);
        ck_assert_int_eq(fe_lm_emit(s, 1.0, 1.0, NULL, 2, NULL), FE_EINVAL);
    }
    for (size_t b = 0; b < 2; b++)
        fe_lm_emit(s, x[1 + b] - 1.0, 1.0, zero, b, j);
    return fe_lm_emit(s, x[0] - 3.0, 1.0, j, FE_SCHUR_NONE, NULL);
}

/* A row given block 0 on a problem without blocks (nl = nb = 0), with its
   Jacobian, on the dense path: block 0 is out of range there (lm.h), and
   the dense fold, which would take a block of no columns, must not be
   reached; the refusal at the starting point is the solver's answer. */
static int block_without_blocks(const double *x, fe_lm_sink *s, void *ctx)
{
    const double j[1] = {1.0};
    (void)ctx;
    ck_assert_int_eq(fe_lm_emit(s, x[0] - 3.0, 1.0, j, 0, j), FE_EINVAL);
    return fe_lm_emit(s, x[0] - 3.0, 1.0, j, FE_SCHUR_NONE, NULL);
}

START_TEST(the_sink_refuses_a_negative_weight_or_a_stray_block_without_a_jacobian)
{
    fe_lm_problem p = {1, 1, 2, cost_only_edges, NULL};
    fe_lm_result r;
    double x[3] = {0.0, 0.0, 0.0}, *w = lm_work(&p, FE_LM_SCHUR);
    cost_only_evaluations = 0;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_SCHUR, NULL, x, w, NULL, NULL, &r), FE_ENOCONV);
    ck_assert_int_eq(r.stop, FE_LM_STUCK);
    ck_assert_int_gt(cost_only_evaluations, 0);
    ck_assert_int_eq(r.accepted, 0);
    ck_assert_double_eq(x[0], 0.0);
    ck_assert_double_eq(x[1], 0.0);
    ck_assert_double_eq(x[2], 0.0);
    ck_assert_double_eq(r.cost, 5.5);           /* (1/2) (3^2 + 1 + 1), the start */
    free(w);
    p = (fe_lm_problem){1, 0, 0, block_without_blocks, NULL};
    w = lm_work(&p, FE_LM_DENSE);
    x[0] = 1.0;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, NULL, x, w, NULL, NULL, &r), FE_EINVAL);
    ck_assert_double_eq(x[0], 1.0);
    free(w);
}
END_TEST

/* f = x - 3, one residual, one global. */
static int minus_three(const double *x, fe_lm_sink *s, void *ctx)
{
    const double j[1] = {1.0};
    (void)ctx;
    return fe_lm_emit(s, x[0] - 3.0, 1.0, j, FE_SCHUR_NONE, NULL);
}

/* Issue 20: the parameters at their edges (lm.h): max_iter 0 makes no
   iteration (FE_ENOCONV, x as given) and -1 is refused; lambda_min equal
   to lambda0 is taken and the next double above refused; each tolerance
   0 is taken and -DBL_TRUE_MIN refused; lambda0 the smallest positive
   double is taken and 0 refused. */
START_TEST(parameters_at_their_edges)
{
    fe_lm_problem p = {1, 0, 0, minus_three, NULL};
    fe_lm_params par;
    fe_lm_result r;
    double x[1], *w = lm_work(&p, FE_LM_DENSE);
    double *const tol[4] = {&par.xtol, &par.gtol, &par.ftol, &par.rtol};
    par = fe_lm_default_params();
    par.max_iter = -1;
    x[0] = 0.0;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_EINVAL);
    par.max_iter = 0;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_ENOCONV);
    ck_assert_int_eq(r.stop, FE_LM_MAXITER);
    ck_assert_int_eq(r.iterations, 0);
    ck_assert_double_eq(x[0], 0.0);
    ck_assert_double_eq(r.cost, 4.5);
    par.max_iter = 1;                               /* one step: 3 (1 - 1e-3 / 1.001...) */
    ck_assert_int_ne(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_EINVAL);
    ck_assert_int_eq(r.iterations, 1);
    ck_assert_double_eq_tol(x[0], 3.0, 1e-2);
    par = fe_lm_default_params();
    par.lambda_min = nextafter(par.lambda0, 1.0);
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_EINVAL);
    par.lambda_min = par.lambda0;
    x[0] = 0.0;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_OK);
    ck_assert_double_eq_tol(x[0], 3.0, 1e-12);
    for (int k = 0; k < 4; k++) {
        par = fe_lm_default_params();
        *tol[k] = -DBL_TRUE_MIN;
        ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_EINVAL);
        *tol[k] = 0.0;
        x[0] = 0.0;
        ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_OK);
        ck_assert_double_eq_tol(x[0], 3.0, 1e-9);
    }
    /* ftol at the starting cost (4.5) stops before the first step; just
       below it, the iteration runs (lm:482 of seed 4's sample made the
       test strict). */
    par = fe_lm_default_params();
    par.ftol = 4.5;
    x[0] = 0.0;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_OK);
    ck_assert_int_eq(r.stop, FE_LM_FTOL);
    ck_assert_int_eq(r.iterations, 0);
    ck_assert_double_eq(x[0], 0.0);
    par.ftol = nextafter(4.5, 0.0);
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_OK);
    ck_assert_int_eq(r.iterations, 1);      /* one step, to a cost far below ftol */
    ck_assert_int_eq(r.stop, FE_LM_FTOL);
    ck_assert_double_eq_tol(x[0], 3.0, 1e-2);
    par = fe_lm_default_params();
    par.lambda_min = 0.0;
    par.lambda0 = 0.0;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_EINVAL);
    par.lambda0 = DBL_TRUE_MIN;
    x[0] = 0.0;
    ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &par, x, w, NULL, NULL, &r), FE_OK);
    ck_assert_double_eq_tol(x[0], 3.0, 1e-12);
    free(w);
}
END_TEST

/* Issue 20: the session count at its edges from inside: one session and
   FE_SESSIONS_MAX sessions (their readings on spheres of radius 1 about
   offsets of their own, through one S = I) are fitted; 0 and one more
   are refused (emit_and_sessions_refusals_at_their_edges). */
START_TEST(one_and_the_most_sessions_are_fitted)
{
    enum { R = 20 };
    static double m[FE_SESSIONS_MAX][3 * R];
    fe_sessions c;
    fe_rng g = fe_rng_seed(64);
    memset(&c, 0, sizeof c);
    for (size_t s = 0; s < FE_SESSIONS_MAX; s++) {
        for (size_t i = 0; i < R; i++) {
            double u[3];
            fe_rng_unit_vector(&g, u);
            for (int j = 0; j < 3; j++)
                m[s][3 * i + j] = (double)(s % 4) + (double)j * (double)s / 16.0 + u[j];
        }
        c.m[s] = m[s];
        c.n[s] = R;
    }
    for (size_t count = 1; count <= FE_SESSIONS_MAX; count += FE_SESSIONS_MAX - 1) {
        double *x = malloc(fe_sessions_params(&(fe_sessions){count, {0}, {0}, 0}) * sizeof *x);
        fe_lm_result res;
        double S[3][3];
        c.count = count;
        ck_assert_int_eq(magcal_fit(&c, x, &res), FE_OK);
        fe_sessions_matrix(x, S);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                ck_assert_double_eq_tol(fabs(S[i][j]), i == j ? 1.0 : 0.0, 1e-6);
        for (size_t s = 0; s < count; s++)
            ck_assert_double_eq_tol(x[6 + 3 * s + 2], (double)(s % 4) + 2.0 * (double)s / 16.0,
                                    1e-6);
        free(x);
    }
}
END_TEST

Suite *fe_lm_suite(void)
{
    Suite *s = suite_create("lm");
    TCase *t = tcase_create("levenberg-marquardt");
    tcase_set_timeout(t, 300);
    tcase_add_test(t, rosenbrock_dense_and_schur);
    tcase_add_test(t, the_workspace_is_read_only_up_to_its_end);
    tcase_add_test(t, the_search_along_the_last_two_steps_moves_every_parameter);
    tcase_add_test(t, a_bad_method_or_no_workspace_is_refused_on_a_good_problem);
    tcase_add_test(t, linear_model_matches_normal_equations);
    tcase_add_test(t, wide_linear_model_dense_and_schur);
    tcase_add_test(t, wide_rows_with_blocks_dense_and_schur);
    tcase_add_test(t, bundle_adjustment_dense_and_schur_agree);
    tcase_add_test(t, bundle_adjustment_noisy_ends_at_the_optimum);
    tcase_add_test(t, report_table_and_stop);
    tcase_add_test(t, model_failures_are_handled);
    tcase_add_test(t, a_flat_cost_is_not_a_relative_convergence);
    tcase_add_test(t, sessions_count_their_parameters);
    tcase_add_test(t, sessions_first_step_from_a_numerical_jacobian);
    tcase_add_test(t, sessions_start_at_the_centroids);
    tcase_add_test(t, first_step_is_extended_along_its_line);
    tcase_add_test(t, a_step_already_at_its_parabolas_minimum_is_not_extended);
    tcase_add_test(t, second_step_searches_along_the_last_two);
    tcase_add_test(t, undamped_rank_test_is_relative_to_the_diagonal);
    tcase_add_test(t, magnetometer_sessions_synthetic);
    tcase_add_test(t, magnetometer_sessions_real);
    tcase_add_test(t, emit_and_sessions_refusals_at_their_edges);
    tcase_add_test(t, the_sink_refuses_a_negative_weight_or_a_stray_block_without_a_jacobian);
    tcase_add_test(t, parameters_at_their_edges);
    tcase_add_test(t, one_and_the_most_sessions_are_fitted);
    suite_add_tcase(s, t);
    return s;
}
