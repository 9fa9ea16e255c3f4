# SPDX-License-Identifier: MIT
# tests/ship/ship.mk: check-ship, what a new user meets first: the dependency tiers
# (no package named twice, `make demo` needs the first tier only, one apt-get
# line when not root), make demo (its own robot and LCM URL, a simulator that
# cannot listen stops it, nothing left running), the README's urrt-sim and
# urrt-dump lines run as the README shows them, urrt-spy's checks (and the jar
# found in the build tree), and the examples' invalid= sentinels before the
# first packet.
.PHONY: check-ship
check-ship: $(BUILD)/bin/urrt-gateway $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump $(LCMTYPES_JAR)
	$(call suite,$@,BUILD=$(BUILD) MAKE="$(MAKE)" PYTHON=$(PYTHON) timeout -k 5 120 sh tests/ship/check_ship.sh)

CHECKS += check-ship
