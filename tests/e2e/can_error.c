/* SPDX-License-Identifier: MIT */
/*
 * can_error IFACE: writes one bus-off error frame on IFACE, as a CAN
 * controller's driver would report it. vcan has no controller, but every
 * socket subscribed to error frames on the interface receives it.
 */
#define _GNU_SOURCE
#include <linux/can.h>
#include <linux/can/error.h>
#include <net/if.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

int main(int argc, char **argv)
{
    struct sockaddr_can addr = {.can_family = AF_CAN};
    struct can_frame frame = {.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF, .len = CAN_ERR_DLC};
    int fd;

    if (argc != 2) {
        fprintf(stderr, "usage: can_error IFACE\n");
        return 2;
    }
    fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
    addr.can_ifindex = (int)if_nametoindex(argv[1]);
    if (fd < 0 || addr.can_ifindex == 0 || bind(fd, (struct sockaddr *)&addr, sizeof addr) != 0 ||
        write(fd, &frame, sizeof frame) != (ssize_t)sizeof frame) {
        perror("can_error");
        return 1;
    }
    close(fd);
    return 0;
}
