# SPDX-License-Identifier: MIT
# tests/canopen/check-canopen.mk: urrt-gateway as a CANopen node on vcan, in the qemu VM
# (tests/vm/run.sh), managed by a CiA 301 master written in the tests
# (tests/canopen/master.py, python3-can): boot-up, identity, heartbeat time, every
# bad SDO request, TPDOs, SYNC, stop, reset, the robot link cut (EMCY). On the host:
# the EDS against CiA 306 (eds_check.py), every frame through tshark's CANopen
# dissector, the TPDO values through the DBC against urrt-dump (canopen.post).
# docs/examples/rtde-plc.ini, and plc-io-canopen.ini (a manager's RPDOs and SDO writes
# become urrt-sim's registers: check-plc-io-co.sh, plc_io_co.py), in VMs of their own.
#   check-canopen
# (tshark: tests/wireshark/wireshark.mk; python3-can, qemu: tests/vm/vm.mk.)
CHECKS += check-canopen
.PHONY: check-canopen
check-canopen: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-gateway $(BUILD)/bin/urrt-dump
	$(call suite,$@,tests/canopen/check-canopen.sh '$(BUILD)')
