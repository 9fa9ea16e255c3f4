# SPDX-License-Identifier: MIT
# tests/gateway/can/can.mk: the gateway's CAN mapping (gateway/can/), on top of lib/urrt_can.
#   check-can-map      tests/gateway/can/test_can_map.c: configurations loaded by the gateway's
#                      loader and their rejections with FILE:LINE, bus load, the urrt_cantx
#                      tables, scheduling and the heartbeat on a fake clock, the DBC text;
#                      [input NAME] frames: their recipes, every refusal with FILE:LINE, their DBC
#   check-can-map-san  the same under ASan + UBSan, lib/ and gateway/ compiled with them
#   check-can-dbc      DBCs and payloads against python3-canmatrix and an independent
#                      Python reference; the example configurations in docs/examples/; then
#                      check_dbc_input.py: the [input] frames (the PLC's) in the DBC, their values
#                      both ways between canmatrix and lib/urrt_can with the map's table, and their
#                      C tables compiled under lib/'s warnings (host and Cortex-M4) and decoding
#                      canmatrix's payloads through ctables_input.c
#   check-replay-rtde  urrt-gateway --replay of RTDE captures of urrt-sim's sessions: the frames
#                      against canmatrix and against the RealTime capture's, CANopen with
#                      --replay-rx, the refusals (check_replay_rtde.py; processes: a timing suite)
#   bench-can          ns per packet for the CAN mapping beside urrt_decode of the same packet

CANT := $(BUILD)/tests/gateway/can
CAN_TEST_SRCS = $(CAN_GATEWAY_OBJS:$(BUILD)/%.o=%.c) gateway/common/conf.c gateway/urrt-gateway/config.c
# The tests load configurations as the gateway does: its loader (config.o, which
# needs no LCM), conf.o (gateway/common/common.mk) and the port's link defaults.
CAN_TEST_OBJS := $(CAN_GATEWAY_OBJS) $(BUILD)/gateway/urrt-gateway/config.o $(CONF_OBJ)
CAN_TEST_CFLAGS := $(PROG_WARN) $(CPPFLAGS) $(GATEWAY_INC) -Itests

CHECKS += check-can-map check-can-map-san check-can-dbc check-replay-rtde check-fuzz-can-in
BENCHES += bench-can
.PHONY: check-can-map check-can-map-san check-can-dbc check-replay-rtde bench-can check-fuzz-can-in fuzz-can-in

# The PLC's inputs as untrusted input (tests/gateway/can/fuzz_can_in.c): [input] frames
# through can_in, and NMT, RPDOs and SDO requests through the CANopen node into them; lib/
# and gateway/ instrumented. Seeds from can_in_seeds.py.
CAN_IN_SEEDS := $(CANT)/can-in-seeds
$(CANT)/fuzz_can_in: tests/gateway/can/fuzz_can_in.c $(CAN_TEST_SRCS) $(GATEWAY_HDRS) $(LIB_SRCS) $(LIB_HDRS) \
  $(LIBPORT)
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=gnu11 -Wall -Wextra -Wshadow -Werror -g -O1 -fsanitize=fuzzer,address,undefined \
	  -fno-sanitize-recover=all $(CPPFLAGS) $(GATEWAY_INC) $< $(CAN_TEST_SRCS) $(LIB_SRCS) $(LIBPORT) -lm -o $@

$(CAN_IN_SEEDS)/.stamp: tests/gateway/can/can_in_seeds.py
	rm -rf $(@D)
	$(PYTHON) $< $(@D)
	touch $@

check-fuzz-can-in: $(CANT)/fuzz_can_in $(CAN_IN_SEEDS)/.stamp
	$(call suite,$@,sh tests/lib/fuzz.sh $(CANT)/fuzz_can_in $(CAN_IN_SEEDS) $(CANT)/fuzz-can-in-check \
	  $(FUZZ_CHECK_SECONDS) --check)

# make fuzz FUZZ_SECONDS=N: as long as asked; the corpus grows in $(CANT)/fuzz-can-in.
fuzz-can-in: $(CANT)/fuzz_can_in $(CAN_IN_SEEDS)/.stamp
	sh tests/lib/fuzz.sh $(CANT)/fuzz_can_in $(CAN_IN_SEEDS) $(CANT)/fuzz-can-in $(FUZZ_SECONDS)

fuzz: fuzz-can-in

# test_can_map, can_tool and bench_can: one source each, the same objects.
$(CANT)/%: tests/gateway/can/%.c tests/check.h tests/testutil.h tests/gateway/bench.h $(CAN_TEST_OBJS) $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(CAN_TEST_CFLAGS) $(OPT) $< $(CAN_TEST_OBJS) $(LIBPORT) $(LIBURRT) -lm -o $@

$(CANT)/test_can_map_san: tests/gateway/can/test_can_map.c tests/check.h tests/testutil.h $(CAN_TEST_SRCS) \
  $(GATEWAY_HDRS) $(LIB_SRCS) $(LIBPORT)
	@mkdir -p $(@D)
	$(CC) $(CAN_TEST_CFLAGS) -O1 -g $(SAN_FLAGS) -fsanitize=float-cast-overflow $< $(CAN_TEST_SRCS) $(LIB_SRCS) \
	  $(LIBPORT) -lm -o $@

check-can-map: $(CANT)/test_can_map
	$(call suite,$@,$<)

check-can-map-san: $(CANT)/test_can_map_san
	$(call suite,$@,ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 $<)

# The [input] half runs after the rest (a failure there stops the suite); the C tables it
# writes are compiled by it with $(CC) and lib/'s flags, and with target.mk's Cortex-M4 compiler.
check-can-dbc: $(CANT)/can_tool $(LIBURRT) tests/gateway/can/ctables_input.c
	$(call suite,$@,$(PYTHON) tests/gateway/can/test_dbc.py --tool $< --work $(CANT)/work && \
	  $(PYTHON) tests/gateway/can/check_dbc_input.py --tool $< --work $(CANT)/work-input --cc "$(CC)" \
	    --cflags "$(LIB_WARN)" --liburrt $(LIBURRT) --target-cc "$(TGT_CM) $(TGT_M4)")

check-replay-rtde: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-gateway
	$(call suite,$@,timeout -k 5 120 $(PYTHON) tests/gateway/can/check_replay_rtde.py $(BUILD))

bench-can: $(CANT)/bench_can
	@$< docs/examples/canopen.ini
