# SPDX-License-Identifier: MIT
# tests/stress/stress.mk: the flake gate (not part of make check).
#   check-stress   every suite with processes, sockets or time, RUNS times,
#                  half of them with the other core busy; prints a table of
#                  runs and failures per suite and per check
RUNS ?= 20
STRESS_SUITES ?= check-gateway check-notify check-metrics check-tools check-sim-rtde check-dump-rtde check-replay-rtde check-link check-can-log check-vm check-canopen check-wireshark-rtde check-plc-io
.PHONY: check-stress
check-stress: deps
	@sh tests/stress/stress.sh $(BUILD) $(RUNS) $(STRESS_SUITES)
