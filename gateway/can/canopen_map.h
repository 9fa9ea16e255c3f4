/* SPDX-License-Identifier: MIT */
/*
 * canopen_map: the configuration front end of urrt-gateway's CANopen node
 * (lib/urrt_co.h). The keys of [canopen] (node id, identity, strings, NMT
 * start, heartbeat) and the CANopen keys of a [frame NAME] (tpdo,
 * transmission, own_id), and the rules that make a CAN mapping (can_map.h)
 * a set of TPDOs: every [frame] is a TPDO, classic and 11-bit, whose
 * signals are Intel and byte-aligned, each owning the bytes of the object it
 * becomes; TPDO1..4's ids follow from the node id. It describes; co_run.h
 * builds the node. docs/canopen.md is the user's reference.
 *
 * Dependencies point one way: canopen_map uses can_map, never the reverse.
 *
 * Life cycle (the configuration loader, gateway/urrt-gateway/config.c):
 *   canopen_map_init(&co);
 *   a [canopen] section:  canopen_map_begin, then canopen_map_set per key
 *   a [frame NAME] key of canopen_map_frame_keys: canopen_map_frame_set
 *   canopen_map_prepare(&co, &can)    before can_map_finish: ids filled in
 *   can_map_finish(&can, ...)
 *   canopen_map_check(&co, &can)      after it: the PDO layout rules
 *   ... co_run_build ...
 *   canopen_map_free(&co);
 */
#ifndef URRT_GATEWAY_CANOPEN_MAP_H
#define URRT_GATEWAY_CANOPEN_MAP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "can_map.h"
#include "conf.h"
#include "urrt_co.h"

#define CANOPEN_TEXT_MAX 64           /* device name, hardware version, vendor name */
#define CANOPEN_MAX_TPDOS 512u
#define CANOPEN_STATUS_INDEX 0x2000u  /* the gateway's status: one sub per heartbeat signal */
#define CANOPEN_VALUES_INDEX 0x2100u  /* TPDO n's values: 0x2100 + n - 1, one sub per signal */
#define CANOPEN_INPUTS_INDEX 0x2200u  /* RPDO n's registers: 0x2200 + n - 1, one sub per signal, rww */
#define CANOPEN_DUMMY_U8 0x0005u      /* CiA 301's UNSIGNED8 dummy: a byte no signal owns */
#define CANOPEN_STATUS_ID_BASE 0x680u /* the status TPDO's id past TPDO4: 0x680 + node id */
/* The node's traffic beside its TPDOs in the worst-case bus load
 * (docs/canopen.md, "Bus load"): its heartbeat every heartbeat_ms (1 byte);
 * EMCYs (8 bytes), each of the node's conditions starting and ending once
 * a second; SDO, a manager's request and the node's answer (8 bytes each)
 * every CANOPEN_SDO_POLL_MS. The manager's SYNC is not the node's: not counted. */
#define CANOPEN_EMCY_PER_S (2.0 * URRT_CO_CONDITIONS)
#define CANOPEN_SDO_POLL_MS 10u

/* Keys of [canopen], in canopen_map_keys' order. */
enum canopen_key {
    CANOPEN_K_NODE_ID, CANOPEN_K_DEVICE_TYPE, CANOPEN_K_VENDOR_ID, CANOPEN_K_PRODUCT_CODE, CANOPEN_K_REVISION,
    CANOPEN_K_SERIAL, CANOPEN_K_VENDOR_NAME, CANOPEN_K_DEVICE_NAME, CANOPEN_K_HARDWARE_VERSION,
    CANOPEN_K_NMT_START, CANOPEN_K_HEARTBEAT, CANOPEN_K_SDO_TIMEOUT, CANOPEN_K_COUNT
};

/* CANopen keys of a [frame NAME], in canopen_map_frame_keys' order. */
enum canopen_frame_key { CANOPEN_FK_TPDO, CANOPEN_FK_TRANSMISSION, CANOPEN_FK_OWN_ID, CANOPEN_FK_COUNT };

struct canopen_frame {
    uint32_t tpdo;                  /* 1..512 as given; 0: its place among the [frame]s */
    uint32_t sync_every;            /* transmission = sync N: N (1..240); 0: event (type 254) */
    bool own_id;                    /* its id is its own, not the node's pre-defined COB-ID */
    struct can_map_loc key_loc[CANOPEN_FK_COUNT];
};

struct canopen_map {
    bool configured;                /* a [canopen] section was seen */
    struct can_map_loc loc;         /* its header */
    struct can_map_loc key_loc[CANOPEN_K_COUNT];
    uint32_t node_id;
    uint32_t device_type;
    uint32_t vendor_id;
    uint32_t product_code;
    uint32_t revision;
    uint32_t serial;
    char vendor_name[CANOPEN_TEXT_MAX + 1];
    char device_name[CANOPEN_TEXT_MAX + 1];
    char hardware_version[CANOPEN_TEXT_MAX + 1];
    uint8_t nmt_start;              /* URRT_CO_START_* */
    uint32_t heartbeat_ms;          /* 0x1017's default, 0: off */
    uint32_t sdo_timeout_ms;
    /* Per [frame], by its index in the can_map (grown as keys come). */
    struct canopen_frame *frames;
    size_t frame_count;
    /* Resolved by canopen_map_prepare. */
    uint16_t *tpdo_of;              /* per can_map frame: its TPDO number, 1.. */
    size_t tpdo_count;              /* the [frame]s' TPDOs; the status TPDO is number tpdo_count + 1 */
};

extern const struct conf_key canopen_map_keys[CANOPEN_K_COUNT];
extern const struct conf_key canopen_map_frame_keys[CANOPEN_FK_COUNT];

void canopen_map_init(struct canopen_map *co);
void canopen_map_free(struct canopen_map *co);
bool canopen_map_enabled(const struct canopen_map *co);

/* [canopen] begins; one of its keys; a CANopen key of [frame NAME] number
 * frame (its index in the can_map). false with the reason in why. */
void canopen_map_begin(struct canopen_map *co, struct conf_at at);
bool canopen_map_set(struct canopen_map *co, const struct conf_key *key, const char *value, struct conf_at at,
                     char *why, size_t n);
bool canopen_map_frame_set(struct canopen_map *co, size_t frame, const struct conf_key *key, const char *value,
                           struct conf_at at, char *why, size_t n);

/*
 * Before can_map_finish: TPDO numbers (unique, 1..n without a gap), each
 * frame's id from the node id (TPDO1..4: 0x180/0x280/0x380/0x480 + node id;
 * any other id needs own_id = yes), each [input] RPDO1..4 in order, its id
 * the RPDO's pre-defined one (0x200/0x300/0x400/0x500 + node id), the [can] keys a node replaces, the
 * status TPDO's id, and the node's heartbeat, EMCY and SDO as traffic for
 * the bus load (can_map_add_traffic; the parts named TPDOs and status TPDO).
 * Problems go to can's reporter. Returns the number found.
 */
int canopen_map_prepare(struct canopen_map *co, struct can_map *can);

/* Without [canopen]: each CANopen key of a [frame] is a problem. Returns
 * their number. */
int canopen_map_orphans(const struct canopen_map *co, const struct can_map *can);

/* After can_map_finish accepted can: each frame a classic 11-bit TPDO, and
 * each [input] an RPDO, of at most 8 bytes, each signal Intel,
 * byte-aligned, of an object type, its bytes its own (an RPDO's integers
 * only); with [input]s, at most 256 [frame]s (their values' indices end
 * below 0x2200). Returns the number of problems (to can's reporter). */
int canopen_map_check(const struct canopen_map *co, const struct can_map *can);

/* What a TPDO signal becomes: the object's type (URRT_CO_*) and size in
 * bytes, or false with the reason in why. */
bool canopen_signal_object(const urrt_can_signal *sig, const struct can_map_signal *meta, uint8_t *type,
                           unsigned *bytes, char *why, size_t n);

/* The pre-defined COB-ID of TPDO n (1..4) for the node; 0 past TPDO4. */
uint32_t canopen_predefined_tpdo_id(unsigned n, uint32_t node_id);
/* The pre-defined COB-ID of RPDO n (1..4) for the node; 0 past RPDO4. */
uint32_t canopen_predefined_rpdo_id(unsigned n, uint32_t node_id);

/* A CAN-ID CiA 301 keeps for NMT, SYNC, EMCY, SDO, heartbeat and LSS. */
bool canopen_id_restricted(uint32_t id);

/* "pre-operational" or "operational". */
const char *canopen_nmt_start_name(uint8_t start);

#endif /* URRT_GATEWAY_CANOPEN_MAP_H */
