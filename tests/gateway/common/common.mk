# SPDX-License-Identifier: MIT
# tests/gateway/common/common.mk: what the three programs share (gateway/common/).
#   check-rtde-capture      gateway/common/rtde_capture (tests/gateway/common/test_rtde_capture.c):
#                           every session of tests/ref/rtde_ref.py written as a capture (the
#                           controller's bytes split at every point) and replayed through
#                           lib's client: the same events and values as lib fed directly;
#                           the records byte for byte; cut, damaged and foreign files
#   check-rtde-capture-san  the same under ASan + UBSan

GCT := $(BUILD)/tests/gateway/common

CHECKS += check-rtde-capture check-rtde-capture-san
.PHONY: check-rtde-capture check-rtde-capture-san

$(GCT)/test_rtde_capture: tests/gateway/common/test_rtde_capture.c gateway/common/rtde_capture.c \
                          gateway/common/rtde_capture.h tests/check.h $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(GW_CFLAGS) -Itests $< gateway/common/rtde_capture.c $(LIBURRT) -lm -o $@

$(GCT)/test_rtde_capture_san: tests/gateway/common/test_rtde_capture.c gateway/common/rtde_capture.c \
                              gateway/common/rtde_capture.h tests/check.h $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(GW_CFLAGS) -O1 -g $(SAN_FLAGS) -Itests $< gateway/common/rtde_capture.c $(LIB_SRCS) -lm -o $@

# tests/lib/rtde.mk, which names the vectors, is read after this file: $$ defers the name
# to the second expansion (.SECONDEXPANSION is on since gateway/urrt-gateway/urrt-gateway.mk).
check-rtde-capture: $(GCT)/test_rtde_capture $$(RTDE_VECTORS)
	@mkdir -p $(GCT)/scratch
	$(call suite,$@,$(GCT)/test_rtde_capture $(RTDE_VECTORS) $(GCT)/scratch)

check-rtde-capture-san: $(GCT)/test_rtde_capture_san $$(RTDE_VECTORS)
	@mkdir -p $(GCT)/scratch-san
	$(call suite,$@,ASAN_OPTIONS=detect_leaks=1 $(GCT)/test_rtde_capture_san $(RTDE_VECTORS) $(GCT)/scratch-san)
