# SPDX-License-Identifier: MIT
# lib/: the freestanding decoder, built alone under the strictest warnings.
# LIB_SRCS are the files a firmware compiles (lib/*.c). A host build compiles
# LIB_HOST_SRCS: the same with lib/vector/urrt_vector.c in place of
# lib/urrt.c, which it includes and extends with the vector paths (x86
# SSSE3/AVX2/AVX-512BW chosen by the CPU, ARM NEON).
LIB_SRCS := $(wildcard lib/*.c)
LIB_HDRS := $(wildcard lib/*.h)
LIB_VECTOR_SRC := lib/vector/urrt_vector.c
LIB_HOST_SRCS := $(filter-out lib/urrt.c,$(LIB_SRCS)) $(LIB_VECTOR_SRC)
# Every source a host build reads: what its rules depend on.
LIB_HOST_DEPS := $(LIB_SRCS) $(LIB_VECTOR_SRC) $(LIB_HDRS)
LIB_OBJS := $(LIB_HOST_SRCS:lib/%.c=$(BUILD)/lib/%.o)
LIBURRT := $(BUILD)/liburrt.a

$(BUILD)/lib/%.o: lib/%.c $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_WARN) $(OPT) -c $< -o $@
$(BUILD)/lib/vector/urrt_vector.o: lib/urrt.c

$(LIBURRT): $(LIB_OBJS)
	rm -f $@
	ar rcs $@ $^

all: $(LIBURRT)
