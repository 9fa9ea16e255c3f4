# SPDX-License-Identifier: MIT
# tests/lib/can.mk: lib/urrt_can (bit packing) and lib/urrt_cantx (the CAN core) on the host.
#   check-can        tests/lib/test_can.c: bit placement by hand-worked vectors, rounding,
#                    saturation, NaN, layout checks, frame bit lengths
#   check-can-san    the same under ASan + UBSan (float-cast-overflow included: no float to
#                    integer conversion may be undefined), lib/ compiled with them
#   check-cantx      tests/lib/test_cantx.c: schedule, stale policies, alive counters, validity
#                    bits and the heartbeat on a fake clock
#   check-cantx-san  the same under ASan + UBSan
# check-lib-m4 and check-lib-be (tests/target/target.mk) run both on emulated cores.
LIBCANT := $(BUILD)/tests/lib
LIBCAN_TEST_CFLAGS := $(PROG_WARN) $(CPPFLAGS) -Itests
LIBCAN_SAN := -O1 -g $(SAN_FLAGS) -fsanitize=float-cast-overflow

CHECKS += check-can check-can-san check-cantx check-cantx-san
.PHONY: check-can check-can-san check-cantx check-cantx-san

$(LIBCANT)/test_can $(LIBCANT)/test_cantx: $(LIBCANT)/%: tests/lib/%.c tests/check.h tests/testutil.h $(LIBURRT) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIBCAN_TEST_CFLAGS) $(OPT) $< $(LIBURRT) -lm -o $@

$(LIBCANT)/test_can_san $(LIBCANT)/test_cantx_san: $(LIBCANT)/%_san: tests/lib/%.c tests/check.h tests/testutil.h $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIBCAN_TEST_CFLAGS) $(LIBCAN_SAN) $< $(LIB_SRCS) -lm -o $@

SAN_ENV := ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1
check-can: $(LIBCANT)/test_can
	$(call suite,$@,$<)
check-can-san: $(LIBCANT)/test_can_san
	$(call suite,$@,$(SAN_ENV) $<)
check-cantx: $(LIBCANT)/test_cantx
	$(call suite,$@,$<)
check-cantx-san: $(LIBCANT)/test_cantx_san
	$(call suite,$@,$(SAN_ENV) $<)
