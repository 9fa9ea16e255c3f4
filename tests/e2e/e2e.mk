# SPDX-License-Identifier: MIT
# tests/e2e/e2e.mk: urrt-sim -> urrt-gateway -> vcan0 -> candump on a real kernel,
# inside the check-vm VM (tests/vm/vm.mk); tests/e2e/e2e-can.post checks the
# recording on the host through the gateway's DBC, and the gateway's LCM
# status through tests/gateway's subscriber.
E2E := $(BUILD)/tests/e2e
VM_TESTS += tests/e2e/e2e-can.sh
VM_FILES += $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-gateway tests/e2e/e2e-can.ini $(E2E)/can_error $(BUILD)/tests/gateway/lcm_sub
check-vm: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-gateway $(E2E)/can_error $(BUILD)/tests/gateway/lcm_sub

$(E2E)/can_error: tests/e2e/can_error.c
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $< -o $@
