# SPDX-License-Identifier: MIT
# gateway/deb.mk: `make deb` builds the Debian package (debian/) from this
# tree into $(BUILD)/deb/. dpkg-buildpackage works on a copy, because it
# writes into debian/ and the parent directory; build directories stay out.
DEB_DIR := $(BUILD)/deb
DEB_WORK := $(BUILD)/deb-work
DEB_JOBS ?= $(shell nproc 2>/dev/null || echo 1)

.PHONY: deb
deb:
	rm -rf $(DEB_WORK) $(DEB_DIR)
	mkdir -p $(DEB_WORK)/urrt $(DEB_DIR)
	tar -c --exclude-vcs --exclude='./build' --exclude='./build-*' --exclude='./$(BUILD)' . | tar -x -C $(DEB_WORK)/urrt
	cd $(DEB_WORK)/urrt && DEB_BUILD_OPTIONS="parallel=$(DEB_JOBS) noddebs $(DEB_BUILD_OPTIONS)" \
	  dpkg-buildpackage -b -us -uc > ../build.log 2>&1 || { tail -n 30 ../build.log; exit 1; }
	mv $(DEB_WORK)/*.deb $(DEB_WORK)/*.changes $(DEB_WORK)/*.buildinfo $(DEB_WORK)/build.log $(DEB_DIR)/
	rm -rf $(DEB_WORK)
	@ls $(DEB_DIR)/*.deb
