# SPDX-License-Identifier: MIT
# gateway/common/common.mk: what the three programs share: the value parsers of
# the configuration front end (conf), the command-line helpers (cli), and the
# RTDE session on a robot link (rtde_source: urrt-gateway and urrt-dump),
# RTDE captures (rtde_capture: written by urrt-dump, read by all three), and
# the RTDE-only values' units and reading (rtde_only: the gateway's outputs, urrt-dump).
#
# Every gateway/ folder compiles its .c files with GW_CFLAGS: -MMD -MP let the
# compiler tell make which headers an object depends on, so no .mk lists them.

GATEWAY_INC := -Igateway/common -Igateway/urrt-gateway -Igateway/can -Igateway/tools
GW_CFLAGS = $(PROG_WARN) $(OPT) $(CPPFLAGS) $(GATEWAY_INC) -MMD -MP
# For tests that compile gateway/ sources in one command (sanitizer builds).
GATEWAY_HDRS := $(wildcard gateway/*/*.h)

CONF_OBJ := $(BUILD)/gateway/common/conf.o
CLI_OBJ := $(BUILD)/gateway/common/cli.o $(CONF_OBJ)
RTDE_SOURCE_OBJ := $(BUILD)/gateway/common/rtde_source.o
RTDE_CAPTURE_OBJ := $(BUILD)/gateway/common/rtde_capture.o
RTDE_ONLY_OBJ := $(BUILD)/gateway/common/rtde_only.o

$(BUILD)/gateway/common/%.o: gateway/common/%.c
	@mkdir -p $(@D)
	$(CC) $(GW_CFLAGS) -c $< -o $@

-include $(CLI_OBJ:.o=.d) $(RTDE_SOURCE_OBJ:.o=.d) $(RTDE_CAPTURE_OBJ:.o=.d) $(RTDE_ONLY_OBJ:.o=.d)
