# SPDX-License-Identifier: MIT
# tests/vm.mk: tests on a real Linux kernel with SocketCAN, in a qemu VM
# (tests/vm/run.sh, docs/vm.md).
#   check-vm       boots the VM once and runs every script of VM_TESTS inside
#                  (the CAN link against vcan: frames, candump/canplayer
#                  agreement, full queue, down/up, error frames)
#   check-can-log  the CAN link's candump-log output on the host (no VM)
#
# Another suite joins the VM run from its own fragment:
#   VM_TESTS += tests/vm/e2e.sh                     (a sh script, see suite.sh)
#   VM_FILES += $(BUILD)/bin/urrt-gateway gw.ini    (put in the VM's /t)
#   VM_MODULES += can-gw                            (more kernel modules)
#   check-vm: $(BUILD)/bin/urrt-gateway            (built first)
VMT := $(BUILD)/tests
VM_TESTS += tests/vm/can-link.sh
VM_FILES += $(VMT)/can_link_test $(VMT)/can_link_test_san
VM_MODULES += sch_plug

CHECKS += check-can-log check-vm
DEB_DEPS += qemu-system-x86 busybox-static cpio xz-utils iproute2 can-utils python3-can
.PHONY: check-vm check-can-log vm-kernel

$(VMT)/can_link_test: tests/vm/can_link_test.c tests/check.h port/port.h $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(CPPFLAGS) $< $(LIBPORT) $(LIBURRT) -o $@

# The same tests with ASan and UBSan, everything compiled with them.
$(VMT)/can_link_test_san: tests/vm/can_link_test.c tests/check.h port/port.h $(PORT_SRCS) $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) -O1 -g $(SAN_FLAGS) $(CPPFLAGS) $< $(PORT_SRCS) $(LIB_SRCS) -o $@

check-vm: $(VMT)/can_link_test $(VMT)/can_link_test_san
	@tests/vm/check-vm.sh '$(BUILD)' '$(VM_TESTS)' '$(VM_FILES)' '$(VM_MODULES)'

check-can-log: $(VMT)/can_link_test $(VMT)/can_link_test_san
	@tests/vm/check-can-log.sh '$(BUILD)'

# Downloads the kernel into the cache ahead of time (check-vm does it too).
vm-kernel:
	@tests/vm/fetch-kernel.sh
