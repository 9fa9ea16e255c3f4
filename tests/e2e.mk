# tests/e2e.mk: urrt-sim -> urrt-gateway -> vcan0 -> candump on a real kernel,
# inside the check-vm VM (tests/vm.mk); tests/e2e/e2e-can.post checks the
# recording on the host through the gateway's DBC.
VM_TESTS += tests/e2e/e2e-can.sh
VM_FILES += $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-gateway tests/e2e/e2e-can.ini
check-vm: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-gateway
