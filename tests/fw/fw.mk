# SPDX-License-Identifier: MIT
# tests/fw/fw.mk: a firmware gateway built from lib/ alone against urrt-gateway.
#   check-fw-gateway  the same capture (tests/fw/make_capture.py: 500 packets with a stall,
#                     clamped and NaN values, garbage between packets) through
#                     (a) urrt-gateway --replay with the configuration, interface = log:PATH
#                     (b) tests/fw/fw_gateway.c with lib/ and the tables urrt-gateway --print-c-tables
#                         wrote for the same file, bare metal on qemu's Cortex-M4 (mps2-an386), no C
#                         library, the capture read through semihosting in 1460-byte chunks
#                     both clocked by the packets' controller time: the frames (id, flags, payload,
#                     order) must be identical. For canopen.ini (classic, a CANopen node: the
#                     image runs lib/urrt_co too, built with -DFW_CANOPEN, no manager), fd.ini
#                     (CAN FD), j1939.ini (29-bit ids) and canopen-vm: tests/canopen/canopen.ini
#                     fed what make check-canopen's VM run recorded, the robot's stream
#                     (tests/fw/vm-capture.bin.xz) and the frames tests/canopen/master.py sent on
#                     its clock (tests/fw/vm-master.log: NMT, SYNC, SDO; via --replay-rx and the
#                     image's receive table), whose SDO answers must be the live node's
#                     (tests/fw/vm-node.log); prints the canopen image's footprint.
#                     RTDE (-DFW_RTDE: lib/urrt_rtde's client with the generated recipe):
#                     rtde-plc (docs/examples/rtde-plc.ini, a CANopen node) and rtde-types
#                     (tests/fw/rtde-types.ini, plain CAN, every wire type), fed an RTDE capture
#                     (tests/fw/make_rtde_capture.py) through urrt-gateway --replay, and the image
#                     the bytes tests/fw/rtde_controller.py plays as the controller of that capture
#                     to the recipe the tables carry; its requests are checked too (V, v, O, S only,
#                     the recipe's names); prints the rtde-plc image's footprint.
#                     The PLC's answers (-DFW_INPUTS: lib/urrt_plcin over the node's RPDOs, lib/urrt_rtde_in's
#                     input recipes): plc-inputs (tests/fw/plc-inputs.ini, two [input]s as RPDO1 and RPDO2)
#                     fed tests/fw/make_rx_inputs.py's manager (RPDOs, refused values, silences, an SDO
#                     write, NMT stop and start, an RPDO switched off and on): the input packages the
#                     image sends its scripted controller must be, byte for byte and in order, those
#                     urrt-gateway --replay --replay-inputs writes; its requests V, v, O, I, I, S, U...
#   record-fw-master  make check-canopen, then that recording from its run (tests/fw/record_master.py)
# The rules use target.mk's toolchain variables in recipes only (it is included after this file).

FW := $(BUILD)/tests/fw
FW_CONFIGS := canopen canopen-vm fd j1939 rtde-plc rtde-types plc-inputs
FW_CANOPEN := canopen canopen-vm rtde-plc plc-inputs
FW_RTDE := rtde-plc rtde-types plc-inputs
FW_INPUTS := plc-inputs
FW_LIB_OBJS = $(LIB_SRCS:lib/%.c=$(FW)/lib/%.o)

CHECKS += check-fw-gateway
.PHONY: check-fw-gateway record-fw-master

$(FW)/capture.bin: tests/fw/make_capture.py tests/ref/urrt_ref.py
	@mkdir -p $(@D)
	$(PYTHON) tests/fw/make_capture.py $@

$(FW)/rtde-capture.bin: tests/fw/make_rtde_capture.py tests/ref/rtde_ref.py
	@mkdir -p $(@D)
	$(PYTHON) tests/fw/make_rtde_capture.py $@

# What the scripted controller of that capture sends the image, which asks for the tables' recipe.
$(FW)/%/controller.bin: $(FW)/rtde-capture.bin $(FW)/%/tables.c tests/fw/rtde_controller.py tests/ref/rtde_ref.py
	$(PYTHON) tests/fw/rtde_controller.py stream $< $(FW)/$*/tables.c $@

# The manager's frames, for --replay-rx (rx.log) and the image (rx.c): canopen-vm's were
# recorded; a node with no manager gets none.
$(FW)/canopen-vm/rx.log: tests/fw/vm-master.log
	@mkdir -p $(@D)
	cp $< $@
$(FW)/plc-inputs/rx.log: tests/fw/make_rx_inputs.py
	@mkdir -p $(@D)
	$(PYTHON) $< $@
$(FW)/%/rx.log:
	@mkdir -p $(@D)
	: > $@
$(FW)/%/rx.c: $(FW)/%/rx.log tests/fw/rx_table.py
	$(PYTHON) tests/fw/rx_table.py $< $@

$(FW)/canopen-vm/capture.bin: tests/fw/vm-capture.bin.xz
	@mkdir -p $(@D)
	xz -dc $< > $@
# The live node's SDO answers, which the replay's must equal.
$(FW)/canopen-vm/node.log: tests/fw/vm-node.log
	@mkdir -p $(@D)
	cp $< $@

$(FW)/%/rx.o: $(FW)/%/rx.c tests/fw/fw_rx.h
	$(TGT_CM) $(TGT_M4) -Os $(TGT_LIB_FLAGS) -Itests/fw -c $< -o $@

# The configuration with its CAN frames logged to a file: an example, or check-canopen's.
define fw_log_ini
	@mkdir -p $(@D)
	sed 's|^interface = .*|interface = log:$(@D)/gateway.log|' $< > $@
	@grep -q '^interface = log:' $@ || { echo "$@: no interface line in $<"; exit 1; }
endef
$(FW)/%/gateway.ini: docs/examples/%.ini
	$(fw_log_ini)
$(FW)/canopen-vm/gateway.ini: tests/canopen/canopen.ini
	$(fw_log_ini)
$(FW)/rtde-types/gateway.ini: tests/fw/rtde-types.ini
	$(fw_log_ini)
$(FW)/plc-inputs/gateway.ini: tests/fw/plc-inputs.ini
	$(fw_log_ini)

$(FW)/%/tables.c: $(FW)/%/gateway.ini $(BUILD)/bin/urrt-gateway
	$(BUILD)/bin/urrt-gateway --print-c-tables -o $@ $<

# rtde-port: rtde-types' tables with the robot's port made RealTime's (30003), which the
# configuration check refuses and so only an edit makes: the image must refuse it, sending nothing.
$(FW)/rtde-port/tables.c: $(FW)/rtde-types/tables.c
	@mkdir -p $(@D)
	sed 's/^\(const uint16_t urrt_gateway_rtde_port\[1\] = {\)30004};/\130003};/' $< > $@
	@grep -q '^const uint16_t urrt_gateway_rtde_port\[1\] = {30003};' $@ || \
	  { echo "$@: $< has no port table of one robot on 30004 to change"; exit 1; }

$(FW)/lib/%.o: lib/%.c $(LIB_HDRS)
	@mkdir -p $(@D)
	$(TGT_CM) $(TGT_M4) -Os $(TGT_LIB_FLAGS) -c $< -o $@

# The generated tables under lib/'s own warnings.
$(FW)/%/tables.o: $(FW)/%/tables.c $(LIB_HDRS)
	$(TGT_CM) $(TGT_M4) -Os $(TGT_LIB_FLAGS) -Ilib -c $< -o $@

# Kept between runs (make deletes what pattern rules make along the way).
.PRECIOUS: $(FW)/%/gateway.ini $(FW)/%/tables.c $(FW)/%/tables.o $(FW)/lib/%.o $(FW)/%/rx.log $(FW)/%/rx.c \
  $(FW)/%/rx.o $(FW)/%/controller.bin

.SECONDEXPANSION:
$(FW)/%/fw_gateway.elf: tests/fw/fw_gateway.c tests/fw/fw_rx.h tests/target/cm.c tests/target/target.h \
  tests/target/an386.ld $(FW)/%/tables.o $$(if $$(filter $$*,$$(FW_CANOPEN)),$(FW)/%/rx.o $(FW)/%/rx.log) \
  $$(FW_LIB_OBJS)
	$(TGT_CM) $(TGT_M4) -Os $(TGT_FLAGS) -DURRT_TARGET_CORTEX_M $(if $(filter $*,$(FW_CANOPEN)),-DFW_CANOPEN) \
	  $(if $(filter $*,$(FW_RTDE) rtde-port),-DFW_RTDE) $(if $(filter $*,$(FW_INPUTS)),-DFW_INPUTS) \
	  -Itests/fw tests/target/cm.c tests/fw/fw_gateway.c $(FW)/$*/tables.o \
	  $(if $(filter $*,$(FW_CANOPEN)),$(FW)/$*/rx.o) $(FW_LIB_OBJS) -T tests/target/an386.ld $(TGT_LINK) -o $@

check-fw-gateway: $(foreach c,$(FW_CONFIGS) rtde-port,$(FW)/$(c)/fw_gateway.elf) \
  $(foreach c,$(FW_CONFIGS),$(FW)/$(c)/gateway.ini) $(FW)/capture.bin \
  $(FW)/canopen-vm/capture.bin $(FW)/canopen-vm/node.log $(foreach c,$(FW_RTDE),$(FW)/$(c)/controller.bin) \
  $(FW)/rtde-capture.bin tests/fw/run.sh tests/fw/compare.sh tests/fw/rtde_controller.py
	$(call suite,check-fw-gateway,sh tests/fw/run.sh $(BUILD) $(FW) $(FW_CONFIGS))

# Writes tests/fw/vm-capture.bin.xz, vm-master.log and vm-node.log from a passing check-canopen run.
record-fw-master: check-canopen
	$(PYTHON) tests/fw/record_master.py $(BUILD)/vm/check-canopen/out tests/fw
