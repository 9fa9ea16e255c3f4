# SPDX-License-Identifier: MIT
# gateway/can/can.mk: what urrt-gateway's CAN side is without the gateway's
# loop. The mapping language (can_map), an [input]'s frames as its input
# recipe's values (can_in), its run-time tables over
# lib/urrt_cantx (can_run), the DBC writer (dbc) and the C tables writer
# (can_ctables), the CANopen node's configuration (canopen_map), its description
# (co_run) and EDS writer (eds), which tests link too; and --replay (can_replay), which uses
# the port's CAN link and only the gateway links. The CAN output, beside the
# loop that drives it, is gateway/urrt-gateway/can_out.c. tests/gateway/can/can.mk tests them.

CAN_GATEWAY_OBJS := $(addprefix $(BUILD)/gateway/can/,can_map.o can_in.o can_run.o canopen_map.o co_run.o eds.o \
  dbc.o can_ctables.o) $(RTDE_ONLY_OBJ)
CAN_PORT_OBJS := $(addprefix $(BUILD)/gateway/can/,can_replay.o)
GATEWAY_EXTRA_OBJS += $(CAN_GATEWAY_OBJS) $(CAN_PORT_OBJS)

$(BUILD)/gateway/can/%.o: gateway/can/%.c
	@mkdir -p $(@D)
	$(CC) $(GW_CFLAGS) -c $< -o $@

-include $(CAN_GATEWAY_OBJS:.o=.d) $(CAN_PORT_OBJS:.o=.d)
