# SPDX-License-Identifier: MIT
# tests/fw.mk: a firmware gateway built from lib/ alone against urrt-gateway.
#   check-fw-gateway  the same capture (tests/fw/make_capture.py: 500 packets with a stall,
#                     clamped and NaN values, garbage between packets) through
#                     (a) urrt-gateway --replay with docs/examples/canopen.ini and interface = log:PATH
#                     (b) tests/fw/fw_gateway.c with lib/ and the tables urrt-gateway --print-c-tables
#                         wrote for the same file, bare metal on qemu's Cortex-M4 (mps2-an386), no C
#                         library, the capture read through semihosting in 1460-byte chunks
#                     both clocked by the packets' controller time: the frames (id, flags, payload,
#                     order) must be identical. Prints the image's footprint.
# The rules use target.mk's toolchain variables in recipes only (it is included after this file).

FW := $(BUILD)/tests/fw
FW_CONFIG := docs/examples/canopen.ini
FW_LIB_OBJS = $(LIB_SRCS:lib/%.c=$(FW)/lib/%.o)

CHECKS += check-fw-gateway
.PHONY: check-fw-gateway

$(FW)/capture.bin: tests/fw/make_capture.py tests/ref/urrt_ref.py
	@mkdir -p $(@D)
	$(PYTHON) tests/fw/make_capture.py $@

# The example configuration with its CAN frames logged to a file.
$(FW)/gateway.ini: $(FW_CONFIG)
	@mkdir -p $(@D)
	sed 's|^interface = .*|interface = log:$(FW)/gateway.log|' $< > $@
	@grep -q '^interface = log:' $@ || { echo "$@: no interface line in $<"; exit 1; }

$(FW)/tables.c: $(FW)/gateway.ini $(BUILD)/bin/urrt-gateway
	$(BUILD)/bin/urrt-gateway --print-c-tables -o $@ $(FW)/gateway.ini

$(FW)/lib/%.o: lib/%.c $(LIB_HDRS)
	@mkdir -p $(@D)
	$(TGT_CM) $(TGT_M4) -Os $(TGT_LIB_FLAGS) -c $< -o $@

$(FW)/tables.o: $(FW)/tables.c $(LIB_HDRS)
	$(TGT_CM) $(TGT_M4) -Os $(TGT_LIB_FLAGS) -Ilib -c $< -o $@

$(FW)/fw_gateway.elf: tests/fw/fw_gateway.c tests/target/cm.c tests/target/target.h tests/target/an386.ld \
  $(FW)/tables.o $$(FW_LIB_OBJS)
	$(TGT_CM) $(TGT_M4) -Os $(TGT_FLAGS) -DURRT_TARGET_CORTEX_M tests/target/cm.c tests/fw/fw_gateway.c \
	  $(FW)/tables.o $(FW_LIB_OBJS) -T tests/target/an386.ld $(TGT_LINK) -o $@

check-fw-gateway: $(FW)/fw_gateway.elf $(FW)/capture.bin $(FW)/gateway.ini tests/fw/run.sh tests/fw/compare.sh
	$(call lib_suite,check-fw-gateway,sh tests/fw/run.sh $(BUILD) $(FW))
