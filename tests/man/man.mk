# SPDX-License-Identifier: MIT
# tests/man/man.mk: check-man, the man pages against the programs' option tables.
.PHONY: check-man
check-man: $(MAN_PAGES) $(BUILD)/bin/urrt-gateway $(BUILD)/bin/urrt-dump $(BUILD)/bin/urrt-sim
	$(call suite,$@,$(PYTHON) tests/man/check_man.py $(BUILD))

CHECKS += check-man
