# SPDX-License-Identifier: MIT
# gateway/can.mk: the CAN side of urrt-gateway: the mapping configuration and
# frame scheduling (can_map) and the DBC writer (dbc). The gateway links them
# through GATEWAY_EXTRA_OBJS, with can_out joining them to the CAN link as one
# gateway output; tests/can.mk tests them.

CAN_GATEWAY_OBJS := $(BUILD)/gateway/can_map.o $(BUILD)/gateway/can_run.o $(BUILD)/gateway/dbc.o \
                    $(BUILD)/gateway/can_ctables.o
CAN_GATEWAY_HDRS := gateway/can_map.h gateway/dbc.h gateway/can_out.h gateway/can_ctables.h gateway/can_replay.h gateway/gateway.h gateway/config.h port/port.h $(LIB_HDRS)
# The parts that use the port (the CAN link) are the gateway's only.
CAN_PORT_OBJS := $(BUILD)/gateway/can_out.o $(BUILD)/gateway/can_replay.o
GATEWAY_EXTRA_OBJS += $(CAN_GATEWAY_OBJS) $(CAN_PORT_OBJS)

$(CAN_GATEWAY_OBJS) $(CAN_PORT_OBJS): $(BUILD)/gateway/%.o: gateway/%.c $(CAN_GATEWAY_HDRS)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(CPPFLAGS) -Igateway -c $< -o $@
