/* SPDX-License-Identifier: MIT */
/*
 * A firmware gateway in lib/ alone: RealTime bytes in, CAN frames out, with
 * the frame tables `urrt-gateway --print-c-tables` wrote for the same
 * configuration. docs/firmware.md walks through it.
 *
 * On a real board the bytes come from the TCP stack's receive callback, the
 * time from a microsecond timer and the frames go to the CAN controller's
 * transmit mailbox. In check-fw-gateway it runs on qemu's Cortex-M4
 * (mps2-an386) without a C library: the bytes are a capture read through
 * semihosting in TCP-sized chunks, the time is each packet's controller
 * time (as `urrt-gateway --replay` takes it), and each frame is printed as
 * candump prints it ("185#0102...") for comparison with urrt-gateway's log.
 */
#include <stddef.h>
#include <stdint.h>

#include "target.h"
#include "urrt.h"
#include "urrt_cantx.h"

/* From the generated tables. */
extern const urrt_cantx_tables urrt_gateway_tables;
int urrt_gateway_cantx_init(urrt_cantx *tx, size_t *bad_frame, size_t *bad_signal);

#define CHUNK 1460 /* one TCP segment on Ethernet */

static urrt_framer framer;
static urrt_state state;
static urrt_cantx tx;
static uint8_t chunk[CHUNK];
static uint32_t frames_sent;

/* ---- the board's side: here semihosting -------------------------------------- */

static void put_hex(char *out, uint32_t v, unsigned digits)
{
    static const char hex[] = "0123456789ABCDEF";
    while (digits-- > 0) {
        out[digits] = hex[v & 0xFu];
        v >>= 4;
    }
}

/* The CAN controller's transmit: here one candump-style line per frame. */
static void can_transmit(void *ctx, const urrt_can_frame *f, uint64_t now_us)
{
    char line[3 + 8 + 2 + 2 * URRT_CAN_MAX_LEN + 2];
    unsigned n = f->extended ? 8u : 3u;
    unsigned i;
    (void)ctx;
    (void)now_us;
    put_hex(line, f->id, n);
    line[n++] = '#';
    if (f->fd) {
        line[n++] = '#';
        line[n++] = '4'; /* FD without the bit rate switch, as the log link writes it */
    }
    for (i = 0; i < f->len; i++, n += 2) {
        put_hex(line + n, f->data[i], 2);
    }
    line[n++] = '\n';
    line[n] = '\0';
    target_puts(line);
    frames_sent++;
}

/* ---- the gateway: the same for every board ------------------------------------ */

/* One complete packet: its values to the CAN core, then whatever is due. */
static void on_packet(const uint8_t *pkt, size_t len)
{
    int64_t now_us;
    if (urrt_decode(pkt, len, &state) < 0 || !urrt_has(&state, URRT_F_TIME) ||
        urrt_time_us(state.time[0], &now_us) != URRT_OK) {
        return; /* no usable clock in it: nothing to send it by */
    }
    /* A board wakes at every deadline (urrt_cantx_deadline) on its timer;
     * here the clock jumps from packet to packet, so catch up first. */
    urrt_cantx_catch_up(&tx, (uint64_t)now_us, can_transmit, NULL);
    urrt_cantx_on_packet(&tx, 0, &state, (uint64_t)now_us);
    urrt_cantx_run(&tx, (uint64_t)now_us, can_transmit, NULL);
}

/* Bytes as the TCP stack hands them over, in any chunking. */
static void on_tcp_bytes(const uint8_t *p, size_t n)
{
    while (n > 0) {
        size_t used = 0;
        if (urrt_framer_feed(&framer, p, n, &used) > 0) {
            size_t len;
            const uint8_t *pkt = urrt_framer_packet(&framer, &len);
            on_packet(pkt, len);
        }
        p += used;
        n -= used;
    }
}

int main(void)
{
    size_t bad_frame;
    size_t bad_signal;
    size_t n;
    int capture = target_open_cmdline_file();
    if (capture < 0) {
        target_puts("fw_gateway: cannot open the capture named on the semihosting command line\n");
        return 1;
    }
    if (urrt_gateway_cantx_init(&tx, &bad_frame, &bad_signal) != 0) {
        target_puts("fw_gateway: the generated tables are refused by urrt_cantx_init\n");
        return 1;
    }
    urrt_framer_init(&framer);
    while ((n = target_read(capture, chunk, sizeof chunk)) > 0) {
        on_tcp_bytes(chunk, n);
    }
    target_puts("fw_gateway: frames sent: ");
    target_put_uint(frames_sent);
    target_puts("\n");
    return frames_sent > 0 ? 0 : 1;
}
