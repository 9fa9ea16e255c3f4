/* SPDX-License-Identifier: MIT */
/*
 * check-rtde-capture: gateway/common/rtde_capture on the sessions
 * tests/ref/rtde_ref.py writes (the reference plays the controller).
 *
 * Each session is written as a capture, the controller's bytes handed to
 * the writer in two reads split at every point, and read back through
 * rtde_replay: its events and every decoded value must be those of lib's
 * client fed the same bytes directly (test_rtde.c holds those to the
 * reference), so the capture loses nothing a replay needs. Then the
 * records themselves (every package whole, in order, the peer), and the
 * ways a file can be wrong: another header, a cut, a bad kind, a bad size,
 * a request urrt's client does not make.
 *
 *   test_rtde_capture VECTORS SCRATCH_DIR
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "rtde_capture.h"

#define LINE_MAX_CHARS 20000
#define BYTES_MAX 16384
#define REQUESTS_MAX 16
#define TRANSCRIPT_MAX 8192

/* One session of the vectors: what the client sent and the controller's bytes. */
typedef struct session {
    char name[64];
    uint16_t vars[URRT_RTDE_MAX_VARS];
    size_t var_count;
    double freq;
    bool usable;                      /* a handshake urrt's client makes, with nothing scripted by the caller */
    uint8_t sent[REQUESTS_MAX][URRT_RTDE_REQUEST_MAX];
    size_t sent_size[REQUESTS_MAX];
    size_t sent_before[REQUESTS_MAX]; /* controller bytes received before each request */
    size_t nsent;
    uint8_t recv[BYTES_MAX];
    size_t nrecv;
} session;

static const char *scratch;

static size_t unhex(const char *h, uint8_t *out, size_t cap)
{
    size_t n = 0;
    while (h[0] != '\0' && h[1] != '\0' && n < cap) {
        unsigned v;
        if (sscanf(h, "%2x", &v) != 1) {
            break;
        }
        out[n++] = (uint8_t)v;
        h += 2;
    }
    return n;
}

/* ---- transcripts: every event and decoded value, as text ------------------- */

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const uint8_t *b = p;
    for (size_t i = 0; i < n; i++) {
        h = (h ^ b[i]) * 1099511628211ull;
    }
    return h;
}

static void note(char *t, size_t *at, int k, const urrt_rtde_event *ev, const urrt_state *st,
                 const urrt_rtde_values *vals)
{
    int n;
    if (*at >= TRANSCRIPT_MAX - 200) {
        return;
    }
    n = snprintf(t + *at, TRANSCRIPT_MAX - *at, "%d e%d p%u r%u l%u f%d v%u.%u.%u.%u t%.*s", k, ev->error,
                 ev->protocol, ev->recipe_id, ev->level, ev->first, (unsigned)ev->version[0],
                 (unsigned)ev->version[1], (unsigned)ev->version[2], (unsigned)ev->version[3],
                 k == URRT_RTDE_EV_TEXT ? (int)ev->text_len : 0, k == URRT_RTDE_EV_TEXT ? ev->text : "");
    *at += (size_t)n;
    if (k == URRT_RTDE_EV_DATA) {
        uint64_t h = fnv(1469598103934665603ull, st, sizeof *st);
        h = fnv(h, vals, sizeof *vals);
        n = snprintf(t + *at, TRANSCRIPT_MAX - *at, " %016llx", (unsigned long long)h);
        *at += (size_t)n;
    }
    t[(*at)++] = '\n';
    t[*at] = '\0';
}

/* lib's client fed the session directly, its requests taken after each event. */
static void direct(const session *s, char *t)
{
    static urrt_rtde r;
    static urrt_state st;
    static urrt_rtde_values vals;
    uint8_t out[URRT_RTDE_REQUEST_MAX];
    const uint8_t *p = s->recv;
    size_t len = s->nrecv, at = 0;
    urrt_rtde_init(&r);
    urrt_state_clear(&st);
    urrt_rtde_values_clear(&vals);
    t[0] = '\0';
    urrt_rtde_begin(&r, s->vars, s->var_count, s->freq);
    while (urrt_rtde_output(&r, out, sizeof out) > 0) {
    }
    while (len > 0) {
        size_t used = 0;
        urrt_rtde_event ev;
        int k = urrt_rtde_feed(&r, p, len, &used, &ev, &st, &vals);
        if (k <= 0) {
            break;
        }
        p += used;
        len -= used;
        note(t, &at, k, &ev, &st, &vals);
        while (urrt_rtde_output(&r, out, sizeof out) > 0) {
        }
    }
}

/* The session written as a capture, the controller's bytes in two reads split at cut. */
static bool write_capture(const session *s, const char *path, size_t cut)
{
    char why[256];
    size_t done = 0, held = 99;
    rtde_capture_writer *w = rtde_capture_create(path, why, sizeof why);
    CHECK(w != NULL, "%s", "");
    if (w == NULL) {
        return false;
    }
    rtde_capture_connected(w, "robot:30004");
    for (size_t i = 0; i <= s->nsent; i++) {
        size_t upto = i < s->nsent ? s->sent_before[i] : s->nrecv;
        /* The bytes received before this request, split at cut where it falls. */
        if (cut > done && cut < upto) {
            rtde_capture_received(w, s->recv + done, cut - done);
            done = cut;
        }
        rtde_capture_received(w, s->recv + done, upto - done);
        done = upto;
        if (i < s->nsent) {
            rtde_capture_sent(w, s->sent[i], s->sent_size[i]);
        }
    }
    CHECK(rtde_capture_close(w, &held, why, sizeof why), "%s", "");
    return held < 99;
}

static void replayed(const char *path, char *t, char *why, size_t why_size, int *last)
{
    FILE *f = fopen(path, "rb");
    rtde_replay *r;
    size_t at = 0;
    urrt_rtde_event ev;
    int k;
    t[0] = '\0';
    *last = -2;
    CHECK(f != NULL, "%s", "");
    if (f == NULL) {
        return;
    }
    r = rtde_replay_open(f, path, why, why_size);
    CHECK(r != NULL, "%s", "");
    if (r != NULL) {
        while ((k = rtde_replay_next(r, &ev, why, why_size)) > 0) {
            if (k == RTDE_REPLAY_SESSION) {
                CHECK_EQ_STR(rtde_replay_peer(r), "robot:30004");
            } else {
                note(t, &at, k, &ev, rtde_replay_state(r), rtde_replay_values(r));
            }
        }
        *last = k;
        rtde_replay_free(r);
    }
    fclose(f);
}

/* Whether the session's controller bytes hold a size no capture can frame:
 * the writer stops recording there (the client drops the session). */
static bool unframable(const session *s)
{
    size_t at = 0;
    while (at + URRT_RTDE_HEADER_SIZE <= s->nrecv) {
        size_t size = (size_t)s->recv[at] << 8 | s->recv[at + 1];
        if (size < URRT_RTDE_HEADER_SIZE || size > URRT_RTDE_PACKAGE_MAX) {
            return true;
        }
        at += size;
    }
    return false;
}

/* Whether the client ended the session on its own, before a request: a
 * frequency past the controller's maximum is refused without asking, so
 * the capture holds no trace of it. */
static bool client_refused(const char *t)
{
    char tail[32];
    snprintf(tail, sizeof tail, "%d e%d ", URRT_RTDE_EV_CONFIG, URRT_RTDE_E_FREQUENCY);
    return strstr(t, tail) != NULL;
}

static void check_session(const session *s)
{
    static char want[TRANSCRIPT_MAX], got[TRANSCRIPT_MAX];
    char path[512], why[256];
    int last;
    snprintf(path, sizeof path, "%s/%s.rtde", scratch, s->name);
    direct(s, want);
    for (size_t cut = 0; cut <= s->nrecv; cut++) {
        write_capture(s, path, cut);
        replayed(path, got, why, sizeof why, &last);
        if (unframable(s)) {
            /* What was recorded replays as lib decodes it; the rest is not there. */
            CHECK(strncmp(want, got, strlen(got)) == 0, "%s split at %zu", s->name, cut);
        } else if (client_refused(want)) {
            /* The same up to the controller's version, which this client refused. */
            size_t upto = (size_t)(strrchr(want, '\n') - want);
            while (upto > 0 && want[upto - 1] != '\n') {
                upto--;
            }
            CHECK(strncmp(want, got, upto) == 0 && strstr(got + upto, " v3.15.0.1 ") != NULL, "%s split at %zu",
                  s->name, cut);
        } else if (strcmp(want, got) != 0) {
            CHECK(false, "%s split at %zu: replay\n%s\ndirect\n%s", s->name, cut, got, want);
            return;
        }
        CHECK(last == 0, "%s: replay ended with %d: %s", s->name, last, why);
        if (s->nrecv > 600 && cut > 40 && cut < s->nrecv - 40) {
            cut += 37; /* long sessions: the boundaries and a sample between */
        }
    }
    CHECK(want[0] != '\0', "%s", "");
}

/* ---- the vectors ------------------------------------------------------------- */

static bool read_session(FILE *f, session *s)
{
    static char line[LINE_MAX_CHARS];
    bool in = false;
    memset(s, 0, sizeof *s);
    while (fgets(line, sizeof line, f) != NULL) {
        char *arg;
        line[strcspn(line, "\n")] = '\0';
        arg = strchr(line, ' ');
        if (arg != NULL) {
            *arg++ = '\0';
        }
        if (strcmp(line, "session") == 0) {
            snprintf(s->name, sizeof s->name, "%s", arg);
            s->usable = true;
            in = true;
        } else if (!in) {
            continue;
        } else if (strcmp(line, "vars") == 0) {
            for (char *name = strtok(arg, ","); name != NULL; name = strtok(NULL, ",")) {
                int var = urrt_rtde_var_find(name, strlen(name));
                if (var < 0 || s->var_count == URRT_RTDE_MAX_VARS) {
                    s->usable = false;
                } else {
                    s->vars[s->var_count++] = (uint16_t)var;
                }
            }
        } else if (strcmp(line, "freq") == 0) {
            s->freq = atof(arg);
        } else if (strcmp(line, "send") == 0) {
            if (s->nsent == REQUESTS_MAX) {
                s->usable = false;
            } else {
                s->sent_size[s->nsent] = unhex(arg, s->sent[s->nsent], URRT_RTDE_REQUEST_MAX);
                s->sent_before[s->nsent++] = s->nrecv;
            }
        } else if (strcmp(line, "recv") == 0) {
            size_t n = strlen(arg) / 2;
            if (s->nrecv + n > BYTES_MAX) {
                s->usable = false;
            } else {
                s->nrecv += unhex(arg, s->recv + s->nrecv, BYTES_MAX - s->nrecv);
            }
        } else if (strcmp(line, "begin_error") == 0 || strcmp(line, "pause") == 0 || strcmp(line, "start") == 0 ||
                   strncmp(line, "set_recipe", 10) == 0) {
            s->usable = false; /* the caller scripts what a capture's client never does */
        } else if (strcmp(line, "end") == 0) {
            return true;
        }
    }
    return false;
}

static size_t run_vectors(const char *path)
{
    static session s;
    size_t used = 0;
    FILE *f = fopen(path, "r");
    CHECK(f != NULL, "%s", "");
    if (f == NULL) {
        return 0;
    }
    while (read_session(f, &s)) {
        if (s.usable && s.nsent > 0) {
            check_session(&s);
            used++;
        }
    }
    fclose(f);
    return used;
}

/* ---- the records and the broken files ----------------------------------------- */

static void write_bytes(const char *path, const uint8_t *p, size_t n)
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL, "%s", "");
    if (f != NULL) {
        CHECK(fwrite(p, 1, n, f) == n, "%s", "");
        fclose(f);
    }
}

static size_t read_bytes(const char *path, uint8_t *p, size_t cap)
{
    FILE *f = fopen(path, "rb");
    size_t n = 0;
    if (f != NULL) {
        n = fread(p, 1, cap, f);
        fclose(f);
    }
    return n;
}

/* What reading path ends with: the records read, the last result and its reason. */
static int read_records(const char *path, size_t *count, size_t *truncated, char *why, size_t why_size)
{
    FILE *f = fopen(path, "rb");
    rtde_capture *c;
    rtde_capture_record rec;
    int k = -9;
    *count = 0;
    *truncated = 0;
    why[0] = '\0';
    if (f == NULL) {
        return -9;
    }
    c = rtde_capture_open(f, path, why, why_size);
    if (c != NULL) {
        while ((k = rtde_capture_next(c, &rec, why, why_size)) > 0) {
            (*count)++;
        }
        *truncated = rtde_capture_truncated(c);
        rtde_capture_free(c);
    }
    fclose(f);
    return k;
}

static void test_records(void)
{
    static const uint8_t v_req[] = {0, 5, 'V', 0, 2}, v_ok[] = {0, 4, 'V', 1};
    static const uint8_t text[] = {0, 9, 'M', 3, 'a', 'b', 'c', 0, 3};
    static uint8_t file[4096];
    char path[512], bad[512], why[256];
    size_t n, count, truncated, held;
    rtde_capture_writer *w;
    FILE *f;
    snprintf(path, sizeof path, "%s/records.rtde", scratch);
    snprintf(bad, sizeof bad, "%s/bad.rtde", scratch);
    w = rtde_capture_create(path, why, sizeof why);
    CHECK(w != NULL, "%s", "");
    if (w == NULL) {
        return;
    }
    CHECK(rtde_capture_connected(w, "[::1]:30004"), "%s", "");
    CHECK(rtde_capture_sent(w, v_req, sizeof v_req), "%s", "");
    CHECK(rtde_capture_received(w, v_ok, 1), "%s", "");      /* a package in three reads, */
    CHECK(rtde_capture_received(w, v_ok + 1, 2), "%s", "");
    CHECK(rtde_capture_received(w, v_ok + 3, 1), "%s", "");
    CHECK(rtde_capture_received(w, text, 5), "%s", "");      /* then one and a half */
    CHECK(rtde_capture_connected(w, "robot:30004"), "%s", ""); /* a reconnect drops the half */
    CHECK(rtde_capture_received(w, text, sizeof text), "%s", "");
    CHECK(rtde_capture_received(w, text, 4), "%s", "");      /* kept back at the close */
    CHECK(rtde_capture_close(w, &held, why, sizeof why), "%s", "");
    CHECK_EQ_INT(held, 4u);

    n = read_bytes(path, file, sizeof file);
    {
        static const uint8_t want[] = {'U', 'R', 'R', 'T', ' ', 'R', 'T', 'D', 'E', ' ', 'c', 'a', 'p', 't', 'u', 'r', 'e', ' ', '1', '\n',
                                       'C', 0, 14, 'C', '[', ':', ':', '1', ']', ':', '3', '0', '0', '0', '4',
                                       '>', 0, 5, 'V', 0, 2,
                                       '<', 0, 4, 'V', 1,
                                       'C', 0, 14, 'C', 'r', 'o', 'b', 'o', 't', ':', '3', '0', '0', '0', '4',
                                       '<', 0, 9, 'M', 3, 'a', 'b', 'c', 0, 3};
        CHECK_EQ_INT(n, sizeof want);
        CHECK(n == sizeof want && memcmp(file, want, n) == 0, "%s", "");
    }
    CHECK_EQ_INT(read_records(path, &count, &truncated, why, sizeof why), 0);
    CHECK_EQ_INT(count, 5u);
    CHECK_EQ_INT(truncated, 0u);

    /* Cut at every byte: the records before the cut, the cut reported. */
    for (size_t cut = RTDE_CAPTURE_MAGIC_LEN; cut < n; cut++) {
        static const size_t ends[] = {35, 41, 46, 61, 73};
        size_t whole = 0, at = RTDE_CAPTURE_MAGIC_LEN;
        while (whole < 5 && ends[whole] <= cut) {
            at = ends[whole++];
        }
        write_bytes(bad, file, cut);
        CHECK_EQ_INT(read_records(bad, &count, &truncated, why, sizeof why), 0);
        CHECK_EQ_INT(count, whole);
        CHECK_EQ_INT(truncated, cut - at);
    }

    /* A bad kind byte, a size out of bounds: the offset and the reason. */
    file[35] = 'X';
    write_bytes(bad, file, n);
    CHECK_EQ_INT(read_records(bad, &count, &truncated, why, sizeof why), -1);
    CHECK_EQ_INT(count, 1u);
    CHECK(strstr(why, "byte 35: record kind 0x58") != NULL, "%s", "");
    file[35] = '>';
    file[42] = 0x10; /* '<' V reply's size 0x1004: past 4096 */
    write_bytes(bad, file, n);
    CHECK_EQ_INT(read_records(bad, &count, &truncated, why, sizeof why), -1);
    CHECK(strstr(why, "byte 42: a package of 4100 bytes") != NULL, "%s", "");
    file[42] = 0;
    file[43] = 2; /* and below its own header */
    write_bytes(bad, file, n);
    CHECK_EQ_INT(read_records(bad, &count, &truncated, why, sizeof why), -1);
    CHECK(strstr(why, "a package of 2 bytes") != NULL, "%s", "");

    /* Another header: a RealTime capture, an older or foreign file. */
    {
        static const uint8_t realtime[] = {0, 0, 4, 0x5C, 0x40, 0x8F};
        write_bytes(bad, realtime, sizeof realtime);
        CHECK_EQ_INT(read_records(bad, &count, &truncated, why, sizeof why), -9);
        CHECK(strstr(why, "is not an RTDE capture") != NULL, "%s", "");
        write_bytes(bad, (const uint8_t *)"URRT RTDE capture 2\n", 20);
        CHECK_EQ_INT(read_records(bad, &count, &truncated, why, sizeof why), -9);
        write_bytes(bad, (const uint8_t *)"URRT RTDE", 9);
        CHECK_EQ_INT(read_records(bad, &count, &truncated, why, sizeof why), -9);
    }

    /* A request urrt's client does not make at that point (a pause first). */
    {
        static const uint8_t pause_req[] = {0, 3, 'P'};
        rtde_replay *r;
        urrt_rtde_event ev;
        w = rtde_capture_create(bad, why, sizeof why);
        CHECK(w != NULL, "%s", "");
        if (w == NULL) {
            return;
        }
        rtde_capture_connected(w, "robot:30004");
        rtde_capture_sent(w, pause_req, sizeof pause_req);
        CHECK(rtde_capture_close(w, NULL, why, sizeof why), "%s", "");
        f = fopen(bad, "rb");
        r = f != NULL ? rtde_replay_open(f, bad, why, sizeof why) : NULL;
        CHECK(r != NULL, "%s", "");
        if (r != NULL) {
            CHECK_EQ_INT(rtde_replay_next(r, &ev, why, sizeof why), RTDE_REPLAY_SESSION);
            CHECK_EQ_INT(rtde_replay_next(r, &ev, why, sizeof why), -1);
            CHECK(strstr(why, "request type 0x50 where urrt's handshake has 'V' due") != NULL, "%s", "");
            rtde_replay_free(r);
        }
        if (f != NULL) {
            fclose(f);
        }
    }

    /* A file that cannot be created: the reason says what to do. */
    CHECK(rtde_capture_create("/nonexistent-dir/x.rtde", why, sizeof why) == NULL, "%s", "");
    CHECK(strstr(why, "cannot create the capture /nonexistent-dir/x.rtde") != NULL, "%s", "");
}

int main(int argc, char **argv)
{
    size_t sessions;
    if (argc != 3) {
        fprintf(stderr, "usage: %s VECTORS SCRATCH_DIR\n", argv[0]);
        return 2;
    }
    scratch = argv[2];
    sessions = run_vectors(argv[1]);
    CHECK(sessions >= 25, "%s", "");
    printf("%zu reference sessions written and replayed at every split\n", sessions);
    test_records();
    return check_report();
}
