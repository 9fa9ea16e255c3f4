/* SPDX-License-Identifier: MIT */
/*
 * dbc: the DBC file describing what urrt-gateway sends on CAN, and what it
 * receives, written from the same mapping (struct can_map) that packs and
 * unpacks the frames, so that the file handed to the PLC engineer cannot
 * disagree with the bus.
 *
 * What it writes (Vector's conventions, as CANdb++ and python3-canmatrix
 * read them): one node for the gateway (BU_), each configured frame and the
 * heartbeat (BO_ with the byte length as DLC, extended ids with the
 * 0x80000000 flag), every signal (SG_ with the DBC start bit for both byte
 * orders, @1/@0, +/-, factor, offset, min, max, unit, receiver), float
 * signals (SIG_VALTYPE_), GenMsgCycleTime, GenMsgSendType, VFrameFormat
 * (StandardCAN, ExtendedCAN, StandardCAN_FD, ExtendedCAN_FD), CANFD_BRS,
 * value tables (VAL_) for the enumerations and comments (CM_) naming each
 * signal's field, element and RealTime column.
 *
 * The frames it receives, each [input NAME], follow the heartbeat: a BO_
 * whose transmitter is the PLC ([can] receiver, or Vector__XXX, "no
 * node"), its signals received by the gateway's node (BU_ names both), with
 * the same SG_ syntax, VFrameFormat and CANFD_BRS, GenMsgSendType Cyclic and
 * no GenMsgCycleTime (the PLC picks its period: see put_attributes), and
 * comments naming the register each signal writes, the frame's timeout_ms
 * and on_silence.
 */
#ifndef URRT_GATEWAY_DBC_H
#define URRT_GATEWAY_DBC_H

#include <stdio.h>

#include "can_map.h"

/*
 * Writes the DBC for a map that can_map_finish accepted. source names the
 * configuration in the header comment (NULL: none). Returns 0, or -1 when
 * the map is not finished or writing failed (errno from the stream).
 */
int dbc_write(FILE *out, const struct can_map *map, const char *source);

/* The value written for a number: the shortest decimal that reads back as
 * the same double ("0.1", "1e-05", "-3276.8"). buf of at least 32 bytes. */
const char *dbc_number(double value, char *buf, size_t size);

#endif /* URRT_GATEWAY_DBC_H */
