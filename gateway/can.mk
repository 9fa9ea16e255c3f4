# SPDX-License-Identifier: MIT
# gateway/can.mk: the CAN side of urrt-gateway: the mapping configuration and
# frame scheduling (can_map) and the DBC writer (dbc). The gateway links them
# through GATEWAY_EXTRA_OBJS, with can_out joining them to the CAN link as one
# gateway output; tests/can.mk tests them.

CAN_GATEWAY_OBJS := $(BUILD)/gateway/can_map.o $(BUILD)/gateway/can_run.o $(BUILD)/gateway/dbc.o
CAN_GATEWAY_HDRS := gateway/can_map.h gateway/dbc.h gateway/can_out.h gateway/gateway.h gateway/config.h port/port.h $(LIB_HDRS)
GATEWAY_EXTRA_OBJS += $(CAN_GATEWAY_OBJS) $(BUILD)/gateway/can_out.o

$(CAN_GATEWAY_OBJS) $(BUILD)/gateway/can_out.o: $(BUILD)/gateway/%.o: gateway/%.c $(CAN_GATEWAY_HDRS)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(CPPFLAGS) -Igateway -c $< -o $@
