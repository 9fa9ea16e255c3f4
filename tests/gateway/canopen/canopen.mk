# SPDX-License-Identifier: MIT
# tests/gateway/canopen/canopen.mk: the gateway's CANopen node (gateway/can/canopen_map.c,
# co_run.c, eds.c), on top of lib/urrt_co.
#   check-co-gw   tests/gateway/canopen/test_canopen.c: every rejection of a [canopen]
#                 configuration with FILE:LINE and its reason; docs/examples/canopen.ini's
#                 node description; its EDS read back by SDO from the node itself; the DBC
#                 and --print-c-tables carrying the same TPDOs; docs/canopen.md's table of
#                 the example's object dictionary row for row against its EDS; the C
#                 tables compiled for Cortex-M4 against lib/ alone (a prerequisite); a node
#                 with [input]s (RPDOs): its EDS read back and against the node by SDO, SDO
#                 downloads and RPDO frames through it; both EDSs through
#                 tests/canopen/eds_check.py (CiA 306's rules, python3)
#   check-co-gw-san  the same under ASan + UBSan, lib/ and gateway/ compiled with them
#   bench-co-gw   ns per SDO request and per SYNC of the example's node, beside urrt_decode of
#                 one packet in the same run (tests/gateway/canopen/bench_canopen.c)

COGWT := $(BUILD)/tests/gateway/canopen
COGW_EXAMPLE := docs/examples/canopen.ini
COGW_M4_CC ?= arm-none-eabi-gcc
COGW_EDS_CHECK := tests/canopen/eds_check.py

CHECKS += check-co-gw check-co-gw-san
BENCHES += bench-co-gw
.PHONY: check-co-gw check-co-gw-san bench-co-gw

# test_canopen and bench_canopen: one source each, the gateway's loader and CAN objects.
$(COGWT)/%: tests/gateway/canopen/%.c tests/check.h tests/gateway/bench.h $(CAN_TEST_OBJS) $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(CAN_TEST_CFLAGS) $(OPT) $< $(CAN_TEST_OBJS) $(LIBPORT) $(LIBURRT) -lm -o $@

$(COGWT)/tables.c: $(COGW_EXAMPLE) $(BUILD)/bin/urrt-gateway
	@mkdir -p $(@D)
	$(BUILD)/bin/urrt-gateway --print-c-tables -o $@ $<

# The firmware's view: the generated tables with lib/'s headers, nothing of gateway/ or port/.
$(COGWT)/tables-m4.o: $(COGWT)/tables.c $(LIB_HDRS)
	$(COGW_M4_CC) -std=c99 -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -Os -Wall -Wextra -Werror -ffreestanding \
	  -Ilib -c $< -o $@

check-co-gw: $(COGWT)/test_canopen $(COGWT)/tables-m4.o
	$(call suite,$@,$< $(COGW_EXAMPLE) $(COGWT)/tables.c docs/canopen.md $(COGW_EDS_CHECK))

$(COGWT)/test_canopen_san: tests/gateway/canopen/test_canopen.c tests/check.h $(CAN_TEST_SRCS) $(GATEWAY_HDRS) \
  $(LIB_SRCS) $(LIBPORT)
	@mkdir -p $(@D)
	$(CC) $(CAN_TEST_CFLAGS) -O1 -g $(SAN_FLAGS) $< $(CAN_TEST_SRCS) $(LIB_SRCS) $(LIBPORT) -lm -o $@

check-co-gw-san: $(COGWT)/test_canopen_san $(COGWT)/tables.c
	$(call suite,$@,ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 $< $(COGW_EXAMPLE) \
	  $(COGWT)/tables.c docs/canopen.md $(COGW_EDS_CHECK))

bench-co-gw: $(COGWT)/bench_canopen
	@$< $(COGW_EXAMPLE)
