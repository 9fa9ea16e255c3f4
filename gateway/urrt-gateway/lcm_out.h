/* SPDX-License-Identifier: MIT */
/*
 * lcm_out.h: the LCM output of urrt-gateway.
 *
 * Per robot NAME it publishes NAME.STATE (urrt.state_t), NAME.JOINTS,
 * NAME.TOOL, NAME.STATUS on packets (every one, or decimated on the
 * controller's clock) and NAME.GATEWAY (urrt.gateway_t) on its own period,
 * whatever the link does. Messages are encoded with the lcm-gen `_encode`
 * functions into one buffer the output owns and sent with lcm_publish: the
 * generated `_publish` would malloc on every call.
 *
 * A URL that cannot be opened, or publishing that keeps failing, is logged
 * and retried (the LCM instance is recreated with backoff); lost messages
 * are counted in each robot's status.
 */
#ifndef URRT_GATEWAY_LCM_OUT_H
#define URRT_GATEWAY_LCM_OUT_H

#include "gateway.h"

typedef struct lcm_out lcm_out;

/* NULL when out of memory; an LCM URL that does not open yet is not an
 * error (it is retried). */
lcm_out *lcm_out_new(gateway *gw, const gw_lcm_config *cfg);
/* The gw_output to register with gw_add_output; close frees it. */
gw_output lcm_out_output(lcm_out *out);

/* A robot's counts, for the metrics (metrics.h). */
typedef struct lcm_out_counts {
    uint64_t published[GW_KIND_COUNT]; /* messages per channel */
    uint64_t errors;                   /* messages lost: publishing failed */
    uint64_t stale_dropped;            /* messages not published: the data was stale */
} lcm_out_counts;
void lcm_out_get_counts(const lcm_out *out, unsigned robot, lcm_out_counts *counts);

#endif
