/* SPDX-License-Identifier: MIT */
/*
 * urrt_rtde: a read-only client of Universal Robots' Real-Time Data Exchange
 * (RTDE, TCP port 30004), without I/O: the caller moves the bytes.
 *
 * This header is the API manual; docs/rtde.md is the wire format, the errors
 * and the bounds. Freestanding C99 like urrt.h: no heap, no globals, no
 * clock, every byte of state in a struct the caller declares. A firmware that
 * decodes only RealTime (urrt.c) does not link this file and pays nothing.
 *
 * The session in one paragraph (the heatshrink pattern):
 *
 *   static urrt_rtde s;                        about URRT_RTDE_RAM bytes
 *   urrt_rtde_init(&s);
 *   on every TCP (re)connect:
 *       urrt_rtde_begin(&s, vars, count, 0.0);  restarts the handshake
 *   whenever the socket may be written:
 *       n = urrt_rtde_output(&s, out, sizeof out);  the next request, if any
 *   for every chunk read (any split):
 *       while (len > 0) {
 *           int k = urrt_rtde_feed(&s, p, len, &used, &ev, &st, &vals);
 *           p += used; len -= used;
 *           k == URRT_RTDE_EV_DATA: st and vals hold a data package
 *           k == URRT_RTDE_EV_DROP: protocol error: close, reconnect soon
 *           k == URRT_RTDE_EV_CONFIG: configuration error: close, back off long
 *           ... then take urrt_rtde_output() again
 *       }
 *   on close: urrt_rtde_finish(&s)
 *
 * The client asks for protocol version 2 (1 if the controller refuses), the
 * controller version, one output recipe (the caller's variables) and start.
 * It never writes setup-inputs or data packages: no function here can. Data
 * packages are decoded through the accepted recipe, compiled once into a
 * table (wire offset, wire type, destination), into the urrt_state members
 * the RealTime decode fills (actual_q into q_actual, ...; present says which
 * are there) and, for the values RealTime does not have (registers, status
 * bits, ...), into a urrt_rtde_values.
 *
 * What a decode writes:
 *   - every value of the recipe, once, and the present bits, whole: st->present
 *     is exactly the recipe's fields and vals' present bits exactly its
 *     RTDE-only variables (urrt_rtde_has), whatever the struct held before,
 *     so no value of another recipe or session is ever read as present;
 *     st->length, doubles, extra_columns and generation as urrt_decode's;
 *   - nothing else: a member the recipe lacks keeps what it held.
 * What a recipe lacks cannot change within a session, so it is set absent
 * once: the feed that accepts the recipe (URRT_RTDE_EV_RECIPE) clears the
 * urrt_state and the urrt_rtde_values passed to it (urrt_state_clear's NaN,
 * urrt_rtde_values_clear's NaN and 0, present none). A caller that decodes
 * into those structs only, and does not write the absent members itself,
 * sees NaN (and 0) there for the whole session, as before. A caller that
 * decodes into other structs as well (double buffers) clears each of them
 * once (urrt_state_clear, urrt_rtde_values_clear) if it reads absent members
 * at all; a caller that reads only what present says needs nothing.
 *
 * The receive path: a read that holds a whole data package is decoded where
 * it lies, in the caller's bytes; only what a split leaves (a package's
 * first part, and every other package: replies, text messages) is copied
 * into s->buf, in words where the target loads them unaligned.
 */
#ifndef URRT_RTDE_H
#define URRT_RTDE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "urrt.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The protocol versions this client speaks: it asks for the first, falls
 * back to the second. */
#define URRT_RTDE_PROTOCOL 2
#define URRT_RTDE_PROTOCOL_FALLBACK 1
#define URRT_RTDE_PORT 30004

/* ---- bounds (for buffers sized at compile time) ---------------------------- */

/* Every package: uint16 size (header included, big-endian), uint8 type. */
#define URRT_RTDE_HEADER_SIZE 3
/* The longest name list of a setup request: UR's limit. */
#define URRT_RTDE_NAMES_MAX 2048
/* The most variables in one recipe. */
#define URRT_RTDE_MAX_VARS 128
/* The largest package accepted from the controller: a setup reply of
 * URRT_RTDE_MAX_VARS types fits (3 + 1 + 128 * 14 bytes), a version-2 text
 * message fits (3 + 513), and so does a data package of any recipe begin
 * recipe (URRT_RTDE_MAX_VARS of the largest variables need about 2100
 * bytes; check-rtde holds that they fit). Larger sizes end the session
 * (URRT_RTDE_E_SIZE_LARGE). */
#define URRT_RTDE_PACKAGE_MAX 4096
/* The largest request the client writes (a setup request: header,
 * frequency, name list); urrt_rtde_output needs this much room. */
#define URRT_RTDE_REQUEST_MAX (URRT_RTDE_HEADER_SIZE + 8 + URRT_RTDE_NAMES_MAX)
/* Frequencies the controller generations stream at, at most. */
#define URRT_RTDE_HZ_CB3 125.0
#define URRT_RTDE_HZ_E_SERIES 500.0

/* Package types (the ASCII letter of byte 2). */
#define URRT_RTDE_TYPE_PROTOCOL_VERSION 'V'
#define URRT_RTDE_TYPE_CONTROLLER_VERSION 'v'
#define URRT_RTDE_TYPE_TEXT_MESSAGE 'M'
#define URRT_RTDE_TYPE_DATA 'U'
#define URRT_RTDE_TYPE_SETUP_OUTPUTS 'O'
#define URRT_RTDE_TYPE_START 'S'
#define URRT_RTDE_TYPE_PAUSE 'P'

/* ---- results --------------------------------------------------------------- */

/* Negative, beside urrt_result's (URRT_E_ARG and URRT_E_NO_SPACE are used
 * with their meaning). Protocol errors end the session: reconnect. Errors
 * of the configuration (urrt_rtde_is_config_error) end it too, and a
 * reconnect gets the same answer: back off long, tell the operator. */
enum urrt_rtde_result {
    /* protocol errors */
    URRT_RTDE_E_SIZE_SMALL = -32,    /* package size below 3 (its own header) */
    URRT_RTDE_E_SIZE_LARGE = -33,    /* package size past URRT_RTDE_PACKAGE_MAX */
    URRT_RTDE_E_REPLY_LENGTH = -34,  /* a reply longer or shorter than its layout */
    URRT_RTDE_E_REPLY_VALUE = -35,   /* an accepted flag neither 0 nor 1 */
    URRT_RTDE_E_VERSION_ZERO = -36,  /* controller version 0.0.0.0 */
    URRT_RTDE_E_DATA_EARLY = -37,    /* a data package before a recipe was accepted */
    URRT_RTDE_E_RECIPE_ID = -38,     /* a data package of another recipe id */
    URRT_RTDE_E_DATA_SIZE = -39,     /* a data package not the recipe's size */
    URRT_RTDE_E_TYPE_TOKEN = -40,    /* a setup reply entry that is no type name */
    URRT_RTDE_E_TYPE_COUNT = -41,    /* more or fewer types than names asked for */
    URRT_RTDE_E_TEXT_LENGTH = -42,   /* text message lengths that do not fill the package */
    URRT_RTDE_E_PAUSE_REFUSED = -43, /* the controller refused a pause */
    URRT_RTDE_E_ENDED = -44,         /* feed after the session ended: begin again */
    /* configuration errors */
    URRT_RTDE_E_NOT_FOUND = -48,     /* names the controller does not have (urrt_rtde_not_found) */
    URRT_RTDE_E_TYPE_MISMATCH = -49, /* a name's type is not the one urrt knows for it */
    URRT_RTDE_E_PROTOCOL_REFUSED = -50, /* neither protocol version 2 nor 1 accepted */
    URRT_RTDE_E_START_REFUSED = -51, /* the controller refused to start the recipe */
    URRT_RTDE_E_FREQUENCY = -52,     /* frequency past what this controller streams */
    URRT_RTDE_E_IN_USE = -53,        /* inputs another client or a fieldbus owns (urrt_rtde_in.h) */
    URRT_RTDE_E_INPUTS_PROTOCOL = -54, /* inputs asked of a controller that speaks protocol 1 only */
    /* arguments of urrt_rtde_begin and the request writers */
    URRT_RTDE_E_NAMES_TOO_LONG = -56, /* name list past URRT_RTDE_NAMES_MAX bytes */
    URRT_RTDE_E_NOT_WRITABLE = -57,   /* an input that is not a general purpose register */
    URRT_RTDE_E_DUPLICATE = -58,      /* a variable asked for twice */
    URRT_RTDE_E_UNKNOWN_NAME = -59,   /* no RTDE output of that name */
    URRT_RTDE_E_SCRIPT_PORT = -60,    /* a port that runs what it receives, or its twin */
    /* the writing side's values and packages (urrt_rtde_in.h) */
    URRT_RTDE_E_VALUE = -61,          /* a value its register cannot hold: refused, never clamped */
    URRT_RTDE_E_NOT_STARTED = -62,    /* an input package before the recipe is accepted and streaming */
    URRT_RTDE_E_INCOMPLETE = -63      /* an input package while a register has no value */
};

/* A short English text for a result (urrt_strerror's for urrt_result). */
const char *urrt_rtde_strerror(int result);

/* True for the errors a reconnect does not cure. */
bool urrt_rtde_is_config_error(int result);

/* ---- ports ------------------------------------------------------------------ */

/*
 * The controller's other TCP servers, which an RTDE client must never write
 * to: 29999 (the dashboard server runs the commands it receives), 30001,
 * 30002 and 30003 (the primary, secondary and RealTime client interfaces run
 * what they receive as URScript), 30020 (interpreter mode's socket, e-Series
 * 5.10 on, runs URScript too) and 30011-30013 (the read-only twins of the
 * first three: they stream without a handshake, so a handshake there is a
 * mistake that another port would turn into a program). RTDE's port is
 * URRT_RTDE_PORT; a forwarded or simulated port is any other number.
 *
 * urrt_rtde_check_port: URRT_OK, or URRT_RTDE_E_SCRIPT_PORT for those ports.
 * A client calls it with the port it connects to before it writes a byte.
 * urrt_rtde_port_role: what listens on such a port ("the RealTime interface,
 * which runs the URScript it receives"), NULL for any other port.
 */
int urrt_rtde_check_port(uint32_t port);
const char *urrt_rtde_port_role(uint32_t port);

/* ---- wire types ------------------------------------------------------------- */

typedef enum urrt_rtde_type {
    URRT_RTDE_T_NONE = 0,
    URRT_RTDE_T_BOOL,
    URRT_RTDE_T_UINT8,
    URRT_RTDE_T_UINT32,
    URRT_RTDE_T_UINT64,
    URRT_RTDE_T_INT32,
    URRT_RTDE_T_DOUBLE,
    URRT_RTDE_T_VECTOR3D,
    URRT_RTDE_T_VECTOR6D,
    URRT_RTDE_T_VECTOR6INT32,
    URRT_RTDE_T_VECTOR6UINT32,
    URRT_RTDE_T_COUNT
} urrt_rtde_type;

/* The C type and element count each wire type decodes to in
 * urrt_rtde_values (BOOL as 0 or 1). */
#define URRT_RTDE_CTYPE_BOOL uint8_t
#define URRT_RTDE_CTYPE_UINT8 uint8_t
#define URRT_RTDE_CTYPE_UINT32 uint32_t
#define URRT_RTDE_CTYPE_UINT64 uint64_t
#define URRT_RTDE_CTYPE_INT32 int32_t
#define URRT_RTDE_CTYPE_DOUBLE double
#define URRT_RTDE_CTYPE_VECTOR3D double
#define URRT_RTDE_CTYPE_VECTOR6D double
#define URRT_RTDE_CTYPE_VECTOR6INT32 int32_t
#define URRT_RTDE_CTYPE_VECTOR6UINT32 uint32_t
#define URRT_RTDE_COUNT_BOOL 1
#define URRT_RTDE_COUNT_UINT8 1
#define URRT_RTDE_COUNT_UINT32 1
#define URRT_RTDE_COUNT_UINT64 1
#define URRT_RTDE_COUNT_INT32 1
#define URRT_RTDE_COUNT_DOUBLE 1
#define URRT_RTDE_COUNT_VECTOR3D 3
#define URRT_RTDE_COUNT_VECTOR6D 6
#define URRT_RTDE_COUNT_VECTOR6INT32 6
#define URRT_RTDE_COUNT_VECTOR6UINT32 6

/* The type's name on the wire ("VECTOR6D"), NULL for none. */
const char *urrt_rtde_type_name(urrt_rtde_type type);
/* Bytes of one value of the type on the wire, 0 for none. */
unsigned urrt_rtde_type_size(urrt_rtde_type type);

/* ---- the output variables: two tables, written once ------------------------ */

/*
 * Controller versions as one number, major << 16 | minor << 8 | bugfix, and
 * the "since" triple of each row: (CB3 3.x, e-Series 5.x, PolyScope X 10.x).
 * URRT_RTDE_ANY: since RTDE exists on that line. URRT_RTDE_UNSTATED: no
 * source gives the version; only the controller's NOT_FOUND will tell.
 * URRT_RTDE_NEVER: that line does not have it.
 */
#define URRT_RTDE_VER(major, minor, bugfix) \
    ((uint32_t)(major) << 16 | (uint32_t)(minor) << 8 | (uint32_t)(bugfix))
#define URRT_RTDE_ANY 0u
#define URRT_RTDE_UNSTATED 1u
#define URRT_RTDE_NEVER 0xFFFFFFFFu
#define URRT_RTDE_ALWAYS (URRT_RTDE_ANY, URRT_RTDE_ANY, URRT_RTDE_ANY)
#define URRT_RTDE_NOT_STATED (URRT_RTDE_UNSTATED, URRT_RTDE_UNSTATED, URRT_RTDE_UNSTATED)

/*
 * The outputs RealTime has too: each row names the urrt_state field an RTDE
 * output fills (the one place that maps RealTime to RTDE).
 *   X(ID, name, TYPE, FIELD, member, since)
 * FIELD/member: the urrt_field_id suffix and urrt_state member it fills
 * (every value converted to double, as RealTime sends it).
 */
#define URRT_RTDE_MAPPED(X) \
    X(TIMESTAMP, "timestamp", DOUBLE, TIME, time, URRT_RTDE_ALWAYS) \
    X(TARGET_Q, "target_q", VECTOR6D, Q_TARGET, q_target, URRT_RTDE_ALWAYS) \
    X(TARGET_QD, "target_qd", VECTOR6D, QD_TARGET, qd_target, URRT_RTDE_ALWAYS) \
    X(TARGET_QDD, "target_qdd", VECTOR6D, QDD_TARGET, qdd_target, URRT_RTDE_ALWAYS) \
    X(TARGET_CURRENT, "target_current", VECTOR6D, I_TARGET, i_target, URRT_RTDE_ALWAYS) \
    X(TARGET_MOMENT, "target_moment", VECTOR6D, M_TARGET, m_target, URRT_RTDE_ALWAYS) \
    X(ACTUAL_Q, "actual_q", VECTOR6D, Q_ACTUAL, q_actual, URRT_RTDE_ALWAYS) \
    X(ACTUAL_QD, "actual_qd", VECTOR6D, QD_ACTUAL, qd_actual, URRT_RTDE_ALWAYS) \
    X(ACTUAL_CURRENT, "actual_current", VECTOR6D, I_ACTUAL, i_actual, URRT_RTDE_ALWAYS) \
    X(JOINT_CONTROL_OUTPUT, "joint_control_output", VECTOR6D, I_CONTROL, i_control, URRT_RTDE_ALWAYS) \
    X(ACTUAL_TCP_POSE, "actual_TCP_pose", VECTOR6D, TOOL_VECTOR_ACTUAL, tool_vector_actual, URRT_RTDE_ALWAYS) \
    X(ACTUAL_TCP_SPEED, "actual_TCP_speed", VECTOR6D, TCP_SPEED_ACTUAL, tcp_speed_actual, URRT_RTDE_ALWAYS) \
    X(ACTUAL_TCP_FORCE, "actual_TCP_force", VECTOR6D, TCP_FORCE, tcp_force, URRT_RTDE_ALWAYS) \
    X(TARGET_TCP_POSE, "target_TCP_pose", VECTOR6D, TOOL_VECTOR_TARGET, tool_vector_target, URRT_RTDE_ALWAYS) \
    X(TARGET_TCP_SPEED, "target_TCP_speed", VECTOR6D, TCP_SPEED_TARGET, tcp_speed_target, URRT_RTDE_ALWAYS) \
    X(ACTUAL_DIGITAL_INPUT_BITS, "actual_digital_input_bits", UINT64, DIGITAL_INPUT_BITS, digital_input_bits, URRT_RTDE_ALWAYS) \
    X(JOINT_TEMPERATURES, "joint_temperatures", VECTOR6D, MOTOR_TEMPERATURES, motor_temperatures, URRT_RTDE_ALWAYS) \
    X(ACTUAL_EXECUTION_TIME, "actual_execution_time", DOUBLE, CONTROLLER_TIMER, controller_timer, URRT_RTDE_ALWAYS) \
    X(ROBOT_MODE, "robot_mode", INT32, ROBOT_MODE, robot_mode, URRT_RTDE_ALWAYS) \
    X(JOINT_MODE, "joint_mode", VECTOR6INT32, JOINT_MODES, joint_modes, URRT_RTDE_ALWAYS) \
    X(SAFETY_MODE, "safety_mode", INT32, SAFETY_MODE, safety_mode, URRT_RTDE_ALWAYS) \
    X(ACTUAL_TOOL_ACCELEROMETER, "actual_tool_accelerometer", VECTOR3D, TOOL_ACCELEROMETER, tool_accelerometer, URRT_RTDE_ALWAYS) \
    X(SPEED_SCALING, "speed_scaling", DOUBLE, SPEED_SCALING, speed_scaling, URRT_RTDE_ALWAYS) \
    X(ACTUAL_MOMENTUM, "actual_momentum", DOUBLE, LINEAR_MOMENTUM_NORM, linear_momentum_norm, URRT_RTDE_ALWAYS) \
    X(ACTUAL_MAIN_VOLTAGE, "actual_main_voltage", DOUBLE, V_MAIN, v_main, URRT_RTDE_ALWAYS) \
    X(ACTUAL_ROBOT_VOLTAGE, "actual_robot_voltage", DOUBLE, V_ROBOT, v_robot, URRT_RTDE_ALWAYS) \
    X(ACTUAL_ROBOT_CURRENT, "actual_robot_current", DOUBLE, I_ROBOT, i_robot, URRT_RTDE_ALWAYS) \
    X(ACTUAL_JOINT_VOLTAGE, "actual_joint_voltage", VECTOR6D, V_ACTUAL, v_actual, URRT_RTDE_ALWAYS) \
    X(ACTUAL_DIGITAL_OUTPUT_BITS, "actual_digital_output_bits", UINT64, DIGITAL_OUTPUTS, digital_outputs, URRT_RTDE_ALWAYS) \
    X(RUNTIME_STATE, "runtime_state", UINT32, PROGRAM_STATE, program_state, URRT_RTDE_ALWAYS) \
    X(ELBOW_POSITION, "elbow_position", VECTOR3D, ELBOW_POSITION, elbow_position, (URRT_RTDE_VER(3, 5, 0), URRT_RTDE_ANY, URRT_RTDE_ANY)) \
    X(ELBOW_VELOCITY, "elbow_velocity", VECTOR3D, ELBOW_VELOCITY, elbow_velocity, (URRT_RTDE_VER(3, 5, 0), URRT_RTDE_ANY, URRT_RTDE_ANY)) \
    X(SAFETY_STATUS, "safety_status", INT32, SAFETY_STATUS, safety_status, (URRT_RTDE_VER(3, 10, 0), URRT_RTDE_VER(5, 4, 0), URRT_RTDE_ANY)) \
    X(PAYLOAD, "payload", DOUBLE, PAYLOAD_MASS, payload_mass, (URRT_RTDE_VER(3, 11, 0), URRT_RTDE_VER(5, 5, 1), URRT_RTDE_ANY)) \
    X(PAYLOAD_COG, "payload_cog", VECTOR3D, PAYLOAD_COG, payload_cog, (URRT_RTDE_VER(3, 11, 0), URRT_RTDE_VER(5, 5, 1), URRT_RTDE_ANY)) \
    X(PAYLOAD_INERTIA, "payload_inertia", VECTOR6D, PAYLOAD_INERTIA, payload_inertia, (URRT_RTDE_VER(3, 15, 0), URRT_RTDE_VER(5, 11, 0), URRT_RTDE_ANY))

/*
 * The outputs only RTDE has, each a member of urrt_rtde_values.
 *   X(ID, member, name, TYPE, first, names, split, since, since_from_split)
 * A row of one name (names 1) is the name itself. A row of several is a
 * family: names first .. first + names - 1 are name followed by the decimal
 * index ("output_int_register_" 0..47), and member[i] holds index first + i
 * (times the type's element count). Indexes from first + split on have the
 * versions since_from_split (the upper register ranges came later).
 */
#define URRT_RTDE_BITS_HI (URRT_RTDE_VER(3, 9, 0), URRT_RTDE_VER(5, 3, 0), URRT_RTDE_ANY)
#define URRT_RTDE_REG_LO (URRT_RTDE_VER(3, 4, 0), URRT_RTDE_ANY, URRT_RTDE_ANY)
#define URRT_RTDE_NOT_CB3(e, x) (URRT_RTDE_NEVER, (e), (x))
#define URRT_RTDE_ONLY(X) \
    X(TARGET_SPEED_FRACTION, target_speed_fraction, "target_speed_fraction", DOUBLE, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(ROBOT_STATUS_BITS, robot_status_bits, "robot_status_bits", UINT32, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(SAFETY_STATUS_BITS, safety_status_bits, "safety_status_bits", UINT32, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(TCP_OFFSET, tcp_offset, "tcp_offset", VECTOR6D, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(OUTPUT_BIT_REGISTERS0_TO_31, output_bit_registers0_to_31, "output_bit_registers0_to_31", UINT32, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(OUTPUT_BIT_REGISTERS32_TO_63, output_bit_registers32_to_63, "output_bit_registers32_to_63", UINT32, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(OUTPUT_BIT_REGISTER, output_bit_register, "output_bit_register_", BOOL, 64, 64, 64, URRT_RTDE_BITS_HI, URRT_RTDE_BITS_HI) \
    X(OUTPUT_INT_REGISTER, output_int_register, "output_int_register_", INT32, 0, 48, 24, URRT_RTDE_REG_LO, URRT_RTDE_BITS_HI) \
    X(OUTPUT_DOUBLE_REGISTER, output_double_register, "output_double_register_", DOUBLE, 0, 48, 24, URRT_RTDE_REG_LO, URRT_RTDE_BITS_HI) \
    X(INPUT_BIT_REGISTERS0_TO_31, input_bit_registers0_to_31, "input_bit_registers0_to_31", UINT32, 0, 1, 1, URRT_RTDE_REG_LO, URRT_RTDE_REG_LO) \
    X(INPUT_BIT_REGISTERS32_TO_63, input_bit_registers32_to_63, "input_bit_registers32_to_63", UINT32, 0, 1, 1, URRT_RTDE_REG_LO, URRT_RTDE_REG_LO) \
    X(INPUT_BIT_REGISTER, input_bit_register, "input_bit_register_", BOOL, 64, 64, 64, URRT_RTDE_BITS_HI, URRT_RTDE_BITS_HI) \
    X(INPUT_INT_REGISTER, input_int_register, "input_int_register_", INT32, 0, 48, 24, URRT_RTDE_REG_LO, URRT_RTDE_BITS_HI) \
    X(INPUT_DOUBLE_REGISTER, input_double_register, "input_double_register_", DOUBLE, 0, 48, 24, URRT_RTDE_REG_LO, URRT_RTDE_BITS_HI) \
    X(ACTUAL_CURRENT_WINDOW, actual_current_window, "actual_current_window", VECTOR6D, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(ACTUAL_CURRENT_AS_TORQUE, actual_current_as_torque, "actual_current_as_torque", VECTOR6D, 0, 1, 1, URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 23, 0), URRT_RTDE_VER(10, 11, 0)), URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 23, 0), URRT_RTDE_VER(10, 11, 0))) \
    X(ACTUAL_TCP_ACCELERATION, actual_TCP_acceleration, "actual_TCP_acceleration", VECTOR6D, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(TARGET_TCP_ACCELERATION, target_TCP_acceleration, "target_TCP_acceleration", VECTOR6D, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(ACTUAL_CONFIGURABLE_DIGITAL_INPUT_BITS, actual_configurable_digital_input_bits, "actual_configurable_digital_input_bits", UINT64, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(ACTUAL_CONFIGURABLE_DIGITAL_OUTPUT_BITS, actual_configurable_digital_output_bits, "actual_configurable_digital_output_bits", UINT64, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(TARGET_EXECUTION_TIME, target_execution_time, "target_execution_time", DOUBLE, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(ANALOG_IO_TYPES, analog_io_types, "analog_io_types", UINT32, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(STANDARD_ANALOG_INPUT, standard_analog_input, "standard_analog_input", DOUBLE, 0, 2, 2, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(STANDARD_ANALOG_OUTPUT, standard_analog_output, "standard_analog_output", DOUBLE, 0, 2, 2, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(IO_CURRENT, io_current, "io_current", DOUBLE, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(ACTUAL_ROBOT_ENERGY_CONSUMED, actual_robot_energy_consumed, "actual_robot_energy_consumed", DOUBLE, 0, 1, 1, URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 23, 0), URRT_RTDE_VER(10, 11, 0)), URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 23, 0), URRT_RTDE_VER(10, 11, 0))) \
    X(ACTUAL_ROBOT_BRAKING_ENERGY_DISSIPATED, actual_robot_braking_energy_dissipated, "actual_robot_braking_energy_dissipated", DOUBLE, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(ENCODER0_RAW, encoder0_raw, "encoder0_raw", INT32, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(ENCODER1_RAW, encoder1_raw, "encoder1_raw", INT32, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(EUROMAP67_INPUT_BITS, euromap67_input_bits, "euromap67_input_bits", UINT32, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(EUROMAP67_OUTPUT_BITS, euromap67_output_bits, "euromap67_output_bits", UINT32, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(EUROMAP67_24V_VOLTAGE, euromap67_24V_voltage, "euromap67_24V_voltage", DOUBLE, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(EUROMAP67_24V_CURRENT, euromap67_24V_current, "euromap67_24V_current", DOUBLE, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(TOOL_MODE, tool_mode, "tool_mode", UINT32, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(TOOL_ANALOG_INPUT_TYPES, tool_analog_input_types, "tool_analog_input_types", UINT32, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(TOOL_ANALOG_INPUT, tool_analog_input, "tool_analog_input", DOUBLE, 0, 2, 2, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(TOOL_OUTPUT_VOLTAGE, tool_output_voltage, "tool_output_voltage", INT32, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(TOOL_OUTPUT_CURRENT, tool_output_current, "tool_output_current", DOUBLE, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(TOOL_TEMPERATURE, tool_temperature, "tool_temperature", DOUBLE, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(TOOL_OUTPUT_MODE, tool_output_mode, "tool_output_mode", UINT8, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(TOOL_DIGITAL_OUTPUT0_MODE, tool_digital_output0_mode, "tool_digital_output0_mode", UINT8, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(TOOL_DIGITAL_OUTPUT1_MODE, tool_digital_output1_mode, "tool_digital_output1_mode", UINT8, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(TCP_FORCE_SCALAR, tcp_force_scalar, "tcp_force_scalar", DOUBLE, 0, 1, 1, URRT_RTDE_ALWAYS, URRT_RTDE_ALWAYS) \
    X(JOINT_POSITION_DEVIATION_RATIO, joint_position_deviation_ratio, "joint_position_deviation_ratio", DOUBLE, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(COLLISION_DETECTION_RATIO, collision_detection_ratio, "collision_detection_ratio", DOUBLE, 0, 1, 1, URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 15, 0), URRT_RTDE_ANY), URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 15, 0), URRT_RTDE_ANY)) \
    X(FT_RAW_WRENCH, ft_raw_wrench, "ft_raw_wrench", VECTOR6D, 0, 1, 1, URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 9, 0), URRT_RTDE_ANY), URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 9, 0), URRT_RTDE_ANY)) \
    X(WRENCH_CALC_FROM_CURRENTS, wrench_calc_from_currents, "wrench_calc_from_currents", VECTOR6D, 0, 1, 1, URRT_RTDE_NOT_STATED, URRT_RTDE_NOT_STATED) \
    X(SCRIPT_CONTROL_LINE, script_control_line, "script_control_line", UINT32, 0, 1, 1, (URRT_RTDE_VER(3, 14, 0), URRT_RTDE_VER(5, 9, 0), URRT_RTDE_ANY), (URRT_RTDE_VER(3, 14, 0), URRT_RTDE_VER(5, 9, 0), URRT_RTDE_ANY)) \
    X(TIME_SCALE_SOURCE, time_scale_source, "time_scale_source", INT32, 0, 1, 1, URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 17, 0), URRT_RTDE_ANY), URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 17, 0), URRT_RTDE_ANY)) \
    X(TARGET_GRAVITY, target_gravity, "target_gravity", VECTOR3D, 0, 1, 1, URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 26, 0), URRT_RTDE_VER(10, 12, 0)), URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 26, 0), URRT_RTDE_VER(10, 12, 0))) \
    X(TARGET_BASE_ACCELERATION, target_base_acceleration, "target_base_acceleration", VECTOR6D, 0, 1, 1, URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 26, 0), URRT_RTDE_VER(10, 12, 0)), URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 26, 0), URRT_RTDE_VER(10, 12, 0))) \
    X(CONTROL_STEP, control_step, "control_step", UINT64, 0, 1, 1, URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 26, 0), URRT_RTDE_VER(10, 13, 0)), URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 26, 0), URRT_RTDE_VER(10, 13, 0))) \
    X(TARGET_BASE_WRENCH, target_base_wrench, "target_base_wrench", VECTOR6D, 0, 1, 1, URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 26, 0), URRT_RTDE_VER(10, 13, 0)), URRT_RTDE_NOT_CB3(URRT_RTDE_VER(5, 26, 0), URRT_RTDE_VER(10, 13, 0)))

/*
 * Variable ids: one per name, the mapped rows first, then every name of
 * every RTDE-only row (URRT_RTDE_V_OUTPUT_INT_REGISTER + 5 is
 * "output_int_register_5"; for families starting at 64, + 0 is index 64).
 */
typedef enum urrt_rtde_var {
#define URRT_RTDE_X_MAPPED_ID(ID, name, TYPE, FIELD, member, since) URRT_RTDE_V_##ID,
    URRT_RTDE_MAPPED(URRT_RTDE_X_MAPPED_ID)
#undef URRT_RTDE_X_MAPPED_ID
    URRT_RTDE_MAPPED_COUNT,
    URRT_RTDE_ONLY_BEFORE_ = URRT_RTDE_MAPPED_COUNT - 1,
#define URRT_RTDE_X_ONLY_ID(ID, member, name, TYPE, first, names, split, since, since_hi) \
    URRT_RTDE_V_##ID, URRT_RTDE_V_##ID##_LAST_ = URRT_RTDE_V_##ID + (names) - 1,
    URRT_RTDE_ONLY(URRT_RTDE_X_ONLY_ID)
#undef URRT_RTDE_X_ONLY_ID
    URRT_RTDE_VAR_COUNT
} urrt_rtde_var;

#define URRT_RTDE_ONLY_COUNT (URRT_RTDE_VAR_COUNT - URRT_RTDE_MAPPED_COUNT)
/* Words of urrt_rtde_values' present bits: one bit per RTDE-only variable,
 * in whole groups of four words (the decode writes them four at a time). */
#define URRT_RTDE_PRESENT_WORDS (4 * ((URRT_RTDE_ONLY_COUNT + 127) / 128))
/* The longest variable name, for buffers of urrt_rtde_var_name(). */
#define URRT_RTDE_NAME_MAX 40

/*
 * The RTDE-only values of a data package. Members hold a value only where
 * urrt_rtde_has() says so, and every decode writes the present bits whole.
 * Absent doubles hold NaN and absent integers 0 from the last clear on
 * (urrt_rtde_values_clear, or the feed of URRT_RTDE_EV_RECIPE): a decode
 * writes only its recipe's members (see the top of this file).
 */
typedef struct urrt_rtde_values {
#define URRT_RTDE_X_MEMBER(ID, member, name, TYPE, first, names, split, since, since_hi) \
    URRT_RTDE_CTYPE_##TYPE member[(names) * URRT_RTDE_COUNT_##TYPE];
    URRT_RTDE_ONLY(URRT_RTDE_X_MEMBER)
#undef URRT_RTDE_X_MEMBER
    uint32_t present[URRT_RTDE_PRESENT_WORDS]; /* bit (var - URRT_RTDE_MAPPED_COUNT) % 32 of word / 32 */
} urrt_rtde_values;

/* 1 if variable var (an RTDE-only one) is in *v. */
#define urrt_rtde_has(v, var)                                                                  \
    ((unsigned)(var) >= (unsigned)URRT_RTDE_MAPPED_COUNT && (unsigned)(var) < (unsigned)URRT_RTDE_VAR_COUNT && \
     (((v)->present[((unsigned)(var) - (unsigned)URRT_RTDE_MAPPED_COUNT) / 32u] >>              \
       (((unsigned)(var) - (unsigned)URRT_RTDE_MAPPED_COUNT) % 32u)) & 1u))

/* Set every double of *v to NaN, every integer to 0, present to none. */
void urrt_rtde_values_clear(urrt_rtde_values *v);

/* The values of RTDE-only variable var in *v (urrt_rtde_var_type's C type
 * as URRT_RTDE_CTYPE_* gives it, as many as its element count), NULL for
 * other ids. */
const void *urrt_rtde_value(const urrt_rtde_values *v, int var);

/* Variable id of a name (len bytes, not NUL-terminated), or
 * URRT_RTDE_E_UNKNOWN_NAME. Names are case-sensitive, as on the wire. */
int urrt_rtde_var_find(const char *name, size_t len);

/* Writes var's name and a NUL into out (cap bytes; URRT_RTDE_NAME_MAX is
 * always enough); returns its length, URRT_E_ARG or URRT_E_NO_SPACE. */
int urrt_rtde_var_name(int var, char *out, size_t cap);

/* The variable's wire type, URRT_RTDE_T_NONE for an id out of range. */
urrt_rtde_type urrt_rtde_var_type(int var);

/* The urrt_state field a variable fills, or -1 for RTDE-only ones. */
int urrt_rtde_var_field(int var);

/* The variable that fills a urrt_state field, or -1 if RTDE has none. */
int urrt_rtde_var_of_field(urrt_field_id field);

/* Whether a controller version has a variable (by the version tables, without
 * asking it): 1 yes, 0 no, URRT_RTDE_UNKNOWN where no source states it (the
 * controller's NOT_FOUND will tell), URRT_E_ARG for an id out of range.
 * Major 3 is CB3, 4..9 the e-Series line (5.x), 10 and later PolyScope X;
 * before 3 there is no RTDE. */
#define URRT_RTDE_UNKNOWN 2
int urrt_rtde_var_available(int var, uint32_t major, uint32_t minor, uint32_t bugfix);

/* ---- requests, written into caller buffers -------------------------------- */

/* Each returns the bytes written, URRT_E_NO_SPACE if cap is too small or
 * URRT_E_ARG. These five are every package the client can write (the
 * writing side, urrt_rtde_in.h, a file of its own, adds 'I' and 'U'). */
int urrt_rtde_write_protocol_version(uint8_t *out, size_t cap, uint16_t version);
int urrt_rtde_write_controller_version(uint8_t *out, size_t cap);
/* Protocol 1 has no frequency field: frequency is then not written. */
int urrt_rtde_write_setup_outputs(uint8_t *out, size_t cap, unsigned protocol, double frequency,
                                  const uint16_t *vars, size_t count);
int urrt_rtde_write_start(uint8_t *out, size_t cap);
int urrt_rtde_write_pause(uint8_t *out, size_t cap);

/* ---- the session ------------------------------------------------------------ */

typedef enum urrt_rtde_event_kind {
    URRT_RTDE_EV_NONE = 0,     /* all input consumed */
    URRT_RTDE_EV_PROTOCOL = 1, /* protocol version accepted: ev.protocol */
    URRT_RTDE_EV_FALLBACK,     /* protocol 2 refused: the request for 1 is due */
    URRT_RTDE_EV_CONTROLLER,   /* controller version: ev.version */
    URRT_RTDE_EV_RECIPE,       /* recipe accepted: ev.recipe_id (0 in protocol 1) */
    URRT_RTDE_EV_STARTED,      /* start accepted */
    URRT_RTDE_EV_PAUSED,       /* pause accepted */
    URRT_RTDE_EV_TEXT,         /* text message: ev.level, ev.text, ev.source */
    URRT_RTDE_EV_DATA,         /* data package decoded into st and vals; ev.first once per session */
    URRT_RTDE_EV_DROP,         /* protocol error ev.error: close and reconnect */
    URRT_RTDE_EV_CONFIG,       /* configuration error ev.error: close, back off long */
    URRT_RTDE_EV_INPUTS        /* urrt_rtde_in_feed only: an input recipe accepted (urrt_rtde_in.h) */
} urrt_rtde_event_kind;

/* Text message levels. */
#define URRT_RTDE_LEVEL_EXCEPTION 0
#define URRT_RTDE_LEVEL_ERROR 1
#define URRT_RTDE_LEVEL_WARNING 2
#define URRT_RTDE_LEVEL_INFO 3

typedef struct urrt_rtde_event {
    urrt_rtde_event_kind kind;
    int error;             /* EV_DROP, EV_CONFIG: the reason */
    uint8_t protocol;      /* EV_PROTOCOL; EV_FALLBACK: the version asked for next */
    uint8_t recipe_id;     /* EV_RECIPE; EV_INPUTS: the input recipe's */
    uint8_t level;         /* EV_TEXT: URRT_RTDE_LEVEL_*, as sent (may be past 3) */
    bool first;            /* EV_DATA: the session's first data package ("up") */
    uint32_t version[4];   /* EV_CONTROLLER: major, minor, bugfix, build */
    const char *text;      /* EV_TEXT: text_len bytes, not NUL-terminated; valid */
    const char *source;    /* until the next feed (source_len 0 in protocol 1) */
    uint16_t text_len;
    uint16_t source_len;
    uint16_t not_found;    /* EV_CONFIG with URRT_RTDE_E_NOT_FOUND (or _IN_USE): how many names */
    int var;               /* EV_CONFIG, URRT_RTDE_E_TYPE_MISMATCH (an input setup's refusal too):
                            * the variable; EV_INPUTS: the input recipe's index */
} urrt_rtde_event;

typedef struct urrt_rtde_stats {
    uint64_t bytes;     /* fed */
    uint64_t packages;  /* complete packages received */
    uint64_t data;      /* data packages decoded */
    uint64_t texts;     /* text messages */
    uint64_t ignored;   /* replies nobody waited for, unknown package types */
    uint64_t errors;    /* sessions ended by an error */
} urrt_rtde_stats;

/* One compiled recipe entry: where a variable sits in a data package, where
 * it goes and how it is converted. Variables that follow each other both on
 * the wire and in their struct, converted alike (target_q, target_qd, ...:
 * doubles; robot_mode, joint_mode, safety_mode: int32s into doubles;
 * robot_status_bits, safety_status_bits: 32 bits) are one entry, a run.
 * The short entries (up to 8 doubles or 32-bit values) come first, those
 * into urrt_state before those into urrt_rtde_values, each in wire order;
 * then the rest. */
typedef struct urrt_rtde_entry {
    uint16_t wire_offset; /* from the package's first byte */
    uint16_t dest_offset; /* bytes into urrt_state or urrt_rtde_values */
    uint16_t count;       /* elements */
    uint8_t op;           /* how each element is converted, internal */
    uint8_t to_state;     /* 1: urrt_state (as doubles), 0: urrt_rtde_values */
} urrt_rtde_entry;

typedef struct urrt_rtde {
    uint8_t buf[URRT_RTDE_PACKAGE_MAX];       /* the package being received */
    urrt_rtde_entry recipe[URRT_RTDE_MAX_VARS]; /* compiled from the setup reply */
    uint16_t vars[URRT_RTDE_MAX_VARS];        /* the variables asked for, in order */
    uint32_t values_present[URRT_RTDE_PRESENT_WORDS]; /* urrt_rtde_values present bits of the recipe */
    uint8_t not_found[URRT_RTDE_MAX_VARS / 8]; /* bit i: vars[i] was NOT_FOUND */
    uint16_t var_count;
    uint16_t entry_count;  /* entries of recipe[] in use */
    uint16_t state_entries; /* of the short entries, the first ones, into urrt_state, internal */
    uint16_t data_size;    /* size of a data package of the accepted recipe, 0 before */
    uint32_t head, head_mask; /* a data package's first bytes, internal */
    uint16_t have;         /* bytes of buf filled */
    uint16_t need;         /* size of the package being received, 0 in its header */
    uint16_t short_entries; /* of recipe[], the first ones, converted without a loop (the
                             * rest: long runs, other conversions), internal */
    double frequency;      /* asked for; 0: the controller's maximum */
    uint64_t state_present; /* urrt_state present mask of the recipe */
    uint32_t controller[4];
    int error;             /* the error that ended the session, 0 */
    uint8_t phase;         /* internal */
    uint8_t pending;       /* the request urrt_rtde_output gives next, internal */
    uint8_t protocol;      /* asked for until accepted, then the one in use */
    uint8_t protocol_accepted;
    uint8_t recipe_id;
    uint8_t has_values;    /* the recipe has RTDE-only variables */
    uint8_t has_state;     /* the recipe has variables of urrt_state */
    uint8_t up;            /* a data package was decoded in this session */
    urrt_rtde_stats stats;
} urrt_rtde;

#define URRT_RTDE_RAM (sizeof(urrt_rtde))

/* Zero everything, statistics included. The session then waits for begin. */
void urrt_rtde_init(urrt_rtde *s);

/*
 * Start a session on a fresh connection: forget any partial package and
 * any earlier handshake, keep the statistics, and queue the protocol version
 * request. vars: count (1..URRT_RTDE_MAX_VARS) distinct variable ids, the
 * recipe in the order asked. frequency: Hz, 0 for the controller's maximum
 * (125 on CB3, 500 later); ignored by protocol 1, checked against the
 * controller's maximum when its version is known. Returns URRT_OK or an
 * error (URRT_E_ARG, URRT_RTDE_E_DUPLICATE, URRT_RTDE_E_NAMES_TOO_LONG),
 * in which case the session waits for a good begin.
 */
int urrt_rtde_begin(urrt_rtde *s, const uint16_t *vars, size_t count, double frequency);

/* Between EV_CONTROLLER and the setup request, the controller's version now
 * known (s->controller): replace the recipe, by begin's rules (to leave out
 * what this version lacks). URRT_OK, or begin's errors, or URRT_E_ARG in
 * another phase; on an error the recipe is unchanged. */
int urrt_rtde_set_recipe(urrt_rtde *s, const uint16_t *vars, size_t count);

/* The next request to send: writes it whole into out (cap >=
 * URRT_RTDE_REQUEST_MAX is always enough) and returns its size, 0 when none
 * is due, URRT_E_NO_SPACE (the request stays due) or URRT_E_ARG. */
int urrt_rtde_output(urrt_rtde *s, uint8_t *out, size_t cap);

/*
 * Feed received bytes. Consumes bytes until an event completes (returns its
 * kind, > 0, *used says how many bytes) or all are consumed (returns
 * URRT_RTDE_EV_NONE). Any chunking of the same bytes gives the same events.
 * On URRT_RTDE_EV_DATA, *st (and *vals if the recipe has RTDE-only
 * variables) hold the package as urrt_rtde_decode writes it; either may be
 * NULL if the recipe has no variable for it. On URRT_RTDE_EV_RECIPE, *st and
 * *vals (those not NULL) are cleared: every member absent (NaN, 0), present
 * none, so that what the recipe lacks stays absent for the session. A data
 * package a read holds whole is decoded in place, in data; the bytes of a
 * package split across reads are gathered in s->buf. On EV_DROP or EV_CONFIG
 * the session has ended: later feeds return URRT_RTDE_E_ENDED until the next
 * begin. URRT_E_ARG for null pointers, URRT_RTDE_E_ENDED also before the
 * first begin.
 */
int urrt_rtde_feed(urrt_rtde *s, const uint8_t *data, size_t len, size_t *used, urrt_rtde_event *ev,
                   urrt_state *st, urrt_rtde_values *vals);

/* The connection closed: returns how many bytes of an incomplete package
 * are dropped (0 on a package boundary); the session waits for begin. */
size_t urrt_rtde_finish(urrt_rtde *s);

/* Queue a pause (once streaming) or a start (once paused). URRT_OK, or
 * URRT_E_ARG in another phase or with a request still due. */
int urrt_rtde_pause(urrt_rtde *s);
int urrt_rtde_start(urrt_rtde *s);

/* True once the session has decoded its first data package ("up"). */
bool urrt_rtde_up(const urrt_rtde *s);

/* The most this session's controller streams, in Hz (URRT_RTDE_HZ_CB3 for
 * major < 5, else URRT_RTDE_HZ_E_SERIES): what a frequency of 0 asks for,
 * and what URRT_RTDE_E_FREQUENCY compares with once the version is known. */
double urrt_rtde_max_frequency(const urrt_rtde *s);

/* For the writing side (urrt_rtde_in.h), which runs the handshake around
 * this one; a read-only firmware calls none of them and links none.
 * urrt_rtde_due: the type letter of the request urrt_rtde_output writes
 * next, 0 when none is due. urrt_rtde_streaming: start was accepted and the
 * session is neither paused (nor asked to pause) nor ended. urrt_rtde_end:
 * ends the session with error (< 0) as a reply that broke the protocol or
 * the configuration would (ev gets EV_DROP or EV_CONFIG, as
 * urrt_rtde_is_config_error says; later feeds return URRT_RTDE_E_ENDED);
 * returns the event's kind, or URRT_E_ARG for null pointers or error >= 0. */
int urrt_rtde_due(const urrt_rtde *s);
bool urrt_rtde_streaming(const urrt_rtde *s);
int urrt_rtde_end(urrt_rtde *s, urrt_rtde_event *ev, int error);

/* The i-th variable (0-based) the controller answered NOT_FOUND for, or -1
 * past the last: after an EV_CONFIG with URRT_RTDE_E_NOT_FOUND. */
int urrt_rtde_not_found(const urrt_rtde *s, size_t i);

/*
 * Decode one data package (size bytes, header included, anywhere in memory)
 * through the session's accepted recipe: what feed does for each. *st gets
 * the mapped variables (present their mask, length the package size,
 * doubles and extra_columns 0, generation URRT_GEN_3X: RTDE's robot mode
 * numbering is 3.x/5.x's); *vals the RTDE-only ones and its present bits,
 * whole. Nothing else of either is written: the members the recipe lacks
 * keep what they held (NaN and 0 after a clear; see the top of this file).
 * Returns the size, or URRT_RTDE_E_DATA_EARLY, _DATA_SIZE, _RECIPE_ID,
 * URRT_E_ARG.
 */
int urrt_rtde_decode(const urrt_rtde *s, const uint8_t *pkg, size_t size, urrt_state *st,
                     urrt_rtde_values *vals);

#ifdef __cplusplus
}
#endif

#endif /* URRT_RTDE_H */
