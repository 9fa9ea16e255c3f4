# SPDX-License-Identifier: MIT
# tests/tools.mk: the robot link, urrt-sim and urrt-dump.
#   check-tools-link  the POSIX link against in-process servers, and cli.c (C)
#   check-tools       urrt-sim and urrt-dump end to end (shell + Python reference)
#   check-tools-asan  both again, everything built with ASan and UBSan
#   bench-tools       the simulator's schedule at 500 Hz: lateness, late packets
# No fixed TCP port: every server takes one from the system, so that runs in
# two build directories at once (or -j) do not meet.
TOOLS_TEST_LINK := $(BUILD)/tests/test_link

$(TOOLS_TEST_LINK): tests/tools/test_link.c tests/check.h $(CLI_OBJ) $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(CPPFLAGS) $(GATEWAY_INC) -Itests -o $@ $< $(CLI_OBJ) $(LIBPORT) $(LIBURRT) -lm

.PHONY: check-tools-link check-tools check-tools-asan bench-tools
check-tools-link: $(TOOLS_TEST_LINK)
	@mkdir -p $(BUILD)/results
	@rc=0; timeout -k 5 60 $(TOOLS_TEST_LINK) > $(BUILD)/results/$@.result || rc=$$?; \
	  cat $(BUILD)/results/$@.result; exit $$rc

check-tools: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
	@mkdir -p $(BUILD)/results
	BUILD=$(BUILD) PYTHON=$(PYTHON) timeout -k 5 110 sh tests/tools/check_tools.sh

# The same suites on a sanitized build in its own directory. Leak checking is
# off: LeakSanitizer needs ptrace, which hangs at exit in some sandboxes.
TOOLS_ASAN_BUILD := $(BUILD)/tools-asan
check-tools-asan:
	@mkdir -p $(BUILD)/results
	@$(MAKE) --no-print-directory BUILD=$(TOOLS_ASAN_BUILD) OPT="-O1 -g $(SAN_FLAGS)" \
	  $(TOOLS_ASAN_BUILD)/bin/urrt-sim $(TOOLS_ASAN_BUILD)/bin/urrt-dump $(TOOLS_ASAN_BUILD)/tests/test_link >/dev/null
	@rm -rf $(TOOLS_ASAN_BUILD)/results; \
	  ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  $(MAKE) --no-print-directory -k BUILD=$(TOOLS_ASAN_BUILD) OPT="-O1 -g $(SAN_FLAGS)" \
	  check-tools-link check-tools > $(TOOLS_ASAN_BUILD)/check.log 2>&1; rc=$$?; \
	  grep -v '^ok: ' $(TOOLS_ASAN_BUILD)/check.log | grep -v '^rt.py: ' | tail -n 20; \
	  sh tests/summary.sh $(TOOLS_ASAN_BUILD)/results check-tools-link check-tools | tail -n 1 > $(BUILD)/results/$@.result; \
	  cat $(BUILD)/results/$@.result; [ $$rc = 0 ] && grep -q ' 0 failed$$' $(BUILD)/results/$@.result

bench-tools: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
	BUILD=$(BUILD) timeout 60 sh tests/tools/bench_tools.sh

CHECKS += check-tools-link check-tools check-tools-asan
BENCHES += bench-tools
