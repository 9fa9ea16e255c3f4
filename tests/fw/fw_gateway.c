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
 *
 * The generated init prepares every signal's scale (urrt_cantx_prepare), as
 * urrt-gateway's own tables do: both pack exactly, so the frames are the
 * same bits.
 *
 * Built with -DFW_CANOPEN for a configuration with [canopen]: the CANopen
 * node of lib/urrt_co.h runs over the CAN core (the generated tables carry
 * its description, urrt_gateway_co_init), booted at the first packet as
 * `urrt-gateway --replay` boots it: boot-up, heartbeats, EMCYs, TPDOs. A
 * manager's frames (tests/fw/fw_rx.h: what a board's CAN receive interrupt
 * would hand over) go to urrt_co_on_frame at their time, between the
 * packets, as `urrt-gateway --replay-rx` feeds the same frames.
 *
 * Built with -DFW_RTDE for a robot read over RTDE (source = rtde): lib's
 * RTDE client (lib/urrt_rtde.h) in place of the framer, with the recipe the
 * generated tables carry (urrt_gateway_rtde_vars). Its requests go to the
 * TCP stack, here printed as "rtde> HEX" lines for run.sh to check; the
 * controller's bytes (a scripted controller's, tests/fw/rtde_controller.py)
 * come through semihosting in the same chunks; each data package's state,
 * and its RTDE-only values through urrt_gateway_rtde_values, go to the CAN
 * core at the package's controller time.
 *
 * Built with -DFW_INPUTS too (a CANopen node whose RPDOs are [input]s): the
 * PLC's answers. The session sets up one input recipe per [input]
 * (lib/urrt_rtde_in.h, urrt_gateway_inputs[k].regs); after each frame to the
 * node, at each package and at each of their deadlines, lib/urrt_plcin.h
 * takes what the node's RPDOs and SDO writes stored and says when an input
 * package is due, which goes to the TCP stack like a request ("rtde> HEX"),
 * as `urrt-gateway --replay --replay-inputs` writes the same packages.
 */
#include <stddef.h>
#include <stdint.h>

#include "target.h"
#include "urrt.h"
#include "urrt_cantx.h"
#ifdef FW_CANOPEN
#include "fw_rx.h"
#include "urrt_co.h"
#endif
#ifdef FW_RTDE
#include "urrt_rtde.h"
#endif
#ifdef FW_INPUTS
#include "urrt_plcin.h"
#endif

/* From the generated tables. */
extern const urrt_cantx_tables urrt_gateway_tables;
int urrt_gateway_cantx_init(urrt_cantx *tx, size_t *bad_frame, size_t *bad_signal);
#ifdef FW_CANOPEN
int urrt_gateway_co_init(urrt_co *co, urrt_cantx *tx, size_t *bad_item);
#endif
#ifdef FW_RTDE
extern const uint16_t *const urrt_gateway_rtde_vars[];
extern const size_t urrt_gateway_rtde_var_count[];
extern const double urrt_gateway_rtde_frequency[];
extern const uint16_t urrt_gateway_rtde_port[];
void urrt_gateway_rtde_values(size_t robot, const urrt_rtde_values *values);
#endif
#ifdef FW_INPUTS
extern const urrt_plcin_desc urrt_gateway_inputs[];
extern const size_t urrt_gateway_input_count;
extern const uint64_t urrt_gateway_inputs_period_us;
extern const uint16_t urrt_gateway_input_first_var[];
#define FW_INPUTS_MAX 4 /* the node's RPDOs */
static urrt_rtde_in inputs[FW_INPUTS_MAX];  /* URRT_RTDE_IN_RAM each */
static urrt_plcin input_states[FW_INPUTS_MAX];
static const uint32_t session_number = 1;   /* one TCP connection here; a board counts its connects */
static uint32_t input_packages;
#endif

#define CHUNK 1460 /* one TCP segment on Ethernet */

#ifdef FW_RTDE
static urrt_rtde session; /* URRT_RTDE_RAM */
/* Two, because this clock jumps: a package is decoded before the frames due
 * since the last one are caught up, and those must still read the last
 * one's values. A board that wakes at every deadline decodes into one. */
static urrt_rtde_values rtde_values[2];
static unsigned rtde_decoding;
static uint8_t request[URRT_RTDE_REQUEST_MAX];
static uint32_t rtde_packages;
#else
static urrt_framer framer;
#endif
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

/* The package's RTDE-only values to the frames, just before its state, as
 * urrt-gateway's CAN output hands them over (RealTime has none). */
static void values_to_tables(void)
{
#ifdef FW_RTDE
    urrt_gateway_rtde_values(0, &rtde_values[rtde_decoding]);
    rtde_decoding ^= 1u;
#endif
}

#ifdef FW_CANOPEN
static urrt_co node;
static uint64_t node_us; /* the node's latest run */
static int booted;
static uint64_t inputs_us; /* the inputs' latest look */

#ifdef FW_INPUTS
static void tcp_send(const uint8_t *p, size_t n);

/* Each input through the node at now_us (lib's look), then its package if due. */
static void inputs_look(uint64_t now_us)
{
    static uint8_t pkg[URRT_RTDE_IN_PACKAGE_MAX];
    size_t k;
    inputs_us = now_us;
    for (k = 0; k < urrt_gateway_input_count && k < FW_INPUTS_MAX; k++) {
        const urrt_plcin_rpdo rpdo = {&node, urrt_gateway_input_first_var[k], (uint8_t)k};
        urrt_plcin_look look;
        int n;
        urrt_plcin_node(&urrt_gateway_inputs[k], &rpdo, &input_states[k], &inputs[k], now_us, &look);
        if (!urrt_plcin_due(&urrt_gateway_inputs[k], &input_states[k], urrt_rtde_in_ready(&session, &inputs[k]),
                            session_number, now_us, urrt_gateway_inputs_period_us)) {
            continue;
        }
        n = urrt_rtde_in_package(&session, &inputs[k], pkg, sizeof pkg);
        urrt_plcin_sent(&input_states[k], n > 0, session_number, now_us);
        if (n > 0) {
            tcp_send(pkg, (size_t)n);
            input_packages++;
        }
    }
}

/* The inputs' earliest deadline, never before the latest look. */
static uint64_t inputs_deadline(void)
{
    uint64_t due = URRT_CANTX_NEVER;
    size_t k;
    for (k = 0; k < urrt_gateway_input_count && k < FW_INPUTS_MAX; k++) {
        uint64_t d = urrt_plcin_deadline(&urrt_gateway_inputs[k], &input_states[k],
                                         urrt_rtde_in_ready(&session, &inputs[k]), urrt_gateway_inputs_period_us);
        due = d < due ? d : due;
    }
    return due != URRT_CANTX_NEVER && due < inputs_us ? inputs_us : due;
}
#else
static void inputs_look(uint64_t now_us)
{
    (void)now_us;
}

static uint64_t inputs_deadline(void)
{
    return URRT_CANTX_NEVER;
}
#endif

/* A board wakes at every deadline (urrt_co_deadline, and the inputs') on its
 * timer; here the clock jumps from packet to packet, so run each due first,
 * in time order. */
static void node_catch_up(uint64_t until_us)
{
    for (;;) {
        uint64_t due = urrt_co_deadline(&node), in_due = inputs_deadline();
        due = due < node_us ? node_us : due;
        if (due >= until_us && in_due >= until_us) {
            return;
        }
        if (due <= in_due) {
            urrt_co_run(&node, due, can_transmit, NULL);
            if (due == node_us && urrt_co_deadline(&node) <= due) {
                return;
            }
            node_us = due;
        } else {
            uint64_t before = inputs_us;
            inputs_look(in_due);
            if (in_due == before && inputs_deadline() <= in_due) {
                return;
            }
        }
    }
}

/* The manager's frames up to now_us, each at its own time. */
static void rx_until(uint64_t now_us)
{
    static unsigned next;
    for (; next < fw_rx_count && fw_rx_frames[next].t_us <= now_us; next++) {
        const struct fw_rx_frame *f = &fw_rx_frames[next];
        uint64_t at = f->t_us < node_us ? node_us : f->t_us;
#ifdef FW_INPUTS
        at = at < inputs_us ? inputs_us : at;
#endif
        node_catch_up(at);
        urrt_co_on_frame(&node, f->id, 0, f->data, f->len, at, can_transmit, NULL);
        node_us = at;
#ifdef FW_INPUTS
        inputs_look(at);
#endif
    }
}

static void packet_at(uint64_t now_us)
{
    if (!booted) {
        booted = 1; /* power-on at the first packet: the boot-up frame */
        node_us = now_us;
        urrt_co_start(&node, now_us, can_transmit, NULL);
    }
    rx_until(now_us);
    node_catch_up(now_us);
    values_to_tables();
    urrt_cantx_on_packet(&tx, 0, &state, now_us);
    urrt_co_run(&node, now_us, can_transmit, NULL);
    node_us = now_us;
#ifdef FW_INPUTS
    inputs_look(now_us);
#endif
}
#else
static void packet_at(uint64_t now_us)
{
    /* A board wakes at every deadline (urrt_cantx_deadline) on its timer;
     * here the clock jumps from packet to packet, so catch up first. */
    urrt_cantx_catch_up(&tx, now_us, can_transmit, NULL);
    values_to_tables();
    urrt_cantx_on_packet(&tx, 0, &state, now_us);
    urrt_cantx_run(&tx, now_us, can_transmit, NULL);
}
#endif

#ifdef FW_RTDE
/* The TCP stack's send: here one line per request, "rtde> " and its bytes in hex. */
static void tcp_send(const uint8_t *p, size_t n)
{
    char hex[2 * 32 + 1];
    target_puts("rtde> ");
    while (n > 0) {
        size_t k = n < 32u ? n : 32u;
        for (size_t i = 0; i < k; i++) {
            put_hex(hex + 2 * i, p[i], 2);
        }
        hex[2 * k] = '\0';
        target_puts(hex);
        p += k;
        n -= k;
    }
    target_puts("\n");
}

/* Every request the session has due (whenever the socket may be written). */
static void send_requests(void)
{
    int n;
#ifdef FW_INPUTS
    while ((n = urrt_rtde_in_output(&session, inputs, urrt_gateway_input_count, request, sizeof request)) > 0) {
#else
    while ((n = urrt_rtde_output(&session, request, sizeof request)) > 0) {
#endif
        tcp_send(request, (size_t)n);
    }
}

/* A data package: its state and RTDE-only values, on its controller time. */
static void on_data(void)
{
    int64_t now_us;
    rtde_packages++;
    if (!urrt_has(&state, URRT_F_TIME) || urrt_time_us(state.time[0], &now_us) != URRT_OK) {
        return; /* the recipe has the timestamp: only a broken one has none */
    }
    packet_at((uint64_t)now_us);
}

/* Bytes as the TCP stack hands them over, in any chunking: 0, or -1 when
 * the session ended (a board closes the socket; after EV_DROP it reconnects
 * soon, after EV_CONFIG it backs off long: the controller refused the recipe). */
static int on_tcp_bytes(const uint8_t *p, size_t n)
{
    while (n > 0) {
        size_t used = 0;
        urrt_rtde_event ev;
#ifdef FW_INPUTS
        int k = urrt_rtde_in_feed(&session, inputs, urrt_gateway_input_count, p, n, &used, &ev, &state,
                                  &rtde_values[rtde_decoding]);
#else
        int k = urrt_rtde_feed(&session, p, n, &used, &ev, &state, &rtde_values[rtde_decoding]);
#endif
        p += used;
        n -= used;
        if (k == URRT_RTDE_EV_DATA) {
            on_data();
        } else if (k == URRT_RTDE_EV_DROP || k == URRT_RTDE_EV_CONFIG || k < 0) {
            target_puts("fw_gateway: the RTDE session ended: ");
            target_puts(urrt_rtde_strerror(k < 0 ? k : ev.error));
            target_puts("\n");
            urrt_rtde_finish(&session);
            return -1;
        }
        send_requests();
    }
    return 0;
}
#else
/* One complete packet: its values to the CAN core, then whatever is due. */
static void on_packet(const uint8_t *pkt, size_t len)
{
    int64_t now_us;
    if (urrt_decode(pkt, len, &state) < 0 || !urrt_has(&state, URRT_F_TIME) ||
        urrt_time_us(state.time[0], &now_us) != URRT_OK) {
        return; /* no usable clock in it: nothing to send it by */
    }
    packet_at((uint64_t)now_us);
}

/* Bytes as the TCP stack hands them over, in any chunking. */
static int on_tcp_bytes(const uint8_t *p, size_t n)
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
    return 0;
}
#endif

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
        target_puts("fw_gateway: the generated tables are refused by urrt_cantx_init or urrt_cantx_prepare\n");
        return 1;
    }
    if (tx.scales == NULL) {
        target_puts("fw_gateway: urrt_gateway_cantx_init left the scales unprepared: the generated init must call "
                    "urrt_cantx_prepare (gateway/can/can_ctables.c)\n");
        return 1;
    }
#ifdef FW_CANOPEN
    if (urrt_gateway_co_init(&node, &tx, &bad_frame) != 0) {
        target_puts("fw_gateway: the generated node is refused by urrt_co_init\n");
        return 1;
    }
#endif
#ifdef FW_RTDE
    /* Never a byte to a port that runs what it receives: checked before the
     * connection, whatever the tables say (check-fw-gateway's rtde-port
     * image is given 30003). */
    if (urrt_rtde_check_port(urrt_gateway_rtde_port[0]) != URRT_OK) {
        target_puts("fw_gateway: refusing RTDE on port ");
        target_put_uint(urrt_gateway_rtde_port[0]);
        target_puts(": ");
        target_puts(urrt_rtde_port_role(urrt_gateway_rtde_port[0]));
        target_puts("\n");
        return 1;
    }
    /* The TCP connection is up: the handshake with the generated recipe. */
    urrt_rtde_init(&session);
    if (urrt_rtde_begin(&session, urrt_gateway_rtde_vars[0], urrt_gateway_rtde_var_count[0],
                        urrt_gateway_rtde_frequency[0]) != URRT_OK) {
        target_puts("fw_gateway: urrt_rtde_begin refuses the generated recipe (urrt_gateway_rtde_vars)\n");
        return 1;
    }
#ifdef FW_INPUTS
    /* One input recipe per [input] (its RPDO), set up in the handshake; nothing is
     * written before the PLC writes. */
    for (n = 0; n < urrt_gateway_input_count && n < FW_INPUTS_MAX; n++) {
        if (urrt_rtde_in_init(&inputs[n], urrt_gateway_inputs[n].regs, urrt_gateway_inputs[n].reg_count) !=
            URRT_OK) {
            target_puts("fw_gateway: urrt_rtde_in_init refuses a generated input recipe (urrt_gateway_inputs)\n");
            return 1;
        }
        urrt_plcin_init(&input_states[n]);
    }
    urrt_rtde_in_begin(inputs, urrt_gateway_input_count);
#endif
    send_requests();
#else
    urrt_framer_init(&framer);
#endif
    while ((n = target_read(capture, chunk, sizeof chunk)) > 0) {
        if (on_tcp_bytes(chunk, n) != 0) {
            return 1;
        }
    }
#ifdef FW_RTDE
    target_puts("fw_gateway: RTDE data packages: ");
    target_put_uint(rtde_packages);
    target_puts("\n");
#endif
#ifdef FW_INPUTS
    target_puts("fw_gateway: input packages: ");
    target_put_uint(input_packages);
    target_puts("\n");
#endif
    target_puts("fw_gateway: frames sent: ");
    target_put_uint(frames_sent);
    target_puts("\n");
    return frames_sent > 0 ? 0 : 1;
}
