# SPDX-License-Identifier: MIT
# tests/gateway/tools/tools.mk: urrt-sim and urrt-dump.
#   check-tools       urrt-sim and urrt-dump end to end (shell + Python reference)
#   check-tools-asan  check-link (tests/port), check-tools, check-sim-rtde and check-dump-rtde again, everything built with ASan and UBSan
#   check-sim-rtde    urrt-sim's RTDE port against a client written from the protocol (rtde_peer.py)
#   check-dump-rtde   urrt-dump --rtde against urrt-sim's RTDE port and its RealTime output; its RTDE captures (-w, --file)
#   bench-tools       the simulator's schedule at 500 Hz: lateness, late packets
# No fixed TCP port: every server takes one from the system, so that runs in
# two build directories at once (or -j) do not meet.
.PHONY: check-tools check-tools-asan check-sim-rtde check-dump-rtde bench-tools
check-tools: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
	$(call suite,$@,BUILD=$(BUILD) PYTHON=$(PYTHON) timeout -k 5 110 sh tests/gateway/tools/check_tools.sh)

check-sim-rtde: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
	$(call suite,$@,timeout -k 5 200 $(PYTHON) tests/gateway/tools/check_sim_rtde.py $(BUILD))

check-dump-rtde: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
	$(call suite,$@,timeout -k 5 200 $(PYTHON) tests/gateway/tools/check_dump_rtde.py $(BUILD))

# The same suites on a sanitized build in its own directory. Leak checking is
# off: LeakSanitizer needs ptrace, which hangs at exit in some sandboxes.
TOOLS_ASAN_BUILD := $(BUILD)/tools-asan
check-tools-asan:
	@$(MAKE) --no-print-directory BUILD=$(TOOLS_ASAN_BUILD) OPT="-O1 -g $(SAN_FLAGS)" \
	  $(TOOLS_ASAN_BUILD)/bin/urrt-sim $(TOOLS_ASAN_BUILD)/bin/urrt-dump $(TOOLS_ASAN_BUILD)/tests/port/test_link >/dev/null
	$(call suite,$@,rm -rf $(TOOLS_ASAN_BUILD)/results; \
	  ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  $(MAKE) --no-print-directory -k BUILD=$(TOOLS_ASAN_BUILD) OPT="-O1 -g $(SAN_FLAGS)" \
	  check-link check-tools check-sim-rtde check-dump-rtde > $(TOOLS_ASAN_BUILD)/check.log 2>&1; \
	  grep -v '^ok: ' $(TOOLS_ASAN_BUILD)/check.log | grep -v '^rt.py: ' | grep -v ' passed.* failed$$' | tail -n 20; \
	  sh tests/summary.sh $(TOOLS_ASAN_BUILD)/results check-link check-tools check-sim-rtde check-dump-rtde)

bench-tools: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
	BUILD=$(BUILD) timeout 60 sh tests/gateway/tools/bench_tools.sh

CHECKS += check-tools check-tools-asan check-sim-rtde check-dump-rtde
BENCHES += bench-tools
