# SPDX-License-Identifier: MIT
# gateway/man/man.mk: the man pages, rendered from gateway/man/*.md by
# gateway/man/render.awk (awk only: no documentation toolchain to install).
# tests/man/man.mk checks that each page documents exactly its program's options.
MAN_SRCS := $(sort $(wildcard gateway/man/*.md))
MAN_PAGES := $(MAN_SRCS:gateway/man/%.md=$(BUILD)/man/%)
URRT_VERSION := $(shell sed -n 's/^\#define URRT_VERSION_STRING "\(.*\)"/\1/p' lib/urrt.h)
# Reproducible: dpkg-buildpackage sets SOURCE_DATE_EPOCH from the changelog.
MAN_DATE := $(shell date -u -d @$${SOURCE_DATE_EPOCH:-$$(date +%s)} +%Y-%m-%d)

$(BUILD)/man/%: gateway/man/%.md gateway/man/render.awk lib/urrt.h
	@mkdir -p $(@D)
	awk -v version='$(URRT_VERSION)' -v date='$(MAN_DATE)' -v source='$(<F)' -f gateway/man/render.awk $< > $@

.PHONY: man
man: $(MAN_PAGES)
all: $(MAN_PAGES)
