/* SPDX-License-Identifier: MIT */
/*
 * bench-can (make bench): what the CAN mapping costs per robot packet, beside
 * what decoding that packet costs in the same run (urrt_decode of a 1220-byte
 * packet), as ns and as a ratio. Prints `name: value` lines, asserts nothing.
 *
 *   can_pack_signal_ns      one 16-bit signal, urrt_can_pack
 *   can_map_packet_ns       urrt_cantx_on_packet + can_run_due for docs/examples/canopen.ini
 *                           (4 frames, 18 signals, heartbeat) at 500 Hz: the values
 *                           taken at every packet, each frame packed and sent at its
 *                           period (can_frames_per_packet)
 *   decode_packet_ns        urrt_decode, the baseline
 *
 * Each figure is the best of several batches, subject and baseline
 * alternating, so that both see the same machine.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gateway/bench.h"
#include "can_run.h"
#include "config.h"

#define BATCHES 9
#define ITERATIONS 20000

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : "docs/examples/canopen.ini";
    gw_config cfg;
    struct can_run *run;
    urrt_state st;
    uint8_t packet[URRT_PACKET_KNOWN_MAX];
    urrt_can_signal sig = {0.0002, 0, -6.5536, 6.5534, 0, 0, 16, URRT_CAN_INTEL, URRT_CAN_SIGNED, 0};
    uint8_t data[8] = {0};
    double best_map = 1e30, best_decode = 1e30, best_pack = 1e30;
    uint64_t now = 0;
    uint64_t frames = 0;
    int b, i;

    /* Loaded as the gateway loads it: its robot (version auto) sends at 500 Hz. */
    if (gw_config_load(&cfg, path, stderr) != 0 || (run = cfg.can_run) == NULL) {
        fprintf(stderr, "bench-can: %s: not a valid configuration with CAN frames\n", path);
        gw_config_free(&cfg);
        return 1;
    }
    if (bench_packet(&st, packet, sizeof packet) < 0) {
        fprintf(stderr, "bench-can: cannot build a packet\n");
        gw_config_free(&cfg);
        return 1;
    }
    can_run_start(run, 0);
    for (b = 0; b < BATCHES; b++) {
        double t0 = now_ns();
        for (i = 0; i < ITERATIONS; i++) {
            now += 2000; /* 500 Hz */
            urrt_cantx_on_packet(can_run_tx(run), 0, &st, now);
            can_run_due(run, now, NULL, count_frame, &frames);
        }
        double t1 = now_ns();
        for (i = 0; i < ITERATIONS; i++) {
            sink += (uint64_t)urrt_decode(packet, BENCH_PACKET_LEN, &st);
        }
        double t2 = now_ns();
        for (i = 0; i < ITERATIONS; i++) {
            sink += (uint64_t)urrt_can_pack(&sig, (double)i * 1e-4, data, 8) + data[1];
        }
        double t3 = now_ns();
        best_map = (t1 - t0) / ITERATIONS < best_map ? (t1 - t0) / ITERATIONS : best_map;
        best_decode = (t2 - t1) / ITERATIONS < best_decode ? (t2 - t1) / ITERATIONS : best_decode;
        best_pack = (t3 - t2) / ITERATIONS < best_pack ? (t3 - t2) / ITERATIONS : best_pack;
    }
    sink += frames;
    printf("can_pack_signal_ns: %.1f\n", best_pack);
    printf("can_map_packet_ns: %.1f\n", best_map);
    printf("decode_packet_ns: %.1f\n", best_decode);
    printf("can_map_packet_vs_decode: %.2f\n", best_map / best_decode);
    printf("can_frames_per_packet: %.2f\n", (double)frames / (BATCHES * ITERATIONS));
    gw_config_free(&cfg);
    return 0;
}
