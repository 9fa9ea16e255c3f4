/* SPDX-License-Identifier: MIT */
/* can_replay.c: see can_replay.h. */
#include "can_replay.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "can_in.h"
#include "cli.h"
#include "rtde_only.h"
#include "port.h"
#include "rtde_capture.h"

/* An [input] of the first robot: lib's description, state and recipe. */
struct replay_input {
    urrt_plcin_desc d;
    uint16_t *vars;
    urrt_plcin st;
    urrt_rtde_in in;
    size_t index;          /* among the map's [input]s: with [canopen], its RPDO */
};

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
    urrt_state state;      /* the RealTime packet's decode */
    uint64_t packets;      /* RealTime packets or RTDE data packages */
    uint64_t undated;      /* packets without a usable controller time: skipped */
    uint64_t sessions;     /* an RTDE capture's connections */
    uint64_t ended;        /* RTDE sessions the capture's client ended on an error */
    uint64_t frames;
    uint64_t refused;
    /* The [input]s (with --replay-inputs): the input packages the gateway
     * would write, one line each, on the capture's clock. */
    struct co_run *co_run;
    struct replay_input *inputs;
    size_t input_count;
    uint64_t period_us;    /* [can] inputs_min_rate's */
    FILE *inputs_out;
    const urrt_rtde *session; /* the capture's session, while an RTDE capture is replayed */
    bool recipe_in;        /* this session's recipe is in: the input recipes are taken as accepted */
    uint8_t recipe_id;     /* its id: input recipe k's is recipe_id + 1 + k */
    uint64_t inputs_us;    /* the latest look: its time never goes back */
    uint64_t packages;     /* input packages written */
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

/* ---- the [input]s: what the gateway would write to the robot ---------------- */

/* The session streams, its recipe in: the capture's controller is taken as
 * having accepted every input recipe, after the output recipe, in order. */
static bool inputs_ready(const struct replay *r, const struct replay_input *x)
{
    (void)x;
    return r->session != NULL && r->recipe_in && urrt_rtde_streaming(r->session);
}

/* The input data package of x, as the gateway writes it (docs/rtde.md: size,
 * 'U', the input recipe's id, its values big-endian in recipe order): its
 * size, or 0 while a register holds no value. */
static size_t input_package(const struct replay *r, const struct replay_input *x, uint8_t *pkg)
{
    size_t size = URRT_RTDE_HEADER_SIZE + 1u + x->in.data_size;
    if (!urrt_rtde_in_complete(&x->in)) {
        return 0;
    }
    pkg[0] = (uint8_t)(size >> 8);
    pkg[1] = (uint8_t)size;
    pkg[2] = URRT_RTDE_TYPE_DATA;
    pkg[3] = (uint8_t)(r->recipe_id + 1u + (x - r->inputs));
    memcpy(pkg + 4, x->in.data, x->in.data_size);
    return size;
}

/* One look at every [input] at now_us, as the gateway's loop takes one: with
 * a node, what its RPDOs and SDO writes stored (and its state); without, the
 * timeout; then each package due, written as a line. */
static void inputs_look(struct replay *r, uint64_t now_us)
{
    uint8_t pkg[URRT_RTDE_IN_PACKAGE_MAX];
    r->inputs_us = now_us;
    for (size_t i = 0; i < r->input_count; i++) {
        struct replay_input *x = &r->inputs[i];
        bool ready = inputs_ready(r, x);
        size_t n;
        if (r->node != NULL) {
            urrt_plcin_rpdo rpdo = {r->node, (uint16_t)co_run_input_first_var(r->co_run, x->index),
                                    (uint8_t)x->index};
            urrt_plcin_look look;
            urrt_plcin_node(&x->d, &rpdo, &x->st, &x->in, now_us, &look);
        } else if (urrt_plcin_timed_out(&x->d, &x->st, now_us)) {
            urrt_plcin_silent(&x->d, &x->st, &x->in);
        }
        if (!urrt_plcin_due(&x->d, &x->st, ready, (uint32_t)r->sessions, now_us, r->period_us)) {
            continue;
        }
        n = input_package(r, x, pkg);
        urrt_plcin_sent(&x->st, n > 0, (uint32_t)r->sessions, now_us);
        if (n > 0) {
            fprintf(r->inputs_out, "(%llu.%06llu) ", (unsigned long long)(now_us / 1000000u),
                    (unsigned long long)(now_us % 1000000u));
            for (size_t k = 0; k < n; k++) {
                fprintf(r->inputs_out, "%02X", pkg[k]);
            }
            fputc('\n', r->inputs_out);
            r->packages++;
        }
    }
}

/* The earliest of the [input]s' deadlines (lib's), never before the latest look. */
static uint64_t inputs_deadline(const struct replay *r)
{
    uint64_t due = URRT_CANTX_NEVER;
    for (size_t i = 0; i < r->input_count; i++) {
        const struct replay_input *x = &r->inputs[i];
        uint64_t d = urrt_plcin_deadline(&x->d, &x->st, inputs_ready(r, x), r->period_us);
        due = d < due ? d : due;
    }
    return due != URRT_CANTX_NEVER && due < r->inputs_us ? r->inputs_us : due;
}

/* The node and the [input]s at each of their deadlines before until_us, in
 * time order: heartbeats, EMCYs, TPDOs, timeouts and input packages, as a
 * loop waking at each would have sent them. */
static void catch_up(struct replay *r, uint64_t until_us)
{
    for (;;) {
        uint64_t node_due = URRT_CANTX_NEVER, in_due = inputs_deadline(r);
        if (r->node != NULL) {
            node_due = urrt_co_deadline(r->node);
            node_due = node_due < r->node_us ? r->node_us : node_due;
        }
        if (node_due >= until_us && in_due >= until_us) {
            return;
        }
        if (node_due <= in_due) {
            urrt_co_run(r->node, node_due, emit, r);
            if (node_due == r->node_us && urrt_co_deadline(r->node) <= node_due) {
                return; /* nothing left at this instant that time would change */
            }
            r->node_us = node_due;
        } else {
            uint64_t before = r->inputs_us;
            inputs_look(r, in_due);
            if (in_due == before && inputs_deadline(r) <= in_due) {
                return; /* likewise */
            }
        }
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

/* A received frame to the [input] of its id, when there is no node. */
static void input_frame(struct replay *r, const urrt_can_frame *f, uint64_t at_us)
{
    uint64_t raws[URRT_PLCIN_MAX_SIGNALS];
    for (size_t i = 0; i < r->input_count; i++) {
        struct replay_input *x = &r->inputs[i];
        if (x->d.id == f->id && ((x->d.flags & URRT_CANTX_EXTENDED) != 0) == f->extended &&
            urrt_plcin_raws(&x->d, f->data, f->len, f->fd, raws)) {
            (void)urrt_plcin_take(&x->d, &x->st, &x->in, raws, 0, at_us);
        }
    }
}

/* The frames received up to t_us, each at its own time, after what the node
 * (and the [input]s) would have sent before it, then the [input]s looked
 * at. A node's frames before the first packet wait for its boot. */
static void rx_until(struct replay *r, uint64_t t_us)
{
    while (r->has_next && r->next.t_us <= t_us) {
        uint64_t at = r->next.t_us < r->node_us ? r->node_us : r->next.t_us;
        at = at < r->inputs_us ? r->inputs_us : at;
        catch_up(r, at);
        if (r->node != NULL) {
            urrt_co_on_frame(r->node, r->next.frame.id, r->next.frame.extended ? URRT_CO_RX_EXTENDED : 0u,
                             r->next.frame.data, r->next.frame.len, at, emit, r);
            r->node_us = at;
        } else {
            input_frame(r, &r->next.frame, at);
        }
        if (r->input_count > 0) {
            inputs_look(r, at);
        }
        r->rx_frames++;
        rx_advance(r);
    }
}

/* The frames due before the packet go out with the values before it; then
 * the packet's state (and an RTDE package's RTDE-only values, handed over
 * just before it, as can_out does) and what is due at its time. */
static void packet_at(struct replay *r, uint64_t t_us, const urrt_state *st, const urrt_rtde_values *values)
{
    if (r->node == NULL) {
        /* What a gateway waking at each deadline would have sent until now. */
        rx_until(r, t_us);
        catch_up(r, t_us);
        urrt_cantx_catch_up(can_run_tx(r->run), t_us, emit, r);
        can_run_rtde(r->run, 0, values);
        urrt_cantx_on_packet(can_run_tx(r->run), 0, st, t_us);
        can_run_due(r->run, t_us, urrt_canlink_get_stats(r->link), emit, r);
        if (r->input_count > 0) {
            inputs_look(r, t_us);
        }
        return;
    }
    if (!r->started) {
        r->started = true; /* the node boots at the capture's first packet */
        r->node_us = t_us;
        urrt_co_start(r->node, t_us, emit, r);
    }
    rx_until(r, t_us);
    catch_up(r, t_us);
    can_run_rtde(r->run, 0, values);
    urrt_cantx_on_packet(can_run_tx(r->run), 0, st, t_us);
    can_run_set_link(r->run, urrt_canlink_get_stats(r->link));
    urrt_co_run(r->node, t_us, emit, r);
    r->node_us = t_us;
    if (r->input_count > 0) {
        inputs_look(r, t_us);
    }
}

/* One packet (values NULL: RealTime's) at its own controller time: what a
 * firmware does with each packet. */
static void on_state(struct replay *r, const urrt_state *st, const urrt_rtde_values *values)
{
    int64_t t_us;
    r->packets++;
    if (!urrt_has(st, URRT_F_TIME) || urrt_time_us(st->time[0], &t_us) != URRT_OK) {
        r->undated++;
        return;
    }
    packet_at(r, (uint64_t)t_us, st, values);
}

static void on_packet(struct replay *r, const uint8_t *pkt, size_t len)
{
    if (urrt_decode(pkt, len, &r->state) < 0) {
        r->packets++;
        r->undated++;
        return;
    }
    on_state(r, &r->state, NULL);
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

/* ---- what the configuration needs of an RTDE capture ----------------------- */

/* A value the first robot's signals need, and the first signal needing it. */
struct need {
    int var;                /* urrt_rtde_var; -1: a field RTDE has no variable for */
    int field;              /* with var -1: the field */
    const struct can_map_frame *frame;
    const struct can_map_signal *sig;
};

/* The capture's robot's (the first) signals: each RTDE variable once (a
 * field's through urrt_rtde_var_of_field), each field RTDE lacks once.
 * Returns how many, at most max. */
static size_t needs_of(const struct can_map *map, struct need *out, size_t max)
{
    size_t n = 0;
    for (size_t f = 0; f < map->frame_count; f++) {
        const struct can_map_frame *frame = &map->frames[f];
        for (size_t i = 0; frame->robot_index == 0 && i < frame->count; i++) {
            const struct can_map_signal *m = &frame->meta[i];
            int var = m->role == CAN_MAP_ROLE_RTDE    ? m->var
                      : m->role == CAN_MAP_ROLE_FIELD ? urrt_rtde_var_of_field((urrt_field_id)m->field)
                                                      : -2;
            bool seen = var == -2;
            for (size_t k = 0; k < n && !seen; k++) {
                seen = out[k].var == var && (var >= 0 || out[k].field == m->field);
            }
            if (!seen && n < max) {
                out[n++] = (struct need){var, m->field, frame, m};
            }
        }
    }
    return n;
}

/* A refusal's text: each missing value with a signal that needs it, and
 * the names again for urrt-dump's -k. The log takes about 1000 characters
 * a line: past DETAIL_MAX of details, values go by name only. */
#define DETAIL_MAX 560
struct missing {
    char text[DETAIL_MAX + 96];
    size_t len;
    unsigned more;          /* values past DETAIL_MAX, named in names only */
    char names[400];
    size_t names_len;
};

static void put_text(char *buf, size_t size, size_t *len, const char *fmt, ...)
{
    va_list ap;
    int n;
    if (*len >= size) {
        return;
    }
    va_start(ap, fmt);
    n = vsnprintf(buf + *len, size - *len, fmt, ap);
    va_end(ap);
    *len = n < 0 ? size : *len + (size_t)n;
}

/* The configuration file's name without its folders: the user gave it. */
static const char *base_name(const char *path)
{
    const char *slash = path != NULL ? strrchr(path, '/') : NULL;
    return path == NULL ? "?" : slash != NULL ? slash + 1 : path;
}

/* "NAME (frame F, signal S, FILE:LINE)" into the text, NAME into names. */
static void add_missing(struct missing *m, const char *name, const struct need *nd)
{
    if (m->len < DETAIL_MAX) {
        put_text(m->text, sizeof m->text, &m->len, "%s%s (frame %s, signal %s, %s:%d)", m->len == 0 ? "" : ", ",
                 name, nd->frame->name, nd->sig->name, base_name(nd->sig->loc.file), nd->sig->loc.line);
    } else {
        m->more++;
    }
    put_text(m->names, sizeof m->names, &m->names_len, "%s%s", m->names_len == 0 ? "" : ",", name);
}

static const char *more_text(const struct missing *m, char *buf, size_t size)
{
    buf[0] = '\0';
    if (m->more > 0) {
        snprintf(buf, size, " and %u more", m->more);
    }
    return buf;
}

/* A RealTime capture has no RTDE-only values: false (logged, naming every
 * signal's value) when the configuration needs some. */
static bool realtime_has_all(const struct can_map *map, const char *path)
{
    static struct need needs[URRT_RTDE_VAR_COUNT + URRT_FIELD_COUNT];
    static struct missing m;
    size_t n = needs_of(map, needs, sizeof needs / sizeof needs[0]);
    char more[32];
    memset(&m, 0, sizeof m);
    for (size_t k = 0; k < n; k++) {
        char name[URRT_RTDE_NAME_MAX];
        if (needs[k].var >= 0 && rtde_only(needs[k].var)) {
            (void)urrt_rtde_var_name(needs[k].var, name, sizeof name);
            add_missing(&m, name, &needs[k]);
        }
    }
    if (m.names_len == 0) {
        return true;
    }
    urrt_log(URRT_LOG_ERR, "%s is a RealTime capture, which has no RTDE-only values, and the CAN side needs %s%s; "
             "replay an RTDE capture of them: urrt-dump --rtde -w FILE -k %s", path, m.text,
             more_text(&m, more, sizeof more), m.names);
    return false;
}

/* The session's recipe against the needs: false (logged, every missing
 * value with a signal that needs it, and what to do) if it lacks any. */
static bool recipe_has_all(const rtde_replay *rp, const struct need *needs, size_t n, const char *path,
                           uint64_t session)
{
    static struct missing m;
    char more[32], fields[320] = "";
    size_t fields_len = 0;
    bool clock = rtde_replay_has(rp, URRT_RTDE_V_TIMESTAMP);
    memset(&m, 0, sizeof m);
    if (!clock) {
        put_text(m.text, sizeof m.text, &m.len, "timestamp (the replay's clock, which urrt-dump --rtde -w always "
                 "records)");
    }
    for (size_t k = 0; k < n; k++) {
        char name[URRT_RTDE_NAME_MAX];
        if (needs[k].var < 0) {
            put_text(fields, sizeof fields, &fields_len, "%s%s (frame %s, signal %s, %s:%d)",
                     fields_len == 0 ? "" : ", ", urrt_field((urrt_field_id)needs[k].field)->name,
                     needs[k].frame->name, needs[k].sig->name, base_name(needs[k].sig->loc.file),
                     needs[k].sig->loc.line);
        } else if (needs[k].var != URRT_RTDE_V_TIMESTAMP && !rtde_replay_has(rp, needs[k].var)) {
            (void)urrt_rtde_var_name(needs[k].var, name, sizeof name);
            add_missing(&m, name, &needs[k]);
        }
    }
    if (clock && m.names_len == 0 && fields_len == 0) {
        return true;
    }
    urrt_log(URRT_LOG_ERR, "%s: the recipe of session %llu (%s) lacks what the CAN side needs: %s%s%s%s%s%s%s", path,
             (unsigned long long)session, rtde_replay_peer(rp), m.text, more_text(&m, more, sizeof more),
             m.names_len > 0 ? "; record them: urrt-dump --rtde -w FILE -k " : "", m.names,
             fields_len == 0 ? "" : m.len > 0 ? "; RTDE has no " : "RTDE has no ", fields,
             fields_len == 0 ? "" : ": replay a RealTime capture (urrt-dump -w FILE) for them");
    return false;
}

/* The first pass: every session's recipe has what the first robot's
 * signals need, and the capture is whole up to its end (a cut-off last
 * record aside). Nothing is sent unless all of it can be. */
static bool rtde_check(const struct can_map *map, FILE *in, const char *path)
{
    static struct need needs[URRT_RTDE_VAR_COUNT + URRT_FIELD_COUNT];
    size_t n = needs_of(map, needs, sizeof needs / sizeof needs[0]);
    char why[512];
    urrt_rtde_event ev;
    rtde_replay *rp = rtde_replay_open(in, path, why, sizeof why);
    uint64_t sessions = 0;
    int k = 0;
    bool ok = true;
    if (rp == NULL) {
        urrt_log(URRT_LOG_ERR, "%s", why);
        return false;
    }
    while (ok && (k = rtde_replay_next(rp, &ev, why, sizeof why)) > 0) {
        if (k == RTDE_REPLAY_SESSION) {
            sessions++;
        } else if (k == URRT_RTDE_EV_RECIPE) {
            ok = recipe_has_all(rp, needs, n, path, sessions);
        }
    }
    if (ok && k < 0) {
        urrt_log(URRT_LOG_ERR, "%s; nothing was replayed", why);
        ok = false;
    }
    rtde_replay_free(rp);
    return ok;
}

/* The second pass: each data package's state and RTDE-only values on the
 * capture's clock. */
static int rtde_pump(struct replay *r, FILE *in, const char *path)
{
    char why[512];
    urrt_rtde_event ev;
    rtde_replay *rp = rtde_replay_open(in, path, why, sizeof why);
    int k;
    if (rp == NULL) {
        urrt_log(URRT_LOG_ERR, "%s", why);
        return CLI_EXIT_RUNTIME;
    }
    r->session = rtde_replay_session(rp);
    while ((k = rtde_replay_next(rp, &ev, why, sizeof why)) > 0) {
        if (k == RTDE_REPLAY_SESSION) {
            r->sessions++;
            r->recipe_in = false;
        } else if (k == URRT_RTDE_EV_RECIPE) {
            r->recipe_in = true;
            r->recipe_id = ev.recipe_id;
        } else if (k == URRT_RTDE_EV_DATA) {
            on_state(r, rtde_replay_state(rp), rtde_replay_values(rp));
        } else if (k == URRT_RTDE_EV_DROP || k == URRT_RTDE_EV_CONFIG) {
            r->ended++;
            urrt_log(URRT_LOG_INFO, "%s: session %llu ended: %s", path, (unsigned long long)r->sessions,
                     urrt_rtde_strerror(ev.error));
        }
    }
    if (k < 0) {
        urrt_log(URRT_LOG_ERR, "%s", why); /* the first pass read it whole: the file changed */
    } else if (rtde_replay_truncated(rp) > 0) {
        urrt_log(URRT_LOG_WARNING, "%s ends inside a record (%zu bytes, the recorder stopped mid-write): replayed "
                 "up to it", path, rtde_replay_truncated(rp));
    }
    r->session = NULL;
    rtde_replay_free(rp);
    return k < 0 ? CLI_EXIT_RUNTIME : CLI_EXIT_OK;
}

static bool open_rx(struct replay *r, const char *rx_path)
{
    if (rx_path == NULL) {
        return true;
    }
    if (r->node == NULL && r->input_count == 0) {
        urrt_log(URRT_LOG_ERR, "--replay-rx feeds a CANopen node, or the [input]s with --replay-inputs: the "
                 "configuration has no [canopen] section, and no --replay-inputs FILE was given");
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

/* Whether f holds an RTDE capture (by its first byte, never its name);
 * f is back at its start. */
static bool is_rtde_capture(FILE *f)
{
    int first = fgetc(f);
    rewind(f);
    return first == RTDE_CAPTURE_FIRST_BYTE;
}

/* The first robot's [input]s, for --replay-inputs path (NULL: none). */
static bool open_inputs(struct replay *r, const struct can_map *map, const char *path)
{
    size_t n = 0;
    if (path == NULL) {
        return true;
    }
    for (size_t i = 0; i < map->input_count; i++) {
        n += map->inputs[i].robot_index == 0;
    }
    if (n == 0) {
        urrt_log(URRT_LOG_ERR, "--replay-inputs %s: the configuration has no [input NAME] of its first robot (the "
                 "capture's): nothing would be written to it", path);
        return false;
    }
    if ((r->inputs = calloc(n, sizeof *r->inputs)) == NULL) {
        urrt_log(URRT_LOG_ERR, "--replay-inputs: out of memory");
        return false;
    }
    for (size_t i = 0; i < map->input_count; i++) {
        const struct can_map_frame *f = &map->inputs[i];
        struct replay_input *x = &r->inputs[r->input_count];
        if (f->robot_index != 0) {
            continue;
        }
        r->input_count++;
        x->index = i;
        if ((x->vars = malloc(f->count * sizeof *x->vars)) == NULL) {
            urrt_log(URRT_LOG_ERR, "--replay-inputs: out of memory");
            return false;
        }
        can_in_desc(f, x->vars, &x->d);
        urrt_plcin_init(&x->st);
        (void)urrt_rtde_in_init(&x->in, f->regs, f->reg_count); /* can_map_finish checked the recipe */
    }
    r->period_us = (uint64_t)(1e6 / map->inputs_min_rate_hz);
    if ((r->inputs_out = fopen(path, "w")) == NULL) {
        urrt_log(URRT_LOG_ERR, "cannot write the input packages to %s: %s", path, strerror(errno));
        return false;
    }
    return true;
}

static int close_all(struct replay *r, FILE *in, int rc)
{
    if (in != NULL) {
        fclose(in);
    }
    if (r->rx != NULL) {
        fclose(r->rx);
    }
    if (r->inputs_out != NULL && fclose(r->inputs_out) != 0 && rc == CLI_EXIT_OK) {
        urrt_log(URRT_LOG_ERR, "writing the input packages failed: %s", strerror(errno));
        rc = CLI_EXIT_RUNTIME;
    }
    for (size_t i = 0; i < r->input_count; i++) {
        free(r->inputs[i].vars);
    }
    free(r->inputs);
    return rc;
}

int can_replay(const struct can_map *map, struct can_run *run, struct co_run *node, const char *capture_path,
               const char *rx_path, const char *inputs_path)
{
    struct replay r;
    urrt_canlink_config cfg;
    FILE *in;
    bool rtde;
    int rc;
    memset(&r, 0, sizeof r);
    r.run = run;
    r.co_run = node;
    r.node = node != NULL ? co_run_node(node) : NULL;
    if (run == NULL) {
        urrt_log(URRT_LOG_ERR, "--replay needs a [can] section and [frame NAME]s in the configuration");
        return CLI_EXIT_USAGE;
    }
    if (!open_inputs(&r, map, inputs_path)) {
        return close_all(&r, NULL, r.inputs_out == NULL && r.inputs == NULL ? CLI_EXIT_USAGE : CLI_EXIT_RUNTIME);
    }
    if (!open_rx(&r, rx_path)) {
        return close_all(&r, NULL, r.node == NULL && r.input_count == 0 ? CLI_EXIT_USAGE : CLI_EXIT_RUNTIME);
    }
    if ((in = fopen(capture_path, "rb")) == NULL) {
        urrt_log(URRT_LOG_ERR, "cannot open the capture %s: %s", capture_path, strerror(errno));
        return close_all(&r, NULL, CLI_EXIT_RUNTIME);
    }
    /* Refusals come before the link opens: a refused replay leaves an
     * earlier log as it was. */
    rtde = is_rtde_capture(in);
    if (!rtde && r.input_count > 0) {
        urrt_log(URRT_LOG_ERR, "--replay-inputs: %s is a RealTime capture, and input registers are written over "
                 "RTDE: replay an RTDE capture (urrt-dump --rtde -w FILE)", capture_path);
        return close_all(&r, in, CLI_EXIT_RUNTIME);
    }
    if (rtde ? !rtde_check(map, in, capture_path) : !realtime_has_all(map, capture_path)) {
        return close_all(&r, in, CLI_EXIT_RUNTIME);
    }
    rewind(in);
    urrt_canlink_config_defaults(&cfg);
    can_map_link_config(map, &cfg);
    cfg.log_caller_clock = true; /* each frame at its time on the capture's clock */
    if ((r.link = urrt_canlink_new(&cfg)) == NULL) {
        return close_all(&r, in, CLI_EXIT_RUNTIME);
    }
    rc = rtde ? rtde_pump(&r, in, capture_path) : pump(&r, in, capture_path);
    if (r.rx != NULL) {
        if (r.has_next) {
            urrt_log(URRT_LOG_WARNING, "%s: frames after the capture's last packet were not fed", r.rx_path);
        }
        urrt_log(URRT_LOG_NOTICE, "fed %llu received frames from %s (%llu lines not a classic frame, skipped)",
                 (unsigned long long)r.rx_frames, r.rx_path, (unsigned long long)r.rx_bad);
    }
    if (r.input_count > 0) {
        urrt_log(URRT_LOG_NOTICE, "wrote %llu input packages of %zu [input]%s to %s", (unsigned long long)r.packages,
                 r.input_count, r.input_count == 1 ? "" : "s", inputs_path);
    }
    rc = close_all(&r, in, rc);
    urrt_canlink_free(r.link);
    if (rtde) {
        urrt_log(URRT_LOG_NOTICE, "replayed %s (RTDE): %llu data packages in %llu session%s (%llu ended on an error, "
                 "%llu packages without a controller time, skipped), %llu frames sent%s", capture_path,
                 (unsigned long long)r.packets, (unsigned long long)r.sessions, r.sessions == 1 ? "" : "s",
                 (unsigned long long)r.ended,
                 (unsigned long long)r.undated, (unsigned long long)r.frames,
                 r.refused ? ", some refused by the link (see above)" : "");
    } else {
        urrt_log(URRT_LOG_NOTICE, "replayed %s: %llu packets (%llu without a controller time, skipped), %llu frames "
                 "sent%s", capture_path, (unsigned long long)r.packets, (unsigned long long)r.undated,
                 (unsigned long long)r.frames, r.refused ? ", some refused by the link (see above)" : "");
    }
    return r.refused ? CLI_EXIT_RUNTIME : rc;
}
