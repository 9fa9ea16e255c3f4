# SPDX-License-Identifier: MIT
# tests/lib/canopen.mk: the CANopen node (lib/urrt_co), on its own.
#   check-co        tests/lib/test_co.c: NMT, heartbeat, SDO (every abort code), TPDO gating
#                   and SYNC, EMCY, RPDOs (at once, at the SYNC, lengths, ranges, deadlines,
#                   freshness) and the consumer heartbeat; frames written out by hand from
#                   CiA 301; lengths 0..8 on every id and 10^5 random frames (tests/testutil.h's
#                   sequence) against invariants; check-lib-m4 runs it on the emulated Cortex-M4
#                   and M0, check-lib-be on big-endian CPUs (tests/target/target.mk)
#   check-co-san    the same under ASan + UBSan, lib/ compiled with them
#   check-fuzz-co   the libFuzzer harness tests/lib/fuzz_co.c, briefly (FUZZ_CO_SECONDS, 20)
#   fuzz-co         the same for FUZZ_SECONDS; the corpus grows in $(COT)/fuzz

COT := $(BUILD)/tests/co
FUZZ_CO_SECONDS ?= 20

CHECKS += check-co check-co-san check-fuzz-co
.PHONY: check-co check-co-san check-fuzz-co fuzz-co

$(COT)/test_co: tests/lib/test_co.c tests/lib/co_fixture.h tests/check.h tests/testutil.h $(LIBURRT) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) $< $(LIBURRT) -lm -o $@

$(COT)/test_co_san: tests/lib/test_co.c tests/lib/co_fixture.h tests/check.h tests/testutil.h $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) -O1 -g $(SAN_FLAGS) -fsanitize=float-cast-overflow $< $(LIB_SRCS) -lm -o $@

check-co: $(COT)/test_co
	$(call suite,check-co,$(COT)/test_co)

check-co-san: $(COT)/test_co_san
	$(call suite,check-co-san,ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 $(COT)/test_co_san)

$(COT)/fuzz_co: tests/lib/fuzz_co.c tests/lib/co_fixture.h $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c99 -Wall -Wextra -Werror -g -O1 -fsanitize=fuzzer,address,undefined \
	  -fno-sanitize-recover=all $(CPPFLAGS) $< $(LIB_SRCS) -o $@

# Seeds: an NMT start, SDO reads and a segmented upload, SYNCs, a packet; and
# (even lengths: the node with RPDOs) RPDOs, a heartbeat of 0x1016's producer,
# SDO requests to 0x1400 and 0x1016; the fuzzer mutates from them. tests/lib/fuzz.sh
# runs it (fixed seed under check).
$(COT)/seeds/.made: tests/lib/canopen.mk
	@mkdir -p $(@D)
	@i=0; for s in '\000\000\002\001\012' '\001\002\010\100\000\020\000\000\000\000\000' \
	  '\001\002\010\100\010\020\000\000\000\000\000\001\002\010\140\000\000\000\000\000\000\000' \
	  '\001\002\010\053\027\020\000\012\000\000\000' '\001\002\010\057\000\030\002\003\000\000\000' \
	  '\000\000\002\001\000\001\001\000\001\001\000\001\001\000' '\010\360\000\050\360\001' \
	  '\001\002\010\043\000\030\001\241\001\000\200' '\377\361\004\377\362\014' \
	  '\000\000\002\201\000\000\000\002\202\012' '\001\002\010\240\000\020\000\000\000\000\000' \
	  '\001\002\005\100\000\020\000\000' \
	  '\000\000\002\001\000\001\010\007\364\001\001\170\126\064\022\001\013\001\005\001\012\004\005\252\040\000\001\001\000\377\013\000' \
	  '\000\042\010\043\000\000\001\012\002\000\200\000\042\010\100\004\000\001\000\000\000\000'; do \
	  i=$$((i + 1)); printf "$$s" > $(@D)/seed$$i; done; touch $@

check-fuzz-co: $(COT)/fuzz_co $(COT)/seeds/.made
	$(call suite,$@,sh tests/lib/fuzz.sh $(COT)/fuzz_co $(COT)/seeds $(COT)/fuzz-check $(FUZZ_CO_SECONDS) --check)

fuzz-co: $(COT)/fuzz_co $(COT)/seeds/.made
	sh tests/lib/fuzz.sh $(COT)/fuzz_co $(COT)/seeds $(COT)/fuzz $(FUZZ_SECONDS)

fuzz: fuzz-co
