# SPDX-License-Identifier: MIT
# tests/lib/canscale.mk: lib/urrt_can's integer scaling against exact rational arithmetic.
#   check-can-scale  tests/lib/can_scale_ref.py: 10^5 values for each signal kind (the limits,
#                    +-0, NaN, infinities, subnormals, exact ties, the values one ulp either side
#                    of each tie and limit, then uniform, log-uniform and random bits) packed by
#                    tests/lib/can_scale_driver.c, its raw values and outcomes held against
#                    fractions.Fraction: built for this machine, under ASan + UBSan, and without
#                    a C library on qemu's Cortex-M4 (soft-float -Os, hard-float -O2) and
#                    Cortex-M0 (-Os), compared there by digest
# The rules use target.mk's toolchain variables in recipes only (it is included after this file).

CSCALE := $(BUILD)/tests/can-scale
CSCALE_DRIVER := tests/lib/can_scale_driver.c
CSCALE_QEMU = $(TGT_QEMU_M),arg={cases}
CSCALE_CFLAGS := $(PROG_WARN) $(CPPFLAGS) -Itests

CHECKS += check-can-scale
.PHONY: check-can-scale

$(CSCALE)/driver: $(CSCALE_DRIVER) $(LIBURRT) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(CSCALE_CFLAGS) $(OPT) $< $(LIBURRT) -lm -o $@

$(CSCALE)/driver_san: $(CSCALE_DRIVER) $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(CSCALE_CFLAGS) -O1 -g $(SAN_FLAGS) -fsanitize=float-cast-overflow $< $(LIB_SRCS) -lm -o $@

# $(call cscale_image,NAME,CPU FLAGS,OPT,LINKER SCRIPT): the driver and lib/ on a Cortex-M.
define cscale_image
$(CSCALE)/driver-$(1).elf: $(CSCALE_DRIVER) tests/target/cm.c tests/target/target.h tests/target/$(4) \
  $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $$(@D)
	$$(TGT_CM) $(2) $(3) $$(TGT_FLAGS) -DURRT_TARGET_CORTEX_M tests/target/cm.c $$< $(LIB_SRCS) \
	  -T tests/target/$(4) $$(TGT_LINK) -o $$@
endef
$(eval $(call cscale_image,m4-os,-mcpu=cortex-m4 -mthumb,-Os,an386.ld))
$(eval $(call cscale_image,m4f-o2,-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard,-O2,an386.ld))
$(eval $(call cscale_image,m0-os,-mcpu=cortex-m0 -mthumb,-Os,microbit.ld))
CSCALE_BOARDS := m4-os:mps2-an386 m4f-o2:mps2-an386 m0-os:microbit

check-can-scale: $(CSCALE)/driver $(CSCALE)/driver_san tests/lib/can_scale_ref.py \
  $(foreach b,$(CSCALE_BOARDS),$(CSCALE)/driver-$(firstword $(subst :, ,$(b))).elf)
	$(call suite,check-can-scale,ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  $(PYTHON) tests/lib/can_scale_ref.py $(CSCALE)/work --host $(CSCALE)/driver --host $(CSCALE)/driver_san \
	  $(foreach b,$(CSCALE_BOARDS),--target "$(CSCALE_QEMU) -M $(lastword $(subst :, ,$(b))) \
	    -kernel $(CSCALE)/driver-$(firstword $(subst :, ,$(b))).elf"))
