/* SPDX-License-Identifier: MIT */
/*
 * Benchmark of lib/ (make bench): nanoseconds per packet, each beside floors
 * measured in the same run, and the ratios to them. The decode's floors, in
 * the order docs/performance.md gives them: the copy floor (what the decode
 * cannot avoid: the packet's doubles byte-swapped into a urrt_state-sized
 * buffer and the rest of it set, in the widest vectors the CPU has), the
 * store floor (a memset of a urrt_state: the bytes the decode must write
 * whatever it reads), the plain byte-swap loop, and memcpy of the packet's
 * bytes (context only: it moves with the memory layout); at every length of
 * lib's controller table. Never a test: it prints `name: value` lines and
 * asserts nothing.
 *
 * Each ns figure is the best of several batches (the least disturbed by the
 * rest of the machine); the subject and its baseline alternate batch by
 * batch so that both see the same conditions, and the ratio is the median of
 * the per-batch ratios. Results are kept alive with a compiler barrier on
 * the output memory and a checksum written to a volatile, so no work can be
 * optimised away; lib/ is a separate translation unit in a static library,
 * so its calls cannot be elided either.
 */
#define _POSIX_C_SOURCE 200809L
#include "urrt.h"
#include "urrt_rtde.h"

/* Names a second build's figures apart ("edge_"), see tests/lib/lib.mk. */
#ifndef URRT_BENCH_PREFIX
#define URRT_BENCH_PREFIX ""
#endif

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define BATCHES 41
#define BATCH_NS 2000000.0 /* about 2 ms per batch: a pair of batches then mostly sees one machine state */
#define STREAM_PACKETS 59   /* 59 x 1116 bytes: just over 64 KiB */

/* Tells the compiler that memory at p is read: stores to it must happen. */
#define USE(p) __asm__ volatile("" : : "r"(p) : "memory")

static volatile uint64_t checksum;

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

/* Runs about `iterations` units of work and returns how many it did. */
typedef size_t (*bench_fn)(void *ctx, size_t iterations);

/* Iterations that take about BATCH_NS. */
static size_t calibrate(bench_fn fn, void *ctx)
{
    size_t n = 16;
    for (;;) {
        double t0 = now_ns();
        size_t done = fn(ctx, n);
        double dt = (now_ns() - t0) * (double)n / (double)done;
        if (dt > BATCH_NS / 4 || n > ((size_t)1 << 30)) {
            return (size_t)((double)n * BATCH_NS / (dt > 1 ? dt : 1)) + 1;
        }
        n *= 4;
    }
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Best ns per iteration of subject and baseline, batches interleaved, and
 * the median of the per-batch ratios (a pair of neighbouring batches sees
 * the same machine, so the ratio is steadier than either figure). */
static void measure(bench_fn subject, void *sctx, bench_fn baseline, void *bctx, double *s_ns, double *b_ns,
                    double *ratio)
{
    size_t ns = calibrate(subject, sctx), nb = calibrate(baseline, bctx);
    double ratios[BATCHES];
    *s_ns = *b_ns = 1e300;
    for (int i = 0; i < BATCHES; i++) {
        double t0 = now_ns();
        size_t ds = subject(sctx, ns);
        double t1 = now_ns();
        size_t db = baseline(bctx, nb);
        double t2 = now_ns();
        if ((t1 - t0) / (double)ds < *s_ns) *s_ns = (t1 - t0) / (double)ds;
        if ((t2 - t1) / (double)db < *b_ns) *b_ns = (t2 - t1) / (double)db;
        ratios[i] = ((t1 - t0) / (double)ds) / ((t2 - t1) / (double)db);
    }
    qsort(ratios, BATCHES, sizeof ratios[0], compare_doubles);
    *ratio = ratios[BATCHES / 2];
}

/* The subject against the faster of two floors, all three interleaved: the
 * ratio is the median of the per-batch ratios to the faster floor of that
 * batch; f_ns[k] is floor k's best. */
static void measure_min(bench_fn subject, void *sctx, bench_fn floor0, void *f0ctx, bench_fn floor1, void *f1ctx,
                        double *s_ns, double f_ns[2], double *ratio)
{
    bench_fn floors[2] = {floor0, floor1};
    void *fctx[2] = {f0ctx, f1ctx};
    size_t ns = calibrate(subject, sctx), nf[2] = {calibrate(floor0, f0ctx), calibrate(floor1, f1ctx)};
    double ratios[BATCHES];
    *s_ns = f_ns[0] = f_ns[1] = 1e300;
    for (int i = 0; i < BATCHES; i++) {
        double t0 = now_ns();
        size_t ds = subject(sctx, ns);
        double s = (now_ns() - t0) / (double)ds, f = 1e300;
        /* alternate which floor runs next to the subject */
        for (int k = 0; k < 2; k++) {
            int j = (i + k) & 1;
            double t1 = now_ns();
            size_t df = floors[j](fctx[j], nf[j]);
            double t = (now_ns() - t1) / (double)df;
            if (t < f_ns[j]) f_ns[j] = t;
            if (t < f) f = t;
        }
        if (s < *s_ns) *s_ns = s;
        ratios[i] = s / f;
    }
    qsort(ratios, BATCHES, sizeof ratios[0], compare_doubles);
    *ratio = ratios[BATCHES / 2];
}

/* ---- subjects ------------------------------------------------------------- */

#define VARIANTS 8 /* distinct packets, so that no result is the same twice */
#define STRIDE 1280  /* bytes between variants: a multiple of 64, more than any packet + 4 */

/* bytes[v] is variant v, `offset` bytes past a 64-byte boundary. */
typedef struct packets {
    uint8_t storage[VARIANTS * STRIDE + 64] __attribute__((aligned(64)));
    const uint8_t *bytes[VARIANTS];
    size_t length;
} packets;

static uint8_t copy_target[1 << 17] __attribute__((aligned(64)));

static size_t bench_memcpy(void *ctx, size_t n)
{
    const packets *p = ctx;
    for (size_t i = 0; i < n; i++) {
        memcpy(copy_target, p->bytes[i % VARIANTS], p->length);
        USE(copy_target);
    }
    checksum += copy_target[12];
    return n;
}

static urrt_state state __attribute__((aligned(64)));

/* The floor a C programmer writes first: per double one 8-byte load, a byte
 * swap and a store (the "plain loop"; -O2 leaves it scalar). */
static double plain_target[URRT_PACKET_KNOWN_MAX / 8] __attribute__((aligned(64)));

static __attribute__((noinline)) void plain_swap(double *dst, const uint8_t *src, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        uint64_t v;
        memcpy(&v, src + 8 * i, sizeof v);
        v = __builtin_bswap64(v);
        memcpy(&dst[i], &v, sizeof v);
    }
}

static size_t bench_plain(void *ctx, size_t n)
{
    const packets *p = ctx;
    for (size_t i = 0; i < n; i++) {
        plain_swap(plain_target, p->bytes[i % VARIANTS] + URRT_HEADER_SIZE, (p->length - URRT_HEADER_SIZE) / 8);
        USE(plain_target);
    }
    checksum += (uint64_t)plain_target[3];
    return n;
}

/* The store floor: sizeof(urrt_state) bytes written to the decode's own
 * target, a different byte each time; the barrier makes every memset happen.
 * Called through a volatile pointer, so that it is the C library's memset (the
 * widest stores this CPU has) in both builds, not what the compiler inlines
 * for a known size: GCC's generic tuning inlines `rep stosq`, about twice as
 * slow on the AMD EPYC of docs/performance.md. */
static void *(*volatile store_fn)(void *, int, size_t) = memset;

static size_t bench_store(void *ctx, size_t n)
{
    (void)ctx;
    for (size_t i = 0; i < n; i++) {
        store_fn(&state, (int)(i & 0x7F), sizeof state);
        USE(&state);
    }
    checksum += state.present;
    return n;
}

/* The copy floor: what the decode cannot avoid, a byte-swapping copy of the
 * packet's doubles into a buffer of sizeof(urrt_state) bytes and a memset
 * of the rest. Two ways, each measured beside the decode in every batch and
 * the faster taken, batch by batch, as the floor: the widest vectors this
 * CPU has (chosen at run time as the decode's own dispatch chooses:
 * AVX-512BW, AVX2, SSSE3), their stores aligned, the vector where the
 * packet ends loaded masked (zeros past its end) so that it is one store;
 * and the plain loop with the C library's memset of the rest. */
static uint8_t copy_floor_target[sizeof(urrt_state)] __attribute__((aligned(64)));
_Static_assert(sizeof(urrt_state) % 8 == 0, "the fill's tail is whole doubles");

typedef void (*copy_floor_fn)(uint8_t *dst, const uint8_t *src, size_t doubles);

static __attribute__((noinline)) void copy_floor_plain(uint8_t *dst, const uint8_t *src, size_t doubles)
{
    plain_swap((double *)(void *)dst, src, doubles);
    store_fn(dst + 8 * doubles, 0, sizeof(urrt_state) - 8 * doubles);
}

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

/* Each 16-byte lane: its two doubles' bytes reversed (PSHUFB is per lane). */
#define SWAP_LANE_R 7, 6, 5, 4, 3, 2, 1, 0, 15, 14, 13, 12, 11, 10, 9, 8

static __attribute__((noinline, target("avx512bw"))) void copy_floor_64(uint8_t *dst, const uint8_t *src,
                                                                          size_t doubles)
{
    const __m512i swap = _mm512_broadcast_i32x4(_mm_setr_epi8(SWAP_LANE_R));
    const __m512i zero = _mm512_setzero_si512();
    size_t bytes = 8 * doubles, i = 0;
    for (; i + 128 <= bytes; i += 128) {
        __m512i a = _mm512_loadu_si512(src + i), b = _mm512_loadu_si512(src + i + 64);
        _mm512_store_si512(dst + i, _mm512_shuffle_epi8(a, swap));
        _mm512_store_si512(dst + i + 64, _mm512_shuffle_epi8(b, swap));
    }
    if (i + 64 <= bytes) {
        _mm512_store_si512(dst + i, _mm512_shuffle_epi8(_mm512_loadu_si512(src + i), swap));
        i += 64;
    }
    if (i < bytes) {
        __mmask8 m = (__mmask8)((1u << ((bytes - i) / 8)) - 1u);
        _mm512_store_si512(dst + i, _mm512_shuffle_epi8(_mm512_maskz_loadu_epi64(m, src + i), swap));
        i += 64;
    }
    for (; i + 64 <= sizeof(urrt_state); i += 64) {
        _mm512_store_si512(dst + i, zero);
    }
    if (i < sizeof(urrt_state)) {
        _mm512_mask_storeu_epi64(dst + i, (__mmask8)((1u << ((sizeof(urrt_state) - i) / 8)) - 1u), zero);
    }
}

static __attribute__((noinline, target("avx2"))) void copy_floor_32(uint8_t *dst, const uint8_t *src,
                                                                      size_t doubles)
{
    const __m256i swap = _mm256_setr_epi8(SWAP_LANE_R, SWAP_LANE_R);
    const __m256i zero = _mm256_setzero_si256();
    const __m256i lanes = _mm256_setr_epi64x(0, 1, 2, 3);
    size_t bytes = 8 * doubles, i = 0;
    for (; i + 64 <= bytes; i += 64) {
        __m256i a = _mm256_loadu_si256((const void *)(src + i)), b = _mm256_loadu_si256((const void *)(src + i + 32));
        _mm256_store_si256((void *)(dst + i), _mm256_shuffle_epi8(a, swap));
        _mm256_store_si256((void *)(dst + i + 32), _mm256_shuffle_epi8(b, swap));
    }
    if (i + 32 <= bytes) {
        _mm256_store_si256((void *)(dst + i), _mm256_shuffle_epi8(_mm256_loadu_si256((const void *)(src + i)), swap));
        i += 32;
    }
    if (i < bytes) {
        __m256i m = _mm256_cmpgt_epi64(_mm256_set1_epi64x((long long)((bytes - i) / 8)), lanes);
        _mm256_store_si256((void *)(dst + i),
                           _mm256_shuffle_epi8(_mm256_maskload_epi64((const long long *)(const void *)(src + i), m), swap));
        i += 32;
    }
    for (; i + 32 <= sizeof(urrt_state); i += 32) {
        _mm256_store_si256((void *)(dst + i), zero);
    }
    if (i < sizeof(urrt_state)) {
        __m256i m = _mm256_cmpgt_epi64(_mm256_set1_epi64x((long long)((sizeof(urrt_state) - i) / 8)), lanes);
        _mm256_maskstore_epi64((long long *)(void *)(dst + i), m, zero);
    }
}

static __attribute__((noinline, target("ssse3"))) void copy_floor_16(uint8_t *dst, const uint8_t *src,
                                                                       size_t doubles)
{
    const __m128i swap = _mm_setr_epi8(SWAP_LANE_R);
    const __m128i zero = _mm_setzero_si128();
    size_t bytes = 8 * doubles, i = 0;
    for (; i + 32 <= bytes; i += 32) {
        __m128i a = _mm_loadu_si128((const void *)(src + i)), b = _mm_loadu_si128((const void *)(src + i + 16));
        _mm_store_si128((void *)(dst + i), _mm_shuffle_epi8(a, swap));
        _mm_store_si128((void *)(dst + i + 16), _mm_shuffle_epi8(b, swap));
    }
    if (i + 16 <= bytes) {
        _mm_store_si128((void *)(dst + i), _mm_shuffle_epi8(_mm_loadu_si128((const void *)(src + i)), swap));
        i += 16;
    }
    if (i < bytes) { /* one double: the load zeroes the upper one */
        _mm_store_si128((void *)(dst + i), _mm_shuffle_epi8(_mm_loadl_epi64((const void *)(src + i)), swap));
        i += 16;
    }
    for (; i + 16 <= sizeof(urrt_state); i += 16) {
        _mm_store_si128((void *)(dst + i), zero);
    }
    if (i < sizeof(urrt_state)) {
        _mm_storel_epi64((void *)(dst + i), zero);
    }
}

/* The vector ways this CPU runs, widest first, tested in the decode's order. */
static size_t copy_floor_ways(copy_floor_fn fn[3], unsigned bytes[3])
{
    size_t n = 0;
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512bw")) {
        fn[n] = copy_floor_64;
        bytes[n++] = 64;
    }
    if (__builtin_cpu_supports("avx2")) {
        fn[n] = copy_floor_32;
        bytes[n++] = 32;
    }
    if (__builtin_cpu_supports("ssse3")) {
        fn[n] = copy_floor_16;
        bytes[n++] = 16;
    }
    return n;
}
#else
static size_t copy_floor_ways(copy_floor_fn fn[3], unsigned bytes[3])
{
    (void)fn;
    (void)bytes;
    return 0; /* no vector floor written for this target: the plain loop alone */
}
#endif

/* The widest way this CPU has; the plain loop (0 bytes) where it has none. */
static copy_floor_fn copy_floor_widest(unsigned *bytes)
{
    copy_floor_fn fn[3];
    unsigned b[3];
    if (copy_floor_ways(fn, b) == 0) {
        *bytes = 0;
        return copy_floor_plain;
    }
    *bytes = b[0];
    return fn[0];
}

typedef struct copy_floor_bench {
    const packets *p;
    copy_floor_fn fn;
} copy_floor_bench;

static size_t bench_copy_floor(void *ctx, size_t n)
{
    const copy_floor_bench *c = ctx;
    size_t doubles = (c->p->length - URRT_HEADER_SIZE) / 8;
    for (size_t i = 0; i < n; i++) {
        c->fn(copy_floor_target, c->p->bytes[i % VARIANTS] + URRT_HEADER_SIZE, doubles);
        USE(copy_floor_target);
    }
    checksum += copy_floor_target[11];
    return n;
}

static size_t bench_decode(void *ctx, size_t n)
{
    const packets *p = ctx;
    uint64_t sum = 0;
    for (size_t i = 0; i < n; i++) {
        sum += (uint64_t)urrt_decode(p->bytes[i % VARIANTS], p->length, &state);
        USE(&state);
        sum += state.present;
    }
    checksum += sum;
    return n;
}

/* ---- RTDE: data packages of two recipes ------------------------------------ */

/* The recipe that mirrors what urrt publishes from RealTime (docs/rtde.md):
 * a 904-byte data package. */
static const char *const rtde_state_names[] = {
    "timestamp", "target_q", "target_qd", "target_qdd", "target_current", "target_moment", "actual_q",
    "actual_qd", "actual_current", "joint_control_output", "actual_TCP_pose", "actual_TCP_speed",
    "actual_TCP_force", "target_TCP_pose", "target_TCP_speed", "actual_digital_input_bits",
    "joint_temperatures", "actual_execution_time", "robot_mode", "joint_mode", "safety_mode",
    "actual_tool_accelerometer", "speed_scaling", "actual_momentum", "actual_main_voltage",
    "actual_robot_voltage", "actual_robot_current", "actual_joint_voltage", "actual_digital_output_bits",
    "runtime_state"};
/* A small recipe, a PLC's: the clock, the joints, the status bits and one
 * register a robot program writes: a 72-byte data package. */
static const char *const rtde_small_names[] = {"timestamp", "actual_q", "robot_status_bits", "safety_status_bits",
                                               "output_int_register_24"};

typedef struct rtde_bench {
    urrt_rtde session;
    packets pkgs;
} rtde_bench;

static urrt_rtde_values rtde_vals __attribute__((aligned(64)));

/* Feeds one package (size and letter in front of body) to the session. */
static int rtde_reply(urrt_rtde *s, uint8_t type, const uint8_t *body, size_t n)
{
    static uint8_t pkg[URRT_RTDE_PACKAGE_MAX];
    urrt_rtde_event ev;
    size_t used;
    uint8_t out[URRT_RTDE_REQUEST_MAX];
    pkg[0] = (uint8_t)((n + 3) >> 8);
    pkg[1] = (uint8_t)(n + 3);
    pkg[2] = type;
    memcpy(pkg + 3, body, n);
    while (urrt_rtde_output(s, out, sizeof out) > 0) {
    }
    return urrt_rtde_feed(s, pkg, n + 3, &used, &ev, &state, &rtde_vals);
}

/* The session through the handshake (the bench's own replies: what is
 * measured is the data, not the replies), and its data packages, each 64
 * bytes aligned (its values then start 4 bytes past that, after the header
 * and the recipe id), of `size` bytes. */
static void rtde_setup(rtde_bench *b, const char *const *names, size_t count, size_t size)
{
    uint16_t vars[URRT_RTDE_MAX_VARS];
    char types[URRT_RTDE_MAX_VARS * 14 + 1] = {1}; /* recipe id 1, then the types */
    size_t at = 1;
    static const uint8_t yes = 1, version[16] = {0, 0, 0, 5, 0, 0, 0, 12};
    packets *p = &b->pkgs;
    for (size_t i = 0; i < count; i++) {
        const char *t;
        vars[i] = (uint16_t)urrt_rtde_var_find(names[i], strlen(names[i]));
        t = urrt_rtde_type_name(urrt_rtde_var_type(vars[i]));
        at += (size_t)sprintf(types + at, "%s%s", i > 0 ? "," : "", t);
    }
    urrt_rtde_init(&b->session);
    if (urrt_rtde_begin(&b->session, vars, count, 0.0) != URRT_OK ||
        rtde_reply(&b->session, 'V', &yes, 1) != URRT_RTDE_EV_PROTOCOL ||
        rtde_reply(&b->session, 'v', version, 16) != URRT_RTDE_EV_CONTROLLER ||
        rtde_reply(&b->session, 'O', (const uint8_t *)types, at) != URRT_RTDE_EV_RECIPE ||
        rtde_reply(&b->session, 'S', &yes, 1) != URRT_RTDE_EV_STARTED || b->session.data_size != size) {
        fprintf(stderr, "bench: the RTDE handshake failed\n");
        exit(1);
    }
    p->length = b->session.data_size;
    for (size_t v = 0; v < VARIANTS; v++) {
        uint8_t *bytes = p->storage + v * STRIDE;
        for (size_t i = 0; i < p->length; i++) {
            bytes[i] = (uint8_t)(i * 7 + v * 13 + 1);
        }
        bytes[0] = (uint8_t)(p->length >> 8);
        bytes[1] = (uint8_t)p->length;
        bytes[2] = 'U';
        bytes[3] = 1;
        p->bytes[v] = bytes;
    }
}

/* urrt_rtde_decode of the package, into a urrt_state and the RTDE-only
 * values, as a caller that takes the packages out itself. */
static size_t bench_rtde_decode(void *ctx, size_t n)
{
    const rtde_bench *b = ctx;
    uint64_t sum = 0;
    for (size_t i = 0; i < n; i++) {
        sum += (uint64_t)urrt_rtde_decode(&b->session, b->pkgs.bytes[i % VARIANTS], b->pkgs.length, &state,
                                          &rtde_vals);
        USE(&state);
        USE(&rtde_vals);
        sum += state.present;
    }
    checksum += sum;
    return n;
}

/* What the gateway and a firmware run: urrt_rtde_feed of the bytes a read
 * returned, here one whole package, to its event. */
static size_t bench_rtde_feed(void *ctx, size_t n)
{
    rtde_bench *b = ctx;
    uint64_t sum = 0;
    for (size_t i = 0; i < n; i++) {
        urrt_rtde_event ev;
        size_t used;
        int k = urrt_rtde_feed(&b->session, b->pkgs.bytes[i % VARIANTS], b->pkgs.length, &used, &ev, &state,
                               &rtde_vals);
        USE(&state);
        USE(&rtde_vals);
        sum += (uint64_t)k + used + state.present;
    }
    if (sum != n * (URRT_RTDE_EV_DATA + b->pkgs.length + state.present)) {
        fprintf(stderr, "bench: a feed of a whole data package did not give its data event\n");
        exit(1);
    }
    checksum += sum;
    return n;
}

/* The copy floors: each recipe's values, byte-swapped into a struct of
 * their own C types, field by field, as a C programmer writes it for one
 * recipe (the bench's flags: -O2, or -O2 -march=native). */
static inline double be_f64(const uint8_t *p)
{
    uint64_t v;
    double d;
    memcpy(&v, p, sizeof v);
    v = __builtin_bswap64(v);
    memcpy(&d, &v, sizeof d);
    return d;
}

static inline uint64_t be_u64(const uint8_t *p)
{
    uint64_t v;
    memcpy(&v, p, sizeof v);
    return __builtin_bswap64(v);
}

static inline uint32_t be_u32(const uint8_t *p)
{
    uint32_t v;
    memcpy(&v, p, sizeof v);
    return __builtin_bswap32(v);
}

#define F64(m) (c->m = be_f64(p), p += 8)
#define F64N(m, n) bench_f64n(c->m, &p, n)
static inline void bench_f64n(double *d, const uint8_t **p, unsigned n)
{
    for (unsigned k = 0; k < n; k++) {
        d[k] = be_f64(*p + 8 * k);
    }
    *p += 8 * n;
}

typedef struct state_copy {
    double timestamp, target_q[6], target_qd[6], target_qdd[6], target_current[6], target_moment[6], actual_q[6],
        actual_qd[6], actual_current[6], joint_control_output[6], actual_tcp_pose[6], actual_tcp_speed[6],
        actual_tcp_force[6], target_tcp_pose[6], target_tcp_speed[6];
    uint64_t actual_digital_input_bits;
    double joint_temperatures[6], actual_execution_time;
    int32_t robot_mode, joint_mode[6], safety_mode;
    double actual_tool_accelerometer[3], speed_scaling, actual_momentum, actual_main_voltage, actual_robot_voltage,
        actual_robot_current, actual_joint_voltage[6];
    uint64_t actual_digital_output_bits;
    uint32_t runtime_state;
} state_copy;

static state_copy state_copy_target __attribute__((aligned(64)));

static __attribute__((noinline)) void copy_state_recipe(state_copy *c, const uint8_t *pkg)
{
    const uint8_t *p = pkg + 4;
    F64(timestamp);
    F64N(target_q, 6);
    F64N(target_qd, 6);
    F64N(target_qdd, 6);
    F64N(target_current, 6);
    F64N(target_moment, 6);
    F64N(actual_q, 6);
    F64N(actual_qd, 6);
    F64N(actual_current, 6);
    F64N(joint_control_output, 6);
    F64N(actual_tcp_pose, 6);
    F64N(actual_tcp_speed, 6);
    F64N(actual_tcp_force, 6);
    F64N(target_tcp_pose, 6);
    F64N(target_tcp_speed, 6);
    c->actual_digital_input_bits = be_u64(p);
    p += 8;
    F64N(joint_temperatures, 6);
    F64(actual_execution_time);
    c->robot_mode = (int32_t)be_u32(p);
    p += 4;
    for (unsigned k = 0; k < 6; k++, p += 4) {
        c->joint_mode[k] = (int32_t)be_u32(p);
    }
    c->safety_mode = (int32_t)be_u32(p);
    p += 4;
    F64N(actual_tool_accelerometer, 3);
    F64(speed_scaling);
    F64(actual_momentum);
    F64(actual_main_voltage);
    F64(actual_robot_voltage);
    F64(actual_robot_current);
    F64N(actual_joint_voltage, 6);
    c->actual_digital_output_bits = be_u64(p);
    p += 8;
    c->runtime_state = be_u32(p);
}

typedef struct small_copy {
    double timestamp, actual_q[6];
    uint32_t robot_status_bits, safety_status_bits;
    int32_t output_int_register_24;
} small_copy;

static small_copy small_copy_target __attribute__((aligned(64)));

static __attribute__((noinline)) void copy_small_recipe(small_copy *c, const uint8_t *pkg)
{
    const uint8_t *p = pkg + 4;
    F64(timestamp);
    F64N(actual_q, 6);
    c->robot_status_bits = be_u32(p);
    c->safety_status_bits = be_u32(p + 4);
    c->output_int_register_24 = (int32_t)be_u32(p + 8);
}

static size_t bench_state_copy(void *ctx, size_t n)
{
    const rtde_bench *b = ctx;
    for (size_t i = 0; i < n; i++) {
        copy_state_recipe(&state_copy_target, b->pkgs.bytes[i % VARIANTS]);
        USE(&state_copy_target);
    }
    checksum += (uint64_t)state_copy_target.runtime_state;
    return n;
}

static size_t bench_small_copy(void *ctx, size_t n)
{
    const rtde_bench *b = ctx;
    for (size_t i = 0; i < n; i++) {
        copy_small_recipe(&small_copy_target, b->pkgs.bytes[i % VARIANTS]);
        USE(&small_copy_target);
    }
    checksum += (uint64_t)small_copy_target.robot_status_bits;
    return n;
}

/* The session's decode, feed and copy floor of one recipe, and `what`
 * (urrt_rtde_decode or urrt_rtde_feed) against the floor. */
static void rtde_versus(const char *name, const char *what, bench_fn subject, bench_fn floor_fn, rtde_bench *b)
{
    double s, f, r;
    measure(subject, b, floor_fn, b, &s, &f, &r);
    printf("%srtde_%s_%s_ns: %.1f\n", URRT_BENCH_PREFIX, what, name, s);
    printf("%srtde_%s_%s_copy_floor_ns: %.1f\n", URRT_BENCH_PREFIX, what, name, f);
    printf("%srtde_%s_%s_vs_copy_floor: %.2f\n", URRT_BENCH_PREFIX, what, name, r);
    printf("%srtde_%s_%s_vs_copy_floor_of_best: %.2f\n", URRT_BENCH_PREFIX, what, name, s / f);
}

static const urrt_field_id read_fields[10] = {
    URRT_F_TIME, URRT_F_Q_ACTUAL, URRT_F_QD_ACTUAL, URRT_F_TOOL_VECTOR_ACTUAL, URRT_F_TCP_FORCE,
    URRT_F_ROBOT_MODE, URRT_F_SAFETY_MODE, URRT_F_DIGITAL_INPUT_BITS, URRT_F_PROGRAM_STATE, URRT_F_SAFETY_STATUS,
};

static size_t bench_read10(void *ctx, size_t n)
{
    const packets *p = ctx;
    double values[10];
    for (size_t i = 0; i < n; i++) {
        const uint8_t *pkt = p->bytes[i % VARIANTS];
        for (unsigned f = 0; f < 10; f++) {
            urrt_read(pkt, p->length, read_fields[f], f % 3, &values[f]);
        }
        USE(values);
    }
    checksum += (uint64_t)values[0];
    return n;
}

typedef struct stream {
    uint8_t *bytes;
    size_t length;
    size_t chunk;
    size_t packets;
} stream;

static urrt_framer framer;

/* One iteration = one packet's worth of the stream: the whole stream is fed
 * in chunks, every packet decoded, and the time divided by its packets. */
static size_t bench_framer(void *ctx, size_t n)
{
    const stream *s = ctx;
    uint64_t sum = 0;
    size_t rounds = (n + s->packets - 1) / s->packets;
    for (size_t r = 0; r < rounds; r++) {
        urrt_framer_init(&framer);
        for (size_t at = 0; at < s->length;) {
            size_t chunk = s->length - at < s->chunk ? s->length - at : s->chunk;
            const uint8_t *p = s->bytes + at;
            at += chunk;
            while (chunk > 0) {
                size_t used;
                if (urrt_framer_feed(&framer, p, chunk, &used) > 0) {
                    size_t len;
                    const uint8_t *pkt = urrt_framer_packet(&framer, &len);
                    sum += (uint64_t)urrt_decode(pkt, len, &state);
                    USE(&state);
                }
                p += used;
                chunk -= used;
            }
        }
    }
    checksum += sum;
    return rounds * s->packets;
}

/* The RealTime receive path as the RTDE one is measured: a read that holds
 * one whole packet fed to the framer, and the packet it yields decoded. */
static size_t bench_framer_whole(void *ctx, size_t n)
{
    const packets *p = ctx;
    uint64_t sum = 0;
    for (size_t i = 0; i < n; i++) {
        size_t used, len;
        const uint8_t *pkt;
        if (urrt_framer_feed(&framer, p->bytes[i % VARIANTS], p->length, &used) > 0) {
            pkt = urrt_framer_packet(&framer, &len);
            sum += (uint64_t)urrt_decode(pkt, len, &state);
            USE(&state);
            sum += state.present;
        }
    }
    checksum += sum;
    return n;
}

/* The baseline: the same bytes, memcpy'd a packet at a time. */
static size_t bench_stream_memcpy(void *ctx, size_t n)
{
    const stream *s = ctx;
    size_t per = s->length / s->packets;
    size_t rounds = (n + s->packets - 1) / s->packets;
    for (size_t r = 0; r < rounds; r++) {
        for (size_t k = 0; k < s->packets; k++) {
            memcpy(copy_target, s->bytes + k * per, per);
            USE(copy_target);
        }
    }
    checksum += copy_target[5];
    return rounds * s->packets;
}

/* ---- setup ------------------------------------------------------------------ */

static void make_packets(packets *p, uint32_t length, size_t offset)
{
    static urrt_state st;
    uint64_t x = 0x243F6A8885A308D3u;
    p->length = length;
    for (int v = 0; v < VARIANTS; v++) {
        uint8_t *bytes = p->storage + (size_t)v * STRIDE + offset;
        p->bytes[v] = bytes;
        urrt_state_clear(&st);
        /* Plausible values: every double of the grid set. */
        for (unsigned c = 0; c < URRT_WIRE_COLUMNS; c++) {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            ((double *)(void *)&st)[c] = (double)(x % 2000000) / 1000.0 - 1000.0;
        }
        st.robot_mode[0] = 7;
        st.safety_mode[0] = 1;
        if (urrt_encode(&st, length, bytes, STRIDE) != (int)length) {
            fprintf(stderr, "bench: encode failed\n");
            exit(1);
        }
    }
}

static void report(const char *name, double subject, double baseline, double ratio)
{
    printf("%s%s_ns: %.1f\n", URRT_BENCH_PREFIX, name, subject);
    printf("%s%s_memcpy_ns: %.1f\n", URRT_BENCH_PREFIX, name, baseline);
    printf("%s%s_ratio: %.2f\n", URRT_BENCH_PREFIX, name, ratio);
    printf("%s%s_ratio_of_best: %.2f\n", URRT_BENCH_PREFIX, name, subject / baseline);
}

/* The decode against one floor, measured side by side: prints the floor's
 * ns, `decode_LEN_ALIGN_vs_FLOOR` (median of the per-batch ratios) and its
 * `_of_best`. */
static void decode_versus(const char *name, const char *floor, bench_fn floor_fn, packets *p)
{
    double s, f, r;
    measure(bench_decode, p, floor_fn, p, &s, &f, &r);
    printf("%s%s_%s_ns: %.1f\n", URRT_BENCH_PREFIX, name, floor, f);
    printf("%s%s_vs_%s: %.2f\n", URRT_BENCH_PREFIX, name, floor, r);
    printf("%s%s_vs_%s_of_best: %.2f\n", URRT_BENCH_PREFIX, name, floor, s / f);
}

/* Every vector way must write what the plain loop does, or it is no floor. */
static void check_copy_floor(const packets *p)
{
    static uint8_t plain[sizeof(urrt_state)];
    copy_floor_fn fn[3];
    unsigned bytes[3];
    size_t ways = copy_floor_ways(fn, bytes);
    size_t doubles = (p->length - URRT_HEADER_SIZE) / 8;
    memset(plain, 0xAA, sizeof plain);
    copy_floor_plain(plain, p->bytes[1] + URRT_HEADER_SIZE, doubles);
    for (size_t w = 0; w < ways; w++) {
        memset(copy_floor_target, 0x55, sizeof copy_floor_target);
        fn[w](copy_floor_target, p->bytes[1] + URRT_HEADER_SIZE, doubles);
        if (memcmp(copy_floor_target, plain, sizeof plain) != 0) {
            fprintf(stderr, "bench: the %u-byte vector copy floor differs from the plain loop at %u bytes: "
                            "fix copy_floor_%u in tests/lib/bench_lib.c\n",
                    bytes[w], (unsigned)p->length, bytes[w]);
            exit(1);
        }
    }
}

/* The decode against the copy floor, the faster of its two ways in each
 * batch: `decode_LEN_ALIGN_vs_copy_floor`, `_of_best`, and both ways' best
 * ns (`_copy_floor_ns`: the vector way; `_copy_floor_plain_ns`). */
static void decode_versus_copy_floor(const char *name, packets *p)
{
    static copy_floor_bench vector, plain;
    double s, f[2], r;
    unsigned bytes;
    vector.p = plain.p = p;
    vector.fn = copy_floor_widest(&bytes);
    plain.fn = copy_floor_plain;
    measure_min(bench_decode, p, bench_copy_floor, &vector, bench_copy_floor, &plain, &s, f, &r);
    printf("%s%s_copy_floor_ns: %.1f\n", URRT_BENCH_PREFIX, name, f[0]);
    printf("%s%s_copy_floor_plain_ns: %.1f\n", URRT_BENCH_PREFIX, name, f[1]);
    printf("%s%s_vs_copy_floor: %.2f\n", URRT_BENCH_PREFIX, name, r);
    printf("%s%s_vs_copy_floor_of_best: %.2f\n", URRT_BENCH_PREFIX, name, s / (f[0] < f[1] ? f[0] : f[1]));
}

/* The full decode of one length, its packets 64-byte aligned ("a64") and 4
 * bytes past that ("a64p4"): against the copy floor, the store floor, the
 * plain loop, and memcpy of the packet. */
static void bench_decode_at(uint32_t length)
{
    static packets p;
    static const size_t offsets[2] = {0, 4};
    static const char *const names[2] = {"a64", "a64p4"};
    for (int a = 0; a < 2; a++) {
        char name[64];
        double s, b, r;
        make_packets(&p, length, offsets[a]);
        check_copy_floor(&p);
        snprintf(name, sizeof name, "decode_%u_%s", (unsigned)length, names[a]);
        decode_versus_copy_floor(name, &p);
        decode_versus(name, "store", bench_store, &p);
        decode_versus(name, "plain", bench_plain, &p);
        measure(bench_decode, &p, bench_memcpy, &p, &s, &b, &r);
        report(name, s, b, r);
        measure(bench_plain, &p, bench_memcpy, &p, &s, &b, &r);
        snprintf(name, sizeof name, "plain_%u_%s", (unsigned)length, names[a]);
        report(name, s, b, r);
    }
}

/* The sections to run: all, or those named on the command line (decode,
 * rtde, framer). */
static int wanted(int argc, char **argv, const char *section)
{
    if (argc < 2) {
        return 1;
    }
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], section) == 0) {
            return 1;
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    static packets p1116;
    static stream streams[3];
    static const size_t chunks[3] = {1, 64, 65536};
    double s, b, r;

    make_packets(&p1116, 1116, 4);
    printf("bench: ns per packet, best of %d batches, each beside a floor measured in the same run;\n"
           "bench: *_vs_copy_floor: the decode against the copy floor (*_copy_floor_ns: the packet's doubles\n"
           "bench: byte-swapped by the widest vectors this CPU has into sizeof(urrt_state) bytes, the rest\n"
           "bench: zeroed; each batch takes the faster of that and *_copy_floor_plain_ns, the plain loop and\n"
           "bench: memset); *_vs_store: against the store floor (*_store_ns: a memset of sizeof(urrt_state)\n"
           "bench: = %zu bytes, what the decode must write); *_vs_plain: against a byte-swap loop (8-byte load,\n"
           "bench: bswap, store per double; *_plain_ns); *_ratio: against memcpy of the packet's bytes\n"
           "bench: (*_memcpy_ns; context: it moves with the memory layout). A ratio is the median of the\n"
           "bench: per-batch ratios, *_of_best the ratio of the best figures (steadier on a busy machine);\n"
           "bench: a64: packet 64-byte aligned, a64p4: 4 bytes past that; rtde_feed_* and rtde_decode_*:\n"
           "bench: urrt_rtde_feed of a read holding one whole data package (and urrt_rtde_decode of it) of the\n"
           "bench: STATE recipe (904 bytes) and of a 5-value recipe (72 bytes) against each recipe's copy floor\n"
           "bench: (its values byte-swapped into a struct of their own types, field by field);\n"
           "bench: framer_decode_1116: urrt_framer_feed of a read holding one whole packet, and urrt_decode of it,\n"
           "bench: against the decode's copy floor\n",
           BATCHES, sizeof(urrt_state));
#ifdef URRT_BENCH_FLAGS
    printf("bench_flags: %s\n", URRT_BENCH_FLAGS);
#endif
    {
        FILE *f = fopen("/proc/cpuinfo", "r");
        char line[256];
        while (f != NULL && fgets(line, sizeof line, f) != NULL) {
            if (strncmp(line, "model name", 10) == 0 && strchr(line, ':') != NULL) {
                printf("bench_cpu: %s", strchr(line, ':') + 2);
                break;
            }
        }
        if (f != NULL) {
            fclose(f);
        }
    }

#if defined(__x86_64__)
    printf("bench_decode_vector_bytes: %u\n", urrt_x86_vector_bytes());
#endif
    {
        unsigned bytes;
        (void)copy_floor_widest(&bytes);
        printf("bench_copy_floor_vector_bytes: %u\n", bytes);
    }
    if (wanted(argc, argv, "decode")) { /* every length a controller sends, from lib's table */
        size_t rows;
        const urrt_controller *c = urrt_controllers(&rows);
        for (size_t i = 0; i < rows; i++) {
            bench_decode_at(c[i].length);
        }
    }
    if (wanted(argc, argv, "decode")) {
        measure(bench_read10, &p1116, bench_memcpy, &p1116, &s, &b, &r);
        report("read10_1116", s, b, r);
    }

    if (wanted(argc, argv, "rtde")) {
        static rtde_bench state_recipe, small_recipe;
        rtde_setup(&state_recipe, rtde_state_names, sizeof rtde_state_names / sizeof rtde_state_names[0], 904);
        rtde_setup(&small_recipe, rtde_small_names, sizeof rtde_small_names / sizeof rtde_small_names[0], 72);
        rtde_versus("state", "feed", bench_rtde_feed, bench_state_copy, &state_recipe);
        rtde_versus("small", "feed", bench_rtde_feed, bench_small_copy, &small_recipe);
        rtde_versus("state", "decode", bench_rtde_decode, bench_state_copy, &state_recipe);
        rtde_versus("small", "decode", bench_rtde_decode, bench_small_copy, &small_recipe);
        /* beside it, the RealTime decode of a 1116-byte packet (4 bytes past a 64-byte boundary) */
        measure(bench_rtde_decode, &state_recipe, bench_decode, &p1116, &s, &b, &r);
        printf("%srtde_decode_state_realtime_decode_1116_ns: %.1f\n", URRT_BENCH_PREFIX, b);
        printf("%srtde_decode_state_vs_realtime_decode_1116: %.2f\n", URRT_BENCH_PREFIX, r);
    }

    if (wanted(argc, argv, "framer")) {
        /* the framer fed one whole 1116-byte packet per read, and its decode, against the
         * decode's copy floor of that packet */
        static copy_floor_bench vector, plain;
        double f[2];
        unsigned bytes;
        vector.p = plain.p = &p1116;
        vector.fn = copy_floor_widest(&bytes);
        plain.fn = copy_floor_plain;
        urrt_framer_init(&framer);
        measure_min(bench_framer_whole, &p1116, bench_copy_floor, &vector, bench_copy_floor, &plain, &s, f, &r);
        printf("%sframer_decode_1116_ns: %.1f\n", URRT_BENCH_PREFIX, s);
        printf("%sframer_decode_1116_copy_floor_ns: %.1f\n", URRT_BENCH_PREFIX, f[0] < f[1] ? f[0] : f[1]);
        printf("%sframer_decode_1116_vs_copy_floor: %.2f\n", URRT_BENCH_PREFIX, r);
        printf("%sframer_decode_1116_vs_copy_floor_of_best: %.2f\n", URRT_BENCH_PREFIX, s / (f[0] < f[1] ? f[0] : f[1]));
        decode_versus_copy_floor("decode_1116_beside_framer", &p1116); /* the decode alone, for scale */
    }

    for (int i = 0; i < 3 && wanted(argc, argv, "framer"); i++) {
        stream *st = &streams[i];
        st->packets = STREAM_PACKETS;
        st->length = STREAM_PACKETS * p1116.length;
        st->chunk = chunks[i];
        st->bytes = malloc(st->length);
        for (size_t k = 0; k < STREAM_PACKETS; k++) {
            memcpy(st->bytes + k * p1116.length, p1116.bytes[k % VARIANTS], p1116.length);
        }
        measure(bench_framer, st, bench_stream_memcpy, st, &s, &b, &r);
        {
            char name[64];
            snprintf(name, sizeof name, "framer_decode_1116_chunk_%zu", chunks[i]);
            report(name, s, b, r);
        }
        free(st->bytes);
    }
    printf("bench_checksum: %llu\n", (unsigned long long)(checksum & 0xFFFF));
    return 0;
}
