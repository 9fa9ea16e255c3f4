/* SPDX-License-Identifier: MIT */
/*
 * What the target drivers (test_target.c, bench_target.c) need from the
 * machine they run on, without a C library: text out, an exit status, and on
 * Cortex-M the stack and a cycle counter. cm.c implements it with semihosting
 * on qemu's Cortex-M boards, linux_start.c with Linux system calls for
 * freestanding big-endian images under qemu-user.
 */
#ifndef URRT_TARGET_H
#define URRT_TARGET_H

#include <stddef.h>
#include <stdint.h>

void target_puts(const char *s);
__attribute__((noreturn)) void target_exit(int status);

/* A number in decimal, without a C library's printf. */
static inline void target_put_uint(uint64_t v)
{
    char text[24];
    int i = 23;
    text[i] = '\0';
    do {
        text[--i] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v != 0);
    target_puts(text + i);
}

#ifdef URRT_TARGET_CORTEX_M
/* The stack: [target_stack_limit(), initial SP). */
uintptr_t target_stack_limit(void);
/* Fill the stack below sp with a pattern; the lowest changed word after a
 * call is its high-water mark. Uses no stack itself. */
void target_stack_paint(uintptr_t sp);
uintptr_t target_stack_lowest_used(uintptr_t sp);
/* The host file qemu's `-semihosting-config ...,arg=PATH` names, opened for
 * reading (a handle, or -1), and up to n bytes of it (0 at its end). */
int target_open_cmdline_file(void);
size_t target_read(int handle, void *buf, size_t n);
/* SysTick, counting down from 0xFFFFFF at the core clock. */
void target_systick_start(void);
static inline uint32_t target_systick(void)
{
    return *(volatile uint32_t *)0xE000E018u;
}
static inline __attribute__((always_inline)) uintptr_t target_sp(void)
{
    uintptr_t sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    return sp;
}
#endif

#endif
