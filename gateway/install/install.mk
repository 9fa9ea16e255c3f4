# SPDX-License-Identifier: MIT
# gateway/install/install.mk: `make install` and `make uninstall` (PREFIX, DESTDIR and
# the directory variables below; debian/rules sets them for the package).
# INSTALL_ITEMS is the one list both rules read: uninstall removes exactly
# what install put there. Each entry is SOURCE:DIRECTORY:MODE, the file keeping
# its name; a file that needs another name or rewritten paths is made under
# $(DIST) first. Other fragments hook their own install-X/uninstall-X rules
# into install: and uninstall: (gateway/wireshark/wireshark.mk does).
SYSCONFDIR ?= /etc
UNITDIR ?= /lib/systemd/system
DATADIR ?= $(PREFIX)/share
JAVADIR ?= $(DATADIR)/java
DOCDIR ?= $(DATADIR)/doc/urrt
MANDIR ?= $(DATADIR)/man
INCLUDEDIR ?= $(PREFIX)/include
LIBDIR ?= $(PREFIX)/lib
PKGCONFIGDIR ?= $(LIBDIR)/pkgconfig
URRT_VERSION := $(shell sed -n 's/^\#define URRT_VERSION_STRING "\(.*\)"/\1/p' lib/urrt.h)
DIST := $(BUILD)/dist
# Java policy: a versioned jar and an unversioned link to it.
TYPES_JAR := urrt-lcmtypes-$(URRT_VERSION).jar

# The documents go into DOCDIR flat (docs/can.md is DOCDIR/can.md, docs/img/ is DOCDIR/img/), the
# paths the man pages name; the README's links into docs/ are rewritten to match ($(DIST)/README.md).
# Every relative link in the installed documents resolves: check-deb follows them all.
DOCS := $(sort $(wildcard docs/*.md))
DOC_IMAGES := $(sort $(wildcard docs/img/*))
EXAMPLES := $(sort $(wildcard docs/examples/*.ini))
DIST_FILES := $(DIST)/README.md $(DIST)/urrt-spy $(DIST)/urrt-gateway.service $(DIST)/urrt-gateway@.service $(DIST)/urrt.pc \
              $(DIST)/gateway.ini $(DIST)/$(TYPES_JAR)

# The library's headers: every header of lib/ (lib/lib.mk's LIB_HDRS: each module's, and the
# seams its sources include, such as urrt_co_internal.h), so that a module added to lib/ is
# installed whole (check-deb holds the package to the headers the library's objects are built from).
LIB_INSTALL_HDRS = $(LIB_HDRS)

INSTALL_ITEMS = $(foreach f,$(PROGRAMS) $(DIST)/urrt-spy,$(f):$(BINDIR):0755) \
  $(DIST)/$(TYPES_JAR):$(JAVADIR):0644 \
  $(DIST)/urrt-gateway.service:$(UNITDIR):0644 $(DIST)/urrt-gateway@.service:$(UNITDIR):0644 \
  gateway/install/urrt-gateway.example.ini:$(DATADIR)/urrt:0644 \
  $(foreach f,$(LCMTYPES),$(f):$(DATADIR)/urrt/lcmtypes:0644) \
  $(foreach f,$(MAN_PAGES),$(f):$(MANDIR)/man$(subst .,,$(suffix $(f))):0644) \
  $(foreach f,$(DIST)/README.md $(DOCS) LICENSE,$(f):$(DOCDIR):0644) \
  $(foreach f,$(DOC_IMAGES),$(f):$(DOCDIR)/img:0644) \
  $(foreach f,$(EXAMPLES),$(f):$(DOCDIR)/examples:0644) \
  $(foreach f,$(LIB_INSTALL_HDRS),$(f):$(INCLUDEDIR):0644) \
  $(LIBURRT):$(LIBDIR):0644 \
  $(DIST)/urrt.pc:$(PKGCONFIGDIR):0644
# Symbolic links: TARGET:LINK (TARGET relative to the link's directory).
INSTALL_LINKS = $(TYPES_JAR):$(JAVADIR)/urrt-lcmtypes.jar
# Directories of our own, removed by uninstall when empty (deepest first).
INSTALL_OWN_DIRS = $(DATADIR)/urrt/lcmtypes $(DATADIR)/urrt $(DOCDIR)/img $(DOCDIR)/examples $(DOCDIR) \
  $(SYSCONFDIR)/urrt
CONFIG_FILE = $(SYSCONFDIR)/urrt/gateway.ini

# The checked-in unit is right for PREFIX=/usr; other prefixes rewrite its paths.
$(DIST)/urrt-gateway.service: gateway/install/urrt-gateway.service
	@mkdir -p $(@D)
	sed -e 's|/usr/bin/urrt-gateway|$(BINDIR)/urrt-gateway|g; s|/etc/urrt/|$(SYSCONFDIR)/urrt/|g' $< > $@

# The template unit, urrt-gateway@NAME.service: one more gateway reading $(SYSCONFDIR)/urrt/NAME.ini
# (docs/gateway.md, "Scaling"). Written from the plain unit so that the two share every line of
# hardening and restart policy; what differs per instance is its header, Description=, the
# configuration in ExecStart= and LogsDirectory= (instances run as different dynamic users, and
# systemd hands each its own directory: one shared by two would be taken over by the last started).
$(DIST)/urrt-gateway@.service: $(DIST)/urrt-gateway.service
	sed -e '1i # SPDX-License-Identifier: MIT' \
	    -e '1i # urrt-gateway@NAME: one more urrt-gateway, reading $(SYSCONFDIR)/urrt/NAME.ini' \
	    -e '1i # (check it with `urrt-gateway --check-config $(SYSCONFDIR)/urrt/NAME.ini`).' \
	    -e '1i # Written by gateway/install/install.mk from urrt-gateway.service: the same' \
	    -e '1i # hardening and restart policy. One instance per configuration:' \
	    -e '1i #   systemctl enable --now urrt-gateway@NAME' \
	    -e '1i # Logs: journalctl -u urrt-gateway@NAME' \
	    -e '/^\[Unit\]/,$$!d' \
	    -e 's|^Description=urrt-gateway: |Description=urrt-gateway %i: |' \
	    -e 's|^\(ExecStart=[^ ]* .*/urrt/\)gateway\.ini$$|\1%i.ini|' \
	    -e 's|^LogsDirectory=urrt$$|LogsDirectory=urrt-%i|; s|/var/log/urrt/|/var/log/urrt-NAME/|g; s|/var/log/urrt,|/var/log/urrt-NAME,|' \
	    $< > $@
	@grep -q '^ExecStart=.*/%i\.ini$$' $@ && grep -q '^LogsDirectory=urrt-%i$$' $@ || \
	  { echo "$@: the plain unit's ExecStart= or LogsDirectory= changed: update this rule"; rm -f $@; exit 1; }
# check-man holds both units' Documentation= to the man page.
check-man: $(DIST)/urrt-gateway@.service

# Links to docs/X (inline, reference definitions, and their text) become X: the
# documents sit beside it.
$(DIST)/README.md: README.md
	@mkdir -p $(@D)
	sed -e 's|](docs/|](|g; s|\[docs/|[|g; s|^\( \{0,3\}\[[^]]*\]: *\)docs/|\1|' $< > $@

$(DIST)/urrt-spy: gateway/install/urrt-spy
	@mkdir -p $(@D)
	sed -e 's|^URRT_JAR_DEFAULT=.*|URRT_JAR_DEFAULT=$(JAVADIR)/urrt-lcmtypes.jar|' $< > $@

$(DIST)/$(TYPES_JAR): $(LCMTYPES_JAR)
	@mkdir -p $(@D)
	cp $< $@

# The example with its robot commented out: an unedited install refuses to
# start and says which file to edit.
$(DIST)/gateway.ini: gateway/install/urrt-gateway.example.ini
	@mkdir -p $(@D)
	awk '/^\[/ { robot = /^\[robot / } \
	     robot && /^\[robot / { print "# Uncomment this section and set the robot'\''s address, then run"; \
	       print "#   urrt-gateway --check-config $(CONFIG_FILE)" } \
	     { print (robot && $$0 != "" && $$0 !~ /^#/ ? "#" : "") $$0 }' $< > $@

$(DIST)/urrt.pc: lib/urrt.h
	@mkdir -p $(@D)
	printf '%s\n' 'prefix=$(PREFIX)' 'libdir=$(LIBDIR)' 'includedir=$(INCLUDEDIR)' '' 'Name: urrt' \
	  'Description: Universal Robots RealTime decoder and RTDE client, CAN packing and CANopen node (freestanding C99)' \
	  'Version: $(URRT_VERSION)' 'Libs: -L$${libdir} -lurrt' 'Cflags: -I$${includedir}' > $@

# The paths are baked into the generated files: make them again on every install.
.PHONY: install-files uninstall-files uninstall dist-files
dist-files:
	@rm -f $(DIST_FILES)
	@$(MAKE) --no-print-directory $(DIST_FILES)

install: install-files
install-files: all dist-files
	@set -e; for e in $(INSTALL_ITEMS); do \
	  src=$${e%%:*}; rest=$${e#*:}; dir=$${rest%:*}; mode=$${rest#*:}; \
	  install -d $(DESTDIR)$$dir; install -m $$mode $$src $(DESTDIR)$$dir/; \
	done
	@for e in $(INSTALL_LINKS); do ln -sfn $${e%%:*} $(DESTDIR)$${e#*:}; done
	install -d $(DESTDIR)$(SYSCONFDIR)/urrt
	@# An existing configuration (edited or not) is never overwritten.
	[ -e $(DESTDIR)$(CONFIG_FILE) ] || install -m 0644 $(DIST)/gateway.ini $(DESTDIR)$(CONFIG_FILE)

uninstall: uninstall-files
uninstall-files: dist-files
	@for e in $(INSTALL_ITEMS); do \
	  src=$${e%%:*}; rest=$${e#*:}; dir=$${rest%:*}; rm -f $(DESTDIR)$$dir/$${src##*/}; \
	done
	@for e in $(INSTALL_LINKS); do rm -f $(DESTDIR)$${e#*:}; done
	@# The configuration goes only as installed; an edited one stays.
	@if cmp -s $(DIST)/gateway.ini $(DESTDIR)$(CONFIG_FILE); then rm -f $(DESTDIR)$(CONFIG_FILE); \
	elif [ -e $(DESTDIR)$(CONFIG_FILE) ]; then echo "uninstall: $(DESTDIR)$(CONFIG_FILE) was edited: kept"; fi
	@for d in $(INSTALL_OWN_DIRS); do [ ! -d $(DESTDIR)$$d ] || rmdir --ignore-fail-on-non-empty $(DESTDIR)$$d; done

# ---- the Debian package ------------------------------------------------------------
# `make deb` builds the Debian package (debian/) from this
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
	@# The package builds with its own make settings (debian/rules): none of this make's may
	@# reach it, or its `make clean` would remove a BUILD given here (an absolute one lies
	@# outside the copy).
	cd $(DEB_WORK)/urrt && env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL -u MAKEOVERRIDES -u BUILD \
	  DEB_BUILD_OPTIONS="parallel=$(DEB_JOBS) noddebs $(DEB_BUILD_OPTIONS)" \
	  dpkg-buildpackage -b -us -uc > ../build.log 2>&1 || { tail -n 30 ../build.log; exit 1; }
	mv $(DEB_WORK)/*.deb $(DEB_WORK)/*.changes $(DEB_WORK)/*.buildinfo $(DEB_WORK)/build.log $(DEB_DIR)/
	rm -rf $(DEB_WORK)
	@ls $(DEB_DIR)/*.deb
