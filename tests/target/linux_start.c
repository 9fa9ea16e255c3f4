/* SPDX-License-Identifier: MIT */
/*
 * target.h for freestanding Linux images (no C library exists for armeb or
 * aarch64_be in Debian): _start calls main and exits with its status; text
 * goes out with the write system call. Run under qemu-armeb / qemu-aarch64_be.
 */
#include "target.h"

int main(void);

#if defined(__aarch64__)
__asm__(".global _start\n_start:\n\tbl main\n\tmov x8, #93\n\tsvc #0\n");

static long sys3(long nr, long a, long b, long c)
{
    register long x8 __asm__("x8") = nr;
    register long x0 __asm__("x0") = a;
    register long x1 __asm__("x1") = b;
    register long x2 __asm__("x2") = c;
    __asm__ volatile("svc #0" : "+r"(x0) : "r"(x8), "r"(x1), "r"(x2) : "memory");
    return x0;
}
#define SYS_WRITE 64
#define SYS_EXIT 93
#elif defined(__arm__)
__asm__(".global _start\n_start:\n\tbl main\n\tmov r7, #1\n\tsvc #0\n");

static long sys3(long nr, long a, long b, long c)
{
    register long r7 __asm__("r7") = nr;
    register long r0 __asm__("r0") = a;
    register long r1 __asm__("r1") = b;
    register long r2 __asm__("r2") = c;
    __asm__ volatile("svc #0" : "+r"(r0) : "r"(r7), "r"(r1), "r"(r2) : "memory");
    return r0;
}
#define SYS_WRITE 4
#define SYS_EXIT 1
#else
#error "linux_start.c: AArch64 or ARM only"
#endif

void target_puts(const char *s)
{
    long n = 0;
    while (s[n] != '\0') {
        n++;
    }
    sys3(SYS_WRITE, 1, (long)s, n);
}

void target_exit(int status)
{
    for (;;) {
        sys3(SYS_EXIT, status, 0, 0);
    }
}
