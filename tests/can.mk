# SPDX-License-Identifier: MIT
# tests/can.mk: the CAN mapping, packing and DBC.
#   check-can      lib/urrt_can and gateway/can/can_map, can_run unit tests (hand vectors,
#                  saturation, configurations loaded by the gateway's loader and their
#                  rejections with FILE:LINE, bus load, scheduling on a fake clock)
#   check-can-san  the same under ASan + UBSan (float-cast-overflow included: no float to
#                  integer conversion may be undefined), lib/ and gateway/ compiled with them
#   check-can-dbc  DBCs and payloads against python3-canmatrix and an independent
#                  Python reference; the example configurations in docs/examples/
#   bench-can      ns per packet for the CAN mapping beside urrt_decode of the same packet

CANT := $(BUILD)/tests/can
CAN_TEST_SRCS := gateway/can/can_map.c gateway/can/can_run.c gateway/can/dbc.c gateway/common/conf.c \
                 gateway/urrt-gateway/config.c
# The tests load configurations as the gateway does: its loader (config.o, which
# needs no LCM), conf.o (gateway/common/common.mk) and the port's link defaults.
CAN_TEST_OBJS := $(CAN_GATEWAY_OBJS) $(BUILD)/gateway/urrt-gateway/config.o $(CONF_OBJ)
CAN_TEST_CFLAGS := $(PROG_WARN) $(CPPFLAGS) $(GATEWAY_INC) -Itests

CHECKS += check-can check-can-san check-can-dbc
.PHONY: check-can check-can-san check-can-dbc

# $(call can_suite,NAME,COMMAND): runs COMMAND, shows its output and keeps its
# last line ("N passed, N failed") as the suite's result.
define can_suite
	@mkdir -p $(BUILD)/results
	@$(2) > $(BUILD)/results/$(1).log 2>&1; rc=$$?; cat $(BUILD)/results/$(1).log; \
	  tail -n 1 $(BUILD)/results/$(1).log > $(BUILD)/results/$(1).result; \
	  grep -q '^[0-9]* passed, 0 failed$$' $(BUILD)/results/$(1).result || rc=1; exit $$rc
endef

$(CANT)/test_can: tests/can/test_can.c tests/check.h $(CAN_TEST_OBJS) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(CAN_TEST_CFLAGS) $(OPT) $< $(CAN_TEST_OBJS) $(LIBPORT) $(LIBURRT) -lm -o $@

$(CANT)/test_can_san: tests/can/test_can.c tests/check.h $(CAN_TEST_SRCS) $(GATEWAY_HDRS) $(LIB_SRCS) $(LIBPORT)
	@mkdir -p $(@D)
	$(CC) $(CAN_TEST_CFLAGS) -O1 -g $(SAN_FLAGS) -fsanitize=float-cast-overflow $< $(CAN_TEST_SRCS) $(LIB_SRCS) \
	  $(LIBPORT) -lm -o $@

$(CANT)/can_tool: tests/can/can_tool.c $(CAN_TEST_OBJS) $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(CAN_TEST_CFLAGS) $(OPT) $< $(CAN_TEST_OBJS) $(LIBPORT) $(LIBURRT) -lm -o $@

check-can: $(CANT)/test_can
	$(call can_suite,check-can,$(CANT)/test_can)

check-can-san: $(CANT)/test_can_san
	$(call can_suite,check-can-san,ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 $(CANT)/test_can_san)

check-can-dbc: $(CANT)/can_tool
	$(call can_suite,check-can-dbc,$(PYTHON) tests/can/test_dbc.py --tool $(CANT)/can_tool --work $(CANT)/work)

# ---- benchmark ---------------------------------------------------------------------
BENCHES += bench-can
.PHONY: bench-can

$(CANT)/bench_can: tests/can/bench_can.c $(CAN_TEST_OBJS) $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(CAN_TEST_CFLAGS) $(OPT) $< $(CAN_TEST_OBJS) $(LIBPORT) $(LIBURRT) -lm -o $@

bench-can: $(CANT)/bench_can
	@$(CANT)/bench_can docs/examples/canopen.ini

# ---- the CAN core alone (lib/urrt_cantx), here and on the emulated cores -------------
#   check-cantx      tests/can/test_cantx.c on the host (check-lib-m4 runs it on Cortex-M)
#   check-cantx-san  the same under ASan + UBSan
CHECKS += check-cantx check-cantx-san
.PHONY: check-cantx check-cantx-san

$(CANT)/test_cantx: tests/can/test_cantx.c $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(CAN_TEST_CFLAGS) $(OPT) $< $(LIBURRT) -lm -o $@

$(CANT)/test_cantx_san: tests/can/test_cantx.c $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(CAN_TEST_CFLAGS) -O1 -g $(SAN_FLAGS) -fsanitize=float-cast-overflow $< $(LIB_SRCS) -lm -o $@

check-cantx: $(CANT)/test_cantx
	$(call can_suite,check-cantx,$(CANT)/test_cantx)

check-cantx-san: $(CANT)/test_cantx_san
	$(call can_suite,check-cantx-san,$(CANT)/test_cantx_san)
