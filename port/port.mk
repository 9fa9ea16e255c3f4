# SPDX-License-Identifier: MIT
# port/: the POSIX implementation of port/port.h.
PORT_SRCS := $(wildcard port/posix/*.c)
PORT_OBJS := $(PORT_SRCS:port/posix/%.c=$(BUILD)/port/%.o)
LIBPORT := $(BUILD)/liburrt-port.a

$(BUILD)/port/%.o: port/posix/%.c port/port.h $(LIB_HDRS) $(wildcard port/posix/*.h)
	@mkdir -p $(@D)
	$(CC) $(PROG_WARN) $(OPT) $(CPPFLAGS) -c $< -o $@

$(LIBPORT): $(PORT_OBJS)
	rm -f $@
	ar rcs $@ $^

all: $(LIBPORT)
