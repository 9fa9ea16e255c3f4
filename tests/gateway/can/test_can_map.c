/* SPDX-License-Identifier: MIT */
/*
 * check-can-map: gateway/can/can_map with its tables, gateway/can/can_run
 * (configurations loaded as the gateway loads them, and their rejections
 * with FILE:LINE, bus load against hand-computed figures, scheduling,
 * staleness, alive counters and the heartbeat on a fake clock) and the DBC
 * text; [input NAME] frames (the PLC's): what they hold, every refusal with
 * its message and line, their DBC text. The bit packing underneath is tests/lib/test_can.c's; the DBC and
 * bulk packing are checked against python3-canmatrix by test_dbc.py.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "can_map.h"
#include "can_run.h"
#include "check.h"
#include "config.h"
#include "dbc.h"
#include "testutil.h"
#include "urrt_can.h"
#include "urrt_rtde.h"

/* ---- can_map: configuration ---------------------------------------------------------- */

/* The CAN side as the gateway has it: the file loaded by the gateway's
 * loader (gateway/urrt-gateway/config.c), the map and its tables kept. */

/* The tables of the map load() gave last: what the scheduling tests run
 * (unload() frees both). */
static struct can_run *loaded_run;

static const struct can_map_robot one_robot[] = {{"arm", 8000}};

/* Loads text as "t.ini" through the gateway's loader, with a [robot NAME]
 * section after it for each of robots (its period from its version: 8000
 * us a 3.10 controller's, else 5.10's 2000), and keeps its map in *map and
 * its tables in loaded_run: 0, or -1 with the messages in err, causes
 * first, one per line. */
static int load(struct can_map *map, const char *text, const struct can_map_robot *robots, size_t n, char *err,
                size_t errlen)
{
    char *file = NULL, *messages = NULL;
    size_t file_size = 0, size = 0;
    FILE *in = open_memstream(&file, &file_size);
    FILE *out = open_memstream(&messages, &size);
    gw_config cfg;
    int errors;
    fputs(text, in);
    for (size_t i = 0; i < n; i++) {
        fprintf(in, "\n[robot %s]\nhost = h\nversion = %s\n", robots[i].name,
                robots[i].period_us == 8000 ? "3.10" : "5.10");
    }
    fclose(in);
    in = fmemopen(file, file_size, "r");
    errors = gw_config_load_stream(&cfg, in, "t.ini", out);
    fclose(in);
    fclose(out);
    snprintf(err, errlen, "%.*s", (int)(size > 0 && messages[size - 1] == '\n' ? size - 1 : size), messages);
    *map = cfg.can;
    loaded_run = cfg.can_run;
    memset(&cfg.can, 0, sizeof cfg.can);
    cfg.can_run = NULL;
    gw_config_free(&cfg);
    free(file);
    free(messages);
    return errors == 0 ? 0 : -1;
}

static void unload(struct can_map *map)
{
    can_run_free(loaded_run);
    loaded_run = NULL;
    can_map_free(map);
}

#define CAN_HEAD "[can]\ninterface = vcan0\nheartbeat_id = 0x701\n"

static const char *const good_config =
    "; a comment\n"
    "[can]\n"
    "interface = vcan0\n"
    "bitrate = 500000\n"
    "heartbeat_id = 0x701\n"
    "\n"
    "[frame joints]\n"
    "id = 0x181\n"
    "period_ms = 10\n"
    "signal = q_actual[0] @0|16 intel signed factor=0.0001 unit=rad\n"
    "signal = q_actual[1] @16|16 intel signed factor=0.0001\n"
    "signal = tool_vector_actual[4] @39|16 motorola signed factor=0.0001 name=rx\n"
    "alive_counter = 56\n"
    "validity_bit = 63\n"
    "\n"
    "[frame status]\n"
    "id = 0x18FF0080\n"
    "extended = yes\n"
    "period_ms = every\n"
    "length = 4\n"
    "signal = robot_mode @0|8 intel signed\n"
    "signal = digital_input_bits @8|18 intel unsigned\n"
    "signal = v_robot @26|6 intel unsigned factor=2 offset=0 min=0 max=60 unit=\"V DC\"\n";

static void test_config_good(void)
{
    struct can_map map;
    char err[2048] = "";
    int rc = load(&map, good_config, one_robot, 1, err, sizeof err);
    CHECK(rc == 0, "good config rejected: %s", err);
    if (rc != 0) {
        unload(&map);
        return;
    }
    CHECK(can_map_enabled(&map), "enabled");
    {
        urrt_canlink_config cfg;
        char line[256];
        memset(&cfg, 0, sizeof cfg);
        cfg.reopen_interval_ms = 1234;
        can_map_link_config(&map, &cfg);
        CHECK(cfg.interface == map.interface && !cfg.fd && !cfg.fd_brs && cfg.reopen_interval_ms == 1234,
              "link configuration");
        can_map_describe(&map, line, sizeof line);
        /* 2.7 % + 29-bit 4 bytes (54+32+13+21 = 120 bits, 240 us) every 8 ms 3.0 % + 0.27 %, the parts
         * after the colon */
        CHECK_EQ_STR(line, "2 frames + heartbeat 0x701 on vcan0, worst-case bus load 6.0% of 500000 bit/s (max 50%): "
                           "frames 5.70% + heartbeat 0.27%");
    }
    CHECK_EQ_STR(map.interface, "vcan0");
    CHECK_EQ_INT(map.frame_count, 2);
    CHECK_EQ_INT(map.hb_id, 0x701);
    {
        const struct can_map_frame *j = &map.frames[0];
        CHECK_EQ_STR(j->name, "joints");
        CHECK(j->id == 0x181 && !j->extended && !j->fd && j->len == 8 && j->period_ms == 10 && !j->every, "joints");
        CHECK_EQ_INT(j->count, 5);
        CHECK_EQ_STR(j->meta[0].name, "q_actual_0");
        CHECK_EQ_STR(j->meta[0].unit, "rad");
        CHECK_EQ_STR(j->meta[1].unit, "rad"); /* from the field table */
        CHECK_EQ_STR(j->meta[2].name, "rx");
        CHECK_EQ_STR(j->meta[2].unit, "rad"); /* "m, rad": element 4 is a rotation */
        CHECK(j->sigs[0].min == -3.2768 && j->sigs[0].max == 3.2767, "q range %.17g %.17g", j->sigs[0].min,
              j->sigs[0].max);
        CHECK(j->sigs[2].byte_order == URRT_CAN_MOTOROLA && j->sigs[2].start == 39, "motorola parsed");
        CHECK(j->alive_index == 3 && j->valid_index == 4, "alive %d valid %d", j->alive_index, j->valid_index);
        CHECK_EQ_INT(j->stale_after_ms, 100u);
        CHECK(j->stale_policy == CAN_MAP_STALE_STOP, "default policy stop");
        CHECK_EQ_INT(j->key_loc[CAN_MAP_FK_ID].line, 8);
    }
    {
        const struct can_map_frame *s = &map.frames[1];
        CHECK(s->id == 0x18FF0080 && s->extended && s->every && s->len == 4, "status frame");
        CHECK_EQ_STR(s->meta[0].unit, "");
        CHECK(s->meta[1].bitmask, "digital inputs are a bit mask");
        CHECK_EQ_STR(s->meta[2].unit, "V DC");
        CHECK(s->sigs[2].min == 0 && s->sigs[2].max == 60, "v_robot limits");
    }
    unload(&map);

    /* No CAN configuration at all: finishes, stays disabled. */
    rc = load(&map, "[other]\nkey = 1\n", one_robot, 1, err, sizeof err);
    CHECK(rc == -1 && strstr(err, "t.ini:1: unknown section [other]") == err, "[other] is no section: %s", err);
    unload(&map);
    can_map_init(&map);
    CHECK_EQ_INT(can_map_finish(&map, one_robot, 1, err, sizeof err), 0);
    CHECK(!can_map_enabled(&map), "no CAN sections: disabled");
    unload(&map);
}

struct rejection {
    const char *config;
    const char *expect; /* the first error begins with this */
};

static const struct rejection rejections[] = {
    /* Syntax of keys and values. */
    {CAN_HEAD "bogus = 1\n", "t.ini:4: unknown key \"bogus\" in [can]"},
    {CAN_HEAD "interface = can1\n", "t.ini:4: interface is set again (first at line 2)"},
    {CAN_HEAD "heartbeat_period_ms = 1001\n", "t.ini:4: heartbeat_period_ms = '1001': give 10..1000"},
    {CAN_HEAD "bitrate = fast\n", "t.ini:4: bitrate = 'fast': give bits per second"},
    {CAN_HEAD "[frame 9lives]\nid = 1\n", "t.ini:4: [frame 9lives]: the frame name is its DBC name"},
    {CAN_HEAD "[frame urrt_heartbeat]\nid = 1\n", "t.ini:4: [frame urrt_heartbeat]: that name is the heartbeat's"},
    {CAN_HEAD "[frame a]\nid = 0x100\nid = 0x101\n", "t.ini:6: id is set again (first at line 5)"},
    {CAN_HEAD "[frame a]\ncolour = red\n", "t.ini:5: unknown key \"colour\" in [frame a]"},
    {CAN_HEAD "[frame a]\nperiod_ms = sometimes\n", "t.ini:5: period_ms = 'sometimes'"},
    {CAN_HEAD "[frame a]\nstale_policy = ignore\n", "t.ini:5: stale_policy = 'ignore': use stop or invalid"},
    {CAN_HEAD "[frame a]\nsignal = q_actual[0] @0|16 intel\n", "t.ini:5: signal = 'q_actual[0] @0|16 intel': expected"},
    {CAN_HEAD "[frame a]\nsignal = q_actual[6] @0|16 intel signed\n",
     "t.ini:5: signal: q_actual has 6 elements: q_actual[6] is out of range (0..5)"},
    {CAN_HEAD "[frame a]\nsignal = q_actual @0|16 intel signed\n",
     "t.ini:5: signal: q_actual has 6 elements: write q_actual[0] .. q_actual[5]"},
    {CAN_HEAD "[frame a]\nsignal = q_wrong[0] @0|16 intel signed\n", "t.ini:5: signal: no field 'q_wrong'"},
    {CAN_HEAD "[frame a]\nsignal = time @0|65 intel unsigned\n",
     "t.ini:5: [frame a] signal 'time': length 65: give 1..64 bits"},
    {CAN_HEAD "[frame a]\nsignal = q_actual[2] @0|0 intel signed name=q2\n",
     "t.ini:5: [frame a] signal 'q_actual[2]': length 0: give 1..64 bits"},
    /* Bit masks (fields of unit "bits") are sent bit for bit. */
    {CAN_HEAD "[frame a]\nsignal = digital_input_bits @0|16 intel unsigned factor=2\n",
     "t.ini:5: signal: digital_input_bits is a bit mask, sent bit for bit: remove factor= (bits=FIRST-LAST picks"},
    {CAN_HEAD "[frame a]\nsignal = digital_outputs @0|16 intel unsigned offset=1\n",
     "t.ini:5: signal: digital_outputs is a bit mask, sent bit for bit: remove offset="},
    {CAN_HEAD "[frame a]\nsignal = digital_outputs @0|16 intel unsigned min=0\n",
     "t.ini:5: signal: digital_outputs is a bit mask, sent bit for bit: remove min="},
    {CAN_HEAD "[frame a]\nsignal = digital_input_bits @0|16 intel unsigned max=65535\n",
     "t.ini:5: signal: digital_input_bits is a bit mask, sent bit for bit: remove max="},
    {CAN_HEAD "[frame a]\nsignal = digital_input_bits @0|16 intel signed\n",
     "t.ini:5: signal: digital_input_bits is a bit mask: its type is unsigned, not signed"},
    {CAN_HEAD "[frame a]\nsignal = digital_outputs @0|32 intel float32\n",
     "t.ini:5: signal: digital_outputs is a bit mask: its type is unsigned, not float32"},
    {CAN_HEAD "[frame a]\nsignal = digital_input_bits @0|4 intel unsigned bits=16-17\n",
     "t.ini:5: signal: bits=16-17 are 2 bits, but the signal has 4: make them agree"},
    {CAN_HEAD "[frame a]\nsignal = digital_input_bits @0|2 intel unsigned bits=17\n",
     "t.ini:5: signal: bits=17-17 is 1 bit, but the signal has 2: make them agree"},
    {CAN_HEAD "[frame a]\nsignal = digital_input_bits @0|1 intel unsigned bits=17-16\n",
     "t.ini:5: signal: bits = '17-16': give FIRST-LAST with 0 <= FIRST <= LAST <= 63"},
    {CAN_HEAD "[frame a]\nsignal = digital_input_bits @0|1 intel unsigned bits=64\n",
     "t.ini:5: signal: bits = '64': give FIRST-LAST with 0 <= FIRST <= LAST <= 63"},
    {CAN_HEAD "[frame a]\nsignal = digital_input_bits @0|1 intel unsigned bits=-3\n",
     "t.ini:5: signal: bits = '-3': give the mask's bits as FIRST-LAST (16-17) or one BIT"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned bits=0-7\n",
     "t.ini:5: signal: bits= is for bit masks (fields of unit bits, such as digital_input_bits), not time"},
    {CAN_HEAD "[frame a]\nsignal = time @512|8 intel unsigned\n", "t.ini:5: signal: start bit 512"},
    {CAN_HEAD "[frame a]\nsignal = time 0|8 intel unsigned\n", "t.ini:5: signal: '0|8': expected @START|LENGTH"},
    {CAN_HEAD "[frame a]\nsignal = time @0|16 intel float32\n", "t.ini:5: signal: float32 needs length 32, not 16"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 unsigned factor=1\n", "t.ini:5: signal: byte order missing"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel\n", "t.ini:5: signal = 'time @0|8 intel': expected"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned big\n", "t.ini:5: signal: unknown word 'big'"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel intel unsigned\n", "t.ini:5: signal: 'intel': byte order given twice"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned factor=0\n", "t.ini:5: signal: factor must not be 0"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned factor=x\n", "t.ini:5: signal: factor = 'x' is not a finite number"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned max=256\n",
     "t.ini:5: signal: max=256 is above what the signal can carry (255)"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel signed min=-200\n",
     "t.ini:5: signal: min=-200 is below what the signal can carry (-128)"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned min=10 max=5\n", "t.ini:5: signal: min=10 is above max=5"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned invalid=256\n", "t.ini:5: signal: invalid=256 does not fit 8 bits"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned invalid=-1\n", "t.ini:5: signal: invalid=-1 does not fit 8 unsigned bits"},
    {CAN_HEAD "[frame a]\nsignal = time @0|32 intel float32 invalid=0\n", "t.ini:5: signal: invalid= applies to integer signals"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned name=1x\n", "t.ini:5: signal: name '1x'"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned colour=red\n", "t.ini:5: signal: unknown option 'colour='"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned unit=\"a\n", "t.ini:5: signal: unbalanced quotes"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned\nsignal = time @8|8 intel unsigned\n",
     "t.ini:6: signal name 'time' already used in [frame a] (line 5): add name=OTHER"},
    {CAN_HEAD "[frame a]\nalive_counter = 99 big\n", "t.ini:5: alive_counter: byte order 'big'"},
    /* Control characters would go raw into the DBC and the log (found by
     * tests/gateway/config/fuzz_config.c). */
    {CAN_HEAD "[frame a]\ncomment = Joint\x01" "positions\n",
     "t.ini:5: comment: at most 127 characters, no '\"', '\\' or control characters"},
    {CAN_HEAD "[frame a]\nsignal = time @0|8 intel unsigned unit=r\x7f" "ad\n",
     "t.ini:5: signal: unit 'r\\x7Fad': at most 24 characters, no '\"', '\\' or control characters"},
    {"[can]\ninterface = log:/tmp/a\x1b[2J\n", "t.ini:2: interface = 'log:/tmp/a\\x1B[2J': no control characters"},
    {CAN_HEAD "[frame a]\nvalidity_bit = 600\n", "t.ini:5: validity_bit = 600: give a bit number 0..511"},
    /* Whole-file checks (can_map_finish). */
    {"[frame a]\nid = 1\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:1: CAN frames need a [can] section"},
    {"[can]\nheartbeat_id = 0x700\n[frame a]\nid = 1\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:1: [can] has no interface"},
    {"[can]\ninterface = can0\n[frame a]\nid = 1\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:1: [can] has no heartbeat_id"},
    {CAN_HEAD, "t.ini:1: [can] without any [frame NAME] or [input NAME] section: nothing to send or receive"},
    {CAN_HEAD "[frame a]\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n", "t.ini:4: [frame a] has no id"},
    {CAN_HEAD "[frame a]\nid = 0x800\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:5: [frame a] id 0x800 is past 0x7FF, the largest 11-bit id: set extended = yes"},
    {CAN_HEAD "[frame a]\nid = 0x20000000\nextended = yes\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:5: [frame a] id 0x20000000 is past 0x1FFFFFFF, the largest 29-bit id"},
    {CAN_HEAD "heartbeat_extended = no\n[frame a]\nid = 0x701\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:3: the heartbeat id 0x701 is already used by [frame a] (line 6)"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n"
              "[frame b]\nid = 0x100\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:9: [frame b] id 0x100 is already used by [frame a] (line 5)"},
    {CAN_HEAD "[frame a]\nid = 0x100\nlength = 12\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:6: [frame a] length 12: a classic CAN frame carries at most 8 bytes"},
    {CAN_HEAD "fd = yes\n[frame a]\nid = 0x100\nfd = yes\nlength = 10\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:8: [frame a] length 10 is not a CAN FD length (0-8, 12, 16, 20, 24, 32, 48, 64): use 12"},
    {CAN_HEAD "[frame a]\nid = 0x100\nfd = yes\nlength = 12\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:6: [frame a] is a CAN FD frame but [can] fd is not yes"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = time @0|16 intel unsigned\n"
              "signal = robot_mode @8|8 intel signed\n",
     "t.ini:8: [frame a] signal 'robot_mode' overlaps signal 'time' (line 7)"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = time @0|16 intel unsigned\nalive_counter = 12\n",
     "t.ini:8: [frame a] signal 'alive_counter' overlaps signal 'time' (line 7)"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nvalidity_bit = 7\nsignal = time @0|8 intel unsigned\n",
     "t.ini:8: [frame a] signal 'time' overlaps signal 'valid' (line 7)"},
    {CAN_HEAD "[frame a]\nid = 0x100\nlength = 2\nperiod_ms = 10\nsignal = time @8|16 intel unsigned\n",
     "t.ini:8: [frame a] signal 'time' (@8|16) reaches byte 2, past the frame's length 2"},
    {CAN_HEAD "[frame a]\nid = 0x100\nlength = 2\nperiod_ms = 10\nsignal = time @15|16 motorola unsigned\n",
     "t.ini:8: [frame a] signal 'time' (@15|16) reaches byte 2, past the frame's length 2"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 5\nsignal = time @0|8 intel unsigned\n",
     "t.ini:6: [frame a] period_ms = 5 is faster than robot arm sends (every 8 ms, 125 Hz): use period_ms >= 8 or every"},
    {CAN_HEAD "[frame a]\nid = 0x100\nrobot = bob\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:6: [frame a]: unknown robot 'bob' (robots: arm)"},
    {CAN_HEAD "[frame a]\nid = 0x100\nsignal = time @0|8 intel unsigned\n",
     "t.ini:4: [frame a] has no period_ms"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\n", "t.ini:4: [frame a] has no signal"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nstale_policy = invalid\nsignal = time @0|8 intel unsigned\n",
     "t.ini:7: [frame a] stale_policy = invalid needs a validity_bit"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = every\nvalidity_bit = 63\nstale_policy = invalid\n"
              "signal = time @0|8 intel unsigned\n",
     "t.ini:8: [frame a]: a period_ms = every frame stops with the packets"},
    {CAN_HEAD "data_bitrate = 2000000\n[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
     "t.ini:4: data_bitrate is for CAN FD"},
    {CAN_HEAD "max_bus_load = 5\n[frame a]\nid = 0x100\nperiod_ms = 1\nperiod_ms = 2\n", "t.ini:8: period_ms is set again (first at line 7)"},
};

static void test_config_rejections(void)
{
    size_t i;
    for (i = 0; i < sizeof rejections / sizeof rejections[0]; i++) {
        struct can_map map;
        char err[4096] = "";
        const struct can_map_robot robots[] = {{"arm", 8000}};
        int rc = load(&map, rejections[i].config, robots, 1, err, sizeof err);
        CHECK(rc == -1 && strncmp(err, rejections[i].expect, strlen(rejections[i].expect)) == 0,
              "rejection %zu:\n  got:  %s\n  want: %s", i, err, rejections[i].expect);
        unload(&map);
    }
}

struct reported {
    int count;
    char first[512];
    int first_line;
};

static void record_problem(void *ctx, const char *file, int line, const char *reason)
{
    struct reported *r = ctx;
    if (r->count++ == 0) {
        snprintf(r->first, sizeof r->first, "%s|%s", file, reason);
        r->first_line = line;
    }
}

/* A caller with its own error list (the loader) gets file, line and reason
 * apart; a key's own error is the caller's to report. */
static void test_reporter(void)
{
    struct can_map map;
    struct reported r;
    struct can_map_frame *f;
    char why[CONF_WHY_MAX] = "";
    memset(&r, 0, sizeof r);
    can_map_init(&map);
    can_map_set_reporter(&map, record_problem, &r);
    f = can_map_frame_begin(&map, "a", (struct conf_at){"gw.ini", 11}, why, sizeof why);
    CHECK(f != NULL, "frame: %s", why);
    if (f == NULL) {
        can_map_free(&map);
        return;
    }
    CHECK(!can_map_set(&map, f, &can_map_frame_keys[CAN_MAP_FK_ID], "zz", (struct conf_at){"gw.ini", 12}, why,
                       sizeof why),
          "id zz accepted");
    CHECK_EQ_STR(why, "id = 'zz' is not a number (0x181 or 385)");
    CHECK(can_map_set(&map, f, &can_map_frame_keys[CAN_MAP_FK_SIGNAL], "time @0|8 intel unsigned",
                      (struct conf_at){"gw.ini", 13}, why, sizeof why),
          "signal: %s", why);
    CHECK_EQ_INT(r.count, 0);
    CHECK_EQ_INT(can_map_finish(&map, one_robot, 1, NULL, 0), -1);
    /* No [can] section, and the frame has neither id nor period: three problems. */
    CHECK(r.count == 3 && r.first_line == 11, "finish reported %d, first at %d: %s", r.count, r.first_line, r.first);
    CHECK_EQ_STR(r.first, "gw.ini|CAN frames need a [can] section (interface, heartbeat_id, ...)");
    can_map_free(&map);
}

static void test_config_robots(void)
{
    struct can_map map;
    char err[4096] = "";
    const struct can_map_robot two[] = {{"left", 2000}, {"right", 8000}};
    const char *cfg = CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n";
    int rc = load(&map, cfg, two, 2, err, sizeof err);
    CHECK(rc == -1, "several robots need robot = NAME");
    CHECK(strstr(err, "t.ini:1: heartbeat: the gateway has 2 robots (left, right): say which with heartbeat_robot = NAME") != NULL,
          "heartbeat robot: %s", err);
    CHECK(strstr(err, "t.ini:4: [frame a]: the gateway has 2 robots (left, right): say which with robot = NAME") != NULL,
          "frame robot: %s", err);
    unload(&map);
    rc = load(&map,
              CAN_HEAD "heartbeat_robot = right\n[frame a]\nid = 0x100\nrobot = left\nperiod_ms = 2\n"
                       "signal = time @0|8 intel unsigned\n",
              two, 2, err, sizeof err);
    CHECK(rc == 0, "two robots: %s", err);
    if (rc == 0) {
        CHECK(map.frames[0].robot_index == 0 && map.hb_robot_index == 1, "robots resolved");
    }
    unload(&map);
    /* Every error is reported, one per line. */
    rc = load(&map,
              CAN_HEAD "[frame a]\nid = 0x900\nperiod_ms = 10\nsignal = time @0|16 intel unsigned\n"
                       "signal = robot_mode @8|8 intel signed\n",
              one_robot, 1, err, sizeof err);
    CHECK(rc == -1 && strstr(err, "t.ini:5: [frame a] id 0x900") == err &&
              strstr(err, "\nt.ini:8: [frame a] signal 'robot_mode' overlaps") != NULL,
          "two errors: %s", err);
    unload(&map);
}

/* ---- can_map: bus load ---------------------------------------------------------------- */

static void test_bus_load(void)
{
    struct can_map map;
    char err[4096] = "";
    int rc;
    /* 500 kbit/s, 2 us per bit. 11-bit, 8 bytes: 135 bits = 270 us; every
     * 10 ms is 2.7 %. The heartbeat (11-bit, 8 bytes, 100 ms) is 0.27 %. */
    rc = load(&map, CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n", one_robot,
              1, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    CHECK(fabs(map.frames[0].load - 0.027) < 1e-12, "load %.6f", map.frames[0].load);
    CHECK(fabs(map.load - 0.0297) < 1e-12, "total %.6f", map.load);
    CHECK(fabs(can_map_frame_time_us(&map, 8, true, false) - 320.0) < 1e-9, "29-bit 8 bytes: 160 bits");
    unload(&map);
    /* every packet at 125 Hz: 270 us / 8 ms = 3.375 %; 29-bit 8 bytes at
     * 250 kbit/s: 160 bits = 640 us, every 20 ms = 3.2 %; heartbeat at 1000
     * ms on 250 kbit/s: 540 us / 1 s = 0.054 %. */
    rc = load(&map,
              CAN_HEAD "bitrate = 250000\nheartbeat_period_ms = 1000\n[frame a]\nid = 0x100\nperiod_ms = every\n"
                       "signal = time @0|8 intel unsigned\n[frame b]\nid = 0x100\nextended = yes\nperiod_ms = 20\n"
                       "signal = time @0|8 intel unsigned\n",
              one_robot, 1, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    CHECK(fabs(map.frames[0].load - 0.0675) < 1e-12, "every at 125 Hz, 250k: %.6f", map.frames[0].load);
    CHECK(fabs(map.frames[1].load - 0.032) < 1e-12, "29-bit at 20 ms: %.6f", map.frames[1].load);
    CHECK(fabs(map.hb_load - 0.00054) < 1e-12, "heartbeat: %.6f", map.hb_load);
    unload(&map);
    /* FD, 64 bytes, 500k/2M: 34 bits at 2 us + 679 bits at 0.5 us = 407.5 us;
     * every 10 ms: 4.075 %. */
    rc = load(&map,
              CAN_HEAD "fd = yes\ndata_bitrate = 2000000\n[frame a]\nid = 0x100\nfd = yes\nlength = 64\n"
                       "period_ms = 10\nsignal = time @0|8 intel unsigned\n",
              one_robot, 1, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    CHECK(fabs(map.frames[0].load - 0.04075) < 1e-12, "FD 64: %.6f", map.frames[0].load);
    unload(&map);
    /* Over the threshold: 10 frames every 1 ms... at 125 Hz the robot
     * limits periods, so use an e-series robot: 2 ms. 4 frames of 270 us
     * every 2 ms = 54 % + heartbeat 0.27 % = 54.27 % over 50 %. */
    {
        const struct can_map_robot fast[] = {{"arm", 2000}};
        char cfg[2048];
        int n = snprintf(cfg, sizeof cfg, "%s", CAN_HEAD);
        int k;
        for (k = 0; k < 4; k++) {
            n += snprintf(cfg + n, sizeof cfg - (size_t)n,
                          "[frame f%d]\nid = 0x%x\nperiod_ms = 2\nsignal = time @0|8 intel unsigned\n", k, 0x100 + k);
        }
        rc = load(&map, cfg, fast, 1, err, sizeof err);
        CHECK(rc == -1 && strstr(err, "t.ini:1: worst-case bus load 54.3% at 500000 bit/s is over max_bus_load = 50% "
                                      "(frames 54.00% + heartbeat 0.27%; heaviest: f0 13.5%, f1 13.5%, f2 13.5%)") ==
                              err,
              "bus load rejection: %s", err);
        unload(&map);
        /* The same at max_bus_load = 60 passes, and the message points at
         * max_bus_load when it is given. */
        snprintf(cfg + strlen(CAN_HEAD), sizeof cfg - strlen(CAN_HEAD), "max_bus_load = 54\n%s", "");
        n = (int)strlen(cfg);
        for (k = 0; k < 4; k++) {
            n += snprintf(cfg + n, sizeof cfg - (size_t)n,
                          "[frame f%d]\nid = 0x%x\nperiod_ms = 2\nsignal = time @0|8 intel unsigned\n", k, 0x100 + k);
        }
        rc = load(&map, cfg, fast, 1, err, sizeof err);
        CHECK(rc == -1 && strncmp(err, "t.ini:4: worst-case bus load 54.3%", 34) == 0, "at max_bus_load: %s", err);
        unload(&map);
    }
}

/* ---- can_map: run time on a fake clock --------------------------------------------------- */

#define MAX_SENT 4096
struct sent {
    uint64_t t;
    urrt_can_frame f;
};
struct capture {
    uint64_t now;
    size_t n;
    struct sent s[MAX_SENT];
};

static void capture_frame(void *ctx, const urrt_can_frame *f, uint64_t now_us)
{
    struct capture *c = ctx;
    if (c->n < MAX_SENT) {
        c->s[c->n].t = now_us;
        c->s[c->n].f = *f;
        c->n++;
    }
}

static double hb_value(const urrt_can_frame *f, enum urrt_cantx_hb_signal k)
{
    double v = NAN;
    urrt_can_unpack(&urrt_cantx_heartbeat_signals[k], f->data, f->len, &v);
    return v;
}

static uint64_t bits_of(const urrt_can_frame *f, unsigned start, unsigned length)
{
    urrt_can_signal s = {0};
    s.start = (uint16_t)start;
    s.length = (uint8_t)length;
    s.byte_order = URRT_CAN_INTEL;
    s.type = URRT_CAN_UNSIGNED;
    s.factor = 1;
    uint64_t raw = 0;
    urrt_can_get_raw(&s, f->data, f->len, &raw);
    return raw;
}

static void packet(uint64_t t, double q0, double mode, bool with_q)
{
    urrt_state st;
    urrt_state_clear(&st);
    st.generation = URRT_GEN_3X;
    st.time[0] = (double)t / 1e6;
    st.robot_mode[0] = mode;
    st.safety_mode[0] = 1;
    st.q_actual[0] = q0;
    st.present = (UINT64_C(1) << URRT_F_TIME) | (UINT64_C(1) << URRT_F_ROBOT_MODE) |
                 (UINT64_C(1) << URRT_F_SAFETY_MODE) | (with_q ? UINT64_C(1) << URRT_F_Q_ACTUAL : 0);
    urrt_cantx_on_packet(can_run_tx(loaded_run), 0, &st, t);
}

static const char *const sched_config =
    "[can]\n"
    "interface = log:-\n"
    "heartbeat_id = 0x701\n"
    "heartbeat_period_ms = 100\n"
    "stale_after_ms = 50\n"
    "[frame fast]\n"
    "id = 0x181\n"
    "period_ms = 10\n"
    "alive_counter = 60\n"
    "validity_bit = 59\n"
    "stale_policy = invalid\n"
    "signal = q_actual[0] @0|16 intel signed factor=0.001\n"
    "[frame slow]\n"
    "id = 0x281\n"
    "period_ms = 20\n"
    "stale_after_ms = 30\n"
    "signal = robot_mode @0|8 intel signed\n"
    "[frame each]\n"
    "id = 0x381\n"
    "period_ms = every\n"
    "signal = time @0|32 intel unsigned factor=0.001\n";

static struct capture cap;

/* What test_schedule's first 300 ms sent: frames per id, and whether every
 * fast and every-packet frame was as expected. */
struct sched_tally {
    size_t fast, slow, each, hb;
    bool ok_valid, ok_alive, ok_fast_t, ok_q, ok_each;
};

/* Packets every 8 ms from 1 ms to 97 ms; due() every millisecond to 300 ms.
 * Returns the number of packets. */
static int schedule_first_300ms(void)
{
    uint64_t t;
    uint64_t last_packet = 0;
    int packets = 0;
    for (t = 0; t < 300000; t += 1000) {
        cap.now = t;
        if (t % 8000 == 1000 && t < 100000) {
            packet(t, 1.234, 7, true);
            last_packet = t;
            packets++;
        }
        can_run_due(loaded_run, t, NULL, capture_frame, &cap);
        if (t == 50000) {
            /* Next: fast at 60, slow at 61 (started at the first packet, 1 ms), heartbeat at 100. */
            CHECK_EQ_INT(urrt_cantx_deadline(can_run_tx(loaded_run)), 60000);
        }
    }
    (void)last_packet;
    return packets;
}

static void tally_fast_frame(struct sched_tally *k, const struct sent *s)
{
    bool has = s->t >= 1000;
    uint64_t age = has ? s->t - (s->t >= 97000 ? 97000 : ((s->t - 1000) / 8000) * 8000 + 1000) : 0;
    bool want_valid = has && age <= 50000;
    k->ok_fast_t &= s->t == k->fast * 10000;
    k->ok_alive &= bits_of(&s->f, 60, 4) == k->fast % 16;
    k->ok_valid &= bits_of(&s->f, 59, 1) == (want_valid ? 1u : 0u);
    /* Before data: NaN packs physical 0; after: 1.234 -> 1234. */
    k->ok_q &= bits_of(&s->f, 0, 16) == (has ? 1234u : 0u);
    k->fast++;
}

/* Heartbeat number hb: starting, then OK on the packets' data, then stale. */
static void check_schedule_heartbeat(const struct sent *s, size_t hb)
{
    CHECK(s->t == hb * 100000, "heartbeat %zu at %llu", hb, (unsigned long long)s->t);
    CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_ALIVE), hb);
    if (hb == 0) {
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_STATE), URRT_CANTX_STARTING);
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_ROBOT_MODE), URRT_CANTX_HB_ROBOT_MODE_NA);
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_SAFETY_MODE), URRT_CANTX_HB_SAFETY_MODE_NA);
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_DATA_AGE), 65535);
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_GENERATION), 0);
    } else if (hb == 1) {
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_STATE), URRT_CANTX_OK);
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_ROBOT_MODE), 7);
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_SAFETY_MODE), 1);
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_DATA_AGE), 3); /* last packet at 97 ms */
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_GENERATION), 3);
    } else {
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_STATE), URRT_CANTX_DATA_STALE);
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_DATA_AGE), 103);
        /* Modes as old as the data are not current: not available. */
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_ROBOT_MODE), URRT_CANTX_HB_ROBOT_MODE_NA);
        CHECK_EQ_INT(hb_value(&s->f, URRT_CANTX_HB_SAFETY_MODE), URRT_CANTX_HB_SAFETY_MODE_NA);
    }
    CHECK(s->f.len == 8 && !s->f.fd && !s->f.extended, "heartbeat frame shape");
}

/* The frames of schedule_first_300ms, in the order they were sent. */
static void check_schedule_frames(int packets)
{
    struct sched_tally k = {0, 0, 0, 0, true, true, true, true, true};
    size_t i;
    for (i = 0; i < cap.n; i++) {
        const struct sent *s = &cap.s[i];
        switch (s->f.id) {
        case 0x181: tally_fast_frame(&k, s); break;
        case 0x281:
            /* Started by the first packet at 1 ms; every 20 ms; stops once
             * the data is older than 30 ms: the last packet is at 97 ms, so
             * 121 (age 24) is sent and 141 (age 44) is not. */
            CHECK(s->t == 1000 + k.slow * 20000, "slow frame %zu at %llu", k.slow, (unsigned long long)s->t);
            CHECK(s->f.data[0] == 7 && s->f.len == 8, "slow frame carries robot mode 7");
            k.slow++;
            break;
        case 0x381:
            k.ok_each &= s->t % 8000 == 1000 && bits_of(&s->f, 0, 32) == s->t / 1000;
            k.each++;
            break;
        case 0x701:
            check_schedule_heartbeat(s, k.hb);
            k.hb++;
            break;
        default: CHECK(false, "unexpected id 0x%X", (unsigned)s->f.id);
        }
    }
    CHECK_EQ_INT(k.fast, 30);
    CHECK(k.ok_fast_t, "fast frames every 10 ms from 0");
    CHECK(k.ok_alive, "alive counter 0..15, 0, ...");
    CHECK(k.ok_valid, "validity bit follows data age (50 ms) and data presence");
    CHECK(k.ok_q, "fast frame payload");
    CHECK_EQ_INT(k.slow, 7); /* 1, 21, 41, 61, 81, 101, 121 */
    CHECK_EQ_INT(k.each, packets);
    CHECK(k.ok_each, "every-packet frames at the packets, with their time");
    CHECK_EQ_INT(k.hb, 3);
}

/* Data comes back: the slow frame resumes at once, then every 20 ms. */
static void schedule_data_returns(void)
{
    uint64_t t;
    size_t i;
    cap.n = 0;
    for (t = 300000; t < 345000; t += 1000) {
        cap.now = t;
        if (t == 305000) {
            packet(t, -1.0, 5, true);
        }
        can_run_due(loaded_run, t, NULL, capture_frame, &cap);
    }
    {
        uint64_t slow_at[8];
        size_t ns = 0;
        for (i = 0; i < cap.n; i++) {
            if (cap.s[i].f.id == 0x281 && ns < 8) {
                slow_at[ns++] = cap.s[i].t;
            }
        }
        CHECK(ns == 2 && slow_at[0] == 305000 && slow_at[1] == 325000, "slow resumes: %zu frames, first at %llu", ns,
              ns ? (unsigned long long)slow_at[0] : 0ull);
        /* 345: the 325 one was the last within 30 ms of data at 305 (age 20) */
    }
}

/* A stalled loop: one frame per frame, not a burst of the missed slots. */
static void schedule_after_stall(void)
{
    size_t i;
    cap.n = 0;
    cap.now = 1000000;
    can_run_due(loaded_run, 1000000, NULL, capture_frame, &cap);
    {
        size_t nfast = 0, nhb = 0;
        for (i = 0; i < cap.n; i++) {
            nfast += cap.s[i].f.id == 0x181;
            nhb += cap.s[i].f.id == 0x701;
        }
        CHECK(nfast == 1 && nhb == 1 && cap.n == 2, "after a stall: %zu fast, %zu heartbeats, %zu frames", nfast, nhb,
              cap.n);
        CHECK_EQ_INT(urrt_cantx_deadline(can_run_tx(loaded_run)), 1010000);
    }
}

/* An every-packet frame left pending while the CAN link was down (the
 * gateway calls no due() then) must not carry stale data out when the
 * link comes back: it stops with the packets. */
static void schedule_every_packet_after_link_down(void)
{
    uint64_t t;
    size_t i;
    packet(2000000, 1.234, 7, true);
    for (t = 2200000; t <= 2300000; t += 100000) {
        size_t neach = 0;
        if (t == 2300000) {
            packet(t, 1.234, 7, true);
        }
        cap.n = 0;
        cap.now = t;
        can_run_due(loaded_run, t, NULL, capture_frame, &cap);
        for (i = 0; i < cap.n; i++) {
            neach += cap.s[i].f.id == 0x381;
        }
        CHECK(neach == (t == 2300000 ? 1u : 0u), "every-packet frame at %llu ms, %s data: %zu sent",
              (unsigned long long)(t / 1000), t == 2300000 ? "fresh" : "200 ms old", neach);
    }
}

/* One map through time: each step goes on from the state the one before left. */
static void test_schedule(void)
{
    struct can_map map;
    char err[4096] = "";
    int packets;
    int rc = load(&map, sched_config, one_robot, 1, err, sizeof err);
    CHECK(rc == 0, "schedule config: %s", err);
    if (rc != 0) {
        return;
    }
    memset(&cap, 0, sizeof cap);
    CHECK(urrt_cantx_deadline(can_run_tx(loaded_run)) == URRT_CANTX_NEVER, "no deadline before start");
    can_run_start(loaded_run, 0);
    packets = schedule_first_300ms();
    check_schedule_frames(packets);
    schedule_data_returns();
    schedule_after_stall();
    schedule_every_packet_after_link_down();
    unload(&map);
}

/* The fast frame through data in range, saturated, absent and in range again:
 * its payload and validity bit. */
static void validity_of_fast_frames(urrt_canlink_stats *stats)
{
    size_t i;
    /* In range: valid. */
    packet(1000, 2.0, 7, true);
    cap.now = 1000;
    can_run_due(loaded_run, 1000, stats, capture_frame, &cap);
    /* 40.0 rad does not fit 16 signed bits at 0.001: saturated, invalid. */
    packet(9000, 40.0, 7, true);
    cap.now = 10000;
    can_run_due(loaded_run, 10000, stats, capture_frame, &cap);
    /* q absent from the packet (NaN): invalid, payload carries physical 0. */
    packet(17000, 0, 7, false);
    cap.now = 20000;
    can_run_due(loaded_run, 20000, stats, capture_frame, &cap);
    /* In range again: valid. */
    packet(25000, -2.0, 7, true);
    cap.now = 30000;
    can_run_due(loaded_run, 30000, stats, capture_frame, &cap);
    {
        int k = 0;
        const uint64_t want_q[] = {2000, 32767, 0, (uint64_t)(65536 - 2000)};
        const unsigned want_valid[] = {1, 0, 0, 1};
        for (i = 0; i < cap.n; i++) {
            if (cap.s[i].f.id != 0x181 || cap.s[i].t == 0) {
                continue;
            }
            if (k < 4) {
                CHECK(bits_of(&cap.s[i].f, 0, 16) == want_q[k] && bits_of(&cap.s[i].f, 59, 1) == want_valid[k],
                      "frame %d: q raw %llu valid %llu", k, (unsigned long long)bits_of(&cap.s[i].f, 0, 16),
                      (unsigned long long)bits_of(&cap.s[i].f, 59, 1));
            }
            k++;
        }
        CHECK_EQ_INT(k, 4);
    }
}

/* Heartbeat flags say "since the previous heartbeat": the one at 100 ms. */
static void heartbeat_flags_at_100ms(urrt_canlink_stats *stats)
{
    size_t i;
    stats->dropped = 70000;
    stats->bus_off = 1;
    cap.n = 0;
    cap.now = 100000;
    packet(99000, 1, 7, true);
    can_run_due(loaded_run, 100000, stats, capture_frame, &cap);
    for (i = 0; i < cap.n && cap.s[i].f.id != 0x701; i++) {
    }
    CHECK(i < cap.n, "heartbeat at 100 ms");
    if (i < cap.n) {
        const urrt_can_frame *f = &cap.s[i].f;
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_DROPS), 70000 % 65536);
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_TX_DROPPED), 1);
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_BUS_OFF), 1);
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_CAN_ERRORS), 0);
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_CLAMPED), 1); /* 40 rad and NaN since start */
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_DATA_AGE), 1);
    }
}

/* ... and the one at 200 ms, after other link events. */
static void heartbeat_flags_at_200ms(urrt_canlink_stats *stats)
{
    size_t i;
    stats->error_frames = 3;
    stats->down_events = 1;
    stats->send_errors = 2;
    cap.n = 0;
    cap.now = 200000;
    packet(199000, 1, 7, true);
    can_run_due(loaded_run, 200000, stats, capture_frame, &cap);
    for (i = 0; i < cap.n && cap.s[i].f.id != 0x701; i++) {
    }
    if (i < cap.n) {
        const urrt_can_frame *f = &cap.s[i].f;
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_DROPS), 70000 % 65536);
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_TX_DROPPED), 0);
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_BUS_OFF), 0);
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_CAN_ERRORS), 1);
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_CAN_DOWN), 1);
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_SEND_ERRORS), 1);
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_CLAMPED), 0);
        CHECK_EQ_INT(hb_value(f, URRT_CANTX_HB_STATE), URRT_CANTX_OK);
    } else {
        CHECK(false, "heartbeat at 200 ms");
    }
}

/* The link goes down: disconnected, whatever the age. */
static void heartbeat_link_down(urrt_canlink_stats *stats)
{
    urrt_cantx_robot_link(can_run_tx(loaded_run), 0, false);
    CHECK_EQ_INT(can_run_state(loaded_run, 200500), URRT_CANTX_DISCONNECTED);
    {
        urrt_can_frame f;
        can_run_heartbeat_frame(loaded_run, 200500, stats, &f);
        CHECK_EQ_INT(hb_value(&f, URRT_CANTX_HB_STATE), URRT_CANTX_DISCONNECTED);
        CHECK(f.id == 0x701 && f.len == 8, "heartbeat_frame id and length");
    }
    /* Data age saturates at 65534 ms. */
    CHECK_EQ_INT(can_run_state(loaded_run, 100000000), URRT_CANTX_DISCONNECTED);
    {
        urrt_can_frame f;
        can_run_heartbeat_frame(loaded_run, 100000000, stats, &f);
        CHECK_EQ_INT(hb_value(&f, URRT_CANTX_HB_DATA_AGE), 65534);
    }
}

/* Starting: at most CAN_RUN_STARTUP_MS without data, then disconnected
 * (link not up) or stale (link up but silent). */
static void startup_without_data(void)
{
    struct can_map map;
    char err[4096] = "";
    /* The configuration test_validity_and_heartbeat loaded and checked. */
    load(&map, sched_config, one_robot, 1, err, sizeof err);
    can_run_start(loaded_run, 1000);
    CHECK_EQ_INT(can_run_state(loaded_run, 1000 + 4999000), URRT_CANTX_STARTING);
    CHECK_EQ_INT(can_run_state(loaded_run, 1000 + 5000000), URRT_CANTX_DISCONNECTED);
    urrt_cantx_robot_link(can_run_tx(loaded_run), 0, true);
    CHECK_EQ_INT(can_run_state(loaded_run, 1000 + 5000000), URRT_CANTX_DATA_STALE);
    unload(&map);
}

/* Saturation, NaN and link statistics in the frames and the heartbeat, on one
 * map: each step goes on from the state the one before left. */
static void test_validity_and_heartbeat(void)
{
    struct can_map map;
    char err[4096] = "";
    urrt_canlink_stats stats;
    int rc = load(&map, sched_config, one_robot, 1, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    if (rc != 0) {
        return;
    }
    memset(&stats, 0, sizeof stats);
    memset(&cap, 0, sizeof cap);
    can_run_start(loaded_run, 0);
    validity_of_fast_frames(&stats);
    heartbeat_flags_at_100ms(&stats);
    heartbeat_flags_at_200ms(&stats);
    heartbeat_link_down(&stats);
    unload(&map);
    startup_without_data();
}

/* The heartbeat goes at least once a second, whatever the loop's rhythm. */
static void test_heartbeat_rate(void)
{
    struct can_map map;
    char err[4096] = "";
    uint64_t t;
    uint64_t prev = 0;
    uint64_t worst_gap = 0;
    size_t i;
    int n = 0;
    int rc = load(&map,
                  CAN_HEAD "heartbeat_period_ms = 1000\n[frame a]\nid = 0x100\nperiod_ms = 500\n"
                           "signal = time @0|8 intel unsigned\n",
                  one_robot, 1, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    memset(&cap, 0, sizeof cap);
    /* The loop wakes at the map's deadline, a little late each time. */
    t = 5000;
    for (i = 0; i < 200 && t < 20000000; i++) {
        uint64_t d;
        cap.now = t;
        can_run_due(loaded_run, t, NULL, capture_frame, &cap);
        d = urrt_cantx_deadline(can_run_tx(loaded_run));
        CHECK(d > t && d != URRT_CANTX_NEVER, "deadline %llu after %llu", (unsigned long long)d,
              (unsigned long long)t);
        t = d + 700; /* late by 0.7 ms */
    }
    for (i = 0; i < cap.n; i++) {
        if (cap.s[i].f.id == 0x701) {
            if (n > 0 && cap.s[i].t - prev > worst_gap) {
                worst_gap = cap.s[i].t - prev;
            }
            prev = cap.s[i].t;
            n++;
        }
    }
    CHECK(n >= 19, "%d heartbeats in 20 s", n);
    CHECK(worst_gap <= 1000700, "largest gap between heartbeats %llu us", (unsigned long long)worst_gap);
    unload(&map);
}

/* Mangled configurations: never a crash (the sanitizer build watches), and
 * either accepted or rejected with "t.ini:LINE: reason". Accepted ones
 * write a DBC and run a few cycles. */
static void test_config_mutations(void)
{
    static const char alphabet[] = "0123456789@|[]=x \"-.;#_abcfilmnorstuvFX\n";
    char text[4096];
    size_t base = strlen(sched_config);
    int i;
    int rejected = 0;
    int accepted = 0;
    int bad = 0;
    for (i = 0; i < 3000; i++) {
        struct can_map map;
        char err[4096] = "";
        int k;
        int edits = 1 + (int)(test_rng() % 4);
        size_t len = base;
        memcpy(text, sched_config, base + 1);
        for (k = 0; k < edits; k++) {
            size_t at = (size_t)(test_rng() % len);
            switch (test_rng() % 3) {
            case 0: text[at] = alphabet[test_rng() % (sizeof alphabet - 1)]; break;
            case 1: memmove(text + at, text + at + 1, len - at); len--; break;
            default:
                if (len + 1 < sizeof text) {
                    memmove(text + at + 1, text + at, len - at + 1);
                    text[at] = alphabet[test_rng() % (sizeof alphabet - 1)];
                    len++;
                }
            }
        }
        if (load(&map, text, one_robot, 1, err, sizeof err) == 0) {
            FILE *devnull = fopen("/dev/null", "w");
            accepted++;
            if (devnull != NULL) {
                bad += dbc_write(devnull, &map, "t.ini") != 0;
                fclose(devnull);
            }
            memset(&cap, 0, sizeof cap);
            can_run_start(loaded_run, 0);
            packet(1000, 1.0, 7, true);
            can_run_due(loaded_run, 1000, NULL, capture_frame, &cap);
            can_run_due(loaded_run, 200000, NULL, capture_frame, &cap);
        } else {
            rejected++;
            if (strncmp(err, "t.ini:", 6) != 0) {
                if (bad++ < 3) {
                    fprintf(stderr, "mutation: error without a location: %s\n", err);
                }
            }
        }
        unload(&map);
    }
    CHECK(bad == 0, "%d mutated configurations misbehaved", bad);
    CHECK(accepted > 50 && rejected > 1000, "mutations: %d accepted, %d rejected", accepted, rejected);
}

/* ---- bit masks -------------------------------------------------------------------------- */

/* A bit-mask field's signals: the mask kind whatever the field's name (its
 * unit is "bits"), the bits= range, the notices of bits no signal carries. */
static const struct {
    const char *signals; /* [frame a]'s signal lines */
    const char *notices; /* every notice, '|'-separated */
} mask_cases[] = {
    {"signal = digital_input_bits @0|18 intel unsigned\n", ""},
    {"signal = digital_input_bits @0|16 intel unsigned\n",
     "t.ini:8: digital_input_bits: bits 16-17 (tool inputs) are not carried (bits=16-17 in a signal would carry "
     "them)"},
    {"signal = digital_input_bits @0|16 intel unsigned name=din\n"
     "signal = digital_input_bits @16|2 intel unsigned bits=16-17 name=tool\n", ""},
    {"signal = digital_input_bits @0|14 intel unsigned bits=4-17\n",
     "t.ini:8: digital_input_bits: bits 0-3 (standard inputs) are not carried (bits=0-3 in a signal would carry "
     "them)"},
    {"signal = digital_outputs @0|4 motorola unsigned\nsignal = digital_outputs @8|1 intel unsigned bits=16 name=t\n",
     "t.ini:8: digital_outputs: bits 4-7 (standard outputs), bits 8-15 (configurable outputs), bit 17 (tool "
     "outputs) are not carried"},
    {"signal = robot_mode @0|8 intel signed\nsignal = digital_outputs @8|17 intel unsigned\n"
     "signal = digital_input_bits @32|8 intel unsigned bits=10-17\n",
     "t.ini:10: digital_input_bits: bits 0-7 (standard inputs), bits 8-9 (configurable inputs) are not carried|"
     "t.ini:9: digital_outputs: bit 17 (tool outputs) is not carried (bits=17 in a signal would carry it)"},
};

static void masks_notices(void)
{
    for (size_t i = 0; i < sizeof mask_cases / sizeof mask_cases[0]; i++) {
        struct can_map map;
        char err[2048] = "", text[1024], all[1024] = "";
        snprintf(text, sizeof text, CAN_HEAD "\n[frame a]\nid = 0x100\nperiod_ms = 10\n%s", mask_cases[i].signals);
        CHECK(load(&map, text, one_robot, 1, err, sizeof err) == 0, "mask case %zu: %s", i, err);
        for (size_t k = 0; k < can_map_notice_count(&map); k++) {
            snprintf(all + strlen(all), sizeof all - strlen(all), "%s%s", k ? "|" : "", can_map_notice(&map, k));
        }
        CHECK(strcmp(all, mask_cases[i].notices) == 0, "mask case %zu notices:\n  got:  %s\n  want: %s", i, all,
              mask_cases[i].notices);
        for (size_t k = 0; map.frame_count == 1 && k < map.frames[0].count; k++) {
            const struct can_map_signal *m = &map.frames[0].meta[k];
            const urrt_can_signal *sig = &map.frames[0].sigs[k];
            bool mask = m->field == URRT_F_DIGITAL_INPUT_BITS || m->field == URRT_F_DIGITAL_OUTPUTS;
            CHECK(m->bitmask == mask && ((sig->flags & URRT_CAN_SIG_BITMASK) != 0) == mask,
                  "mask case %zu signal %zu: a mask exactly when the field's unit is bits", i, k);
            CHECK(!mask || (sig->factor == 1 && sig->offset == 0 && sig->min == 0 &&
                            sig->max == ldexp(1, sig->length) - 1),
                  "mask case %zu signal %zu: factor 1, offset 0, the whole unsigned range", i, k);
        }
        unload(&map);
    }
}

/* The 1-based number of the first line of path that starts with prefix (0: none). */
static int line_of(const char *path, const char *prefix)
{
    char line[512];
    int n = 0;
    FILE *f = fopen(path, "r");
    while (f != NULL && fgets(line, sizeof line, f) != NULL) {
        n++;
        if (strncmp(line, prefix, strlen(prefix)) == 0) {
            fclose(f);
            return n;
        }
    }
    if (f != NULL) {
        fclose(f);
    }
    return 0;
}

/* The case, through docs/examples/canopen.ini as the gateway loads
 * it: digital inputs 65552 (input 4 and tool input 0) in TPDO4's 16-bit
 * signal at bytes 3-4 are 0x0010, not 65535 ("all sixteen on"), and not
 * counted as clamped; the notice says the tool bits are not carried. */
static void masks_canopen_example(void)
{
    char want[512];
    gw_config cfg;
    urrt_state st;
    char *messages = NULL;
    size_t size = 0;
    FILE *out = open_memstream(&messages, &size);
    int errors = gw_config_load(&cfg, "docs/examples/canopen.ini", out);
    bool found = false;
    fclose(out);
    CHECK(errors == 0, "canopen.ini loads: %s", messages);
    free(messages);
    if (errors != 0) {
        gw_config_free(&cfg);
        return;
    }
    snprintf(want, sizeof want, "docs/examples/canopen.ini:%d: digital_input_bits: bits 16-17 (tool inputs) are not "
             "carried (bits=16-17 in a signal would carry them)", line_of("docs/examples/canopen.ini",
                                                                          "signal = digital_input_bits "));
    CHECK_EQ_INT(can_map_notice_count(&cfg.can), 2);
    CHECK_EQ_STR(can_map_notice(&cfg.can, 0), want);
    memset(&cap, 0, sizeof cap);
    can_run_start(cfg.can_run, 0);
    urrt_state_clear(&st);
    st.generation = URRT_GEN_3X;
    for (int k = 0; k < 6; k++) {
        st.q_actual[k] = 0.5;
        st.tool_vector_actual[k] = 0.25;
    }
    st.speed_scaling[0] = 1;
    st.robot_mode[0] = 7;
    st.safety_mode[0] = 1;
    st.program_state[0] = 2;
    st.digital_input_bits[0] = 65552.0;
    st.digital_outputs[0] = 131071.0; /* 0x1FFFF: tool output 0 and all sixteen */
    st.present = (UINT64_C(1) << URRT_F_DIGITAL_INPUT_BITS) | (UINT64_C(1) << URRT_F_DIGITAL_OUTPUTS) |
                 (UINT64_C(1) << URRT_F_Q_ACTUAL) | (UINT64_C(1) << URRT_F_TOOL_VECTOR_ACTUAL) |
                 (UINT64_C(1) << URRT_F_SPEED_SCALING) | (UINT64_C(1) << URRT_F_ROBOT_MODE) |
                 (UINT64_C(1) << URRT_F_SAFETY_MODE) | (UINT64_C(1) << URRT_F_PROGRAM_STATE);
    urrt_cantx_on_packet(can_run_tx(cfg.can_run), 0, &st, 1000);
    can_run_due(cfg.can_run, 1000, NULL, capture_frame, &cap);
    for (size_t i = 0; i < cap.n; i++) {
        if (cap.s[i].f.id == 0x485) {
            found = true;
            CHECK(bits_of(&cap.s[i].f, 24, 16) == 0x0010, "TPDO4 din: 0x%04llX, want 0x0010",
                  (unsigned long long)bits_of(&cap.s[i].f, 24, 16));
            CHECK(bits_of(&cap.s[i].f, 40, 16) == 0xFFFF, "TPDO4 dout: 0x%04llX, want 0xFFFF",
                  (unsigned long long)bits_of(&cap.s[i].f, 40, 16));
        }
    }
    CHECK(found, "TPDO4 (0x485) sent");
    CHECK_EQ_INT(can_run_clamped(cfg.can_run), 0);
    gw_config_free(&cfg);
}

static void test_masks(void)
{
    masks_notices();
    masks_canopen_example();
}

/* DBC text spot checks (the full comparison is check-can-dbc). */
static void test_dbc_text(void)
{
    struct can_map map;
    char err[4096] = "";
    char *text = NULL;
    size_t size = 0;
    FILE *f;
    char num[40];
    int rc = load(&map, good_config, one_robot, 1, err, sizeof err);
    CHECK(rc == 0, "%s", err);
    f = open_memstream(&text, &size);
    CHECK_EQ_INT(dbc_write(f, &map, "t.ini"), 0);
    fclose(f);
    CHECK(strstr(text, "BO_ 385 joints: 8 URRT_GATEWAY\n") != NULL, "joints BO_");
    CHECK(strstr(text, " SG_ q_actual_0 : 0|16@1- (0.0001,0) [-3.2768|3.2767] \"rad\" Vector__XXX\n") != NULL,
          "q_actual_0 SG_");
    CHECK(strstr(text, " SG_ rx : 39|16@0- (0.0001,0) [-3.2768|3.2767] \"rad\" Vector__XXX\n") != NULL, "rx SG_");
    CHECK(strstr(text, " SG_ alive_counter : 56|4@1+ (1,0) [0|15] \"\" Vector__XXX\n") != NULL, "alive SG_");
    CHECK(strstr(text, "BO_ 2566848640 status: 4 URRT_GATEWAY\n") != NULL, "extended id flagged");
    CHECK(strstr(text, "BA_ \"VFrameFormat\" BO_ 2566848640 1;\n") != NULL, "ExtendedCAN");
    CHECK(strstr(text, "BA_ \"GenMsgCycleTime\" BO_ 385 10;\n") != NULL, "cycle time");
    CHECK(strstr(text, "BA_ \"GenMsgCycleTime\" BO_ 2566848640 8;\n") != NULL, "every packet at 125 Hz: 8 ms");
    CHECK(strstr(text, "VAL_ 2566848640 robot_mode -1 \"NO_CONTROLLER\" 0 \"DISCONNECTED\"") != NULL, "robot mode VAL_");
    CHECK(strstr(text, "VAL_ 1793 state 0 \"STARTING\" 1 \"OK\" 2 \"DATA_STALE\" 3 \"ROBOT_DISCONNECTED\" ;") != NULL,
          "heartbeat state VAL_");
    CHECK(strstr(text, "VAL_ 1793 robot_mode -128 \"NOT_AVAILABLE\" -1 \"NO_CONTROLLER\"") != NULL, "hb robot mode");
    free(text);
    unload(&map);
    CHECK_EQ_STR(dbc_number(0.1, num, sizeof num), "0.1");
    CHECK_EQ_STR(dbc_number(-3276.8, num, sizeof num), "-3276.8");
    CHECK_EQ_STR(dbc_number(1e-5, num, sizeof num), "1e-05");
    CHECK_EQ_STR(dbc_number(3.4028234663852886e+38, num, sizeof num), "3.4028234663852886e+38");
    CHECK(strtod(dbc_number(0.1 + 0.2, num, sizeof num), NULL) == 0.1 + 0.2, "shortest round trip %s", num);
}


/* ---- RTDE-only values as signals -------------------------------------------------------- */

#define RTDE_ROBOT "[robot arm]\nhost = h\nversion = 5.10\nsource = rtde\n"

/* Loads text as "t.ini" into *cfg, kept whole (the recipe too): the error
 * count, the messages in err. */
static int load_cfg(gw_config *cfg, const char *text, char *err, size_t errlen)
{
    char *messages = NULL;
    size_t size = 0;
    FILE *in = fmemopen((void *)text, strlen(text), "r");
    FILE *out = open_memstream(&messages, &size);
    int errors = gw_config_load_stream(cfg, in, "t.ini", out);
    fclose(in);
    fclose(out);
    snprintf(err, errlen, "%.*s", (int)(size > 0 && messages[size - 1] == '\n' ? size - 1 : size), messages);
    free(messages);
    return errors;
}

static const char *const rtde_config =
    CAN_HEAD
    "[frame regs]\nid = 0x100\nperiod_ms = 10\nvalidity_bit = 63\nstale_policy = invalid\n"
    "signal = output_int_register_24 @0|32 intel signed name=reg24\n"              /* line 9 */
    "signal = robot_status_bits @32|8 intel unsigned bits=0-7\n"
    "signal = output_bit_register_64 @40|1 intel unsigned name=bit64\n"
    "signal = output_int_register_47 @48|8 intel signed factor=2 name=reg47\n"
    "[frame masks]\nid = 0x101\nperiod_ms = 10\n"
    "signal = actual_configurable_digital_output_bits @0|64 intel unsigned name=cdo\n"
    "[frame top]\nid = 0x102\nperiod_ms = 10\n"
    "signal = actual_configurable_digital_output_bits @0|8 intel unsigned bits=56-63 name=cdo_top\n"
    "signal = safety_status_bits @15|32 motorola unsigned\n"
    "signal = tcp_offset[5] @40|16 intel signed factor=0.001\n"
    RTDE_ROBOT;

static void set_var(urrt_rtde_values *v, int var)
{
    unsigned bit = (unsigned)(var - URRT_RTDE_MAPPED_COUNT);
    v->present[bit / 32u] |= 1u << (bit % 32u);
}

/* Frame `frame` as it would go out now, after a package with these values. */
static urrt_can_frame rtde_frame(gw_config *cfg, const urrt_rtde_values *v, uint64_t t, size_t frame)
{
    urrt_can_frame out;
    urrt_state st;
    urrt_state_clear(&st);
    st.generation = URRT_GEN_3X;
    st.time[0] = (double)t / 1e6;
    st.present = UINT64_C(1) << URRT_F_TIME;
    can_run_rtde(cfg->can_run, 0, v);
    urrt_cantx_on_packet(can_run_tx(cfg->can_run), 0, &st, t);
    urrt_cantx_peek(can_run_tx(cfg->can_run), frame, t, &out);
    return out;
}

/* Every INT32 edge, BOOL, a UINT32 mask: bit for bit. */
static void rtde_registers(gw_config *cfg)
{
    static const int32_t edges[] = {INT32_MIN, INT32_MIN + 1, -1, 0, 1, INT32_MAX - 1, INT32_MAX};
    urrt_rtde_values v;
    for (size_t i = 0; i < sizeof edges / sizeof edges[0]; i++) {
        urrt_rtde_values_clear(&v);
        v.output_int_register[24] = edges[i];
        v.output_int_register[47] = (int32_t)(i * 2) - 6; /* -6 .. 6, factor 2: raw -3 .. 3 */
        v.robot_status_bits[0] = 0xA5u + (uint32_t)i;
        v.output_bit_register[0] = (uint8_t)(i & 1u);
        set_var(&v, URRT_RTDE_V_OUTPUT_INT_REGISTER + 24);
        set_var(&v, URRT_RTDE_V_OUTPUT_INT_REGISTER + 47);
        set_var(&v, URRT_RTDE_V_ROBOT_STATUS_BITS);
        set_var(&v, URRT_RTDE_V_OUTPUT_BIT_REGISTER);
        urrt_can_frame f = rtde_frame(cfg, &v, 1000000u + i * 10000u, 0);
        CHECK(bits_of(&f, 0, 32) == (uint32_t)edges[i], "reg24 %ld: raw 0x%llx", (long)edges[i],
              (unsigned long long)bits_of(&f, 0, 32));
        CHECK(bits_of(&f, 32, 8) == ((0xA5u + i) & 0xFFu), "robot_status_bits 0..7 of 0x%zx",
              (size_t)(0xA5u + i));
        CHECK(bits_of(&f, 40, 1) == (i & 1u), "output_bit_register_64 %zu", i & 1u);
        CHECK(bits_of(&f, 48, 8) == (uint8_t)(int8_t)((int)i - 3), "reg47 scaled by 2: raw %d", (int)i - 3);
        CHECK(bits_of(&f, 63, 1) == 1, "valid while fresh and exact");
    }
    /* A register reg47's 8 bits cannot carry (300 / 2 = 150 > 127): saturated, and the frame says so. */
    urrt_rtde_values_clear(&v);
    v.output_int_register[47] = 300;
    set_var(&v, URRT_RTDE_V_OUTPUT_INT_REGISTER + 47);
    urrt_can_frame f = rtde_frame(cfg, &v, 1500000u, 0);
    CHECK(bits_of(&f, 48, 8) == 127 && bits_of(&f, 63, 1) == 0, "reg47 300 saturated to raw 127, valid 0: %llu %llu",
          (unsigned long long)bits_of(&f, 48, 8), (unsigned long long)bits_of(&f, 63, 1));
}

/* A UINT64 mask keeps all 64 bits, bit 63 too: no double past 2^53 on the way. */
static void rtde_masks(gw_config *cfg)
{
    static const uint64_t masks[] = {UINT64_C(0x8000000000000001), UINT64_MAX, UINT64_C(0x0123456789ABCDEF),
                                     (UINT64_C(1) << 53) + 1, 0};
    urrt_rtde_values v;
    for (size_t i = 0; i < sizeof masks / sizeof masks[0]; i++) {
        urrt_rtde_values_clear(&v);
        v.actual_configurable_digital_output_bits[0] = masks[i];
        v.safety_status_bits[0] = UINT32_C(0x80000001) ^ (uint32_t)i;
        v.tcp_offset[5] = -1.5;
        set_var(&v, URRT_RTDE_V_ACTUAL_CONFIGURABLE_DIGITAL_OUTPUT_BITS);
        set_var(&v, URRT_RTDE_V_SAFETY_STATUS_BITS);
        set_var(&v, URRT_RTDE_V_TCP_OFFSET);
        urrt_can_frame f = rtde_frame(cfg, &v, 2000000u + i * 10000u, 1);
        CHECK(bits_of(&f, 0, 64) == masks[i], "UINT64 mask 0x%016llx sent as 0x%016llx",
              (unsigned long long)masks[i], (unsigned long long)bits_of(&f, 0, 64));
        f = rtde_frame(cfg, &v, 2000000u + i * 10000u + 1u, 2);
        CHECK(f.data[0] == (uint8_t)(masks[i] >> 56), "bits=56-63 of 0x%016llx: 0x%02x",
              (unsigned long long)masks[i], f.data[0]);
        /* Motorola, start bit 15 (the MSB of byte 1): bytes 1..4 big-endian. */
        uint32_t be = (uint32_t)f.data[1] << 24 | (uint32_t)f.data[2] << 16 | (uint32_t)f.data[3] << 8 | f.data[4];
        CHECK(be == (UINT32_C(0x80000001) ^ (uint32_t)i), "safety_status_bits motorola 0x%08x", be);
        CHECK(bits_of(&f, 40, 16) == (uint16_t)-1500, "tcp_offset[5] -1.5 rad at 0.001: raw %llu",
              (unsigned long long)bits_of(&f, 40, 16));
    }
    /* A package without the values (before the first): no bits set, never a guess. */
    urrt_rtde_values_clear(&v);
    urrt_can_frame f = rtde_frame(cfg, &v, 3000000u, 1);
    CHECK(bits_of(&f, 0, 64) == 0, "absent mask: 0");
}

static bool recipe_has(const gw_robot_config *r, int var, bool optional)
{
    for (size_t i = 0; i < r->recipe_count; i++) {
        if (r->recipe[i] == var) {
            return r->recipe_optional[i] == optional;
        }
    }
    return false;
}

static void rtde_recipe_and_dbc(gw_config *cfg)
{
    const gw_robot_config *r = &cfg->robots[0];
    char *text = NULL;
    size_t size = 0;
    CHECK(recipe_has(r, URRT_RTDE_V_OUTPUT_INT_REGISTER + 24, false), "output_int_register_24 required");
    CHECK(recipe_has(r, URRT_RTDE_V_ACTUAL_CONFIGURABLE_DIGITAL_OUTPUT_BITS, false), "a mask required");
    CHECK(recipe_has(r, URRT_RTDE_V_TCP_OFFSET, false), "tcp_offset required");
    CHECK(recipe_has(r, URRT_RTDE_V_OUTPUT_BIT_REGISTER, false), "output_bit_register_64 required");
    FILE *f = open_memstream(&text, &size);
    CHECK_EQ_INT(dbc_write(f, &cfg->can, "t.ini"), 0);
    fclose(f);
    CHECK(strstr(text, " SG_ reg24 : 0|32@1- (1,0) [-2147483648|2147483647] \"\" Vector__XXX\n") != NULL,
          "reg24 SG_");
    CHECK(strstr(text, " SG_ cdo : 0|64@1+ (1,0) [0|1.8446744073709552e+19] \"\" Vector__XXX\n") != NULL,
          "cdo SG_: a mask's whole range");
    CHECK(strstr(text, " SG_ tcp_offset_5 : 40|16@1- (0.001,0) [-32.768|32.767] \"rad\" Vector__XXX\n") != NULL,
          "tcp_offset_5 SG_: the unit of elements 3-5");
    CHECK(strstr(text, "CM_ SG_ 256 reg24 \"output_int_register_24: RTDE output INT32") != NULL, "reg24 CM_");
    CHECK(strstr(text, "CM_ SG_ 258 cdo_top \"actual_configurable_digital_output_bits: RTDE output UINT64") !=
              NULL && strstr(text, "bit n of this signal is bit 56+n of the value") != NULL,
          "cdo_top CM_: a mask from bit 56");
    free(text);
}

static const struct rejection rtde_rejections[] = {
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = output_int_register_24 @0|32 intel signed\n"
              "[robot arm]\nhost = h\n",
     "t.ini:7: signal output_int_register_24: an RTDE-only value, and robot \"arm\" reads RealTime, which has none"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = safety_status_bits @0|32 intel unsigned factor=2\n"
              RTDE_ROBOT,
     "t.ini:7: signal: safety_status_bits is a bit mask, sent bit for bit: remove factor="},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = robot_status_bits @0|32 intel unsigned max=3\n"
              RTDE_ROBOT,
     "t.ini:7: signal: robot_status_bits is a bit mask, sent bit for bit: remove max="},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = output_int_register_24 @0|8 intel unsigned bits=0-7\n"
              RTDE_ROBOT,
     "t.ini:7: signal: bits= is for bit masks"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = tcp_offset[6] @0|16 intel signed\n" RTDE_ROBOT,
     "t.ini:7: signal: tcp_offset has 6 elements: tcp_offset[6] is out of range (0..5)"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\n"
              "signal = actual_configurable_digital_input_bits @0|8 intel unsigned\n" RTDE_ROBOT,
     "t.ini:7: signal: its name 'actual_configurable_digital_input_bits' is longer than a DBC name's 32"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = output_int_register_48 @0|8 intel signed\n"
              RTDE_ROBOT,
     "t.ini:7: signal: no field 'output_int_register_48'"},
};

static void test_rtde_values(void)
{
    gw_config cfg;
    char err[4096] = "";
    int errors = load_cfg(&cfg, rtde_config, err, sizeof err);
    CHECK(errors == 0 && cfg.can_run != NULL, "RTDE-only signals load: %s", err);
    if (errors == 0 && cfg.can_run != NULL) {
        urrt_cantx_start(can_run_tx(cfg.can_run), 0);
        rtde_registers(&cfg);
        rtde_masks(&cfg);
        rtde_recipe_and_dbc(&cfg);
    }
    gw_config_free(&cfg);
    for (size_t i = 0; i < sizeof rtde_rejections / sizeof rtde_rejections[0]; i++) {
        errors = load_cfg(&cfg, rtde_rejections[i].config, err, sizeof err);
        CHECK(errors > 0 && strncmp(err, rtde_rejections[i].expect, strlen(rtde_rejections[i].expect)) == 0,
              "RTDE rejection %zu:\n  got:  %s\n  want: %s", i, err, rtde_rejections[i].expect);
        gw_config_free(&cfg);
    }
}

/* ---- [input NAME]: frames the gateway receives, writing input registers ---------------------- */

/* The first message of err: its first line. */
static void first_line(const char *err, char *out, size_t size)
{
    snprintf(out, size, "%.*s", (int)strcspn(err, "\n"), err);
}

/* 0x18FF1234 with DBC's extended flag: 0x80000000 | id. */
#define IN_CMD_DBC_ID "2566853172"

static const char *const input_config =
    CAN_HEAD                                                                                     /* lines 1-3 */
    "fd = yes\ndata_bitrate = 2000000\nreceiver = CELL_PLC\n"                                    /* 4-6 */
    "[input cmd]\nid = 0x18FF1234\nextended = yes\nfd = yes\nlength = 16\ntimeout_ms = 250\n"  /* 7-12 */
    "on_silence = value 1\ncomment = Cell PLC setpoints\n"                                       /* 13-14 */
    "signal = input_bit_registers32_to_63 @24|4 intel unsigned bits=4-7 name=mask_hi\n"         /* 15 */
    "signal = input_double_register_30 @7|16 motorola signed factor=0.01 offset=0.5 min=-100 max=200 unit=mm "
    "name=setpoint\n"                                                                            /* 16 */
    "signal = input_bit_registers32_to_63 @16|4 intel unsigned bits=0-3 name=mask_lo\n"         /* 17 */
    "signal = input_int_register_25 @32|32 intel signed name=count\n"                            /* 18 */
    "signal = input_bit_register_100 @64|1 intel unsigned name=flag\n"                           /* 19 */
    "[input stop]\nid = 0x210\ntimeout_ms = 50\non_silence = hold\n"                            /* 20-23 */
    "signal = input_int_register_26 @0|8 intel unsigned\n"                                       /* 24 */
    RTDE_ROBOT;

static void inputs_accepted(void)
{
    gw_config cfg;
    char err[4096] = "";
    int errors = load_cfg(&cfg, input_config, err, sizeof err);
    const struct can_map *map = &cfg.can;
    CHECK(errors == 0, "[input]s load: %s", err);
    if (errors != 0) {
        gw_config_free(&cfg);
        return;
    }
    CHECK_EQ_INT(map->frame_count, 0);
    CHECK_EQ_INT(map->input_count, 2);
    {
        const struct can_map_frame *f = &map->inputs[0];
        const uint16_t want[] = {URRT_RTDE_V_INPUT_BIT_REGISTERS32_TO_63, URRT_RTDE_V_INPUT_DOUBLE_REGISTER + 30,
                                 URRT_RTDE_V_INPUT_INT_REGISTER + 25, URRT_RTDE_V_INPUT_BIT_REGISTER + 36};
        char name[URRT_RTDE_NAME_MAX];
        CHECK_EQ_STR(f->name, "cmd");
        CHECK(f->input && f->id == 0x18FF1234 && f->extended && f->fd && f->len == 16, "cmd: id, kind, length");
        CHECK_EQ_INT(f->timeout_ms, 250);
        CHECK(f->silence == URRT_PLCIN_VALUE && f->silence_value == 1.0, "cmd: on_silence = value 1");
        CHECK_EQ_STR(f->comment, "Cell PLC setpoints");
        CHECK_EQ_INT(f->robot_index, 0);
        CHECK_EQ_INT(f->loc.line, 7);
        CHECK_EQ_INT(f->count, 5);
        /* The recipe: each register once, in the order of its first signal (the mask's two
         * signals are one register). */
        CHECK_EQ_INT(f->reg_count, 4);
        for (size_t k = 0; k < 4 && k < f->reg_count; k++) {
            CHECK(f->regs[k] == want[k], "cmd regs[%zu] = %u, want %u", k, f->regs[k], want[k]);
        }
        CHECK(urrt_rtde_var_name(f->regs[3], name, sizeof name) > 0 && strcmp(name, "input_bit_register_100") == 0,
              "regs[3] is input_bit_register_100: %s", name);
        /* The signals as configured: received raw * factor + offset, min..max bounds what is taken. */
        CHECK(f->meta[0].bitmask && f->meta[2].bitmask && !f->meta[1].bitmask, "the mask's signals are masks");
        CHECK(f->sigs[0].flags == URRT_CAN_SIG_MASK(4) && f->sigs[0].start == 24 && f->sigs[0].length == 4,
              "mask_hi: bits=4-7 at @24|4");
        CHECK(f->sigs[2].flags == URRT_CAN_SIG_MASK(0) && f->sigs[2].start == 16, "mask_lo: bits=0-3 at @16|4");
        CHECK(f->sigs[1].factor == 0.01 && f->sigs[1].offset == 0.5 && f->sigs[1].min == -100 &&
                  f->sigs[1].max == 200 && f->sigs[1].byte_order == URRT_CAN_MOTOROLA &&
                  f->sigs[1].type == URRT_CAN_SIGNED && f->sigs[1].start == 7 && f->sigs[1].length == 16,
              "setpoint: motorola signed 0.01, 0.5, -100..200");
        CHECK_EQ_STR(f->meta[1].unit, "mm");
        CHECK_EQ_STR(f->meta[1].name, "setpoint");
        CHECK(f->meta[1].role == CAN_MAP_ROLE_RTDE && f->meta[1].var == URRT_RTDE_V_INPUT_DOUBLE_REGISTER + 30,
              "setpoint writes input_double_register_30");
        CHECK(f->sigs[3].min == -2147483648.0 && f->sigs[3].max == 2147483647.0, "count: its type's whole range");
        CHECK(f->sigs[4].invalid_raw == 0 && (f->sigs[4].flags & URRT_CAN_SIG_INVALID_RAW) == 0, "no invalid raw");
        CHECK_EQ_INT(f->meta[4].loc.line, 19);
    }
    {
        const struct can_map_frame *f = &map->inputs[1];
        CHECK_EQ_STR(f->name, "stop");
        CHECK(f->id == 0x210 && !f->extended && !f->fd && f->len == 8, "stop: defaults 11-bit, classic, 8 bytes");
        CHECK(f->timeout_ms == 50 && f->silence == URRT_PLCIN_HOLD, "stop: 50 ms, hold");
        CHECK(f->reg_count == 1 && f->regs[0] == URRT_RTDE_V_INPUT_INT_REGISTER + 26, "stop: its one register");
        CHECK_EQ_STR(f->comment, "");
    }
    {
        uint32_t ids[4] = {0};
        CHECK_EQ_INT(can_map_input_ids(map, ids, 4), 2);
        CHECK(ids[0] == (0x18FF1234u | URRT_CANLINK_RX_EXTENDED) && ids[1] == 0x210, "receive ids 0x%X 0x%X",
              (unsigned)ids[0], (unsigned)ids[1]);
        CHECK_EQ_INT(can_map_input_ids(map, ids, 1), 1);
        CHECK(can_map_input_of(map, 0x18FF1234, true) == &map->inputs[0], "input of a 29-bit id");
        CHECK(can_map_input_of(map, 0x18FF1234, false) == NULL, "an 11-bit frame is not a 29-bit [input]");
        CHECK(can_map_input_of(map, 0x210, false) == &map->inputs[1] && can_map_input_of(map, 0x211, false) == NULL,
              "input of an 11-bit id");
    }
    {
        char *text = NULL;
        size_t size = 0;
        FILE *out = open_memstream(&text, &size);
        CHECK_EQ_INT(dbc_write(out, map, "t.ini"), 0);
        fclose(out);
        CHECK(strstr(text, "BU_: URRT_GATEWAY CELL_PLC\n") != NULL, "BU_ names both nodes");
        CHECK(strstr(text, "BO_ " IN_CMD_DBC_ID " cmd: 16 CELL_PLC\n") != NULL, "cmd BO_: sent by the PLC");
        CHECK(strstr(text, " SG_ setpoint : 7|16@0- (0.01,0.5) [-100|200] \"mm\" URRT_GATEWAY\n") != NULL,
              "setpoint SG_: received by the gateway");
        CHECK(strstr(text, " SG_ mask_hi : 24|4@1+ (1,0) [0|15] \"\" URRT_GATEWAY\n") != NULL, "mask_hi SG_");
        CHECK(strstr(text, "BO_ 528 stop: 8 CELL_PLC\n") != NULL, "stop BO_");
        CHECK(strstr(text, "BA_ \"VFrameFormat\" BO_ " IN_CMD_DBC_ID " 15;\n") != NULL, "cmd: ExtendedCAN_FD");
        CHECK(strstr(text, "BA_ \"CANFD_BRS\" BO_ " IN_CMD_DBC_ID " 1;\n") != NULL, "cmd: bit rate switch");
        CHECK(strstr(text, "BA_ \"GenMsgSendType\" BO_ 528 0;\n") != NULL, "stop: Cyclic");
        CHECK(strstr(text, "BA_ \"GenMsgCycleTime\" BO_ 528") == NULL &&
                  strstr(text, "BA_ \"GenMsgCycleTime\" BO_ " IN_CMD_DBC_ID) == NULL,
              "no cycle time for a frame the PLC sends");
        CHECK(strstr(text, "CM_ BO_ " IN_CMD_DBC_ID " \"Cell PLC setpoints. Sent by CELL_PLC, received by "
                           "URRT_GATEWAY, which writes robot arm's input registers over RTDE from it; no frame for "
                           "250 ms is a silent PLC: on_silence = value 1 (written to every register of the "
                           "frame).\";\n") != NULL,
              "cmd CM_ BO_");
        CHECK(strstr(text, "CM_ SG_ " IN_CMD_DBC_ID " setpoint \"input_double_register_30: RTDE input DOUBLE, "
                           "written by urrt-gateway to robot arm as raw * factor + offset; a value outside "
                           "min..max is refused and counted, never clamped; [input cmd] timeout_ms = 250, "
                           "on_silence = value 1\";\n") != NULL,
              "setpoint CM_ SG_");
        CHECK(strstr(text, "CM_ SG_ " IN_CMD_DBC_ID " mask_hi \"input_bit_registers32_to_63: RTDE input UINT32, "
                           "written by urrt-gateway to robot arm; a bit mask, taken bit for bit (never scaled): bit "
                           "n of this signal is bit 4+n of the register; [input cmd] timeout_ms = 250, on_silence "
                           "= value 1\";\n") != NULL,
              "mask_hi CM_ SG_");
        CHECK(strstr(text, "CM_ SG_ 528 input_int_register_26 \"input_int_register_26: RTDE input INT32, written "
                           "by urrt-gateway to robot arm as raw * factor + offset; a value outside min..max is "
                           "refused and counted, never clamped; [input stop] timeout_ms = 50, on_silence = "
                           "hold\";\n") != NULL,
              "stop's CM_ SG_");
        free(text);
    }
    gw_config_free(&cfg);
}

/* docs/examples/plc-io.ini, as shipped. */
static void inputs_example(void)
{
    gw_config cfg;
    char *messages = NULL;
    size_t size = 0;
    FILE *out = open_memstream(&messages, &size);
    int errors = gw_config_load(&cfg, "docs/examples/plc-io.ini", out);
    fclose(out);
    CHECK(errors == 0, "plc-io.ini: %s", messages);
    if (errors == 0) {
        const struct can_map_frame *f = &cfg.can.inputs[0];
        CHECK(cfg.can.input_count == 1 && cfg.can.frame_count == 1, "one [input], one [frame]");
        CHECK_EQ_STR(f->name, "plc_command");
        CHECK(f->id == 0x200 && !f->extended && !f->fd && f->len == 8, "plc_command: 0x200, classic, 8 bytes");
        CHECK(f->timeout_ms == 100 && f->silence == URRT_PLCIN_STOP, "plc_command: 100 ms, stop");
        CHECK(f->reg_count == 3 && f->regs[0] == URRT_RTDE_V_INPUT_INT_REGISTER + 24 &&
                  f->regs[1] == URRT_RTDE_V_INPUT_BIT_REGISTER + 0 && f->regs[2] == URRT_RTDE_V_INPUT_BIT_REGISTER + 1,
              "plc_command's recipe: input_int_register_24, input_bit_register_64, input_bit_register_65");
        CHECK(f->sigs[0].max == 9999 && f->sigs[0].min == 0, "job_number: 0..9999");
        CHECK(cfg.can.inputs_min_rate_hz == 10.0, "inputs_min_rate = 10 Hz");
        CHECK_EQ_STR(cfg.can.receiver, "PLC");
    }
    gw_config_free(&cfg);
    free(messages);
}

/* Each refusal: the whole first message, its line. */
static const struct rejection input_rejections[] = {
    {CAN_HEAD "[input a]\nid = 0x200\nsignal = input_int_register_24 @0|16 intel signed\n" RTDE_ROBOT,
     "t.ini:4: [input a] has no timeout_ms: after how long without the frame is the PLC silent? (the PLC's period "
     "and some margin, e.g. timeout_ms = 100 for a 20 ms frame)"},
    {CAN_HEAD "[input a]\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel signed\n" RTDE_ROBOT,
     "t.ini:4: [input a] has no id"},
    {CAN_HEAD "[input a]\ntimeout_ms = 0\n" RTDE_ROBOT, "t.ini:5: timeout_ms = '0': give 1..60000 milliseconds"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\non_silence = later\n" RTDE_ROBOT,
     "t.ini:7: on_silence = 'later': use stop (the program's RTDE watchdog acts), hold (the last values go on) or "
     "value V (V goes to every register of the frame)"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\non_silence = value x\n" RTDE_ROBOT,
     "t.ini:7: on_silence = 'value x': value takes a finite number (value 0): not a number (write it in decimal, "
     "e.g. 2.5)"},
    {CAN_HEAD "[input a]\nperiod_ms = 10\n" RTDE_ROBOT, "t.ini:5: unknown key \"period_ms\" in [input a] (keys: id, extended, fd, length, robot, "
                                             "timeout_ms, on_silence, comment, signal)"},
    /* Ids: one id, one transmitter. */
    {CAN_HEAD "[frame f]\nid = 0x200\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n"
              "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel signed\n" RTDE_ROBOT,
     "t.ini:9: [input a] id 0x200 is already used by [frame f] (line 5): the PLC's frames need ids of their own"},
    {CAN_HEAD "[input a]\nid = 0x701\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel signed\n"
              RTDE_ROBOT,
     "t.ini:5: [input a] id 0x701 is already used by the heartbeat (line 3): the PLC's frames need ids of their own"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel signed\n"
              "[input b]\nid = 0x200\ntimeout_ms = 100\nsignal = input_int_register_25 @0|16 intel signed\n" RTDE_ROBOT,
     "t.ini:9: [input b] id 0x200 is already used by [input a] (line 5): the PLC's frames need ids of their own"},
    {CAN_HEAD "[input a]\nid = 0x800\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel signed\n"
              RTDE_ROBOT,
     "t.ini:5: [input a] id 0x800 is past 0x7FF, the largest 11-bit id: set extended = yes for a 29-bit id"},
    {CAN_HEAD "[frame a]\nid = 0x100\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n[input a]\nid = 0x200\n"
              RTDE_ROBOT,
     "t.ini:8: [input a]: [frame a] is already defined at line 4: frame names must be unique (the DBC names each "
     "message)"},
    {CAN_HEAD "[input a]\nid = 0x200\n[input a]\nid = 0x201\n" RTDE_ROBOT,
     "t.ini:6: [input a] is already defined at line 4: frame names must be unique (the DBC names each message)"},
    {CAN_HEAD "[input urrt_heartbeat]\nid = 0x200\n" RTDE_ROBOT, "t.ini:4: [input urrt_heartbeat]: that name is the "
                                                                 "heartbeat's"},
    /* What a signal may write: general purpose input registers only. */
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = speed_slider_fraction @0|16 intel unsigned\n"
              RTDE_ROBOT,
     "t.ini:7: signal: speed_slider_fraction is an RTDE input that acts on the robot's hardware with no robot "
     "program deciding: urrt never writes it; an [input] writes only general purpose input registers "
     "(input_int_register_N, input_double_register_N (N 0..47), input_bit_register_N (N 64..127), "
     "input_bit_registers0_to_31, input_bit_registers32_to_63)"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = standard_digital_output_mask @0|8 intel unsigned\n"
              RTDE_ROBOT,
     "t.ini:7: signal: standard_digital_output_mask is an RTDE input that acts on the robot's hardware with no "
     "robot program deciding: urrt never writes it; an [input] writes only general purpose input registers "
     "(input_int_register_N, input_double_register_N (N 0..47), input_bit_register_N (N 64..127), "
     "input_bit_registers0_to_31, input_bit_registers32_to_63)"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = actual_q[0] @0|16 intel signed\n" RTDE_ROBOT,
     "t.ini:7: signal: q_actual is not an input register: an [input] writes only general purpose input registers "
     "(input_int_register_N, input_double_register_N (N 0..47), input_bit_register_N (N 64..127), "
     "input_bit_registers0_to_31, input_bit_registers32_to_63); a value the robot sends goes in a [frame]"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = output_int_register_24 @0|16 intel signed\n"
              RTDE_ROBOT,
     "t.ini:7: signal: output_int_register_24 is not an input register: an [input] writes only general purpose "
     "input registers (input_int_register_N, input_double_register_N (N 0..47), input_bit_register_N (N 64..127), "
     "input_bit_registers0_to_31, input_bit_registers32_to_63); a value the robot sends goes in a [frame]"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = input_bit_register_63 @0|1 intel unsigned\n"
              RTDE_ROBOT,
     "t.ini:7: signal: no field 'input_bit_register_63' (field names as in docs/protocol.md: q_actual, tcp_force, "
     "robot_mode, ...; RTDE-only values by their RTDE names: output_int_register_24, ...)"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel signed invalid=0\n"
              RTDE_ROBOT,
     "t.ini:7: signal: invalid= is for frames the gateway sends; an [input]'s value outside min..max is refused "
     "and counted"},
    /* One register, one signal, one source. */
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel signed\n"
              "signal = input_int_register_24 @16|16 intel signed name=again\n" RTDE_ROBOT,
     "t.ini:8: [input a] signal 'again' writes the register signal 'input_int_register_24' (line 7) writes: one "
     "register, one signal (bits of a mask: disjoint bits=)"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\n"
              "signal = input_bit_registers32_to_63 @0|4 intel unsigned bits=0-3 name=m1\n"
              "signal = input_bit_registers32_to_63 @8|4 intel unsigned bits=3-6 name=m2\n" RTDE_ROBOT,
     "t.ini:8: [input a] signal 'm2' writes the register signal 'm1' (line 7) writes: one register, one signal "
     "(bits of a mask: disjoint bits=)"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel signed\n"
              "[input b]\nid = 0x201\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel signed name=b24\n"
              RTDE_ROBOT,
     "t.ini:11: [input b] signal 'b24': its register is written by [input a] signal 'input_int_register_24' "
     "(line 7) already: one register, one source"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\n"
              "signal = input_bit_registers0_to_31 @0|4 intel unsigned bits=30-33\n" RTDE_ROBOT,
     "t.ini:7: [input a] signal 'input_bit_registers0_to_31' carries bits 30-33 of input_bit_registers0_to_31, "
     "which has 32 (0..31): shorten it, or pick them with bits="},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\n"
              "signal = input_bit_registers0_to_31 @0|40 intel unsigned\n" RTDE_ROBOT,
     "t.ini:7: [input a] signal 'input_bit_registers0_to_31' carries bits 0-39 of input_bit_registers0_to_31, "
     "which has 32 (0..31): shorten it, or pick them with bits="},
    /* on_silence = value V: a value every register of the frame takes. */
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\non_silence = value 0.5\n"
              "signal = input_int_register_24 @0|16 intel signed\n" RTDE_ROBOT,
     "t.ini:7: [input a] on_silence = value 0.5: input_int_register_24 does not take it (an integer register an "
     "integer in its range, a bit 0 or 1, a mask word 0..4294967295)"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\non_silence = value 2\n"
              "signal = input_double_register_24 @0|16 intel signed\n"
              "signal = input_bit_register_64 @16|1 intel unsigned\n" RTDE_ROBOT,
     "t.ini:7: [input a] on_silence = value 2: input_bit_register_64 does not take it (an integer register an "
     "integer in its range, a bit 0 or 1, a mask word 0..4294967295)"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\non_silence = value -1\n"
              "signal = input_int_register_24 @0|16 intel signed min=0\n" RTDE_ROBOT,
     "t.ini:7: [input a] on_silence = value -1 is outside signal 'input_int_register_24''s min..max (0..32767): "
     "a value the PLC could never send"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\non_silence = value -1\n"
              "signal = input_bit_registers32_to_63 @0|8 intel unsigned\n" RTDE_ROBOT,
     "t.ini:7: [input a] on_silence = value -1: input_bit_registers32_to_63 does not take it (an integer register "
     "an integer in its range, a bit 0 or 1, a mask word 0..4294967295)"},
    /* Signals, lengths, FD. */
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\n" RTDE_ROBOT,
     "t.ini:4: [input a] has no signal (signal = input_int_register_24 @0|32 intel signed, ...)"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nlength = 12\nsignal = input_int_register_24 @0|16 intel "
              "signed\n" RTDE_ROBOT,
     "t.ini:7: [input a] length 12: a classic CAN frame carries at most 8 bytes (fd = yes for up to 64)"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nfd = yes\nlength = 12\n"
              "signal = input_int_register_24 @0|16 intel signed\n" RTDE_ROBOT,
     "t.ini:7: [input a] is a CAN FD frame but [can] fd is not yes"},
    {CAN_HEAD "fd = yes\n[input a]\nid = 0x200\ntimeout_ms = 100\nfd = yes\nlength = 10\n"
              "signal = input_int_register_24 @0|16 intel signed\n" RTDE_ROBOT,
     "t.ini:9: [input a] length 10 is not a CAN FD length (0-8, 12, 16, 20, 24, 32, 48, 64): use 12"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nlength = 2\nsignal = input_int_register_24 @8|16 intel "
              "signed\n" RTDE_ROBOT,
     "t.ini:8: [input a] signal 'input_int_register_24' (@8|16) reaches byte 2, past the frame's length 2"},
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel signed\n"
              "signal = input_int_register_25 @8|16 intel signed\n" RTDE_ROBOT,
     "t.ini:8: [input a] signal 'input_int_register_25' overlaps signal 'input_int_register_24' (line 7)"},
    /* The robot: one that reads RealTime never writes. */
    {CAN_HEAD "[input a]\nid = 0x200\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel signed\n"
              "[robot arm]\nhost = h\n",
     "t.ini:4: [input a] writes robot \"arm\"'s input registers, and that robot reads RealTime, which never "
     "writes: add \"source = rtde\" to [robot arm] (RTDE, port 30004) or remove the [input]"},
    {CAN_HEAD "[input a]\nid = 0x200\nrobot = bob\ntimeout_ms = 100\nsignal = input_int_register_24 @0|16 intel "
              "signed\n" RTDE_ROBOT,
     "t.ini:6: [input a]: unknown robot 'bob' (robots: arm)"},
};

static void inputs_rejections(void)
{
    for (size_t i = 0; i < sizeof input_rejections / sizeof input_rejections[0]; i++) {
        gw_config cfg;
        char err[4096] = "", first[1024];
        const char *want = input_rejections[i].expect;
        int errors = load_cfg(&cfg, input_rejections[i].config, err, sizeof err);
        first_line(err, first, sizeof first);
        CHECK(errors > 0 && strcmp(first, want) == 0, "[input] rejection %zu:\n  got:  %s\n  want: %s", i, first,
              want);
        gw_config_free(&cfg);
    }
}

/* An FD [input] of 64 bytes writing bit registers 64..127 (lines 10..73), and with one more
 * register, input_int_register_24, at line 74. */
static void many_registers(char *text, size_t size, bool one_more)
{
    int n = snprintf(text, size, CAN_HEAD "fd = yes\n[input a]\nid = 0x200\nfd = yes\nlength = 64\ntimeout_ms = 100\n");
    for (int b = 0; b < 64; b++) {
        n += snprintf(text + n, size - (size_t)n, "signal = input_bit_register_%d @%d|1 intel unsigned\n", 64 + b, b);
    }
    snprintf(text + n, size - (size_t)n, "%s%s", one_more ? "signal = input_int_register_24 @64|32 intel signed\n" : "",
             RTDE_ROBOT);
}

/* One input recipe takes URRT_RTDE_IN_MAX_VARS (64) registers. */
static void inputs_too_many_registers(void)
{
    char text[8192];
    gw_config cfg;
    char err[4096] = "", first[1024];
    many_registers(text, sizeof text, true);
    CHECK(load_cfg(&cfg, text, err, sizeof err) > 0, "65 registers in one [input] accepted");
    first_line(err, first, sizeof first);
    CHECK_EQ_STR(first, "t.ini:74: [input a] writes more than 64 registers: one input recipe takes at most 64; split "
                        "the frame");
    gw_config_free(&cfg);
    many_registers(text, sizeof text, false);
    CHECK(load_cfg(&cfg, text, err, sizeof err) == 0, "64 registers: %s", err);
    CHECK(cfg.can.input_count == 1 && cfg.can.inputs[0].reg_count == 64 &&
              cfg.can.inputs[0].regs[0] == URRT_RTDE_V_INPUT_BIT_REGISTER &&
              cfg.can.inputs[0].regs[63] == URRT_RTDE_V_INPUT_BIT_REGISTER + 63,
          "64 registers, in order");
    gw_config_free(&cfg);
}

/* What the refusals leave: one id of each kind, one register per robot. */
static void inputs_accepted_apart(void)
{
    gw_config cfg;
    char err[4096] = "";
    int errors = load_cfg(&cfg,
                          CAN_HEAD "heartbeat_robot = left\n"
                          "[input a]\nid = 0x200\nrobot = left\ntimeout_ms = 100\n"
                          "signal = input_int_register_24 @0|16 intel signed\n"
                          "[input b]\nid = 0x200\nextended = yes\nrobot = right\ntimeout_ms = 100\n"
                          "signal = input_int_register_24 @0|16 intel signed\n"
                          "[robot left]\nhost = h\nversion = 5.10\nsource = rtde\n"
                          "[robot right]\nhost = h2\nversion = 5.10\nsource = rtde\n",
                          err, sizeof err);
    CHECK(errors == 0, "an 11-bit and a 29-bit id 0x200, one register on two robots: %s", err);
    if (errors == 0) {
        CHECK(cfg.can.input_count == 2 && cfg.can.inputs[0].robot_index == 0 && cfg.can.inputs[1].robot_index == 1,
              "each [input] its robot");
        CHECK(can_map_input_of(&cfg.can, 0x200, false) == &cfg.can.inputs[0] &&
                  can_map_input_of(&cfg.can, 0x200, true) == &cfg.can.inputs[1],
              "0x200 and 29-bit 0x200 are two frames");
    }
    gw_config_free(&cfg);
}

static void test_inputs(void)
{
    inputs_accepted();
    inputs_example();
    inputs_rejections();
    inputs_accepted_apart();
    inputs_too_many_registers();
}

int main(void)
{
    test_config_good();
    test_config_rejections();
    test_config_robots();
    test_reporter();
    test_bus_load();
    test_schedule();
    test_validity_and_heartbeat();
    test_heartbeat_rate();
    test_config_mutations();
    test_masks();
    test_dbc_text();
    test_rtde_values();
    test_inputs();
    return check_report();
}
