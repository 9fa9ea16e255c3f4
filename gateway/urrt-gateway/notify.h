/* SPDX-License-Identifier: MIT */
/*
 * notify.h: urrt-gateway under systemd (Type=notify), the sd_notify protocol
 * written by hand: one datagram per message to the AF_UNIX socket named by
 * $NOTIFY_SOCKET (a path, or an abstract name written "@name"), no
 * libsystemd.
 *
 * READY=1 once the outputs are open, STOPPING=1 on shutdown, and, as a
 * gw_output, WATCHDOG=1 at half of $WATCHDOG_USEC and a one-line STATUS=
 * (robots up, oldest data age, CAN state) each second when it changed. The
 * pings come from the output's tick, which the poll loop runs (gateway.c):
 * their deadline is one of the loop's, so an idle or busy loop pings on
 * time and a loop that stops servicing stops pinging, and systemd restarts
 * it. Without $NOTIFY_SOCKET nothing is sent and no output is added.
 */
#ifndef URRT_GATEWAY_NOTIFY_H
#define URRT_GATEWAY_NOTIFY_H

#include "can_out.h"
#include "gateway.h"

typedef struct gw_notify gw_notify;

/* NULL when $NOTIFY_SOCKET is unset (not under systemd), or unusable (a
 * warning is logged: the gateway runs without telling systemd). can: the CAN
 * output for the status line, or NULL. */
gw_notify *gw_notify_new(gateway *gw, can_out *can);
/* The gw_output with the watchdog and the status; its close does not free
 * the notifier (STOPPING=1 comes after the loop): gw_notify_free does. */
gw_output gw_notify_output(gw_notify *n);
void gw_notify_ready(gw_notify *n);
void gw_notify_stopping(gw_notify *n);
void gw_notify_free(gw_notify *n);

#endif
