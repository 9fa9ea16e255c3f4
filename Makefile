# SPDX-License-Identifier: MIT
# urrt: plain make. `make demo` runs the gateway against the simulator,
# `make check` runs every test. Each directory adds its own rules in *.mk.
PREFIX ?= /usr/local
BINDIR ?= $(PREFIX)/bin
DESTDIR ?=
BUILD ?= build

CC ?= cc
# Default build flags; docs/performance.md measures them beside -march=native.
OPT ?= -O2 -g
# lib/ is held to the strictest warnings; programs and tests to a little less.
LIB_WARN := -std=c99 -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion \
            -Wcast-align -Wundef -Wshadow -Werror
PROG_WARN := -std=gnu11 -Wall -Wextra -Wshadow -Werror
CPPFLAGS += -Ilib -Iport
SAN_FLAGS := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer

PYTHON := /usr/bin/python3

# Debian packages (Debian 12 names) in three tiers, each package named once
# (check-ship lists the union and finds no duplicate):
# 1. `make` and `make demo`: compiler, LCM (C, lcm-gen, Java), a JDK for the types jar.
DEPS_BUILD := gcc libc6-dev make pkg-config liblcm-dev liblcm-bin liblcm-java default-jdk-headless
# 2. `make spy`: a Java runtime with GUI libraries, and jchart2d for lcm-spy's charts.
DEPS_SPY := default-jre libjchart2d-java
# 3. `make check`: everything else. Fragments add theirs with DEB_DEPS += ...
DEB_DEPS := python3 clang libclang-rt-14-dev python3-canmatrix valgrind gnuplot-nox man-db systemd \
            debhelper lintian
# Installed with --no-install-recommends (fragments add theirs with +=): the ARM
# cross compiler recommends newlib (about 390 MB), which lib/'s freestanding
# builds never use.
DEB_DEPS_NO_RECOMMENDS := gcc-arm-none-eabi binutils-arm-none-eabi

PROGRAMS :=
CHECKS :=
BENCHES :=

.PHONY: all check check-suites bench fuzz clean install uninstall deps deps-build deps-spy deps-list demo
all:

# $(call suite,NAME,COMMAND): the one way a suite runs. COMMAND's output is
# shown as it comes and kept in $(BUILD)/results/NAME.log; the last
# "N passed, N failed" line it printed is the suite's result
# (NAME.result, which tests/summary.sh adds up). The suite passes when
# COMMAND exits 0 and that line says 0 failed: a suite that printed no such
# line has not run, whatever its exit status.
define suite
	@mkdir -p $(BUILD)/results
	@rm -f $(BUILD)/results/$(1).result; \
	  { $(2); echo $$? > $(BUILD)/results/$(1).rc; } 2>&1 | tee $(BUILD)/results/$(1).log; \
	  rc=$$(cat $(BUILD)/results/$(1).rc); \
	  grep -E '^[0-9]+ passed, [0-9]+ failed' $(BUILD)/results/$(1).log | tail -n 1 > $(BUILD)/results/$(1).result; \
	  grep -qE '^[0-9]+ passed, 0 failed' $(BUILD)/results/$(1).result || rc=1; exit $$rc
endef

include lib/lib.mk
include port/port.mk
# gateway/: the definitions other folders use at parse time first (the flags every
# folder compiles with, the LCM types), then each folder's .mk.
GATEWAY_MK_FIRST := gateway/common/common.mk gateway/lcmtypes/lcmtypes.mk
include $(GATEWAY_MK_FIRST)
include $(filter-out $(GATEWAY_MK_FIRST),$(sort $(wildcard gateway/*/*.mk)))
# tests/: one folder per layer (lib, port, gateway/...) and per whole-system
# check (cross, target, vm, fw, ...), each with the .mk of its suites, in
# sorted order (tests/lib/ before tests/target/, whose prerequisites use it).
include $(sort $(wildcard tests/*.mk tests/*/*.mk tests/*/*/*.mk))

all: $(PROGRAMS)

# deps-build, deps-spy and deps (everything `make check` needs) install what
# is missing when root; otherwise they print the one command to run and stop.
# DEB_DEPS_NO_RECOMMENDS (cross toolchains, emulators) are installed without
# their recommends, which would add hundreds of megabytes the tests do not use.
deps_missing = $$(for p in $(1); do \
    dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed' || echo $$p; \
  done)
# $(call deps_install,PACKAGES,PACKAGES_WITHOUT_RECOMMENDS)
define deps_install
	@missing=$(call deps_missing,$(sort $(1))); \
	missing_nr=$(call deps_missing,$(filter-out $(1),$(sort $(2)))); \
	install=""; \
	[ -z "$$missing" ] || install="sudo apt-get install -y $$(echo $$missing)"; \
	[ -z "$$missing_nr" ] || \
	  install="$${install:+$$install && }sudo apt-get install -y --no-install-recommends $$(echo $$missing_nr)"; \
	if [ -n "$$install" ]; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "$@: installing:" $$missing $$missing_nr; \
	    apt-get update -qq || exit 1; \
	    [ -z "$$missing" ] || DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null || exit 1; \
	    [ -z "$$missing_nr" ] || DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
	      $$missing_nr >/dev/null || exit 1; \
	  else \
	    echo "$@: missing Debian packages. Run, then make again:"; \
	    echo "  $$install"; exit 1; \
	  fi; \
	fi
endef
deps-build:
	$(call deps_install,$(DEPS_BUILD))
deps-spy:
	$(call deps_install,$(DEPS_BUILD) $(DEPS_SPY))
deps:
	$(call deps_install,$(DEPS_BUILD) $(DEPS_SPY) $(DEB_DEPS),$(DEB_DEPS_NO_RECOMMENDS))
# Every name as given, one per line with its tier (check-ship looks for duplicates).
deps-list:
	@for p in $(DEPS_BUILD); do echo "build $$p"; done
	@for p in $(DEPS_SPY); do echo "spy $$p"; done
	@for p in $(DEB_DEPS); do echo "check $$p"; done
	@for p in $(DEB_DEPS_NO_RECOMMENDS); do echo "check-no-recommends $$p"; done

# Every suite runs even when one fails; the summary adds them up.
check: deps
	@rm -rf $(BUILD)/results; mkdir -p $(BUILD)/results
	@$(MAKE) --no-print-directory -k check-suites; rc=$$?; \
	  sh tests/summary.sh $(BUILD)/results $(CHECKS); s=$$?; \
	  [ $$rc = 0 ] && [ $$s = 0 ]

check-suites: $(CHECKS)

bench: deps $(BENCHES)

# What goes where: gateway/install/install.mk (and the fragments that hook into install: and uninstall:).
install: all

clean:
	rm -rf $(BUILD)
