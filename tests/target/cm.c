/* SPDX-License-Identifier: MIT */
/*
 * A Cortex-M runtime for qemu's boards without a C library: vector table,
 * reset (copy .data, clear .bss), semihosting output and exit, stack
 * painting, SysTick. Thumb-1 only, so that it runs on ARMv6-M as well.
 */
#include "target.h"

extern uint32_t _estack, _sidata, _sdata, _edata, _sbss, _ebss, _stack_limit;
int main(void);
void reset_handler(void);
void fault_handler(void);

__attribute__((section(".isr_vector"), used)) static const uintptr_t vector_table[16] = {
    (uintptr_t)&_estack,      (uintptr_t)reset_handler, (uintptr_t)fault_handler, (uintptr_t)fault_handler,
    (uintptr_t)fault_handler, (uintptr_t)fault_handler, (uintptr_t)fault_handler, 0, 0, 0, 0,
    (uintptr_t)fault_handler, (uintptr_t)fault_handler, 0, (uintptr_t)fault_handler, (uintptr_t)fault_handler,
};

/* ARM semihosting: operation in r0, argument block in r1, bkpt 0xab. */
static uintptr_t semihost(uintptr_t op, const void *arg)
{
    register uintptr_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

#define SYS_OPEN 0x01u
#define SYS_WRITE0 0x04u
#define SYS_READ 0x06u
#define SYS_GET_CMDLINE 0x15u
#define SYS_EXIT_EXTENDED 0x20u
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u

void target_puts(const char *s)
{
    semihost(SYS_WRITE0, s);
}

int target_open_cmdline_file(void)
{
    static char path[256];
    uintptr_t block[3];
    size_t len = 0;
    block[0] = (uintptr_t)path;
    block[1] = sizeof path;
    if (semihost(SYS_GET_CMDLINE, block) != 0) {
        return -1;
    }
    while (len < sizeof path && path[len] != '\0') {
        len++;
    }
    block[0] = (uintptr_t)path;
    block[1] = 1; /* "rb" */
    block[2] = len;
    return (int)semihost(SYS_OPEN, block);
}

size_t target_read(int handle, void *buf, size_t n)
{
    const uintptr_t block[3] = {(uintptr_t)handle, (uintptr_t)buf, n};
    return n - semihost(SYS_READ, block); /* SYS_READ returns the bytes NOT read */
}

void target_exit(int status)
{
    /* qemu exits with the status: the test's result is the emulator's. */
    const uintptr_t block[2] = {ADP_STOPPED_APPLICATION_EXIT, (uintptr_t)status};
    semihost(SYS_EXIT_EXTENDED, block);
    for (;;) {
    }
}

void fault_handler(void)
{
    uint32_t cfsr = *(volatile uint32_t *)0xE000ED28u;
    char hex[10];
    int i;
    for (i = 0; i < 8; i++) {
        hex[i] = "0123456789abcdef"[(cfsr >> (28 - 4 * i)) & 15u];
    }
    hex[8] = '\n';
    hex[9] = '\0';
    target_puts("target: fault, CFSR 0x");
    target_puts(hex);
    target_puts("0 passed, 1 failed\n");
    target_exit(1);
}

void reset_handler(void)
{
#ifdef __ARM_FP
    /* Full access to the FPU (CP10, CP11) before any floating-point code. */
    *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");
#endif
    /* Volatile pointers: these loops must not become memcpy/memset calls. */
    volatile uint32_t *dst = &_sdata;
    const volatile uint32_t *src = &_sidata;
    while (dst < &_edata) {
        *dst++ = *src++;
    }
    for (dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0;
    }
    target_exit(main());
}

#define PAINT 0xC5A5C5A5u

uintptr_t target_stack_limit(void)
{
    return (uintptr_t)&_stack_limit;
}

void target_stack_paint(uintptr_t sp)
{
    volatile uint32_t *p = (volatile uint32_t *)target_stack_limit();
    while ((uintptr_t)p < sp) {
        *p++ = PAINT;
    }
}

uintptr_t target_stack_lowest_used(uintptr_t sp)
{
    const volatile uint32_t *p = (const volatile uint32_t *)target_stack_limit();
    while ((uintptr_t)p < sp && *p == PAINT) {
        p++;
    }
    return (uintptr_t)p;
}

void target_systick_start(void)
{
    volatile uint32_t *syst = (volatile uint32_t *)0xE000E010u;
    syst[1] = 0xFFFFFFu; /* reload */
    syst[2] = 0;         /* current */
    syst[0] = 5u;        /* enable, processor clock, no interrupt */
}
