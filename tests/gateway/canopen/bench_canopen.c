/* SPDX-License-Identifier: MIT */
/*
 * bench-co-gw (make bench): what the CANopen node (lib/urrt_co) costs the CPU
 * per frame it answers, beside what decoding one robot packet costs in the
 * same run (urrt_decode of a 1220-byte packet), as ns and as a ratio. For
 * docs/examples/canopen.ini's node, loaded as the gateway loads it. Prints
 * `name: value` lines, asserts nothing.
 *
 *   co_sdo_identity_ns   an SDO upload of 0x1018 sub 1 and its answer (expedited)
 *   co_sdo_value_ns      an SDO upload of 0x2100 sub 1, a robot value: its frame packed as it
 *                        would go out now (urrt_cantx_peek), the value read from it
 *   co_sdo_write_ns      an SDO download of 0x1017 (heartbeat time) and its answer
 *   co_sync_ns           a SYNC: the node's SYNC-driven TPDO (TPDO4, type 1) packed and sent
 *   decode_packet_ns     urrt_decode, the floor
 *
 * Each figure is the best of several batches, subject and floor alternating,
 * so that both see the same machine.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "gateway/bench.h"
#include "config.h"

#define BATCHES 9
#define ITERATIONS 20000
#define NODE_SDO_RX 0x605u
#define SYNC_ID 0x080u

struct subject {
    const char *name;
    uint32_t id;
    uint8_t len;
    uint8_t data[8];
    double best;
};

/* ITERATIONS frames of one kind: ns per frame. */
static double run_frames(urrt_co *node, const struct subject *s, uint64_t *now, uint64_t *frames)
{
    double t0 = now_ns();
    for (int i = 0; i < ITERATIONS; i++) {
        *now += 1; /* 20 ms a batch: the data stays fresh (stale after 100 ms), so SYNC sends */
        urrt_co_on_frame(node, s->id, 0, s->data, s->len, *now, count_frame, frames);
    }
    return (now_ns() - t0) / ITERATIONS;
}

static int load(const char *path, gw_config *cfg, urrt_state *st, uint8_t *packet, size_t size)
{
    if (gw_config_load(cfg, path, stderr) != 0 || cfg->co_run == NULL) {
        fprintf(stderr, "bench-co-gw: %s: not a valid configuration with [canopen]\n", path);
        return -1;
    }
    if (bench_packet(st, packet, size) < 0) {
        fprintf(stderr, "bench-co-gw: cannot build a packet\n");
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : "docs/examples/canopen.ini";
    struct subject subjects[] = {
        {"co_sdo_identity_ns", NODE_SDO_RX, 8, {0x40, 0x18, 0x10, 0x01, 0, 0, 0, 0}, 1e30},
        {"co_sdo_value_ns", NODE_SDO_RX, 8, {0x40, 0x00, 0x21, 0x01, 0, 0, 0, 0}, 1e30},
        {"co_sdo_write_ns", NODE_SDO_RX, 8, {0x2B, 0x17, 0x10, 0x00, 0xE8, 0x03, 0, 0}, 1e30},
        {"co_sync_ns", SYNC_ID, 0, {0}, 1e30},
    };
    size_t n_subjects = sizeof subjects / sizeof subjects[0];
    gw_config cfg;
    urrt_state st;
    uint8_t packet[URRT_PACKET_KNOWN_MAX];
    double best_decode = 1e30;
    uint64_t now = 0, frames = 0;
    urrt_co *node;
    if (load(path, &cfg, &st, packet, sizeof packet) != 0) {
        gw_config_free(&cfg);
        return 1;
    }
    node = co_run_node(cfg.co_run);
    urrt_co_start(node, now, count_frame, &frames);   /* canopen.ini starts itself: operational */
    urrt_cantx_on_packet(node->tx, 0, &st, now);       /* data, fresh for the whole run */
    for (int b = 0; b < BATCHES; b++) {
        for (size_t k = 0; k < n_subjects; k++) {
            double ns = run_frames(node, &subjects[k], &now, &frames);
            subjects[k].best = ns < subjects[k].best ? ns : subjects[k].best;
            urrt_cantx_on_packet(node->tx, 0, &st, now);
        }
        double t0 = now_ns();
        for (int i = 0; i < ITERATIONS; i++) {
            sink += (uint64_t)urrt_decode(packet, BENCH_PACKET_LEN, &st);
        }
        double decode = (now_ns() - t0) / ITERATIONS;
        best_decode = decode < best_decode ? decode : best_decode;
    }
    for (size_t k = 0; k < n_subjects; k++) {
        printf("%s: %.1f\n", subjects[k].name, subjects[k].best);
    }
    printf("decode_packet_ns: %.1f\n", best_decode);
    for (size_t k = 0; k < n_subjects; k++) {
        char name[64];
        snprintf(name, sizeof name, "%.*s", (int)(strlen(subjects[k].name) - 3), subjects[k].name);
        printf("%s_vs_decode: %.3f\n", name, subjects[k].best / best_decode);
    }
    printf("co_frames_answered: %llu\n", (unsigned long long)frames);
    gw_config_free(&cfg);
    return 0;
}
