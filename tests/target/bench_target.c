/* SPDX-License-Identifier: MIT */
/*
 * Instructions per operation on an emulated Cortex-M4 (mps2-an386), read
 * from SysTick under qemu -icount: with shift=6 every instruction advances
 * virtual time by 64 ns, which SysTick counts at the 25 MHz core clock. The
 * ratio is calibrated on a loop of known length, and the cost of reading
 * SysTick is measured and taken off. Prints "bench: NAME INSTRUCTIONS";
 * bench_begin()/bench_end() delimit each operation for the cycle estimate
 * (tests/target/bench.py, from a single-step trace of the same image).
 */
#include "target.h"
#include "test_vectors.h"
#include "urrt.h"
#include "urrt_can.h"
#include "urrt_rtde.h"
#ifdef __ARM_ARCH_7EM__ /* the Cortex-M4 images: the PLC's answer (the M0's RAM holds the rest) */
#include "../lib/co_fixture.h"
#include "urrt_plcin.h"
#include "urrt_rtde_in.h"
#define BENCH_PLCIN 1
#endif

/* Marks for the trace: the operation runs between their calls. */
__attribute__((noinline)) void bench_begin(void)
{
    __asm__ volatile("" ::: "memory");
}
__attribute__((noinline)) void bench_end(void)
{
    __asm__ volatile("" ::: "memory");
}

/* Each operation is timed from one SysTick read to the next. */
#define TIMED(ticks, ...)                 \
    do {                                  \
        uint32_t t0_, t1_;                \
        bench_begin();                    \
        t0_ = target_systick();           \
        __VA_ARGS__;                      \
        t1_ = target_systick();           \
        bench_end();                      \
        (ticks) = (t0_ - t1_) & 0xFFFFFFu; \
    } while (0)

static uint32_t overhead_ticks;
/* SysTick ticks per 1000 instructions, calibrated. */
static uint32_t ticks_per_kinsn;

static void report(const char *name, uint32_t ticks)
{
    uint32_t net = ticks > overhead_ticks ? ticks - overhead_ticks : 0;
    target_puts("bench: ");
    target_puts(name);
    target_puts(" ");
    target_put_uint(((uint64_t)net * 1000u + ticks_per_kinsn / 2u) / ticks_per_kinsn);
    target_puts("\n");
}

/* 2 instructions per iteration (subs, bne). */
static __attribute__((noinline)) void known_loop(uint32_t n)
{
    __asm__ volatile(".syntax unified\n1:\tsubs %0, %0, #1\n\tbne 1b" : "+l"(n) : : "cc");
}

static const tv_vector *vector(uint32_t length)
{
    unsigned i;
    for (i = 0; i < tv_vector_count; i++) {
        if (tv_vectors[i].length == length && tv_vectors[i].generation == URRT_GEN_3X) {
            return &tv_vectors[i];
        }
    }
    target_puts("bench: no reference vector of that length\n");
    target_exit(2);
}

/* The floor: a byte-swapping copy of the same bytes (word loads, REV,
 * stores); src is 4-byte aligned, as a packet body in a word-aligned buffer. */
static __attribute__((noinline)) void swap_copy(uint64_t *dst, const uint8_t *src, unsigned n)
{
    const uint8_t *a = __builtin_assume_aligned(src, 4);
    unsigned i;
    for (i = 0; i < n; i++) {
        uint32_t hi, lo;
        __builtin_memcpy(&hi, a + 8u * i, 4);
        __builtin_memcpy(&lo, a + 8u * i + 4, 4);
        dst[i] = (uint64_t)__builtin_bswap32(hi) << 32 | __builtin_bswap32(lo);
    }
}

static urrt_state st;
static uint64_t packet_words[1224 / 8 + 1];
static uint64_t copy_words[1220 / 8];
#define STREAM_PACKETS 4 /* 3 whole segments; small enough for 16 KiB of RAM */
/* The framer and its stream, and the RTDE session and its values, are never
 * in use at once: one piece of RAM (the Cortex-M0 board has 16 KiB). */
static union {
    struct {
        uint8_t stream[STREAM_PACKETS * 1116];
        urrt_framer framer;
    } rt;
    struct {
        urrt_rtde rtde;
        urrt_rtde_values vals;
    } r;
} ram;
#define framer ram.rt.framer

static const urrt_field_id read_fields[10] = {
    URRT_F_TIME, URRT_F_Q_ACTUAL, URRT_F_QD_ACTUAL, URRT_F_TOOL_VECTOR_ACTUAL, URRT_F_TCP_FORCE,
    URRT_F_ROBOT_MODE, URRT_F_SAFETY_MODE, URRT_F_DIGITAL_INPUT_BITS, URRT_F_PROGRAM_STATE, URRT_F_SAFETY_STATUS,
};

/* docs/examples/canopen.ini's TPDO1 (0x185) as urrt_can signals: q_actual[0..2]
 * as 16-bit Intel signed at factor 0.0002, the alive counter in byte 7's low
 * bits (56|4, unsigned) and the validity bit 63. */
static urrt_can_signal tpdo1[5];
static urrt_can_scale tpdo1_scales[5];
static uint8_t payload[URRT_CAN_MAX_LEN]; /* a urrt_can_frame's data */
static void tpdo1_signal(unsigned i, unsigned start, unsigned length, unsigned type, double factor)
{
    urrt_can_signal *s = &tpdo1[i];
    s->factor = factor;
    s->offset = 0;
    s->invalid_raw = 0;
    s->start = (uint16_t)start;
    s->length = (uint8_t)length;
    s->byte_order = URRT_CAN_INTEL;
    s->type = (uint8_t)type;
    s->flags = 0;
    urrt_can_signal_range(s, &s->min, &s->max);
    urrt_can_scale_prepare(s, &tpdo1_scales[i]);
}

/* The frame as a firmware's CAN core packs it: each signal with its scale
 * prepared once (urrt_cantx_prepare), into the frame buffer. */
static int pack_tpdo1(const double *values, uint8_t *frame)
{
    int worst = 0;
    unsigned i;
    for (i = 0; i < 5u; i++) {
        int outcome = urrt_can_pack_scaled(&tpdo1[i], &tpdo1_scales[i], values[i], frame);
        worst = outcome > worst ? outcome : worst;
    }
    return worst;
}

/* SysTick started, the cost of reading it and the ticks per 1000 instructions. */
static void calibrate(void)
{
    uint32_t ticks;
    target_systick_start();
    TIMED(overhead_ticks, (void)0);
    TIMED(ticks, known_loop(10000));
    /* known_loop: 20000 in the loop, plus the call and return (mov, bl, bx). */
    ticks_per_kinsn = (uint32_t)(((uint64_t)(ticks - overhead_ticks) * 1000u + 10001u) / 20003u);
    target_puts("bench: systick_ticks_per_1000_instructions ");
    target_put_uint(ticks_per_kinsn);
    target_puts("\n");
}

/* v's packet, copied into packet_words: decoded, and the floor of a byte-swapping copy. */
static int bench_decode(const tv_vector *v, const char *decode_name, const char *copy_name)
{
    uint32_t ticks, i;
    int sink = 0;
    uint8_t *pkt = (uint8_t *)packet_words;
    for (i = 0; i < v->length; i++) {
        pkt[i] = v->packet[i];
    }
    TIMED(ticks, sink += urrt_decode(pkt, v->length, &st));
    report(decode_name, ticks);
    TIMED(ticks, swap_copy(copy_words, pkt + 4, (v->length - 4u) / 8u));
    report(copy_name, ticks);
    return sink;
}

/* Ten fields read at random from the packet in packet_words. */
static int bench_read10(const tv_vector *v1116)
{
    uint32_t ticks, i;
    int sink = 0;
    uint8_t *pkt = (uint8_t *)packet_words;
    double values[10];
    TIMED(ticks, for (i = 0; i < 10; i++) sink += urrt_read(pkt, v1116->length, read_fields[i], i % 3u,
                                                           &values[i]));
    report("read10_1116", ticks);
    return sink;
}

/* The framer in steady state: a stream of 1116-byte packets arriving as
 * 1460-byte TCP segments; the figure is the mean over the whole segments. */
static int bench_framer(const tv_vector *v1116)
{
    uint32_t ticks, i;
    int sink = 0;
    uint32_t total = 0, segments = 0, pos;
    for (i = 0; i < sizeof ram.rt.stream; i++) {
        ram.rt.stream[i] = v1116->packet[i % 1116u];
    }
    urrt_framer_init(&framer);
    for (pos = 0; pos + 1460u <= sizeof ram.rt.stream; pos += 1460u) {
        TIMED(ticks, {
            const uint8_t *p = ram.rt.stream + pos;
            size_t n = 1460, used;
            while (n > 0) {
                sink += urrt_framer_feed(&framer, p, n, &used);
                p += used;
                n -= used;
            }
        });
        total += ticks - overhead_ticks;
        segments++;
    }
    report("framer_feed_1460", total / segments + overhead_ticks);
    return sink;
}

/* The RealTime receive path as the RTDE one's is measured below: a read
 * that holds one whole 1116-byte packet (4-byte aligned, as a TCP stack's
 * buffer), fed to the framer, and the packet it yields decoded. */
static int bench_framer_decode(const tv_vector *v1116)
{
    uint32_t ticks, i;
    int sink = 0;
    size_t used, len;
    uint8_t *pkt = (uint8_t *)packet_words;
    for (i = 0; i < v1116->length; i++) {
        pkt[i] = v1116->packet[i];
    }
    urrt_framer_init(&framer);
    sink += urrt_framer_feed(&framer, pkt, v1116->length, &used); /* the first: its size is learnt */
    TIMED(ticks, {
        if (urrt_framer_feed(&framer, pkt, v1116->length, &used) > 0) {
            const uint8_t *p = urrt_framer_packet(&framer, &len);
            sink += urrt_decode(p, len, &st);
        }
    });
    report("framer_decode_1116", ticks);
    return sink;
}

/* TPDO1 packed from the decoded packet, signal by signal and as a frame. */
static int bench_can_pack(const tv_vector *v1116)
{
    uint32_t ticks;
    int sink = 0;
    double values[5];
    tpdo1_signal(0, 0, 16, URRT_CAN_SIGNED, 0.0002);
    tpdo1_signal(1, 16, 16, URRT_CAN_SIGNED, 0.0002);
    tpdo1_signal(2, 32, 16, URRT_CAN_SIGNED, 0.0002);
    tpdo1_signal(3, 56, 4, URRT_CAN_UNSIGNED, 1.0);
    tpdo1_signal(4, 63, 1, URRT_CAN_UNSIGNED, 1.0);
    urrt_decode(v1116->packet, v1116->length, &st);
    values[0] = st.q_actual[0];
    values[1] = st.q_actual[1];
    values[2] = st.q_actual[2];
    values[3] = 5;
    values[4] = 1;
    TIMED(ticks, sink += pack_tpdo1(values, payload));
    report("can_pack_tpdo1", ticks);
    TIMED(ticks, sink += urrt_can_pack_frame(tpdo1, values, 5, payload, 8, NULL));
    report("can_pack_frame_tpdo1", ticks);
    return sink;
}

/* ---- RTDE: one data package of the STATE recipe ---------------------------- */

/* The recipe that mirrors what urrt publishes from RealTime (docs/rtde.md):
 * a 904-byte data package, as tests/lib/bench_lib.c measures it on the host. */
static const char *const rtde_state_names[] = {
    "timestamp", "target_q", "target_qd", "target_qdd", "target_current", "target_moment", "actual_q",
    "actual_qd", "actual_current", "joint_control_output", "actual_TCP_pose", "actual_TCP_speed",
    "actual_TCP_force", "target_TCP_pose", "target_TCP_speed", "actual_digital_input_bits",
    "joint_temperatures", "actual_execution_time", "robot_mode", "joint_mode", "safety_mode",
    "actual_tool_accelerometer", "speed_scaling", "actual_momentum", "actual_main_voltage",
    "actual_robot_voltage", "actual_robot_current", "actual_joint_voltage", "actual_digital_output_bits",
    "runtime_state"};
#define RTDE_STATE_VARS (sizeof rtde_state_names / sizeof rtde_state_names[0])
#define RTDE_STATE_SIZE 904u

static size_t text_length(const char *s)
{
    size_t n = 0;
    while (s[n] != '\0') {
        n++;
    }
    return n;
}

/* A small recipe, a PLC's (tests/lib/bench_lib.c's too): a 72-byte package. */
static const char *const rtde_small_names[] = {"timestamp", "actual_q", "robot_status_bits", "safety_status_bits",
                                               "output_int_register_24"};
#define RTDE_SMALL_VARS (sizeof rtde_small_names / sizeof rtde_small_names[0])
#define RTDE_SMALL_SIZE 72u

/* One controller package (type, n bytes of body at pkg + 3) fed to the
 * session after its due request is taken out: the event it gives. */
static int rtde_reply(uint8_t *pkg, uint8_t type, size_t n)
{
    urrt_rtde_event ev;
    size_t used;
    pkg[0] = (uint8_t)((n + 3u) >> 8);
    pkg[1] = (uint8_t)(n + 3u);
    pkg[2] = type;
    while (urrt_rtde_output(&ram.r.rtde, (uint8_t *)copy_words, sizeof copy_words) > 0) {
    }
    return urrt_rtde_feed(&ram.r.rtde, pkg, n + 3u, &used, &ev, &st, &ram.r.vals);
}

/* A controller's type list for a recipe at pkg + 4 (after the recipe id):
 * its length. */
static size_t rtde_types(uint8_t *pkg, const char *const *names, size_t count, uint16_t *vars)
{
    size_t at = 4, i, k;
    for (i = 0; i < count; i++) {
        const char *type;
        vars[i] = (uint16_t)urrt_rtde_var_find(names[i], text_length(names[i]));
        type = urrt_rtde_type_name(urrt_rtde_var_type(vars[i]));
        if (i > 0) {
            pkg[at++] = ',';
        }
        for (k = 0; type[k] != '\0'; k++) {
            pkg[at++] = (uint8_t)type[k];
        }
    }
    return at - 3;
}

/* The session through the handshake of a recipe (the bench's own replies:
 * what is timed is the data), then one data package of `size` bytes in
 * pkg: the 1116-byte packet's bytes as its body. */
static void rtde_session(const tv_vector *v1116, const char *const *names, size_t count, size_t size)
{
    static const uint8_t version[16] = {0, 0, 0, 5, 0, 0, 0, 12, 0, 0, 0, 0, 0, 0, 0, 1};
    uint16_t vars[RTDE_STATE_VARS];
    uint8_t *pkg = (uint8_t *)packet_words;
    size_t k;
    int ok;
    urrt_rtde_init(&ram.r.rtde);
    (void)rtde_types(pkg, names, count, vars);
    ok = urrt_rtde_begin(&ram.r.rtde, vars, count, 0.0) == URRT_OK;
    pkg[3] = 1;
    ok = ok && rtde_reply(pkg, 'V', 1) == URRT_RTDE_EV_PROTOCOL;
    for (k = 0; k < 16; k++) {
        pkg[3 + k] = version[k];
    }
    ok = ok && rtde_reply(pkg, 'v', 16) == URRT_RTDE_EV_CONTROLLER;
    pkg[3] = 1;
    ok = ok && rtde_reply(pkg, 'O', rtde_types(pkg, names, count, vars)) == URRT_RTDE_EV_RECIPE;
    pkg[3] = 1;
    ok = ok && rtde_reply(pkg, 'S', 1) == URRT_RTDE_EV_STARTED && ram.r.rtde.data_size == size;
    if (!ok) {
        target_puts("bench: the RTDE handshake failed\n");
        target_exit(2);
    }
    for (k = 4; k < size; k++) {
        pkg[k] = v1116->packet[k];
    }
    pkg[0] = (uint8_t)(size >> 8);
    pkg[1] = (uint8_t)size;
    pkg[2] = 'U';
    pkg[3] = 1;
}

/* A read that holds one whole data package (4-byte aligned, as a TCP
 * stack's buffer) fed to the session, to its data event: what a firmware
 * runs per package, timed as one call (its arguments set up), as the other
 * operations are. */
static urrt_rtde_event feed_ev;
static size_t feed_used;

static int rtde_feed(const char *name, size_t size)
{
    uint32_t ticks;
    int sink = 0;
    TIMED(ticks, sink += urrt_rtde_feed(&ram.r.rtde, (const uint8_t *)packet_words, size, &feed_used, &feed_ev, &st,
                                         &ram.r.vals));
    if (sink != URRT_RTDE_EV_DATA || feed_used != size) {
        target_puts("bench: the feed of a whole data package gave no data event\n");
        target_exit(2);
    }
    report(name, ticks);
    return sink;
}

/* The STATE recipe: the decode of its package (urrt_rtde_decode), and its
 * feed; then the small recipe's feed. */
static int bench_rtde(const tv_vector *v1116)
{
    uint32_t ticks;
    int sink = 0;
    rtde_session(v1116, rtde_state_names, RTDE_STATE_VARS, RTDE_STATE_SIZE);
    TIMED(ticks, sink += urrt_rtde_decode(&ram.r.rtde, (const uint8_t *)packet_words, RTDE_STATE_SIZE, &st,
                                          &ram.r.vals));
    report("rtde_decode_state", ticks);
    sink += rtde_feed("rtde_feed_state", RTDE_STATE_SIZE);
    rtde_session(v1116, rtde_small_names, RTDE_SMALL_VARS, RTDE_SMALL_SIZE);
    sink += rtde_feed("rtde_feed_small", RTDE_SMALL_SIZE);
    return sink;
}

#ifdef BENCH_PLCIN
/* ---- the PLC's answer: one RPDO to its input data package ------------------------
 * tests/lib/co_fixture.h's node with RPDOs (RPDO1 0x20A: 0x2200 sub 1 INTEGER16,
 * sub 2 a BOOLEAN, sub 3 UNSIGNED32, the node's variables 2, 3, 4), operational;
 * an input recipe of three registers (an INT32 from the INTEGER16, a BOOL, the
 * UINT32 bit-register word from the UNSIGNED32 as a mask) accepted in a streaming
 * session; timed: the RPDO to the node (urrt_co_on_frame), lib's look
 * (urrt_plcin_node: the take and the change), urrt_plcin_due and the package
 * (urrt_rtde_in_package): what a firmware runs from the CAN receive interrupt's
 * frame to the bytes for the TCP stack. */
static urrt_co bench_node;
static urrt_cantx bench_tx;
static urrt_cantx_frame_state bench_frame_states[2];
static urrt_cantx_robot bench_robots[1];
static double bench_values[8];
static urrt_co_tpdo_state bench_tpdo_states[2];
static urrt_co_rpdo_state bench_rpdo_states[2];
static urrt_co_consumer bench_consumer_states[2];
static uint32_t bench_vars[CO_FIXTURE_RX_VARS];
static uint64_t bench_written[CO_FIXTURE_RX_VARS];
static urrt_co_rx_storage bench_storage;
static urrt_rtde_in bench_in;
static urrt_plcin bench_plcin;
static uint8_t bench_package[URRT_RTDE_IN_PACKAGE_MAX];

static const urrt_can_signal plcin_signals[3] = {
    {1, 0, -1000, 1000, 0, 0, 16, URRT_CAN_INTEL, URRT_CAN_SIGNED, 0},
    {1, 0, 0, 1, 0, 16, 8, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 0},
    {1, 0, 0, 4294967295.0, 0, 24, 32, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, URRT_CAN_SIG_MASK(0)},
};
static const uint16_t plcin_regs[3] = {URRT_RTDE_V_INPUT_INT_REGISTER + 24, URRT_RTDE_V_INPUT_BIT_REGISTER + 0,
                                       URRT_RTDE_V_INPUT_BIT_REGISTERS0_TO_31};
static const urrt_plcin_desc plcin_desc = {plcin_signals, plcin_regs, plcin_regs, 3, 3, 7, 0, 0x20A, 100,
                                           URRT_PLCIN_STOP, 0, 0};

static void bench_emit(void *ctx, const urrt_can_frame *f, uint64_t now_us)
{
    (void)ctx, (void)f, (void)now_us;
}

/* The controller's reply to what the session asks (the bench's own): the event. */
static int plcin_reply(uint8_t *pkg, uint8_t type, size_t n)
{
    urrt_rtde_event ev;
    size_t used;
    pkg[0] = (uint8_t)((n + 3u) >> 8);
    pkg[1] = (uint8_t)(n + 3u);
    pkg[2] = type;
    while (urrt_rtde_in_output(&ram.r.rtde, &bench_in, 1, (uint8_t *)copy_words, sizeof copy_words) > 0) {
    }
    return urrt_rtde_in_feed(&ram.r.rtde, &bench_in, 1, pkg, n + 3u, &used, &ev, &st, &ram.r.vals);
}

static int bench_plcin_rpdo(void)
{
    static const uint8_t start[2] = {0x01, NODE};
    static const uint8_t rpdo[7] = {0xE8, 0x03, 0x01, 0x0F, 0x00, 0x00, 0x00};
    static const uint8_t version[16] = {0, 0, 0, 5, 0, 0, 0, 12, 0, 0, 0, 0, 0, 0, 0, 1};
    static const char types[] = "\x02INT32,BOOL,UINT32";
    const urrt_plcin_rpdo r = {&bench_node, 2, 0};
    uint8_t *pkg = (uint8_t *)packet_words;
    uint16_t ts = (uint16_t)URRT_RTDE_V_TIMESTAMP;
    urrt_plcin_look look;
    uint32_t ticks;
    size_t bad, k;
    int sink = 0, ok;
    bench_storage.rpdos = bench_rpdo_states;
    bench_storage.consumers = bench_consumer_states;
    bench_storage.written_us = bench_written;
    ok = urrt_cantx_init(&bench_tx, &tables, bench_frame_states, bench_robots, bench_values, 8, NULL, NULL) == 0;
    ok = ok && urrt_co_init_rx(&bench_node, &co_fixture_rx_node, &bench_tx, bench_tpdo_states, bench_vars,
                               CO_FIXTURE_RX_VARS, &bench_storage, &bad) == 0;
    (void)urrt_co_start(&bench_node, 0, bench_emit, NULL);
    urrt_co_on_frame(&bench_node, 0x000, 0, start, 2, 1000, bench_emit, NULL);
    /* A session of one output (the timestamp) and the input recipe, streaming. */
    urrt_rtde_init(&ram.r.rtde);
    ok = ok && urrt_rtde_in_init(&bench_in, plcin_regs, 3) == URRT_OK;
    ok = ok && urrt_rtde_begin(&ram.r.rtde, &ts, 1, 0.0) == URRT_OK;
    urrt_rtde_in_begin(&bench_in, 1);
    urrt_plcin_init(&bench_plcin);
    pkg[3] = 1;
    ok = ok && plcin_reply(pkg, 'V', 1) == URRT_RTDE_EV_PROTOCOL;
    for (k = 0; k < 16; k++) {
        pkg[3 + k] = version[k];
    }
    ok = ok && plcin_reply(pkg, 'v', 16) == URRT_RTDE_EV_CONTROLLER;
    pkg[3] = 1;
    for (k = 0; k < 6; k++) {
        pkg[4 + k] = (uint8_t)"DOUBLE"[k];
    }
    ok = ok && plcin_reply(pkg, 'O', 7) == URRT_RTDE_EV_RECIPE;
    for (k = 0; k + 1 < sizeof types; k++) {
        pkg[3 + k] = (uint8_t)types[k];
    }
    ok = ok && plcin_reply(pkg, 'I', sizeof types - 1) == URRT_RTDE_EV_INPUTS;
    pkg[3] = 1;
    ok = ok && plcin_reply(pkg, 'S', 1) == URRT_RTDE_EV_STARTED && urrt_rtde_in_ready(&ram.r.rtde, &bench_in);
    if (!ok) {
        target_puts("bench: the node or the RTDE session with an input recipe did not start\n");
        target_exit(2);
    }
    TIMED(ticks, {
        urrt_co_on_frame(&bench_node, 0x20A, 0, rpdo, 7, 2000, bench_emit, NULL);
        urrt_plcin_node(&plcin_desc, &r, &bench_plcin, &bench_in, 2000, &look);
        if (urrt_plcin_due(&plcin_desc, &bench_plcin, true, 1, 2000, 100000)) {
            sink += urrt_rtde_in_package(&ram.r.rtde, &bench_in, bench_package, sizeof bench_package);
        }
    });
    if (sink != 13 || !look.took || bench_package[3] != 2 || bench_package[12] != 0x0F) {
        target_puts("bench: the RPDO did not become its input data package\n");
        target_exit(2);
    }
    report("plcin_rpdo_to_package", ticks);
    return sink;
}
#endif

int main(void)
{
    int sink = 0;
    const tv_vector *v1116 = vector(1116), *v1220 = vector(1220);

    calibrate();
    sink += bench_decode(v1116, "decode_1116", "swap_copy_1116");
    sink += bench_read10(v1116);
    sink += bench_decode(v1220, "decode_1220", "swap_copy_1220");
    sink += bench_framer(v1116);
    sink += bench_framer_decode(v1116);
    sink += bench_can_pack(v1116);
    sink += bench_rtde(v1116);
#ifdef BENCH_PLCIN
    sink += bench_plcin_rpdo();
#endif
    target_puts("bench: sink ");
    target_put_uint((uint32_t)sink);
    target_puts("\n");
    return 0;
}
