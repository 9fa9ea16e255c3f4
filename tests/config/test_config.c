/* SPDX-License-Identifier: MIT */
/*
 * test_config.c: regression tests for what the configuration fuzzer
 * (tests/config/fuzz_config.c) found in the loader, one per finding, with
 * the input it found in tests/config/regressions/ as well. Runs in
 * check-fuzz-config, under ASan + UBSan.
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
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
        "\nt.ini:5: unknown key 'hea\\x02rtbeat_id' in [can] (keys: ",
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

/* Finding 3: a NUL byte in a line longer than libinih's 200-byte buffer
 * hid the line's end from the reader (fgets then strlen), so the rest of
 * the line counted as a line of its own: every later message named a line
 * past the real one, up to lines the file does not have. The reader now
 * counts the bytes it reads, and a NUL byte is an error of its line. */
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
    CHECK_EQ_STR(messages, "t.ini:3: line longer than 197 characters\n"
                           "t.ini:4: port must be a whole number from 1 to 65535, not \"0\"\n"
                           "t.ini:5: a NUL byte: the configuration must be a text file\n");
    CHECK_EQ_STR(cfg.robots[0].expected, "auto");
    gw_config_free(&cfg);
    free(messages);
}

/* Finding 4: an accepted file put control characters into what the
 * gateway prints: the LCM URL of a provider other than udpm (at start and
 * by --check-config). (The CAN side's comment, unit and interface:
 * tests/can/test_can.c.) */
static void test_control_characters_refused(void)
{
    char *messages = NULL;
    CHECK_ERRORS(load_str("[lcm]\nurl = file:///tmp/x\x1b[2J\n[robot a]\nhost = h\n", &messages), 1);
    CHECK_EQ_STR(messages, "t.ini:2: url \"file:///tmp/x\\x1B[2J\": no control characters\n");
    free(messages);
}

/* Finding 5 (found reading the loader while writing the harness, not by
 * the fuzzer): libinih truncates section names to 49 characters, the
 * loader compared its name with the whole header and, on a mismatch,
 * skipped the section's keys silently: a robot named with 44 to 64
 * characters (valid names) was rejected as having no host. */
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
 * section header after spaces and tabs only, libinih after any blank. A
 * header after a form feed was then libinih's section but not the
 * loader's, and when the line also held a '=' (so that the loader did not
 * call it a syntax error) the keys below it were dropped without a word
 * (here port = 0: the file was accepted). */
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
    return check_report();
}
