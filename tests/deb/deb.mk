# SPDX-License-Identifier: MIT
# tests/deb/deb.mk: check-deb builds the Debian package (make deb), runs lintian,
# installs it with dpkg into a scratch root, runs the programs from there and
# removes it again (tests/deb/check_deb.sh). LIB_SRCS: the sources of liburrt.a (lib/lib.mk), which
# the package's library and headers are held to.
.PHONY: check-deb
check-deb:
	$(call suite,$@,BUILD=$(BUILD) MAKE="$(MAKE)" CC="$(CC)" LIB_SRCS="$(LIB_HOST_SRCS)" \
	  timeout -k 5 600 sh tests/deb/check_deb.sh)

CHECKS += check-deb
