/* SPDX-License-Identifier: MIT */
/* rtde_capture.c: RTDE captures (rtde_capture.h). */
#include "rtde_capture.h"

#include <errno.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

static uint16_t be16(const uint8_t *p)
{
    return (uint16_t)((unsigned)p[0] << 8 | p[1]);
}

/* ---- writing ------------------------------------------------------------ */

struct rtde_capture_writer {
    FILE *f;
    char path[256];
    bool failed;
    int error;                                  /* errno of the first failed write */
    uint8_t pending[URRT_RTDE_PACKAGE_MAX];     /* the controller's package being completed */
    size_t have;
    bool unframable;                            /* a size out of bounds: the rest of this connection is not recorded */
};

static bool put(rtde_capture_writer *w, char kind, const uint8_t *pkg, size_t size)
{
    if (w->failed) {
        return false;
    }
    if (fputc(kind, w->f) == EOF || fwrite(pkg, 1, size, w->f) != size) {
        w->failed = true;
        w->error = errno;
        return false;
    }
    return true;
}

rtde_capture_writer *rtde_capture_create(const char *path, char *why, size_t why_size)
{
    rtde_capture_writer *w = calloc(1, sizeof *w);
    if (w == NULL) {
        snprintf(why, why_size, "out of memory for the capture %s", path);
        return NULL;
    }
    snprintf(w->path, sizeof w->path, "%s", path);
    w->f = fopen(path, "wb");
    if (w->f == NULL || fwrite(RTDE_CAPTURE_MAGIC, 1, RTDE_CAPTURE_MAGIC_LEN, w->f) != RTDE_CAPTURE_MAGIC_LEN) {
        snprintf(why, why_size, "cannot create the capture %s: %s; check the folder exists and is writable", path,
                 strerror(errno));
        if (w->f != NULL) {
            fclose(w->f);
        }
        free(w);
        return NULL;
    }
    return w;
}

bool rtde_capture_connected(rtde_capture_writer *w, const char *peer)
{
    uint8_t pkg[3 + 255];
    size_t n = strlen(peer);
    n = n > 255 ? 255 : n;
    pkg[0] = (uint8_t)((3 + n) >> 8);
    pkg[1] = (uint8_t)(3 + n);
    pkg[2] = RTDE_CAPTURE_CONNECT;
    memcpy(pkg + 3, peer, n);
    w->have = 0;
    w->unframable = false;
    return put(w, RTDE_CAPTURE_CONNECT, pkg, 3 + n) && fflush(w->f) == 0;
}

bool rtde_capture_sent(rtde_capture_writer *w, const uint8_t *pkg, size_t size)
{
    return put(w, RTDE_CAPTURE_SENT, pkg, size) && fflush(w->f) == 0;
}

bool rtde_capture_received(rtde_capture_writer *w, const uint8_t *data, size_t len)
{
    while (len > 0 && !w->unframable) {
        /* The header first, then as much of the package as it announces. */
        size_t want = w->have < URRT_RTDE_HEADER_SIZE ? URRT_RTDE_HEADER_SIZE : be16(w->pending);
        size_t take = want - w->have < len ? want - w->have : len;
        memcpy(w->pending + w->have, data, take);
        w->have += take;
        data += take;
        len -= take;
        if (w->have == URRT_RTDE_HEADER_SIZE && want == URRT_RTDE_HEADER_SIZE) {
            size_t size = be16(w->pending);
            if (size < URRT_RTDE_HEADER_SIZE || size > URRT_RTDE_PACKAGE_MAX) {
                w->unframable = true;
                w->have = 0;
                break;
            }
            want = size;
        }
        if (w->have == want) {
            put(w, RTDE_CAPTURE_RECEIVED, w->pending, w->have);
            w->have = 0;
        }
    }
    return !w->failed && fflush(w->f) == 0;
}

bool rtde_capture_close(rtde_capture_writer *w, size_t *held, char *why, size_t why_size)
{
    bool ok = !w->failed;
    int error = w->error;
    if (held != NULL) {
        *held = w->have;
    }
    if (fclose(w->f) != 0 && ok) {
        ok = false;
        error = errno;
    }
    if (!ok) {
        snprintf(why, why_size, "cannot write the capture %s: %s; it ends at the last record written", w->path,
                 strerror(error));
    }
    free(w);
    return ok;
}

/* ---- reading records ---------------------------------------------------- */

struct rtde_capture {
    FILE *f;
    char name[256];
    uint8_t pkg[URRT_RTDE_PACKAGE_MAX];
    uint64_t offset;     /* bytes read so far */
    size_t truncated;
};

rtde_capture *rtde_capture_open(FILE *f, const char *name, char *why, size_t why_size)
{
    char head[RTDE_CAPTURE_MAGIC_LEN];
    size_t got = fread(head, 1, sizeof head, f);
    rtde_capture *c;
    if (got != sizeof head || memcmp(head, RTDE_CAPTURE_MAGIC, sizeof head) != 0) {
        snprintf(why, why_size, "%s is not an RTDE capture: it does not start with \"URRT RTDE capture 1\" "
                 "(record one with urrt-dump --rtde -w FILE)", name);
        return NULL;
    }
    c = calloc(1, sizeof *c);
    if (c == NULL) {
        snprintf(why, why_size, "out of memory reading %s", name);
        return NULL;
    }
    c->f = f;
    snprintf(c->name, sizeof c->name, "%s", name);
    c->offset = RTDE_CAPTURE_MAGIC_LEN;
    return c;
}

int rtde_capture_next(rtde_capture *c, rtde_capture_record *rec, char *why, size_t why_size)
{
    int kind = fgetc(c->f);
    size_t got, size;
    if (kind == EOF) {
        if (ferror(c->f)) {
            snprintf(why, why_size, "cannot read %s at byte %" PRIu64 ": %s", c->name, c->offset, strerror(errno));
            return -1;
        }
        return 0;
    }
    if (kind != RTDE_CAPTURE_CONNECT && kind != RTDE_CAPTURE_SENT && kind != RTDE_CAPTURE_RECEIVED) {
        snprintf(why, why_size, "%s: byte %" PRIu64 ": record kind 0x%02X is none of 'C', '>', '<': the capture is "
                 "damaged after this point", c->name, c->offset, (unsigned)kind);
        return -1;
    }
    got = fread(c->pkg, 1, URRT_RTDE_HEADER_SIZE, c->f);
    if (got < URRT_RTDE_HEADER_SIZE) {
        c->truncated = 1 + got;
        return 0;
    }
    size = be16(c->pkg);
    if (size < URRT_RTDE_HEADER_SIZE || size > URRT_RTDE_PACKAGE_MAX) {
        snprintf(why, why_size, "%s: byte %" PRIu64 ": a package of %zu bytes (RTDE's are 3 to %d): the capture is "
                 "damaged after this point", c->name, c->offset + 1, size, URRT_RTDE_PACKAGE_MAX);
        return -1;
    }
    got = fread(c->pkg + URRT_RTDE_HEADER_SIZE, 1, size - URRT_RTDE_HEADER_SIZE, c->f);
    if (got < size - URRT_RTDE_HEADER_SIZE) {
        c->truncated = 1 + URRT_RTDE_HEADER_SIZE + got;
        return 0;
    }
    rec->kind = (char)kind;
    rec->pkg = c->pkg;
    rec->size = size;
    rec->type = c->pkg[2];
    rec->offset = c->offset;
    c->offset += 1 + size;
    return 1;
}

size_t rtde_capture_truncated(const rtde_capture *c)
{
    return c->truncated;
}

void rtde_capture_free(rtde_capture *c)
{
    free(c);
}

/* ---- replaying through lib/urrt_rtde ------------------------------------ */

struct rtde_replay {
    rtde_capture *cap;
    urrt_rtde session;
    urrt_state state;
    urrt_rtde_values values;
    rtde_capture_record rec;   /* the record being fed */
    size_t fed;                /* bytes of rec fed so far */
    bool feeding;
    bool in_session;
    char peer[256];
    uint8_t data[URRT_RTDE_PACKAGE_MAX]; /* the last data package */
    size_t data_size;
};

rtde_replay *rtde_replay_open(FILE *f, const char *name, char *why, size_t why_size)
{
    rtde_replay *r = calloc(1, sizeof *r);
    if (r == NULL) {
        snprintf(why, why_size, "out of memory reading %s", name);
        return NULL;
    }
    r->cap = rtde_capture_open(f, name, why, why_size);
    if (r->cap == NULL) {
        free(r);
        return NULL;
    }
    urrt_rtde_init(&r->session);
    urrt_state_clear(&r->state);
    urrt_rtde_values_clear(&r->values);
    return r;
}

/* The variables of a recorded setup request, by the session's protocol. */
static int setup_vars(const rtde_replay *r, const rtde_capture_record *rec, uint16_t *vars, size_t *count,
                      char *why, size_t why_size)
{
    size_t at = URRT_RTDE_HEADER_SIZE + (r->session.protocol >= 2 ? 8u : 0u);
    *count = 0;
    if (rec->size <= at) {
        snprintf(why, why_size, "%s: byte %" PRIu64 ": a setup request without names", r->cap->name, rec->offset);
        return -1;
    }
    while (at < rec->size) {
        size_t end = at;
        int var;
        while (end < rec->size && rec->pkg[end] != ',') {
            end++;
        }
        var = urrt_rtde_var_find((const char *)rec->pkg + at, end - at);
        if (var < 0 || *count == URRT_RTDE_MAX_VARS) {
            snprintf(why, why_size, "%s: byte %" PRIu64 ": the recipe asks for \"%.*s\", %s", r->cap->name,
                     rec->offset, (int)(end - at > 64 ? 64 : end - at), (const char *)rec->pkg + at,
                     var < 0 ? "which this urrt does not know (a newer urrt wrote the capture?)"
                             : "past the most variables a recipe holds");
            return -1;
        }
        vars[(*count)++] = (uint16_t)var;
        at = end + 1;
    }
    return 0;
}

/* A request the capture's client sent: the session must have the same one
 * due (the capture follows urrt's handshake); a setup request's names
 * become the session's recipe first. */
static int take_request(rtde_replay *r, const rtde_capture_record *rec, char *why, size_t why_size)
{
    uint8_t out[URRT_RTDE_REQUEST_MAX];
    int n;
    if (rec->type == URRT_RTDE_TYPE_SETUP_OUTPUTS) {
        uint16_t vars[URRT_RTDE_MAX_VARS];
        size_t count;
        int e;
        if (setup_vars(r, rec, vars, &count, why, why_size) < 0) {
            return -1;
        }
        e = urrt_rtde_set_recipe(&r->session, vars, count);
        if (e < 0) {
            snprintf(why, why_size, "%s: byte %" PRIu64 ": the recorded recipe is refused: %s", r->cap->name,
                     rec->offset, urrt_rtde_strerror(e));
            return -1;
        }
    }
    n = urrt_rtde_output(&r->session, out, sizeof out);
    if (n < URRT_RTDE_HEADER_SIZE || out[2] != rec->type) {
        char due[16] = "none";
        if (n >= URRT_RTDE_HEADER_SIZE) {
            snprintf(due, sizeof due, "'%c'", out[2]);
        }
        snprintf(why, why_size, "%s: byte %" PRIu64 ": the client sent request type 0x%02X where urrt's handshake "
                 "has %s due: not a capture of urrt's client", r->cap->name, rec->offset, (unsigned)rec->type, due);
        return -1;
    }
    return 0;
}

int rtde_replay_next(rtde_replay *r, urrt_rtde_event *ev, char *why, size_t why_size)
{
    static const uint16_t placeholder[] = {URRT_RTDE_V_TIMESTAMP};
    memset(ev, 0, sizeof *ev);
    for (;;) {
        if (r->feeding && r->fed < r->rec.size) {
            size_t used = 0;
            int k = urrt_rtde_feed(&r->session, r->rec.pkg + r->fed, r->rec.size - r->fed, &used, ev, &r->state,
                                   &r->values);
            r->fed += used;
            if (k > 0) {
                if (k == URRT_RTDE_EV_DATA) {
                    memcpy(r->data, r->rec.pkg, r->rec.size);
                    r->data_size = r->rec.size;
                }
                return k;
            }
            if (k < 0) {
                r->fed = r->rec.size; /* the session ended: the rest of it is not read */
            }
            continue;
        }
        r->feeding = false;
        int got = rtde_capture_next(r->cap, &r->rec, why, why_size);
        if (got <= 0) {
            return got;
        }
        switch (r->rec.kind) {
        case RTDE_CAPTURE_CONNECT:
            urrt_rtde_finish(&r->session);
            /* The recipe arrives with the setup request; until then one
             * variable stands in (urrt_rtde_set_recipe replaces it). */
            urrt_rtde_begin(&r->session, placeholder, 1, 0.0);
            snprintf(r->peer, sizeof r->peer, "%.*s", (int)(r->rec.size - URRT_RTDE_HEADER_SIZE),
                     (const char *)r->rec.pkg + URRT_RTDE_HEADER_SIZE);
            r->in_session = true;
            return RTDE_REPLAY_SESSION;
        case RTDE_CAPTURE_SENT:
            if (!r->in_session || take_request(r, &r->rec, why, why_size) < 0) {
                if (!r->in_session) {
                    snprintf(why, why_size, "%s: byte %" PRIu64 ": a request before any connection", r->cap->name,
                             r->rec.offset);
                }
                return -1;
            }
            break;
        default: /* RTDE_CAPTURE_RECEIVED */
            if (!r->in_session) {
                snprintf(why, why_size, "%s: byte %" PRIu64 ": a package before any connection", r->cap->name,
                         r->rec.offset);
                return -1;
            }
            r->feeding = true;
            r->fed = 0;
            break;
        }
    }
}

const urrt_rtde *rtde_replay_session(const rtde_replay *r)
{
    return &r->session;
}

const urrt_state *rtde_replay_state(const rtde_replay *r)
{
    return &r->state;
}

const urrt_rtde_values *rtde_replay_values(const rtde_replay *r)
{
    return &r->values;
}

const uint8_t *rtde_replay_package(const rtde_replay *r, size_t *size)
{
    *size = r->data_size;
    return r->data;
}

const char *rtde_replay_peer(const rtde_replay *r)
{
    return r->peer;
}

bool rtde_replay_has(const rtde_replay *r, int var)
{
    const urrt_rtde *s = &r->session;
    for (size_t i = 0; i < s->var_count; i++) {
        if (s->vars[i] == var) {
            return !((s->not_found[i / 8] >> (i % 8)) & 1u);
        }
    }
    return false;
}

size_t rtde_replay_truncated(const rtde_replay *r)
{
    return rtde_capture_truncated(r->cap);
}

void rtde_replay_free(rtde_replay *r)
{
    if (r != NULL) {
        rtde_capture_free(r->cap);
        free(r);
    }
}
