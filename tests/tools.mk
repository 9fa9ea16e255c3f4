# tests/tools.mk: the robot link, urrt-sim and urrt-dump.
#   check-tools-link  the POSIX link against in-process servers, and cli.c (C)
#   check-tools       urrt-sim and urrt-dump end to end (shell + Python reference)
#   bench-tools       the simulator's schedule at 500 Hz: lateness, late packets
# TCP ports: check-tools-link 40500-40509, check-tools 40200-40299, bench 40800.
TOOLS_TEST_LINK := $(BUILD)/tests/test_link

$(TOOLS_TEST_LINK): tests/tools/test_link.c tests/check.h $(CLI_OBJ) $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(CPPFLAGS) -Igateway -Itests -o $@ $< $(CLI_OBJ) $(LIBPORT) $(LIBURRT) -lm

.PHONY: check-tools-link check-tools bench-tools
check-tools-link: $(TOOLS_TEST_LINK)
	@mkdir -p $(BUILD)/results
	@rc=0; timeout 60 $(TOOLS_TEST_LINK) 40500 > $(BUILD)/results/$@.result || rc=$$?; \
	  cat $(BUILD)/results/$@.result; exit $$rc

check-tools: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
	@mkdir -p $(BUILD)/results
	BUILD=$(BUILD) PYTHON=$(PYTHON) timeout 110 sh tests/tools/check_tools.sh

bench-tools: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
	BUILD=$(BUILD) timeout 60 sh tests/tools/bench_tools.sh

CHECKS += check-tools-link check-tools
BENCHES += bench-tools
