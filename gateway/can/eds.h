/* SPDX-License-Identifier: MIT */
/*
 * eds: `urrt-gateway --print-eds`, the Electronic Data Sheet (CiA 306,
 * version 4.0) of a configuration's CANopen node, written from the very
 * description the node runs on (co_run.h): the TPDOs, their mappings and
 * defaults, the manufacturer objects; with [input]s the RPDOs (NrOfRXPDO,
 * 0x1400+n, 0x1600+n: read-only, the mapping is static), the consumer
 * heartbeat 0x1016, and each [input] signal's variable (0x2200 + n - 1 sub
 * k + 1: AccessType rww, PDOMapping=1, LowLimit/HighLimit the raw range
 * the node stores, signed types in signed decimals). A PLC's CANopen
 * manager (CODESYS, TwinCAT, ...) imports it; it cannot disagree with the
 * node. A configuration without [input]s has none of the receiving side:
 * its EDS is what it was before RPDOs came, byte for byte.
 *
 * Where a PLC engineer sees the scaling: each mapped value's ParameterName
 * carries its physical meaning ("q0: q_actual[0], rad = raw x 0.0002"; an
 * [input]'s "job_number: input_int_register_24, 1 = raw x 1 + 0": the
 * register it writes), the name an import shows beside each PDO channel;
 * [Comments] repeats every value with its limits and the raw value that
 * means "not available", and each [input] register with the limits the
 * gateway writes it within (its min..max, narrowed to the object's range).
 */
#ifndef URRT_GATEWAY_EDS_H
#define URRT_GATEWAY_EDS_H

#include <stdio.h>

#include "can_map.h"
#include "canopen_map.h"
#include "co_run.h"

/* Writes the EDS (source: the configuration's name for FileInfo's
 * Description, NULL: none; file_name: the file it goes to, for FileName,
 * NULL: standard output, "urrt-nodeN.eds"). The communication objects are
 * lib/urrt_co's table (urrt_co_comm_table), their defaults read on the
 * node right after a reset, which eds_write does (silently). The dates are
 * SOURCE_DATE_EPOCH's when it is set. 0, or -1 when the stream failed. */
int eds_write(FILE *out, struct co_run *run, const struct canopen_map *co, const struct can_map *can,
              const char *source, const char *file_name);

#endif
