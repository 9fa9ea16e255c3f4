/* SPDX-License-Identifier: MIT */
/*
 * Not for callers: the seam between lib/urrt_co.c (the node) and
 * lib/urrt_co_rx.c (its receiving side: RPDOs and the consumer heartbeat).
 * urrt_co.c reaches the receiving side only through urrt_co.rx, the const
 * table of functions urrt_co_init_rx installs (NULL after urrt_co_init), so
 * that a firmware that never calls urrt_co_init_rx links none of
 * urrt_co_rx.c (--gc-sections): "this node cannot receive PDOs" is a
 * property of the link map. The receiving side keeps its state in the
 * caller's urrt_co_rx_storage (urrt_co.rx_storage). What a node without
 * RPDOs pays for the seam is one test of urrt_co.rx where urrt_co.c calls a
 * function below.
 */
#ifndef URRT_CO_INTERNAL_H
#define URRT_CO_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "urrt_co.h"

#define URRT_CO_NONE SIZE_MAX
#define URRT_CO_MAX_NODE_ID 127u
#define URRT_CO_ID_MASK 0x7FFu
#define URRT_CO_COB_NO_RTR UINT32_C(0x40000000) /* PDO COB-ID bit 30: no RTR allowed (the node serves none) */
#define URRT_CO_NMT_EC_BASE 0x700u              /* boot-up and heartbeat */
#define URRT_CO_SYNC_MAX_N 240u                 /* transmission types 1..240: every nth SYNC (RPDO: 0..240) */
#define URRT_CO_TYPE_EVENT 254u                 /* 254, 255: the event timer */
/* Bit URRT_CO_CONDITIONS of urrt_co.active and .reported: a condition of the
 * receiving side is active (its own are urrt_co_rx_storage.active), so that
 * the error register (bit 4) holds it; set in both, so that the node's EMCYs
 * leave it to the receiving side's. */
#define URRT_CO_RX_ACTIVE (1u << URRT_CO_CONDITIONS)

/* The receiving side, as urrt_co.c calls it (urrt_co_rx.c's table). */
struct urrt_co_rx_ops {
    /* urrt_co_init_rx's checks of its part of the description, after the node's. */
    int (*check)(const urrt_co_desc *d, size_t *bad);
    /* Once every check passed (urrt_co.rx_storage set): its defaults. */
    void (*bind)(urrt_co *co, size_t var_count);
    /* A reset (whole_node: reset node, written_us too), before the boot-up. */
    void (*reset)(urrt_co *co, bool whole_node);
    void (*nmt)(urrt_co *co, urrt_co_nmt state); /* before the node enters `state` */
    /* Every frame but NMT's, in PRE-OPERATIONAL and OPERATIONAL, before the
     * node's own handling: RPDOs, heartbeats, and at a SYNC the synchronous
     * RPDOs kept since the last (before the node's TPDOs). */
    void (*frame)(urrt_co *co, uint32_t id, const uint8_t *data, size_t len, uint64_t now_us);
    /* urrt_co_run, after the node's conditions: its own (0x1003, urrt_co.active's bit). */
    void (*conditions)(urrt_co *co, uint64_t now_us);
    /* urrt_co_run, after the node's EMCYs: its own, as the inhibit time allows. */
    size_t (*emcy)(urrt_co *co, urrt_cantx_emit_fn emit, void *ctx, uint64_t now_us);
    uint64_t (*deadline)(const urrt_co *co);              /* its deadlines, its EMCYs due */
    size_t (*ids)(const urrt_co *co, uint32_t *ids);      /* after NMT, SYNC, SDO */
    /* The SDO server's lookup in its rows (index, sub): 0 with the row and
     * its instance, or URRT_CO_ABORT_NO_OBJECT, _NO_SUB. */
    uint32_t (*find)(const urrt_co *co, uint16_t index, uint8_t sub, const urrt_co_comm **row, size_t *n);
    void (*written)(urrt_co *co, uint16_t item, uint64_t now_us); /* an SDO write stored vars[item]: when */
    /* What urrt_co_comm_table's rows of the receiving side read and write through. */
    urrt_co_read_fn read_consumer;                        /* 0x1016 sub 1.. */
    urrt_co_write_fn write_consumer;
    urrt_co_read_fn read_rpdo;                            /* 0x1400+n sub 1, 2, 5 */
    urrt_co_write_fn write_rpdo;
    urrt_co_read_fn read_rpdo_map;                        /* 0x1600+n */
};

/* urrt_co_init_rx: urrt_co_init with the receiving side (ops, and its storage rx). */
int urrt_co_init_with(urrt_co *co, const urrt_co_desc *desc, urrt_cantx *tx, urrt_co_tpdo_state *tpdo_states,
                      uint32_t *vars, size_t var_count, const struct urrt_co_rx_ops *ops, urrt_co_rx_storage *rx,
                      size_t *bad_item);
/* A COB-ID with a "not valid" bit 31: 0 or URRT_CO_ABORT_VALUE (see urrt_co.c). */
uint32_t urrt_co_cob_check(uint32_t old, uint32_t value, uint32_t also_allowed);
/* The bytes of a value of the type: 1, 2, 4; 0 for a type the node does not take. */
uint32_t urrt_co_type_size(uint8_t type);
/* A value outside low..high of the type: URRT_CO_ABORT_TOO_LOW or _TOO_HIGH; else 0. */
uint32_t urrt_co_range_check(uint32_t value, uint8_t type, uint32_t low, uint32_t high);
/* An order-keeping unsigned key for a value of `bytes` bytes (1, 2, 4): a
 * signed value's bits (those of its size; higher ones ignored) with its
 * sign bit flipped compare as unsigned ones do (no implementation-defined
 * conversion to int32_t): shifted up to bit 31, flipped there, shifted back
 * down. An unsigned value is its own key. Keys are compared only with keys
 * of the same type. Inline: the RPDO path checks each value it receives. */
static inline uint32_t urrt_co_order_key(uint32_t raw, bool is_signed, uint32_t bytes)
{
    uint32_t shift = 32u - 8u * bytes; /* 24, 16, 0 */
    return is_signed ? ((raw << shift) ^ UINT32_C(0x80000000)) >> shift : raw;
}
static inline bool urrt_co_type_signed(uint8_t type)
{
    return type == URRT_CO_INTEGER8 || type == URRT_CO_INTEGER16 || type == URRT_CO_INTEGER32;
}
/* The EMCY of a condition of the receiving side that started (or ended:
 * the reset naming the code), as the node's are sent: emcy is the code, and
 * in bits 16..23 its manufacturer byte 5 (the 0x1016 entry or RPDO). */
size_t urrt_co_emcy_send(urrt_co *co, uint32_t emcy, bool started, uint64_t now_us, urrt_cantx_emit_fn emit,
                         void *ctx);

/* When the inhibit time (0x1015) lets the next EMCY go. */
uint64_t urrt_co_emcy_due(const urrt_co *co);

/*
 * The communication objects (0x1000-0x1FFF), one line each, written once and
 * expanded (nanopb's X-macros): urrt_co.c into the node's rows (the SDO
 * server's), urrt_co_comm_table (every row), the names (which only
 * urrt_co_comm_name reads) and the limits; urrt_co_rx.c into the receiving
 * side's rows (its part of the SDO server). HEAD and ROW are the node's,
 * RX_HEAD and RX_ROW the receiving side's, in index order among them.
 *   HEAD(index, object, flags, name)  an ARRAY or RECORD; the rows of its index follow
 *   ROW(index, sub, subs, object, type, in, what, write, flags, name)
 *       in FN: `what` is the read function; NODE, DESC, TPDO: `what` is the
 *       member of urrt_co, urrt_co_desc or TPDO n's urrt_co_tpdo_state that
 *       holds the value (read as the type); CONST: `what` is the value
 *   LIMITED(the ROW's columns, low, high)  a ROW whose writes outside low..high are refused
 *   RX_HEAD, RX_ROW: HEAD's and ROW's columns (FN, DESC or CONST; no limits)
 */
#define URRT_CO_COMM_LIST(HEAD, ROW, LIMITED, RX_HEAD, RX_ROW)                                                       \
    ROW(0x1000, 0, 1, VAR, U32, DESC, device_type, NULL, 0, "Device type")                                          \
    ROW(0x1001, 0, 1, VAR, U8, FN, read_error_register, NULL, 0, "Error register")                                  \
    HEAD(0x1003, ARRAY, 0, "Pre-defined error field")                                                               \
    ROW(0x1003, 0, 1, SUB, U8, NODE, error_count, write_errors, 0, "Number of errors")                              \
    ROW(0x1003, 1, URRT_CO_HISTORY, SUB, U32, FN, read_errors, NULL, 0, "Standard error field")                     \
    ROW(0x1005, 0, 1, VAR, U32, NODE, sync_cob_id, write_sync, 0, "COB-ID SYNC")                                    \
    ROW(0x1008, 0, 1, VAR, TEXT, DESC, device_name, NULL, 0, "Manufacturer device name")                            \
    ROW(0x1009, 0, 1, VAR, TEXT, DESC, hardware_version, NULL, 0, "Manufacturer hardware version")                  \
    ROW(0x100A, 0, 1, VAR, TEXT, DESC, software_version, NULL, 0, "Manufacturer software version")                  \
    ROW(0x1014, 0, 1, VAR, U32, NODE, emcy_cob_id, write_emcy, NODE_ID, "COB-ID EMCY")                              \
    ROW(0x1015, 0, 1, VAR, U16, NODE, emcy_inhibit_100us, write_emcy_inhibit, 0, "Inhibit time EMCY")               \
    RX_HEAD(0x1016, ARRAY, IF_CONSUMERS, "Consumer heartbeat time")                                                 \
    RX_ROW(0x1016, 0, 1, SUB, U8, DESC, consumer_count, NULL, IF_CONSUMERS, "Highest sub-index supported")          \
    RX_ROW(0x1016, 1, URRT_CO_MAX_CONSUMERS, SUB, U32, FN, read_consumer, write_consumer, IF_CONSUMERS,             \
           "Consumer heartbeat time")                                                                               \
    ROW(0x1017, 0, 1, VAR, U16, NODE, heartbeat_ms, write_heartbeat, 0, "Producer heartbeat time")                  \
    HEAD(0x1018, RECORD, 0, "Identity object")                                                                      \
    ROW(0x1018, 0, 1, SUB, U8, CONST, 4, NULL, 0, "Highest sub-index supported")                                    \
    ROW(0x1018, 1, 1, SUB, U32, DESC, vendor_id, NULL, 0, "Vendor-ID")                                              \
    ROW(0x1018, 2, 1, SUB, U32, DESC, product_code, NULL, 0, "Product code")                                        \
    ROW(0x1018, 3, 1, SUB, U32, DESC, revision, NULL, 0, "Revision number")                                         \
    ROW(0x1018, 4, 1, SUB, U32, DESC, serial, NULL, 0, "Serial number")                                             \
    RX_HEAD(0x1400, RECORD, PER_RPDO, "RPDO communication parameter")                                               \
    /* sub 0: the highest sub-index (3 and 4 are not an RPDO's) */                                                  \
    RX_ROW(0x1400, 0, 1, SUB, U8, CONST, 5, NULL, PER_RPDO, "Highest sub-index supported")                          \
    RX_ROW(0x1400, 1, 1, SUB, U32, FN, read_rpdo, write_rpdo, PER_RPDO | NODE_ID, "COB-ID used by RPDO")            \
    /* 0..240 (at the next SYNC), 254, 255; 241..253 are refused by its write */                                   \
    RX_ROW(0x1400, 2, 1, SUB, U8, FN, read_rpdo, write_rpdo, PER_RPDO, "Transmission type")                         \
    RX_ROW(0x1400, 5, 1, SUB, U16, FN, read_rpdo, write_rpdo, PER_RPDO, "Event timer")                              \
    RX_HEAD(0x1600, RECORD, PER_RPDO, "RPDO mapping parameter")                                                     \
    RX_ROW(0x1600, 0, 1, SUB, U8, FN, read_rpdo_map, NULL, PER_RPDO, "Number of mapped objects")                    \
    RX_ROW(0x1600, 1, URRT_CO_RPDO_MAX_MAPPED, SUB, U32, FN, read_rpdo_map, NULL, PER_RPDO, "Mapped object")        \
    HEAD(0x1800, RECORD, PER_TPDO, "TPDO communication parameter")                                                  \
    /* sub 0: the highest sub-index (4 is reserved, 6 unsupported) */                                               \
    ROW(0x1800, 0, 1, SUB, U8, CONST, 5, NULL, PER_TPDO, "Highest sub-index supported")                             \
    ROW(0x1800, 1, 1, SUB, U32, TPDO, cob_id, tpdo_write, PER_TPDO | NODE_ID, "COB-ID used by TPDO")                \
    /* 1..240 (every nth SYNC), 254, 255; 241..253 are refused by tpdo_write */                                     \
    LIMITED(0x1800, 2, 1, SUB, U8, TPDO, type, tpdo_write, PER_TPDO, "Transmission type", 1, 0xFF)                  \
    ROW(0x1800, 3, 1, SUB, U16, TPDO, inhibit_100us, tpdo_write, PER_TPDO, "Inhibit time")                          \
    ROW(0x1800, 5, 1, SUB, U16, TPDO, event_ms, tpdo_write, PER_TPDO, "Event timer")                                \
    HEAD(0x1A00, RECORD, PER_TPDO, "TPDO mapping parameter")                                                        \
    ROW(0x1A00, 0, 1, SUB, U8, FN, read_tpdo_map, NULL, PER_TPDO, "Number of mapped objects")                       \
    ROW(0x1A00, 1, URRT_CO_MAX_MAPPED, SUB, U32, FN, read_tpdo_map, NULL, PER_TPDO, "Mapped object")

#endif /* URRT_CO_INTERNAL_H */
