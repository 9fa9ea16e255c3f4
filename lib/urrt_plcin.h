/* SPDX-License-Identifier: MIT */
/*
 * urrt_plcin: the PLC's answers. What a PLC sends on CAN (a frame of its
 * own, or a CANopen RPDO whose variables a urrt_co node stored) becomes the
 * values of one RTDE input recipe (lib/urrt_rtde_in.h), and this unit says
 * when that recipe's input package is due, and only while the PLC's data is
 * fresh. Freestanding C99 like the rest of lib/: no heap, no globals, no
 * clock (time is an argument, in microseconds of any monotonic clock).
 * urrt-gateway's [input NAME] sections run on it, and a firmware runs it on
 * the tables `urrt-gateway --print-c-tables` writes for the same file.
 *
 * One urrt_plcin_desc per [input] (its signals, the register each writes,
 * the recipe, the timeout and what silence does), one urrt_plcin (its state)
 * and one urrt_rtde_in (its values and recipe) beside it:
 *
 *   a frame of the input's id:  if (urrt_plcin_raws(&d, data, len, fd, raws))
 *                                   urrt_plcin_take(&d, &p, &in, raws, 0, now);
 *   with a CANopen node:        after each frame to it and each urrt_co_run,
 *                               urrt_plcin_node(&d, &rpdo, &p, &in, now, &look)
 *                               takes what an RPDO or SDO write stored, and
 *                               judges the node's state (below)
 *   at every loop:              if (urrt_plcin_timed_out(&d, &p, now))
 *                                   urrt_plcin_silent(&d, &p, &in);
 *                               (and on the caller's own reasons: the CAN
 *                               interface down, a bus-off, the node not
 *                               OPERATIONAL, the manager's heartbeat lost)
 *                               if (urrt_plcin_due(&d, &p, ready, session, now, period))
 *                                   n = urrt_rtde_in_package(&s, &in, out, cap);
 *                                   urrt_plcin_sent(&p, n > 0 && the bytes went, session, now);
 *   sleep no longer than:       urrt_plcin_deadline(&d, &p, ready, period)
 *
 * ready: the robot's RTDE session accepted the recipe and streams
 * (urrt_rtde_in_ready); session: a number the caller changes at every new
 * session (a reconnect), so that the current values go at once to a new one.
 *
 * The rules, the same in every gateway built on it:
 * - A value is taken as the PLC sent it or not at all: a bit mask's bits
 *   gathered from its signals (URRT_CAN_SIG_MASK: each signal's raw shifted
 *   up by its first bit, or-ed; bits no signal carries are 0), any other
 *   value through its one signal's scaling (raw x factor + offset) and within
 *   the signal's min..max, then urrt_rtde_in_set_*'s check of the register's
 *   type. A value refused, or absent, leaves its register without a value, so
 *   that nothing is sent for it until a good one comes. Never clamped.
 * - Nothing is sent before the PLC first wrote (no invented zeros at start).
 * - A package goes when a value changed, when the session is new, and at
 *   least every period while the PLC's data is fresh, so that the robot
 *   program's rtde_set_watchdog sees a living PLC.
 * - The PLC silent (no write for timeout_ms, or the caller's reasons):
 *   URRT_PLCIN_STOP forgets the values and sends nothing (the program's
 *   watchdog acts), _HOLD goes on sending the last values, _VALUE sends
 *   silence_value to every register of the recipe. Fresh again at its next
 *   write.
 */
#ifndef URRT_PLCIN_H
#define URRT_PLCIN_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "urrt_can.h"
#include "urrt_cantx.h"
#include "urrt_co.h"
#include "urrt_rtde_in.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The most signals an input holds: one per bit of a 64-byte frame. */
#define URRT_PLCIN_MAX_SIGNALS (8u * URRT_CAN_MAX_LEN)

/* What the registers get when the PLC falls silent (on_silence). */
typedef enum urrt_plcin_silence {
    URRT_PLCIN_STOP = 0,  /* nothing more is sent (values forgotten): the program's rtde_set_watchdog acts */
    URRT_PLCIN_HOLD = 1,  /* the last values go on being sent */
    URRT_PLCIN_VALUE = 2  /* silence_value goes to every register of the recipe */
} urrt_plcin_silence;

/* One input: a frame the PLC sends (or an RPDO's mapping, signal i its
 * entry i), whose signals write the input registers of one recipe. */
typedef struct urrt_plcin_desc {
    const urrt_can_signal *signals; /* place and scaling; checked against len before use */
    const uint16_t *vars;           /* per signal: the register it writes (a variable id of urrt_rtde.h) */
    const uint16_t *regs;           /* the input recipe: each register once, in package order */
    uint16_t signal_count;          /* 1..URRT_PLCIN_MAX_SIGNALS */
    uint16_t reg_count;             /* 1..URRT_RTDE_IN_MAX_VARS */
    uint8_t len;                    /* payload bytes: a frame of another length is not used */
    uint8_t flags;                  /* URRT_CANTX_EXTENDED, URRT_CANTX_FD */
    uint32_t id;
    uint32_t timeout_ms;            /* no write for longer than this: the PLC is silent */
    uint8_t silence;                /* urrt_plcin_silence */
    uint8_t robot;                  /* the robot whose registers it writes (the caller's index) */
    double silence_value;           /* URRT_PLCIN_VALUE's; one every register takes */
} urrt_plcin_desc;

/* One input's state: the caller's, zeroed or urrt_plcin_init'ed. */
typedef struct urrt_plcin {
    uint64_t rx_us;     /* the PLC's last write taken */
    uint64_t seen_us;   /* with a node: its newest write to the input's variables at the last look */
    uint64_t sent_us;   /* the last package sent or tried */
    uint32_t session;   /* the session the last package went to */
    bool ever;          /* the PLC wrote since start: before, nothing is sent */
    bool fresh;         /* its data is fresh */
    bool changed;       /* a value changed since the last package */
} urrt_plcin;

void urrt_plcin_init(urrt_plcin *p);

/*
 * The raw value of each of d's signals in a received payload (raws[i] for
 * signal i, URRT_PLCIN_MAX_SIGNALS entries at most): true; false for a
 * payload of another length or kind (classic, FD) than d's (raws
 * untouched), or a signal that does not fit it (raws then undefined): the
 * payload is not used.
 */
bool urrt_plcin_raws(const urrt_plcin_desc *d, const uint8_t *data, unsigned len, bool fd, uint64_t *raws);

/*
 * What the PLC wrote, at at_us: every register of d's recipe `in` (made from
 * d->regs) from raws, bit i of absent saying signal i has no value (a
 * CANopen variable too old; signals past 63 are never absent). The input is
 * fresh from then; a value that changed (or one that came or went) makes the
 * package due. Returns the values refused (outside min..max, or not one the
 * register takes); absent ones are not counted.
 */
size_t urrt_plcin_take(const urrt_plcin_desc *d, urrt_plcin *p, urrt_rtde_in *in, const uint64_t *raws,
                       uint64_t absent, uint64_t at_us);

/* Fresh, and no write for longer than d->timeout_ms at now_us. */
bool urrt_plcin_timed_out(const urrt_plcin_desc *d, const urrt_plcin *p, uint64_t now_us);

/* The PLC fell silent (a timeout, or one of the caller's reasons): no longer
 * fresh, and d->silence applied to in. Nothing happens to an input that is
 * not fresh. */
void urrt_plcin_silent(const urrt_plcin_desc *d, urrt_plcin *p, urrt_rtde_in *in);

/* Whether the registers are written now: the PLC wrote them, and its data
 * is fresh or d->silence sends something. */
bool urrt_plcin_writing(const urrt_plcin_desc *d, const urrt_plcin *p);

/* Whether the package is due at now_us: writing, the session ready, and a
 * value changed, the session is not the last package's, or period_us passed
 * since the last one was sent or tried. */
bool urrt_plcin_due(const urrt_plcin_desc *d, const urrt_plcin *p, bool ready, uint32_t session, uint64_t now_us,
                    uint64_t period_us);

/* The package due was tried at now_us: sent (ok: it went to session), or
 * not (a register without a value, a full queue): still due at the next
 * look, and the deadline a period later, so that a caller that sleeps until
 * urrt_plcin_deadline does not spin on it. */
void urrt_plcin_sent(urrt_plcin *p, bool ok, uint32_t session, uint64_t now_us);

/* The earliest time something is due: the timeout of fresh data (the first
 * microsecond urrt_plcin_timed_out holds), or the next package of one
 * written to a ready session; URRT_CANTX_NEVER when
 * neither. A session that becomes ready, and a write, are the caller's news. */
uint64_t urrt_plcin_deadline(const urrt_plcin_desc *d, const urrt_plcin *p, bool ready, uint64_t period_us);

/* ---- through a CANopen node: RPDOs and SDO writes (lib/urrt_co.h) --------------
 * Input n is the node's RPDO n (urrt_co_init_rx), its signal i the node's
 * variable first_var + i, written by RPDO n or by an SDO download; each
 * variable is as old as its own last write (co->rx_storage->written_us). */
typedef struct urrt_plcin_rpdo {
    const urrt_co *co;
    uint16_t first_var;
    uint8_t rpdo;       /* n: 0 for RPDO1 */
} urrt_plcin_rpdo;

/* Why the input fell silent at a look through the node. */
typedef enum urrt_plcin_why {
    URRT_PLCIN_STILL = 0,            /* it did not fall silent at this look */
    URRT_PLCIN_NOT_OPERATIONAL,      /* the node is not OPERATIONAL */
    URRT_PLCIN_RPDO_OFF,             /* the manager switched the RPDO off (0x1400+n sub 1, bit 31) */
    URRT_PLCIN_HEARTBEAT_LOST,       /* the manager's heartbeat is lost (0x1016) */
    URRT_PLCIN_NO_WRITE              /* no RPDO or SDO write for timeout_ms */
} urrt_plcin_why;

/* What a look through the node did. */
typedef struct urrt_plcin_look {
    bool took;          /* it took a write (as urrt_plcin_take) */
    size_t refused;     /* of its values, refused */
    urrt_plcin_why why; /* it fell silent (urrt_plcin_silent done), and why */
} urrt_plcin_look;

/*
 * One look at input d through the node at now_us: what was written since
 * the last look is taken, while the node may act on it (OPERATIONAL, the RPDO
 * valid, the manager's heartbeat there) and its newest write is at most
 * timeout_ms old, each variable whose own write is older absent (a manager
 * may write by SDO alone, and a value the node refused keeps an older one);
 * then a fresh input falls silent on the node's reason or with no write for
 * timeout_ms. The RPDO's own event timer (urrt_co_rpdo_status's DEADLINE) is
 * the node's EMCY, not a reason: d's timeout_ms is. At most URRT_CO_RPDO_MAX_MAPPED
 * signals (an RPDO maps no more). *look says what happened.
 */
void urrt_plcin_node(const urrt_plcin_desc *d, const urrt_plcin_rpdo *r, urrt_plcin *p, urrt_rtde_in *in,
                     uint64_t now_us, urrt_plcin_look *look);

#ifdef __cplusplus
}
#endif

#endif /* URRT_PLCIN_H */
