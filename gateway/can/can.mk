# SPDX-License-Identifier: MIT
# gateway/can/can.mk: urrt-gateway's CAN side. The mapping configuration
# (can_map), its run-time tables over lib/urrt_cantx (can_run), the DBC writer
# (dbc) and the C tables writer (can_ctables), which tests link too; and the
# parts that use the port's CAN link (can_out, the gateway output; can_replay,
# --replay), which only the gateway links. tests/can.mk tests them.

CAN_GATEWAY_OBJS := $(addprefix $(BUILD)/gateway/can/,can_map.o can_run.o dbc.o can_ctables.o)
CAN_PORT_OBJS := $(addprefix $(BUILD)/gateway/can/,can_out.o can_replay.o)
GATEWAY_EXTRA_OBJS += $(CAN_GATEWAY_OBJS) $(CAN_PORT_OBJS)

$(BUILD)/gateway/can/%.o: gateway/can/%.c
	@mkdir -p $(@D)
	$(CC) $(GW_CFLAGS) -c $< -o $@

-include $(CAN_GATEWAY_OBJS:.o=.d) $(CAN_PORT_OBJS:.o=.d)
