/* SPDX-License-Identifier: MIT */
/* Bad arguments to the public functions: null pointers, zero and
   oversized dimensions, mismatched shapes, out-of-range indices and
   parameters.  Each gives its documented status (FE_EINVAL, FE_ESIZE,
   FE_EMISMATCH, FE_ENONFINITE, ...) or, for the functions that return a
   number, NaN or 0 as documented; none crashes, and a bound accumulation
   passed with a bad argument is left as it was. */
#include "foldest.h"
#include "testutil.h"

START_TEST(kalman_arguments)
{
    double mem[256], mem2[256], A[2] = {1, 0}, z[1] = {1}, Z[1] = {1}, P0[4] = {1, 0, 0, 1};
    double snap[6];
    fe_kalman k, k3;
    fe_kalman_obs o = {1, A, z, Z}, bad = o;
    fe_kalman_info s, s3;
    fe_kalman_monitor m;
    fe_kalman_monitor_params mp = fe_kalman_monitor_default_params();
    fe_kalman_report r = {1, 1.0, 0.0, NULL, NULL, NULL};
    fe_kalman_model model = {NULL, NULL, NULL, 0, NULL};
    fe_kalman_track_obs to = {model, o};
    double lo, hi;

    ck_assert_uint_eq(fe_kalman_doubles(0, 1), 0);
    ck_assert_uint_eq(fe_kalman_doubles(1, 0), 0);
    ck_assert_uint_eq(fe_kalman_doubles(FE_KALMAN_MAX_DIM + 1, 1), 0);
    ck_assert_int_eq(fe_kalman_init(NULL, 2, 1, mem, 256), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_init(&k, 2, 1, NULL, 256), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_init(&k, 0, 1, mem, 256), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_init(&k, 2, 1, mem, 3), FE_ESIZE);
    ck_assert_int_eq(fe_kalman_init(&k, FE_KALMAN_MAX_DIM + 1, 1, mem, 256), FE_ESIZE);
    ck_assert_int_eq(fe_kalman_init(&k, 2, 1, mem, 256), FE_OK);
    ck_assert_int_eq(fe_kalman_init(&k3, 3, 1, mem2, 256), FE_OK);
    ck_assert_int_eq(fe_kalman_set_prior(NULL, NULL, P0), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_set_prior(&k, NULL, NULL), FE_EINVAL);
    {
        double nanP[4] = {1, 0, 0, NAN}, negP[4] = {-1, 0, 0, 1}, x0[2] = {INFINITY, 0};
        ck_assert_int_eq(fe_kalman_set_prior(&k, NULL, nanP), FE_ENONFINITE);
        ck_assert_int_eq(fe_kalman_set_prior(&k, NULL, negP), FE_ENOTPD);
        ck_assert_int_eq(fe_kalman_set_prior(&k, x0, P0), FE_ENONFINITE);
        ck_assert_int_eq(fe_kalman_set_prior_scaled(&k, x0, 1.0), FE_ENONFINITE);
    }
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&k, NULL, -1.0), FE_ENOTPD);  /* a negative variance */
    ck_assert_int_eq(fe_kalman_set_prior_scaled(&k, NULL, NAN), FE_ENONFINITE);
    ck_assert_int_eq(fe_kalman_set_prior(&k, NULL, P0), FE_OK);
    ck_assert(isnan(fe_kalman_sigma(&k, 2)));
    ck_assert(isnan(fe_kalman_sigma(NULL, 0)));
    ck_assert_double_eq(fe_kalman_sigma(&k, 1), 1.0);
    ck_assert_int_eq(fe_kalman_copy(&k3, &k), FE_EMISMATCH);
    ck_assert_int_eq(fe_kalman_copy(NULL, &k), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_copy(&k, &k), FE_OK);
    memcpy(snap, k.x, 2 * sizeof *snap);
    memcpy(snap + 2, k.P, 4 * sizeof *snap);
    /* Bad packets: each refused, the filter unchanged. */
    for (int fast = 0; fast < 2; fast++) {
        int (*upd)(fe_kalman *, const fe_kalman_obs *, fe_kalman_report *) =
            fast ? fe_kalman_update_fast : fe_kalman_update;
        ck_assert_int_eq(upd(NULL, &o, NULL), FE_EINVAL);
        ck_assert_int_eq(upd(&k, NULL, NULL), FE_EINVAL);
        bad = o, bad.b = 0;
        ck_assert_int_eq(upd(&k, &bad, NULL), FE_EINVAL);
        bad = o, bad.b = 2;
        ck_assert_int_eq(upd(&k, &bad, NULL), FE_ESIZE);
        bad = o, bad.A = NULL;
        ck_assert_int_eq(upd(&k, &bad, NULL), FE_EINVAL);
        bad = o, bad.z = NULL;
        ck_assert_int_eq(upd(&k, &bad, NULL), FE_EINVAL);
        bad = o, bad.Z = NULL;
        ck_assert_int_eq(upd(&k, &bad, NULL), FE_EINVAL);
        {
            double nz = NAN, nZ = -1;
            bad = o, bad.z = &nz;
            ck_assert_int_eq(upd(&k, &bad, &r), FE_ENONFINITE);
            bad = o, bad.Z = &nZ;
            ck_assert_int_ne(upd(&k, &bad, &r), FE_OK);
        }
        ck_assert(memcmp(snap, k.x, 2 * sizeof *snap) == 0);
        ck_assert(memcmp(snap + 2, k.P, 4 * sizeof *snap) == 0);
    }
    ck_assert_int_eq(fe_kalman_predict(&k, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_predict(NULL, &model), FE_EINVAL);
    {
        double Phi[4] = {1, NAN, 0, 1};
        fe_kalman_model bm = model;
        bm.Phi = Phi;
        ck_assert_int_eq(fe_kalman_predict(&k, &bm), FE_ENONFINITE);
        bm = model;
        bm.m = FE_KALMAN_MAX_DIM + 1;
        ck_assert_int_ne(fe_kalman_predict(&k, &bm), FE_OK);
    }
    ck_assert_int_eq(fe_kalman_track(&k, NULL, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_track_fast(&k, NULL, NULL), FE_EINVAL);
    to.obs.b = 0;
    ck_assert_int_eq(fe_kalman_track(&k, &to, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_track_fast(&k, &to, NULL), FE_EINVAL);
    ck_assert(memcmp(snap, k.x, 2 * sizeof *snap) == 0);
    /* Information form. */
    ck_assert_uint_eq(fe_kalman_info_doubles(0, 1), 0);
    ck_assert_int_eq(fe_kalman_info_init(NULL, 2, 1, mem2, 256), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_info_init(&s, 2, 1, mem2, 2), FE_ESIZE);
    ck_assert_int_eq(fe_kalman_info_init(&s, 2, 1, mem2, 128), FE_OK);
    ck_assert_int_eq(fe_kalman_info_init(&s3, 3, 1, mem2 + 128, 128), FE_OK);
    ck_assert_int_eq(fe_kalman_info_set_prior(NULL, NULL, P0), FE_EINVAL);
    {
        double notpd[4] = {1, 2, 2, 1};
        ck_assert_int_eq(fe_kalman_info_set_prior(&s, NULL, notpd), FE_ENOTPD);
    }
    ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s, NULL, 0.0), FE_ENOTPD);
    ck_assert_int_ne(fe_kalman_info_set_prior_scaled(&s, NULL, NAN), FE_OK);
    ck_assert_int_eq(fe_kalman_info_update(NULL, &o), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_info_update(&s, NULL), FE_EINVAL);
    bad = o, bad.b = 2;
    ck_assert_int_eq(fe_kalman_info_update(&s, &bad), FE_ESIZE);
    ck_assert_int_eq(fe_kalman_info_merge(&s, &s3), FE_EMISMATCH);
    ck_assert_int_eq(fe_kalman_info_merge(NULL, &s3), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_info_copy(&s, &s3), FE_EMISMATCH);
    ck_assert_int_eq(fe_kalman_info_copy(&s, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_info_to_kalman(&s, &k3), FE_EMISMATCH);
    ck_assert_int_eq(fe_kalman_info_to_kalman(NULL, &k), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_info_to_kalman(&s, &k), FE_ENOTPD);      /* no information yet */
    /* The monitor. */
    ck_assert_int_eq(fe_kalman_monitor_init(NULL, NULL), FE_EINVAL);
    mp.lags = FE_KALMAN_MONITOR_LAGS + 1;
    ck_assert_int_eq(fe_kalman_monitor_init(&m, &mp), FE_EINVAL);
    mp = fe_kalman_monitor_default_params();
    mp.scale_up = 0.5;
    ck_assert_int_eq(fe_kalman_monitor_init(&m, &mp), FE_EINVAL);
    mp = fe_kalman_monitor_default_params();
    mp.threshold = -1;
    ck_assert_int_eq(fe_kalman_monitor_init(&m, &mp), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_monitor_init(&m, NULL), FE_OK);
    ck_assert_int_eq(fe_kalman_monitor_add(&m, NULL), FE_EINVAL);
    r.b = 0;
    ck_assert_int_eq(fe_kalman_monitor_add(&m, &r), FE_EINVAL);
    r.b = 1, r.nis = NAN;
    ck_assert_int_eq(fe_kalman_monitor_add(&m, &r), FE_ENONFINITE);
    r.nis = -1;
    ck_assert_int_ne(fe_kalman_monitor_add(&m, &r), FE_OK);
    ck_assert_uint_eq(m.steps, 0);
    ck_assert_double_eq(fe_kalman_monitor_mean_nis(&m), 0.0);
    ck_assert_int_eq(fe_kalman_monitor_nis_band(&m, 0.95, &lo, &hi), FE_ETOOFEW);
    ck_assert_int_eq(fe_kalman_monitor_nis_band(&m, 1.5, &lo, &hi), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_monitor_nis_band(NULL, 0.5, &lo, &hi), FE_EINVAL);
    ck_assert(isnan(fe_kalman_monitor_autocorr(&m, 0, NULL)));
    ck_assert(isnan(fe_kalman_monitor_autocorr(&m, 99, NULL)));
}
END_TEST

START_TEST(least_squares_arguments)
{
    double g[16], g2[9], j[3] = {1, 2, 3}, x[3], work[16], sw[64], score[3];
    size_t idx[2] = {0, 0}, cols[2] = {0, 0}, bigcol[1] = {7};
    fe_lsq a, b;
    ck_assert_int_eq(fe_lsq_init(NULL, 3, g), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_init(&a, 3, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_init(&a, 3, g), FE_OK);
    ck_assert_int_eq(fe_lsq_init(&b, 2, g2), FE_OK);
    ck_assert_int_eq(fe_lsq_reset(NULL), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add(NULL, j, 1, 1), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add(&a, NULL, 1, 1), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add(&a, j, 1, -1), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add(&a, j, NAN, 1), FE_ENONFINITE);
    ck_assert_int_eq(fe_lsq_add(&a, j, 1, INFINITY), FE_ENONFINITE);
    ck_assert_int_eq(fe_lsq_add_sparse(&a, idx, j, 2, 1, 1), FE_EINVAL);      /* repeated */
    idx[1] = 5;
    ck_assert_int_eq(fe_lsq_add_sparse(&a, idx, j, 2, 1, 1), FE_EINVAL);      /* out of range */
    ck_assert_int_eq(fe_lsq_add_sparse(NULL, idx, j, 2, 1, 1), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_add_rows(&a, NULL, 3, j, NULL, 1, NULL), FE_EINVAL);
    ck_assert_uint_eq(a.n, 0);
    ck_assert_int_eq(fe_lsq_merge(&a, &b), FE_EMISMATCH);
    ck_assert_int_eq(fe_lsq_merge(NULL, &b), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_copy(&a, &b), FE_EMISMATCH);
    ck_assert_int_eq(fe_lsq_copy(NULL, &b), FE_EINVAL);
    ck_assert_double_eq(fe_lsq_gram(&a, 9, 0), 0.0);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, 2, x, NULL, NULL, work), FE_ETOOFEW);
    ck_assert_int_eq(fe_lsq_add(&a, j, 1, 1), FE_OK);
    ck_assert_int_eq(fe_lsq_solve(NULL, NULL, 1, x, NULL, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, 0, x, NULL, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, 4, x, NULL, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_solve(&a, cols, 2, x, NULL, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_solve(&a, bigcol, 1, x, NULL, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_solve(&a, NULL, 1, x, NULL, x, work), FE_ETOOFEW);  /* cov, n <= q */
    ck_assert_int_eq(fe_lsq_scores(&a, cols, 2, cols, 1, score, NULL, NULL, sw), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_scores(&a, NULL, 0, bigcol, 1, score, NULL, NULL, sw), FE_EINVAL);
    ck_assert_int_eq(fe_lsq_scores(NULL, NULL, 0, cols, 1, score, NULL, NULL, sw), FE_EINVAL);
}
END_TEST

START_TEST(schur_and_lm_arguments)
{
    double mem[128], mem2[128], jg[2] = {1, 1}, jl[2] = {1, 1}, x[8], work[64];
    fe_schur a, b;
    ck_assert_int_eq(fe_schur_init(NULL, 1, 1, 1, mem), FE_EINVAL);
    ck_assert_int_eq(fe_schur_init(&a, 0, 0, 1, mem), FE_EINVAL);
    ck_assert_int_eq(fe_schur_init(&a, 1, 1, 1, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_schur_init(&a, 2, 2, 2, mem), FE_OK);
    ck_assert_int_eq(fe_schur_init(&b, 1, 2, 2, mem2), FE_OK);
    ck_assert_int_eq(fe_schur_reset(NULL), FE_EINVAL);
    ck_assert_int_eq(fe_schur_add(NULL, jg, 0, jl, 1, 1), FE_EINVAL);
    ck_assert_int_eq(fe_schur_add(&a, NULL, 0, jl, 1, 1), FE_EINVAL);
    ck_assert_int_eq(fe_schur_add(&a, jg, 2, jl, 1, 1), FE_EINVAL);
    ck_assert_int_eq(fe_schur_add(&a, jg, 0, NULL, 1, 1), FE_EINVAL);
    ck_assert_int_eq(fe_schur_add(&a, jg, 0, jl, 1, -1), FE_EINVAL);
    ck_assert_int_eq(fe_schur_add(&a, jg, 0, jl, NAN, 1), FE_ENONFINITE);
    ck_assert_int_eq(fe_schur_merge(&a, &b), FE_EMISMATCH);
    ck_assert_int_eq(fe_schur_merge(NULL, &b), FE_EINVAL);
    ck_assert_int_eq(fe_schur_copy(&a, &b), FE_EMISMATCH);
    ck_assert_int_eq(fe_schur_copy(&a, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_schur_solve(&a, 0.0, x, NULL, work), FE_ETOOFEW);
    ck_assert_int_eq(fe_schur_add(&a, jg, 0, jl, 1, 1), FE_OK);
    ck_assert_int_eq(fe_schur_solve(&a, -1.0, x, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_schur_solve(&a, NAN, x, NULL, work), FE_EINVAL);
    ck_assert_int_eq(fe_schur_solve(NULL, 0.0, x, NULL, work), FE_EINVAL);
    {
        fe_lm_problem p = {0, 0, 0, NULL, NULL};
        fe_lm_params bad = fe_lm_default_params();
        ck_assert_uint_eq(fe_lm_work(&p, 7), 0);
        ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, NULL, x, work, NULL, NULL, NULL), FE_EINVAL);
        ck_assert_int_eq(fe_lm_solve(NULL, FE_LM_DENSE, NULL, x, work, NULL, NULL, NULL), FE_EINVAL);
        /* A problem without a model is refused whatever the parameters
           (max_iter = 0 is taken with a model: parameters_at_their_edges
           in check_lm). */
        bad.max_iter = 0;
        p.ng = 1;
        ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &bad, x, work, NULL, NULL, NULL), FE_EINVAL);
        bad = fe_lm_default_params();
        ck_assert_int_eq(fe_lm_solve(&p, FE_LM_DENSE, &bad, x, work, NULL, NULL, NULL), FE_EINVAL);
        ck_assert_int_eq(fe_lm_emit(NULL, 1, 1, jg, FE_SCHUR_NONE, NULL), FE_EINVAL);
    }
}
END_TEST

static int count_to_three(void *obs, size_t index, void *ctx)
{
    (void)ctx;
    if (index >= 3)
        return FE_END;
    *(double *)obs = (double)index;
    return FE_OK;
}

START_TEST(fold_stream_and_csv_arguments)
{
    fe_accumulator mv = fe_meanvar_accumulator(), noinit = mv;
    fe_meanvar a = FE_MEANVAR_EMPTY, b = FE_MEANVAR_EMPTY;
    double z[3] = {1, 2, 3}, out[8 * 4];
    fe_source src;
    fe_array_source as;
    fe_generator_source gs;
    fe_fd_source fs;
    char buf[16];
    int state = 0;
    ck_assert_int_eq(fe_init(NULL, &a), FE_EINVAL);
    ck_assert_int_eq(fe_init(&mv, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_step(&mv, &a, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_fold(&mv, &a, NULL, 3, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_fold(NULL, &a, z, 3, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_scan(&mv, &a, z, 3, NULL, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_scan_visit(&mv, &a, z, 3, NULL, NULL, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_merge(&mv, &a, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_copy(&mv, NULL, &b), FE_EINVAL);
    noinit.merge = NULL;
    ck_assert_int_eq(fe_merge(&noinit, &a, &b), FE_ENOTSUP);
    noinit = mv;
    noinit.step = NULL;
    ck_assert_int_eq(fe_step(&noinit, &a, z), FE_EINVAL);
    ck_assert_uint_eq(a.n, 0);
    ck_assert_int_eq(fe_source_from_array(NULL, &as, z, 3, sizeof *z), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_array(&src, &as, NULL, 3, sizeof *z), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_array(&src, &as, z, 3, 0), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_generator(NULL, &gs, count_to_three, &state, out, sizeof *z), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_generator(&src, &gs, NULL, &state, out, sizeof *z), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_fd(&src, &fs, -1, sizeof *z, buf, sizeof buf), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_fd(&src, &fs, 0, sizeof *z, buf, 4), FE_EINVAL);
    ck_assert_int_eq(fe_source_next(NULL, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_source_rewind(NULL), FE_EINVAL);
    ck_assert_int_eq(fe_fold_source(&mv, &a, NULL, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_scan_source(&mv, &a, NULL, NULL, NULL, NULL), FE_EINVAL);
    ck_assert_int_eq(fe_source_from_generator(&src, &gs, count_to_three, &state, out, sizeof *z), FE_OK);
    ck_assert_int_eq(fe_fold_source(&mv, &a, &src, NULL), FE_OK);
    ck_assert_uint_eq(a.n, 3);
    /* CSV. */
    {
        fe_csv_reader r;
        fe_csv_field f = {NULL, 1};
        char *line;
        size_t len, count;
        double v;
        ck_assert_int_eq(fe_csv_reader_init(NULL, 0, buf, sizeof buf), FE_EINVAL);
        ck_assert_int_eq(fe_csv_reader_init(&r, -1, buf, sizeof buf), FE_EINVAL);
        ck_assert_int_eq(fe_csv_reader_init(&r, 0, buf, 1), FE_EINVAL);
        ck_assert_int_eq(fe_csv_next_line(NULL, &line, &len), FE_EINVAL);
        ck_assert_int_eq(fe_csv_split(NULL, ',', NULL, 0, &count, NULL), FE_EINVAL);
        ck_assert_int_eq(fe_csv_split(buf, ',', NULL, 3, &count, NULL), FE_EINVAL);
        ck_assert_int_eq(fe_csv_number(&f, &v), FE_EINVAL);
        ck_assert_int_eq(fe_csv_number(NULL, &v), FE_EINVAL);
    }
}
END_TEST

START_TEST(special_function_domains)
{
    /* Outside their domains the special functions return NaN, never a
       plausible number. */
    ck_assert(isnan(fe_log_gamma(-1.0)));
    ck_assert(isnan(fe_gamma_p(-1.0, 1.0)));
    ck_assert(isnan(fe_gamma_q(1.0, -1.0)));
    ck_assert(isnan(fe_beta_inc(-1.0, 1.0, 0.5)));
    ck_assert(isnan(fe_beta_inc(1.0, 1.0, 1.5)));
    ck_assert(isnan(fe_student_t_two_sided(1.0, 0.0)));
    ck_assert(isnan(fe_student_t_quantile(1.5, 3.0)));
    ck_assert(isnan(fe_f_upper(1.0, -1.0, 2.0)));
    ck_assert(isnan(fe_chi2_upper(1.0, 0.0)));
    ck_assert(isnan(fe_normal_quantile(0.0)));
    ck_assert(isnan(fe_chi2_quantile(0.5, -1.0)));
    ck_assert(isnan(fe_gamma_p(NAN, 1.0)));
    ck_assert_double_eq(fe_gamma_p(2.0, 0.0), 0.0);
    ck_assert_double_eq(fe_chi2_upper(0.0, 3.0), 1.0);
    ck_assert_double_eq(fe_beta_inc(2.0, 3.0, 0.0), 0.0);
    ck_assert_double_eq(fe_beta_inc(2.0, 3.0, 1.0), 1.0);
}
END_TEST

/* Codes of the newer modules at their edges: a catalog takes user terms
   up to FE_DISCOVER_MAX_GROUPS in all and refuses the next, unchanged; a
   region is described only into a buffer; an information filter refuses
   a packet with a NaN, unchanged. */
START_TEST(catalog_region_and_information_codes)
{
    static char names[FE_DISCOVER_MAX_GROUPS][24];
    fe_catalog_scale scale = {0, 0, 0, 0, 0, 0};
    fe_catalog c;
    fe_expr e;
    fe_located l;
    char words[64];
    double mem[128], snap[6], A[2] = {1, 0}, z[1] = {NAN}, Z[1] = {1};
    fe_kalman_obs o = {1, A, z, Z};
    fe_kalman_info s;
    size_t i = 0;
    ck_assert_int_eq(fe_catalog_init(&c, 0, &scale), FE_OK);
    ck_assert_int_eq(fe_expr_compile(&e, "1", NULL, 0, NULL, NULL, 0), FE_OK);
    while (c.count < FE_DISCOVER_MAX_GROUPS) {
        snprintf(names[i], sizeof names[i], "u%zu", i);
        ck_assert_int_eq(fe_catalog_add_expr(&c, names[i], NULL, &e), FE_OK);
        i++;
    }
    ck_assert_int_eq(fe_catalog_add_expr(&c, "extra", NULL, &e), FE_ESIZE);
    ck_assert_uint_eq(c.count, FE_DISCOVER_MAX_GROUPS);
    memset(&l, 0, sizeof l);
    ck_assert_int_eq(fe_region_describe(NULL, words, sizeof words), FE_EINVAL);
    ck_assert_int_eq(fe_region_describe(&l, NULL, sizeof words), FE_EINVAL);
    ck_assert_int_eq(fe_kalman_info_init(&s, 2, 1, mem, 128), FE_OK);
    ck_assert_int_eq(fe_kalman_info_set_prior_scaled(&s, NULL, 1.0), FE_OK);
    memcpy(snap, s.eta, 2 * sizeof *snap);
    memcpy(snap + 2, s.Lambda, 4 * sizeof *snap);
    ck_assert_int_eq(fe_kalman_info_update(&s, &o), FE_ENONFINITE);
    ck_assert(memcmp(snap, s.eta, 2 * sizeof *snap) == 0);
    ck_assert(memcmp(snap + 2, s.Lambda, 4 * sizeof *snap) == 0);
    ck_assert_uint_eq(s.count, 0);
    z[0] = 2.0;
    ck_assert_int_eq(fe_kalman_info_update(&s, &o), FE_OK);
    ck_assert_uint_eq(s.count, 1);
}
END_TEST

Suite *fe_arguments_suite(void)
{
    Suite *s = suite_create("arguments");
    TCase *t = tcase_create("bad");
    tcase_add_test(t, kalman_arguments);
    tcase_add_test(t, least_squares_arguments);
    tcase_add_test(t, schur_and_lm_arguments);
    tcase_add_test(t, fold_stream_and_csv_arguments);
    tcase_add_test(t, special_function_domains);
    tcase_add_test(t, catalog_region_and_information_codes);
    suite_add_tcase(s, t);
    return s;
}
