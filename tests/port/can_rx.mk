# SPDX-License-Identifier: MIT
# tests/port/can_rx.mk: the CAN link's receive side (port/posix/can.c) on vcan, in the
# check-vm VM (tests/vm/vm.mk), and the log link's caller clock: tests/port/can_rx_test.c,
# driven by tests/port/can-rx.sh, once plain and once with ASan and UBSan.
CANRX := $(BUILD)/tests/port
VM_TESTS += tests/port/can-rx.sh
VM_FILES += $(CANRX)/can_rx_test $(CANRX)/can_rx_test_san
check-vm: $(CANRX)/can_rx_test $(CANRX)/can_rx_test_san

$(CANRX)/can_rx_test: tests/port/can_rx_test.c tests/check.h port/port.h $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(CPPFLAGS) $< $(LIBPORT) $(LIBURRT) -pthread -o $@

$(CANRX)/can_rx_test_san: tests/port/can_rx_test.c tests/check.h port/port.h $(PORT_SRCS) $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) -O1 -g $(SAN_FLAGS) $(CPPFLAGS) $< $(PORT_SRCS) $(LIB_SRCS) -pthread -o $@
