/* SPDX-License-Identifier: MIT */
/*
 * urrt: a freestanding decoder for the Universal Robots "RealTime" client
 * interface (TCP ports 30003 and 30013).
 *
 * This header is the API manual. docs/protocol.md is the wire format,
 * docs/security.md says what holds for hostile input.
 *
 * The library is C99 and freestanding: it includes only <stddef.h>,
 * <stdint.h> and <stdbool.h>, never allocates, keeps no globals and does no
 * I/O. Every byte of state lives in structs the caller declares. Vendoring it
 * means copying lib/urrt.h and lib/urrt.c (and lib/urrt_can.[ch] for CAN
 * packing) into a firmware tree; no build system is needed.
 *
 * The wire format in one paragraph: each message is a big-endian int32
 * holding the total message size (those 4 bytes included), then
 * (size - 4) / 8 big-endian IEEE-754 doubles. There is no type, version,
 * sync or checksum field: the size alone tells the layouts apart, and the
 * layout of 1.x controllers differs from 3.x/5.x at some columns. Columns
 * are numbered from 1 as in UR's tables ("Gnuplot col."), so column 1 is the
 * controller time, the first double after the size.
 */
#ifndef URRT_H
#define URRT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Library version, and separately the newest wire layout it understands. */
#define URRT_VERSION_MAJOR 0
#define URRT_VERSION_MINOR 1
#define URRT_VERSION_PATCH 0
#define URRT_VERSION_STRING "0.1.0"
/* Controller software 5.10: 152 columns (1220 bytes). */
#define URRT_WIRE_VERSION 510
#define URRT_WIRE_COLUMNS 152

/*
 * Size bounds. URRT_MAX_DOUBLES bounds what a packet may hold and so the
 * framer's buffer; a firmware that knows its controller may lower it (not
 * below 152, which would cut the newest known layout), or raise it to accept
 * controllers that append more columns.
 */
#ifndef URRT_MAX_DOUBLES
#define URRT_MAX_DOUBLES 256
#endif
#define URRT_HEADER_SIZE 4
#define URRT_PACKET_MIN (URRT_HEADER_SIZE + 8)
#define URRT_PACKET_MAX (URRT_HEADER_SIZE + 8 * URRT_MAX_DOUBLES)
/* Bytes an encoder needs for the newest known layout. */
#define URRT_PACKET_KNOWN_MAX (URRT_HEADER_SIZE + 8 * URRT_WIRE_COLUMNS)

/* Results. Negative values are errors; zero or positive values are success
 * and carry a count where the function says so. */
enum urrt_result {
    URRT_OK = 0,
    URRT_E_ARG = -1,           /* a null pointer or an argument out of its domain */
    URRT_E_TRUNCATED = -2,     /* fewer bytes than the header or the declared size */
    URRT_E_SIZE_SMALL = -3,    /* declared size below URRT_PACKET_MIN (zero or negative included) */
    URRT_E_SIZE_ALIGN = -4,    /* declared size is not 4 + 8n */
    URRT_E_SIZE_LARGE = -5,    /* declared size past URRT_PACKET_MAX */
    URRT_E_ABSENT = -6,        /* the field is not in a packet of this length */
    URRT_E_RANGE = -7,         /* element or column index out of range */
    URRT_E_NOT_BITMASK = -8,   /* value is neither encoding of a bit mask */
    URRT_E_NO_SPACE = -9,      /* output buffer too small */
    URRT_E_UNKNOWN_FIELD = -10 /* no field of that name */
};

/* A short English text for a urrt_result ("ok" for zero or positive). */
const char *urrt_strerror(int result);

/* Controller generations. The numbers differ between them at columns 50-67
 * and 74-85, and in the robot mode enumeration. */
typedef enum urrt_generation {
    URRT_GEN_UNKNOWN = 0, /* 102..129 doubles: only columns both share are decoded */
    URRT_GEN_1X = 1,      /* CB1/CB2, at most 101 doubles (812 bytes) */
    URRT_GEN_3X = 3       /* CB3 and e-series (3.x, 5.x), at least 130 doubles (1044 bytes) */
} urrt_generation;

/*
 * The field table, written once. Each row:
 *   X(ID, name, count, col_1x, col_3x, unit, since, description)
 * ID/name: the field id suffix (URRT_F_ID) and the struct member name.
 * count:   number of doubles.
 * col_1x:  first column in 1.x packets, 0 where 1.x has no such field.
 * col_3x:  first column in 3.x/5.x packets, 0 where 3.x/5.x has no such field.
 * unit:    SI unit, "" where UR gives none, "enum" or "bits" for the coded ones.
 * since:   first controller software version that sends it.
 *
 * Rows with col_3x != 0 come first and in column order: the struct below lays
 * them out exactly as the 3.x/5.x grid, which lets the decoder fill it in one
 * pass. Rows only 1.x has come last.
 */
#define URRT_FIELDS(X) \
    X(TIME, time, 1, 1, 1, "s", "1.5", "Time elapsed since the controller was started") \
    X(Q_TARGET, q_target, 6, 2, 2, "rad", "1.5", "Target joint positions") \
    X(QD_TARGET, qd_target, 6, 8, 8, "rad/s", "1.5", "Target joint velocities") \
    X(QDD_TARGET, qdd_target, 6, 14, 14, "rad/s^2", "1.5", "Target joint accelerations") \
    X(I_TARGET, i_target, 6, 20, 20, "A", "1.5", "Target joint currents") \
    X(M_TARGET, m_target, 6, 26, 26, "Nm", "1.5", "Target joint moments (torques)") \
    X(Q_ACTUAL, q_actual, 6, 32, 32, "rad", "1.5", "Actual joint positions") \
    X(QD_ACTUAL, qd_actual, 6, 38, 38, "rad/s", "1.5", "Actual joint velocities") \
    X(I_ACTUAL, i_actual, 6, 44, 44, "A", "1.5", "Actual joint currents") \
    X(I_CONTROL, i_control, 6, 0, 50, "A", "3.0", "Joint control currents") \
    X(TOOL_VECTOR_ACTUAL, tool_vector_actual, 6, 0, 56, "m, rad", "3.0", "Actual tool pose x, y, z, rx, ry, rz (rotation vector)") \
    X(TCP_SPEED_ACTUAL, tcp_speed_actual, 6, 0, 62, "m/s, rad/s", "3.0", "Actual speed of the tool in Cartesian coordinates") \
    X(TCP_FORCE, tcp_force, 6, 68, 68, "N, Nm", "1.5", "Generalised forces in the TCP") \
    X(TOOL_VECTOR_TARGET, tool_vector_target, 6, 0, 74, "m, rad", "3.0", "Target tool pose x, y, z, rx, ry, rz (rotation vector)") \
    X(TCP_SPEED_TARGET, tcp_speed_target, 6, 0, 80, "m/s, rad/s", "3.0", "Target speed of the tool in Cartesian coordinates") \
    X(DIGITAL_INPUT_BITS, digital_input_bits, 1, 86, 86, "bits", "1.5", "Digital inputs as a bit mask") \
    X(MOTOR_TEMPERATURES, motor_temperatures, 6, 87, 87, "degC", "1.5", "Temperature of each joint") \
    X(CONTROLLER_TIMER, controller_timer, 1, 93, 93, "", "1.5", "Controller realtime thread execution time") \
    X(TEST_VALUE, test_value, 1, 94, 94, "", "1.5", "Used by Universal Robots software only") \
    X(ROBOT_MODE, robot_mode, 1, 95, 95, "enum", "1.7", "Robot mode (numbering differs between 1.x and 3.x/5.x)") \
    X(JOINT_MODES, joint_modes, 6, 96, 96, "enum", "1.8", "Joint modes") \
    X(SAFETY_MODE, safety_mode, 1, 0, 102, "enum", "3.0", "Safety mode") \
    X(RESERVED_103, reserved_103, 6, 0, 103, "", "3.0", "Used by Universal Robots software only") \
    X(TOOL_ACCELEROMETER, tool_accelerometer, 3, 50, 109, "m/s^2", "1.7", "Tool x, y, z accelerometer values") \
    X(RESERVED_112, reserved_112, 6, 0, 112, "", "3.0", "Used by Universal Robots software only") \
    X(SPEED_SCALING, speed_scaling, 1, 0, 118, "", "3.0", "Speed scaling of the trajectory limiter") \
    X(LINEAR_MOMENTUM_NORM, linear_momentum_norm, 1, 0, 119, "kg m/s", "3.0", "Norm of Cartesian linear momentum") \
    X(RESERVED_120, reserved_120, 1, 0, 120, "", "3.0", "Used by Universal Robots software only") \
    X(RESERVED_121, reserved_121, 1, 0, 121, "", "3.0", "Used by Universal Robots software only") \
    X(V_MAIN, v_main, 1, 0, 122, "V", "3.0", "Masterboard main voltage") \
    X(V_ROBOT, v_robot, 1, 0, 123, "V", "3.0", "Masterboard robot voltage (48 V)") \
    X(I_ROBOT, i_robot, 1, 0, 124, "A", "3.0", "Masterboard robot current") \
    X(V_ACTUAL, v_actual, 6, 0, 125, "V", "3.0", "Actual joint voltages") \
    X(DIGITAL_OUTPUTS, digital_outputs, 1, 0, 131, "bits", "3.2", "Digital outputs as a bit mask") \
    X(PROGRAM_STATE, program_state, 1, 0, 132, "enum", "3.2", "Program state") \
    X(ELBOW_POSITION, elbow_position, 3, 0, 133, "m", "3.5", "Elbow position x, y, z") \
    X(ELBOW_VELOCITY, elbow_velocity, 3, 0, 136, "m/s", "3.5", "Elbow velocity x, y, z") \
    X(SAFETY_STATUS, safety_status, 1, 0, 139, "enum", "3.10/5.4", "Safety status") \
    X(RESERVED_140, reserved_140, 3, 0, 140, "", "3.14/5.9", "Used by Universal Robots software only") \
    X(PAYLOAD_MASS, payload_mass, 1, 0, 143, "kg", "5.10", "Payload mass") \
    X(PAYLOAD_COG, payload_cog, 3, 0, 144, "m", "5.10", "Payload centre of gravity x, y, z") \
    X(PAYLOAD_INERTIA, payload_inertia, 6, 0, 147, "kg m^2", "5.10", "Payload inertia Ixx, Iyy, Izz, Ixy, Ixz, Iyz") \
    X(UNUSED_53, unused_53, 15, 53, 0, "", "1.5", "Unused (1.x)") \
    X(TOOL_VECTOR, tool_vector, 6, 74, 0, "m, rad", "1.5", "Tool pose x, y, z, rx, ry, rz (1.x; UR says neither actual nor target)") \
    X(TCP_SPEED, tcp_speed, 6, 80, 0, "m/s, rad/s", "1.5", "Tool speed (1.x; UR says neither actual nor target)")

typedef enum urrt_field_id {
#define URRT_X_ID(ID, name, count, c1, c3, unit, since, desc) URRT_F_##ID,
    URRT_FIELDS(URRT_X_ID)
#undef URRT_X_ID
    URRT_FIELD_COUNT
} urrt_field_id;

/* Largest element count of any field (unused_53). */
#define URRT_FIELD_COUNT_MAX 15

typedef struct urrt_field_info {
    const char *name;
    const char *unit;
    const char *since;
    const char *description;
    uint8_t count;
    uint8_t col_1x; /* 0: not in 1.x packets */
    uint8_t col_3x; /* 0: not in 3.x/5.x packets */
} urrt_field_info;

/* Metadata of a field, or NULL for an id out of range. */
const urrt_field_info *urrt_field(urrt_field_id id);

/* Field id for a name (not NUL-terminated: name_len bytes are compared), or
 * URRT_E_UNKNOWN_FIELD. Programs select fields by name from configuration. */
int urrt_field_find(const char *name, size_t name_len);

/* First column of a field in packets of a generation, 0 if it has none
 * there. For URRT_GEN_UNKNOWN only columns that mean the same in both
 * generations are given. */
unsigned urrt_field_column(urrt_field_id id, urrt_generation gen);

/*
 * A decoded packet. Every field is an array of doubles (count 1 included, so
 * that generic code can treat them alike): st.time[0], st.q_actual[3].
 * A field holds a value only where urrt_has() says so; absent fields hold
 * NaN, so a careless read never yields a plausible number.
 */
typedef struct urrt_state {
#define URRT_X_MEMBER(ID, name, count, c1, c3, unit, since, desc) double name[count];
    URRT_FIELDS(URRT_X_MEMBER)
#undef URRT_X_MEMBER
    uint64_t present;         /* bit (1 << URRT_F_x) set when the field was in the packet */
    uint32_t length;          /* message size in bytes, header included */
    uint16_t doubles;         /* (length - 4) / 8 */
    uint16_t extra_columns;   /* columns past the newest known layout (3.x/5.x only) */
    urrt_generation generation;
} urrt_state;

#define urrt_has(st, id) ((((st)->present) >> (unsigned)(id)) & 1u)

/* The values of field id in *st (urrt_field(id)->count of them), for code
 * that selects fields by id (configuration, mappings); NULL for an id out
 * of range. Absent fields hold NaN, as above. */
const double *urrt_field_values(const urrt_state *st, urrt_field_id id);

/*
 * Validate the header of a packet in buf (len bytes available). Returns the
 * declared size (>= URRT_PACKET_MIN) or a negative urrt_result. A declared
 * size larger than len is URRT_E_TRUNCATED.
 */
int urrt_packet_length(const uint8_t *buf, size_t len);

/* Generation a message size implies. Sizes that are not plausible give
 * URRT_GEN_UNKNOWN. */
urrt_generation urrt_generation_of(uint32_t length);

/*
 * Controller software versions, the one table of what each sends: one row
 * per message size, with the versions that send it as text and as numbers,
 * and the period each sends it at (125 Hz on CB2/CB3, and taken for CB1
 * too, which no source gives; 500 Hz on e-series).
 * docs/protocol.md gives the sources.
 *
 * 1.6 controllers sent 756 or 764 bytes (the sources disagree), so 1.6 is
 * in two rows and urrt_controller_find() reports both: callers refuse the
 * version and name the candidate sizes, never pick one.
 */
#define URRT_MINOR_LATER 255u /* minor_last: and every later minor */

typedef struct urrt_version_range {
    uint8_t major;       /* 1, 3 or 5; 0 marks an unused slot */
    uint8_t minor_first;
    uint8_t minor_last;  /* URRT_MINOR_LATER: no upper end */
    uint16_t period_us;  /* 8000 (125 Hz) or 2000 (500 Hz, e-series) */
} urrt_version_range;

/* The text is held in the row, not pointed to: a pointer would bring the
 * whole string pool of urrt.c (field names and descriptions, ~3 KiB) into a
 * firmware whose framer looks up lengths in this table. */
typedef struct urrt_controller {
    uint32_t length;
    urrt_version_range ranges[2];     /* none for the sizes of early 1.x */
    char versions[24];                /* "3.5-3.9, 5.0-5.3": the ranges as text */
} urrt_controller;

/* The table, in increasing length; *count receives the number of rows. */
const urrt_controller *urrt_controllers(size_t *count);

/* The row of a message size, NULL for a size no known controller sends. */
const urrt_controller *urrt_controller_of_length(uint32_t length);

/* Its versions as text ("3.10-3.13, 5.4-5.8"), or NULL: a view of the table. */
const char *urrt_versions_of(uint32_t length);

/*
 * The rows that list a controller version given as text of len bytes,
 * MAJOR.MINOR with an optional .PATCH (and .BUILD), digits only ("5.10",
 * "3.15.4"): writes up to max of them to found and the period that version
 * sends at to *period_us (either may be NULL). Returns the number of rows:
 * 0 for a version no row lists, 1, or 2 where the sources disagree (1.6:
 * 756 or 764 bytes). URRT_E_ARG for text that is not a version.
 */
int urrt_controller_find(const char *text, size_t len, const urrt_controller **found, size_t max,
                         uint32_t *period_us);

/*
 * The shortest period, in microseconds, at which packets of a size come:
 * of the versions that send it; for a size no version is known to send (or
 * 0, "any"), of every version of the size's generation (of all versions for
 * URRT_GEN_UNKNOWN). A scheduler that must keep up with a robot plans for it.
 */
uint32_t urrt_period_min_us(uint32_t length);

/*
 * The controller's clock (column 1, seconds since it started) in whole
 * microseconds, rounded to nearest (halves away from zero), computed on the
 * bits (no floating-point arithmetic). Returns URRT_OK with the value, or
 * URRT_E_RANGE with it saturated: 0 for NaN and negative times, which no
 * controller sends, and URRT_TIME_US_MAX for times past it (285 years:
 * about where a double stops resolving a microsecond; the headroom to
 * INT64_MAX lets callers add periods without overflow). Callers that need a
 * trustworthy clock check the result; callers that need a number take it.
 */
#define URRT_TIME_US_MAX (INT64_C(1) << 53)
int urrt_time_us(double seconds, int64_t *us);

/*
 * Decode the packet at buf into *st. Returns the packet's size (bytes
 * consumed; bytes past it are left alone) or a negative urrt_result, in
 * which case *st holds no field (present == 0).
 */
int urrt_decode(const uint8_t *buf, size_t len, urrt_state *st);

#if defined(__x86_64__)
/* x86-64: the vector width in bytes urrt_decode uses on this CPU, 64
 * (AVX-512BW), 32 (AVX2), 16 (SSSE3) or 0 (one double at a time). A build
 * without -m flags chooses it at run time; a -march build has it fixed; 0
 * where lib/urrt.c is built without lib/vector/urrt_vector.c. */
unsigned urrt_x86_vector_bytes(void);
#endif

/*
 * Random access without a full decode: element elem of field id, read
 * straight from the packet bytes. URRT_E_ABSENT when this packet's length
 * or generation has no such element.
 */
int urrt_read(const uint8_t *buf, size_t len, urrt_field_id id, unsigned elem, double *out);

/* The double at a column (1-based, as UR's "Gnuplot col."), extra columns
 * included. */
int urrt_read_column(const uint8_t *buf, size_t len, unsigned column, double *out);

/* The raw bits of the double at a column: for bit-exact consumers. */
int urrt_read_column_bits(const uint8_t *buf, size_t len, unsigned column, uint64_t *out);

/*
 * Encode *st as a packet of the given size (4 + 8n, at most
 * URRT_PACKET_MAX) into out. The generation follows from the size: up to 101
 * doubles use the 1.x columns, more use the 3.x/5.x ones. Columns no field
 * covers (past the newest known layout) are written as 0.0. Fields are
 * written as they are in *st, present or not. Returns the size written.
 */
int urrt_encode(const urrt_state *st, uint32_t length, uint8_t *out, size_t out_size);

/* Set every field of *st to NaN and present to 0: a start for the encoder. */
void urrt_state_clear(urrt_state *st);

/*
 * Digital inputs and outputs. UR documents a double holding the integer
 * ("5.0 is bits 0 and 2"); some controllers and decoders treat the eight
 * bytes as a big-endian int64, which read as a double is a tiny subnormal
 * number. Both are recognised per value. URRT_E_NOT_BITMASK for anything
 * else (negative, fractional, NaN, infinite, past 2^53).
 */
int urrt_bitmask(double value, uint64_t *mask);

/* Enumerations. Names are the upper-case names in docs/protocol.md. */
typedef enum urrt_enum_kind {
    URRT_ENUM_NONE = 0,
    URRT_ENUM_ROBOT_MODE,    /* 3.x/5.x numbering */
    URRT_ENUM_ROBOT_MODE_1X, /* CB2 numbering */
    URRT_ENUM_JOINT_MODE,
    URRT_ENUM_SAFETY_MODE,
    URRT_ENUM_SAFETY_STATUS,
    URRT_ENUM_PROGRAM_STATE
} urrt_enum_kind;

typedef struct urrt_enum_entry {
    int value;
    const char *name;
} urrt_enum_entry;

#define URRT_UNKNOWN_NAME "UNKNOWN"

/* The entries of an enumeration, in value order; *count receives their
 * number. NULL (and 0) for URRT_ENUM_NONE or an unknown kind. */
const urrt_enum_entry *urrt_enum_entries(urrt_enum_kind kind, size_t *count);

/* Name of a value, or URRT_UNKNOWN_NAME for a value the enumeration does not
 * list, a fractional value, NaN or infinity. Never NULL. */
const char *urrt_enum_name(urrt_enum_kind kind, double value);

/* The enumeration a field is coded in for a generation (robot mode differs;
 * URRT_ENUM_NONE for robot mode of an unknown generation). */
urrt_enum_kind urrt_field_enum(urrt_field_id id, urrt_generation gen);

/*
 * Stream framing: a push parser over the TCP byte stream.
 *
 *   urrt_framer fr;  urrt_framer_init(&fr);
 *   while (n > 0) {
 *       size_t used;
 *       if (urrt_framer_feed(&fr, p, n, &used) > 0) {
 *           size_t len; const uint8_t *pkt = urrt_framer_packet(&fr, &len);
 *           ... urrt_decode(pkt, len, &st) ...
 *       }
 *       p += used; n -= used;
 *   }
 *
 * feed consumes bytes until a packet is complete (returns 1, *used says how
 * far it got) or the input is used up (returns 0). Any chunking of the same
 * bytes, zero-length chunks included, yields the same packets in the same
 * order, each exactly once. Work per call is bounded by the bytes fed.
 *
 * Framing: the first header of a stream is trusted if it is plausible (4 + 8n
 * between URRT_PACKET_MIN and URRT_PACKET_MAX), because TCP delivers a
 * connection from its first byte. After that a header is accepted only if its
 * size is a known controller length or equals the last accepted size: a
 * controller does not change its length within a connection, and that rule
 * keeps a resync from locking onto the bytes of a double. On a rejected
 * header the framer drops one byte, counts it and looks again.
 */
typedef struct urrt_framer_stats {
    uint64_t bytes;    /* fed */
    uint64_t packets;  /* yielded */
    uint64_t resyncs;  /* times the framer lost sync */
    uint64_t skipped;  /* bytes dropped while out of sync */
} urrt_framer_stats;

typedef struct urrt_framer {
    uint8_t buf[URRT_PACKET_MAX];
    uint32_t have;        /* bytes in buf */
    uint32_t need;        /* size of the packet being collected, 0 while seeking a header */
    uint32_t last_length; /* size of the last accepted packet, 0 at stream start */
    bool out_of_sync;
    const uint8_t *packet; /* the packet yielded by the last feed, or NULL */
    uint32_t packet_length;
    urrt_framer_stats stats;
} urrt_framer;

/* Sizes for static allocation: a framer needs about URRT_PACKET_MAX bytes. */
#define URRT_FRAMER_RAM (sizeof(urrt_framer))

/*
 * The framer's size follows URRT_MAX_DOUBLES, so every file must see the same
 * value: its functions' link names carry it (urrt_framer_feed is the symbol
 * urrt_framer_feed_URRT_MAX_DOUBLES_256 by default). A file built with
 * another value than lib/urrt.c then fails to link with "undefined reference
 * to urrt_framer_feed_URRT_MAX_DOUBLES_152" instead of running with a framer
 * of the wrong size. URRT_MAX_DOUBLES must therefore be a plain decimal
 * number.
 */
#define URRT_MAX_DOUBLES_NAME_(name, max) name##_URRT_MAX_DOUBLES_##max
#define URRT_MAX_DOUBLES_NAME(name, max) URRT_MAX_DOUBLES_NAME_(name, max)
#define urrt_framer_init URRT_MAX_DOUBLES_NAME(urrt_framer_init, URRT_MAX_DOUBLES)
#define urrt_framer_reset URRT_MAX_DOUBLES_NAME(urrt_framer_reset, URRT_MAX_DOUBLES)
#define urrt_framer_feed URRT_MAX_DOUBLES_NAME(urrt_framer_feed, URRT_MAX_DOUBLES)
#define urrt_framer_packet URRT_MAX_DOUBLES_NAME(urrt_framer_packet, URRT_MAX_DOUBLES)
#define urrt_framer_finish URRT_MAX_DOUBLES_NAME(urrt_framer_finish, URRT_MAX_DOUBLES)

void urrt_framer_init(urrt_framer *fr);

/* Forget any partial packet and the last length: call on a new connection.
 * Statistics are kept. */
void urrt_framer_reset(urrt_framer *fr);

/* Returns 1 when a packet is complete, 0 when all input was consumed, or
 * URRT_E_ARG. */
int urrt_framer_feed(urrt_framer *fr, const uint8_t *data, size_t len, size_t *used);

/* The packet the last feed completed, valid until the next feed or reset:
 * it may point into the caller's input (no copy) or into the framer. NULL if
 * the last feed completed none. */
const uint8_t *urrt_framer_packet(const urrt_framer *fr, size_t *len);

/* End of stream: returns the number of bytes of an incomplete packet (or
 * header) that are dropped, 0 if the stream ended on a packet boundary. The
 * framer is reset. */
size_t urrt_framer_finish(urrt_framer *fr);

#ifdef __cplusplus
}
#endif

#endif /* URRT_H */
