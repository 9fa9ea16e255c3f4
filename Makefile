# urrt: plain make. `make demo` runs the gateway against the simulator,
# `make check` runs every test. Each directory adds its own rules in *.mk.
PREFIX ?= /usr/local
BINDIR ?= $(PREFIX)/bin
DESTDIR ?=
BUILD ?= build

CC ?= cc
# What the README recommends for an edge box.
OPT ?= -O2 -g
# lib/ is held to the strictest warnings; programs and tests to a little less.
LIB_WARN := -std=c99 -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion \
            -Wcast-align -Wundef -Wshadow -Werror
PROG_WARN := -std=gnu11 -Wall -Wextra -Wshadow -Werror
CPPFLAGS += -Ilib -Iport
SAN_FLAGS := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer

PYTHON := /usr/bin/python3

# Debian packages the build and the tests use (Debian 12 names).
DEB_DEPS := gcc make python3 gcc-arm-none-eabi binutils-arm-none-eabi clang libclang-rt-14-dev \
            liblcm-dev liblcm-bin liblcm-java libjchart2d-java default-jdk-headless \
            libinih-dev pkg-config can-utils python3-can python3-canmatrix \
            qemu-system-x86 busybox-static cpio valgrind iproute2 gnuplot-nox
# Installed with --no-install-recommends (fragments add theirs with +=).
DEB_DEPS_NO_RECOMMENDS :=

PROGRAMS :=
CHECKS :=
BENCHES :=

.PHONY: all check check-suites bench fuzz clean install deps demo
all:

include lib/lib.mk
include port/port.mk
include $(sort $(wildcard gateway/*.mk))
include $(sort $(wildcard tests/*.mk))

all: $(PROGRAMS)

# Installs what is missing when root; otherwise prints the one command to run.
# DEB_DEPS_NO_RECOMMENDS (cross toolchains, emulators) are installed without
# their recommends, which would add hundreds of megabytes (qemu's firmware)
# the tests do not use. Each package is named once.
deps_missing = $$(for p in $(1); do \
    dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed' || echo $$p; \
  done)
deps:
	@missing=$(call deps_missing,$(sort $(DEB_DEPS))); \
	missing_nr=$(call deps_missing,$(filter-out $(DEB_DEPS),$(sort $(DEB_DEPS_NO_RECOMMENDS)))); \
	install=""; \
	[ -z "$$missing" ] || install="sudo apt-get install -y $$(echo $$missing)"; \
	[ -z "$$missing_nr" ] || \
	  install="$${install:+$$install && }sudo apt-get install -y --no-install-recommends $$(echo $$missing_nr)"; \
	if [ -n "$$install" ]; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "deps: installing:" $$missing $$missing_nr; \
	    apt-get update -qq || exit 1; \
	    [ -z "$$missing" ] || DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null || exit 1; \
	    [ -z "$$missing_nr" ] || DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
	      $$missing_nr >/dev/null || exit 1; \
	  else \
	    echo "deps: missing Debian packages. Run, then make again:"; \
	    echo "  $$install"; exit 1; \
	  fi; \
	fi

# Every suite runs even when one fails; the summary adds them up.
check: deps
	@rm -rf $(BUILD)/results; mkdir -p $(BUILD)/results
	@$(MAKE) --no-print-directory -k check-suites; rc=$$?; \
	  sh tests/summary.sh $(BUILD)/results $(CHECKS); s=$$?; \
	  [ $$rc = 0 ] && [ $$s = 0 ]

check-suites: $(CHECKS)

bench: deps $(BENCHES)

install: all
	install -d $(DESTDIR)$(BINDIR)
	install -m 0755 $(PROGRAMS) $(DESTDIR)$(BINDIR)/

clean:
	rm -rf $(BUILD)
