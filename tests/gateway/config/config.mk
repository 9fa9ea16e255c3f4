# SPDX-License-Identifier: MIT
# tests/gateway/config/config.mk: the gateway configuration as untrusted input.
#   check-fuzz-config  the regression tests of what the fuzzer found (test_config), then the
#                      libFuzzer harness (ASan + UBSan) over the loader, the CAN mapping, its
#                      tables and the DBC writer: every seed and regression input, then briefly
#   fuzz-config        the same harness for FUZZ_SECONDS (part of `make fuzz`)
# Seeds: docs/examples, the example configuration, the e2e one, tests/gateway/config/seeds.

CFGT := $(BUILD)/tests/gateway/config
CFG_SEEDS := $(CFGT)/seeds
CFG_SEED_FILES := $(wildcard docs/examples/*.ini) gateway/install/urrt-gateway.example.ini tests/e2e/e2e-can.ini \
                  $(wildcard tests/gateway/config/seeds/*.ini)
CFG_FUZZ_SRCS = gateway/urrt-gateway/config.c gateway/common/conf.c $(CAN_GATEWAY_OBJS:$(BUILD)/%.o=%.c)
CFG_FUZZ_HDRS := $(GATEWAY_HDRS) port/port.h $(LIB_HDRS)

CHECKS += check-fuzz-config
.PHONY: check-fuzz-config fuzz-config

# One directory of seeds, rebuilt when any of them changes (libFuzzer reads directories).
$(CFG_SEEDS)/.stamp: $(CFG_SEED_FILES)
	rm -rf $(CFG_SEEDS)
	mkdir -p $(CFG_SEEDS)
	for f in $(CFG_SEED_FILES); do cp $$f $(CFG_SEEDS)/$$(echo $$f | tr / _); done
	touch $@

# lib/ and gateway/ instrumented; port/ (only urrt_link_config_defaults is used) as built.
$(CFGT)/fuzz_config: tests/gateway/config/fuzz_config.c $(CFG_FUZZ_SRCS) $(CFG_FUZZ_HDRS) $(LIB_SRCS) $(LIBPORT)
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=gnu11 -Wall -Wextra -Wshadow -Werror -g -O1 -fsanitize=fuzzer,address,undefined \
	  -fno-sanitize-recover=all $(CPPFLAGS) $(GATEWAY_INC) $< $(CFG_FUZZ_SRCS) $(LIB_SRCS) $(LIBPORT) -lm -o $@

$(CFGT)/test_config: tests/gateway/config/test_config.c tests/check.h tests/testutil.h $(CFG_FUZZ_SRCS) $(CFG_FUZZ_HDRS) $(LIB_SRCS) $(LIBPORT)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) -O1 -g $(SAN_FLAGS) -fsanitize=float-cast-overflow $(CPPFLAGS) $(GATEWAY_INC) -Itests \
	  $< $(CFG_FUZZ_SRCS) $(LIB_SRCS) $(LIBPORT) -lm -o $@

check-fuzz-config: $(CFGT)/fuzz_config $(CFGT)/test_config $(CFG_SEEDS)/.stamp
	$(call suite,$@,REGRESSION=$(CFGT)/test_config \
	  sh tests/gateway/config/fuzz.sh $(CFGT)/fuzz_config $(CFG_SEEDS) $(CFGT)/fuzz-check $(FUZZ_CHECK_SECONDS) --check)

# make fuzz FUZZ_SECONDS=N: as long as asked; the corpus grows in $(CFGT)/fuzz.
fuzz-config: $(CFGT)/fuzz_config $(CFG_SEEDS)/.stamp
	sh tests/gateway/config/fuzz.sh $(CFGT)/fuzz_config $(CFG_SEEDS) $(CFGT)/fuzz $(FUZZ_SECONDS)

fuzz: fuzz-config
