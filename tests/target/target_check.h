/* SPDX-License-Identifier: MIT */
/*
 * What tests/check.h needs to print in images without a C library, so
 * that one test source runs on the host and on the emulated cores with the
 * same messages (tests/lib/test_co.c): check.h includes it under
 * URRT_TARGET_CORTEX_M. Its text goes out through target_puts, formatted
 * by a printf of the conversions the tests use: %d %i %u %x %X %s %c %%,
 * a 0 flag, a width, and the l, ll and z lengths.
 *
 * It also defines memcpy, memset and memcmp, which GCC requires of a
 * freestanding environment (it calls them for struct copies and
 * initialisers whatever the source says); TGT_FLAGS'
 * -fno-tree-loop-distribute-patterns keeps the loops below from becoming
 * calls to themselves. Include it in one file of an image only.
 */
#ifndef URRT_TARGET_CHECK_H
#define URRT_TARGET_CHECK_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "target.h"

void *memcpy(void *restrict dst, const void *restrict src, size_t n)
{
    uint8_t *d = dst;
    const uint8_t *s = src;
    while (n-- > 0) {
        *d++ = *s++;
    }
    return dst;
}

void *memset(void *dst, int c, size_t n)
{
    uint8_t *d = dst;
    while (n-- > 0) {
        *d++ = (uint8_t)c;
    }
    return dst;
}

int memcmp(const void *a, const void *b, size_t n)
{
    const uint8_t *x = a;
    const uint8_t *y = b;
    for (; n > 0; n--, x++, y++) {
        if (*x != *y) {
            return *x < *y ? -1 : 1;
        }
    }
    return 0;
}

/* Text out a line at a time: semihosting costs a trap per call. */
static char check_line[128];
static size_t check_line_len;

static void check_putc(char c)
{
    check_line[check_line_len++] = c;
    if (c == '\n' || check_line_len == sizeof check_line - 1u) {
        check_line[check_line_len] = '\0';
        target_puts(check_line);
        check_line_len = 0;
    }
}

static void check_put_number(uint64_t v, bool negative, unsigned base, bool upper, unsigned width, char pad)
{
    const char *digit = upper ? "0123456789ABCDEF" : "0123456789abcdef";
    char text[24];
    unsigned n = 0;
    do {
        text[n++] = digit[v % base];
        v /= base;
    } while (v != 0);
    if (negative && pad == '0') {
        check_putc('-'); /* before the zeros: "-0042" */
        width = width > 0 ? width - 1u : 0u;
    } else if (negative) {
        text[n++] = '-';
    }
    for (; width > n; width--) {
        check_putc(pad);
    }
    while (n > 0) {
        check_putc(text[--n]);
    }
}

/* An integer argument of the length the conversion names (longs: 0, 1 or 2 l's). */
static uint64_t check_arg_unsigned(va_list *ap, unsigned longs, bool size)
{
    return size ? (uint64_t)va_arg(*ap, size_t)
           : longs >= 2 ? (uint64_t)va_arg(*ap, unsigned long long)
           : longs == 1 ? (uint64_t)va_arg(*ap, unsigned long)
                        : (uint64_t)va_arg(*ap, unsigned);
}

static int64_t check_arg_signed(va_list *ap, unsigned longs, bool size)
{
    return size ? (int64_t)va_arg(*ap, ptrdiff_t)
           : longs >= 2 ? (int64_t)va_arg(*ap, long long)
           : longs == 1 ? (int64_t)va_arg(*ap, long)
                        : (int64_t)va_arg(*ap, int);
}

static void check_vprintf(const char *fmt, va_list *ap)
{
    for (; *fmt != '\0'; fmt++) {
        unsigned width = 0;
        unsigned longs = 0;
        bool size = false;
        char pad = ' ';
        if (*fmt != '%') {
            check_putc(*fmt);
            continue;
        }
        if (*++fmt == '0') {
            pad = '0';
            fmt++;
        }
        for (; *fmt >= '0' && *fmt <= '9'; fmt++) {
            width = width * 10u + (unsigned)(*fmt - '0');
        }
        for (; *fmt == 'l' || *fmt == 'z'; fmt++) {
            longs += *fmt == 'l';
            size = size || *fmt == 'z';
        }
        if (*fmt == 'd' || *fmt == 'i') {
            int64_t v = check_arg_signed(ap, longs, size);
            check_put_number(v < 0 ? 0u - (uint64_t)v : (uint64_t)v, v < 0, 10, false, width, pad);
        } else if (*fmt == 'u' || *fmt == 'x' || *fmt == 'X') {
            check_put_number(check_arg_unsigned(ap, longs, size), false, *fmt == 'u' ? 10u : 16u, *fmt == 'X',
                             width, pad);
        } else if (*fmt == 's') {
            for (const char *s = va_arg(*ap, const char *); *s != '\0'; s++) {
                check_putc(*s);
            }
        } else if (*fmt == 'c') {
            check_putc((char)va_arg(*ap, int));
        } else if (*fmt == '%') {
            check_putc('%');
        } else {
            /* A conversion this printf lacks: say so rather than misread the arguments. */
            for (const char *s = "<conversion not in tests/target/target_check.h>"; *s != '\0'; s++) {
                check_putc(*s);
            }
            return;
        }
    }
}

static void check_printf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    check_vprintf(fmt, &ap);
    va_end(ap);
}

static bool check_same_text(const char *a, const char *b)
{
    while (*a != '\0' && *a == *b) {
        a++;
        b++;
    }
    return *a == *b;
}

#endif
