# SPDX-License-Identifier: MIT
# tests/soak/soak.mk: make soak SOAK_MINUTES=N (default 10). urrt-sim cycles through
# every fault mode against two long-running urrt-gateways, one with an LCM and
# a CAN log output, one a CANopen node with its own log; an independent
# checker judges every message's and frame's data age, the node's EMCYs and
# heartbeats, and both gateways' RSS and descriptors. Beside them, in the qemu
# VM (SocketCAN), an RTDE robot through RTDE's faults and a PLC writing its
# input registers by frames and RPDOs (tests/soak/soak_plc.py; python3-can,
# qemu: tests/vm/vm.mk). Not part of `make check`.
SOAK_MINUTES ?= 10
# Seconds per fault phase: 12 phases make one pass.
SOAK_PHASE_SECONDS ?= 10
SOAKT := $(BUILD)/tests/soak

.PHONY: soak

$(SOAKT)/soak_lcm: tests/soak/soak_lcm.c $(LCMTYPES_OBJS) $(LCMTYPES_H)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) -I$(LCMGEN) -o $@ $< $(LCMTYPES_OBJS) -llcm -lm

soak: $(BUILD)/bin/urrt-gateway $(BUILD)/bin/urrt-sim $(SOAKT)/soak_lcm
	@mkdir -p $(BUILD)/results
	tests/canopen/stage-python.sh $(SOAKT)/py
	timeout --signal=TERM --kill-after=30 $$(( $(SOAK_MINUTES) * 60 + 600 )) \
	  $(PYTHON) tests/soak/soak.py --build $(BUILD) --minutes $(SOAK_MINUTES) --phase-seconds $(SOAK_PHASE_SECONDS) \
	  --python-stage $(SOAKT)/py --result $(BUILD)/results/soak.result
