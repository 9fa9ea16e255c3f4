# SPDX-License-Identifier: MIT
# lib/: the freestanding decoder, built alone under the strictest warnings.
LIB_SRCS := $(wildcard lib/*.c)
LIB_HDRS := $(wildcard lib/*.h)
LIB_OBJS := $(LIB_SRCS:lib/%.c=$(BUILD)/lib/%.o)
LIBURRT := $(BUILD)/liburrt.a

$(BUILD)/lib/%.o: lib/%.c $(LIB_HDRS)
	@mkdir -p $(@D)
	$(CC) $(LIB_WARN) $(OPT) -c $< -o $@

$(LIBURRT): $(LIB_OBJS)
	rm -f $@
	ar rcs $@ $^

all: $(LIBURRT)
