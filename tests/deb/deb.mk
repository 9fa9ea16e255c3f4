# SPDX-License-Identifier: MIT
# tests/deb/deb.mk: check-deb builds the Debian package (make deb), runs lintian,
# installs it with dpkg into a scratch root, runs the programs from there and
# removes it again (tests/deb/check_deb.sh).
.PHONY: check-deb
check-deb:
	$(call suite,$@,BUILD=$(BUILD) MAKE="$(MAKE)" timeout -k 5 600 sh tests/deb/check_deb.sh)

CHECKS += check-deb
