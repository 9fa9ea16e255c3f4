/* SPDX-License-Identifier: MIT */
/* can_replay.c: see can_replay.h. */
#include "can_replay.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "port.h"

/* A received frame of the rx log, on the capture's clock. */
struct rx_frame {
    uint64_t t_us;
    urrt_can_frame frame;
};

struct replay {
    struct can_run *run;
    urrt_co *node;         /* the CANopen node over run's core, or NULL */
    uint64_t node_us;      /* the node's latest run: its time never goes back */
    bool started;
    FILE *rx;              /* received frames (candump -l lines), or NULL */
    const char *rx_path;
    struct rx_frame next;  /* the rx log's next frame, valid while has_next */
    bool has_next;
    uint64_t rx_frames;
    uint64_t rx_bad;       /* lines that are not a frame: skipped */
    urrt_canlink *link;
    urrt_state state;
    uint64_t packets;
    uint64_t undated;      /* packets without a usable controller time: skipped */
    uint64_t frames;
    uint64_t refused;
};

static void emit(void *ctx, const urrt_can_frame *frame, uint64_t now_us)
{
    struct replay *r = ctx;
    if (urrt_canlink_send(r->link, frame, now_us) < 0) {
        r->refused++;
    } else {
        r->frames++;
    }
}

/* The node at each of its deadlines before until_us: heartbeats, EMCYs,
 * TPDOs, as a loop waking at each would have sent them. */
static void node_catch_up(struct replay *r, uint64_t until_us)
{
    for (;;) {
        uint64_t due = urrt_co_deadline(r->node);
        due = due < r->node_us ? r->node_us : due;
        if (due >= until_us) {
            return;
        }
        urrt_co_run(r->node, due, emit, r);
        if (due == r->node_us && urrt_co_deadline(r->node) <= due) {
            return; /* nothing left at this instant that time would change */
        }
        r->node_us = due;
    }
}

/* "(SEC.USEC) IFACE ID#DATA" (candump -l): false for anything else (RTR, FD, a comment). */
static bool parse_rx_line(const char *line, struct rx_frame *out)
{
    unsigned long long sec, usec;
    char id_text[16], data[2 * URRT_CAN_CLASSIC_MAX_LEN + 2];
    int used = 0;
    size_t len;
    memset(out, 0, sizeof *out);
    if (sscanf(line, " (%llu.%6llu) %*s %15[0-9A-Fa-f]#%n", &sec, &usec, id_text, &used) != 3 || used == 0) {
        return false;
    }
    data[0] = '\0';
    (void)sscanf(line + used, "%17[0-9A-Fa-f]", data);
    len = strlen(data);
    if (len % 2 != 0 || len > 2 * URRT_CAN_CLASSIC_MAX_LEN) {
        return false;
    }
    out->t_us = (uint64_t)sec * 1000000u + usec;
    out->frame.id = (uint32_t)strtoul(id_text, NULL, 16);
    out->frame.extended = strlen(id_text) > 3;
    out->frame.len = (uint8_t)(len / 2);
    for (size_t i = 0; i < out->frame.len; i++) {
        char byte[3] = {data[2 * i], data[2 * i + 1], '\0'};
        out->frame.data[i] = (uint8_t)strtoul(byte, NULL, 16);
    }
    return true;
}

static void rx_advance(struct replay *r)
{
    char line[256];
    r->has_next = false;
    while (r->rx != NULL && fgets(line, sizeof line, r->rx) != NULL) {
        if (parse_rx_line(line, &r->next)) {
            r->has_next = true;
            return;
        }
        r->rx_bad += line[strspn(line, " \t\r\n")] != '\0' && line[0] != '#';
    }
}

/* The frames received up to t_us, each at its own time, after what the node
 * would have sent before it. Frames before the first packet wait for the boot. */
static void rx_until(struct replay *r, uint64_t t_us)
{
    while (r->has_next && r->next.t_us <= t_us) {
        uint64_t at = r->next.t_us < r->node_us ? r->node_us : r->next.t_us;
        node_catch_up(r, at);
        urrt_co_on_frame(r->node, r->next.frame.id, r->next.frame.extended ? URRT_CO_RX_EXTENDED : 0u,
                         r->next.frame.data, r->next.frame.len, at, emit, r);
        r->node_us = at;
        r->rx_frames++;
        rx_advance(r);
    }
}

static void packet_at(struct replay *r, uint64_t t_us)
{
    if (r->node == NULL) {
        /* What a gateway waking at each deadline would have sent until now. */
        urrt_cantx_catch_up(can_run_tx(r->run), t_us, emit, r);
        urrt_cantx_on_packet(can_run_tx(r->run), 0, &r->state, t_us);
        can_run_due(r->run, t_us, urrt_canlink_get_stats(r->link), emit, r);
        return;
    }
    if (!r->started) {
        r->started = true; /* the node boots at the capture's first packet */
        r->node_us = t_us;
        urrt_co_start(r->node, t_us, emit, r);
    }
    rx_until(r, t_us);
    node_catch_up(r, t_us);
    urrt_cantx_on_packet(can_run_tx(r->run), 0, &r->state, t_us);
    can_run_set_link(r->run, urrt_canlink_get_stats(r->link));
    urrt_co_run(r->node, t_us, emit, r);
    r->node_us = t_us;
}

/* One packet at its own time: what a firmware does with each packet. */
static void on_packet(struct replay *r, const uint8_t *pkt, size_t len)
{
    int64_t t_us;
    r->packets++;
    if (urrt_decode(pkt, len, &r->state) < 0 || !urrt_has(&r->state, URRT_F_TIME) ||
        urrt_time_us(r->state.time[0], &t_us) != URRT_OK) {
        r->undated++;
        return;
    }
    packet_at(r, (uint64_t)t_us);
}

static int pump(struct replay *r, FILE *in, const char *path)
{
    static urrt_framer framer; /* 2 KiB: not on the stack */
    uint8_t buf[4096];
    size_t n;
    urrt_framer_init(&framer);
    while ((n = fread(buf, 1, sizeof buf, in)) > 0) {
        const uint8_t *p = buf;
        while (n > 0) {
            size_t used = 0;
            if (urrt_framer_feed(&framer, p, n, &used) > 0) {
                size_t len;
                const uint8_t *pkt = urrt_framer_packet(&framer, &len);
                on_packet(r, pkt, len);
            }
            p += used;
            n -= used;
        }
    }
    if (ferror(in)) {
        urrt_log(URRT_LOG_ERR, "reading %s failed: %s", path, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    if (urrt_framer_finish(&framer) > 0) {
        urrt_log(URRT_LOG_WARNING, "%s ends inside a packet: its last bytes were not a whole packet", path);
    }
    return CLI_EXIT_OK;
}

static bool open_rx(struct replay *r, const char *rx_path)
{
    if (rx_path == NULL) {
        return true;
    }
    if (r->node == NULL) {
        urrt_log(URRT_LOG_ERR, "--replay-rx feeds a CANopen node: the configuration has no [canopen] section");
        return false;
    }
    if ((r->rx = fopen(rx_path, "r")) == NULL) {
        urrt_log(URRT_LOG_ERR, "cannot open the received frames %s: %s", rx_path, strerror(errno));
        return false;
    }
    r->rx_path = rx_path;
    rx_advance(r);
    return true;
}

int can_replay(const struct can_map *map, struct can_run *run, struct co_run *node, const char *capture_path,
               const char *rx_path)
{
    struct replay r;
    urrt_canlink_config cfg;
    FILE *in;
    int rc;
    memset(&r, 0, sizeof r);
    r.run = run;
    r.node = node != NULL ? co_run_node(node) : NULL;
    if (run == NULL) {
        urrt_log(URRT_LOG_ERR, "--replay needs a [can] section and [frame NAME]s in the configuration");
        return CLI_EXIT_USAGE;
    }
    if (!open_rx(&r, rx_path)) {
        return r.node == NULL ? CLI_EXIT_USAGE : CLI_EXIT_RUNTIME;
    }
    if ((in = fopen(capture_path, "rb")) == NULL) {
        urrt_log(URRT_LOG_ERR, "cannot open the capture %s: %s", capture_path, strerror(errno));
        if (r.rx != NULL) {
            fclose(r.rx);
        }
        return CLI_EXIT_RUNTIME;
    }
    urrt_canlink_config_defaults(&cfg);
    can_map_link_config(map, &cfg);
    cfg.log_caller_clock = true; /* each frame at its time on the capture's clock */
    if ((r.link = urrt_canlink_new(&cfg)) == NULL) {
        fclose(in);
        if (r.rx != NULL) {
            fclose(r.rx);
        }
        return CLI_EXIT_RUNTIME;
    }
    rc = pump(&r, in, capture_path);
    fclose(in);
    if (r.rx != NULL) {
        if (r.has_next) {
            urrt_log(URRT_LOG_WARNING, "%s: frames after the capture's last packet were not fed", r.rx_path);
        }
        urrt_log(URRT_LOG_NOTICE, "fed %llu received frames from %s (%llu lines not a classic frame, skipped)",
                 (unsigned long long)r.rx_frames, r.rx_path, (unsigned long long)r.rx_bad);
        fclose(r.rx);
    }
    urrt_canlink_free(r.link);
    urrt_log(URRT_LOG_NOTICE, "replayed %s: %llu packets (%llu without a controller time, skipped), %llu frames sent%s",
             capture_path, (unsigned long long)r.packets, (unsigned long long)r.undated,
             (unsigned long long)r.frames, r.refused ? ", some refused by the link (see above)" : "");
    return r.refused ? CLI_EXIT_RUNTIME : rc;
}
