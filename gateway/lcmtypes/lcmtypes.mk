# SPDX-License-Identifier: MIT
# gateway/lcmtypes/lcmtypes.mk: the LCM message types, as C for the gateway and
# the tests, and as a jar for lcm-spy (make spy, urrt-spy).

LCM_JAR ?= /usr/share/java/lcm.jar
JCHART2D_JAR ?= /usr/share/java/jchart2d.jar

# ---- LCM types ------------------------------------------------------------------
LCMTYPES := $(sort $(wildcard gateway/lcmtypes/*.lcm))
LCMGEN := $(BUILD)/lcmgen
LCMTYPES_C := $(LCMTYPES:gateway/lcmtypes/%.lcm=$(LCMGEN)/urrt_%.c)
LCMTYPES_H := $(LCMTYPES_C:.c=.h)
LCMTYPES_OBJS := $(LCMTYPES_C:$(LCMGEN)/%.c=$(BUILD)/gateway/lcmtypes/%.o)
LCMTYPES_JAR := $(BUILD)/urrt_lcmtypes.jar

# One lcm-gen run writes both files of a type.
$(LCMGEN)/urrt_%.c $(LCMGEN)/urrt_%.h: gateway/lcmtypes/%.lcm
	@mkdir -p $(LCMGEN)
	lcm-gen -c --c-cpath $(LCMGEN) --c-hpath $(LCMGEN) $<

# Generated code is not ours to clean up: its own warnings are not errors.
$(LCMTYPES_OBJS): $(BUILD)/gateway/lcmtypes/%.o: $(LCMGEN)/%.c $(LCMTYPES_H)
	@mkdir -p $(@D)
	$(CC) -std=gnu11 $(OPT) -Wall -Wno-unused-parameter -I$(LCMGEN) -c $< -o $@

$(LCMTYPES_JAR): $(LCMTYPES)
	rm -rf $(BUILD)/lcmjava
	mkdir -p $(BUILD)/lcmjava/src $(BUILD)/lcmjava/classes
	lcm-gen -j --jpath $(BUILD)/lcmjava/src $(LCMTYPES)
	javac -nowarn -encoding UTF-8 -cp $(LCM_JAR) -d $(BUILD)/lcmjava/classes $(BUILD)/lcmjava/src/urrt/*.java
	jar cf $@ -C $(BUILD)/lcmjava/classes .

all: $(LCMTYPES_JAR)
