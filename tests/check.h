/* SPDX-License-Identifier: MIT */
/* A minimal test harness: each CHECK counts, failures say where and why,
 * and the run ends with the line "N passed, N failed". */
#ifndef URRT_TEST_CHECK_H
#define URRT_TEST_CHECK_H

#include <stdio.h>
#include <string.h>

static unsigned check_passed, check_failed;

#define CHECK(cond, ...)                                                    \
    do {                                                                    \
        if (cond) {                                                         \
            check_passed++;                                                 \
        } else {                                                            \
            check_failed++;                                                 \
            fprintf(stderr, "%s:%d: FAIL: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                   \
            fputc('\n', stderr);                                            \
        }                                                                   \
    } while (0)

#define CHECK_EQ_INT(a, b) \
    CHECK((long long)(a) == (long long)(b), "%lld != %lld", (long long)(a), (long long)(b))

#define CHECK_EQ_STR(a, b) \
    CHECK(strcmp((a), (b)) == 0, "\"%s\" != \"%s\"", (a), (b))

/* Prints the closing line; the exit status is non-zero on any failure. */
static inline int check_report(void)
{
    printf("%u passed, %u failed\n", check_passed, check_failed);
    return check_failed == 0 ? 0 : 1;
}

#endif
