# gateway/gateway.mk: urrt-gateway, its LCM types (C for the gateway, a jar
# for lcm-spy), the urrt-spy launcher, the systemd unit and `make demo`.

LCM_JAR ?= /usr/share/java/lcm.jar
JCHART2D_JAR ?= /usr/share/java/jchart2d.jar
DEMO_SECONDS ?= 0
DEMO_PORT ?= 30003
DEMO_LCM_URL ?= udpm://239.255.76.67:7667?ttl=0

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

# ---- urrt-gateway ------------------------------------------------------------------
GATEWAY_OBJS := $(addprefix $(BUILD)/gateway/,urrt-gateway.o gateway.o freshness.o config.o lcm_out.o) \
                $(BUILD)/gateway/cli.o $(LCMTYPES_OBJS)
# Other fragments append their objects (the CAN output, say); read at link time.
GATEWAY_EXTRA_OBJS ?=
GATEWAY_HDRS := gateway/config.h gateway/gateway.h gateway/freshness.h gateway/lcm_out.h gateway/cli.h gateway/can_map.h gateway/can_out.h gateway/dbc.h port/port.h $(LIB_HDRS)
GATEWAY_LIBS := -llcm -linih -lm

$(addprefix $(BUILD)/gateway/,urrt-gateway.o gateway.o freshness.o config.o lcm_out.o): \
  $(BUILD)/gateway/%.o: gateway/%.c $(GATEWAY_HDRS) $(LCMTYPES_H)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(CPPFLAGS) -Igateway -I$(LCMGEN) -c $< -o $@

# $(BUILD)/gateway/cli.o (the programs' shared helpers) is built by tools.mk.

.SECONDEXPANSION:
$(BUILD)/bin/urrt-gateway: $(GATEWAY_OBJS) $$(GATEWAY_EXTRA_OBJS) $(LIBPORT) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(OPT) -o $@ $(GATEWAY_OBJS) $(GATEWAY_EXTRA_OBJS) $(LIBPORT) $(LIBURRT) $(GATEWAY_LIBS)

PROGRAMS += $(BUILD)/bin/urrt-gateway
all: $(LCMTYPES_JAR)

# ---- lcm-spy ---------------------------------------------------------------------------
# Runs lcm-spy with the urrt types: `make spy` (LCM_URL=... to watch another URL).
.PHONY: spy
spy: $(LCMTYPES_JAR)
	URRT_LCMTYPES_JAR=$(LCMTYPES_JAR) gateway/urrt-spy $(if $(LCM_URL),--lcm-url='$(LCM_URL)')

# ---- install: gateway/install.mk ------------------------------------------------------

# ---- make demo ---------------------------------------------------------------------------
# urrt-sim (e-series 5.10 layout) at 500 Hz on 127.0.0.1:$(DEMO_PORT) and urrt-gateway publishing on
# $(DEMO_LCM_URL), one summary line per second, until Ctrl-C or DEMO_SECONDS.
demo: deps all
	@set -u; dir=$$(mktemp -d); sim=; gw=; \
	stop() { trap - EXIT INT TERM; \
	  for p in $$gw $$sim; do kill $$p 2>/dev/null; done; wait 2>/dev/null; rm -rf "$$dir"; }; \
	trap stop EXIT; trap 'stop; exit 0' INT TERM; \
	printf '[gateway]\nsummary = yes\n\n[lcm]\nurl = %s\n\n[robot arm1]\nhost = 127.0.0.1\nport = %s\n' \
	  '$(DEMO_LCM_URL)' '$(DEMO_PORT)' > "$$dir/demo.ini"; \
	echo "demo: urrt-sim at 500 Hz on 127.0.0.1:$(DEMO_PORT), urrt-gateway on $(DEMO_LCM_URL)"; \
	echo "demo: watch it with 'make spy' in another terminal; Ctrl-C stops$(if $(filter-out 0,$(DEMO_SECONDS)), (or after $(DEMO_SECONDS) s))"; \
	$(BUILD)/bin/urrt-sim --listen 127.0.0.1:$(DEMO_PORT) --version 5.10 --rate 500 & sim=$$!; \
	$(BUILD)/bin/urrt-gateway --summary "$$dir/demo.ini" & gw=$$!; \
	if [ '$(DEMO_SECONDS)' != 0 ]; then sleep '$(DEMO_SECONDS)'; else wait $$gw; fi
