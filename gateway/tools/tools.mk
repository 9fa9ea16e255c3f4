# SPDX-License-Identifier: MIT
# gateway/tools/tools.mk: the commissioning tools urrt-sim and urrt-dump, and
# the simulator's model of a moving arm (sim_model), which tests link to
# recompute what the simulator sent, and its RTDE server (sim_rtde).

SIM_MODEL_OBJ := $(BUILD)/gateway/tools/sim_model.o
SIM_RTDE_OBJ := $(BUILD)/gateway/tools/sim_rtde.o
TOOLS_OBJS := $(SIM_MODEL_OBJ) $(SIM_RTDE_OBJ) $(BUILD)/gateway/tools/urrt-sim.o $(BUILD)/gateway/tools/urrt-dump.o

$(BUILD)/gateway/tools/%.o: gateway/tools/%.c
	@mkdir -p $(@D)
	$(CC) $(GW_CFLAGS) -c $< -o $@

-include $(TOOLS_OBJS:.o=.d)

$(BUILD)/bin/urrt-sim: $(BUILD)/gateway/tools/urrt-sim.o $(SIM_MODEL_OBJ) $(SIM_RTDE_OBJ) $(RTDE_CAPTURE_OBJ) $(CLI_OBJ) $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(OPT) -o $@ $^ -lm

$(BUILD)/bin/urrt-dump: $(BUILD)/gateway/tools/urrt-dump.o $(CLI_OBJ) $(RTDE_SOURCE_OBJ) $(RTDE_CAPTURE_OBJ) $(RTDE_ONLY_OBJ) \
  $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(OPT) -o $@ $^ -lm

PROGRAMS += $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
.PHONY: tools
tools: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
