# SPDX-License-Identifier: MIT
# tests/wireshark/wireshark.mk: the Wireshark dissector (gateway/wireshark/).
#   check-wireshark  tshark captures urrt-sim on loopback and dissects every packet with the
#                    generated $(BUILD)/urrt.lua; each must read as urrt-dump decodes it
#   check-wireshark-rtde  the same dissector on RTDE sessions (protocol 2 and 1, cut small,
#                    coalesced) of urrt-sim with urrt-dump --rtde and rtde_peer.py; every data
#                    package must read as the client decoded it
DEB_DEPS += tshark
CHECKS += check-wireshark check-wireshark-rtde
.PHONY: check-wireshark check-wireshark-rtde

check-wireshark: $(WS_LUA) $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
	$(call suite,$@,BUILD=$(BUILD) PYTHON=$(PYTHON) timeout -k 5 300 sh tests/wireshark/check.sh)

check-wireshark-rtde: $(WS_LUA) $(BUILD)/bin/urrt-sim $(BUILD)/bin/urrt-dump
	$(call suite,$@,BUILD=$(BUILD) PYTHON=$(PYTHON) timeout -k 5 300 sh tests/wireshark/check_rtde.sh)
