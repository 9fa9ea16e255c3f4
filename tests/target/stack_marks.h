/* SPDX-License-Identifier: MIT */
/*
 * The stack marks of the RTDE suites on Cortex-M (tests/target/rtde_target.c,
 * tests/lib/test_rtde_in.c): each measured function's high-water mark,
 * painted below the caller's stack pointer before the call and scanned after
 * it, the worst over its calls while `measuring` is set; stack_marks_print
 * writes them as "stack: NAME BYTES" lines for tests/target/stack.py. Off the
 * target MEASURED only calls. Included after check.h; STACK_MARKS_MAX is how
 * many functions the includer measures at most.
 */
#ifndef URRT_TESTS_STACK_MARKS_H
#define URRT_TESTS_STACK_MARKS_H

#ifdef URRT_TARGET_CORTEX_M
static struct {
    const char *name;
    unsigned bytes;
} marks[STACK_MARKS_MAX];
static unsigned mark_count;
static bool measuring;

static void note(const char *fn, uintptr_t sp, uintptr_t lowest)
{
    unsigned i;
    CHECK(lowest > target_stack_limit(), "%s reached the stack's limit", fn);
    for (i = 0; i < mark_count && !CHECK_SAME_TEXT(marks[i].name, fn); i++) {
    }
    if (i == mark_count) {
        CHECK(i < sizeof marks / sizeof marks[0], "more than %u functions", i);
        if (i == sizeof marks / sizeof marks[0]) {
            return;
        }
        marks[mark_count].name = fn;
        marks[mark_count++].bytes = 0;
    }
    if (sp - lowest > marks[i].bytes) {
        marks[i].bytes = (unsigned)(sp - lowest);
    }
}

static void stack_marks_print(void)
{
    for (unsigned i = 0; i < mark_count; i++) {
        check_printf("stack: %s %u\n", marks[i].name, marks[i].bytes);
    }
}

/* The call, its stack painted and measured while measuring. */
#define MEASURED_CALL(call, fn)                            \
    do {                                                   \
        uintptr_t sp_ = target_sp();                       \
        if (measuring) {                                   \
            target_stack_paint(sp_);                       \
        }                                                  \
        call;                                              \
        if (measuring) {                                   \
            note(#fn, sp_, target_stack_lowest_used(sp_)); \
        }                                                  \
    } while (0)
#else
#define MEASURED_CALL(call, fn) \
    do {                        \
        call;                   \
    } while (0)
#endif

/* result = fn args, or for functions without a result MEASURED_VOID(fn, args). */
#define MEASURED(result, fn, args) MEASURED_CALL(result = fn args, fn)
#define MEASURED_VOID(fn, args) MEASURED_CALL(fn args, fn)

#endif
