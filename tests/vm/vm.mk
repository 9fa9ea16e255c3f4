# SPDX-License-Identifier: MIT
# tests/vm/vm.mk: the harness that runs tests on a real Linux kernel with
# SocketCAN, in a qemu VM booting Debian's kernel (tests/vm/run.sh, docs/vm.md).
#   check-vm       boots the VM once and runs every script of VM_TESTS inside
#                  (tests/port/can-link.sh, tests/port/can-rx.sh, tests/e2e/e2e-can.sh ...),
#                  then each script's host-side checker (NAME.post) if it has one
#
# A suite joins the VM run from its own fragment:
#   VM_TESTS += tests/DIR/NAME.sh                   (a sh script, see suite.sh)
#   VM_FILES += $(BUILD)/bin/urrt-gateway gw.ini    (put in the VM's /t)
#   VM_MODULES += can-gw                            (more kernel modules)
#   check-vm: $(BUILD)/bin/urrt-gateway            (built first)
CHECKS += check-vm
DEB_DEPS += qemu-system-x86 busybox-static cpio xz-utils iproute2 can-utils python3-can
.PHONY: check-vm vm-kernel

check-vm:
	$(call suite,$@,tests/vm/check-vm.sh '$(BUILD)' '$(VM_TESTS)' '$(VM_FILES)' '$(sort $(VM_MODULES))')

# Downloads the kernel into the cache ahead of time (check-vm does it too).
vm-kernel:
	@tests/vm/fetch-kernel.sh
