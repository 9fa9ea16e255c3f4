# SPDX-License-Identifier: MIT
# tests/plc/check-plc-io.mk: the PLC's answers (docs/examples/plc-io.ini) in the qemu
# VM (tests/vm/run.sh): a PLC on vcan0 written in the tests (plc_io.py, python3-can)
# writes urrt-sim's input registers through urrt-gateway's RTDE session, which a
# proxy records byte for byte; IN_USE, refused values, silence, a reconnect, the
# interface down.
#   check-plc-io
#   bench-plc-io   in the same VM, BENCH_PLC_FRAMES frames timed both ways: the PLC's
#                  frame to its input package, beside a data package to its frame (the
#                  RTDE decode's way), median and p99, their ratio; the register read
#                  back in controller cycles; the round trip
# (python3-can, qemu: tests/vm/vm.mk.)
CHECKS += check-plc-io
# bench-plc-io runs as the last part of bench-gateway (tests/gateway/gateway.mk).
BENCH_PLC_FRAMES ?= 1000
.PHONY: check-plc-io bench-plc-io
check-plc-io: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-gateway $(GWT)/lcm_sub
	$(call suite,$@,tests/plc/check-plc-io.sh '$(BUILD)')

bench-plc-io: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-gateway $(GWT)/lcm_sub
	@echo "bench-plc-io: emulated (TCG) VM, one CPU: ratios and counts repeat, milliseconds do not"
	@tests/plc/check-plc-io.sh '$(BUILD)' $(BENCH_PLC_FRAMES) | grep -E '^\*?[a-z_0-9]+ [-0-9.na]+$$'
