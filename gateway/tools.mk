# SPDX-License-Identifier: MIT
# gateway/tools.mk: urrt-sim and urrt-dump, and the modules they share with
# urrt-gateway. Other fragments link $(CLI_OBJ) (and $(SIM_MODEL_OBJ) to
# recompute what the simulator sent) without redefining their rules.
# conf.o: the value parsers every program's options and configuration share.
CONF_OBJ := $(BUILD)/gateway/conf.o
CLI_OBJ := $(BUILD)/gateway/cli.o $(CONF_OBJ)
SIM_MODEL_OBJ := $(BUILD)/gateway/sim_model.o
TOOLS_OBJS := $(CLI_OBJ) $(SIM_MODEL_OBJ) $(BUILD)/gateway/urrt-sim.o $(BUILD)/gateway/urrt-dump.o

$(TOOLS_OBJS): $(BUILD)/gateway/%.o: gateway/%.c gateway/cli.h gateway/conf.h gateway/sim_model.h port/port.h $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(CPPFLAGS) -Igateway -c $< -o $@

$(BUILD)/bin/urrt-sim: $(BUILD)/gateway/urrt-sim.o $(SIM_MODEL_OBJ) $(CLI_OBJ) $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(OPT) -o $@ $^ -lm

$(BUILD)/bin/urrt-dump: $(BUILD)/gateway/urrt-dump.o $(CLI_OBJ) $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(OPT) -o $@ $^ -lm

PROGRAMS += $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
.PHONY: tools
tools: $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
