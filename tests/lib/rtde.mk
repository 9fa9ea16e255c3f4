# SPDX-License-Identifier: MIT
# tests/lib/rtde.mk: the RTDE client (lib/urrt_rtde), on its own.
#   check-rtde       tests/lib/test_rtde.c on the sessions tests/ref/rtde_ref.py writes (it plays
#                    the controller: every type, protocol 1 and 2, every error), fed whole, byte
#                    by byte and in 7-byte reads; every split point of each session; every byte
#                    written is a V, v, O, S or P request; the name and version tables
#   check-rtde-san   the same under ASan + UBSan, lib/ compiled with them
#   check-fuzz-rtde  the libFuzzer harness tests/lib/fuzz_rtde.c, briefly (FUZZ_RTDE_SECONDS, 20)
#   fuzz-rtde        the same for FUZZ_SECONDS; the corpus grows in $(RTT)/fuzz
# The writing side (lib/urrt_rtde_in), on the sessions tests/ref/rtde_ref.py --inputs writes:
#   check-rtde-in    tests/lib/test_rtde_in.c: input recipes in the handshake (V v O I.. S), every
#                    reply token, input data packages byte for byte for given values, refused
#                    values; fed whole, byte by byte and in 7-byte reads; every split point; the
#                    read-only client fed the same streams writes only V, v, O, S and P
#   check-rtde-in-san     the same under ASan + UBSan
#   check-fuzz-rtde-in    the libFuzzer harness tests/lib/fuzz_rtde_in.c, briefly (FUZZ_RTDE_SECONDS)
#   fuzz-rtde-in     the same for FUZZ_SECONDS; the corpus grows in $(RTT)/fuzz-in
# The PLC's answers (lib/urrt_plcin) over it:
#   check-plcin      tests/lib/test_plcin.c: values taken from a frame (scaling, min..max, masks),
#                    refused and absent ones, when a package is due, the timeout and each
#                    on_silence policy, against values worked out by hand; and under ASan + UBSan

RTT := $(BUILD)/tests/rtde
RTDE_VECTORS := $(RTT)/vectors.txt
RTDE_CORPUS := $(RTT)/seeds
FUZZ_RTDE_SECONDS ?= 20

CHECKS += check-rtde check-rtde-san check-fuzz-rtde check-rtde-in check-rtde-in-san check-fuzz-rtde-in check-plcin
.PHONY: check-rtde check-rtde-san check-fuzz-rtde fuzz-rtde check-rtde-in check-rtde-in-san check-fuzz-rtde-in \
        fuzz-rtde-in check-plcin

$(RTDE_VECTORS): tests/ref/rtde_ref.py
	@mkdir -p $(@D)
	rm -rf $(RTDE_CORPUS)
	$(PYTHON) tests/ref/rtde_ref.py --out $@ --corpus $(RTDE_CORPUS)

$(RTT)/test_rtde: tests/lib/test_rtde.c tests/check.h tests/lib/rtde_names.h $(LIBURRT) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) $< $(LIBURRT) -lm -o $@

$(RTT)/test_rtde_san: tests/lib/test_rtde.c tests/check.h tests/lib/rtde_names.h $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) -O1 -g $(SAN_FLAGS) -fsanitize=float-cast-overflow $< $(LIB_SRCS) -lm -o $@

check-rtde: $(RTT)/test_rtde $(RTDE_VECTORS)
	$(call suite,check-rtde,$(RTT)/test_rtde $(RTDE_VECTORS))

check-rtde-san: $(RTT)/test_rtde_san $(RTDE_VECTORS)
	$(call suite,check-rtde-san,ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  $(RTT)/test_rtde_san $(RTDE_VECTORS))

$(RTT)/fuzz_rtde: tests/lib/fuzz_rtde.c $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c99 -Wall -Wextra -Werror -g -O1 -fsanitize=fuzzer,address,undefined \
	  -fno-sanitize-recover=all $(CPPFLAGS) $< $(LIB_SRCS) -o $@

# The seeds are the reference's controller streams (its vectors' rule writes them).
check-fuzz-rtde: $(RTT)/fuzz_rtde $(RTDE_VECTORS)
	$(call suite,$@,sh tests/lib/fuzz.sh $(RTT)/fuzz_rtde $(RTDE_CORPUS) $(RTT)/fuzz-check $(FUZZ_RTDE_SECONDS) --check)

fuzz-rtde: $(RTT)/fuzz_rtde $(RTDE_VECTORS)
	sh tests/lib/fuzz.sh $(RTT)/fuzz_rtde $(RTDE_CORPUS) $(RTT)/fuzz $(FUZZ_SECONDS)

fuzz: fuzz-rtde

# ---- the writing side: lib/urrt_rtde_in ------------------------------------------------

RTDE_IN_VECTORS := $(RTT)/vectors_in.txt
RTDE_IN_CORPUS := $(RTT)/seeds_in

$(RTDE_IN_VECTORS): tests/ref/rtde_ref.py
	@mkdir -p $(@D)
	rm -rf $(RTDE_IN_CORPUS)
	$(PYTHON) tests/ref/rtde_ref.py --inputs --out $@ --corpus $(RTDE_IN_CORPUS)

$(RTT)/test_rtde_in: tests/lib/test_rtde_in.c tests/check.h tests/target/stack_marks.h tests/lib/rtde_names.h $(LIBURRT) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) $< $(LIBURRT) -lm -o $@

$(RTT)/test_rtde_in_san: tests/lib/test_rtde_in.c tests/check.h tests/target/stack_marks.h tests/lib/rtde_names.h $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) -O1 -g $(SAN_FLAGS) -fsanitize=float-cast-overflow $< $(LIB_SRCS) -lm -o $@

check-rtde-in: $(RTT)/test_rtde_in $(RTDE_IN_VECTORS)
	$(call suite,check-rtde-in,$(RTT)/test_rtde_in $(RTDE_IN_VECTORS))

check-rtde-in-san: $(RTT)/test_rtde_in_san $(RTDE_IN_VECTORS)
	$(call suite,check-rtde-in-san,ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  $(RTT)/test_rtde_in_san $(RTDE_IN_VECTORS))

$(RTT)/fuzz_rtde_in: tests/lib/fuzz_rtde_in.c $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) -std=c99 -Wall -Wextra -Werror -g -O1 -fsanitize=fuzzer,address,undefined \
	  -fno-sanitize-recover=all $(CPPFLAGS) $< $(LIB_SRCS) -o $@

# The seeds are the reference's controller streams of its input sessions.
check-fuzz-rtde-in: $(RTT)/fuzz_rtde_in $(RTDE_IN_VECTORS)
	$(call suite,$@,sh tests/lib/fuzz.sh $(RTT)/fuzz_rtde_in $(RTDE_IN_CORPUS) $(RTT)/fuzz-in-check \
	  $(FUZZ_RTDE_SECONDS) --check)

fuzz-rtde-in: $(RTT)/fuzz_rtde_in $(RTDE_IN_VECTORS)
	sh tests/lib/fuzz.sh $(RTT)/fuzz_rtde_in $(RTDE_IN_CORPUS) $(RTT)/fuzz-in $(FUZZ_SECONDS)

fuzz: fuzz-rtde-in

# ---- the PLC's answers: lib/urrt_plcin --------------------------------------------------

$(RTT)/test_plcin: tests/lib/test_plcin.c tests/check.h $(LIBURRT) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) $(OPT) $< $(LIBURRT) -lm -o $@

$(RTT)/test_plcin_san: tests/lib/test_plcin.c tests/check.h $(LIB_SRCS) $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_TEST_CFLAGS) -O1 -g $(SAN_FLAGS) -fsanitize=float-cast-overflow $< $(LIB_SRCS) -lm -o $@

check-plcin: $(RTT)/test_plcin $(RTT)/test_plcin_san
	$(call suite,check-plcin,$(RTT)/test_plcin && UBSAN_OPTIONS=print_stacktrace=1 $(RTT)/test_plcin_san)
