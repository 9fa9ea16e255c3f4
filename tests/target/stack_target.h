/* SPDX-License-Identifier: MIT */
/*
 * Included by test_target.c on Cortex-M: the stack high-water mark of every
 * public lib/ function, painted below the caller's stack pointer before the
 * call and scanned after it, worst over calls that take each function's
 * deepest paths. Printed as "stack: NAME BYTES" lines, which
 * tests/target/stack.py compares with -fstack-usage and docs/footprint.md.
 */

typedef struct stack_mark {
    const char *name;
    unsigned bytes;
} stack_mark;

static stack_mark stack_marks[80];
static unsigned stack_mark_count;

static void stack_note(const char *fn, unsigned bytes)
{
    unsigned i;
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
        stack_note(#fn, (unsigned)(sp_ - target_stack_lowest_used(sp_)));      \
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

/* The CAN core on the signals below (one 64-byte FD frame) and the heartbeat. */
static void stack_cantx(urrt_can_signal *sigs)
{
    static const urrt_cantx_source srcs[8] = {
        {URRT_CANTX_FIELD, URRT_F_Q_ACTUAL, 0},       {URRT_CANTX_FIELD, URRT_F_QD_ACTUAL, 5},
        {URRT_CANTX_FIELD, URRT_F_TCP_FORCE, 2},      {URRT_CANTX_FIELD, URRT_F_TIME, 0},
        {URRT_CANTX_FIELD, URRT_F_ROBOT_MODE, 0},     {URRT_CANTX_FIELD_MASK, URRT_F_DIGITAL_INPUT_BITS, 0},
        {URRT_CANTX_FIELD, URRT_F_SAFETY_MODE, 0},    {URRT_CANTX_FIELD, URRT_F_Q_TARGET, 3},
    };
    static urrt_cantx_frame frames[2];
    static urrt_cantx_tables tables;
    static urrt_cantx_frame_state states[2];
    static urrt_cantx_robot robots[1];
    static double values[8 + URRT_CANTX_HB_COUNT];
    static urrt_cantx tx;
    static urrt_cantx_link link;
    static urrt_can_frame out;
    size_t z1, z2;
    frames[0].signals = sigs;
    frames[0].sources = srcs;
    frames[0].signal_count = 8;
    frames[0].len = 64;
    frames[0].flags = URRT_CANTX_FD;
    frames[0].id = 0x123;
    frames[0].period_us = 10000;
    frames[0].stale_after_us = 100000;
    frames[1].signals = urrt_cantx_heartbeat_signals;
    frames[1].sources = urrt_cantx_heartbeat_sources;
    frames[1].signal_count = URRT_CANTX_HB_COUNT;
    frames[1].len = URRT_CANTX_HB_LEN;
    frames[1].id = 0x700;
    frames[1].period_us = 100000;
    frames[1].stale_after_us = 100000;
    frames[1].stale = URRT_CANTX_STALE_IGNORE;
    frames[1].fill = urrt_cantx_heartbeat_fill;
    tables.frames = frames;
    tables.frame_count = 2;
    tables.robot_count = 1;
    tables.startup_us = 5000000;
    link.bus_off = 1;
    STACK(urrt_cantx_strerror, (URRT_CANTX_E_POLICY));
    STACK(urrt_cantx_value_count, (&tables));
    STACK(urrt_cantx_init, (&tx, &tables, states, robots, values, 8 + URRT_CANTX_HB_COUNT, &z1, &z2));
    /* Deepest paths: a first packet starts the schedule (packing every frame);
     * a heartbeat after a packet packs the frames it took. */
    STACK(urrt_cantx_on_packet, (&tx, 0, &st, 2000));
    STACK(urrt_cantx_start, (&tx, 1000));
    STACK(urrt_cantx_set_link, (&tx, &link));
    STACK(urrt_cantx_on_packet, (&tx, 0, &st, 2000));
    STACK(urrt_cantx_run, (&tx, 2000, stack_emit, NULL));
    urrt_cantx_on_packet(&tx, 0, &st, 3000); /* catch-up's first frame packs new values */
    STACK(urrt_cantx_catch_up, (&tx, 250000, stack_emit, NULL));
    STACK(urrt_cantx_on_packet, (&tx, 0, &st, 255000));
    STACK(urrt_cantx_gateway_state, (&tx, 1, 260000));
    STACK(urrt_cantx_heartbeat_fill, (&tx, 1, 260000, false, values + 8));
    STACK(urrt_cantx_on_packet, (&tx, 0, &st, 256000));
    STACK(urrt_cantx_peek, (&tx, 1, 260000, &out));
    STACK(urrt_cantx_robot_link, (&tx, 0, false));
    STACK(urrt_cantx_deadline, (&tx));
    STACK(urrt_cantx_fresh, (&tx, 0, 260000, 100000));
    STACK(urrt_cantx_state_name, (URRT_CANTX_DATA_STALE));
    CHECK(tx.frames[0].sent > 0 && tx.frames[1].sent > 0, "CAN core frames sent in the stack test", "stack",
          tx.frames[0].sent, tx.frames[1].sent);
}

static void test_stack(void)
{
    static const char name[] = "stack";
    static urrt_can_signal sigs[8];
    static const double values[8] = {1.5, -2.25, 1e30, -1e30, 0.0, 3.75, 100.0, -7.0};
    static uint8_t outcomes[8];
    uint8_t frame[64];
    double d, lo, hi;
    uint64_t raw;
    unsigned u1, u2, u3, i;
    size_t used, len, z1, z2;
    const tv_vector *v1 = &tv_vectors[0], *v3 = &tv_vectors[0];
    const urrt_controller *found[2];
    uint32_t u32;
    int64_t i64;

    for (i = 0; i < tv_vector_count; i++) {
        if (tv_vectors[i].generation == URRT_GEN_1X) {
            v1 = &tv_vectors[i];
        } else if (tv_vectors[i].generation == URRT_GEN_3X && tv_vectors[i].extra > 0) {
            v3 = &tv_vectors[i];
        }
    }
    can_sig(&sigs[0], 0, 16, URRT_CAN_INTEL, URRT_CAN_SIGNED, 0.0002);
    can_sig(&sigs[1], 23, 16, URRT_CAN_MOTOROLA, URRT_CAN_UNSIGNED, 0.01);
    can_sig(&sigs[2], 32, 32, URRT_CAN_INTEL, URRT_CAN_FLOAT32, 1.0);
    can_sig(&sigs[3], 64, 64, URRT_CAN_INTEL, URRT_CAN_FLOAT64, 2.0);
    can_sig(&sigs[4], 135, 64, URRT_CAN_MOTOROLA, URRT_CAN_SIGNED, 0.001);
    can_sig(&sigs[5], 192, 63, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 3.0);
    can_sig(&sigs[6], 256, 1, URRT_CAN_INTEL, URRT_CAN_UNSIGNED, 1.0);
    can_sig(&sigs[7], 300, 12, URRT_CAN_MOTOROLA, URRT_CAN_SIGNED, -0.5);

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
    }
    STACK(urrt_can_layout_check, (sigs, 8, 64, &z1, &z2));
    STACK(urrt_can_pack_frame, (sigs, values, 8, frame, 64, outcomes));
    CHECK(urrt_can_layout_check(sigs, 8, 64, &z1, &z2) == 0, "CAN layout of the stack test", name, z1, z2);
    urrt_decode(v3->packet, v3->length, &st);
    stack_cantx(sigs);

    for (i = 0; i < stack_mark_count; i++) {
        target_puts("stack: ");
        target_puts(stack_marks[i].name);
        target_puts(" ");
        target_put_uint(stack_marks[i].bytes);
        target_puts("\n");
    }
    CHECK(stack_mark_count == 63, "public functions measured", name, stack_mark_count, 63);
}
