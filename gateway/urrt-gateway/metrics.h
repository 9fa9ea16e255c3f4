/* SPDX-License-Identifier: MIT */
/*
 * metrics.h: urrt-gateway's metrics for Prometheus, as a file for
 * node_exporter's textfile collector ([gateway] metrics_file): no network
 * listener. A gw_output whose tick writes the text exposition format every
 * metrics_interval, to PATH.tmp beside PATH and then renamed onto it, so a
 * scrape reads a whole file, old or new. Per robot the link's state and
 * counters and the data's age; per output the LCM messages and errors, the
 * CAN frames, and the CANopen node's NMT state and EMCYs; per [input] the
 * PLC's frames, values refused, packages written and silences, and per
 * robot the last input register the controller refused. docs/gateway.md
 * lists the names.
 *
 * The text is built in a buffer allocated once; a write error is logged
 * (at most once a minute), counted (urrt_metrics_write_errors_total, in
 * the next file that gets through) and never stops the gateway.
 */
#ifndef URRT_GATEWAY_METRICS_H
#define URRT_GATEWAY_METRICS_H

#include "can_out.h"
#include "gateway.h"
#include "lcm_out.h"
#include "plc_in.h"

typedef struct gw_metrics gw_metrics;

/* NULL (logged) when out of memory. lcm, can, inputs: the outputs (can NULL
 * without [can], inputs without [input]s); they must outlive the metrics'
 * last tick. */
gw_metrics *gw_metrics_new(gateway *gw, const gw_config *cfg, lcm_out *lcm, can_out *can, plc_in *inputs);
/* The gw_output to register after lcm and can; close frees it. */
gw_output gw_metrics_output(gw_metrics *m);

#endif
