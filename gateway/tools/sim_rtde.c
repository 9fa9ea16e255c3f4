/* SPDX-License-Identifier: MIT */
/*
 * sim_rtde.c: see sim_rtde.h. The wire format, big-endian throughout: a
 * package is uint16 size (header included), uint8 type letter, payload.
 * docs/tools.md ("RTDE") states what the simulator does where UR's
 * documentation is silent.
 */
#include "sim_rtde.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "port.h"
#include "rtde_capture.h"

/* Package types. */
#define RTDE_V_PROTOCOL 'V'
#define RTDE_V_URCONTROL 'v'
#define RTDE_TEXT 'M'
#define RTDE_DATA 'U'
#define RTDE_SETUP_OUTPUTS 'O'
#define RTDE_SETUP_INPUTS 'I'
#define RTDE_START 'S'
#define RTDE_PAUSE 'P'
#define RTDE_HEADER 3
#define RTDE_SIZE_MAX 65535u
#define RTDE_OUTPUT_RECIPE_ID 1
#define LEVEL_ERROR 1

/* A version as one number: 5.5.1 is 50501. */
#define VER(major, minor, bugfix) ((major) * 10000u + (minor) * 100u + (bugfix))
#define NEVER 0u            /* not on this line of controllers */
#define BASE3 VER(3, 3, 0)  /* RTDE's first CB3 version */
#define BASE5 VER(5, 0, 0)
#define REG3 VER(3, 4, 0)   /* the fieldbus range of registers, 0..23 */
#define UPPER3 VER(3, 9, 0) /* the range for RTDE clients, 24..47 and bits 64..127 */
#define UPPER5 VER(5, 3, 0)

typedef enum wire_type {
    W_BOOL, W_UINT8, W_UINT32, W_UINT64, W_INT32, W_DOUBLE, W_VECTOR3D, W_VECTOR6D, W_VECTOR6INT32, W_VECTOR6UINT32
} wire_type;

static const struct {
    const char *token;
    uint8_t count;  /* elements */
    uint8_t size;   /* bytes of one element */
} wire[] = {
    [W_BOOL] = {"BOOL", 1, 1},       [W_UINT8] = {"UINT8", 1, 1},       [W_UINT32] = {"UINT32", 1, 4},
    [W_UINT64] = {"UINT64", 1, 8},   [W_INT32] = {"INT32", 1, 4},       [W_DOUBLE] = {"DOUBLE", 1, 8},
    [W_VECTOR3D] = {"VECTOR3D", 3, 8}, [W_VECTOR6D] = {"VECTOR6D", 6, 8}, [W_VECTOR6INT32] = {"VECTOR6INT32", 6, 4},
    [W_VECTOR6UINT32] = {"VECTOR6UINT32", 6, 4}, /* no variable of the model's has it; a capture may */
};

/* One cycle's values, every one as doubles (integers up to 2^53 exactly);
 * a recipe field points at its first element. */
typedef struct values {
    double timestamp, target_q[6], target_qd[6], target_qdd[6], target_current[6], target_moment[6];
    double actual_q[6], actual_qd[6], actual_current[6], joint_control_output[6];
    double actual_tcp_pose[6], actual_tcp_speed[6], actual_tcp_force[6], target_tcp_pose[6], target_tcp_speed[6];
    double din, din_conf, dout, dout_conf, joint_temperatures[6], execution_time;
    double robot_mode, joint_mode[6], safety_mode, safety_status, accelerometer[3], speed_scaling;
    double speed_fraction, momentum, main_voltage, robot_voltage, robot_current, joint_voltage[6];
    double runtime_state, elbow_position[3], elbow_velocity[3], robot_status_bits, safety_status_bits;
    double payload, payload_cog[3], payload_inertia[6], time_scale_source, control_step;
    double tool_output_voltage, ft_raw_wrench[6];
    double out_bits[2], out_bit[64], out_int[48], out_double[48];
    double in_bits[2], in_bit[64], in_int[48], in_double[48];
    double zero[6];   /* every variable the model does not move */
} values;

#define VALUES_COUNT (sizeof(values) / sizeof(double))
#define AT(member) ((uint16_t)(offsetof(values, member) / sizeof(double)))

typedef struct variable {
    const char *name;
    uint8_t type;
    uint32_t since3, since5;   /* first CB3 and e-Series versions, NEVER if none */
    uint16_t value;
} variable;

/* UR's output variables and the first versions that have them. Where UR
 * gives no version the simulator serves the variable on every version. */
static const variable outputs[] = {
    {"timestamp", W_DOUBLE, BASE3, BASE5, AT(timestamp)},
    {"target_q", W_VECTOR6D, BASE3, BASE5, AT(target_q)},
    {"target_qd", W_VECTOR6D, BASE3, BASE5, AT(target_qd)},
    {"target_qdd", W_VECTOR6D, BASE3, BASE5, AT(target_qdd)},
    {"target_current", W_VECTOR6D, BASE3, BASE5, AT(target_current)},
    {"target_moment", W_VECTOR6D, BASE3, BASE5, AT(target_moment)},
    {"actual_q", W_VECTOR6D, BASE3, BASE5, AT(actual_q)},
    {"actual_qd", W_VECTOR6D, BASE3, BASE5, AT(actual_qd)},
    {"actual_current", W_VECTOR6D, BASE3, BASE5, AT(actual_current)},
    {"actual_current_window", W_VECTOR6D, BASE3, BASE5, AT(zero)},
    {"actual_current_as_torque", W_VECTOR6D, NEVER, VER(5, 23, 0), AT(zero)},
    {"joint_control_output", W_VECTOR6D, BASE3, BASE5, AT(joint_control_output)},
    {"actual_TCP_pose", W_VECTOR6D, BASE3, BASE5, AT(actual_tcp_pose)},
    {"actual_TCP_speed", W_VECTOR6D, BASE3, BASE5, AT(actual_tcp_speed)},
    {"actual_TCP_force", W_VECTOR6D, BASE3, BASE5, AT(actual_tcp_force)},
    {"target_TCP_pose", W_VECTOR6D, BASE3, BASE5, AT(target_tcp_pose)},
    {"target_TCP_speed", W_VECTOR6D, BASE3, BASE5, AT(target_tcp_speed)},
    {"tcp_offset", W_VECTOR6D, BASE3, BASE5, AT(zero)},
    {"actual_TCP_acceleration", W_VECTOR6D, BASE3, BASE5, AT(zero)},
    {"target_TCP_acceleration", W_VECTOR6D, BASE3, BASE5, AT(zero)},
    {"actual_digital_input_bits", W_UINT64, BASE3, BASE5, AT(din)},
    {"actual_configurable_digital_input_bits", W_UINT64, BASE3, BASE5, AT(din_conf)},
    {"joint_temperatures", W_VECTOR6D, BASE3, BASE5, AT(joint_temperatures)},
    {"actual_execution_time", W_DOUBLE, BASE3, BASE5, AT(execution_time)},
    {"target_execution_time", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"robot_mode", W_INT32, BASE3, BASE5, AT(robot_mode)},
    {"joint_mode", W_VECTOR6INT32, BASE3, BASE5, AT(joint_mode)},
    {"safety_mode", W_INT32, BASE3, BASE5, AT(safety_mode)},
    {"safety_status", W_INT32, VER(3, 10, 0), VER(5, 4, 0), AT(safety_status)},
    {"actual_tool_accelerometer", W_VECTOR3D, BASE3, BASE5, AT(accelerometer)},
    {"speed_scaling", W_DOUBLE, BASE3, BASE5, AT(speed_scaling)},
    {"target_speed_fraction", W_DOUBLE, BASE3, BASE5, AT(speed_fraction)},
    {"actual_momentum", W_DOUBLE, BASE3, BASE5, AT(momentum)},
    {"actual_main_voltage", W_DOUBLE, BASE3, BASE5, AT(main_voltage)},
    {"actual_robot_voltage", W_DOUBLE, BASE3, BASE5, AT(robot_voltage)},
    {"actual_robot_current", W_DOUBLE, BASE3, BASE5, AT(robot_current)},
    {"actual_joint_voltage", W_VECTOR6D, BASE3, BASE5, AT(joint_voltage)},
    {"actual_digital_output_bits", W_UINT64, BASE3, BASE5, AT(dout)},
    {"actual_configurable_digital_output_bits", W_UINT64, BASE3, BASE5, AT(dout_conf)},
    {"runtime_state", W_UINT32, BASE3, BASE5, AT(runtime_state)},
    {"elbow_position", W_VECTOR3D, VER(3, 5, 0), BASE5, AT(elbow_position)},
    {"elbow_velocity", W_VECTOR3D, VER(3, 5, 0), BASE5, AT(elbow_velocity)},
    {"robot_status_bits", W_UINT32, BASE3, BASE5, AT(robot_status_bits)},
    {"safety_status_bits", W_UINT32, BASE3, BASE5, AT(safety_status_bits)},
    {"analog_io_types", W_UINT32, BASE3, BASE5, AT(zero)},
    {"standard_analog_input0", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"standard_analog_input1", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"standard_analog_output0", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"standard_analog_output1", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"io_current", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"output_bit_registers0_to_31", W_UINT32, BASE3, BASE5, AT(out_bits[0])},
    {"output_bit_registers32_to_63", W_UINT32, BASE3, BASE5, AT(out_bits[1])},
    {"input_bit_registers0_to_31", W_UINT32, REG3, BASE5, AT(in_bits[0])},
    {"input_bit_registers32_to_63", W_UINT32, REG3, BASE5, AT(in_bits[1])},
    {"actual_robot_energy_consumed", W_DOUBLE, NEVER, VER(5, 23, 0), AT(zero)},
    {"actual_robot_braking_energy_dissipated", W_DOUBLE, NEVER, VER(5, 23, 0), AT(zero)},
    {"encoder0_raw", W_INT32, BASE3, BASE5, AT(zero)},
    {"encoder1_raw", W_INT32, BASE3, BASE5, AT(zero)},
    {"euromap67_input_bits", W_UINT32, BASE3, BASE5, AT(zero)},
    {"euromap67_output_bits", W_UINT32, BASE3, BASE5, AT(zero)},
    {"euromap67_24V_voltage", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"euromap67_24V_current", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"tool_mode", W_UINT32, BASE3, BASE5, AT(zero)},
    {"tool_analog_input_types", W_UINT32, BASE3, BASE5, AT(zero)},
    {"tool_analog_input0", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"tool_analog_input1", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"tool_output_voltage", W_INT32, BASE3, BASE5, AT(tool_output_voltage)},
    {"tool_output_current", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"tool_temperature", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"tool_output_mode", W_UINT8, BASE3, BASE5, AT(zero)},
    {"tool_digital_output0_mode", W_UINT8, BASE3, BASE5, AT(zero)},
    {"tool_digital_output1_mode", W_UINT8, BASE3, BASE5, AT(zero)},
    {"tcp_force_scalar", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"joint_position_deviation_ratio", W_DOUBLE, BASE3, BASE5, AT(zero)},
    {"collision_detection_ratio", W_DOUBLE, NEVER, VER(5, 15, 0), AT(zero)},
    {"ft_raw_wrench", W_VECTOR6D, NEVER, VER(5, 9, 0), AT(ft_raw_wrench)},
    {"wrench_calc_from_currents", W_VECTOR6D, BASE3, BASE5, AT(zero)},
    {"payload", W_DOUBLE, VER(3, 11, 0), VER(5, 5, 1), AT(payload)},
    {"payload_cog", W_VECTOR3D, VER(3, 11, 0), VER(5, 5, 1), AT(payload_cog)},
    {"payload_inertia", W_VECTOR6D, VER(3, 15, 0), VER(5, 11, 0), AT(payload_inertia)},
    {"script_control_line", W_UINT32, VER(3, 14, 0), VER(5, 9, 0), AT(zero)},
    {"time_scale_source", W_INT32, NEVER, VER(5, 17, 0), AT(time_scale_source)},
    {"target_gravity", W_VECTOR3D, NEVER, VER(5, 26, 0), AT(zero)},
    {"target_base_acceleration", W_VECTOR6D, NEVER, VER(5, 26, 0), AT(zero)},
    {"control_step", W_UINT64, NEVER, VER(5, 26, 0), AT(control_step)},
    {"target_base_wrench", W_VECTOR6D, NEVER, VER(5, 26, 0), AT(zero)},
};

/* The controller's inputs, one double per element: sim_rtde_inputs.value
 * and .next by these indices (slots). A variable is owned at its first slot. */
typedef struct input_values {
    double in_int[48], in_double[48], in_bit[64], in_bits[2];
    double speed_slider_mask, speed_slider_fraction;
    double standard_digital_output_mask, standard_digital_output;
    double configurable_digital_output_mask, configurable_digital_output;
    double tool_digital_output_mask, tool_digital_output;
    double standard_analog_output_mask, standard_analog_output_type, standard_analog_output[2];
    double external_force_torque[6];
} input_values;

_Static_assert(sizeof(input_values) == SIM_RTDE_INPUT_SLOTS * sizeof(double), "a slot per input element");
#define IN_AT(member) ((uint16_t)(offsetof(input_values, member) / sizeof(double)))
_Static_assert(offsetof(input_values, in_int) == 0, "the int registers are slots 0..47");
/* The fieldbus adapters' range: registers 0..23 and bits 0..63. */
#define FIELDBUS_REGISTERS 24u

/* Inputs (RTDE_CONTROL_PACKAGE_SETUP_INPUTS) other than the numbered
 * registers: a controller takes them all (urrt writes registers only). */
static const variable inputs[] = {
    {"speed_slider_mask", W_UINT32, BASE3, BASE5, IN_AT(speed_slider_mask)},
    {"speed_slider_fraction", W_DOUBLE, BASE3, BASE5, IN_AT(speed_slider_fraction)},
    {"standard_digital_output_mask", W_UINT8, BASE3, BASE5, IN_AT(standard_digital_output_mask)},
    {"standard_digital_output", W_UINT8, BASE3, BASE5, IN_AT(standard_digital_output)},
    {"configurable_digital_output_mask", W_UINT8, BASE3, BASE5, IN_AT(configurable_digital_output_mask)},
    {"configurable_digital_output", W_UINT8, BASE3, BASE5, IN_AT(configurable_digital_output)},
    {"tool_digital_output_mask", W_UINT8, BASE3, BASE5, IN_AT(tool_digital_output_mask)},
    {"tool_digital_output", W_UINT8, BASE3, BASE5, IN_AT(tool_digital_output)},
    {"standard_analog_output_mask", W_UINT8, BASE3, BASE5, IN_AT(standard_analog_output_mask)},
    {"standard_analog_output_type", W_UINT8, BASE3, BASE5, IN_AT(standard_analog_output_type)},
    {"standard_analog_output_0", W_DOUBLE, BASE3, BASE5, IN_AT(standard_analog_output[0])},
    {"standard_analog_output_1", W_DOUBLE, BASE3, BASE5, IN_AT(standard_analog_output[1])},
    {"input_bit_registers0_to_31", W_UINT32, REG3, BASE5, IN_AT(in_bits[0])},
    {"input_bit_registers32_to_63", W_UINT32, REG3, BASE5, IN_AT(in_bits[1])},
    {"external_force_torque", W_VECTOR6D, BASE3, BASE5, IN_AT(external_force_torque)},
};

/* The numbered registers: PREFIX + index, a version per range. */
typedef struct register_bank {
    const char *prefix;
    uint8_t type;
    unsigned first, last;       /* indices that exist */
    unsigned upper;             /* from here on: the 3.9 / 5.3 range */
    uint16_t out_value, in_value;
} register_bank;

static const register_bank output_banks[] = {
    {"output_int_register_", W_INT32, 0, 47, 24, AT(out_int), 0},
    {"output_double_register_", W_DOUBLE, 0, 47, 24, AT(out_double), 0},
    {"output_bit_register_", W_BOOL, 64, 127, 64, AT(out_bit), 0},
    {"input_int_register_", W_INT32, 0, 47, 24, AT(in_int), 0},
    {"input_double_register_", W_DOUBLE, 0, 47, 24, AT(in_double), 0},
    {"input_bit_register_", W_BOOL, 64, 127, 64, AT(in_bit), 0},
};
static const register_bank input_banks[] = {
    {"input_int_register_", W_INT32, 0, 47, 24, 0, IN_AT(in_int)},
    {"input_double_register_", W_DOUBLE, 0, 47, 24, 0, IN_AT(in_double)},
    {"input_bit_register_", W_BOOL, 64, 127, 64, 0, IN_AT(in_bit)},
};

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

static uint32_t version_number(const sim_rtde_controller *c)
{
    uint32_t minor = c->minor < 99 ? c->minor : 99, bugfix = c->bugfix < 99 ? c->bugfix : 99;
    return VER(c->major, minor, bugfix);
}

/* Whether the controller has a variable introduced at since3 / since5. */
static bool has_version(const sim_rtde_controller *c, uint32_t since3, uint32_t since5)
{
    uint32_t since = c->major >= 5 ? since5 : since3;
    return since != NEVER && version_number(c) >= since;
}

static bool parse_u32(const char **p, uint32_t *out)
{
    const char *s = *p;
    uint64_t v = 0;
    if (*s < '0' || *s > '9') {
        return false;
    }
    while (*s >= '0' && *s <= '9') {
        v = v * 10u + (uint64_t)(*s++ - '0');
        if (v > UINT32_MAX) {
            return false;
        }
    }
    *out = (uint32_t)v;
    *p = s;
    return true;
}

const char *sim_rtde_controller_parse(const char *text, sim_rtde_controller *c)
{
    uint32_t *parts[4] = {&c->major, &c->minor, &c->bugfix, &c->build};
    const char *p = text;
    size_t n = 0;
    memset(c, 0, sizeof *c);
    while (n < 4 && parse_u32(&p, parts[n])) {
        n++;
        if (*p != '.') {
            break;
        }
        p++;
    }
    if (n < 2 || *p != '\0') {
        return "not a version: MAJOR.MINOR[.BUGFIX[.BUILD]]";
    }
    if (version_number(c) < BASE3 || (c->major != 3 && c->major != 5)) {
        return "no RTDE on this version (CB3 from 3.3, and e-Series 5.x)";
    }
    c->rate_hz = c->major >= 5 ? 500u : 125u;
    c->cycle_hz = c->rate_hz;
    return NULL;
}

/* ---- sending --------------------------------------------------------------- */

static void put_u16(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 8);
    p[1] = (uint8_t)v;
}

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) {
        p[i] = (uint8_t)(v >> (24 - 8 * i));
    }
}

static void put_u64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++) {
        p[i] = (uint8_t)(v >> (56 - 8 * i));
    }
}

/* One package: header and payload (len bytes). */
static bool send_package(sim_rtde_session *s, uint8_t type, const uint8_t *payload, size_t len)
{
    static uint8_t pkg[RTDE_SIZE_MAX];
    if (len > RTDE_SIZE_MAX - RTDE_HEADER) {
        return false;
    }
    put_u16(pkg, (uint32_t)(len + RTDE_HEADER));
    pkg[2] = type;
    if (len > 0) {
        memcpy(pkg + RTDE_HEADER, payload, len);
    }
    return s->emit(s->emit_ctx, pkg, len + RTDE_HEADER);
}

/* A text message in the layout of the protocol in force: v2 length-prefixed
 * message and source and a level; v1 (controller to client) the level and
 * the message to the end of the package. */
static bool send_text_from(sim_rtde_session *s, uint8_t level, const char *msg, size_t mlen, const char *source,
                           size_t slen)
{
    uint8_t p[600];
    size_t n = 0;
    mlen = mlen > 255 ? 255 : mlen;
    slen = slen > 255 ? 255 : slen;
    if (s->protocol >= 2) {
        p[n++] = (uint8_t)mlen;
        memcpy(p + n, msg, mlen);
        n += mlen;
        p[n++] = (uint8_t)slen;
        memcpy(p + n, source, slen);
        n += slen;
        p[n++] = level;
    } else {
        p[n++] = level;
        memcpy(p + n, msg, mlen);
        n += mlen;
    }
    s->texts_sent++;
    return send_package(s, RTDE_TEXT, p, n);
}

static bool send_text(sim_rtde_session *s, uint8_t level, const char *msg)
{
    static const char source[] = "urrt-sim";
    return send_text_from(s, level, msg, strlen(msg), source, sizeof source - 1);
}

/* A protocol problem, told the client as the controller does (an error
 * text message) and logged here. */
static bool complain(sim_rtde_session *s, const char *msg)
{
    urrt_log(URRT_LOG_INFO, "RTDE client %s: %s", s->peer, msg);
    return send_text(s, LEVEL_ERROR, msg);
}

/* A reply, after a text message when the fault asks for one. */
static bool reply(sim_rtde_session *s, uint8_t type, const uint8_t *payload, size_t len)
{
    if (s->faults->text_handshake) {
        char msg[64];
        snprintf(msg, sizeof msg, "urrt-sim: before the reply to '%c' (fault rtde-text-handshake)", type);
        if (!send_text(s, 3, msg)) {
            return false;
        }
    }
    return send_package(s, type, payload, len);
}

static bool reply_byte(sim_rtde_session *s, uint8_t type, uint8_t value)
{
    return reply(s, type, &value, 1);
}

/* ---- requests ---------------------------------------------------------------- */

static bool on_protocol_version(sim_rtde_session *s, const uint8_t *p, size_t len)
{
    unsigned asked;
    bool accept;
    if (len != 2) {
        return complain(s, "RTDE_REQUEST_PROTOCOL_VERSION takes a uint16 version") &&
               reply_byte(s, RTDE_V_PROTOCOL, 0);
    }
    asked = (unsigned)p[0] << 8 | p[1];
    /* Protocol 2 came with 3.4; before it only 1. */
    accept = asked == 1 || (asked == 2 && version_number(s->ctl) >= VER(3, 4, 0) && !s->faults->refuse_v2);
    if (s->ctl->recording != NULL && asked < 3 && s->ctl->recording->protocol_answer[asked] >= 0) {
        /* The capture's controller's own answer. */
        accept = s->ctl->recording->protocol_answer[asked] == 1 && !(asked == 2 && s->faults->refuse_v2);
    }
    urrt_log(URRT_LOG_INFO, "RTDE client %s asks for protocol %u: %s", s->peer, asked, accept ? "accepted" : "refused");
    /* The reply in the layout of the protocol in force before it. */
    if (!reply_byte(s, RTDE_V_PROTOCOL, accept ? 1 : 0)) {
        return false;
    }
    if (accept) {
        s->protocol = asked;
    }
    return true;
}

static bool on_urcontrol_version(sim_rtde_session *s)
{
    uint8_t p[16];
    put_u32(p, s->ctl->major);
    put_u32(p + 4, s->ctl->minor);
    put_u32(p + 8, s->ctl->bugfix);
    put_u32(p + 12, s->ctl->build);
    return reply(s, RTDE_V_URCONTROL, p, sizeof p);
}

/* A register name: the bank's prefix, then an index written plainly. */
static bool find_register(const sim_rtde_controller *c, const register_bank *banks, size_t nbanks, const char *name,
                          size_t len, bool as_input, sim_rtde_field *f)
{
    for (size_t b = 0; b < nbanks; b++) {
        const register_bank *bk = &banks[b];
        size_t plen = strlen(bk->prefix);
        unsigned index = 0;
        if (len <= plen || len > plen + 3 || memcmp(name, bk->prefix, plen) != 0 ||
            (name[plen] == '0' && len > plen + 1)) {
            continue;
        }
        for (size_t i = plen; i < len; i++) {
            if (name[i] < '0' || name[i] > '9') {
                return false;
            }
            index = index * 10u + (unsigned)(name[i] - '0');
        }
        if (index < bk->first || index > bk->last) {
            return false;
        }
        if (!(index >= bk->upper ? has_version(c, UPPER3, UPPER5) : has_version(c, REG3, BASE5))) {
            return false;
        }
        f->type = bk->type;
        f->value = (uint16_t)((as_input ? bk->in_value : bk->out_value) + index - bk->first);
        return true;
    }
    return false;
}

/* A name (len bytes, not terminated) of the list, as this controller
 * version knows it: false for NOT_FOUND. */
static bool find_variable(const sim_rtde_controller *c, const char *name, size_t len, bool input, sim_rtde_field *f)
{
    const variable *table = input ? inputs : outputs;
    size_t n = input ? COUNT(inputs) : COUNT(outputs);
    if (c->recording != NULL && !input) {
        /* A capture's controller has the variables recorded, no other. */
        const sim_rtde_recording *r = c->recording;
        for (size_t i = 0; i < r->nfields; i++) {
            if (r->fields[i].len == len && memcmp(r->fields[i].name, name, len) == 0) {
                f->type = r->fields[i].type;
                f->value = (uint16_t)i;
                return true;
            }
        }
        return false;
    }
    for (size_t i = 0; i < n; i++) {
        if (strlen(table[i].name) == len && memcmp(table[i].name, name, len) == 0) {
            if (!has_version(c, table[i].since3, table[i].since5)) {
                return false;
            }
            f->type = table[i].type;
            f->value = table[i].value;
            return true;
        }
    }
    return input ? find_register(c, input_banks, COUNT(input_banks), name, len, true, f)
                 : find_register(c, output_banks, COUNT(output_banks), name, len, false, f);
}

/* Whether an input variable (by its first slot) belongs to another: to an
 * enabled fieldbus adapter (registers 0..23, the words of bits 0..63), or
 * to another connection's input recipe (one that left too, while
 * rtde-hold-inputs holds its variables). */
static bool input_in_use(const sim_rtde_session *s, uint16_t slot)
{
    uint32_t owner = s->ctl->inputs.owner[slot];
    if (s->ctl->fieldbus &&
        (slot < IN_AT(in_int) + FIELDBUS_REGISTERS || /* in_int is slot 0 on */
         (slot >= IN_AT(in_double) && slot < IN_AT(in_double) + FIELDBUS_REGISTERS) || slot == IN_AT(in_bits[0]) ||
         slot == IN_AT(in_bits[1]))) {
        return true;
    }
    return owner != 0 && owner != s->id;
}

/* The names of a setup, one by one: the type list of the reply, the
 * fields in out (up to max, NULL to drop them). Returns the number of
 * names, *found the number with a type, *in_use (inputs) the number known
 * but another's; the types go to types (NUL-terminated). */
static size_t resolve_names(const sim_rtde_session *s, const uint8_t *names, size_t len, bool input,
                            sim_rtde_field *out, size_t max, size_t *found, size_t *in_use, char *types,
                            size_t types_cap)
{
    size_t count = 0, tlen = 0, start = 0;
    *found = 0;
    *in_use = 0;
    types[0] = '\0';
    for (size_t i = 0; i <= len; i++) {
        sim_rtde_field f;
        const char *token;
        if (i < len && names[i] != ',') {
            continue;
        }
        if (!find_variable(s->ctl, (const char *)names + start, i - start, input, &f)) {
            token = "NOT_FOUND";
        } else if (input && input_in_use(s, f.value)) {
            token = "IN_USE";
            (*in_use)++;
        } else {
            token = wire[f.type].token;
            if (out != NULL && *found < max) {
                out[*found] = f;
            }
            (*found)++;
        }
        tlen += (size_t)snprintf(types + tlen, types_cap - tlen, "%s%s", count ? "," : "", token);
        tlen = tlen < types_cap ? tlen : types_cap - 1;
        count++;
        start = i + 1;
    }
    return count;
}

/* Why a v2 frequency is refused, or NULL: 1 Hz <= f <= the controller's rate. */
static const char *frequency_problem(const sim_rtde_session *s, double f)
{
    if (!(f >= 1.0)) {
        return "the output frequency must be 1 Hz or more";
    }
    if (f > (double)s->ctl->rate_hz) {
        return s->ctl->rate_hz == 125 ? "the output frequency is above this controller's 125 Hz"
                                      : "the output frequency is above this controller's 500 Hz";
    }
    return NULL;
}

static double get_double(const uint8_t *p)
{
    uint64_t bits = 0;
    double d;
    for (int i = 0; i < 8; i++) {
        bits = bits << 8 | p[i];
    }
    memcpy(&d, &bits, sizeof d);
    return d;
}

static bool on_setup_outputs(sim_rtde_session *s, const uint8_t *p, size_t len)
{
    static char types[SIM_RTDE_NAMES_MAX * 13 + 2];
    uint8_t out[sizeof types + 1];
    double freq = (double)s->ctl->rate_hz;
    const char *problem = NULL;
    size_t names, found, in_use, off = 0, tlen;

    if (s->protocol >= 2) {
        if (len < 8) {
            return complain(s, "RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS takes a double frequency, then the names") &&
                   reply_byte(s, RTDE_SETUP_OUTPUTS, 0);
        }
        freq = get_double(p);
        p += 8;
        len -= 8;
        problem = frequency_problem(s, freq);
    }
    if (len > SIM_RTDE_NAMES_MAX) {
        problem = "the variable names are longer than 2048 bytes";
    }
    names = resolve_names(s, p, len, false, s->fields, SIM_RTDE_RECIPE_MAX, &found, &in_use, types, sizeof types);
    if (problem == NULL && found > SIM_RTDE_RECIPE_MAX) {
        problem = "more variables than the simulator holds in a recipe (512)";
    }
    s->recipe_valid = problem == NULL && found == names;
    s->started = s->started && s->recipe_valid;
    s->nfields = s->recipe_valid ? found : 0;
    s->data_size = 0;
    for (size_t i = 0; i < s->nfields; i++) {
        s->data_size += (size_t)wire[s->fields[i].type].count * wire[s->fields[i].type].size;
    }
    /* Every divisor-th cycle: a rate that does not divide the controller's
     * rounds up to the next one that does (a capture's rate, read from its
     * timestamps, is exact only to a few ulps). */
    s->divisor = problem == NULL ? (uint32_t)floor(s->ctl->cycle_hz / freq + 1e-6) : 1;
    s->divisor = s->divisor ? s->divisor : 1;
    if (problem == NULL && s->ctl->recording != NULL && freq > s->ctl->cycle_hz * (1.0 + 1e-6)) {
        urrt_log(URRT_LOG_NOTICE, "RTDE client %s asks for %g Hz: the capture has %g Hz, it gets every package",
                 s->peer, freq, s->ctl->cycle_hz);
    }
    urrt_log(URRT_LOG_INFO, "RTDE client %s: output recipe of %zu variable%s%s, %s", s->peer, names,
             names == 1 ? "" : "s", found == names ? "" : " (some NOT_FOUND)",
             problem ? problem : s->recipe_valid ? "valid" : "invalid");
    if (problem != NULL && !complain(s, problem)) {
        return false;
    }
    if (s->protocol >= 2) {
        /* Recipe id 0: no valid recipe. */
        out[off++] = s->recipe_valid ? RTDE_OUTPUT_RECIPE_ID : 0;
    }
    tlen = strlen(types);
    memcpy(out + off, types, tlen);
    return reply(s, RTDE_SETUP_OUTPUTS, out, off + tlen);
}

/* Holds of rtde-hold-inputs that are over: their variables free again. */
static void release_held(sim_rtde_inputs *in)
{
    uint64_t now;
    size_t i = 0;
    if (in->nheld == 0) {
        return;
    }
    now = urrt_port_monotonic_us();
    while (i < in->nheld) {
        const sim_rtde_held *h = &in->held[i];
        size_t n = 0;
        if (now < h->until_us) {
            i++;
            continue;
        }
        for (size_t j = 0; j < SIM_RTDE_INPUT_SLOTS; j++) {
            if (in->owner[j] == h->owner) {
                in->owner[j] = 0;
                n++;
            }
        }
        urrt_log(URRT_LOG_INFO, "RTDE client %s: its %zu input variable%s held after it left %s free again "
                 "(fault rtde-hold-inputs)", h->peer, n, n == 1 ? "" : "s", n == 1 ? "is" : "are");
        in->held[i] = in->held[--in->nheld];
    }
}

/* An input recipe: each name's type, IN_USE for another's variable,
 * NOT_FOUND for one this version lacks; any of those, id 0. A valid one
 * gets the next id (SIM_RTDE_INPUT_ID on, the output recipe's is 1) and
 * takes its variables for this connection. Protocol 1 too, with the id. */
static bool on_setup_inputs(sim_rtde_session *s, const uint8_t *p, size_t len)
{
    static char types[SIM_RTDE_NAMES_MAX * 13 + 2];
    static sim_rtde_field fields[SIM_RTDE_RECIPE_MAX];
    uint8_t out[sizeof types + 1];
    const char *problem = NULL;
    size_t names, found, in_use, size = 0, tlen;
    uint8_t id = 0;

    release_held(&s->ctl->inputs);
    names = resolve_names(s, p, len, true, fields, SIM_RTDE_RECIPE_MAX, &found, &in_use, types, sizeof types);
    if (len > SIM_RTDE_NAMES_MAX) {
        problem = "the variable names are longer than 2048 bytes";
    } else if (found > SIM_RTDE_RECIPE_MAX) {
        problem = "more variables than the simulator holds in a recipe (512)";
    } else if (found == names && s->ninputs == SIM_RTDE_INPUT_RECIPES) {
        problem = "more input recipes than the simulator holds on a connection (16)";
    } else if (found == names && s->in_nfields + found > SIM_RTDE_INPUT_FIELDS) {
        problem = "more input variables than the simulator holds on a connection (1024)";
    }
    if (problem == NULL && found == names) {
        sim_rtde_input_recipe *r = &s->inputs[s->ninputs];
        r->first = (uint16_t)s->in_nfields;
        r->count = (uint16_t)found;
        for (size_t i = 0; i < found; i++) {
            s->in_fields[s->in_nfields++] = fields[i];
            size += (size_t)wire[fields[i].type].count * wire[fields[i].type].size;
            s->ctl->inputs.owner[fields[i].value] = s->id;
        }
        r->size = size;
        id = (uint8_t)(SIM_RTDE_INPUT_ID + s->ninputs++);
        urrt_log(URRT_LOG_INFO, "RTDE client %s: input recipe %u of %zu variable%s (%zu bytes of values)", s->peer,
                 (unsigned)id, names, names == 1 ? "" : "s", size);
    } else {
        urrt_log(URRT_LOG_INFO, "RTDE client %s: input recipe of %zu variable%s refused (id 0): %zu NOT_FOUND, %zu "
                 "IN_USE%s%s", s->peer, names, names == 1 ? "" : "s", names - found - in_use, in_use,
                 problem ? ", " : "", problem ? problem : "");
    }
    if (problem != NULL && !complain(s, problem)) {
        return false;
    }
    out[0] = id;
    tlen = strlen(types);
    memcpy(out + 1, types, tlen);
    return reply(s, RTDE_SETUP_INPUTS, out, 1 + tlen);
}

static bool on_start(sim_rtde_session *s)
{
    /* No valid output recipe: nothing to synchronise, start refused. */
    s->started = s->recipe_valid;
    urrt_log(URRT_LOG_INFO, "RTDE client %s: start %s", s->peer, s->started ? "accepted" : "refused (no valid output recipe)");
    return reply_byte(s, RTDE_START, s->started ? 1 : 0);
}

/* An input data package the controller does not take: counted, logged (at
 * -v) and told the client in an error text message, as the simulator tells
 * every request UR's documentation is silent about; nothing is applied. */
static bool ignore_input(sim_rtde_session *s, const char *why)
{
    char msg[160];
    s->inputs_ignored++;
    snprintf(msg, sizeof msg, "%s: ignored", why);
    urrt_log(URRT_LOG_INFO, "RTDE client %s: %s (%" PRIu64 " so far)", s->peer, msg, s->inputs_ignored);
    return send_text(s, LEVEL_ERROR, msg);
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/* A field's values from the wire into the controller's next values (the
 * elements of its slots); returns its bytes. Doubles keep their bits. */
static size_t take_field(const uint8_t *p, const sim_rtde_field *f, sim_rtde_inputs *in)
{
    size_t n = 0;
    for (unsigned e = 0; e < wire[f->type].count; e++) {
        double x;
        switch (f->type) {
        case W_BOOL: x = p[n] != 0 ? 1.0 : 0.0; n += 1; break;
        case W_UINT8: x = p[n]; n += 1; break;
        case W_UINT32:
        case W_VECTOR6UINT32: x = (double)get_u32(p + n); n += 4; break;
        case W_INT32:
        case W_VECTOR6INT32: x = (double)(int32_t)get_u32(p + n); n += 4; break;
        case W_UINT64: x = (double)((uint64_t)get_u32(p + n) << 32 | get_u32(p + n + 4)); n += 8; break;
        default: x = get_double(p + n); n += 8; break;
        }
        in->next[f->value + e] = x;
        in->written[f->value + e] = true;
    }
    return n;
}

/* Input data from the client: protocol 2 names its input recipe by id, a
 * protocol 1 package (no id) is the connection's last input recipe's. Its
 * values take effect at the next control cycle (sim_rtde_due), for every
 * client's output recipe. */
static bool on_input_data(sim_rtde_session *s, const uint8_t *p, size_t len)
{
    sim_rtde_inputs *in = &s->ctl->inputs;
    const sim_rtde_input_recipe *r;
    unsigned id;
    char why[128];

    if (s->protocol >= 2) {
        if (len == 0) {
            return ignore_input(s, "an input data package without a recipe id");
        }
        id = p[0];
        p++;
        len--;
    } else {
        id = s->ninputs > 0 ? SIM_RTDE_INPUT_ID + s->ninputs - 1 : 0;
    }
    if (id < SIM_RTDE_INPUT_ID || id - SIM_RTDE_INPUT_ID >= s->ninputs) {
        if (s->protocol >= 2) {
            snprintf(why, sizeof why, "an input data package of recipe id %u, no input recipe of this connection",
                     id);
        } else {
            snprintf(why, sizeof why, "an input data package before any input recipe");
        }
        return ignore_input(s, why);
    }
    r = &s->inputs[id - SIM_RTDE_INPUT_ID];
    if (len != r->size) {
        snprintf(why, sizeof why, "an input data package of %zu byte%s of values for input recipe %u, which has %zu",
                 len, len == 1 ? "" : "s", id, r->size);
        return ignore_input(s, why);
    }
    if (!s->started) {
        snprintf(why, sizeof why, "an input data package for input recipe %u while not started", id);
        return ignore_input(s, why);
    }
    for (size_t i = 0; i < r->count; i++) {
        p += take_field(p, &s->in_fields[r->first + i], in);
    }
    if (in->npending < SIM_RTDE_PENDING_MAX) {
        sim_rtde_pending *q = &in->pending[in->npending++];
        snprintf(q->peer, sizeof q->peer, "%s", s->peer);
        q->recipe_id = (uint8_t)id;
        q->count = r->count;
    } else {
        in->pending_over++;
    }
    s->inputs_applied++;
    return true;
}

/* A text message from the client goes to the log, as a controller's would. */
static void on_text(sim_rtde_session *s, const uint8_t *p, size_t len)
{
    size_t mlen = len > 0 ? p[0] : 0;
    if (len < 1 + mlen) {
        mlen = len > 0 ? len - 1 : 0;
    }
    urrt_log(URRT_LOG_NOTICE, "RTDE client %s says: %.*s", s->peer, (int)mlen, (const char *)p + 1);
}

/* One whole package from the client. */
static bool on_package(sim_rtde_session *s, uint8_t type, const uint8_t *p, size_t len)
{
    char msg[64];
    switch (type) {
    case RTDE_V_PROTOCOL: return on_protocol_version(s, p, len);
    case RTDE_V_URCONTROL: return on_urcontrol_version(s);
    case RTDE_SETUP_OUTPUTS: return on_setup_outputs(s, p, len);
    case RTDE_SETUP_INPUTS: return on_setup_inputs(s, p, len);
    case RTDE_START: return on_start(s);
    case RTDE_PAUSE:
        /* Always accepted. */
        s->started = false;
        return reply_byte(s, RTDE_PAUSE, 1);
    case RTDE_DATA: return on_input_data(s, p, len);
    case RTDE_TEXT: on_text(s, p, len); return true;
    default:
        snprintf(msg, sizeof msg, "unknown package type %u", (unsigned)type);
        return complain(s, msg);
    }
}

void sim_rtde_session_init(sim_rtde_session *s, sim_rtde_controller *ctl, const sim_rtde_faults *faults,
                           sim_rtde_emit emit, void *emit_ctx, const char *peer)
{
    memset(s, 0, sizeof *s);
    s->ctl = ctl;
    if (++ctl->inputs.sessions == 0) {
        ctl->inputs.sessions = 1; /* 0 is no owner */
    }
    s->id = ctl->inputs.sessions;
    s->faults = faults;
    s->emit = emit;
    s->emit_ctx = emit_ctx;
    s->protocol = 1;
    s->divisor = 1;
    snprintf(s->peer, sizeof s->peer, "%s", peer);
}

void sim_rtde_session_end(sim_rtde_session *s)
{
    sim_rtde_inputs *in = &s->ctl->inputs;
    uint32_t hold = s->faults->hold_inputs_ms;
    size_t n = 0;
    for (size_t i = 0; i < SIM_RTDE_INPUT_SLOTS; i++) {
        if (in->owner[i] == s->id) {
            n++;
            if (hold == 0) {
                in->owner[i] = 0;
            }
        }
    }
    if (n > 0 && hold != 0) {
        sim_rtde_held *h;
        if (in->nheld == SIM_RTDE_HELD_MAX) {
            size_t first = 0; /* the hold that ends first ends now */
            for (size_t i = 1; i < in->nheld; i++) {
                first = in->held[i].until_us < in->held[first].until_us ? i : first;
            }
            in->held[first].until_us = 0;
            release_held(in);
        }
        h = &in->held[in->nheld++];
        h->owner = s->id;
        h->until_us = urrt_port_monotonic_us() + (uint64_t)hold * 1000u;
        snprintf(h->peer, sizeof h->peer, "%s", s->peer);
        urrt_log(URRT_LOG_INFO, "RTDE client %s left: its %zu input variable%s stay%s IN_USE for %" PRIu32 " ms "
                 "(fault rtde-hold-inputs)", s->peer, n, n == 1 ? "" : "s", n == 1 ? "s" : "", hold);
    } else if (n > 0) {
        urrt_log(URRT_LOG_INFO, "RTDE client %s left: its %zu input variable%s %s free again, %s kept", s->peer, n,
                 n == 1 ? "" : "s", n == 1 ? "is" : "are", n == 1 ? "its value" : "their values");
    }
    if (s->inputs_applied != 0 || s->inputs_ignored != 0) {
        urrt_log(URRT_LOG_INFO, "RTDE client %s: %" PRIu64 " input data package%s taken, %" PRIu64 " ignored", s->peer,
                 s->inputs_applied, s->inputs_applied == 1 ? "" : "s", s->inputs_ignored);
    }
}

bool sim_rtde_feed(sim_rtde_session *s, const uint8_t *data, size_t len)
{
    while (len > 0 && !s->broken) {
        /* The size field first, then the rest of the package it announces. */
        size_t want = s->in_len < 2 ? 2 : (size_t)s->in[0] << 8 | s->in[1];
        size_t take = want - s->in_len < len ? want - s->in_len : len;
        memcpy(s->in + s->in_len, data, take);
        s->in_len += take;
        data += take;
        len -= take;
        if (s->in_len < 2) {
            break;
        }
        want = (size_t)s->in[0] << 8 | s->in[1];
        if (want < RTDE_HEADER) {
            urrt_log(URRT_LOG_WARNING, "RTDE client %s sent a package of size %zu, below its 3-byte header: "
                     "disconnected", s->peer, want);
            s->broken = true;
            return false;
        }
        if (s->in_len == want) {
            s->in_len = 0;
            if (!on_package(s, s->in[2], s->in + RTDE_HEADER, want - RTDE_HEADER)) {
                return false;
            }
        }
    }
    return !s->broken;
}

/* ---- data ---------------------------------------------------------------------- */

/* A new control cycle k: the input packages received since the last one
 * take effect (each logged at -v), and holds that are over end. */
static void inputs_cycle(sim_rtde_inputs *in, uint64_t k)
{
    for (size_t i = 0; i < SIM_RTDE_INPUT_SLOTS; i++) {
        if (in->written[i]) {
            in->value[i] = in->next[i];
            in->written[i] = false;
        }
    }
    for (size_t i = 0; i < in->npending; i++) {
        const sim_rtde_pending *q = &in->pending[i];
        urrt_log(URRT_LOG_INFO, "RTDE client %s: input data of recipe %u (%u variable%s) applied at cycle %" PRIu64,
                 q->peer, (unsigned)q->recipe_id, (unsigned)q->count, q->count == 1 ? "" : "s", k);
    }
    if (in->pending_over != 0) {
        urrt_log(URRT_LOG_INFO, "RTDE: %" PRIu64 " more input data packages applied at cycle %" PRIu64,
                 in->pending_over, k);
    }
    in->npending = 0;
    in->pending_over = 0;
    in->cycle = k;
    in->cycle_known = true;
    release_held(in);
}

bool sim_rtde_due(sim_rtde_session *s, uint64_t k)
{
    sim_rtde_inputs *in = &s->ctl->inputs;
    if (!in->cycle_known || in->cycle != k) {
        inputs_cycle(in, k);
    }
    return s->started && k % s->divisor == 0;
}

static void copy_doubles(double *to, const double *from, size_t n)
{
    memcpy(to, from, n * sizeof *to);
}

/* Cycle k's values: the RealTime ones from the state, the RTDE-only ones
 * by the rules of docs/tools.md. */
static void cycle_values(uint64_t k, const urrt_state *st, const sim_rtde_inputs *in, values *v)
{
    memset(v, 0, sizeof *v);
    v->timestamp = st->time[0];
    copy_doubles(v->target_q, st->q_target, 6);
    copy_doubles(v->target_qd, st->qd_target, 6);
    copy_doubles(v->target_qdd, st->qdd_target, 6);
    copy_doubles(v->target_current, st->i_target, 6);
    copy_doubles(v->target_moment, st->m_target, 6);
    copy_doubles(v->actual_q, st->q_actual, 6);
    copy_doubles(v->actual_qd, st->qd_actual, 6);
    copy_doubles(v->actual_current, st->i_actual, 6);
    copy_doubles(v->joint_control_output, st->i_control, 6);
    copy_doubles(v->actual_tcp_pose, st->tool_vector_actual, 6);
    copy_doubles(v->actual_tcp_speed, st->tcp_speed_actual, 6);
    copy_doubles(v->actual_tcp_force, st->tcp_force, 6);
    copy_doubles(v->ft_raw_wrench, st->tcp_force, 6);
    copy_doubles(v->target_tcp_pose, st->tool_vector_target, 6);
    copy_doubles(v->target_tcp_speed, st->tcp_speed_target, 6);
    copy_doubles(v->joint_temperatures, st->motor_temperatures, 6);
    copy_doubles(v->joint_mode, st->joint_modes, 6);
    copy_doubles(v->joint_voltage, st->v_actual, 6);
    copy_doubles(v->accelerometer, st->tool_accelerometer, 3);
    copy_doubles(v->elbow_position, st->elbow_position, 3);
    copy_doubles(v->elbow_velocity, st->elbow_velocity, 3);
    copy_doubles(v->payload_cog, st->payload_cog, 3);
    copy_doubles(v->payload_inertia, st->payload_inertia, 6);
    v->din = st->digital_input_bits[0];
    v->dout = st->digital_outputs[0];
    /* Bits 8-15 are the configurable ones, counted from 0 there. */
    v->din_conf = (double)(((uint64_t)v->din >> 8) & 0xffu);
    v->dout_conf = (double)(((uint64_t)v->dout >> 8) & 0xffu);
    v->execution_time = st->controller_timer[0];
    v->robot_mode = st->robot_mode[0];
    v->safety_mode = st->safety_mode[0];
    v->safety_status = st->safety_status[0];
    v->speed_scaling = st->speed_scaling[0];
    v->speed_fraction = 1.0;
    v->momentum = st->linear_momentum_norm[0];
    v->main_voltage = st->v_main[0];
    v->robot_voltage = st->v_robot[0];
    v->robot_current = st->i_robot[0];
    v->runtime_state = st->program_state[0];
    v->payload = st->payload_mass[0];
    /* Power on from POWER_ON (4) up; program running while PLAYING (2). */
    v->robot_status_bits = (v->robot_mode >= 4.0 ? 1.0 : 0.0) + (v->runtime_state == 2.0 ? 2.0 : 0.0);
    /* Bit (safety mode - 1): NORMAL is bit 0, REDUCED bit 1, ... */
    v->safety_status_bits = v->safety_mode >= 1.0 && v->safety_mode <= 11.0 ? ldexp(1.0, (int)v->safety_mode - 1) : 0.0;
    v->time_scale_source = v->runtime_state == 2.0 && v->speed_scaling == 1.0 ? 1.0 : 0.0;
    v->control_step = (double)k;
    v->tool_output_voltage = 24.0;
    /* The general-purpose output registers, as a robot program writing
     * them every cycle would: ints count cycles, doubles count seconds of
     * the stream, bits count in binary. */
    v->out_bits[0] = (double)(uint32_t)k;
    v->out_bits[1] = (double)(uint32_t)~(uint32_t)k;
    for (unsigned n = 0; n < 48; n++) {
        v->out_int[n] = (double)(int32_t)(uint32_t)(k + n);
        v->out_double[n] = (double)n + (double)k / 1000.0;
    }
    for (unsigned n = 64; n < 128; n++) {
        v->out_bit[n - 64] = (double)((k >> (n % 32)) & 1u);
    }
    /* The input registers, read back: what the controller holds. */
    copy_doubles(v->in_int, in->value + IN_AT(in_int), 48);
    copy_doubles(v->in_double, in->value + IN_AT(in_double), 48);
    copy_doubles(v->in_bit, in->value + IN_AT(in_bit), 64);
    copy_doubles(v->in_bits, in->value + IN_AT(in_bits), 2);
}

/* A field's wire bytes. */
static size_t put_field(uint8_t *p, const sim_rtde_field *f, const double *vals)
{
    const double *x = vals + f->value;
    size_t n = 0;
    for (unsigned e = 0; e < wire[f->type].count; e++) {
        uint64_t bits;
        switch (f->type) {
        case W_BOOL: p[n++] = x[e] != 0.0 ? 1 : 0; break;
        case W_UINT8: p[n++] = (uint8_t)x[e]; break;
        case W_UINT32:
        case W_VECTOR6UINT32: put_u32(p + n, (uint32_t)x[e]); n += 4; break;
        case W_INT32:
        case W_VECTOR6INT32: put_u32(p + n, (uint32_t)(int32_t)x[e]); n += 4; break;
        case W_UINT64: put_u64(p + n, (uint64_t)x[e]); n += 8; break;
        default:
            memcpy(&bits, &x[e], 8);
            put_u64(p + n, bits);
            n += 8;
            break;
        }
    }
    return n;
}

/* A data package's recipe id, in protocol 2: its bytes (0 or 1). */
static size_t put_recipe_id(const sim_rtde_session *s, uint8_t *p)
{
    if (s->protocol < 2) {
        return 0;
    }
    p[0] = RTDE_OUTPUT_RECIPE_ID;
    return 1;
}

/* Sends the session's next data package, its payload (recipe id and
 * values) in p, len bytes: after a text message, or bad, when a fault says
 * so. */
static bool send_payload(sim_rtde_session *s, uint8_t *p, size_t len)
{
    const sim_rtde_faults *f = s->faults;
    uint64_t n = ++s->data_sent;
    uint8_t type = RTDE_DATA;

    if (f->text_every != 0 && n > 1 && (n - 1) % f->text_every == 0) {
        char msg[96];
        snprintf(msg, sizeof msg, "urrt-sim: text message %" PRIu64 " (fault rtde-text-every)", s->texts_sent + 1);
        if (!send_text(s, f->text_level, msg)) {
            return false;
        }
    }
    if (f->bad_every != 0 && n % f->bad_every == 0) {
        switch (f->bad_kind) {
        case SIM_RTDE_BAD_HEADER: {
            /* Size 2: below the header itself, so no reader can frame what follows. */
            static const uint8_t broken[3] = {0x00, 0x02, RTDE_DATA};
            return s->emit(s->emit_ctx, broken, sizeof broken);
        }
        case SIM_RTDE_BAD_TYPE: type = 'X'; break;
        case SIM_RTDE_BAD_RECIPE:
            if (s->protocol >= 2) {
                p[0] = RTDE_OUTPUT_RECIPE_ID + 1;
                break;
            }
            /* v1 packages carry no recipe id: one byte short instead. */
            len--;
            break;
        case SIM_RTDE_BAD_SIZE: len--; break;
        }
    }
    return send_package(s, type, p, len);
}

bool sim_rtde_send_data(sim_rtde_session *s, uint64_t k, const urrt_state *st)
{
    static values v;
    static uint8_t payload[RTDE_SIZE_MAX];
    size_t off = put_recipe_id(s, payload);

    _Static_assert(sizeof(values) == VALUES_COUNT * sizeof(double), "values is an array of doubles");
    cycle_values(k, st, &s->ctl->inputs, &v);
    for (size_t i = 0; i < s->nfields; i++) {
        off += put_field(payload + off, &s->fields[i], (const double *)&v);
    }
    return send_payload(s, payload, off);
}

bool sim_rtde_send_recorded(sim_rtde_session *s, uint64_t k)
{
    static uint8_t payload[RTDE_SIZE_MAX];
    const sim_rtde_recording *r = s->ctl->recording;
    const uint8_t *vals = r->file + r->at[k % r->count];
    size_t off = put_recipe_id(s, payload);

    /* The texts recorded since this client's previous package (the
     * divisor's worth of packages before this one), in its protocol. */
    for (uint64_t j = k + 1 >= s->divisor ? k + 1 - s->divisor : 0; j <= k; j++) {
        size_t i = (size_t)(j % r->count);
        for (size_t t = r->text_first[i]; t < r->text_first[i + 1]; t++) {
            const sim_rtde_recorded_text *x = &r->texts[t];
            if (!send_text_from(s, x->level, x->message, x->mlen, x->source, x->slen)) {
                return false;
            }
        }
    }
    /* Each variable's bytes as the controller sent them. */
    for (size_t i = 0; i < s->nfields; i++) {
        const sim_rtde_recorded_field *f = &r->fields[s->fields[i].value];
        size_t size = (size_t)wire[f->type].count * wire[f->type].size;
        memcpy(payload + off, vals + f->offset, size);
        off += size;
    }
    return send_payload(s, payload, off);
}

/* ---- a capture as the controller ------------------------------------------------ */

/* What is known of the capture's session being read. */
typedef struct reading {
    const char *path;
    sim_rtde_recording *r;
    sim_rtde_controller *ctl;
    bool have_version;
    bool recipe_fixed;        /* the recipe of the first session with an accepted one */
    unsigned protocol;        /* this session's, 1 until V is accepted */
    unsigned asked;           /* the version its last V asked for */
    bool decided;             /* a session has had its recipe accepted: later ones do not answer V for the replay */
    bool session_ok;          /* this session's recipe is the replay's */
    bool started;             /* its start was accepted */
    uint8_t recipe_id;
    uint8_t *setup;           /* this session's last setup request */
    size_t setup_size;
    size_t texts_cap, at_cap;
    uint64_t skipped, first_skipped;
    bool other_recipe;        /* a later session asked for another recipe: the replay ends before it */
} reading;

/* The names of a setup request, past the frequency of protocol 2. */
static const uint8_t *setup_names(const reading *rd, size_t *len)
{
    size_t skip = RTDE_HEADER + (rd->protocol >= 2 ? 8u : 0u);
    *len = rd->setup_size > skip ? rd->setup_size - skip : 0;
    return rd->setup + skip;
}

static int wire_of_token(const char *t, size_t len)
{
    for (size_t w = 0; w < COUNT(wire); w++) {
        if (strlen(wire[w].token) == len && memcmp(wire[w].token, t, len) == 0) {
            return (int)w;
        }
    }
    return -1;
}

/* The tokens of a setup reply against the request's names: the recipe they
 * make (into fields, up to max), or false when a name was refused. */
static bool recorded_recipe(const reading *rd, const uint8_t *types, size_t tlen, sim_rtde_recorded_field *fields,
                            size_t max, size_t *count)
{
    size_t nlen, n = 0, ni = 0, ti = 0, offset = 0;
    const uint8_t *names = setup_names(rd, &nlen);
    if (nlen == 0 || tlen == 0) {
        return false;
    }
    while (ni <= nlen && ti <= tlen) {
        size_t ne = ni, te = ti;
        int w;
        while (ne < nlen && names[ne] != ',') {
            ne++;
        }
        while (te < tlen && types[te] != ',') {
            te++;
        }
        w = wire_of_token((const char *)types + ti, te - ti);
        if (w < 0 || n == max) {
            return false; /* NOT_FOUND, IN_USE or a token the simulator does not know */
        }
        fields[n++] = (sim_rtde_recorded_field){(const char *)names + ni, ne - ni, (uint8_t)w, offset};
        offset += (size_t)wire[w].count * wire[w].size;
        ni = ne + 1;
        ti = te + 1;
        if ((ni > nlen) != (ti > tlen)) {
            return false; /* as many types as names, or the reply is not this request's */
        }
    }
    *count = n;
    return true;
}

/* A setup reply: the session's recipe, the replay's if it is the first. */
static bool on_recorded_setup(reading *rd, const rtde_capture_record *rec, char *why, size_t why_size)
{
    static sim_rtde_recorded_field fields[SIM_RTDE_RECIPE_MAX];
    sim_rtde_recording *r = rd->r;
    size_t idlen = rd->protocol >= 2 ? 1 : 0, count = 0, nlen;
    const uint8_t *names = setup_names(rd, &nlen);

    rd->session_ok = false;
    if (rd->setup == NULL || rec->size < RTDE_HEADER + idlen ||
        !recorded_recipe(rd, rec->pkg + RTDE_HEADER + idlen, rec->size - RTDE_HEADER - idlen, fields,
                         COUNT(fields), &count)) {
        return true; /* refused: this session sends no data */
    }
    rd->recipe_id = idlen ? rec->pkg[RTDE_HEADER] : 0;
    if (rd->recipe_fixed) {
        bool same = count == r->nfields && strlen(r->names) == nlen && memcmp(r->names, names, nlen) == 0;
        for (size_t i = 0; same && i < count; i++) {
            same = fields[i].type == r->fields[i].type;
        }
        if (!same) {
            rd->other_recipe = true;
            urrt_log(URRT_LOG_NOTICE, "capture %s: the session at byte %" PRIu64 " asks for another recipe: the "
                     "replay ends before it (it serves the first session's recipe)", rd->path, rec->offset);
        }
        rd->session_ok = same;
        if (same) {
            r->sessions++;
        }
        return true;
    }
    r->names = malloc(nlen + 1);
    r->fields = malloc(count * sizeof *r->fields);
    if (r->names == NULL || r->fields == NULL) {
        snprintf(why, why_size, "out of memory reading %s", rd->path);
        return false;
    }
    memcpy(r->names, names, nlen);
    r->names[nlen] = '\0';
    r->nfields = count;
    r->timestamp_at = SIZE_MAX;
    for (size_t i = 0; i < count; i++) {
        r->fields[i] = fields[i];
        r->fields[i].name = r->names + (fields[i].name - (const char *)names);
        if (fields[i].len == 9 && memcmp(fields[i].name, "timestamp", 9) == 0 && fields[i].type == W_DOUBLE &&
            r->timestamp_at == SIZE_MAX) {
            r->timestamp_at = fields[i].offset;
        }
        r->values_size = fields[i].offset + (size_t)wire[fields[i].type].count * wire[fields[i].type].size;
    }
    if (r->timestamp_at == SIZE_MAX) {
        snprintf(why, why_size, "%s: its recipe (byte %" PRIu64 ") has no timestamp, the clock a replay is paced by; "
                 "record the capture with urrt-dump --rtde -w FILE, whose recipe always has it", rd->path,
                 rec->offset);
        return false;
    }
    rd->recipe_fixed = rd->session_ok = rd->decided = true;
    r->sessions = 1;
    return true;
}

/* A data package of the session: its values' place in the file, when it
 * matches the recipe (a client would drop one that does not). */
static bool on_recorded_data(reading *rd, const rtde_capture_record *rec, char *why, size_t why_size)
{
    sim_rtde_recording *r = rd->r;
    size_t idlen = rd->protocol >= 2 ? 1 : 0;
    if (!rd->session_ok || rec->size != RTDE_HEADER + idlen + r->values_size ||
        (idlen && rec->pkg[RTDE_HEADER] != rd->recipe_id)) {
        if (rd->skipped++ == 0) {
            rd->first_skipped = rec->offset;
        }
        return true;
    }
    if (r->count == rd->at_cap) {
        size_t cap = rd->at_cap ? rd->at_cap * 2 : 4096;
        uint64_t *at = realloc(r->at, cap * sizeof *at);
        size_t *first = realloc(r->text_first, (cap + 1) * sizeof *first);
        if (at != NULL) {
            r->at = at;
        }
        if (first != NULL) {
            r->text_first = first;
        }
        if (at == NULL || first == NULL) {
            snprintf(why, why_size, "out of memory reading %s", rd->path);
            return false;
        }
        if (r->count == 0) {
            r->text_first[0] = 0;
        }
        rd->at_cap = cap;
    }
    r->at[r->count] = rec->offset + 1 + RTDE_HEADER + idlen;
    r->text_first[++r->count] = r->ntexts;
    return true;
}

/* A text message while data flowed: sent again before the next package. */
static bool on_recorded_text(reading *rd, const rtde_capture_record *rec, char *why, size_t why_size)
{
    sim_rtde_recording *r = rd->r;
    const uint8_t *p = rec->pkg + RTDE_HEADER;
    size_t len = rec->size - RTDE_HEADER;
    sim_rtde_recorded_text t;
    if (!rd->session_ok || !rd->started || len < 1) {
        return true; /* a text of a handshake is not replayed */
    }
    memset(&t, 0, sizeof t);
    if (rd->protocol >= 2) {
        size_t m = p[0], n;
        if (len < 3 + m || len != 3 + m + p[1 + m]) {
            return true;
        }
        n = p[1 + m];
        t.mlen = (uint8_t)m;
        t.slen = (uint8_t)n;
        memcpy(t.message, p + 1, m);
        memcpy(t.source, p + 2 + m, n);
        t.level = p[2 + m + n];
    } else {
        t.level = p[0];
        t.mlen = (uint8_t)(len - 1 > 255 ? 255 : len - 1);
        memcpy(t.message, p + 1, t.mlen);
    }
    if (r->ntexts == rd->texts_cap) {
        size_t cap = rd->texts_cap ? rd->texts_cap * 2 : 16;
        sim_rtde_recorded_text *x = realloc(r->texts, cap * sizeof *x);
        if (x == NULL) {
            snprintf(why, why_size, "out of memory reading %s", rd->path);
            return false;
        }
        r->texts = x;
        rd->texts_cap = cap;
    }
    r->texts[r->ntexts++] = t;
    return true;
}

/* A package the controller sent. */
static bool on_recorded_reply(reading *rd, const rtde_capture_record *rec, char *why, size_t why_size)
{
    const uint8_t *p = rec->pkg + RTDE_HEADER;
    switch (rec->type) {
    case RTDE_V_PROTOCOL:
        if (rec->size == RTDE_HEADER + 1) {
            if (!rd->decided && rd->asked < 3 && rd->r->protocol_answer[rd->asked] < 0) {
                rd->r->protocol_answer[rd->asked] = p[0] != 0;
            }
            if (p[0] != 0) {
                rd->protocol = rd->asked;
            }
        }
        return true;
    case RTDE_V_URCONTROL:
        if (rec->size == RTDE_HEADER + 16 && !rd->have_version) {
            uint32_t v[4];
            for (int i = 0; i < 4; i++) {
                v[i] = (uint32_t)p[4 * i] << 24 | (uint32_t)p[4 * i + 1] << 16 | (uint32_t)p[4 * i + 2] << 8 |
                       p[4 * i + 3];
            }
            rd->ctl->major = v[0];
            rd->ctl->minor = v[1];
            rd->ctl->bugfix = v[2];
            rd->ctl->build = v[3];
            rd->have_version = true;
        }
        return true;
    case RTDE_SETUP_OUTPUTS: return on_recorded_setup(rd, rec, why, why_size);
    case RTDE_START:
        rd->started = rec->size == RTDE_HEADER + 1 && p[0] == 1;
        return true;
    case RTDE_DATA: return on_recorded_data(rd, rec, why, why_size);
    case RTDE_TEXT: return on_recorded_text(rd, rec, why, why_size);
    default: return true;
    }
}

/* A request the client sent: what the next reply answers. */
static bool on_recorded_request(reading *rd, const rtde_capture_record *rec)
{
    if (rec->type == RTDE_V_PROTOCOL && rec->size == RTDE_HEADER + 2) {
        rd->asked = (unsigned)rec->pkg[3] << 8 | rec->pkg[4];
    } else if (rec->type == RTDE_SETUP_OUTPUTS) {
        memcpy(rd->setup, rec->pkg, rec->size);
        rd->setup_size = rec->size;
    } else if (rec->type == RTDE_PAUSE) {
        rd->started = false;
    }
    return true;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The packages' rate: one over the median step of their timestamps (steps
 * that run back, stand still or jump 10 s or more, reconnects, left out). */
static double recorded_rate(const sim_rtde_recording *r)
{
    double *steps = malloc((r->count ? r->count : 1) * sizeof *steps), rate = 0.0;
    size_t n = 0;
    if (steps == NULL) {
        return 0.0;
    }
    for (size_t i = 1; i < r->count; i++) {
        double d = sim_rtde_recording_time(r, i) - sim_rtde_recording_time(r, i - 1);
        if (isfinite(d) && d > 0.0 && d < 10.0) {
            steps[n++] = d;
        }
    }
    if (n > 0) {
        qsort(steps, n, sizeof *steps, compare_doubles);
        rate = 1.0 / steps[n / 2];
    }
    free(steps);
    return rate;
}

/* Reads the records; false with the reason in why. */
static bool read_recording(reading *rd, FILE *f, char *why, size_t why_size)
{
    rtde_capture *cap = rtde_capture_open(f, rd->path, why, why_size);
    rtde_capture_record rec;
    int got = 0;
    if (cap == NULL) {
        return false;
    }
    while (!rd->other_recipe && (got = rtde_capture_next(cap, &rec, why, why_size)) > 0) {
        bool ok = true;
        if (rec.kind == RTDE_CAPTURE_CONNECT) {
            rd->protocol = 1;
            rd->session_ok = rd->started = false;
            rd->setup_size = 0;
        } else if (rec.kind == RTDE_CAPTURE_SENT) {
            ok = on_recorded_request(rd, &rec);
        } else {
            ok = on_recorded_reply(rd, &rec, why, why_size);
        }
        if (!ok) {
            rtde_capture_free(cap);
            return false;
        }
    }
    if (got == 0 && rtde_capture_truncated(cap) > 0) {
        urrt_log(URRT_LOG_NOTICE, "capture %s: its last record is cut short (%zu bytes, a recorder stopped "
                 "mid-write): left out", rd->path, rtde_capture_truncated(cap));
    }
    rtde_capture_free(cap);
    return got >= 0 || rd->other_recipe;
}

int sim_rtde_sniff(const char *path)
{
    FILE *f = fopen(path, "rb");
    int c = f != NULL ? fgetc(f) : EOF;
    if (f != NULL) {
        fclose(f);
    }
    return f == NULL ? -1 : c == RTDE_CAPTURE_FIRST_BYTE;
}

bool sim_rtde_recording_load(const char *path, sim_rtde_recording *r, sim_rtde_controller *ctl, char *why,
                             size_t why_size)
{
    reading rd = {.path = path, .r = r, .ctl = ctl, .protocol = 1};
    struct stat st;
    FILE *f = NULL;
    void *map;
    bool ok;
    bool fieldbus = ctl->fieldbus; /* the controller's configuration, not the capture's */
    int fd = open(path, O_RDONLY | O_CLOEXEC);

    memset(r, 0, sizeof *r);
    memset(ctl, 0, sizeof *ctl);
    ctl->fieldbus = fieldbus;
    memset(r->protocol_answer, 0xff, sizeof r->protocol_answer);
    if (fd < 0 || fstat(fd, &st) != 0 || st.st_size == 0) {
        snprintf(why, why_size, "cannot read the capture %s: %s", path, fd < 0 ? strerror(errno) : "empty");
        if (fd >= 0) {
            close(fd);
        }
        return false;
    }
    map = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, fd, 0);
    close(fd);
    if (map == MAP_FAILED) {
        snprintf(why, why_size, "cannot map the capture %s: %s", path, strerror(errno));
        return false;
    }
    r->file = map;
    r->file_size = (size_t)st.st_size;
    rd.setup = malloc(RTDE_SIZE_MAX);
    f = fmemopen(map, r->file_size, "rb");
    ok = rd.setup != NULL && f != NULL;
    if (!ok) {
        snprintf(why, why_size, "cannot read the capture %s: out of memory", path);
    }
    ok = ok && read_recording(&rd, f, why, why_size);
    if (f != NULL) {
        fclose(f);
    }
    free(rd.setup);
    if (ok && !rd.have_version) {
        snprintf(why, why_size, "%s has no reply to the controller version request ('v'): not a capture of a "
                 "whole session; record one with urrt-dump --rtde -w FILE", path);
        ok = false;
    } else if (ok && !rd.recipe_fixed) {
        snprintf(why, why_size, "%s has no output recipe its controller accepted: nothing to replay", path);
        ok = false;
    } else if (ok && r->count == 0) {
        snprintf(why, why_size, "%s holds no data package of its recipe: nothing to replay", path);
        ok = false;
    }
    if (!ok) {
        sim_rtde_recording_free(r);
        return false;
    }
    if (rd.skipped > 0) {
        urrt_log(URRT_LOG_NOTICE, "capture %s: %" PRIu64 " data package%s that do%s not match the recipe (the first "
                 "at byte %" PRIu64 "): left out, as its client dropped them", path, rd.skipped,
                 rd.skipped == 1 ? "" : "s", rd.skipped == 1 ? "es" : "", rd.first_skipped);
    }
    ctl->rate_hz = ctl->major >= 5 ? 500u : 125u;
    r->rate_hz = recorded_rate(r);
    ctl->cycle_hz = r->rate_hz > 0.0 ? r->rate_hz : (double)ctl->rate_hz;
    ctl->recording = r;
    return true;
}

double sim_rtde_recording_time(const sim_rtde_recording *r, size_t i)
{
    return get_double(r->file + r->at[i] + r->timestamp_at);
}

void sim_rtde_recording_free(sim_rtde_recording *r)
{
    if (r->file != NULL) {
        munmap((void *)(uintptr_t)r->file, r->file_size);
    }
    free(r->names);
    free(r->fields);
    free(r->at);
    free(r->texts);
    free(r->text_first);
    memset(r, 0, sizeof *r);
}
