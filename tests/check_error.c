/* SPDX-License-Identifier: MIT */
/* Status codes: every code has its own message; unknown codes are safe. */
#include "foldest.h"
#include "testutil.h"

START_TEST(every_code_has_a_distinct_message)
{
    for (int i = 0; i < FE_STATUS_COUNT; i++) {
        const char *m = fe_strerror(i);
        ck_assert_ptr_nonnull(m);
        ck_assert_str_ne(m, "unknown foldest status");
        for (int j = 0; j < i; j++)
            ck_assert_str_ne(m, fe_strerror(j));
    }
    ck_assert_int_eq(FE_OK, 0);
    /* The first and last codes are inside the table's bounds. */
    ck_assert_str_eq(fe_strerror(FE_OK), "success");
    ck_assert_str_eq(fe_strerror(FE_STATUS_COUNT - 1), fe_strerror(FE_EINTERNAL));
}
END_TEST

START_TEST(unknown_codes)
{
    ck_assert_str_eq(fe_strerror(-1), "unknown foldest status");
    ck_assert_str_eq(fe_strerror(FE_STATUS_COUNT), "unknown foldest status");
    ck_assert_str_eq(fe_strerror(1 << 30), "unknown foldest status");
}
END_TEST

Suite *fe_error_suite(void)
{
    Suite *s = suite_create("error");
    TCase *t = tcase_create("core");
    tcase_add_test(t, every_code_has_a_distinct_message);
    tcase_add_test(t, unknown_codes);
    suite_add_tcase(s, t);
    return s;
}
