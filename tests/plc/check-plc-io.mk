# SPDX-License-Identifier: MIT
# tests/plc/check-plc-io.mk: the PLC's answers (docs/examples/plc-io.ini) in the qemu
# VM (tests/vm/run.sh): a PLC on vcan0 written in the tests (plc_io.py, python3-can)
# writes urrt-sim's input registers through urrt-gateway's RTDE session, which a
# proxy records byte for byte; IN_USE, refused values, silence, a reconnect, the
# interface down.
#   check-plc-io
# (python3-can, qemu: tests/vm/vm.mk.)
CHECKS += check-plc-io
.PHONY: check-plc-io
check-plc-io: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-gateway
	$(call suite,$@,tests/plc/check-plc-io.sh '$(BUILD)')
