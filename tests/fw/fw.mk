# SPDX-License-Identifier: MIT
# tests/fw/fw.mk: a firmware gateway built from lib/ alone against urrt-gateway.
#   check-fw-gateway  the same capture (tests/fw/make_capture.py: 500 packets with a stall,
#                     clamped and NaN values, garbage between packets) through
#                     (a) urrt-gateway --replay with a docs/examples/ configuration, interface = log:PATH
#                     (b) tests/fw/fw_gateway.c with lib/ and the tables urrt-gateway --print-c-tables
#                         wrote for the same file, bare metal on qemu's Cortex-M4 (mps2-an386), no C
#                         library, the capture read through semihosting in 1460-byte chunks
#                     both clocked by the packets' controller time: the frames (id, flags, payload,
#                     order) must be identical. For canopen.ini (classic, a CANopen node: the
#                     image runs lib/urrt_co too, built with -DFW_CANOPEN, and both are fed the
#                     same manager's frames, tests/fw/master_frames.py: NMT, SYNC, SDO with
#                     segmented upload and aborts, via --replay-rx), fd.ini (CAN FD) and
#                     j1939.ini (29-bit ids); prints the canopen image's footprint.
# The rules use target.mk's toolchain variables in recipes only (it is included after this file).

FW := $(BUILD)/tests/fw
FW_CONFIGS := canopen fd j1939
FW_CANOPEN := canopen
FW_LIB_OBJS = $(LIB_SRCS:lib/%.c=$(FW)/lib/%.o)

CHECKS += check-fw-gateway
.PHONY: check-fw-gateway

$(FW)/capture.bin: tests/fw/make_capture.py tests/ref/urrt_ref.py
	@mkdir -p $(@D)
	$(PYTHON) tests/fw/make_capture.py $@

# The manager's frames, for --replay-rx (rx.log) and the image (rx.c): one script writes both.
$(FW)/%/rx.log $(FW)/%/rx.c: tests/fw/master_frames.py
	@mkdir -p $(@D)
	$(PYTHON) tests/fw/master_frames.py $(FW)/$*/rx.log $(FW)/$*/rx.c

$(FW)/%/rx.o: $(FW)/%/rx.c tests/fw/fw_rx.h
	$(TGT_CM) $(TGT_M4) -Os $(TGT_LIB_FLAGS) -Itests/fw -c $< -o $@

# The example configuration with its CAN frames logged to a file.
$(FW)/%/gateway.ini: docs/examples/%.ini
	@mkdir -p $(@D)
	sed 's|^interface = .*|interface = log:$(@D)/gateway.log|' $< > $@
	@grep -q '^interface = log:' $@ || { echo "$@: no interface line in $<"; exit 1; }

$(FW)/%/tables.c: $(FW)/%/gateway.ini $(BUILD)/bin/urrt-gateway
	$(BUILD)/bin/urrt-gateway --print-c-tables -o $@ $<

$(FW)/lib/%.o: lib/%.c $(LIB_HDRS)
	@mkdir -p $(@D)
	$(TGT_CM) $(TGT_M4) -Os $(TGT_LIB_FLAGS) -c $< -o $@

# The generated tables under lib/'s own warnings.
$(FW)/%/tables.o: $(FW)/%/tables.c $(LIB_HDRS)
	$(TGT_CM) $(TGT_M4) -Os $(TGT_LIB_FLAGS) -Ilib -c $< -o $@

# Kept between runs (make deletes what pattern rules make along the way).
.PRECIOUS: $(FW)/%/gateway.ini $(FW)/%/tables.c $(FW)/%/tables.o $(FW)/lib/%.o $(FW)/%/rx.log $(FW)/%/rx.c \
  $(FW)/%/rx.o

.SECONDEXPANSION:
$(FW)/%/fw_gateway.elf: tests/fw/fw_gateway.c tests/fw/fw_rx.h tests/target/cm.c tests/target/target.h \
  tests/target/an386.ld $(FW)/%/tables.o $$(if $$(filter $$*,$$(FW_CANOPEN)),$(FW)/%/rx.o $(FW)/%/rx.log) \
  $$(FW_LIB_OBJS)
	$(TGT_CM) $(TGT_M4) -Os $(TGT_FLAGS) -DURRT_TARGET_CORTEX_M $(if $(filter $*,$(FW_CANOPEN)),-DFW_CANOPEN) \
	  -Itests/fw tests/target/cm.c tests/fw/fw_gateway.c $(FW)/$*/tables.o \
	  $(if $(filter $*,$(FW_CANOPEN)),$(FW)/$*/rx.o) $(FW_LIB_OBJS) -T tests/target/an386.ld $(TGT_LINK) -o $@

check-fw-gateway: $(foreach c,$(FW_CONFIGS),$(FW)/$(c)/fw_gateway.elf $(FW)/$(c)/gateway.ini) $(FW)/capture.bin \
  tests/fw/run.sh tests/fw/compare.sh
	$(call suite,check-fw-gateway,sh tests/fw/run.sh $(BUILD) $(FW) $(FW_CONFIGS))
