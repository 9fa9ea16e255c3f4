/* SPDX-License-Identifier: MIT */
/* can_replay.c: see can_replay.h. */
#include "can_replay.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "port.h"

struct replay {
    struct can_run *run;
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
    /* What a gateway waking at each deadline would have sent until now. */
    urrt_cantx_catch_up(can_run_tx(r->run), (uint64_t)t_us, emit, r);
    urrt_cantx_on_packet(can_run_tx(r->run), 0, &r->state, (uint64_t)t_us);
    can_run_due(r->run, (uint64_t)t_us, urrt_canlink_get_stats(r->link), emit, r);
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

int can_replay(const struct can_map *map, struct can_run *run, const char *capture_path)
{
    struct replay r;
    urrt_canlink_config cfg;
    FILE *in;
    int rc;
    memset(&r, 0, sizeof r);
    r.run = run;
    if (run == NULL) {
        urrt_log(URRT_LOG_ERR, "--replay needs a [can] section and [frame NAME]s in the configuration");
        return CLI_EXIT_USAGE;
    }
    if ((in = fopen(capture_path, "rb")) == NULL) {
        urrt_log(URRT_LOG_ERR, "cannot open the capture %s: %s", capture_path, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    urrt_canlink_config_defaults(&cfg);
    can_map_link_config(map, &cfg);
    if ((r.link = urrt_canlink_new(&cfg)) == NULL) {
        fclose(in);
        return CLI_EXIT_RUNTIME;
    }
    rc = pump(&r, in, capture_path);
    fclose(in);
    urrt_canlink_free(r.link);
    urrt_log(URRT_LOG_NOTICE, "replayed %s: %llu packets (%llu without a controller time, skipped), %llu frames sent%s",
             capture_path, (unsigned long long)r.packets, (unsigned long long)r.undated,
             (unsigned long long)r.frames, r.refused ? ", some refused by the link (see above)" : "");
    return r.refused ? CLI_EXIT_RUNTIME : rc;
}
