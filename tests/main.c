/* SPDX-License-Identifier: MIT */
/* The one test runner: every tests/check_<module>.c defines
   `Suite *fe_<module>_suite(void)`; the Makefile lists them in suites.h. */
#include <check.h>
#include <stdlib.h>

#define FE_SUITE(name) Suite *name(void);
#include "suites.h"
#undef FE_SUITE

int main(void)
{
    SRunner *sr = srunner_create(NULL);
    int failed;
#define FE_SUITE(name) srunner_add_suite(sr, name());
#include "suites.h"
#undef FE_SUITE
    srunner_run_all(sr, CK_NORMAL);
    failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
