/* SPDX-License-Identifier: MIT */
/*
 * conf.h: the one front end of the configuration language and of the
 * command lines: one parser per kind of value, and keys described by tables.
 * A value means the same in every section of the gateway's file and on
 * every command line (urrt-dump, urrt-sim).
 *
 * The grammar, once (gateway/man/urrt-gateway.ini.5.md says it to users):
 *   integer   decimal (385) or hexadecimal with 0x (0x181); no sign. A
 *             leading zero (0100) is refused: C would read it as octal.
 *   number    decimal with an optional fraction and exponent (0.001, 1e-3).
 *   boolean   yes/no, true/false, on/off, 1/0, in any case.
 *   duration  a number and a unit: us, ms, s or min ("250 ms", "1.5s").
 *             A bare number only where the key's name carries the unit
 *             (stale_after_ms = 100), and it means that unit.
 *   rate      a number of Hz, the unit optional ("50 Hz", "50Hz" and "50"
 *             are the same rate): the one unit of a rate, so that a bare
 *             number means Hz wherever a rate is given.
 *   name      1 to N letters, digits and '_' (and '-' or '.' where said);
 *             a C identifier where the name becomes a DBC name.
 *   text      any printable text, one pair of double quotes dropped.
 *
 * Every parser returns true with the value in *out, or false with the
 * reason in why (without the key: "a leading zero is not allowed (write
 * 0x40 for hexadecimal or 100 for decimal)"), for the caller to say where.
 */
#ifndef URRT_GATEWAY_CONF_H
#define URRT_GATEWAY_CONF_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define CONF_WHY_MAX 512 /* room for any reason these functions write */
/* How the reason for a leading zero begins: a message that replaces the
 * parser's reason with its own words keeps this one, which says what to write. */
#define CONF_LEADING_ZERO "a leading zero is not allowed"
#define CONF_IS_LEADING_ZERO(why) (strncmp((why), CONF_LEADING_ZERO, sizeof CONF_LEADING_ZERO - 1) == 0)

/* Writes a reason into why (n bytes); false, for "return conf_fail(...)". */
bool conf_fail(char *why, size_t n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

bool conf_uint(const char *text, uint64_t min, uint64_t max, uint64_t *out, char *why, size_t n);
bool conf_u32(const char *text, uint32_t min, uint32_t max, uint32_t *out, char *why, size_t n);
/* An integer with an optional '-'. */
bool conf_int(const char *text, int64_t min, int64_t max, int64_t *out, char *why, size_t n);
/* A finite decimal number. */
bool conf_number(const char *text, double min, double max, double *out, char *why, size_t n);
bool conf_bool(const char *text, bool *out, char *why, size_t n);

/* A duration in microseconds. bare_unit: what a number without a unit
 * means ("ms"), or NULL where a unit is required. */
bool conf_duration_us(const char *text, const char *bare_unit, uint64_t min_us, uint64_t max_us, uint64_t *out,
                      char *why, size_t n);
/* The same in whole milliseconds. */
bool conf_duration_ms(const char *text, const char *bare_unit, uint32_t min_ms, uint32_t max_ms, uint32_t *out,
                      char *why, size_t n);
/* The unit a key's name carries: "ms" for "period_ms" ("us", "s"), else NULL. */
const char *conf_bare_unit(const char *key);

/* A rate in Hz in [min, max]: a number, then "Hz" or nothing (a bare number
 * is Hz). No sign: "-5 Hz" is no rate. */
bool conf_rate_hz(const char *text, double min, double max, double *out, char *why, size_t n);

enum conf_name_flags {
    CONF_NAME_DASH = 1, /* '-' allowed */
    CONF_NAME_DOTS = 2, /* '.' allowed inside */
    CONF_NAME_C = 4     /* a C identifier: a letter or '_' first, then letters, digits, '_' */
};
bool conf_name(const char *text, unsigned flags, size_t max, char *why, size_t n);
/* Text without control characters (it is printed and written to files). */
bool conf_printable(const char *text, char *why, size_t n);
/* Text into dst (size bytes with its NUL), one pair of surrounding double
 * quotes dropped; no '"', '\' or control characters inside. */
bool conf_text(char *dst, size_t size, const char *text, char *why, size_t n);

/* ---- keys described by tables ---------------------------------------------------- */

enum conf_kind {
    CONF_FN = 0, /* the key's set function parses the value */
    CONF_UINT,   /* an integer in [min, max] into an unsigned field of size 1, 2, 4 or 8 */
    CONF_BOOL,   /* into a bool field */
    CONF_MS      /* a duration in whole milliseconds in [min, max] into a uint32_t field */
};

/* Where a value comes from, for the messages and for later checks. */
struct conf_at {
    const char *file;
    int line;
};

struct conf_key;
/* Parses value into obj; false with the whole reason in why ("KEY = ..."). */
typedef bool (*conf_set_fn)(void *obj, const struct conf_key *key, const char *value, struct conf_at at, char *why,
                            size_t n);

/*
 * One key: how its value is parsed and everything said about it. The table
 * is the one source of a key's default, bounds and help: the loader applies
 * def, and --help, --print-keys (and through it check-man, against the man
 * page, docs/ and the example configuration) show them.
 */
struct conf_key {
    const char *name;
    enum conf_kind kind;
    size_t offset;     /* of the field in the section's object (not CONF_FN) */
    size_t size;
    /* CONF_UINT; CONF_MS in milliseconds; a CONF_FN key that parses a number
     * may use them too. min == max == 0: no bounds to show. */
    uint64_t min, max;
    conf_set_fn set;   /* CONF_FN */
    /* The message for a bad value other than a leading zero, a printf
     * format taking the key (%1$s) and the value (%2$s); NULL: the parser's
     * reason, as KEY = "VALUE": reason. */
    const char *hint;
    bool many;         /* may appear more than once in a section (a frame's signal lines) */
    const char *form;  /* what a value looks like ("DURATION", "yes|no", "every|N Hz|off") */
    const char *def;   /* the default in the file's grammar, set before the section's keys; NULL: none */
    const char *absent; /* without def: what holds when the key is not given ("required", "the only robot") */
    const char *help;  /* one line: what the key does */
};

/* CONF_FIELD(type, member): the offset and size of a destination. */
#define CONF_FIELD(type, member) offsetof(type, member), sizeof(((type *)0)->member)

/* Sets every key of the table that has a default (def) in obj, as if the
 * file said so: false with the reason (a bug in the table) in why. */
bool conf_key_defaults(const struct conf_key *keys, size_t count, void *obj, char *why, size_t n);
/* The key's bounds as a value of its grammar ("1..65535", "20 ms..10 min",
 * "10..1000" for a key named _ms); "" when it has none. */
const char *conf_key_bounds(const struct conf_key *key, char *buf, size_t size);
/* What --print-keys writes for a table: one line per key, tab-separated:
 * SECTION KEY FORM DEFAULT BOUNDS HELP ("-" for an empty column; DEFAULT is
 * def, or "(absent)" when the key has none). */
void conf_key_print(FILE *out, const char *section, const struct conf_key *keys, size_t count);
/* What --help writes for a table: per key "  KEY = FORM   (default DEF;
 * BOUNDS)" and its help on a line of its own. */
void conf_key_usage(FILE *out, const struct conf_key *keys, size_t count);

const struct conf_key *conf_key_find(const struct conf_key *keys, size_t count, const char *name);
/* Parses value for key into obj: false with the whole reason in why. */
bool conf_key_set(const struct conf_key *key, void *obj, const char *value, struct conf_at at, char *why, size_t n);
/* 'unknown key "hots" in [robot a]: did you mean "host"? (keys: host, port, ...)' */
void conf_unknown_key(const struct conf_key *keys, size_t count, const char *key, const char *section, char *why,
                      size_t n);
/* The "did you mean" hint: of a table of count entries stride bytes apart,
 * each starting with its name (a const char *), the name nearest to word,
 * at most two edits away and fewer than word has letters; NULL if none. */
const char *conf_suggest(const char *word, const void *table, size_t count, size_t stride);
/* The same hint for the name of a value (word, len bytes, that neither table
 * knows as written), over both of lib's tables: every RealTime field
 * (lib/urrt.h) and every RTDE variable (lib/urrt_rtde.h, each index of a
 * family a name: output_int_register_24), letters compared without case;
 * or, nearer still, an RTDE family named without its index or with one it
 * lacks (output_bit_register_3). Writes into buf (size bytes) what follows
 * "did you mean ": "\"robot_status_bits\"" or "one of output_bit_register_64
 * to output_bit_register_127", and returns buf; NULL (buf "") if nothing is
 * near. */
const char *conf_suggest_value(const char *word, size_t len, char *buf, size_t size);

#endif
