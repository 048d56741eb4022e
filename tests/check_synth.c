/* SPDX-License-Identifier: MIT */
/* The synthetic recordings' refusals, each at its edge: equal, just
   inside, just outside (their statistics are checked by the discovery and
   model suites, which fold them). */
#include "foldest.h"
#include "foldest/synth.h"
#include "testutil.h"

START_TEST(spec_refusals_at_their_edges)
{
    fe_synth g;
    fe_synth_spec s = fe_synth_default_spec("quadratic_drag", 3);
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
    s.rows = 100;                           /* the fewest rows taken */
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
    s.rows = 99;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_ETOOFEW);
    s = fe_synth_default_spec("quadratic_drag", 3);
    s.noise_sd = 0.0;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
    s.noise_sd = 1e-300;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
    s = fe_synth_default_spec("quadratic_drag", 3);
    s.noise_rho = 1.0;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
    s.noise_rho = 0.999;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
    s.noise_rho = 0.0;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_OK);
    s.noise_rho = -1e-9;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
    s.noise_rho = NAN;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
    s = fe_synth_default_spec("quadratic_drag", 3);
    s.effect = NULL;
    ck_assert_int_eq(fe_synth_init(&g, &s), FE_EINVAL);
    ck_assert_int_eq(fe_synth_init(NULL, &s), FE_EINVAL);
}
END_TEST

Suite *fe_synth_suite(void)
{
    Suite *s = suite_create("synth");
    TCase *t = tcase_create("core");
    tcase_add_test(t, spec_refusals_at_their_edges);
    suite_add_tcase(s, t);
    return s;
}
