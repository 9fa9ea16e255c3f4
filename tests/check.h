/* SPDX-License-Identifier: MIT */
/* A minimal test harness: each CHECK counts, failures say where and why,
 * and the run ends with the line "N passed, N failed". On the host the
 * failures go to stderr and the closing line to stdout; in the bare-metal
 * images of tests/target (URRT_TARGET_CORTEX_M) both go out through
 * target_check.h's printf, so one test source runs in both places. */
#ifndef URRT_TEST_CHECK_H
#define URRT_TEST_CHECK_H

#ifdef URRT_TARGET_CORTEX_M
#include "target_check.h"
#define CHECK_FAIL_PRINTF check_printf
#define CHECK_FAIL_END() check_putc('\n')
#define CHECK_REPORT_PRINTF check_printf
#define CHECK_SAME_TEXT(a, b) check_same_text((a), (b))
#else
#include <stdio.h>
#include <string.h>
#define CHECK_FAIL_PRINTF(...) fprintf(stderr, __VA_ARGS__)
#define CHECK_FAIL_END() fputc('\n', stderr)
#define CHECK_REPORT_PRINTF printf
#define CHECK_SAME_TEXT(a, b) (strcmp((a), (b)) == 0)
#endif

static unsigned check_passed, check_failed;

#define CHECK(cond, ...)                                                        \
    do {                                                                        \
        if (cond) {                                                             \
            check_passed++;                                                     \
        } else {                                                                \
            check_failed++;                                                     \
            CHECK_FAIL_PRINTF("%s:%d: FAIL: %s: ", __FILE__, __LINE__, #cond);  \
            CHECK_FAIL_PRINTF(__VA_ARGS__);                                     \
            CHECK_FAIL_END();                                                   \
        }                                                                       \
    } while (0)

#define CHECK_EQ_INT(a, b) \
    CHECK((long long)(a) == (long long)(b), "%lld != %lld", (long long)(a), (long long)(b))

#define CHECK_EQ_STR(a, b) CHECK(CHECK_SAME_TEXT((a), (b)), "\"%s\" != \"%s\"", (a), (b))

/* Prints the closing line; the exit status is non-zero on any failure. */
static inline int check_report(void)
{
    CHECK_REPORT_PRINTF("%u passed, %u failed\n", check_passed, check_failed);
    return check_failed == 0 ? 0 : 1;
}

#endif
