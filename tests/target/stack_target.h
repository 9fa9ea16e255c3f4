/* SPDX-License-Identifier: MIT */
/*
 * Included by test_target.c on Cortex-M: the stack high-water mark of every
 * public lib/ function, painted below the caller's stack pointer before the
 * call and scanned after it, worst over calls that take each function's
 * deepest paths. Printed as "stack: NAME BYTES" lines, which
 * tests/target/stack.py compares with -fstack-usage and docs/footprint.md.
 */

#include "../lib/co_fixture.h"

typedef struct stack_mark {
    const char *name;
    unsigned bytes;
} stack_mark;

#define STACK_FUNCTIONS 93 /* the public functions of lib/ but the RTDE client's (rtde_target.c's) */
static stack_mark stack_marks[STACK_FUNCTIONS];
static unsigned stack_mark_count;

/* fn's mark: the paint below sp, lowest the deepest word it changed. */
static void stack_note(const char *fn, uintptr_t sp, uintptr_t lowest)
{
    unsigned bytes = (unsigned)(sp - lowest);
    unsigned i;
    CHECK(lowest > target_stack_limit(), "the stack reached its limit: raise STACK_SIZE in the board's .ld", fn,
          sp, lowest);
    for (i = 0; i < stack_mark_count && !same_text(stack_marks[i].name, fn); i++) {
    }
    if (i == stack_mark_count) {
        if (i == sizeof stack_marks / sizeof stack_marks[0]) {
            CHECK(0, "too many functions", fn, i, 0);
            return;
        }
        stack_marks[stack_mark_count].name = fn;
        stack_marks[stack_mark_count++].bytes = 0;
    }
    if (bytes > stack_marks[i].bytes) {
        stack_marks[i].bytes = bytes;
    }
}

/* #fn: the API name, also for functions urrt.h renames by URRT_MAX_DOUBLES. */
#define STACK(fn, args)                                                        \
    do {                                                                       \
        uintptr_t sp_ = target_sp();                                           \
        target_stack_paint(sp_);                                               \
        (void)fn args;                                                         \
        stack_note(#fn, sp_, target_stack_lowest_used(sp_));                   \
    } while (0)

/* Filled in place: a struct copy may be a call to memcpy on Cortex-M0. */
static void can_sig(urrt_can_signal *s, unsigned start, unsigned length, unsigned order, unsigned type,
                    double factor)
{
    s->factor = factor;
    s->offset = 0.5;
    s->invalid_raw = 0;
    s->start = (uint16_t)start;
    s->length = (uint8_t)length;
    s->byte_order = (uint8_t)order;
    s->type = (uint8_t)type;
    s->flags = 0;
    urrt_can_signal_range(s, &s->min, &s->max);
}

/* The CAN core's callbacks: leaves that use no stack of their own. */
static void stack_emit(void *ctx, const urrt_can_frame *f, uint64_t now_us)
{
    (void)ctx;
    (void)f;
    (void)now_us;
}

/* The CAN core's storage, for stack_cantx's tables and then the CANopen node's
 * (one set: the Cortex-M0 board has 16 KiB of RAM). */
static urrt_cantx core_tx;
static urrt_cantx_frame_state core_states[2];
static urrt_cantx_robot core_robots[1];
static double core_values[8 + URRT_CANTX_HB_COUNT];

/* The CAN core on the signals below (one 64-byte FD frame) and the heartbeat; the
 * seventh signal is a bit mask, so its field is read as one. */
static void stack_cantx(urrt_can_signal *sigs)
{
    static const urrt_cantx_source srcs[8] = {
        {URRT_CANTX_FIELD, URRT_F_Q_ACTUAL, 0},       {URRT_CANTX_FIELD, URRT_F_QD_ACTUAL, 5},
        {URRT_CANTX_FIELD, URRT_F_TCP_FORCE, 2},      {URRT_CANTX_FIELD, URRT_F_TIME, 0},
        {URRT_CANTX_FIELD, URRT_F_ROBOT_MODE, 0},     {URRT_CANTX_FIELD, URRT_F_SAFETY_MODE, 0},
        {URRT_CANTX_FIELD_MASK, URRT_F_DIGITAL_INPUT_BITS, 0}, {URRT_CANTX_FIELD, URRT_F_Q_TARGET, 3},
    };
    static urrt_cantx_frame frames_fd[2];
    static urrt_cantx_tables tables_fd;
    static urrt_can_scale scales[8 + URRT_CANTX_HB_COUNT];
    static urrt_cantx_link link;
    urrt_can_frame out;
    size_t z1, z2;
    frames_fd[0].signals = sigs;
    frames_fd[0].sources = srcs;
    frames_fd[0].signal_count = 8;
    frames_fd[0].len = 64;
    frames_fd[0].flags = URRT_CANTX_FD;
    frames_fd[0].id = 0x123;
    frames_fd[0].period_us = 10000;
    frames_fd[0].stale_after_us = 100000;
    frames_fd[1].signals = urrt_cantx_heartbeat_signals;
    frames_fd[1].sources = urrt_cantx_heartbeat_sources;
    frames_fd[1].signal_count = URRT_CANTX_HB_COUNT;
    frames_fd[1].len = URRT_CANTX_HB_LEN;
    frames_fd[1].id = 0x700;
    frames_fd[1].period_us = 100000;
    frames_fd[1].stale_after_us = 100000;
    frames_fd[1].stale = URRT_CANTX_STALE_IGNORE;
    frames_fd[1].fill = urrt_cantx_heartbeat_fill;
    tables_fd.frames = frames_fd;
    tables_fd.frame_count = 2;
    tables_fd.robot_count = 1;
    tables_fd.startup_us = 5000000;
    link.bus_off = 1;
    STACK(urrt_cantx_strerror, (URRT_CANTX_E_POLICY));
    STACK(urrt_cantx_value_count, (&tables_fd));
    STACK(urrt_cantx_mask_value, (UINT64_C(0x8000000000000001)));
    STACK(urrt_cantx_init,
          (&core_tx, &tables_fd, core_states, core_robots, core_values, 8 + URRT_CANTX_HB_COUNT, &z1, &z2));
    /* Deepest paths: a first packet starts the schedule (packing every frame);
     * a heartbeat after a packet packs the frames it took. */
    STACK(urrt_cantx_on_packet, (&core_tx, 0, &st, 2000));
    STACK(urrt_cantx_start, (&core_tx, 1000));
    STACK(urrt_cantx_set_link, (&core_tx, &link));
    STACK(urrt_cantx_on_packet, (&core_tx, 0, &st, 2000));
    STACK(urrt_cantx_run, (&core_tx, 2000, stack_emit, NULL));
    urrt_cantx_on_packet(&core_tx, 0, &st, 3000); /* catch-up's first frame packs new values */
    STACK(urrt_cantx_catch_up, (&core_tx, 250000, stack_emit, NULL));
    STACK(urrt_cantx_on_packet, (&core_tx, 0, &st, 255000));
    STACK(urrt_cantx_gateway_state, (&core_tx, 1, 260000));
    STACK(urrt_cantx_heartbeat_fill, (&core_tx, 1, 260000, false, core_values + 8));
    STACK(urrt_cantx_on_packet, (&core_tx, 0, &st, 256000));
    /* The run-time changes a CANopen node makes. A trigger packs the frame's
     * values of the latest packet, if no heartbeat packed them to report
     * clamping: unprepared here, prepared below. */
    STACK(urrt_cantx_gate, (&core_tx, 0, false));
    STACK(urrt_cantx_trigger, (&core_tx, 0, 258000, stack_emit, NULL));
    STACK(urrt_cantx_gate, (&core_tx, 0, true));
    urrt_cantx_on_packet(&core_tx, 0, &st, 259000);
    STACK(urrt_cantx_peek, (&core_tx, 1, 260000, &out));
    STACK(urrt_cantx_robot_state, (&core_tx, 0, 260000, 100000)); /* fresh data: judged by its age */
    STACK(urrt_cantx_set_id, (&core_tx, 0, 0x124));
    STACK(urrt_cantx_set_period, (&core_tx, 0, 20000, 260000));
    STACK(urrt_cantx_prepare, (&core_tx, scales, 8 + URRT_CANTX_HB_COUNT));
    urrt_cantx_on_packet(&core_tx, 0, &st, 261000);
    STACK(urrt_cantx_trigger, (&core_tx, 0, 261000, stack_emit, NULL));
    STACK(urrt_cantx_robot_link, (&core_tx, 0, false));
    STACK(urrt_cantx_deadline, (&core_tx));
    STACK(urrt_cantx_fresh, (&core_tx, 0, 260000, 100000));
    STACK(urrt_cantx_state_name, (URRT_CANTX_DATA_STALE));
    CHECK(core_tx.frames[0].sent > 0 && core_tx.frames[1].sent > 0, "CAN core frames sent in the stack test",
          "stack", core_tx.frames[0].sent, core_tx.frames[1].sent);
}

/* An SDO request to the fixture's node. */
static void stack_sdo(urrt_co *co, uint8_t cmd, uint16_t index, uint8_t sub, uint32_t value, uint64_t now_us)
{
    uint8_t req[8];
    unsigned i;
    req[0] = cmd;
    req[1] = (uint8_t)index;
    req[2] = (uint8_t)(index >> 8);
    req[3] = sub;
    for (i = 0; i < 4; i++) {
        req[4 + i] = (uint8_t)(value >> (8 * i));
    }
    STACK(urrt_co_on_frame, (co, 0x600 + NODE, 0, req, 8, now_us, stack_emit, NULL));
}

/* The CANopen node of tests/lib/co_fixture.h over the CAN core's storage,
 * initialised again for the fixture's tables, on the decoded packet in st:
 * every urrt_co_* call, urrt_co_on_frame on each
 * kind of frame (an SDO upload of a robot value packs its frame, a SYNC
 * sends a TPDO, a write of a TPDO's parameters moves its id and period),
 * urrt_co_run with the core's frames, a heartbeat and EMCYs. */
/* The node's storage, for both nodes in turn (the Cortex-M0 board's RAM is small). */
static urrt_co stack_node;
static urrt_co_tpdo_state stack_tpdo_states[2];
static uint32_t stack_vars[CO_FIXTURE_RX_VARS];

static void stack_co(void)
{
    urrt_co *const co_ = &stack_node;
    urrt_co_tpdo_state *const tpdo_states = stack_tpdo_states;
    uint32_t *const vars = stack_vars;
    static const uint8_t nmt_start[2] = {URRT_CO_NMT_START, 0};
    static const uint8_t sync[1] = {1};
    size_t bad;
    urrt_cantx_init(&core_tx, &tables, core_states, core_robots, core_values, 8, NULL, NULL);
    STACK(urrt_co_strerror, (URRT_CO_E_OBJECT));
    STACK(urrt_co_init, (co_, &co_fixture_node, &core_tx, tpdo_states, vars, 2, &bad));
    STACK(urrt_co_start, (co_, 0, stack_emit, NULL));
    urrt_cantx_on_packet(&core_tx, 0, &st, 1000);
    STACK(urrt_co_on_frame, (co_, 0x000, 0, nmt_start, 2, 1000, stack_emit, NULL));
    stack_sdo(co_, 0x40, 0x2000, 1, 0, 1000);             /* a robot value: its frame packed */
    stack_sdo(co_, 0x40, 0x1018, 2, 0, 1000);             /* identity */
    stack_sdo(co_, 0x2B, 0x2100, 0, 500, 1000);           /* a variable */
    stack_sdo(co_, 0x40, 0x1008, 0, 0, 1000);             /* device name: a segmented upload */
    stack_sdo(co_, 0x60, 0, 0, 0, 1000);                  /* its first segment */
    stack_sdo(co_, 0x23, 0x1800, 1, 0x8000018Au, 1000);   /* TPDO1 invalid, */
    stack_sdo(co_, 0x2B, 0x1800, 5, 20, 1000);            /* its event timer, */
    stack_sdo(co_, 0x23, 0x1800, 1, 0x0000019Au, 1000);   /* valid at a new id */
    stack_sdo(co_, 0x2F, 0x1801, 2, 1, 1000);             /* TPDO2 on every SYNC */
    stack_sdo(co_, 0x23, 0x1234, 0, 0, 1000);             /* an abort */
    urrt_cantx_on_packet(&core_tx, 0, &st, 2000); /* new values: the SYNC's TPDO packs them */
    STACK(urrt_co_on_frame, (co_, 0x080, 0, sync, 1, 2000, stack_emit, NULL));
    urrt_cantx_on_packet(&core_tx, 0, &st, 3000); /* and TPDO1's, due since its new id */
    STACK(urrt_co_run, (co_, 3000, stack_emit, NULL));
    STACK(urrt_co_run, (co_, 100000, stack_emit, NULL));  /* stale data: EMCY, heartbeat, TPDO1 */
    STACK(urrt_co_set_error_passive, (co_, true));
    STACK(urrt_co_run, (co_, 200000, stack_emit, NULL));
    STACK(urrt_co_deadline, (co_));
    STACK(urrt_co_state, (co_));
    STACK(urrt_co_state_name, (URRT_CO_STOPPED));
    STACK(urrt_co_error_register, (co_));
    STACK(urrt_co_tpdo_cob_default, (co_, 0));
    STACK(urrt_co_comm_instances, (co_, &urrt_co_comm_table[0]));
    {
        uint32_t ids[URRT_CO_RX_IDS_MAX];
        STACK(urrt_co_rx_ids, (co_, ids));
    }
    {
        urrt_co_value v;
        uint32_t low, high;
        STACK(urrt_co_comm_read, (co_, &urrt_co_comm_table[0], 0, 0, &v)); /* 0x1000 */
        STACK(urrt_co_comm_name, (&urrt_co_comm_table[urrt_co_comm_count - 1u])); /* the longest walk */
        STACK(urrt_co_comm_limits, (&urrt_co_comm_table[0], &low, &high));
    }
    CHECK(urrt_co_state(co_) == URRT_CO_OPERATIONAL && urrt_co_error_register(co_) != 0,
          "CANopen node operational with an error in the stack test", "stack", urrt_co_state(co_),
          urrt_co_error_register(co_));
}

/* The node with RPDOs and a consumer heartbeat (co_fixture_rx_node): its
 * init, the SDO writes of 0x1400 and 0x1016, RPDOs acted on at once and at a
 * SYNC, a short one, heartbeats, and runs that raise and reset the receiving
 * side's EMCYs; each urrt_co_ function's mark is the worst of both nodes. */
static void stack_co_rx(void)
{
    urrt_co *const co_ = &stack_node;
    urrt_co_tpdo_state *const tpdo_states = stack_tpdo_states;
    uint32_t *const vars = stack_vars;
    static urrt_co_rpdo_state rpdo_states[2];
    static urrt_co_consumer consumer_states[2];
    static uint64_t written[CO_FIXTURE_RX_VARS];
    static urrt_co_rx_storage rx = {.rpdos = rpdo_states, .consumers = consumer_states, .written_us = written};
    static const uint8_t nmt_start[2] = {URRT_CO_NMT_START, 0};
    static const uint8_t rpdo1[7] = {0xF4, 0x01, 0x01, 0x78, 0x56, 0x34, 0x12};
    static const uint8_t rpdo2[4] = {0x9C, 0x00, 0x10, 0x00};
    static const uint8_t heartbeat[1] = {0x05};
    size_t bad;
    urrt_cantx_init(&core_tx, &tables, core_states, core_robots, core_values, 8, NULL, NULL);
    STACK(urrt_co_init_rx, (co_, &co_fixture_rx_node, &core_tx, tpdo_states, vars, CO_FIXTURE_RX_VARS, &rx, &bad));
    STACK(urrt_co_start, (co_, 0, stack_emit, NULL));
    STACK(urrt_co_on_frame, (co_, 0x000, 0, nmt_start, 2, 1000, stack_emit, NULL));
    stack_sdo(co_, 0x23, 0x1400, 1, 0x8000020Au, 1000); /* RPDO1 off, */
    stack_sdo(co_, 0x23, 0x1400, 1, 0x0000020Au, 1000); /* on again */
    stack_sdo(co_, 0x2B, 0x1400, 5, 50, 1000);          /* its deadline */
    stack_sdo(co_, 0x23, 0x1016, 1, 0x00010014u, 1000); /* node 1, 20 ms */
    stack_sdo(co_, 0x23, 0x1016, 2, 0x00010014u, 1000); /* node 1 twice: an abort */
    stack_sdo(co_, 0x40, 0x1600, 3, 0, 1000);           /* a mapping entry */
    stack_sdo(co_, 0x2B, 0x2200, 1, 500, 1000);         /* a variable an RPDO writes */
    STACK(urrt_co_on_frame, (co_, 0x20A, 0, rpdo1, 7, 2000, stack_emit, NULL));    /* at once */
    STACK(urrt_co_on_frame, (co_, 0x20A, 0, rpdo1, 3, 2000, stack_emit, NULL));    /* too short */
    STACK(urrt_co_on_frame, (co_, 0x30A, 0, rpdo2, 4, 2000, stack_emit, NULL));    /* kept, */
    STACK(urrt_co_on_frame, (co_, 0x080, 0, NULL, 0, 3000, stack_emit, NULL));     /* acted on at the SYNC */
    STACK(urrt_co_on_frame, (co_, 0x701, 0, heartbeat, 1, 3000, stack_emit, NULL));
    STACK(urrt_co_rpdo_status, (co_, 0, 3000)); /* the heartbeat watched, RPDO1's deadline too */
    STACK(urrt_co_run, (co_, 3000, stack_emit, NULL));        /* EMCY 0x8210 */
    STACK(urrt_co_deadline, (co_));
    STACK(urrt_co_run, (co_, 60000, stack_emit, NULL));       /* 0x8250, 0x8130 */
    STACK(urrt_co_on_frame, (co_, 0x20A, 0, rpdo1, 7, 61000, stack_emit, NULL)); /* ends 0x8210, 0x8250 */
    STACK(urrt_co_run, (co_, 61000, stack_emit, NULL));
    STACK(urrt_co_rpdo_status, (co_, 0, 61000));
    STACK(urrt_co_rpdo_cob_default, (co_, 1));
    STACK(urrt_co_rx_strerror, (URRT_CO_E_CONSUMER));
    STACK(urrt_co_comm_instances, (co_, &urrt_co_comm_table[urrt_co_comm_count - 1u]));
    {
        uint32_t ids[URRT_CO_RX_IDS_MAX];
        STACK(urrt_co_rx_ids, (co_, ids));
    }
    CHECK(vars[5] == 0x9C && co_->values_refused == 0 && urrt_co_error_register(co_) != 0,
          "the CANopen node with RPDOs took them in the stack test", "stack", vars[5], co_->values_refused);
}

/* Eight CAN signals of every byte order and type, a bit mask among them, over one
 * 64-byte FD frame. */
static void stack_can_signals(urrt_can_signal *sigs)
{
    can_sig(&sigs[0], 0, 16, URRT_CAN_INTEL, URRT_CAN_SIGNED, 0.0002);
    can_sig(&sigs[1], 23, 16, URRT_CAN_MOTOROLA, URRT_CAN_UNSIGNED, 0.01);
    can_sig(&sigs[2], 32, 32, URRT_CAN_INTEL, URRT_CAN_FLOAT32, 1.0);
    can_sig(&sigs[3], 64, 64, URRT_CAN_INTEL, URRT_CAN_FLOAT64, 2.0);
    can_sig(&sigs[4], 135, 64, URRT_CAN_MOTOROLA, URRT_CAN_SIGNED, 0.001);
    can_sig(&sigs[5], 192, 63, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 3.0);
    can_sig(&sigs[6], 256, 1, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1.0);
    sigs[6].offset = 0.0; /* a bit mask: bit 0 of the mask, never scaled */
    sigs[6].flags = URRT_CAN_SIG_MASK(0);
    can_sig(&sigs[7], 300, 12, URRT_CAN_MOTOROLA, URRT_CAN_SIGNED, -0.5);
}

/* The field tables, controllers, decode, random access, encoder and enums, on
 * a 1.x packet (v1) and a 3.x one with extra columns (v3). */
static void stack_decode(const tv_vector *v1, const tv_vector *v3)
{
    double d;
    uint64_t raw;
    size_t len;
    const urrt_controller *found[2];
    uint32_t u32;
    int64_t i64;
    STACK(urrt_strerror, (URRT_E_RANGE));
    STACK(urrt_field, (URRT_F_Q_ACTUAL));
    STACK(urrt_field_find, ("payload_inertia", 15));
    STACK(urrt_field_column, (URRT_F_TOOL_ACCELEROMETER, URRT_GEN_UNKNOWN));
    STACK(urrt_field_values, (&st, URRT_F_Q_ACTUAL));
    STACK(urrt_controllers, (&len));
    STACK(urrt_controller_of_length, (1116));
    STACK(urrt_controller_find, ("5.11.2.108", 10, found, 2, &u32));
    STACK(urrt_controller_find, ("1.6", 3, found, 2, &u32));
    STACK(urrt_period_min_us, (1108));
    STACK(urrt_time_us, (123456.789, &i64));
    STACK(urrt_time_us, (-0.0, &i64));
    STACK(urrt_packet_length, (v3->packet, v3->length));
    STACK(urrt_generation_of, (v3->length));
    STACK(urrt_versions_of, (v3->length));
    STACK(urrt_decode, (v1->packet, v1->length, &st));
    STACK(urrt_decode, (v3->packet, v3->length, &st));
    STACK(urrt_decode, (v3->packet, 3, &st));
    STACK(urrt_read, (v1->packet, v1->length, URRT_F_TOOL_ACCELEROMETER, 2, &d));
    STACK(urrt_read, (v3->packet, v3->length, URRT_F_PAYLOAD_INERTIA, 5, &d));
    STACK(urrt_read_column, (v3->packet, v3->length, 150, &d));
    STACK(urrt_read_column_bits, (v3->packet, v3->length, 150, &raw));
    STACK(urrt_encode, (&st, v3->length, scratch, sizeof scratch_words));
    urrt_decode(v1->packet, v1->length, &st);
    STACK(urrt_encode, (&st, v1->length, scratch, sizeof scratch_words));
    STACK(urrt_state_clear, (&st));
    STACK(urrt_bitmask, (37.0, &raw));
    STACK(urrt_enum_entries, (URRT_ENUM_JOINT_MODE, &len));
    STACK(urrt_enum_name, (URRT_ENUM_JOINT_MODE, 255.0));
    STACK(urrt_enum_name, (URRT_ENUM_ROBOT_MODE, -1.0));
    STACK(urrt_field_enum, (URRT_F_ROBOT_MODE, URRT_GEN_1X));
}

/* The framer: a packet in pieces, whole, a new length, and garbage. */
static void stack_framer(const tv_vector *v1, const tv_vector *v3)
{
    size_t used, len;
    STACK(urrt_framer_init, (&framer));
    STACK(urrt_framer_reset, (&framer));
    STACK(urrt_framer_feed, (&framer, v3->packet, 3, &used));
    STACK(urrt_framer_feed, (&framer, v3->packet + 3, 100, &used));
    STACK(urrt_framer_feed, (&framer, v3->packet + 103, v3->length - 103, &used));
    STACK(urrt_framer_packet, (&framer, &len));
    STACK(urrt_framer_feed, (&framer, v3->packet, v3->length, &used));
    STACK(urrt_framer_feed, (&framer, v1->packet, v1->length, &used)); /* a new length: looked up */
    STACK(urrt_framer_feed, (&framer, (const uint8_t *)"\1\2\3\4\5\6\7", 7, &used));
    STACK(urrt_framer_finish, (&framer));
}

/* lib/urrt_can: every call on each of the signals, and on all of them as a frame. */
static void stack_can(const char *name, const urrt_can_signal *sigs)
{
    static const double values[8] = {1.5, -2.25, 1e30, -1e30, 0.0, 3.75, 100.0, -7.0};
    static uint8_t outcomes[8];
    static urrt_can_scale scale;
    uint8_t frame[64];
    double d, lo, hi;
    uint64_t raw;
    unsigned u1, u2, u3, i;
    size_t z1, z2;
    STACK(urrt_can_strerror, (URRT_CAN_E_OVERLAP));
    STACK(urrt_can_length_valid, (48, true));
    STACK(urrt_can_len_to_dlc, (48));
    STACK(urrt_can_dlc_to_len, (14));
    STACK(urrt_can_fd_length_round_up, (33));
    STACK(urrt_can_id_valid, (0x1FFFFFFF, true));
    STACK(urrt_can_frame_bits, (64, true, true, &u1, &u2));
    STACK(urrt_can_frame_bits, (8, false, false, &u1, &u2));
    for (i = 0; i < 8; i++) {
        STACK(urrt_can_signal_check, (&sigs[i], 64));
        STACK(urrt_can_signal_span, (&sigs[i], &u1, &u2, &u3));
        STACK(urrt_can_signal_range, (&sigs[i], &lo, &hi));
        STACK(urrt_can_to_raw, (&sigs[i], values[i], &raw));
        STACK(urrt_can_to_raw, (&sigs[i], -values[i] * 1e10, &raw));
        STACK(urrt_can_from_raw, (&sigs[i], 0x8000000000000001ull));
        STACK(urrt_can_put_raw, (&sigs[i], 0xFFFFFFFFFFFFFFFFull, frame, 64));
        STACK(urrt_can_get_raw, (&sigs[i], frame, 64, &raw));
        STACK(urrt_can_pack, (&sigs[i], values[i], frame, 64));
        STACK(urrt_can_unpack, (&sigs[i], frame, 64, &d));
    }
    for (i = 0; i < 8; i++) {
        STACK(urrt_can_pack_checked, (&sigs[i], values[i], frame));
        STACK(urrt_can_put_raw_checked, (&sigs[i], 0x5555555555555555ull, frame));
        STACK(urrt_can_scale_prepare, (&sigs[i], &scale));
        STACK(urrt_can_to_raw_scaled, (&sigs[i], &scale, -values[i] * 1e10, &raw));
        STACK(urrt_can_pack_scaled, (&sigs[i], &scale, values[i], frame));
    }
    STACK(urrt_can_layout_check, (sigs, 8, 64, &z1, &z2));
    STACK(urrt_can_pack_frame, (sigs, values, 8, frame, 64, outcomes));
    CHECK(urrt_can_layout_check(sigs, 8, 64, &z1, &z2) == 0, "CAN layout of the stack test", name, z1, z2);
}

static void test_stack(void)
{
    static const char name[] = "stack";
    static urrt_can_signal sigs[8];
    unsigned i;
    const tv_vector *v1 = &tv_vectors[0], *v3 = &tv_vectors[0];

    for (i = 0; i < tv_vector_count; i++) {
        if (tv_vectors[i].generation == URRT_GEN_1X) {
            v1 = &tv_vectors[i];
        } else if (tv_vectors[i].generation == URRT_GEN_3X && tv_vectors[i].extra > 0) {
            v3 = &tv_vectors[i];
        }
    }
    stack_can_signals(sigs);
    stack_decode(v1, v3);
    stack_framer(v1, v3);
    stack_can(name, sigs);
    urrt_decode(v3->packet, v3->length, &st);
    stack_cantx(sigs);
    stack_co();
    stack_co_rx();

    for (i = 0; i < stack_mark_count; i++) {
        target_puts("stack: ");
        target_puts(stack_marks[i].name);
        target_puts(" ");
        target_put_uint(stack_marks[i].bytes);
        target_puts("\n");
    }
    CHECK(stack_mark_count == STACK_FUNCTIONS, "public functions measured", name, stack_mark_count, STACK_FUNCTIONS);
}
