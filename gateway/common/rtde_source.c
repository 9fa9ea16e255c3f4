/* SPDX-License-Identifier: MIT */
/* rtde_source.c: an RTDE session on a robot link (rtde_source.h). */
#include "rtde_source.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct rtde_source {
    urrt_rtde session;
    urrt_link *link;
    char name[64];
    uint16_t wanted[URRT_RTDE_MAX_VARS];  /* the configuration's recipe, in order */
    bool optional[URRT_RTDE_MAX_VARS];
    size_t count;
    double frequency;
    urrt_state state;
    urrt_rtde_values values;
    rtde_source_event_fn event_fn;
    void *event_ctx;
    rtde_source_tap_fn tap_fn;
    void *tap_ctx;
    urrt_rtde_in *in;                     /* the input recipes (NULL: a reader) */
    size_t in_count;
    uint64_t in_sessions;                 /* sessions streaming with every input recipe accepted */
    uint64_t in_busy;                     /* input packages the link's queue had no room for */
    unsigned in_use_tries;                /* IN_USE refusals in a row (RTDE_SOURCE_IN_USE_RETRIES) */
    int in_refusal;                       /* the last input setup refused: error, register */
    int in_refusal_var;
    bool dropped;                         /* this connection was dropped: ignore its bytes */
    uint8_t first[4];                     /* the connection's first bytes: a RealTime length? */
    size_t first_len;
};

/* Appends text to out[*len] as far as it fits, always NUL-terminated. */
static void append(char *out, size_t size, size_t *len, const char *text)
{
    int n = snprintf(out + *len, size - *len, "%s", text);
    if (n > 0) {
        *len += (size_t)n < size - *len ? (size_t)n : size - *len - 1;
    }
}

/* Appends var's name, with ", " before all but the first. */
static void append_name(char *out, size_t size, size_t *len, int var)
{
    char name[URRT_RTDE_NAME_MAX];
    if (*len > 0) {
        append(out, size, len, ", ");
    }
    append(out, size, len, urrt_rtde_var_name(var, name, sizeof name) > 0 ? name : "?");
}

rtde_source *rtde_source_new(const rtde_source_config *cfg, char *why, size_t why_size)
{
    rtde_source *src;
    urrt_rtde probe;
    int r;
    if (cfg->count == 0 || cfg->count > URRT_RTDE_MAX_VARS) {
        snprintf(why, why_size, "an RTDE recipe of %zu variables: it takes 1 to %d; publish fewer values",
                 cfg->count, URRT_RTDE_MAX_VARS);
        return NULL;
    }
    if (!(cfg->frequency >= 0.0 && cfg->frequency <= URRT_RTDE_HZ_E_SERIES)) {
        snprintf(why, why_size, "rtde_frequency %g Hz: no controller streams faster than %g Hz; lower it",
                 cfg->frequency, URRT_RTDE_HZ_E_SERIES);
        return NULL;
    }
    /* begin's checks, on a session of its own: the source's starts at connect. */
    urrt_rtde_init(&probe);
    r = urrt_rtde_begin(&probe, cfg->vars, cfg->count, cfg->frequency);
    if (r < 0) {
        snprintf(why, why_size, "the RTDE recipe is refused: %s%s", urrt_rtde_strerror(r),
                 r == URRT_RTDE_E_NAMES_TOO_LONG ? " (UR's limit is 2048 bytes of names); publish fewer values"
                                                 : "; fix the configuration");
        return NULL;
    }
    if (cfg->input_count > URRT_RTDE_IN_MAX_RECIPES) {
        snprintf(why, why_size, "%zu input recipes: a session takes at most %d; write fewer frames' registers",
                 cfg->input_count, URRT_RTDE_IN_MAX_RECIPES);
        return NULL;
    }
    src = calloc(1, sizeof *src);
    if (src == NULL || (cfg->input_count > 0 && (src->in = calloc(cfg->input_count, sizeof *src->in)) == NULL)) {
        snprintf(why, why_size, "out of memory for an RTDE source");
        free(src);
        return NULL;
    }
    for (size_t g = 0; g < cfg->input_count; g++) {
        r = urrt_rtde_in_init(&src->in[g], cfg->inputs[g].vars, cfg->inputs[g].count);
        if (r < 0) {
            snprintf(why, why_size, "input recipe %zu is refused: %s; fix the configuration", g + 1,
                     urrt_rtde_strerror(r));
            rtde_source_free(src);
            return NULL;
        }
    }
    src->in_count = cfg->input_count;
    src->in_refusal_var = -1;
    urrt_rtde_init(&src->session);
    snprintf(src->name, sizeof src->name, "%s", cfg->name != NULL ? cfg->name : "robot");
    memcpy(src->wanted, cfg->vars, cfg->count * sizeof cfg->vars[0]);
    for (size_t i = 0; i < cfg->count; i++) {
        src->optional[i] = cfg->optional != NULL && cfg->optional[i];
    }
    src->count = cfg->count;
    src->frequency = cfg->frequency;
    urrt_state_clear(&src->state);
    urrt_rtde_values_clear(&src->values);
    return src;
}

void rtde_source_free(rtde_source *src)
{
    if (src != NULL) {
        free(src->in);
    }
    free(src);
}

/* Writes every request the session has due. */
static void flush(rtde_source *src)
{
    uint8_t out[URRT_RTDE_REQUEST_MAX];
    int n;
    while ((n = urrt_rtde_in_output(&src->session, src->in, src->in_count, out, sizeof out)) > 0) {
        if (urrt_link_send(src->link, out, (size_t)n) != URRT_OK) {
            urrt_link_drop(src->link, URRT_LINK_DROP_PROTOCOL, "RTDE: the request queue is full");
            src->dropped = true;
            return;
        }
        if (src->tap_fn != NULL) {
            src->tap_fn(src->tap_ctx, RTDE_SOURCE_TAP_SENT, out, (size_t)n);
        }
    }
}

static void drop(rtde_source *src, urrt_link_drop_kind kind, const char *reason)
{
    urrt_link_drop(src->link, kind, reason);
    src->dropped = true;
}

static void on_connected(void *ctx, urrt_link *link, uint64_t now_us)
{
    rtde_source *src = ctx;
    int r;
    (void)now_us;
    src->link = link;
    src->dropped = false;
    src->first_len = 0;
    if (src->tap_fn != NULL) {
        src->tap_fn(src->tap_ctx, RTDE_SOURCE_TAP_CONNECTED, NULL, 0);
    }
    r = urrt_rtde_begin(&src->session, src->wanted, src->count, src->frequency);
    if (r < 0) { /* checked by rtde_source_new: cannot happen */
        char why[160];
        snprintf(why, sizeof why, "RTDE recipe: %s", urrt_rtde_strerror(r));
        drop(src, URRT_LINK_DROP_CONFIG, why);
        return;
    }
    urrt_rtde_in_begin(src->in, src->in_count);
    flush(src);
}

static void version_text(const urrt_rtde *s, char *out, size_t size)
{
    snprintf(out, size, "%" PRIu32 ".%" PRIu32 ".%" PRIu32 ".%" PRIu32, s->controller[0], s->controller[1],
             s->controller[2], s->controller[3]);
}

/* The controller's version is known: leave out the optional variables it
 * lacks; a required one it lacks is the configuration's error. */
static void narrow_recipe(rtde_source *src)
{
    const uint32_t *v = src->session.controller;
    uint16_t vars[URRT_RTDE_MAX_VARS];
    char missing[512], version[48], why[700];
    size_t n = 0, missing_len = 0;
    missing[0] = '\0';
    for (size_t i = 0; i < src->count; i++) {
        /* Unknown (2) keeps the variable: the controller's NOT_FOUND decides. */
        if (urrt_rtde_var_available(src->wanted[i], v[0], v[1], v[2]) != 0) {
            vars[n++] = src->wanted[i];
        } else if (!src->optional[i]) {
            append_name(missing, sizeof missing, &missing_len, src->wanted[i]);
        }
    }
    version_text(&src->session, version, sizeof version);
    if (missing_len > 0) {
        snprintf(why, sizeof why, "RTDE: controller version %s does not have %s: remove them from the "
                 "configuration or update the controller", version, missing);
        drop(src, URRT_LINK_DROP_CONFIG, why);
    } else if (n == 0) {
        snprintf(why, sizeof why, "RTDE: controller version %s has none of the values configured", version);
        drop(src, URRT_LINK_DROP_CONFIG, why);
    } else if (n != src->count && urrt_rtde_set_recipe(&src->session, vars, n) != URRT_OK) {
        drop(src, URRT_LINK_DROP_PROTOCOL, "RTDE: the narrowed recipe was refused (a bug: please report it)");
    }
}

/* The reason of a configuration error, with what to do. */
static void config_reason(const rtde_source *src, const urrt_rtde_event *ev, char *why, size_t size)
{
    char version[48], names[512];
    size_t len = 0;
    version_text(&src->session, version, sizeof version);
    names[0] = '\0';
    if (ev->error == URRT_RTDE_E_NOT_FOUND) {
        for (size_t i = 0; urrt_rtde_not_found(&src->session, i) >= 0; i++) {
            append_name(names, sizeof names, &len, urrt_rtde_not_found(&src->session, i));
        }
        snprintf(why, size, "RTDE: controller version %s does not have %s (NOT_FOUND): remove them from the "
                 "configuration or update the controller", version, names);
    } else if (ev->error == URRT_RTDE_E_FREQUENCY) {
        double max = urrt_rtde_max_frequency(&src->session);
        snprintf(why, size, "RTDE: rtde_frequency %g Hz is past this %" PRIu32 ".%" PRIu32 " controller's maximum "
                 "of %g Hz: lower it or use auto", src->session.frequency, src->session.controller[0],
                 src->session.controller[1], max);
    } else if (ev->error == URRT_RTDE_E_IN_USE) {
        char name[URRT_RTDE_NAME_MAX]; /* the first register refused: one name */
        if (urrt_rtde_var_name(ev->var, name, sizeof name) <= 0) {
            snprintf(name, sizeof name, "?");
        }
        snprintf(why, size, "RTDE: controller version %s refuses to let this client write %s%s (IN_USE): another "
                 "RTDE client, or an enabled fieldbus adapter (EtherNet/IP, PROFINET, Modbus: registers 0..23), "
                 "holds it; write registers 24..47 (bits 64..127), or free it on the controller", version, name,
                 ev->not_found > 1 ? " and more" : "");
    } else if (ev->error == URRT_RTDE_E_INPUTS_PROTOCOL) {
        snprintf(why, size, "RTDE: controller version %s speaks RTDE protocol 1 only, and urrt writes input "
                 "registers with protocol 2: update the controller or remove the [input] frames", version);
    } else if (ev->error == URRT_RTDE_E_TYPE_MISMATCH) {
        append_name(names, sizeof names, &len, ev->var);
        snprintf(why, size, "RTDE: controller version %s sends %s in a type urrt does not know for it: "
                 "remove it from the configuration", version, names);
    } else {
        snprintf(why, size, "RTDE: controller version %s: %s; check the controller's RTDE settings and the "
                 "configuration", version, urrt_rtde_strerror(ev->error));
    }
}

/* The reason of a protocol error. A peer that sends before it was answered,
 * and whose first four bytes are the length of a RealTime packet, is a
 * RealTime port (it streams without a handshake): say so, and how to read
 * it, rather than what its bytes mean as RTDE. */
static void drop_reason(const rtde_source *src, const urrt_rtde_event *ev, char *why, size_t size)
{
    uint32_t length = 0;
    const char *versions = NULL;
    if (!src->session.protocol_accepted && src->first_len == sizeof src->first) {
        length = (uint32_t)src->first[0] << 24 | (uint32_t)src->first[1] << 16 | (uint32_t)src->first[2] << 8 |
                 src->first[3];
        versions = urrt_versions_of(length);
    }
    if (versions != NULL) {
        snprintf(why, size, "the peer streams without a handshake, as a RealTime port (%u) does: its first bytes "
                 "announce a %" PRIu32 "-byte RealTime packet (versions %s): read it as RealTime (urrt-dump "
                 "without --rtde, source = realtime), or give RTDE's port (%u)",
                 (unsigned)URRT_LINK_PORT_RW, length, versions, (unsigned)URRT_RTDE_PORT);
    } else {
        snprintf(why, size, "RTDE protocol error: %s", urrt_rtde_strerror(ev->error));
    }
}

static void log_text(const rtde_source *src, const urrt_rtde_event *ev)
{
    urrt_log_level level = ev->level <= URRT_RTDE_LEVEL_ERROR     ? URRT_LOG_ERR
                           : ev->level == URRT_RTDE_LEVEL_WARNING ? URRT_LOG_WARNING
                                                                  : URRT_LOG_INFO;
    urrt_log(level, "robot %s: controller says%s%.*s: %.*s", src->name, ev->source_len > 0 ? " from " : "",
             (int)ev->source_len, ev->source_len > 0 ? ev->source : "", (int)ev->text_len, ev->text);
}

/* A configuration error ends the session with the long backoff, but an
 * input setup's IN_USE is first tried again with the usual one: right after
 * a reconnect the controller may still hold this client's old connection. */
static urrt_link_drop_kind config_drop_kind(rtde_source *src, const urrt_rtde_event *ev)
{
    if (ev->error == URRT_RTDE_E_IN_USE || ev->error == URRT_RTDE_E_NOT_FOUND) {
        bool input = ev->error == URRT_RTDE_E_IN_USE || urrt_rtde_in_writable(ev->var);
        if (input) {
            src->in_refusal = ev->error;
            src->in_refusal_var = ev->var;
        }
    }
    if (ev->error == URRT_RTDE_E_IN_USE && src->in_use_tries < RTDE_SOURCE_IN_USE_RETRIES) {
        src->in_use_tries++;
        return URRT_LINK_DROP_PROTOCOL;
    }
    return URRT_LINK_DROP_CONFIG;
}

/* Acts on one event; false when the connection ended. */
static bool on_event(rtde_source *src, const urrt_rtde_event *ev, uint64_t rx_us)
{
    char why[700];
    switch (ev->kind) {
    case URRT_RTDE_EV_CONTROLLER: narrow_recipe(src); break;
    case URRT_RTDE_EV_TEXT: log_text(src, ev); break;
    case URRT_RTDE_EV_FALLBACK:
        urrt_log(URRT_LOG_NOTICE, "robot %s: the controller refuses RTDE protocol %d: asking for %u", src->name,
                 URRT_RTDE_PROTOCOL, (unsigned)ev->protocol);
        break;
    case URRT_RTDE_EV_DATA:
        urrt_link_source_packet(src->link, src->session.buf, src->session.data_size, rx_us);
        break;
    case URRT_RTDE_EV_DROP:
        drop_reason(src, ev, why, sizeof why);
        drop(src, URRT_LINK_DROP_PROTOCOL, why);
        break;
    case URRT_RTDE_EV_CONFIG:
        config_reason(src, ev, why, sizeof why);
        drop(src, config_drop_kind(src, ev), why);
        break;
    case URRT_RTDE_EV_STARTED:
        /* Every input recipe was accepted: a refusal is over. */
        src->in_sessions += src->in_count > 0;
        src->in_use_tries = 0;
        src->in_refusal = 0;
        src->in_refusal_var = -1;
        break;
    default: break;
    }
    if (src->event_fn != NULL) {
        src->event_fn(src->event_ctx, ev, rx_us);
    }
    if (!src->dropped) {
        flush(src);
    }
    return !src->dropped;
}

static void on_received(void *ctx, urrt_link *link, const uint8_t *data, size_t len, uint64_t rx_us)
{
    rtde_source *src = ctx;
    src->link = link;
    for (size_t i = 0; i < len && src->first_len < sizeof src->first; i++) {
        src->first[src->first_len++] = data[i];
    }
    while (len > 0 && !src->dropped) {
        size_t used = 0;
        urrt_rtde_event ev;
        int k = urrt_rtde_in_feed(&src->session, src->in, src->in_count, data, len, &used, &ev, &src->state,
                                  &src->values);
        /* Tapped as the session takes them, each piece before what it
         * leads to: a recorder that stops at a package (urrt-dump -n N -w)
         * holds exactly the bytes up to it. */
        if (src->tap_fn != NULL && used > 0) {
            src->tap_fn(src->tap_ctx, RTDE_SOURCE_TAP_RECEIVED, data, used);
        }
        if (k <= 0) {
            break; /* all consumed (or the session already ended: the drop is on its way) */
        }
        data += used;
        len -= used;
        if (!on_event(src, &ev, rx_us)) {
            break;
        }
    }
}

bool rtde_source_attach(rtde_source *src, urrt_link *link)
{
    urrt_link_source hooks = {.ctx = src, .connected = on_connected, .received = on_received};
    src->link = link;
    return urrt_link_set_source(link, &hooks) == URRT_OK;
}

const urrt_state *rtde_source_state(const rtde_source *src)
{
    return &src->state;
}

const urrt_rtde_values *rtde_source_values(const rtde_source *src)
{
    return &src->values;
}

const urrt_rtde *rtde_source_session(const rtde_source *src)
{
    return &src->session;
}

urrt_rtde_in *rtde_source_in(rtde_source *src, size_t g)
{
    return g < src->in_count ? &src->in[g] : NULL;
}

bool rtde_source_input_ready(const rtde_source *src, size_t g)
{
    return g < src->in_count && !src->dropped && urrt_rtde_in_ready(&src->session, &src->in[g]);
}

int rtde_source_send_input(rtde_source *src, size_t g)
{
    uint8_t out[URRT_RTDE_IN_PACKAGE_MAX];
    int n, r;
    if (!rtde_source_input_ready(src, g)) {
        return 0;
    }
    n = urrt_rtde_in_package(&src->session, &src->in[g], out, sizeof out);
    if (n <= 0) {
        return 0; /* a register without a value: nothing is invented for it */
    }
    r = urrt_link_send(src->link, out, (size_t)n);
    if (r != URRT_OK) {
        /* A full queue: the controller does not read, and the next package
         * carries the newest values. Otherwise the connection just ended. */
        src->in_busy += r == URRT_E_NO_SPACE;
        return 0;
    }
    if (src->tap_fn != NULL) {
        src->tap_fn(src->tap_ctx, RTDE_SOURCE_TAP_SENT, out, (size_t)n);
    }
    return 1;
}

uint64_t rtde_source_input_sessions(const rtde_source *src)
{
    return src->in_sessions;
}

uint64_t rtde_source_input_busy(const rtde_source *src)
{
    return src->in_busy;
}

int rtde_source_input_refusal(const rtde_source *src, int *var)
{
    *var = src->in_refusal_var;
    return src->in_refusal;
}

size_t rtde_source_recipe_text(const rtde_source *src, char *out, size_t size)
{
    size_t len = 0;
    const urrt_rtde *s = &src->session;
    const uint16_t *vars = s->var_count > 0 ? s->vars : src->wanted;
    size_t count = s->var_count > 0 ? s->var_count : src->count;
    if (size == 0) {
        return 0;
    }
    out[0] = '\0';
    for (size_t i = 0; i < count; i++) {
        char name[URRT_RTDE_NAME_MAX];
        if (urrt_rtde_var_name(vars[i], name, sizeof name) > 0) {
            if (len > 0) {
                append(out, size, &len, ",");
            }
            append(out, size, &len, name);
        }
    }
    return len;
}

void rtde_source_set_event_fn(rtde_source *src, rtde_source_event_fn fn, void *ctx)
{
    src->event_fn = fn;
    src->event_ctx = ctx;
}

void rtde_source_set_tap(rtde_source *src, rtde_source_tap_fn fn, void *ctx)
{
    src->tap_fn = fn;
    src->tap_ctx = ctx;
}
