/* SPDX-License-Identifier: MIT */
/*
 * Not for callers: the seam between lib/urrt_co.c (the node) and
 * lib/urrt_co_rx.c (its receiving side: RPDOs and the consumer heartbeat).
 * urrt_co.c reaches the receiving side only through urrt_co.rx, the const
 * table of functions urrt_co_init_rx installs (NULL after urrt_co_init), so
 * that a firmware that never calls urrt_co_init_rx links none of
 * urrt_co_rx.c (--gc-sections): "this node cannot receive PDOs" is a
 * property of the link map.
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

/* Conditions: bit i of urrt_co.active, with its EMCY code and error
 * register bits; the receiving side's after the five of urrt_co.h, one per
 * 0x1016 entry or RPDO. */
enum {
    URRT_CO_COND_HEARTBEAT = URRT_CO_CONDITIONS,                             /* + 0x1016 entry */
    URRT_CO_COND_LENGTH = URRT_CO_COND_HEARTBEAT + URRT_CO_MAX_CONSUMERS,    /* + RPDO */
    URRT_CO_COND_TIMEOUT = URRT_CO_COND_LENGTH + URRT_CO_MAX_RPDOS,          /* + RPDO */
    URRT_CO_COND_ALL = URRT_CO_COND_TIMEOUT + URRT_CO_MAX_RPDOS
};
#define URRT_CO_BASE_CONDITIONS ((UINT32_C(1) << URRT_CO_CONDITIONS) - 1u)

/* The receiving side, as urrt_co.c calls it (urrt_co_rx.c's table). */
struct urrt_co_rx_ops {
    /* urrt_co_init_rx's checks, in urrt_co_init's order: the storage, then the description. */
    bool (*missing)(const urrt_co_desc *d, const urrt_co_rx_storage *rx);
    int (*check)(const urrt_co_desc *d, size_t *bad);
    /* urrt_co_init_rx's storage, bound once the checks passed; the defaults set. */
    void (*bind)(urrt_co *co, const urrt_co_rx_storage *rx, size_t var_count);
    /* A reset (whole_node: reset node, written_us too). */
    void (*reset)(urrt_co *co, bool boot, bool whole_node);
    void (*nmt)(urrt_co *co, urrt_co_nmt state);              /* before the node enters `state` */
    void (*frame)(urrt_co *co, uint32_t id, const uint8_t *data, size_t len, uint64_t now_us); /* not NMT/SYNC/SDO */
    void (*sync)(urrt_co *co, uint64_t now_us);               /* a SYNC in OPERATIONAL, before the TPDOs */
    uint32_t (*conditions)(urrt_co *co, uint64_t now_us);     /* its bits of urrt_co.active now */
    uint32_t (*emcy)(unsigned condition);                     /* its code | byte 5 << 16 */
    uint64_t (*deadline)(const urrt_co *co);
    size_t (*ids)(const urrt_co *co, uint32_t *ids);          /* after NMT, SYNC, SDO */
    urrt_co_read_fn read_rpdo_map;                            /* 0x1600+n */
    urrt_co_read_fn read_consumer;                            /* 0x1016 sub 1.. */
    urrt_co_write_fn write_rpdo;                              /* 0x1400+n sub 1, 2, 5 */
    urrt_co_write_fn write_consumer;                          /* 0x1016 sub 1.. */
};

/* urrt_co_init and urrt_co_init_rx (ops NULL: none, and rx unused). */
int urrt_co_init_with(urrt_co *co, const urrt_co_desc *desc, urrt_cantx *tx, urrt_co_tpdo_state *tpdo_states,
                      uint32_t *vars, size_t var_count, const struct urrt_co_rx_ops *ops,
                      const urrt_co_rx_storage *rx, size_t *bad_item);
/* A COB-ID with a "not valid" bit 31: 0 or URRT_CO_ABORT_VALUE (see urrt_co.c). */
uint32_t urrt_co_cob_check(uint32_t old, uint32_t value, uint32_t also_allowed);
/* A value outside low..high of the type: URRT_CO_ABORT_TOO_LOW or _TOO_HIGH; else 0. */
uint32_t urrt_co_range_check(uint32_t value, uint8_t type, uint32_t low, uint32_t high);

static inline uint64_t urrt_co_min64(uint64_t a, uint64_t b)
{
    return a < b ? a : b;
}

static inline bool urrt_co_cob_valid(uint32_t cob)
{
    return (cob & URRT_CO_COB_INVALID) == 0u;
}

static inline uint32_t urrt_co_type_size(uint8_t type)
{
    switch (type) {
    case URRT_CO_INTEGER8:
    case URRT_CO_UNSIGNED8: return 1;
    case URRT_CO_INTEGER16:
    case URRT_CO_UNSIGNED16: return 2;
    case URRT_CO_INTEGER32:
    case URRT_CO_UNSIGNED32:
    case URRT_CO_REAL32: return 4;
    default: return 0;
    }
}

/* A number: its size is its row's type's (urrt_co_comm_read). */
static inline uint32_t urrt_co_value_of(urrt_co_value *v, uint32_t value)
{
    v->value = value;
    v->text = NULL;
    return 0;
}

/* A variable stored by an RPDO or an SDO write: when, for the caller. */
static inline void urrt_co_var_store(urrt_co *co, uint16_t item, uint32_t value, uint64_t now_us)
{
    co->vars[item] = value;
    if (co->written_us != NULL) {
        co->written_us[item] = now_us;
    }
}

#endif /* URRT_CO_INTERNAL_H */
