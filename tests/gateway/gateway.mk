# SPDX-License-Identifier: MIT
# tests/gateway/gateway.mk: urrt-gateway against urrt-sim, through LCM.
#   check-gateway   values, decimation, two robots, restart/stall, a stopped
#                   simulator (GATEWAY's link state, EMCY 0xFF01 and the CAN
#                   heartbeat down until data flows), the summary's rates,
#                   mismatch, zero allocations, publish errors, bad configurations, jar
#   check-freshness the age estimator and the summary's rate meter on a fake clock
#   check-notify    systemd's notify protocol on the test's own NOTIFY_SOCKET: READY,
#                   STATUS, WATCHDOG at half the period and none while SIGSTOPped, STOPPING
#   check-metrics   the Prometheus textfile: promtool accepts it, values against the
#                   simulator and the CAN log, renamed whole, write errors counted
#   bench-gateway   first counts per packet beside a minimal relay
#                   (bench_relay.c): user-space instructions (valgrind's
#                   cachegrind) and system calls (strace -c), RealTime and RTDE
#                   (urrt-sim --rtde), 1/10/50 robots; then latency robot ->
#                   subscriber and CPU per packet beside the relay, 1/10/50
#                   robots, the CPU per packet at 50 robots against 10, highest
#                   rate, and the 500 Hz robots one core serves; then
#                   bench-plc-io (the PLC's frames written as input registers,
#                   in the VM)
GWT := $(BUILD)/tests/gateway
GWT_CFLAGS := $(PROG_WARN) $(OPT) $(CPPFLAGS) -I$(LCMGEN)

CHECKS += check-freshness check-gateway check-notify check-metrics
BENCHES += bench-gateway
.PHONY: check-freshness check-gateway check-notify check-metrics bench-gateway
# promtool, for check-metrics; strace, for bench-gateway's system calls per
# packet (valgrind, its instructions, is in the Makefile's list).
DEB_DEPS += prometheus strace

# The age estimator and the rate meter on a fake clock (gateway/urrt-gateway/freshness.h).
$(GWT)/test_freshness: tests/gateway/test_freshness.c tests/check.h gateway/urrt-gateway/freshness.c gateway/urrt-gateway/freshness.h
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(GATEWAY_INC) -Itests $< gateway/urrt-gateway/freshness.c -o $@

check-freshness: $(GWT)/test_freshness
	$(call suite,$@,$<)

$(GWT)/lcm_sub: tests/gateway/lcm_sub.c $(LCMTYPES_OBJS) $(LCMTYPES_H) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(GWT_CFLAGS) -o $@ $< $(LCMTYPES_OBJS) $(LIBURRT) -llcm -lm

$(GWT)/alloc_shim.so: tests/gateway/alloc_shim.c
	@mkdir -p $(@D)
	$(CC) -std=gnu11 $(OPT) -Wall -Wextra -Werror -fPIC -shared -o $@ $< -ldl

$(GWT)/bench_gateway: tests/gateway/bench_gateway.c $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(GWT_CFLAGS) -o $@ $< $(LIBURRT) -lm -lpthread

$(GWT)/bench_relay: tests/gateway/bench_relay.c $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(GWT_CFLAGS) -o $@ $< $(LIBURRT) -llcm

check-gateway: $(BUILD)/bin/urrt-gateway $(BUILD)/bin/urrt-sim $(GWT)/lcm_sub $(GWT)/alloc_shim.so $(LCMTYPES_JAR)
	$(call suite,$@,$(PYTHON) tests/gateway/test_gateway.py --build $(BUILD))

check-notify: $(BUILD)/bin/urrt-gateway $(BUILD)/bin/urrt-sim
	$(call suite,$@,$(PYTHON) tests/gateway/test_notify.py --build $(BUILD))

check-metrics: $(BUILD)/bin/urrt-gateway $(BUILD)/bin/urrt-sim
	$(call suite,$@,$(PYTHON) tests/gateway/test_metrics.py --build $(BUILD))

# First the counts: gateway and relay under valgrind (instructions) and strace
# (system calls), RealTime and RTDE, at each of BENCH_GATEWAY_ROBOTS, every
# message at every packet, BENCH_GATEWAY_COUNT_PACKETS packets a figure
# (BENCH_GATEWAY_KEEP=DIR keeps the tools' files). Then the times: the gateway
# beside the relay, every message at every packet, then the
# focused messages at 50 Hz and no state; then one gateway against 1, 10 and
# 50 robots at 500 Hz each, every message at every packet, and again with the
# focused messages; then the CPU per packet at 50 robots against 10, three
# rounds of each in turn, both ways. Each CPU per packet also says how many
# robots one core serves.
BENCH_GATEWAY_ROBOTS ?= 1 10 50
# --no-pin: the bench and the subject wherever the scheduler puts them.
BENCH_GATEWAY_FLAGS ?=
BENCH_GATEWAY_COUNT_PACKETS ?= 1000
BENCH_GATEWAY_KEEP ?=
BENCH_GW = $(GWT)/bench_gateway $(BENCH_GATEWAY_FLAGS)
bench-gateway: $(BUILD)/bin/urrt-gateway $(BUILD)/bin/urrt-sim $(GWT)/bench_gateway $(GWT)/bench_relay
	@echo "bench-gateway: counts per packet, which do not move with the load: *instructions_per_packet, user space"
	@echo "bench-gateway: (valgrind --tool=cachegrind), *syscalls_per_packet (strace -f -c), each the difference of a"
	@echo "bench-gateway: long and a short session over the packets between; every message at every packet, each"
	@echo "bench-gateway: packet written once the last one's messages are in; RTDE: urrt-sim --rtde's handshake"
	@$(BENCH_GW) --counts --gateway $(BUILD)/bin/urrt-gateway --relay $(GWT)/bench_relay --sim $(BUILD)/bin/urrt-sim \
	  --count-robots "$(BENCH_GATEWAY_ROBOTS)" --count-packets $(BENCH_GATEWAY_COUNT_PACKETS) \
	  $(if $(BENCH_GATEWAY_KEEP),--keep $(BENCH_GATEWAY_KEEP))
	@echo "bench-gateway: then the times, the second figure: latency, CPU per packet (wall clock, machine and load)"
	@echo "bench-gateway: *robots_per_core = 1 / (cpu_per_packet_us * 1e-6 * 500): the 500 Hz robots one core"
	@echo "bench-gateway: serves at the subject's CPU per packet (its threads, from schedstat) measured there"
	@echo "bench-gateway: the subject on a core of its own, the bench on another (BENCH_GATEWAY_FLAGS=--no-pin:"
	@echo "bench-gateway: as the scheduler places them); *runs_per_packet, *subscriber_reads_per_packet: counts"
	@echo "bench-gateway: all messages at every packet, gateway beside relay"
	@$(BENCH_GW) --gateway $(BUILD)/bin/urrt-gateway --relay $(GWT)/bench_relay --max-rate
	@echo "bench-gateway: focused messages at 50 Hz, no state, gateway beside relay"
	@$(BENCH_GW) --gateway $(BUILD)/bin/urrt-gateway --relay $(GWT)/bench_relay --focused-hz 50 \
	  | sed 's/^/decimated_/'
	@echo "bench-gateway: one gateway, many robots at 500 Hz, every message at every packet"
	@for n in $(BENCH_GATEWAY_ROBOTS); do \
	  $(BENCH_GW) --gateway $(BUILD)/bin/urrt-gateway --robots $$n || exit 1; done
	@echo "bench-gateway: one gateway, many robots at 500 Hz, focused messages at 50 Hz, no state"
	@for n in $(BENCH_GATEWAY_ROBOTS); do \
	  $(BENCH_GW) --gateway $(BUILD)/bin/urrt-gateway --robots $$n --focused-hz 50 || exit 1; done
	@echo "bench-gateway: CPU per packet at 50 robots against 10 (the loop's cost per wake-up must not grow with the robots)"
	@$(BENCH_GW) --gateway $(BUILD)/bin/urrt-gateway --robots 10 --versus 50 --rounds 3
	@$(BENCH_GW) --gateway $(BUILD)/bin/urrt-gateway --robots 10 --versus 50 --rounds 3 --focused-hz 50
	@echo "bench-gateway: the PLC's answers (tests/plc/check-plc-io.mk), in the VM: its frame to the input package, beside a package to its frame"
	@$(MAKE) --no-print-directory bench-plc-io
