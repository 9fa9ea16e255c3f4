/* SPDX-License-Identifier: MIT */
/* freshness.c: see freshness.h. */
#include "freshness.h"

void gw_age_reset(gw_age *age)
{
    age->anchored = false;
}

/* The floor now: it rises by the allowed drift since it was set. */
static int64_t floor_at(const gw_age *age, uint64_t rx_us)
{
    uint64_t since = rx_us > age->floor_at_us ? rx_us - age->floor_at_us : 0;
    return age->floor_us + (int64_t)(since / (1000000u / GW_AGE_DRIFT_PPM));
}

static uint64_t controller_lag(gw_age *age, uint64_t rx_us, int64_t controller_us, bool newest)
{
    int64_t offset = (int64_t)rx_us - controller_us;
    int64_t floor;

    if (controller_us < age->last_controller_us) {
        age->anchored = false; /* a restart: its clock started again */
    }
    age->last_controller_us = controller_us;
    if (!age->anchored) {
        if (!newest) {
            return GW_AGE_UNKNOWN;
        }
        age->anchored = true;
        age->floor_us = offset;
        age->floor_at_us = rx_us;
    }
    floor = floor_at(age, rx_us);
    if (offset <= floor) {
        age->floor_us = offset;
        age->floor_at_us = rx_us;
        return 0;
    }
    return (uint64_t)(offset - floor);
}

uint64_t gw_age_lag_us(gw_age *age, uint64_t rx_us, uint64_t empty_us, bool has_clock, int64_t controller_us,
                       bool newest)
{
    uint64_t host = rx_us > empty_us ? rx_us - empty_us : 0;
    uint64_t controller = has_clock ? controller_lag(age, rx_us, controller_us, newest) : 0;
    return host > controller ? host : controller;
}

void gw_meter_event(gw_meter *m, uint64_t now_us)
{
    m->count++;
    m->last_us = now_us;
    if (!m->marked) {
        m->marked = true;
        m->mark_count = m->count;
        m->mark_us = now_us;
    }
}

double gw_meter_rate(gw_meter *m, uint64_t now_us)
{
    double stop_us;
    if (!m->marked) {
        return m->measured ? m->rate : -1.0;
    }
    if (m->count > m->mark_count && m->last_us - m->mark_us >= GW_METER_MIN_SPAN_US) {
        m->rate = (double)(m->count - m->mark_count) * 1e6 / (double)(m->last_us - m->mark_us);
        m->measured = true;
        m->mark_count = m->count;
        m->mark_us = m->last_us;
    }
    if (!m->measured) {
        return -1.0;
    }
    /* Without a measured rate there is no period to call overdue. */
    stop_us = m->rate > 0 ? 2e6 / m->rate : 0;
    stop_us = stop_us > GW_METER_MIN_SPAN_US ? stop_us : GW_METER_MIN_SPAN_US;
    if (m->rate > 0 && now_us > m->last_us && (double)(now_us - m->last_us) > stop_us) {
        m->rate = 0; /* stopped: the next message starts a new measurement */
        m->marked = false;
    }
    return m->rate;
}
