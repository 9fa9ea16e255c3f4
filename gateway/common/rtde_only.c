/* SPDX-License-Identifier: MIT */
/* rtde_only.c: see rtde_only.h. */
#include "rtde_only.h"

#include <math.h>
#include <string.h>

/* Units of the RTDE-only rows (UR's RTDE guide), by family: first .. last. */
#define ROW(ID, unit) {URRT_RTDE_V_##ID, URRT_RTDE_V_##ID##_LAST_, unit}
static const struct {
    int first, last;
    const char *unit;
} units[] = {
    ROW(TARGET_SPEED_FRACTION, ""),
    ROW(ROBOT_STATUS_BITS, "bits"),
    ROW(SAFETY_STATUS_BITS, "bits"),
    ROW(TCP_OFFSET, "m, rad"),
    ROW(OUTPUT_BIT_REGISTERS0_TO_31, "bits"),
    ROW(OUTPUT_BIT_REGISTERS32_TO_63, "bits"),
    ROW(OUTPUT_BIT_REGISTER, ""),
    ROW(OUTPUT_INT_REGISTER, ""),
    ROW(OUTPUT_DOUBLE_REGISTER, ""),
    ROW(INPUT_BIT_REGISTERS0_TO_31, "bits"),
    ROW(INPUT_BIT_REGISTERS32_TO_63, "bits"),
    ROW(INPUT_BIT_REGISTER, ""),
    ROW(INPUT_INT_REGISTER, ""),
    ROW(INPUT_DOUBLE_REGISTER, ""),
    ROW(ACTUAL_CURRENT_WINDOW, "A"),
    ROW(ACTUAL_CURRENT_AS_TORQUE, "Nm"),
    ROW(ACTUAL_TCP_ACCELERATION, "m/s^2, rad/s^2"),
    ROW(TARGET_TCP_ACCELERATION, "m/s^2, rad/s^2"),
    ROW(ACTUAL_CONFIGURABLE_DIGITAL_INPUT_BITS, "bits"),
    ROW(ACTUAL_CONFIGURABLE_DIGITAL_OUTPUT_BITS, "bits"),
    ROW(TARGET_EXECUTION_TIME, "s"),
    ROW(ANALOG_IO_TYPES, "bits"),
    ROW(STANDARD_ANALOG_INPUT, ""),  /* mA or V, as analog_io_types says */
    ROW(STANDARD_ANALOG_OUTPUT, ""),
    ROW(IO_CURRENT, "mA"),
    ROW(ACTUAL_ROBOT_ENERGY_CONSUMED, "J"),
    ROW(ACTUAL_ROBOT_BRAKING_ENERGY_DISSIPATED, "J"),
    ROW(ENCODER0_RAW, ""),
    ROW(ENCODER1_RAW, ""),
    ROW(EUROMAP67_INPUT_BITS, "bits"),
    ROW(EUROMAP67_OUTPUT_BITS, "bits"),
    ROW(EUROMAP67_24V_VOLTAGE, "V"),
    ROW(EUROMAP67_24V_CURRENT, "mA"),
    ROW(TOOL_MODE, ""),
    ROW(TOOL_ANALOG_INPUT_TYPES, "bits"),
    ROW(TOOL_ANALOG_INPUT, ""),      /* mA or V, as tool_analog_input_types says */
    ROW(TOOL_OUTPUT_VOLTAGE, "V"),
    ROW(TOOL_OUTPUT_CURRENT, "mA"),
    ROW(TOOL_TEMPERATURE, "degC"),
    ROW(TOOL_OUTPUT_MODE, ""),
    ROW(TOOL_DIGITAL_OUTPUT0_MODE, ""),
    ROW(TOOL_DIGITAL_OUTPUT1_MODE, ""),
    ROW(TCP_FORCE_SCALAR, "N"),
    ROW(JOINT_POSITION_DEVIATION_RATIO, ""),
    ROW(COLLISION_DETECTION_RATIO, ""),
    ROW(FT_RAW_WRENCH, "N, Nm"),
    ROW(WRENCH_CALC_FROM_CURRENTS, "N, Nm"),
    ROW(SCRIPT_CONTROL_LINE, ""),
    ROW(TIME_SCALE_SOURCE, ""),
    ROW(TARGET_GRAVITY, "m/s^2"),
    ROW(TARGET_BASE_ACCELERATION, "m/s^2, rad/s^2"),
    ROW(CONTROL_STEP, ""),
    ROW(TARGET_BASE_WRENCH, "N, Nm"),
};
#undef ROW

bool rtde_only(int var)
{
    return var >= URRT_RTDE_MAPPED_COUNT && var < URRT_RTDE_VAR_COUNT;
}

unsigned rtde_only_elements(int var)
{
    if (!rtde_only(var)) {
        return 0;
    }
    switch (urrt_rtde_var_type(var)) {
    case URRT_RTDE_T_VECTOR3D: return 3;
    case URRT_RTDE_T_VECTOR6D:
    case URRT_RTDE_T_VECTOR6INT32:
    case URRT_RTDE_T_VECTOR6UINT32: return 6;
    default: return 1;
    }
}

const char *rtde_only_unit(int var)
{
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++) {
        if (var >= units[i].first && var <= units[i].last) {
            return units[i].unit;
        }
    }
    return "";
}

bool rtde_only_is_mask(int var)
{
    return strcmp(rtde_only_unit(var), "bits") == 0;
}

double rtde_only_element(const urrt_rtde_values *v, int var, unsigned elem)
{
    const void *p = urrt_rtde_value(v, var);
    if (p == NULL || !urrt_rtde_has(v, var) || elem >= rtde_only_elements(var)) {
        return NAN;
    }
    switch (urrt_rtde_var_type(var)) {
    case URRT_RTDE_T_BOOL:
    case URRT_RTDE_T_UINT8: return ((const uint8_t *)p)[elem];
    case URRT_RTDE_T_UINT32:
    case URRT_RTDE_T_VECTOR6UINT32: return ((const uint32_t *)p)[elem];
    case URRT_RTDE_T_UINT64: return (double)((const uint64_t *)p)[elem];
    case URRT_RTDE_T_INT32:
    case URRT_RTDE_T_VECTOR6INT32: return ((const int32_t *)p)[elem];
    default: return ((const double *)p)[elem];
    }
}

uint64_t rtde_only_mask(const urrt_rtde_values *v, int var)
{
    const void *p = urrt_rtde_value(v, var);
    if (p == NULL || !urrt_rtde_has(v, var)) {
        return 0;
    }
    switch (urrt_rtde_var_type(var)) {
    case URRT_RTDE_T_UINT64: return *(const uint64_t *)p;
    case URRT_RTDE_T_UINT32: return *(const uint32_t *)p;
    default: return 0;
    }
}
