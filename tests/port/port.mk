# SPDX-License-Identifier: MIT
# tests/port/port.mk: port/posix, the seam a firmware replaces.
#   check-link     tests/port/test_link.c: the robot link (port/posix/link.c) against
#                  in-process servers: framing across reads, read stamps, silence, backoff,
#                  reconnects, a frozen peer (up only when data flows), a source that speaks
#                  first (handshake, partial writes, drops); and gateway/common/cli.c's
#                  host:port parsing
#   check-can-log  the CAN link's candump-log output (port/posix/can.c) on the host, no CAN
#                  needed: exact lines from can_link_test, then python-can's candump-log reader;
#                  log:- into a pipe, a socket and a terminal whose reader stalls
#   (check-vm)     the CAN link on a real kernel's vcan: tests/port/can-link.sh runs
#                  can_link_test in the VM of tests/vm/vm.mk (frames, candump/canplayer
#                  agreement, full queue, down/up, error frames)
# No fixed TCP port: every server takes one from the system.
PORTT := $(BUILD)/tests/port

CHECKS += check-link check-can-log
.PHONY: check-link check-can-log

$(PORTT)/test_link: tests/port/test_link.c tests/check.h $(CLI_OBJ) $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(CPPFLAGS) $(GATEWAY_INC) -Itests -o $@ $< $(CLI_OBJ) $(LIBPORT) $(LIBURRT) -lm

check-link: $(PORTT)/test_link
	$(call suite,$@,timeout -k 5 60 $<)

$(PORTT)/can_link_test: tests/port/can_link_test.c tests/check.h port/port.h $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(CPPFLAGS) $< $(LIBPORT) $(LIBURRT) -o $@

# The same tests with ASan and UBSan, everything compiled with them.
$(PORTT)/can_link_test_san: tests/port/can_link_test.c tests/check.h port/port.h $(PORT_SRCS) $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) -O1 -g $(SAN_FLAGS) $(CPPFLAGS) $< $(PORT_SRCS) $(LIB_SRCS) -o $@

check-can-log: $(PORTT)/can_link_test $(PORTT)/can_link_test_san
	$(call suite,$@,sh tests/port/check-can-log.sh $(PORTT))

VM_TESTS += tests/port/can-link.sh
VM_FILES += $(PORTT)/can_link_test $(PORTT)/can_link_test_san
VM_MODULES += sch_plug
check-vm: $(PORTT)/can_link_test $(PORTT)/can_link_test_san
