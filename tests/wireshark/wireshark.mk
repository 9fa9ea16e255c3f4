# SPDX-License-Identifier: MIT
# tests/wireshark/wireshark.mk: the Wireshark dissector (gateway/wireshark/).
#   check-wireshark  tshark captures urrt-sim on loopback and dissects every packet with the
#                    generated $(BUILD)/urrt.lua; each must read as urrt-dump decodes it
DEB_DEPS += tshark
CHECKS += check-wireshark
.PHONY: check-wireshark

check-wireshark: $(WS_LUA) $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
	$(call suite,$@,BUILD=$(BUILD) PYTHON=$(PYTHON) timeout -k 5 300 sh tests/wireshark/check.sh)
