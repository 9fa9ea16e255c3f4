/* SPDX-License-Identifier: MIT */
/*
 * A freestanding Cortex-M4 image around lib/: a vector table and a reset
 * handler that frames, decodes and random-reads packets from a static
 * receive buffer, so that the linker keeps what a firmware would use.
 * Linked with -nostdlib: any symbol lib/ needs from outside shows up as an
 * undefined reference (tests/cross/check.sh compares them with docs/footprint.md).
 */
#include "urrt.h"

extern uint32_t _estack, _sidata, _sdata, _edata, _sbss, _ebss;

void reset_handler(void);
void default_handler(void);

/* Cortex-M vector table: initial stack pointer, then the handlers. */
__attribute__((section(".isr_vector"), used)) static const uintptr_t vector_table[16] = {
    (uintptr_t)&_estack,         (uintptr_t)reset_handler,   (uintptr_t)default_handler,
    (uintptr_t)default_handler,  (uintptr_t)default_handler, (uintptr_t)default_handler,
    (uintptr_t)default_handler,  0, 0, 0, 0,
    (uintptr_t)default_handler,  (uintptr_t)default_handler, 0,
    (uintptr_t)default_handler,  (uintptr_t)default_handler,
};

/* What a TCP stack would fill; volatile reads stop the compiler from
 * treating it as known-zero. */
static uint8_t rx_buffer[1500];
volatile size_t rx_length;
static urrt_framer framer;
static urrt_state state;
volatile double sink_value;
volatile int sink_result;

void default_handler(void)
{
    for (;;) {
    }
}

void reset_handler(void)
{
    /* Volatile pointers keep these loops from being turned into memcpy and
     * memset calls, which a -nostdlib image does not have. */
    volatile uint32_t *dst = &_sdata;
    const volatile uint32_t *src = &_sidata;
    while (dst < &_edata) {
        *dst++ = *src++;
    }
    for (dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0;
    }

    urrt_framer_init(&framer);
    for (;;) {
        const uint8_t *data = rx_buffer;
        size_t n = rx_length;
        while (n > 0) {
            size_t used = 0;
            if (urrt_framer_feed(&framer, data, n, &used) > 0) {
                size_t len;
                const uint8_t *pkt = urrt_framer_packet(&framer, &len);
                double q;
                sink_result = urrt_decode(pkt, len, &state);
                sink_value = state.time[0];
                if (urrt_read(pkt, len, URRT_F_Q_ACTUAL, 0, &q) == URRT_OK) {
                    sink_value = q;
                }
            }
            data += used;
            n -= used;
        }
    }
}
