/* SPDX-License-Identifier: MIT */
/*
 * alloc_shim.so: LD_PRELOADed into urrt-gateway by the tests. It counts
 * every heap allocation (malloc, calloc, realloc, posix_memalign,
 * aligned_alloc, memalign, valloc) and wraps lcm_publish to count
 * publishes and the allocations made inside lcm_publish itself.
 *
 *   ALLOC_SHIM_OUT=PATH        report file
 *   ALLOC_SHIM_WARMUP=N        publishes before the window opens
 *   ALLOC_SHIM_WINDOW=M        publishes in the window
 *   ALLOC_SHIM_FAIL_FROM=N     make publishes N .. N+COUNT-1 fail (ENOBUFS)
 *   ALLOC_SHIM_FAIL_COUNT=COUNT
 *   ALLOC_SHIM_DELAY_US=D      every publish on a channel ending in
 *   ALLOC_SHIM_DELAY_SUFFIX=S  S (default ".STATE") returns D us after the
 *                              message left: a gateway slower than its robot
 *
 * When the window closes it writes "publishes M allocs X in_publish Y
 * outside Z" to PATH: the allocations of the whole process over M
 * publishes, split into those lcm_publish made and the rest.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

extern void *__libc_malloc(size_t);
extern void *__libc_calloc(size_t, size_t);
extern void *__libc_realloc(void *, size_t);
extern void *__libc_memalign(size_t, size_t);

static uint64_t allocs, allocs_in_publish;
static __thread int in_publish;

static void count(void)
{
    __atomic_add_fetch(&allocs, 1, __ATOMIC_RELAXED);
    if (in_publish) {
        __atomic_add_fetch(&allocs_in_publish, 1, __ATOMIC_RELAXED);
    }
}

void *malloc(size_t n) { count(); return __libc_malloc(n); }
void *calloc(size_t a, size_t b) { count(); return __libc_calloc(a, b); }
void *realloc(void *p, size_t n) { count(); return __libc_realloc(p, n); }
void *memalign(size_t a, size_t n) { count(); return __libc_memalign(a, n); }
void *aligned_alloc(size_t a, size_t n) { count(); return __libc_memalign(a, n); }
void *valloc(size_t n) { count(); return __libc_memalign(4096, n); }
int posix_memalign(void **p, size_t a, size_t n)
{
    count();
    *p = __libc_memalign(a, n);
    return *p != NULL ? 0 : ENOMEM;
}

typedef struct _lcm_t lcm_t;
typedef int (*publish_fn)(lcm_t *, const char *, const void *, unsigned int);

static uint64_t publishes, warmup = UINT64_MAX, window, fail_from = UINT64_MAX, fail_count, delay_us;
static const char *delay_suffix = ".STATE";
static uint64_t start_allocs, start_in_publish;
static const char *report_path;
static int configured;

static uint64_t env_u64(const char *name, uint64_t fallback)
{
    const char *v = getenv(name);
    return v != NULL && *v != '\0' ? strtoull(v, NULL, 10) : fallback;
}

int lcm_publish(lcm_t *lcm, const char *channel, const void *data, unsigned int len)
{
    static publish_fn real;
    uint64_t n;
    int r;
    if (!configured) {
        report_path = getenv("ALLOC_SHIM_OUT");
        warmup = env_u64("ALLOC_SHIM_WARMUP", UINT64_MAX);
        window = env_u64("ALLOC_SHIM_WINDOW", 0);
        fail_from = env_u64("ALLOC_SHIM_FAIL_FROM", UINT64_MAX);
        fail_count = env_u64("ALLOC_SHIM_FAIL_COUNT", 0);
        delay_us = env_u64("ALLOC_SHIM_DELAY_US", 0);
        if (getenv("ALLOC_SHIM_DELAY_SUFFIX") != NULL) {
            delay_suffix = getenv("ALLOC_SHIM_DELAY_SUFFIX");
        }
        real = (publish_fn)dlsym(RTLD_NEXT, "lcm_publish");
        configured = 1;
    }
    n = ++publishes;
    if (n == warmup) {
        start_allocs = allocs;
        start_in_publish = allocs_in_publish;
    }
    if (n >= fail_from && n < fail_from + fail_count) {
        errno = ENOBUFS;
        r = -1;
    } else {
        in_publish++;
        r = real(lcm, channel, data, len);
        in_publish--;
    }
    /* After the send: the gateway is slow, but what it sends leaves when
     * it decided to send it (its age check just before lcm_publish). */
    if (delay_us > 0 && strlen(channel) >= strlen(delay_suffix) &&
        strcmp(channel + strlen(channel) - strlen(delay_suffix), delay_suffix) == 0) {
        struct timespec d = {(time_t)(delay_us / 1000000u), (long)(delay_us % 1000000u) * 1000};
        while (nanosleep(&d, &d) != 0) {
        }
    }
    if (warmup != UINT64_MAX && n == warmup + window && report_path != NULL) {
        uint64_t total = allocs - start_allocs, inside = allocs_in_publish - start_in_publish;
        FILE *f = fopen(report_path, "w");
        if (f != NULL) {
            fprintf(f, "publishes %llu allocs %llu in_publish %llu outside %llu\n",
                    (unsigned long long)window, (unsigned long long)total, (unsigned long long)inside,
                    (unsigned long long)(total - inside));
            fclose(f);
        }
    }
    return r;
}
