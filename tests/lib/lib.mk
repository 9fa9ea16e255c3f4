# SPDX-License-Identifier: MIT
# tests/lib/lib.mk: proof that lib/ is right and freestanding.
#   check-lib       black-box tests against the independent Python reference (every vector
#                   width, URRT_MAX_DOUBLES=152, lib/urrt.c alone as a firmware or vendor
#                   compiles it, and the non-GNU / big-endian code paths)
#   check-lib-san   the same tests under ASan + UBSan
#   check-fuzz-lib  the libFuzzer harness, briefly (make fuzz FUZZ_SECONDS=N for longer)
#   check-cross     every lib/*.c alone for Cortex-M0+, M4 (with and without unaligned access),
#                   M7 hard-float and RV32IMAC at -Os and -O2, linked -nostdlib -lgcc: what it
#                   needs is libgcc's and docs/footprint.md's symbol table; footprint vs that
#                   page; mixing URRT_MAX_DOUBLES values fails to link
# Executed on emulated Cortex-M and big-endian CPUs: tests/target/target.mk.
#   check-docs      the generated tables of docs/protocol.md (fields, enums) and docs/rtde.md
#                   (RTDE variables) are lib's, row for row (make docs rewrites them)
#   bench-lib       ns/packet at every length of lib's controller table against the copy
#                   floor (the packet's doubles byte-swapped by the CPU's widest vectors into
#                   a urrt_state-sized buffer, the rest set), the store floor (memset of a
#                   urrt_state), the plain byte-swap loop and memcpy of the packet; the receive
#                   paths: a read holding one whole package fed to the RTDE client (the STATE
#                   recipe and a 5-value one, each beside its own copy floor) and to the framer
#                   and decoded (docs/performance.md); `bench_lib decode|rtde|framer` runs parts
# Every lib-level rule takes lib/*.c by wildcard (LIB_SRCS, or LIB_HOST_SRCS: the same with
# lib/vector/urrt_vector.c in place of lib/urrt.c, lib/lib.mk), so new modules are covered.

LIBT := $(BUILD)/tests/lib
LIB_VECTORS := $(LIBT)/vectors.txt
LIB_CORPUS := $(LIBT)/corpus
LIB_TEST_CFLAGS := $(PROG_WARN) $(CPPFLAGS) -Itests

CHECKS += check-lib check-lib-san check-fuzz-lib check-cross check-docs
BENCHES += bench-lib

.PHONY: check-lib check-lib-san check-fuzz-lib check-cross check-docs bench-lib fuzz-lib docs


# Vectors and the fuzz seed corpus come from the reference, at test time.
$(LIB_VECTORS): tests/ref/urrt_ref.py
	@mkdir -p $(@D)
	rm -rf $(LIB_CORPUS)
	$(PYTHON) tests/ref/urrt_ref.py --out $@ --corpus $(LIB_CORPUS)

# ---- unit tests --------------------------------------------------------------

$(LIBT)/test_lib: tests/lib/test_lib.c tests/check.h tests/testutil.h tests/lib/state_slot.h $(LIBURRT) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) $< $(LIBURRT) -lm -o $@

# The sanitizer build compiles lib/ itself with the sanitizers too, for this
# machine's CPU, so that the widest vector path of the decoder it has
# (AVX-512, AVX2, SSSE3 or NEON) runs under the sanitizers; check-lib covers
# the portable path and the other widths.
$(LIBT)/test_lib_san: tests/lib/test_lib.c tests/check.h tests/testutil.h tests/lib/state_slot.h $(LIB_HOST_DEPS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) -O1 -g -march=native $(SAN_FLAGS) $< $(LIB_HOST_SRCS) -lm -o $@

# On x86-64 also each vector width of the decoder's grid copy that this CPU
# can run: 16 bytes (SSSE3), 32 (AVX2), 64 (AVX-512BW).
LIB_CPU_FLAGS := $(shell grep -m 1 '^flags' /proc/cpuinfo 2>/dev/null)
LIB_TEST_ISAS := $(if $(filter x86_64,$(shell uname -m)),$(filter ssse3 avx2 avx512bw,$(LIB_CPU_FLAGS)))
LIB_TEST_VARIANTS := $(LIB_TEST_ISAS:%=$(LIBT)/test_lib_%)
$(LIBT)/test_lib_%: tests/lib/test_lib.c tests/check.h tests/testutil.h tests/lib/state_slot.h $(LIB_HOST_DEPS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) -m$* $< $(LIB_HOST_SRCS) -lm -o $@

# And the widths a baseline build (no -m flags: SSSE3 off) chooses at run
# time, each forced by capping the choice (URRT_X86_MAX_VECTOR_BYTES), the
# test asserting the width that ran; 0 is the scalar fallback.
LIB_ISA_BYTES_ssse3 := 16
LIB_ISA_BYTES_avx2 := 32
LIB_ISA_BYTES_avx512bw := 64
LIB_DISPATCH_WIDTHS := $(if $(filter x86_64,$(shell uname -m)),0 $(foreach i,$(LIB_TEST_ISAS),$(LIB_ISA_BYTES_$(i))))
LIB_TEST_VARIANTS += $(LIB_DISPATCH_WIDTHS:%=$(LIBT)/test_lib_dispatch%)
$(LIBT)/test_lib_dispatch%: tests/lib/test_lib.c tests/check.h tests/testutil.h tests/lib/state_slot.h $(LIB_HOST_DEPS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) -mno-ssse3 -DURRT_X86_MAX_VECTOR_BYTES=$* -DURRT_TEST_VECTOR_BYTES=$* \
	  $< $(LIB_HOST_SRCS) -lm -o $@

# And the smallest packet bound a firmware may choose (URRT_MAX_DOUBLES=152):
# longer reference packets must then be refused, not misread.
$(LIBT)/test_lib_max152: tests/lib/test_lib.c tests/check.h tests/testutil.h tests/lib/state_slot.h $(LIB_HOST_DEPS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) -DURRT_MAX_DOUBLES=152 $< $(LIB_HOST_SRCS) -lm -o $@

# And lib/*.c alone, as a firmware or a vendor copies it (urrt.h + urrt.c):
# the portable grid copy, one double at a time, even where the host's
# instruction set (-march=native) has the vectors of lib/vector/urrt_vector.c.
$(LIBT)/test_lib_alone: tests/lib/test_lib.c tests/check.h tests/testutil.h tests/lib/state_slot.h $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) -march=native -DURRT_TEST_VECTOR_BYTES=0 $< $(LIB_SRCS) -lm -o $@

# And lib/ as a compiler without GNU extensions (IAR, Keil armcc) or a
# big-endian target builds it: no builtins, no vectors, loads byte by byte.
# No other variant reaches that code.
LIBT_NOGNU := $(LIB_SRCS:lib/%.c=$(LIBT)/nognu/%.o)
$(LIBT)/nognu/%.o: lib/%.c $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_WARN) $(OPT) -U__GNUC__ -U__BYTE_ORDER__ -c $< -o $@

$(LIBT)/test_lib_nognu: tests/lib/test_lib.c tests/check.h tests/testutil.h tests/lib/state_slot.h $(LIBT_NOGNU) $(LIB_HDRS)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) $< $(LIBT_NOGNU) -lm -o $@

check-lib: $(LIBT)/test_lib $(LIBT)/test_lib_max152 $(LIBT)/test_lib_alone $(LIBT)/test_lib_nognu $(LIB_TEST_VARIANTS) \
  $(LIB_VECTORS)
	$(call suite,check-lib,sh tests/lib/run_all.sh $(LIB_VECTORS) $(LIBT)/test_lib $(LIBT)/test_lib_max152 \
	  $(LIBT)/test_lib_alone $(LIBT)/test_lib_nognu $(LIB_TEST_VARIANTS))

check-lib-san: $(LIBT)/test_lib_san $(LIB_VECTORS)
	$(call suite,check-lib-san,ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 $(LIBT)/test_lib_san $(LIB_VECTORS))

# ---- freestanding proof -------------------------------------------------------

check-cross: $(LIB_HOST_DEPS) $(wildcard tests/cross/*)
	$(call suite,$@,sh tests/cross/check.sh $(BUILD)/cross docs/footprint.md "$(LIB_WARN)" $(LIB_SRCS))

# ---- docs/protocol.md's and docs/rtde.md's tables from lib's tables ----------

DOC_TABLE_DOCS := docs/protocol.md docs/rtde.md

$(LIBT)/doc_table: tests/lib/doc_table.c $(LIBURRT) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) $< $(LIBURRT) -o $@

docs: $(LIBT)/doc_table
	sh tests/lib/docs.sh $(LIBT)/doc_table $(DOC_TABLE_DOCS)

check-docs: $(LIBT)/doc_table
	$(call suite,$@,sh tests/lib/docs.sh $(LIBT)/doc_table $(DOC_TABLE_DOCS) --check)

# ---- fuzzing -------------------------------------------------------------------

FUZZ_CC ?= clang
FUZZ_SECONDS ?= 300
# Seconds of fuzzing inside make check.
FUZZ_CHECK_SECONDS ?= 15

$(LIBT)/fuzz_lib: tests/lib/fuzz_lib.c tests/lib/state_slot.h $(LIB_HOST_DEPS)
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c99 -Wall -Wextra -Werror -g -O1 -march=native -fsanitize=fuzzer,address,undefined \
	  -fno-sanitize-recover=all $(CPPFLAGS) $< $(LIB_HOST_SRCS) -o $@

check-fuzz-lib: $(LIBT)/fuzz_lib $(LIB_VECTORS)
	$(call suite,$@,sh tests/lib/fuzz.sh $(LIBT)/fuzz_lib $(LIB_CORPUS) $(LIBT)/fuzz-check $(FUZZ_CHECK_SECONDS) --check)

# make fuzz FUZZ_SECONDS=N: as long as asked; the corpus grows in $(LIBT)/fuzz.
fuzz-lib: $(LIBT)/fuzz_lib $(LIB_VECTORS)
	sh tests/lib/fuzz.sh $(LIBT)/fuzz_lib $(LIB_CORPUS) $(LIBT)/fuzz $(FUZZ_SECONDS)

fuzz: fuzz-lib

# ---- benchmark -----------------------------------------------------------------

# Two builds: with $(OPT), as a distribution would build it, and with the flags
# docs/performance.md recommends for an edge box (BENCH_EDGE_OPT), whose
# figures carry the prefix edge_ and are the ones held to the targets.
BENCH_EDGE_OPT ?= -O2 -g -march=native
$(LIBT)/bench_lib: tests/lib/bench_lib.c $(LIBURRT) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) -DURRT_BENCH_FLAGS='"$(OPT)"' $< $(LIBURRT) -o $@

$(LIBT)/bench_lib_edge: tests/lib/bench_lib.c $(LIB_HOST_DEPS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(BENCH_EDGE_OPT) -DURRT_BENCH_FLAGS='"$(BENCH_EDGE_OPT)"' \
	  -DURRT_BENCH_PREFIX='"edge_"' $< $(LIB_HOST_SRCS) -o $@

bench-lib: $(LIBT)/bench_lib $(LIBT)/bench_lib_edge
	@$(LIBT)/bench_lib
	@$(LIBT)/bench_lib_edge
