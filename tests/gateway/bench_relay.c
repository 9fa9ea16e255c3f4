/* SPDX-License-Identifier: MIT */
/*
 * bench_relay: the floor under urrt-gateway in bench-gateway. It reads the
 * robot's TCP stream, frames it with lib's framer and publishes each packet's
 * raw bytes once per message the gateway would send, and does nothing else:
 * no decode, no encode, no clocks, no checks.
 *
 *   bench_relay HOST PORT LCM_URL PREFIX EVERY KIND...
 *
 * Every EVERY-th packet (1: each) goes out on PREFIX.KIND for each KIND, in
 * the order given. Ends at end of stream or on SIGTERM.
 */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <lcm/lcm.h>

#include "urrt.h"

#define MAX_KINDS 4

int main(int argc, char **argv)
{
    if (argc < 7 || argc - 6 > MAX_KINDS) {
        fprintf(stderr, "usage: bench_relay HOST PORT LCM_URL PREFIX EVERY KIND...\n");
        return 2;
    }
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)atoi(argv[2]))};
    long every = atol(argv[5]);
    int kinds = argc - 6;
    char channel[MAX_KINDS][96];
    for (int k = 0; k < kinds; k++) {
        snprintf(channel[k], sizeof channel[k], "%s.%s", argv[4], argv[6 + k]);
    }
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    lcm_t *lcm = lcm_create(argv[3]);
    if (inet_pton(AF_INET, argv[1], &a.sin_addr) != 1 || every < 1 || lcm == NULL ||
        connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        perror("bench_relay");
        return 1;
    }
    static urrt_framer fr;
    static uint8_t buf[65536];
    long count = 0;
    urrt_framer_init(&fr);
    for (ssize_t n; (n = read(fd, buf, sizeof buf)) > 0;) {
        const uint8_t *p = buf;
        size_t left = (size_t)n;
        while (left > 0) {
            size_t used, len;
            if (urrt_framer_feed(&fr, p, left, &used) > 0 && count++ % every == 0) {
                const uint8_t *pkt = urrt_framer_packet(&fr, &len);
                for (int k = 0; k < kinds; k++) {
                    lcm_publish(lcm, channel[k], pkt, (unsigned)len);
                }
            }
            p += used;
            left -= used;
        }
    }
    lcm_destroy(lcm);
    return 0;
}
