/* SPDX-License-Identifier: MIT */
/*
 * test_config.c: regression tests for what the configuration fuzzer
 * (tests/gateway/config/fuzz_config.c) found in the loader, one per finding, with
 * the input it found in tests/gateway/config/regressions/ as well; then the rules
 * of the one configuration front end (gateway/common/conf.h): one parser per kind
 * of value, the same in every section, and messages causes first. Runs in
 * check-fuzz-config, under ASan + UBSan.
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "can_run.h"
#include "check.h"
#include "conf.h"
#include "config.h"

/* CHECK_EQ_INT evaluates its arguments again to print them: once only. */
#define CHECK_ERRORS(call, n)          \
    do {                               \
        int errors_ = (call);          \
        CHECK_EQ_INT(errors_, (n));    \
    } while (0)

/* Loads text (len bytes, NULs allowed) as "t.ini": the error count, and the
 * messages in *messages (caller frees). */
static int load(const char *text, size_t len, char **messages, gw_config *cfg)
{
    size_t size = 0;
    char *copy = malloc(len ? len : 1);
    FILE *in;
    FILE *err = open_memstream(messages, &size);
    int errors;
    memcpy(copy, text, len);
    in = fmemopen(copy, len, "r");
    errors = gw_config_load_stream(cfg, in, "t.ini", err);
    fclose(in);
    fclose(err);
    free(copy);
    return errors;
}

static int load_str(const char *text, char **messages)
{
    gw_config cfg;
    int errors = load(text, strlen(text), messages, &cfg);
    gw_config_free(&cfg);
    return errors;
}

/* The stream entry point reads as the file one does. */
static void test_stream_and_file(void)
{
    static const char text[] = "[robot a]\nhost = h\nport = 0\n";
    char *from_stream = NULL;
    char *from_file = NULL;
    size_t size = 0;
    char path[] = "/tmp/test_config_XXXXXX";
    int fd = mkstemp(path);
    FILE *f = fdopen(fd, "w");
    FILE *err = open_memstream(&from_file, &size);
    gw_config cfg;
    fputs(text, f);
    fclose(f);
    CHECK_ERRORS(load_str(text, &from_stream), 1);
    CHECK_EQ_STR(from_stream, "t.ini:3: port must be a whole number from 1 to 65535, not \"0\"\n");
    CHECK_ERRORS(gw_config_load(&cfg, path, err), 1);
    fclose(err);
    CHECK(strstr(from_file, ":3: port must be a whole number from 1 to 65535, not \"0\"\n") != NULL, "%s",
          from_file);
    gw_config_free(&cfg);
    unlink(path);
    free(from_stream);
    free(from_file);
}

/* Finding 1: a valid file has no message, and the loader sorted the
 * message array anyway: qsort(NULL, 0, ...), undefined behaviour (UBSan,
 * nonnull-attribute). This test runs under UBSan. */
static void test_valid_file_no_messages(void)
{
    char *messages = NULL;
    CHECK_ERRORS(load_str("[robot a]\nhost = h\n", &messages), 0);
    CHECK_EQ_STR(messages, "");
    free(messages);
}

/* Finding 2: messages echo the file's text, and control characters went
 * out raw: an escape sequence from the file reached the terminal, a
 * carriage return hid the start of the message, a tab or a byte 0x02 made
 * a message that is not one plain line. They are written as \xNN. */
static void test_control_characters_escaped(void)
{
    static const char text[] = "[robot a]\nhost = h\x1b[2J\nport = 1\r2\n[can]\nhea\x02rtbeat_id = 0x701\n"
                               "interface = a\tb\n";
    static const char *const want[] = {
        "\nt.ini:2: host \"h\\x1B[2J\" is not a host name, IPv4 or IPv6 address\n",
        "\nt.ini:3: port must be a whole number from 1 to 65535, not \"1\\x0D2\"\n",
        "\nt.ini:5: unknown key \"hea\\x02rtbeat_id\" in [can]: did you mean \"heartbeat_id\"? (keys: ",
        "\nt.ini:6: interface = 'a\\x09b': no control characters\n",
    };
    char *messages = NULL;
    char *lined;
    CHECK_ERRORS(load_str(text, &messages), 8); /* and the 4 of a robot and [can] left incomplete */
    CHECK(asprintf(&lined, "\n%s", messages) > 0, "asprintf");
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        CHECK(strstr(lined, want[i]) != NULL, "message %zu missing:\n%s", i, messages);
    }
    CHECK(strcspn(messages, "\x01\x02\x03\x04\x05\x06\x07\x08\x09\x0b\x0c\x0d\x0e\x0f\x10\x11\x12\x13\x14"
                            "\x15\x16\x17\x18\x19\x1a\x1b\x1c\x1d\x1e\x1f\x7f") == strlen(messages),
          "a control character in the messages:\n%s", messages);
    free(lined);
    free(messages);
}

/* Finding 3: a NUL byte in a line longer than the reader's 200-byte buffer
 * hid the line's end from the reader (fgets then strlen), so the rest of
 * the line counted as a line of its own: every later message named a line
 * past the real one, up to lines the file does not have. The reader now
 * counts the bytes it reads, and a NUL byte is an error of its line. A
 * line holds 198 characters before its end (the message said 197, true of
 * a "\r\n" line only). */
static void test_nul_byte(void)
{
    char text[512];
    size_t len = 0;
    char *messages = NULL;
    gw_config cfg;
    len += (size_t)sprintf(text + len, "[robot a]\nhost = h\n# x");
    text[len++] = '\0';
    memset(text + len, 'y', 300);
    len += 300;
    len += (size_t)sprintf(text + len, "\nport = 0\nversion = 5.1");
    text[len++] = '\0';
    len += (size_t)sprintf(text + len, "0\n");
    CHECK_ERRORS(load(text, len, &messages, &cfg), 3);
    CHECK_EQ_STR(messages, "t.ini:3: line longer than 198 characters\n"
                           "t.ini:4: port must be a whole number from 1 to 65535, not \"0\"\n"
                           "t.ini:5: a NUL byte: the configuration must be a text file\n");
    CHECK_EQ_STR(cfg.robots[0].expected, "auto");
    gw_config_free(&cfg);
    free(messages);
}

/* Finding 4: an accepted file put control characters into what the
 * gateway prints: the LCM URL of a provider other than udpm (at start and
 * by --check-config). (The CAN side's comment, unit and interface:
 * tests/lib/test_can.c.) */
static void test_control_characters_refused(void)
{
    char *messages = NULL;
    CHECK_ERRORS(load_str("[lcm]\nurl = file:///tmp/x\x1b[2J\n[robot a]\nhost = h\n", &messages), 1);
    CHECK_EQ_STR(messages, "t.ini:2: url \"file:///tmp/x\\x1B[2J\": no control characters\n");
    free(messages);
}

/* Finding 5 (found reading the loader while writing the harness, not by
 * the fuzzer): libinih, which read the file then, truncated section names
 * to 49 characters, the loader compared its name with the whole header
 * and, on a mismatch, skipped the section's keys silently: a robot named
 * with 44 to 64 characters (valid names) was rejected as having no host. */
static void test_long_robot_name(void)
{
    static const char name[] = "a123456789012345678901234567890123456789012345678901234567890123";
    char text[256];
    char *messages = NULL;
    gw_config cfg;
    snprintf(text, sizeof text, "[robot %s]\nhost = h\nport = 30013\n", name);
    CHECK_EQ_INT(strlen(name), 64);
    CHECK_ERRORS(load(text, strlen(text), &messages, &cfg), 0);
    CHECK_EQ_STR(messages, "");
    if (cfg.robot_count == 1) {
        CHECK_EQ_STR(cfg.robots[0].name, name);
        CHECK_EQ_STR(cfg.robots[0].host, "h");
        CHECK_EQ_INT(cfg.robots[0].port, 30013);
    }
    gw_config_free(&cfg);
    free(messages);
}

/* Finding 6 (the harness's "no key ignored" check, on a hand-made input;
 * the fuzzer did not reach it in 4 minutes): the loader took a line for a
 * section header after spaces and tabs only, libinih (which then split
 * the keys) after any blank. A header after a form feed was then libinih's
 * section but not the loader's, and when the line also held a '=' (so that
 * the loader did not call it a syntax error) the keys below it were
 * dropped without a word (here port = 0: the file was accepted). One
 * reader now reads each line once. */
static void test_header_after_form_feed(void)
{
    char *messages = NULL;
    CHECK_ERRORS(load_str("[robot a]\nhost = h\n\f[robot b=x]\nport = 0\n", &messages), 1);
    CHECK_EQ_STR(messages, "t.ini:3: robot name \"b=x\" must be 1 to 64 letters, digits, '_' or '-'\n");
    free(messages);
    CHECK_ERRORS(load_str("[robot a]\nhost = h\n\v [lcm]\nstate_rate = 1 Hz\n", &messages), 0);
    CHECK_EQ_STR(messages, "");
    free(messages);
}

/* Finding 7 (review while writing the harness): text after a section
 * header was ignored by libinih and by the loader alike, so
 * "[lcm] url = ...?ttl=1" left the default URL in place without a word. */
static void test_text_after_header(void)
{
    char *messages = NULL;
    CHECK_ERRORS(load_str("[lcm] url = udpm://239.255.76.67:7667?ttl=1\n[robot a]\nhost = h\n", &messages), 1);
    CHECK_EQ_STR(messages, "t.ini:1: text after the section header: \"url = udpm://239.255.76.67:7667?ttl=1\" (keys go "
                           "on lines of their own)\n");
    free(messages);
    CHECK_ERRORS(load_str("[lcm] ; the bus\n[robot a] # first\t\nhost = h\n", &messages), 0);
    CHECK_EQ_STR(messages, "");
    free(messages);
}

/* ---- the one front end (gateway/common/conf.h) -------------------------------------------- */

/* Integers: decimal or 0x hexadecimal; a leading zero is C's octal and is
 * refused with both readings spelled out. */
static void test_integers(void)
{
    char why[CONF_WHY_MAX] = "";
    uint64_t v = 0;
    uint32_t v32 = 0;
    int64_t i = 0;
    CHECK(conf_uint("100", 0, 1000, &v, why, sizeof why) && v == 100, "100: %s", why);
    CHECK(conf_uint("0x40", 0, 1000, &v, why, sizeof why) && v == 64, "0x40: %s", why);
    CHECK(conf_uint("0X7ff", 0, 0x7ff, &v, why, sizeof why) && v == 0x7ff, "0X7ff: %s", why);
    CHECK(conf_uint("0", 0, 10, &v, why, sizeof why) && v == 0, "0: %s", why);
    CHECK(!conf_uint("0100", 0, 1000, &v, why, sizeof why), "0100 accepted");
    CHECK_EQ_STR(why, "a leading zero is not allowed (write 0x40 for hexadecimal or 100 for decimal)");
    CHECK(!conf_u32("010", 1, 100, &v32, why, sizeof why), "010 accepted");
    CHECK_EQ_STR(why, "a leading zero is not allowed (write 0x8 for hexadecimal or 10 for decimal)");
    CHECK(!conf_uint("09", 0, 100, &v, why, sizeof why), "09 accepted");
    CHECK_EQ_STR(why, "a leading zero is not allowed (write 9)");
    CHECK(!conf_uint("70000", 1, 65535, &v, why, sizeof why), "70000 accepted");
    CHECK_EQ_STR(why, "out of range: from 1 to 65535");
    CHECK(!conf_uint("99999999999999999999999", 0, UINT64_MAX, &v, why, sizeof why), "overflow accepted");
    CHECK_EQ_STR(why, "out of range: from 0 to 18446744073709551615");
    for (size_t k = 0; k < 6; k++) {
        static const char *const words[] = {"-1", "+1", "12abc", "0x", " 1", "1.5"};
        CHECK(!conf_uint(words[k], 0, 100, &v, why, sizeof why), "%s accepted", words[k]);
        CHECK_EQ_STR(why, "not a whole number (decimal, or hexadecimal with 0x)");
    }
    CHECK(!conf_uint("", 0, 100, &v, why, sizeof why), "empty accepted");
    CHECK_EQ_STR(why, "no value");
    CHECK(conf_int("-128", INT64_MIN, INT64_MAX, &i, why, sizeof why) && i == -128, "-128: %s", why);
    CHECK(conf_int("0x8000", INT64_MIN, INT64_MAX, &i, why, sizeof why) && i == 0x8000, "0x8000: %s", why);
    CHECK(conf_int("-9223372036854775808", INT64_MIN, INT64_MAX, &i, why, sizeof why) && i == INT64_MIN,
          "INT64_MIN: %s", why);
    CHECK(!conf_int("-010", INT64_MIN, INT64_MAX, &i, why, sizeof why), "-010 accepted");
    CHECK_EQ_STR(why, "a leading zero is not allowed (write 0x8 for hexadecimal or 10 for decimal)");
    CHECK(!conf_int("-5", -4, 4, &i, why, sizeof why), "-5 accepted");
    CHECK_EQ_STR(why, "out of range: from -4 to 4");
}

static void test_numbers_and_booleans(void)
{
    static const char *const yes[] = {"yes", "YES", "True", "on", "ON", "1"};
    static const char *const no[] = {"no", "No", "FALSE", "off", "Off", "0"};
    char why[CONF_WHY_MAX] = "";
    double d = 0;
    bool b;
    CHECK(conf_number("2.5", 0, 10, &d, why, sizeof why) && d == 2.5, "2.5: %s", why);
    CHECK(conf_number("1e-3", 0, 10, &d, why, sizeof why) && d == 1e-3, "1e-3: %s", why);
    CHECK(conf_number("-.5", -1, 1, &d, why, sizeof why) && d == -0.5, "-.5: %s", why);
    for (size_t k = 0; k < 4; k++) {
        static const char *const words[] = {"nan", "inf", "0x1p3", "2.5x"};
        CHECK(!conf_number(words[k], -1e300, 1e300, &d, why, sizeof why), "%s accepted", words[k]);
        CHECK_EQ_STR(why, "not a number (write it in decimal, e.g. 2.5)");
    }
    CHECK(!conf_number("11", 0.1, 10, &d, why, sizeof why), "11 accepted");
    CHECK_EQ_STR(why, "out of range: from 0.1 to 10");
    for (size_t k = 0; k < 6; k++) {
        b = false;
        CHECK(conf_bool(yes[k], &b, why, sizeof why) && b, "%s", yes[k]);
        b = true;
        CHECK(conf_bool(no[k], &b, why, sizeof why) && !b, "%s", no[k]);
    }
    CHECK(!conf_bool("maybe", &b, why, sizeof why), "maybe accepted");
    CHECK_EQ_STR(why, "use yes or no (or true/false, on/off, 1/0)");
}

/* One grammar for every duration key: a number and a unit; a bare number
 * only where the key's name carries the unit. */
static void test_durations(void)
{
    static const struct { const char *text; const char *bare; uint32_t ms; } good[] = {
        {"100ms", NULL, 100}, {"250 ms", NULL, 250}, {"1.5s", NULL, 1500}, {"2 s", NULL, 2000},
        {"2 min", NULL, 120000}, {"5000us", NULL, 5}, {"100", "ms", 100}, {"0.5 s", "ms", 500},
    };
    char why[CONF_WHY_MAX] = "";
    uint32_t ms = 0;
    uint64_t us = 0;
    for (size_t k = 0; k < sizeof good / sizeof good[0]; k++) {
        ms = 0;
        CHECK(conf_duration_ms(good[k].text, good[k].bare, 1, 600000, &ms, why, sizeof why) && ms == good[k].ms,
              "%s: %u, %s", good[k].text, (unsigned)ms, why);
    }
    CHECK(!conf_duration_ms("100", NULL, 1, 600000, &ms, why, sizeof why), "bare 100 accepted");
    CHECK_EQ_STR(why, "a duration is written with a unit (us, ms, s or min), e.g. \"100 ms\" or \"100 s\"");
    CHECK(!conf_duration_ms("5 ms", NULL, 20, 600000, &ms, why, sizeof why), "5 ms accepted");
    CHECK_EQ_STR(why, "out of range: from 20 ms to 10 min");
    CHECK(!conf_duration_ms("1.5 ms", NULL, 1, 600000, &ms, why, sizeof why), "1.5 ms accepted");
    CHECK_EQ_STR(why, "not a whole number of milliseconds");
    CHECK(!conf_duration_ms("3 h", NULL, 1, 600000, &ms, why, sizeof why), "3 h accepted");
    CHECK_EQ_STR(why, "unknown unit \"h\": write us, ms, s or min");
    CHECK(!conf_duration_ms("-1 s", NULL, 0, 600000, &ms, why, sizeof why), "-1 s accepted");
    CHECK(conf_duration_us("2.5", "s", 0, 10000000, &us, why, sizeof why) && us == 2500000, "2.5 s: %s", why);
    CHECK(conf_bare_unit("stale_after_ms") != NULL && strcmp(conf_bare_unit("stale_after_ms"), "ms") == 0, "_ms");
    CHECK(conf_bare_unit("period_ms") != NULL && strcmp(conf_bare_unit("period_ms"), "ms") == 0, "period_ms");
    CHECK(conf_bare_unit("silence_timeout") == NULL, "no unit in the name");
    CHECK(conf_bare_unit("ms") == NULL, "a name that is only a unit");
}

/* One grammar for every rate: a number of Hz, the unit optional, so a bare
 * number means Hz in [lcm] and [robot] alike; the refusal of a frequency too
 * high says the largest one in a form the file takes. */
static void test_rates(void)
{
    static const struct { const char *text; double hz; } good[] = {
        {"50 Hz", 50}, {"50Hz", 50}, {"50", 50}, {"0.5 Hz", 0.5}, {"1e2", 100}, {"125\tHz", 125},
    };
    static const struct { const char *text; const char *why; } bad[] = {
        {"50 hz", "unknown unit \"hz\": a rate is in Hz, e.g. \"50 Hz\" (or 50)"},
        {"50 kHz", "unknown unit \"kHz\": a rate is in Hz, e.g. \"50 Hz\" (or 50)"},
        {"fast", "not a rate: a number of Hz, e.g. \"50 Hz\" (or 50)"},
        {"-5", "not a rate: a number of Hz, e.g. \"50 Hz\" (or 50)"},
        {"nan Hz", "not a rate: a number of Hz, e.g. \"50 Hz\" (or 50)"},
        {"600", "out of range: from 0.01 Hz to 500 Hz"},
        {"", "no value"},
    };
    static const struct { const char *value; const char *want; } refused[] = {
        {"600", "t.ini:4: rtde_frequency 600 Hz is above 500 Hz, the fastest any controller streams RTDE: write "
                "rtde_frequency = 500 Hz or less, or rtde_frequency = auto\n"},
        {"600 Hz", "t.ini:4: rtde_frequency 600 Hz is above 500 Hz, the fastest any controller streams RTDE: write "
                   "rtde_frequency = 500 Hz or less, or rtde_frequency = auto\n"},
        {"0", "t.ini:4: rtde_frequency 0 Hz is out of range: from 0.01 Hz to 500 Hz, or auto\n"},
        {"fast", "t.ini:4: rtde_frequency must be \"auto\" or a rate such as \"125 Hz\" (a bare 125 is Hz too), at "
                 "most 500 Hz, not \"fast\"\n"},
    };
    char why[CONF_WHY_MAX] = "";
    double hz = 0;
    for (size_t k = 0; k < sizeof good / sizeof good[0]; k++) {
        hz = 0;
        CHECK(conf_rate_hz(good[k].text, 0.01, 500, &hz, why, sizeof why) && hz == good[k].hz, "%s: %g, %s",
              good[k].text, hz, why);
    }
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        CHECK(!conf_rate_hz(bad[k].text, 0.01, 500, &hz, why, sizeof why), "%s accepted", bad[k].text);
        CHECK_EQ_STR(why, bad[k].why);
    }
    /* The same values with and without the unit, in each key that takes a rate. */
    for (int unit = 0; unit < 2; unit++) {
        char text[256];
        char *messages = NULL;
        gw_config cfg;
        const char *hz_ = unit ? " Hz" : "";
        snprintf(text, sizeof text, "[lcm]\njoints_rate = 50%s\ngateway_rate = 2%s\n[robot a]\nhost = h\n"
                 "source = rtde\nrtde_frequency = 500%s\n", hz_, hz_, hz_);
        CHECK_ERRORS(load(text, strlen(text), &messages, &cfg), 0);
        CHECK(cfg.robot_count == 1 && cfg.robots[0].rtde_frequency == 500 &&
                  cfg.lcm.rate[GW_KIND_JOINTS].mode == GW_RATE_HZ && cfg.lcm.rate[GW_KIND_JOINTS].hz == 50 &&
                  cfg.lcm.rate[GW_KIND_GATEWAY].hz == 2, "rates%s: %s", hz_, messages);
        gw_config_free(&cfg);
        free(messages);
    }
    for (size_t k = 0; k < sizeof refused / sizeof refused[0]; k++) {
        char text[256];
        char *messages = NULL;
        snprintf(text, sizeof text, "[robot a]\nhost = h\nsource = rtde\nrtde_frequency = %s\n", refused[k].value);
        CHECK_ERRORS(load_str(text, &messages), 1);
        CHECK(strcmp(messages, refused[k].want) == 0, "rtde_frequency = %s:\n  got:  %s  want: %s",
              refused[k].value, messages, refused[k].want);
        free(messages);
    }
}

static void test_names_and_text(void)
{
    char why[CONF_WHY_MAX] = "";
    char text[8];
    CHECK(conf_name("arm-1", CONF_NAME_DASH, 64, why, sizeof why), "arm-1: %s", why);
    CHECK(!conf_name("arm.1", CONF_NAME_DASH, 64, why, sizeof why), "arm.1 accepted");
    CHECK_EQ_STR(why, "must be 1 to 64 letters, digits, '_' or '-'");
    CHECK(conf_name("A.B", CONF_NAME_DASH | CONF_NAME_DOTS, 64, why, sizeof why), "A.B: %s", why);
    CHECK(!conf_name(".AB", CONF_NAME_DASH | CONF_NAME_DOTS, 64, why, sizeof why), ".AB accepted");
    CHECK(conf_name("_q0", CONF_NAME_C, 32, why, sizeof why), "_q0: %s", why);
    CHECK(!conf_name("9lives", CONF_NAME_C, 32, why, sizeof why), "9lives accepted");
    CHECK_EQ_STR(why, "is not a C identifier of at most 32 characters");
    CHECK(conf_text(text, sizeof text, "\"N m\"", why, sizeof why), "quoted: %s", why);
    CHECK_EQ_STR(text, "N m");
    CHECK(!conf_text(text, sizeof text, "a\x1b[2J", why, sizeof why), "escape accepted");
    CHECK_EQ_STR(why, "at most 7 characters, no '\"', '\\' or control characters");
    CHECK(!conf_printable("a\tb", why, sizeof why), "tab accepted");
    CHECK_EQ_STR(why, "no control characters");
}

#define CAN_TEXT "[can]\ninterface = vcan0\nheartbeat_id = 0x701\n"
#define FRAME_TEXT "[frame f]\nid = 0x100\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n"

/* A value means the same in every section: fd = YES and summary = YES,
 * 0x ids, and durations with a unit wherever a duration is asked. */
static void test_same_everywhere(void)
{
    static const char text[] = "[gateway]\nsummary = YES\n[robot a]\nhost = h\nport = 0x7533\n"
                               "silence_timeout = 250ms\nconnect_timeout = 1.5s\n"
                               "[can]\ninterface = vcan0\nheartbeat_id = 0x701\nfd = YES\nheartbeat_period_ms = 0.5 s\n"
                               "stale_after_ms = 200\n"
                               "[frame f]\nid = 0x40\nperiod_ms = 1s\nstale_after_ms = 50 ms\nextended = On\n"
                               "signal = time @0|8 intel unsigned invalid=0xFF\n";
    char *messages = NULL;
    gw_config cfg;
    CHECK_ERRORS(load(text, strlen(text), &messages, &cfg), 0);
    CHECK_EQ_STR(messages, "");
    CHECK(cfg.summary, "summary = YES");
    CHECK(cfg.can.fd, "fd = YES");
    CHECK_EQ_INT(cfg.robots[0].port, 30003);
    CHECK_EQ_INT(cfg.robots[0].link.silence_timeout_ms, 250);
    CHECK_EQ_INT(cfg.robots[0].link.connect_timeout_ms, 1500);
    CHECK_EQ_INT(cfg.can.hb_period_ms, 500);
    CHECK_EQ_INT(cfg.can.stale_after_ms, 200);
    if (cfg.can.frame_count == 1) {
        CHECK_EQ_INT(cfg.can.frames[0].id, 0x40);
        CHECK_EQ_INT(cfg.can.frames[0].period_ms, 1000);
        CHECK_EQ_INT(cfg.can.frames[0].stale_after_ms, 50);
        CHECK(cfg.can.frames[0].extended, "extended = On");
        CHECK_EQ_INT(cfg.can.frames[0].sigs[0].invalid_raw, 0xFF);
    }
    gw_config_free(&cfg);
    free(messages);
}

/* Each refusal, with its message: the value as written, what to write. */
static void test_refusals(void)
{
    static const struct { const char *text; const char *want; } cases[] = {
        {"[robot a]\nhost = h\n" CAN_TEXT "[frame f]\nid = 0100\nperiod_ms = 10\nsignal = time @0|8 intel unsigned\n",
         "t.ini:7: id = \"0100\": a leading zero is not allowed (write 0x40 for hexadecimal or 100 for decimal)\n"
         "t.ini:6: [frame f] has no id\n"},
        {"[robot a]\nhost = h\nport = 030003\n",
         "t.ini:3: port = \"030003\": a leading zero is not allowed (write 0x3003 for hexadecimal or 30003 for "
         "decimal)\n"},
        {"[robot a]\nhost = h\nsilence_timeout = 100\n",
         "t.ini:3: silence_timeout = \"100\": a duration is written with a unit (us, ms, s or min), e.g. \"100 ms\" "
         "or \"100 s\"\n"},
        {"[robot a]\nhost = h\nbackoff_max = 2 h\n",
         "t.ini:3: backoff_max = \"2 h\": unknown unit \"h\": write us, ms, s or min\n"},
        {"[robot a]\nhost = h\n" CAN_TEXT FRAME_TEXT "signal = robot_mode @8|8 intel signed invalid=0200\n",
         "t.ini:10: signal: invalid = '0200' is not an integer raw value: a leading zero is not allowed (write 0x80 "
         "for hexadecimal or 200 for decimal)\n"},
        {"[robot a]\nhost = h\n" CAN_TEXT FRAME_TEXT "validity_bit = 063\n",
         "t.ini:10: validity_bit = '063': give the bit number (0..511)\n"},
        {"[gateway]\nsummary = maybe\n[robot a]\nhost = h\n",
         "t.ini:2: summary must be yes or no (or true/false, on/off, 1/0), not \"maybe\"\n"},
        {"[robot a]\nhost = 127.0.0.1:47010\nport = 1\n",
         "t.ini:2: host \"127.0.0.1:47010\" is HOST:PORT: write host = 127.0.0.1 and port = 47010\n"
         "t.ini:1: [robot a] has no host: add \"host = ADDRESS\"\n"},
        {"[robot a]\nhost = [::1]:30003\n",
         "t.ini:2: host \"[::1]:30003\": write the address without brackets (host = ::1) and the port apart "
         "(port = 30003)\n"
         "t.ini:1: [robot a] has no host: add \"host = ADDRESS\"\n"},
        {"[robot a]\nhost = [fe80::1]\n",
         "t.ini:2: host \"[fe80::1]\": write the address without brackets (host = fe80::1)\n"
         "t.ini:1: [robot a] has no host: add \"host = ADDRESS\"\n"},
        {"[robot a]\nhost = h\n" CAN_TEXT "[frame f]\nid = 0x100\n[frame f]\nperiod_ms = 10\n",
         "t.ini:8: [frame f] is already defined at line 6: frame names must be unique (the DBC names each message)\n"
         "t.ini:6: [frame f] has no period_ms (milliseconds, or every)\n"
         "t.ini:6: [frame f] has no signal (signal = FIELD[ELEM] @START|LENGTH ...)\n"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char *messages = NULL;
        load_str(cases[k].text, &messages);
        CHECK(strcmp(messages, cases[k].want) == 0, "case %zu:\n  got:  %s  want: %s", k, messages, cases[k].want);
        free(messages);
    }
    /* Valid before, valid now: an IPv6 address, and a bare number where the key names the unit. */
    {
        char *messages = NULL;
        CHECK_ERRORS(load_str("[robot a]\nhost = fe80::1%eth0\n[robot b]\nhost = ::1\n", &messages), 0);
        CHECK_EQ_STR(messages, "");
        free(messages);
    }
}

/* A table of keys: each kind parsed into its field, a hint replacing the
 * parser's reason (but not the leading-zero one), a hint for the unknown. */
struct table_test {
    uint16_t port;
    bool on;
    uint32_t wait_ms;
    uint32_t period_ms;
};

static void test_key_table(void)
{
    static const struct conf_key keys[] = {
        {"port", CONF_UINT, CONF_FIELD(struct table_test, port), 1, 65535, NULL, "%1$s: 1 to 65535, not %2$s", false,
         NULL, "80", NULL, "a port"},
        {"on", CONF_BOOL, CONF_FIELD(struct table_test, on), 0, 0, NULL, NULL, false, NULL, "yes", NULL, NULL},
        {"wait", CONF_MS, CONF_FIELD(struct table_test, wait_ms), 1, 1000, NULL, NULL, false, NULL, NULL, "required",
         "a wait"},
        {"period_ms", CONF_MS, CONF_FIELD(struct table_test, period_ms), 1, 1000, NULL, NULL, false, NULL, "0.5 s",
         NULL, NULL},
        {"bad", CONF_MS, CONF_FIELD(struct table_test, port), 1, 1000, NULL, NULL, false, NULL, NULL, NULL, NULL},
    };
    struct table_test t = {0};
    struct conf_at at = {"t.ini", 1};
    char why[CONF_WHY_MAX] = "";
    CHECK(conf_key_set(conf_key_find(keys, 5, "port"), &t, "0x7533", at, why, sizeof why) && t.port == 30003,
          "port: %s", why);
    CHECK(conf_key_set(&keys[1], &t, "TRUE", at, why, sizeof why) && t.on, "on: %s", why);
    CHECK(conf_key_set(&keys[2], &t, "0.25 s", at, why, sizeof why) && t.wait_ms == 250, "wait: %s", why);
    CHECK(conf_key_set(&keys[3], &t, "20", at, why, sizeof why) && t.period_ms == 20, "period_ms: %s", why);
    CHECK(!conf_key_set(&keys[0], &t, "0", at, why, sizeof why), "port 0 accepted");
    CHECK_EQ_STR(why, "port: 1 to 65535, not 0");
    CHECK(!conf_key_set(&keys[0], &t, "080", at, why, sizeof why), "port 080 accepted");
    CHECK_EQ_STR(why, "port = \"080\": a leading zero is not allowed (write 80)");
    CHECK(!conf_key_set(&keys[2], &t, "20", at, why, sizeof why), "bare wait accepted");
    CHECK_EQ_STR(why, "wait = \"20\": a duration is written with a unit (us, ms, s or min), e.g. \"20 ms\" or \"20 s\"");
    CHECK(!conf_key_set(&keys[4], &t, "20 ms", at, why, sizeof why), "a 2-byte duration field accepted");
    CHECK_EQ_STR(why, "bad: the table gives a field of 2 bytes (a bug)");
    CHECK(conf_key_find(keys, 5, "Port") == NULL, "names are case-sensitive");
    conf_unknown_key(keys, 4, "prot", "x", why, sizeof why);
    CHECK_EQ_STR(why, "unknown key \"prot\" in [x]: did you mean \"port\"? (keys: port, on, wait, period_ms)");
    conf_unknown_key(keys, 4, "colour", "x", why, sizeof why);
    CHECK_EQ_STR(why, "unknown key \"colour\" in [x] (keys: port, on, wait, period_ms)");
    CHECK(conf_suggest("o", keys, 4, sizeof keys[0]) == NULL, "no hint from one letter");
    /* What the table says of its keys: defaults set, bounds, one line each. */
    memset(&t, 0, sizeof t);
    CHECK(conf_key_defaults(keys, 4, &t, why, sizeof why), "defaults: %s", why);
    CHECK(t.port == 80 && t.on && t.wait_ms == 0 && t.period_ms == 500, "defaults set");
    CHECK_EQ_STR(conf_key_bounds(&keys[0], why, sizeof why), "1..65535");
    CHECK_EQ_STR(conf_key_bounds(&keys[1], why, sizeof why), "");
    CHECK_EQ_STR(conf_key_bounds(&keys[2], why, sizeof why), "1 ms..1 s");
    CHECK_EQ_STR(conf_key_bounds(&keys[3], why, sizeof why), "1..1000");
    {
        char *text = NULL;
        size_t size = 0;
        FILE *out = open_memstream(&text, &size);
        conf_key_print(out, "x", keys, 3);
        fclose(out);
        CHECK_EQ_STR(text, "x\tport\tN\t80\t1..65535\ta port\n"
                           "x\ton\tyes|no\tyes\t-\t-\n"
                           "x\twait\tDURATION\t(required)\t1 ms..1 s\ta wait\n");
        free(text);
    }
}

/* Every table's defaults parse (a bug otherwise), and a file that sets
 * nothing gets them: the loader applies the table, the one source. */
static void test_table_defaults(void)
{
    static const char text[] = "[robot a]\nhost = h\n";
    char *messages = NULL;
    gw_config cfg;
    CHECK_ERRORS(load(text, strlen(text), &messages, &cfg), 0);
    CHECK_EQ_STR(messages, "");
    if (cfg.robot_count == 1) {
        const gw_robot_config *r = &cfg.robots[0];
        CHECK_EQ_INT(r->link.silence_timeout_ms, URRT_LINK_SILENCE_TIMEOUT_MS);
        CHECK(r->port == 30003 && r->link.connect_timeout_ms == 2000 && r->link.backoff_initial_ms == 100 &&
                  r->link.backoff_max_ms == 5000 && r->expected_length == 0 && strcmp(r->expected, "auto") == 0,
              "robot defaults");
    }
    CHECK(cfg.log_level == URRT_LOG_NOTICE && !cfg.summary, "[gateway] defaults");
    CHECK_EQ_STR(cfg.lcm.url, GW_DEFAULT_LCM_URL);
    CHECK_EQ_STR(cfg.lcm.channel[GW_KIND_GATEWAY], "GATEWAY");
    CHECK(cfg.lcm.rate[GW_KIND_STATE].mode == GW_RATE_EVERY && cfg.lcm.rate[GW_KIND_STATUS].hz == 10 &&
              cfg.lcm.rate[GW_KIND_GATEWAY].hz == 1 && cfg.lcm.channel_line[GW_KIND_STATE] == 0,
          "[lcm] defaults");
    CHECK(cfg.can.bitrate == 500000 && cfg.can.max_load_percent == 50 && cfg.can.hb_period_ms == 100 &&
              cfg.can.stale_after_ms == 100 && cfg.can.generation == URRT_GEN_3X &&
              strcmp(cfg.can.node, "URRT_GATEWAY") == 0 && strcmp(cfg.can.receiver, "Vector__XXX") == 0,
          "[can] defaults");
    CHECK(cfg.can_run == NULL, "no CAN output: no tables");
    gw_config_free(&cfg);
    free(messages);
}

/* The CAN tables are built with the file: --check-config proves they
 * build, and a frame's defaults come from its table. */
static void test_tables_built(void)
{
    static const char text[] = "[robot a]\nhost = h\n" CAN_TEXT FRAME_TEXT;
    char *messages = NULL;
    gw_config cfg;
    CHECK_ERRORS(load(text, strlen(text), &messages, &cfg), 0);
    CHECK_EQ_STR(messages, "");
    CHECK(cfg.can_run != NULL && can_run_heartbeat_index(cfg.can_run) == 1, "tables built with the file");
    if (cfg.can.frame_count == 1) {
        CHECK(cfg.can.frames[0].len == 8 && cfg.can.frames[0].stale_policy == CAN_MAP_STALE_STOP &&
                  cfg.can.frames[0].stale_after_ms == 100,
              "frame defaults");
    }
    gw_config_free(&cfg);
    free(messages);
}

/* The reader: each line read once, as libinih read it before (a ':' for
 * '=', comments after a blank, a byte order mark, "\r\n" ends), and its
 * own messages. */
static void test_reader(void)
{
    static const struct { const char *text; const char *want; } cases[] = {
        {"\xEF\xBB\xBF[robot a]\r\nhost: h ; the arm\r\nport = 30013# not a comment\r\n",
         "t.ini:3: port must be a whole number from 1 to 65535, not \"30013# not a comment\"\n"},
        {"host = h\n[robot a]\nhost = h\n",
         "t.ini:1: \"host\" is outside of any section: put it under [gateway], [lcm] or [robot NAME]\n"},
        {"[robot a]\nhost = h\nport ;30013 = 1\n",
         "t.ini:3: expected \"[section]\" or \"key = value\", not \"port ;30013 = 1\"\n"},
        {"[robot a]\nhost = h\nport = 1\nport = 2\n", "t.ini:4: port is set again (first at line 3)\n"},
        {"[robot a\nhost = h\n",
         "t.ini:1: section header without ']'\n"
         "t.ini:2: \"host\" is outside of any section: put it under [gateway], [lcm] or [robot NAME]\n"
         "t.ini: no robot: edit t.ini and add a section \"[robot NAME]\" with \"host = ADDRESS\" (the installed "
         "file has one commented out)\n"},
        {"[robot a]\nhost =\n", "t.ini:2: host has no value\nt.ini:1: [robot a] has no host: add \"host = ADDRESS\"\n"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char *messages = NULL;
        load_str(cases[k].text, &messages);
        CHECK(strcmp(messages, cases[k].want) == 0, "case %zu:\n  got:  %s  want: %s", k, messages, cases[k].want);
        free(messages);
    }
    /* 198 characters before the line's end, "\r\n" or "\n", and no more. */
    for (int crlf = 0; crlf < 2; crlf++) {
        char text[512];
        char *messages = NULL;
        int n = snprintf(text, sizeof text, "[robot a]\nhost = h\n#");
        memset(text + n, 'x', 197);
        snprintf(text + n + 197, sizeof text - (size_t)n - 197, "%s", crlf ? "\r\n" : "\n");
        CHECK_ERRORS(load_str(text, &messages), 0);
        free(messages);
        snprintf(text + n + 197, sizeof text - (size_t)n - 197, "y%s", crlf ? "\r\n" : "\n");
        CHECK_ERRORS(load_str(text, &messages), 1);
        CHECK_EQ_STR(messages, "t.ini:3: line longer than 198 characters\n");
        free(messages);
    }
}

/* Causes first: a typo'd key or section before what it then lacks. */
static void test_causes_first(void)
{
    static const struct { const char *text; const char *want; } cases[] = {
        {"[robot arm1]\nport = 30003\nhots = 127.0.0.1\n",
         "t.ini:3: unknown key \"hots\" in [robot arm1]: did you mean \"host\"? (keys: host, port, source, "
         "rtde_frequency, rtde_values, version, connect_timeout, silence_timeout, backoff_initial, backoff_max)\n"
         "t.ini:1: [robot arm1] has no host: add \"host = ADDRESS\"\n"},
        {"[lcm]\nstate_rate = 10 Hz\n[robto arm1]\nhost = h\n",
         "t.ini:3: unknown section [robto arm1]: did you mean [robot NAME]? (sections: [gateway], [robot NAME], "
         "[lcm], [can], [frame NAME], [input NAME], [canopen])\n"
         "t.ini: no robot: edit t.ini and add a section \"[robot NAME]\" with \"host = ADDRESS\" (the installed "
         "file has one commented out)\n"},
        {"[robot a]\nhost = h\n" CAN_TEXT "[frame f]\nid = 0x100\nperoid_ms = 10\nsignal = time @0|8 intel unsigned\n",
         "t.ini:8: unknown key \"peroid_ms\" in [frame f]: did you mean \"period_ms\"? (keys: id, extended, fd, "
         "length, period_ms, robot, alive_counter, validity_bit, stale_after_ms, stale_policy, comment, signal)\n"
         "t.ini:6: [frame f] has no period_ms (milliseconds, or every)\n"},
        {"[gateway]\nverbose = 1\n[robot a]\nhost = h\n",
         "t.ini:2: unknown key \"verbose\" in [gateway] (keys: log_level, summary, metrics_file, "
         "metrics_interval)\n"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char *messages = NULL;
        load_str(cases[k].text, &messages);
        CHECK(strcmp(messages, cases[k].want) == 0, "case %zu:\n  got:  %s  want: %s", k, messages, cases[k].want);
        free(messages);
    }
}

/* A misspelled value name gets the nearest name of both of lib's tables (the
 * RealTime fields and the RTDE variables, each index of a family a name),
 * or a family's range: one short line, never a list of names. The same
 * conf_suggest_value serves urrt-dump's -k (check-tools, check-dump-rtde). */
static void test_value_names(void)
{
#define RTDE_ROBOT "[robot a]\nhost = h\nsource = rtde\nrtde_values = "
    static const struct { const char *value; const char *want; } cases[] = {
        {"robot_status_bit", "t.ini:4: rtde_values: \"robot_status_bit\" is no RTDE output: did you mean "
                             "\"robot_status_bits\"?\n"},
        {"safety_status_bits, outptu_int_register_24", "t.ini:4: rtde_values: \"outptu_int_register_24\" is no "
                                                       "RTDE output: did you mean \"output_int_register_24\"?\n"},
        {"Robot_Status_Bits", "t.ini:4: rtde_values: \"Robot_Status_Bits\" is no RTDE output: did you mean "
                              "\"robot_status_bits\"?\n"},
        {"output_bit_register_3", "t.ini:4: rtde_values: \"output_bit_register_3\" is no RTDE output: did you mean "
                                  "one of output_bit_register_64 to output_bit_register_127?\n"},
        {"input_int_register_48", "t.ini:4: rtde_values: \"input_int_register_48\" is no RTDE output: did you mean "
                                  "one of input_int_register_0 to input_int_register_47?\n"},
        {"output_int_register_05", "t.ini:4: rtde_values: \"output_int_register_05\" is no RTDE output: did you "
                                   "mean \"output_int_register_5\"?\n"},
        {"q_actual", "t.ini:4: rtde_values: \"q_actual\" is a RealTime field: it is published on NAME.STATE "
                     "already; list only RTDE-only values here, by their RTDE names\n"},
        {"colour", "t.ini:4: rtde_values: \"colour\" is no RTDE output (names are case-sensitive, e.g. "
                   "output_int_register_24, safety_status_bits; docs/rtde.md lists them)\n"},
    };
    static const struct { const char *word; const char *want; } near[] = {
        {"q_actul", "\"q_actual\""},                   /* RealTime's table */
        {"actual_TCP_pos", "\"actual_TCP_pose\""},     /* RTDE's, a mapped name */
        {"tool_analog_input", "one of tool_analog_input0 to tool_analog_input1"},
        {"output_int_register", "one of output_int_register_0 to output_int_register_47"},
        {"output_bit_registers0_to_3", "\"output_bit_registers0_to_31\""},
        {"xyz", NULL},
        {"o", NULL},
    };
    char buf[128];
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char text[256];
        char *messages = NULL;
        snprintf(text, sizeof text, RTDE_ROBOT "%s\n", cases[k].value);
        CHECK_ERRORS(load_str(text, &messages), 1);
        CHECK(strcmp(messages, cases[k].want) == 0, "rtde_values = %s:\n  got:  %s  want: %s", cases[k].value,
              messages, cases[k].want);
        CHECK(strchr(messages, '\n') == messages + strlen(messages) - 1 && strlen(messages) < 200,
              "rtde_values = %s: one short line, no list of names: %s", cases[k].value, messages);
        free(messages);
    }
    for (size_t k = 0; k < sizeof near / sizeof near[0]; k++) {
        const char *got = conf_suggest_value(near[k].word, strlen(near[k].word), buf, sizeof buf);
        CHECK(near[k].want != NULL ? got == buf && strcmp(buf, near[k].want) == 0 : got == NULL && buf[0] == '\0',
              "conf_suggest_value(%s): got %s, want %s", near[k].word, buf, near[k].want ? near[k].want : "none");
    }
    /* Not NUL-terminated: len bytes only ("robot_status_bit" of a longer text). */
    CHECK(conf_suggest_value("robot_status_bit,x", 16, buf, sizeof buf) == buf &&
              strcmp(buf, "\"robot_status_bits\"") == 0, "a word inside a list: %s", buf);
#undef RTDE_ROBOT
}

int main(void)
{
    test_stream_and_file();
    test_valid_file_no_messages();
    test_control_characters_escaped();
    test_nul_byte();
    test_control_characters_refused();
    test_long_robot_name();
    test_header_after_form_feed();
    test_text_after_header();
    test_integers();
    test_numbers_and_booleans();
    test_durations();
    test_rates();
    test_names_and_text();
    test_same_everywhere();
    test_refusals();
    test_key_table();
    test_table_defaults();
    test_tables_built();
    test_reader();
    test_causes_first();
    test_value_names();
    return check_report();
}
