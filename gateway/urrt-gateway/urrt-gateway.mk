# SPDX-License-Identifier: MIT
# gateway/urrt-gateway/urrt-gateway.mk: urrt-gateway itself (its loop, the
# freshness estimator, the configuration file, its two outputs, LCM and CAN;
# the CAN mapping and tables are gateway/can/), `make spy` and `make demo`.

# The demo cannot be mistaken for production: its own robot name, its own LCM
# group and port (the default is 239.255.76.67:7667), ttl=0 (this host only), and
# the simulator on a free port unless DEMO_PORT says otherwise.
DEMO_SECONDS ?= 0
DEMO_PORT ?= 0
DEMO_ROBOT ?= demo
DEMO_LCM_URL ?= udpm://239.255.76.68:7668?ttl=0

# ---- urrt-gateway ------------------------------------------------------------------
GATEWAY_OBJS := $(addprefix $(BUILD)/gateway/urrt-gateway/,urrt-gateway.o gateway.o freshness.o config.o lcm_out.o \
                  can_out.o plc_in.o notify.o metrics.o)
# Other folders append their objects (the CAN side); read at link time.
GATEWAY_EXTRA_OBJS ?=
GATEWAY_LIBS := -llcm -lm

# The LCM types' headers are generated: they exist before anything includes them.
$(BUILD)/gateway/urrt-gateway/%.o: gateway/urrt-gateway/%.c | $(LCMTYPES_H)
	@mkdir -p $(@D)
	$(CC) $(GW_CFLAGS) -I$(LCMGEN) -c $< -o $@

-include $(GATEWAY_OBJS:.o=.d)

.SECONDEXPANSION:
$(BUILD)/bin/urrt-gateway: $(GATEWAY_OBJS) $(CLI_OBJ) $(RTDE_SOURCE_OBJ) $(RTDE_CAPTURE_OBJ) $(LCMTYPES_OBJS) $$(GATEWAY_EXTRA_OBJS) $(LIBPORT) \
                           $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(OPT) -o $@ $(GATEWAY_OBJS) $(CLI_OBJ) $(RTDE_SOURCE_OBJ) $(RTDE_CAPTURE_OBJ) $(LCMTYPES_OBJS) $(GATEWAY_EXTRA_OBJS) $(LIBPORT) $(LIBURRT) \
	  $(GATEWAY_LIBS)

PROGRAMS += $(BUILD)/bin/urrt-gateway

# ---- lcm-spy ---------------------------------------------------------------------------
# Runs lcm-spy with the urrt types on the demo's URL: `make spy` (DEMO_LCM_URL=...
# as given to `make demo`, or LCM_URL=... to watch another URL).
.PHONY: spy
spy: deps-spy $(LCMTYPES_JAR)
	URRT_LCMTYPES_JAR=$(LCMTYPES_JAR) gateway/install/urrt-spy --lcm-url='$(or $(LCM_URL),$(DEMO_LCM_URL))'

# ---- install: gateway/install/install.mk ----------------------------------------------

# ---- make demo ---------------------------------------------------------------------------
# urrt-sim (e-series 5.10 layout, 500 Hz) on 127.0.0.1, and once it listens urrt-gateway
# publishing robot $(DEMO_ROBOT) on $(DEMO_LCM_URL), one summary line per second, until
# Ctrl-C or DEMO_SECONDS. A simulator that cannot start stops the demo (exit 1).
demo: deps-build all
	@set -u; dir=$$(mktemp -d); sim=; gw=; timer=; tipped=; \
	stop() { trap - EXIT INT TERM; \
	  for p in $$timer $$gw $$sim; do kill $$p 2>/dev/null; done; wait 2>/dev/null; rm -rf "$$dir"; }; \
	tip() { [ -n "$$tipped" ] && return; tipped=1; \
	  echo "demo: stopped. To watch the next one: make demo in one terminal, make spy in another" \
	    "(both take DEMO_LCM_URL; channels $(DEMO_ROBOT).STATE, .JOINTS, .TOOL, .STATUS, .GATEWAY)"; }; \
	trap stop EXIT; trap 'stop; tip; exit 0' INT TERM; \
	$(BUILD)/bin/urrt-sim --listen 127.0.0.1:$(DEMO_PORT) --port-file "$$dir/port" --controller 5.10 --rate 500 & \
	sim=$$!; \
	while [ ! -s "$$dir/port" ]; do \
	  if ! kill -0 $$sim 2>/dev/null; then \
	    echo "demo: urrt-sim could not listen on 127.0.0.1:$(DEMO_PORT) (see above): choose another port with" \
	      "make demo DEMO_PORT=N, or DEMO_PORT=0 for any free one" >&2; exit 1; fi; \
	  sleep 0.05; \
	done; \
	port=$$(cat "$$dir/port"); \
	printf '[gateway]\nsummary = yes\n\n[lcm]\nurl = %s\n\n[robot %s]\nhost = 127.0.0.1\nport = %s\n' \
	  '$(DEMO_LCM_URL)' '$(DEMO_ROBOT)' "$$port" > "$$dir/demo.ini"; \
	echo "demo: urrt-sim (5.10, 500 Hz) on 127.0.0.1:$$port -> urrt-gateway -> robot $(DEMO_ROBOT) on $(DEMO_LCM_URL)"; \
	$(BUILD)/bin/urrt-gateway "$$dir/demo.ini" & gw=$$!; \
	if [ '$(DEMO_SECONDS)' != 0 ]; then (sleep '$(DEMO_SECONDS)'; kill $$gw 2>/dev/null) & timer=$$!; fi; \
	echo "demo: watch it in another terminal: make spy$(if $(filter-out $(origin DEMO_LCM_URL),file), DEMO_LCM_URL='$(DEMO_LCM_URL)')" \
	  "(lcm-spy on $(DEMO_LCM_URL)), or $(BUILD)/bin/urrt-dump -n 1 127.0.0.1:$$port (the raw stream)"; \
	echo "demo: runs until Ctrl-C$(if $(filter-out 0,$(DEMO_SECONDS)), (or $(DEMO_SECONDS) s), (make demo DEMO_SECONDS=10 stops after 10 s))"; \
	wait $$gw; rc=$$?; gw=; \
	tip; exit $$rc
