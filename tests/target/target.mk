# SPDX-License-Identifier: MIT
# tests/target/target.mk: lib/ executed where firmware runs (tests/target/).
#   check-lib-m4   the reference vectors (decode and random access from every misalignment,
#                  encoder round trip), the framer on streams of every length with garbage in
#                  every chunk size 1..1460, on qemu's Cortex-M boards: mps2-an386 (Cortex-M4
#                  soft-float -Os as check-cross builds lib/, the same with -mno-unaligned-access,
#                  and hard-float -O2), netduinoplus2
#                  (STM32F405) and microbit (Cortex-M0, -Os and -O2); no C library in the
#                  images, results through semihosting and qemu's exit status; and the painted
#                  stack of every public lib/ function against -fstack-usage and docs/footprint.md;
#                  the CAN core's and the CANopen node's tests (tests/lib/test_cantx.c, test_co.c)
#                  on the M4 (soft and hard float) and the M0; the RTDE client on the reference's
#                  sessions (tests/target/rtde_target.c) on the same three, which also paints the
#                  stack of the urrt_rtde functions (its log joins stack_target.h's for stack.py);
#                  the RTDE client's writing side (tests/lib/test_rtde_in.c, which reads
#                  tests/ref/rtde_ref.py --inputs's sessions through semihosting) on the same three,
#                  with the stack of the urrt_rtde_in functions; the PLC's answers (tests/lib/test_plcin.c)
#                  on the same three, with the stack of the urrt_plcin functions
#   check-lib-be   tests/lib/test_lib.c on big-endian s390x, powerpc and mips (with the lib/urrt_can,
#                  urrt_cantx, urrt_co, urrt_rtde, urrt_rtde_in and urrt_plcin tests of tests/lib/test_can.c,
#                  test_cantx.c, test_co.c, test_rtde.c, test_rtde_in.c, test_plcin.c),
#                  lib/*.c alone, and on little-endian NEON
#                  (aarch64, armhf; lib/vector/urrt_vector.c, and aarch64 also lib/*.c alone)
#                  under qemu-user; on big-endian NEON (aarch64_be, armeb; freestanding)
#                  lib/vector/urrt_vector.c passes and the same with the old vector condition
#                  (commit d7588d7) fails
#   bench-lib-m4   instructions per operation on the emulated Cortex-M4 (qemu -icount),
#                  a cycle estimate at 168 MHz, checked against docs/performance.md (and the
#                  RTDE feed of a read holding a 5-value recipe's package within 300); packing
#                  a CAN frame also on the M4 with its single-precision FPU and the M0, its
#                  instruction budget on the M4 (soft-float)

TGT := $(BUILD)/tests/target
TGT_QEMU_M := qemu-system-arm -nographic -monitor none -serial none -semihosting-config enable=on,target=native
TGT_CM := arm-none-eabi-gcc
# lib/ as check-cross compiles it; the drivers as tests, freestanding.
TGT_LIB_FLAGS := $(LIB_WARN) -ffreestanding -ffunction-sections -fdata-sections -fstack-usage -fcallgraph-info=su
TGT_FLAGS := $(PROG_WARN) -ffreestanding -fno-tree-loop-distribute-patterns -ffunction-sections -fdata-sections \
             -Ilib -Itests/target
TGT_LINK := -nostdlib -Ltests/target -Wl,--gc-sections -lgcc
TGT_M4 := -mcpu=cortex-m4 -mthumb
TGT_M4F := -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard
TGT_M0 := -mcpu=cortex-m0 -mthumb

DEB_DEPS_NO_RECOMMENDS += qemu-system-arm qemu-user gcc-s390x-linux-gnu gcc-powerpc-linux-gnu \
                          gcc-mips-linux-gnu gcc-aarch64-linux-gnu gcc-arm-linux-gnueabihf \
                          libc6-dev-s390x-cross libc6-dev-powerpc-cross libc6-dev-mips-cross \
                          libc6-dev-arm64-cross libc6-dev-armhf-cross gcc-riscv64-unknown-elf

CHECKS += check-lib-m4 check-lib-be bench-lib-m4
BENCHES += bench-lib-m4
.PHONY: check-lib-m4 check-lib-be bench-lib-m4

# The reference's vectors as C arrays: all of them, or fewer for small flash.
$(TGT)/vectors_%.c: $(LIB_VECTORS) tests/target/vectors_c.py
	@mkdir -p $(@D)
	$(PYTHON) tests/target/vectors_c.py $(LIB_VECTORS) $@ $*

TGT_DRIVER := tests/target/test_target.c tests/target/stack_target.h tests/target/target.h tests/lib/state_slot.h \
              tests/testutil.h tests/lib/co_fixture.h tests/target/test_vectors.h tests/target/cm.c \
              tests/target/sections.ld

# $(call tgt_image,NAME,CPU FLAGS,OPT,LINKER SCRIPT,VECTORS): lib/ objects and a test image.
define tgt_image
$(TGT)/$(1)/lib/%.o: lib/%.c $(LIB_HDRS)
	@mkdir -p $$(@D)
	$(TGT_CM) $(2) $(3) $(TGT_LIB_FLAGS) -c $$< -o $$@
$(TGT)/$(1)/test.elf: $(TGT_DRIVER) tests/target/$(4) $(TGT)/vectors_$(5).c $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o)
	$(TGT_CM) $(2) $(3) $(TGT_FLAGS) -DURRT_TARGET_CORTEX_M tests/target/cm.c tests/target/test_target.c \
	  $(TGT)/vectors_$(5).c $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o) -T tests/target/$(4) $(TGT_LINK) -o $$@
endef
$(eval $(call tgt_image,m4-os,$(TGT_M4),-Os,an386.ld,all))
$(eval $(call tgt_image,m4f-o2,$(TGT_M4F),-O2,an386.ld,all))
$(eval $(call tgt_image,m4na-os,$(TGT_M4) -mno-unaligned-access,-Os,an386.ld,named+8))
$(eval $(call tgt_image,f405-os,$(TGT_M4F),-Os,f405.ld,named+2))
$(eval $(call tgt_image,m0-os,$(TGT_M0),-Os,microbit.ld,named))
$(eval $(call tgt_image,m0-o2,$(TGT_M0),-O2,microbit.ld,named+32))
TGT_BOARDS := m4-os:mps2-an386 m4f-o2:mps2-an386 m4na-os:mps2-an386 f405-os:netduinoplus2 m0-os:microbit m0-o2:microbit

# The CAN core's and the CANopen node's tests (tests/lib/test_cantx.c, test_co.c) as images
# of their own, NAME/cantx.elf and NAME/co.elf, on the lib/ objects of an image above:
# $(call tgt_unit,NAME,CPU FLAGS,OPT,LINKER SCRIPT).
TGT_UNITS := cantx co plcin
TGT_UNIT_DEPS := tests/target/cm.c tests/target/target.h tests/target/target_check.h tests/testutil.h \
                 tests/lib/co_fixture.h
define tgt_unit
$(foreach u,$(TGT_UNITS),$(TGT)/$(1)/$(u).elf): $(TGT)/$(1)/%.elf: tests/lib/test_%.c $(TGT_UNIT_DEPS) \
  tests/target/$(4) $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o)
	$(TGT_CM) $(2) $(3) $(TGT_FLAGS) -Itests -DURRT_TARGET_CORTEX_M tests/target/cm.c $$< \
	  $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o) -T tests/target/$(4) $(TGT_LINK) -o $$@
endef
$(eval $(call tgt_unit,m4-os,$(TGT_M4),-Os,an386.ld))
$(eval $(call tgt_unit,m4f-o2,$(TGT_M4F),-O2,an386.ld))
$(eval $(call tgt_unit,m0-os,$(TGT_M0),-Os,microbit.ld))
TGT_UNIT_BOARDS := m4-os:mps2-an386 m4f-o2:mps2-an386 m0-os:microbit

# The RTDE client (tests/target/rtde_target.c) on the reference's sessions as C data
# (tests/target/rtde_vectors_c.py), NAME/rtde.elf on the lib/ objects of an image above:
# $(call tgt_rtde_image,NAME,CPU FLAGS,OPT,LINKER SCRIPT).
$(TGT)/rtde_vectors.c: $(RTDE_VECTORS) tests/target/rtde_vectors_c.py
	@mkdir -p $(@D)
	$(PYTHON) tests/target/rtde_vectors_c.py $(RTDE_VECTORS) $@
define tgt_rtde_image
$(TGT)/$(1)/rtde.elf: tests/target/rtde_target.c tests/target/rtde_vectors.h tests/target/stack_marks.h tests/lib/rtde_names.h $(TGT_UNIT_DEPS) tests/target/$(4) \
  $(TGT)/rtde_vectors.c $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o)
	$(TGT_CM) $(2) $(3) $(TGT_FLAGS) -Itests -DURRT_TARGET_CORTEX_M tests/target/cm.c $$< $(TGT)/rtde_vectors.c \
	  $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o) -T tests/target/$(4) $(TGT_LINK) -o $$@
endef
$(eval $(call tgt_rtde_image,m4-os,$(TGT_M4),-Os,an386.ld))
$(eval $(call tgt_rtde_image,m4f-o2,$(TGT_M4F),-O2,an386.ld))
$(eval $(call tgt_rtde_image,m0-os,$(TGT_M0),-Os,microbit.ld))
TGT_RTDE_BOARDS := m4-os:mps2-an386 m4f-o2:mps2-an386 m0-os:microbit

# The writing side (tests/lib/test_rtde_in.c) as NAME/rtde_in.elf on the same lib/ objects; it
# reads the vectors through semihosting, the file qemu's arg= names: $(call tgt_rtde_in_image,...).
TGT_QEMU_M_VECTORS := qemu-system-arm -nographic -monitor none -serial none \
                      -semihosting-config enable=on,target=native,arg=$(RTDE_IN_VECTORS)
define tgt_rtde_in_image
$(TGT)/$(1)/rtde_in.elf: tests/lib/test_rtde_in.c tests/target/stack_marks.h tests/lib/rtde_names.h $(TGT_UNIT_DEPS) tests/target/$(4) \
  $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o)
	$(TGT_CM) $(2) $(3) $(TGT_FLAGS) -Itests -DURRT_TARGET_CORTEX_M tests/target/cm.c $$< \
	  $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o) -T tests/target/$(4) $(TGT_LINK) -o $$@
endef
$(eval $(call tgt_rtde_in_image,m4-os,$(TGT_M4),-Os,an386.ld))
$(eval $(call tgt_rtde_in_image,m4f-o2,$(TGT_M4F),-O2,an386.ld))
$(eval $(call tgt_rtde_in_image,m0-os,$(TGT_M0),-Os,microbit.ld))

check-lib-m4: $(foreach b,$(TGT_BOARDS),$(TGT)/$(firstword $(subst :, ,$(b)))/test.elf) tests/target/stack.py \
  $(foreach u,$(TGT_UNITS),$(foreach b,$(TGT_UNIT_BOARDS),$(TGT)/$(firstword $(subst :, ,$(b)))/$(u).elf)) \
  $(foreach b,$(TGT_RTDE_BOARDS),$(TGT)/$(firstword $(subst :, ,$(b)))/rtde.elf) \
  $(foreach b,$(TGT_RTDE_BOARDS),$(TGT)/$(firstword $(subst :, ,$(b)))/rtde_in.elf) $(RTDE_IN_VECTORS)
	$(call suite,check-lib-m4,sh tests/target/run.sh $(TGT)/logs \
	  $(foreach b,$(TGT_RTDE_BOARDS),rtde-$(firstword $(subst :, ,$(b)))="$(TGT_QEMU_M) \
	    -M $(lastword $(subst :, ,$(b))) -kernel $(TGT)/$(firstword $(subst :, ,$(b)))/rtde.elf") \
	  $(foreach b,$(TGT_RTDE_BOARDS),rtde-in-$(firstword $(subst :, ,$(b)))="$(TGT_QEMU_M_VECTORS) \
	    -M $(lastword $(subst :, ,$(b))) -kernel $(TGT)/$(firstword $(subst :, ,$(b)))/rtde_in.elf") \
	  $(foreach b,$(TGT_BOARDS),$(firstword $(subst :, ,$(b)))="$(TGT_QEMU_M) -M $(lastword $(subst :, ,$(b))) \
	    -kernel $(TGT)/$(firstword $(subst :, ,$(b)))/test.elf") \
	  $(foreach u,$(TGT_UNITS),$(foreach b,$(TGT_UNIT_BOARDS),$(u)-$(firstword $(subst :, ,$(b)))="$(TGT_QEMU_M) \
	    -M $(lastword $(subst :, ,$(b))) -kernel $(TGT)/$(firstword $(subst :, ,$(b)))/$(u).elf")) \
	  stack-m4-os="cat $(TGT)/logs/m4-os.log $(TGT)/logs/rtde-m4-os.log $(TGT)/logs/rtde-in-m4-os.log \
	    $(TGT)/logs/plcin-m4-os.log \
	    > $(TGT)/logs/stack-m4-os.marks && \
	    $(PYTHON) tests/target/stack.py $(TGT)/logs/stack-m4-os.marks docs/footprint.md $(TGT)/m4-os/lib/*.ci")

# ---- big-endian and NEON under qemu-user ---------------------------------------------

# $(call tgt_linux,NAME,CC AND FLAGS,QEMU,SOURCES[,can]): test_lib of lib/ as SOURCES
# (LIB_SRCS or LIB_HOST_SRCS, lib/lib.mk) and with "can" the tests of urrt_can, urrt_cantx and
# urrt_co (TGT_BE_CAN), which have no vector path: on the big-endian targets only; static.
TGT_BE_CAN := can cantx co
define tgt_linux
$(TGT)/$(1)/lib/%.o: lib/%.c $(LIB_HDRS)
	@mkdir -p $$(@D)
	$(2) $(LIB_WARN) -O2 -c $$< -o $$@
$(TGT)/$(1)/lib/vector/urrt_vector.o: lib/urrt.c
$(TGT)/$(1)/test_lib: tests/lib/test_lib.c tests/check.h tests/testutil.h tests/lib/state_slot.h \
  $(4:lib/%.c=$(TGT)/$(1)/lib/%.o)
	$(2) -static $(LIB_TEST_CFLAGS) -O2 $$< $(4:lib/%.c=$(TGT)/$(1)/lib/%.o) -lm -o $$@
$(TGT_BE_CAN:%=$(TGT)/$(1)/test_%): $(TGT)/$(1)/%: tests/lib/%.c tests/check.h tests/testutil.h tests/lib/co_fixture.h \
  $(4:lib/%.c=$(TGT)/$(1)/lib/%.o)
	$(2) -static $(LIB_TEST_CFLAGS) -O2 $$< $(4:lib/%.c=$(TGT)/$(1)/lib/%.o) -lm -o $$@
TGT_BE_BINS += $(TGT)/$(1)/test_lib $(if $(5),$(TGT_BE_CAN:%=$(TGT)/$(1)/test_%))
TGT_BE_RUNS += $(1)="$(3) $(TGT)/$(1)/test_lib $(LIB_VECTORS)" \
               $(if $(5),$(foreach t,$(TGT_BE_CAN),$(1)-$(t)="$(3) $(TGT)/$(1)/test_$(t)"))
endef
TGT_NEON := -mfpu=neon-vfpv4
$(eval $(call tgt_linux,s390x,s390x-linux-gnu-gcc,qemu-s390x,$(LIB_SRCS),can))
$(eval $(call tgt_linux,powerpc,powerpc-linux-gnu-gcc,qemu-ppc,$(LIB_SRCS),can))
$(eval $(call tgt_linux,mips,mips-linux-gnu-gcc,qemu-mips,$(LIB_SRCS),can))
$(eval $(call tgt_linux,aarch64,aarch64-linux-gnu-gcc,qemu-aarch64,$(LIB_HOST_SRCS)))
$(eval $(call tgt_linux,aarch64-alone,aarch64-linux-gnu-gcc,qemu-aarch64,$(LIB_SRCS)))
$(eval $(call tgt_linux,armhf,arm-linux-gnueabihf-gcc $(TGT_NEON),qemu-arm,$(LIB_HOST_SRCS)))

# Which grid copy each build of lib/vector/urrt_vector.c takes: the byte-swapping vector
# path on little-endian NEON, never on big-endian NEON (where the wire's order is the host's).
TGT_ARMEB := arm-none-eabi-gcc -mbig-endian -mcpu=cortex-a7 $(TGT_NEON) -mfloat-abi=hard -Wl,--be8
TGT_A64BE := aarch64-linux-gnu-gcc -mbig-endian
tgt_vector = $(1) -ffreestanding -O2 -Ilib -E -dM $(LIB_VECTOR_SRC) | grep -q '^\#define URRT_VECTOR ' && \
  echo '1 passed, 0 failed'
tgt_no_vector = ! $(1) -ffreestanding -O2 -Ilib -E -dM $(LIB_VECTOR_SRC) | grep -q '^\#define URRT_VECTOR ' && \
  echo '1 passed, 0 failed'

# Big-endian NEON has no C library in Debian: freestanding images of
# test_target.c with tests/target/linux_start.c, on lib/vector/urrt_vector.c
# (the vector paths; lib/urrt.c alone has none). The regression build is that
# file with the vector condition as it was before commit d7588d7 (any GNU
# compiler, not little-endian only), generated here; it must fail. The copy
# finds its #include "../urrt.c" through -Ilib/vector.
TGT_OLD_NEON := $(TGT)/old_neon/urrt_vector.c
$(TGT_OLD_NEON): $(LIB_VECTOR_SRC)
	@mkdir -p $(@D)
	sed 's/^#if defined(URRT_LOAD_UNALIGNED) && (defined(__SSSE3__) || defined(__ARM_NEON))$$/#if defined(__GNUC__) \&\& (defined(__SSSE3__) || defined(__ARM_NEON))/' $< > $@.tmp
	@grep -q '^#if defined(__GNUC__) && (defined(__SSSE3__) || defined(__ARM_NEON))$$' $@.tmp || \
	  { echo "$@: $<'s vector condition changed: update the regression's sed"; exit 1; }
	mv $@.tmp $@

TGT_BE_FREE := $(TGT_FLAGS) -O2 -nostdlib -static tests/target/linux_start.c tests/target/test_target.c \
               $(TGT)/vectors_named.c
$(TGT)/%/neon_be: $(TGT_DRIVER) tests/target/linux_start.c $(TGT)/vectors_named.c $(LIB_VECTOR_SRC) lib/urrt.c \
  $(LIB_HDRS)
	@mkdir -p $(@D)
	$(if $(filter armeb,$*),$(TGT_ARMEB),$(TGT_A64BE)) $(TGT_BE_FREE) $(LIB_VECTOR_SRC) -o $@
$(TGT)/%/neon_be_old: $(TGT_DRIVER) tests/target/linux_start.c $(TGT)/vectors_named.c $(TGT_OLD_NEON) lib/urrt.c \
  $(LIB_HDRS)
	@mkdir -p $(@D)
	$(if $(filter armeb,$*),$(TGT_ARMEB),$(TGT_A64BE)) $(TGT_BE_FREE) -Ilib/vector $(TGT_OLD_NEON) -o $@
TGT_BE_BINS += $(foreach a,armeb aarch64_be,$(TGT)/$(a)/neon_be $(TGT)/$(a)/neon_be_old)

# The RTDE client's tests (tests/lib/test_rtde.c, test_rtde_in.c, test_plcin.c) on the big-endian CPUs,
# on the reference's sessions: $(call tgt_rtde,NAME,CC,QEMU), on the lib/ objects of tgt_linux.
define tgt_rtde
$(TGT)/$(1)/test_rtde: tests/lib/test_rtde.c tests/check.h tests/lib/rtde_names.h $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o)
	$(2) -static $(LIB_TEST_CFLAGS) -O2 $$< $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o) -lm -o $$@
$(TGT)/$(1)/test_rtde_in: tests/lib/test_rtde_in.c tests/check.h tests/target/stack_marks.h tests/lib/rtde_names.h $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o)
	$(2) -static $(LIB_TEST_CFLAGS) -O2 $$< $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o) -lm -o $$@
$(TGT)/$(1)/test_plcin: tests/lib/test_plcin.c tests/check.h tests/target/stack_marks.h $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o)
	$(2) -static $(LIB_TEST_CFLAGS) -O2 $$< $(LIB_SRCS:lib/%.c=$(TGT)/$(1)/lib/%.o) -lm -o $$@
TGT_BE_BINS += $(TGT)/$(1)/test_rtde $(TGT)/$(1)/test_rtde_in $(TGT)/$(1)/test_plcin
TGT_BE_RUNS += $(1)-rtde="$(3) $(TGT)/$(1)/test_rtde $(RTDE_VECTORS)" \
               $(1)-rtde-in="$(3) $(TGT)/$(1)/test_rtde_in $(RTDE_IN_VECTORS)" \
               $(1)-plcin="$(3) $(TGT)/$(1)/test_plcin"
endef
$(eval $(call tgt_rtde,s390x,s390x-linux-gnu-gcc,qemu-s390x))
$(eval $(call tgt_rtde,powerpc,powerpc-linux-gnu-gcc,qemu-ppc))
$(eval $(call tgt_rtde,mips,mips-linux-gnu-gcc,qemu-mips))

check-lib-be: $(TGT_BE_BINS) $(LIB_VECTORS) $(RTDE_VECTORS) $(RTDE_IN_VECTORS) $(TGT_OLD_NEON)
	$(call suite,check-lib-be,sh tests/target/run.sh $(TGT)/logs-be $(TGT_BE_RUNS) \
	  aarch64-vector-path="$(call tgt_vector,aarch64-linux-gnu-gcc)" \
	  armhf-vector-path="$(call tgt_vector,arm-linux-gnueabihf-gcc $(TGT_NEON))" \
	  armeb-no-vector-path="$(call tgt_no_vector,$(TGT_ARMEB))" \
	  aarch64_be-no-vector-path="$(call tgt_no_vector,$(TGT_A64BE))" \
	  armeb-neon="qemu-armeb $(TGT)/armeb/neon_be" aarch64_be-neon="qemu-aarch64_be $(TGT)/aarch64_be/neon_be" \
	  !armeb-neon-before-d7588d7="qemu-armeb $(TGT)/armeb/neon_be_old" \
	  !aarch64_be-neon-before-d7588d7="qemu-aarch64_be $(TGT)/aarch64_be/neon_be_old")

# ---- instructions per operation -------------------------------------------------------

# $(call tgt_bench,NAME,CPU FLAGS,OPT,LINKER SCRIPT,EXTRA FLAGS FOR lib/)
define tgt_bench
$(TGT)/bench-$(1).elf: tests/target/bench_target.c tests/target/target.h tests/target/cm.c tests/target/$(4) \
  $(TGT)/vectors_named.c $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $$(@D)
	$(TGT_CM) $(2) $(3) $(TGT_FLAGS) -DURRT_TARGET_CORTEX_M -c $(TGT)/vectors_named.c -o $$@.vectors.o
	$(TGT_CM) $(2) $(3) $(TGT_FLAGS) -DURRT_TARGET_CORTEX_M tests/target/cm.c tests/target/bench_target.c \
	  $$@.vectors.o $(5) $(LIB_SRCS) -T tests/target/$(4) $(TGT_LINK) -o $$@
endef
$(eval $(call tgt_bench,m4-os,$(TGT_M4),-Os,an386.ld,))
$(eval $(call tgt_bench,m4-o2,$(TGT_M4),-O2,an386.ld,))
$(eval $(call tgt_bench,m4f-o2,$(TGT_M4F),-O2,an386.ld,))
# Cortex-M0: lib/'s word path against its portable byte path (no __BYTE_ORDER__).
$(eval $(call tgt_bench,m0-os,$(TGT_M0),-Os,microbit.ld,))
$(eval $(call tgt_bench,m0-os-portable,$(TGT_M0),-Os,microbit.ld,-U__BYTE_ORDER__))

bench-lib-m4: $(foreach b,m4-os m4-o2 m4f-o2 m0-os m0-os-portable,$(TGT)/bench-$(b).elf) tests/target/bench.py
	$(call suite,bench-lib-m4,sh tests/target/run.sh $(TGT)/logs-bench \
	  m4="$(PYTHON) tests/target/bench.py docs/performance.md '$(TGT_QEMU_M) -M mps2-an386' \
	    -Os=$(TGT)/bench-m4-os.elf -O2=$(TGT)/bench-m4-o2.elf" \
	  m0="$(PYTHON) tests/target/bench.py --not-slower '$(TGT_QEMU_M) -M microbit' \
	    words=$(TGT)/bench-m0-os.elf portable=$(TGT)/bench-m0-os-portable.elf" \
	  can="$(PYTHON) tests/target/bench.py --can docs/performance.md '$(TGT_QEMU_M)' \
	    'M4 -Os=mps2-an386:$(TGT)/bench-m4-os.elf' 'M4 -O2=mps2-an386:$(TGT)/bench-m4-o2.elf' \
	    'M4F -O2=mps2-an386:$(TGT)/bench-m4f-o2.elf' 'M0 -Os=microbit:$(TGT)/bench-m0-os.elf'")
