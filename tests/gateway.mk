# tests/gateway.mk: urrt-gateway against urrt-sim, through LCM.
#   check-gateway   values, decimation, two robots, restart/stall, mismatch,
#                   zero allocations, publish errors, bad configurations, jar
#   bench-gateway   latency sim -> subscriber, CPU per packet, highest rate
GWT := $(BUILD)/tests/gateway
GWT_CFLAGS := $(PROG_WARN) $(OPT) $(CPPFLAGS) -I$(LCMGEN)

CHECKS += check-gateway
BENCHES += bench-gateway
.PHONY: check-gateway bench-gateway

$(GWT)/lcm_sub: tests/gateway/lcm_sub.c $(LCMTYPES_OBJS) $(LCMTYPES_H) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(GWT_CFLAGS) -o $@ $< $(LCMTYPES_OBJS) $(LIBURRT) -llcm -lm

$(GWT)/alloc_shim.so: tests/gateway/alloc_shim.c
	@mkdir -p $(@D)
	$(CC) -std=gnu11 $(OPT) -Wall -Wextra -Werror -fPIC -shared -o $@ $< -ldl

$(GWT)/bench_gateway: tests/gateway/bench_gateway.c $(LCMTYPES_OBJS) $(LCMTYPES_H) $(LIBURRT)
	@mkdir -p $(@D)
	$(CC) $(GWT_CFLAGS) -o $@ $< $(LCMTYPES_OBJS) $(LIBURRT) -llcm -lm

check-gateway: $(BUILD)/bin/urrt-gateway $(BUILD)/bin/urrt-sim $(GWT)/lcm_sub $(GWT)/alloc_shim.so $(LCMTYPES_JAR)
	@mkdir -p $(BUILD)/results
	$(PYTHON) tests/gateway/test_gateway.py --build $(BUILD) --result $(BUILD)/results/check-gateway.result \
	  --port-base 41000

bench-gateway: $(BUILD)/bin/urrt-gateway $(GWT)/bench_gateway
	$(GWT)/bench_gateway --gateway $(BUILD)/bin/urrt-gateway --port 41500
