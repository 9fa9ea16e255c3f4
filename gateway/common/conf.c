/* SPDX-License-Identifier: MIT */
/* conf.c: one parser per kind of value, and keys by tables (see conf.h). */
#define _GNU_SOURCE
#include "conf.h"

#include "urrt.h"
#include "urrt_rtde.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

bool conf_fail(char *why, size_t n, const char *fmt, ...)
{
    va_list ap;
    if (why != NULL && n > 0) {
        va_start(ap, fmt);
        vsnprintf(why, n, fmt, ap);
        va_end(ap);
    }
    return false;
}

static bool all_digits(const char *s, int base)
{
    if (*s == '\0') {
        return false;
    }
    for (; *s != '\0'; s++) {
        if (base == 16 ? !isxdigit((unsigned char)*s) : !isdigit((unsigned char)*s)) {
            return false;
        }
    }
    return true;
}

/* "0100": C's octal. Say what each reading would be written as. */
static bool leading_zero(const char *text, char *why, size_t n)
{
    const char *decimal = text + strspn(text, "0");
    if (*decimal == '\0') {
        decimal = "0";
    }
    if (strspn(text, "01234567") == strlen(text) && strlen(text) <= 22) {
        return conf_fail(why, n, CONF_LEADING_ZERO " (write 0x%llX for hexadecimal or %s for decimal)",
                   strtoull(text, NULL, 8), decimal);
    }
    return conf_fail(why, n, CONF_LEADING_ZERO " (write %s)", decimal);
}

bool conf_uint(const char *text, uint64_t min, uint64_t max, uint64_t *out, char *why, size_t n)
{
    const char *digits = text;
    int base = 10;
    unsigned long long v;
    if (text == NULL || text[0] == '\0') {
        return conf_fail(why, n, "no value");
    }
    if (text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
        base = 16;
        digits = text + 2;
    }
    if (!all_digits(digits, base)) {
        return conf_fail(why, n, "not a whole number (decimal, or hexadecimal with 0x)");
    }
    if (base == 10 && text[0] == '0' && text[1] != '\0') {
        return leading_zero(text, why, n);
    }
    errno = 0;
    v = strtoull(digits, NULL, base);
    if (errno == ERANGE || v < min || v > max) {
        return conf_fail(why, n, "out of range: from %llu to %llu", (unsigned long long)min, (unsigned long long)max);
    }
    *out = v;
    return true;
}

bool conf_u32(const char *text, uint32_t min, uint32_t max, uint32_t *out, char *why, size_t n)
{
    uint64_t v;
    if (!conf_uint(text, min, max, &v, why, n)) {
        return false;
    }
    *out = (uint32_t)v;
    return true;
}

bool conf_int(const char *text, int64_t min, int64_t max, int64_t *out, char *why, size_t n)
{
    bool negative = text != NULL && text[0] == '-';
    char reason[CONF_WHY_MAX];
    uint64_t magnitude;
    int64_t v;
    if (!conf_uint(negative ? text + 1 : text, 0, UINT64_MAX, &magnitude, reason, sizeof reason)) {
        if (strncmp(reason, "out of range", 12) != 0) {
            return conf_fail(why, n, "%s", reason);
        }
        magnitude = UINT64_MAX; /* reported below with this range */
    }
    if (negative) {
        v = magnitude > (uint64_t)INT64_MAX ? INT64_MIN : -(int64_t)magnitude;
    } else {
        v = magnitude > (uint64_t)INT64_MAX ? INT64_MAX : (int64_t)magnitude;
    }
    if ((negative && magnitude > (uint64_t)INT64_MAX + 1) || (!negative && magnitude > (uint64_t)INT64_MAX) ||
        v < min || v > max) {
        return conf_fail(why, n, "out of range: from %lld to %lld", (long long)min, (long long)max);
    }
    *out = v;
    return true;
}

/* Digits, one '.', an exponent: what a person writes, not C's hex floats,
 * "inf" or "nan". rest receives what follows (NULL: nothing may). */
static bool parse_decimal(const char *text, double *out, const char **rest)
{
    char *end;
    const char *p = text + (text[0] == '-' || text[0] == '+');
    if (!isdigit((unsigned char)p[0]) && !(p[0] == '.' && isdigit((unsigned char)p[1]))) {
        return false;
    }
    if (p[0] == '0' && (p[1] == 'x' || p[1] == 'X')) {
        return false;
    }
    errno = 0;
    *out = strtod(text, &end);
    if (end == text || !isfinite(*out) || (errno == ERANGE && fabs(*out) > 1.0)) {
        return false;
    }
    if (rest == NULL) {
        return *end == '\0';
    }
    *rest = end;
    return true;
}

bool conf_number(const char *text, double min, double max, double *out, char *why, size_t n)
{
    double v;
    if (text == NULL || text[0] == '\0') {
        return conf_fail(why, n, "no value");
    }
    if (!parse_decimal(text, &v, NULL)) {
        return conf_fail(why, n, "not a number (write it in decimal, e.g. 2.5)");
    }
    if (v < min || v > max) {
        return conf_fail(why, n, "out of range: from %g to %g", min, max);
    }
    *out = v;
    return true;
}

bool conf_bool(const char *text, bool *out, char *why, size_t n)
{
    static const char *const words[][2] = {{"yes", "no"}, {"true", "false"}, {"on", "off"}, {"1", "0"}};
    for (size_t i = 0; text != NULL && i < sizeof words / sizeof words[0]; i++) {
        for (int v = 0; v < 2; v++) {
            if (strcasecmp(text, words[i][v]) == 0) {
                *out = v == 0;
                return true;
            }
        }
    }
    return conf_fail(why, n, "use yes or no (or true/false, on/off, 1/0)");
}

/* ---- durations ----------------------------------------------------------------- */

static const struct { const char *name; double us; } units[] = {
    {"us", 1.0}, {"ms", 1e3}, {"s", 1e6}, {"min", 60e6},
};

/* "20 ms", "600 s", "10 min": the largest unit that makes a whole number. */
static const char *format_duration(uint64_t us, char *buf, size_t size)
{
    size_t u = sizeof units / sizeof units[0];
    while (--u > 0 && (us == 0 || us % (uint64_t)units[u].us != 0)) {
    }
    snprintf(buf, size, "%llu %s", (unsigned long long)(us / (uint64_t)units[u].us), units[u].name);
    return buf;
}

static bool unit_scale(const char *unit, double *scale)
{
    for (size_t u = 0; u < sizeof units / sizeof units[0]; u++) {
        if (strcmp(unit, units[u].name) == 0) {
            *scale = units[u].us;
            return true;
        }
    }
    return false;
}

bool conf_duration_us(const char *text, const char *bare_unit, uint64_t min_us, uint64_t max_us, uint64_t *out,
                      char *why, size_t n)
{
    double v, scale, us;
    const char *unit;
    char lo[32], hi[32];
    if (text == NULL || text[0] == '\0') {
        return conf_fail(why, n, "no value");
    }
    if (text[0] == '-' || text[0] == '+' || !parse_decimal(text, &v, &unit)) {
        return conf_fail(why, n, "not a duration: a number with a unit (us, ms, s or min), e.g. \"250 ms\" or \"1.5 s\"");
    }
    unit += strspn(unit, " \t");
    if (unit[0] == '\0' && bare_unit == NULL) {
        return conf_fail(why, n, "a duration is written with a unit (us, ms, s or min), e.g. \"%s ms\" or \"%s s\"", text,
                   text);
    }
    if (!unit_scale(unit[0] == '\0' ? bare_unit : unit, &scale)) {
        return conf_fail(why, n, "unknown unit \"%s\": write us, ms, s or min", unit);
    }
    us = v * scale;
    if (us < (double)min_us - 1e-6 || us > (double)max_us + 1e-6) {
        return conf_fail(why, n, "out of range: from %s to %s", format_duration(min_us, lo, sizeof lo),
                   format_duration(max_us, hi, sizeof hi));
    }
    if (fabs(us - nearbyint(us)) > 1e-6 * (us > 1 ? us : 1)) {
        return conf_fail(why, n, "finer than a microsecond");
    }
    *out = (uint64_t)nearbyint(us);
    return true;
}

bool conf_duration_ms(const char *text, const char *bare_unit, uint32_t min_ms, uint32_t max_ms, uint32_t *out,
                      char *why, size_t n)
{
    uint64_t us;
    if (!conf_duration_us(text, bare_unit, (uint64_t)min_ms * 1000u, (uint64_t)max_ms * 1000u, &us, why, n)) {
        return false;
    }
    if (us % 1000u != 0) {
        return conf_fail(why, n, "not a whole number of milliseconds");
    }
    *out = (uint32_t)(us / 1000u);
    return true;
}

const char *conf_bare_unit(const char *key)
{
    static const char *const suffixes[] = {"_us", "_ms", "_s"};
    size_t len = strlen(key);
    for (size_t i = 0; i < sizeof suffixes / sizeof suffixes[0]; i++) {
        size_t sl = strlen(suffixes[i]);
        if (len > sl && strcmp(key + len - sl, suffixes[i]) == 0) {
            return suffixes[i] + 1;
        }
    }
    return NULL;
}

/* ---- rates ---------------------------------------------------------------------- */

bool conf_rate_hz(const char *text, double min, double max, double *out, char *why, size_t n)
{
    double v;
    const char *unit;
    if (text == NULL || text[0] == '\0') {
        return conf_fail(why, n, "no value");
    }
    if (text[0] == '-' || text[0] == '+' || !parse_decimal(text, &v, &unit)) {
        return conf_fail(why, n, "not a rate: a number of Hz, e.g. \"50 Hz\" (or 50)");
    }
    unit += strspn(unit, " \t");
    if (unit[0] != '\0' && strcmp(unit, "Hz") != 0) {
        return conf_fail(why, n, "unknown unit \"%s\": a rate is in Hz, e.g. \"50 Hz\" (or 50)", unit);
    }
    if (v < min || v > max) {
        return conf_fail(why, n, "out of range: from %g Hz to %g Hz", min, max);
    }
    *out = v;
    return true;
}

/* ---- names and text ------------------------------------------------------------ */

bool conf_name(const char *text, unsigned flags, size_t max, char *why, size_t n)
{
    size_t len = strlen(text);
    bool ok = len >= 1 && len <= max;
    if (flags & CONF_NAME_C) {
        ok = ok && (isalpha((unsigned char)text[0]) || text[0] == '_');
    }
    for (size_t i = 0; ok && i < len; i++) {
        unsigned char c = (unsigned char)text[i];
        ok = isalnum(c) || c == '_' || ((flags & CONF_NAME_DASH) && c == '-') ||
             ((flags & CONF_NAME_DOTS) && c == '.' && i > 0 && i + 1 < len);
    }
    if (ok) {
        return true;
    }
    if (flags & CONF_NAME_C) {
        return conf_fail(why, n, "is not a C identifier of at most %zu characters", max);
    }
    return conf_fail(why, n, "must be 1 to %zu letters, digits, '_'%s%s", max, (flags & CONF_NAME_DASH) ? " or '-'" : "",
               (flags & CONF_NAME_DOTS) ? " (or '.' inside)" : "");
}

bool conf_printable(const char *text, char *why, size_t n)
{
    for (const char *c = text; *c != '\0'; c++) {
        if ((unsigned char)*c < 0x20 || *c == 0x7f) {
            return conf_fail(why, n, "no control characters");
        }
    }
    return true;
}

bool conf_text(char *dst, size_t size, const char *text, char *why, size_t n)
{
    size_t len = strlen(text);
    if (len >= 2 && text[0] == '"' && text[len - 1] == '"') {
        text++;
        len -= 2;
    }
    if (len >= size || memchr(text, '"', len) != NULL || memchr(text, '\\', len) != NULL ||
        !conf_printable(text, NULL, 0)) {
        return conf_fail(why, n, "at most %zu characters, no '\"', '\\' or control characters", size - 1);
    }
    memcpy(dst, text, len);
    dst[len] = '\0';
    return true;
}

/* ---- keys ------------------------------------------------------------------------ */

const struct conf_key *conf_key_find(const struct conf_key *keys, size_t count, const char *name)
{
    for (size_t i = 0; i < count; i++) {
        if (strcmp(keys[i].name, name) == 0) {
            return &keys[i];
        }
    }
    return NULL;
}

static void store_uint(void *field, size_t size, uint64_t v)
{
    switch (size) {
    case 1: *(uint8_t *)field = (uint8_t)v; break;
    case 2: *(uint16_t *)field = (uint16_t)v; break;
    case 4: *(uint32_t *)field = (uint32_t)v; break;
    default: *(uint64_t *)field = v; break;
    }
}

bool conf_key_set(const struct conf_key *key, void *obj, const char *value, struct conf_at at, char *why, size_t n)
{
    char reason[CONF_WHY_MAX];
    void *field = (char *)obj + key->offset;
    uint64_t v = 0;
    bool ok;
    if ((key->kind == CONF_BOOL && key->size != sizeof(bool)) || (key->kind == CONF_MS && key->size != 4) ||
        (key->kind == CONF_UINT && key->size != 1 && key->size != 2 && key->size != 4 && key->size != 8)) {
        return conf_fail(why, n, "%s: the table gives a field of %zu bytes (a bug)", key->name, key->size);
    }
    switch (key->kind) {
    case CONF_UINT: ok = conf_uint(value, key->min, key->max, &v, reason, sizeof reason); break;
    case CONF_BOOL: ok = conf_bool(value, (bool *)field, reason, sizeof reason); break;
    case CONF_MS:
        ok = conf_duration_ms(value, conf_bare_unit(key->name), (uint32_t)key->min, (uint32_t)key->max,
                              (uint32_t *)field, reason, sizeof reason);
        break;
    default: return key->set(obj, key, value, at, why, n);
    }
    if (ok) {
        if (key->kind == CONF_UINT) {
            store_uint(field, key->size, v);
        }
        return true;
    }
    if (key->hint != NULL && !CONF_IS_LEADING_ZERO(reason)) {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
        snprintf(why, n, key->hint, key->name, value);
#pragma GCC diagnostic pop
        return false;
    }
    return conf_fail(why, n, "%s = \"%s\": %s", key->name, value, reason);
}

/* Levenshtein distance, for names of up to 63 characters; fold: letters
 * that differ only in case are the same. */
static size_t distance(const char *a, const char *b, bool fold)
{
    size_t la = strlen(a), lb = strlen(b);
    size_t row[64];
    if (la >= 64 || lb >= 64) {
        return SIZE_MAX;
    }
    for (size_t j = 0; j <= lb; j++) {
        row[j] = j;
    }
    for (size_t i = 1; i <= la; i++) {
        size_t diag = row[0];
        row[0] = i;
        for (size_t j = 1; j <= lb; j++) {
            size_t up = row[j];
            unsigned char ca = (unsigned char)a[i - 1], cb = (unsigned char)b[j - 1];
            size_t best = diag + (fold ? tolower(ca) != tolower(cb) : ca != cb);
            best = up + 1 < best ? up + 1 : best;
            best = row[j - 1] + 1 < best ? row[j - 1] + 1 : best;
            diag = up;
            row[j] = best;
        }
    }
    return row[lb];
}

/* The rule of every "did you mean": at most two edits away, fewer edits
 * than the word has letters, and nearer than the best so far. */
#define SUGGEST_EDITS 2
static bool nearer(size_t d, size_t best_d, size_t word_len)
{
    return d <= SUGGEST_EDITS && d < word_len && d < best_d;
}

const char *conf_suggest(const char *word, const void *table, size_t count, size_t stride)
{
    const char *best = NULL;
    size_t best_d = SIZE_MAX;
    for (size_t i = 0; i < count; i++) {
        const char *name = *(const char *const *)(const void *)((const char *)table + i * stride);
        size_t d = distance(word, name, false);
        if (nearer(d, best_d, strlen(word))) {
            best = name;
            best_d = d;
        }
    }
    return best;
}

/* The families of lib's RTDE table (its rows of several names): name
 * followed by an index from first to first + names - 1. */
static const struct {
    const char *stem;
    int first, names;
} rtde_families[] = {
#define CONF_X_FAMILY(ID, member, name, TYPE, first, names, split, since, since_hi) {name, first, names},
    URRT_RTDE_ONLY(CONF_X_FAMILY)
#undef CONF_X_FAMILY
};

const char *conf_suggest_value(const char *word, size_t len, char *buf, size_t size)
{
    char w[64], name[64];
    size_t best_d = SIZE_MAX, stem_len = len;
    long index = -1;
    if (buf == NULL || size == 0) {
        return NULL;
    }
    buf[0] = '\0';
    if (word == NULL || len >= sizeof w) {
        return NULL;
    }
    memcpy(w, word, len);
    w[len] = '\0';
    /* Every name of both tables: RealTime's fields, then RTDE's variables,
     * each index of a family its own name (output_int_register_24). */
    for (int i = 0; i < (int)URRT_FIELD_COUNT + (int)URRT_RTDE_VAR_COUNT; i++) {
        const char *cand = name;
        size_t d;
        if (i < (int)URRT_FIELD_COUNT) {
            cand = urrt_field((urrt_field_id)i)->name;
        } else if (urrt_rtde_var_name(i - (int)URRT_FIELD_COUNT, name, sizeof name) < 0) {
            continue;
        }
        d = distance(w, cand, true);
        if (strcmp(w, cand) != 0 && nearer(d, best_d, len)) {
            best_d = d;
            snprintf(buf, size, "\"%s\"", cand);
        }
    }
    /* A family's name and an index it has, the number written otherwise
     * (output_int_register_05: output_int_register_5); without an index, or
     * with one the family does not have (output_bit_register_3): the
     * family's range. Either when nearer than any name above. */
    while (stem_len > 0 && isdigit((unsigned char)w[stem_len - 1])) {
        stem_len--;
    }
    if (stem_len < len && len - stem_len <= 9) {
        index = strtol(w + stem_len, NULL, 10);
    }
    w[stem_len] = '\0';
    for (size_t f = 0; f < sizeof rtde_families / sizeof rtde_families[0]; f++) {
        int first = rtde_families[f].first, last = first + rtde_families[f].names - 1;
        size_t d = distance(w, rtde_families[f].stem, true);
        if (rtde_families[f].names == 1 || !nearer(d, best_d, len)) {
            continue;
        }
        if (index >= first && index <= last) {
            snprintf(name, sizeof name, "%s%ld", rtde_families[f].stem, index);
            if (strncmp(word, name, len) == 0 && name[len] == '\0') {
                continue;
            }
            snprintf(buf, size, "\"%s\"", name);
        } else {
            snprintf(buf, size, "one of %s%d to %s%d", rtde_families[f].stem, first, rtde_families[f].stem, last);
        }
        best_d = d;
    }
    return buf[0] != '\0' ? buf : NULL;
}

void conf_unknown_key(const struct conf_key *keys, size_t count, const char *key, const char *section, char *why,
                      size_t n)
{
    const char *near = conf_suggest(key, keys, count, sizeof *keys);
    size_t used = 0;
    if (near != NULL) {
        snprintf(why, n, "unknown key \"%s\" in [%s]: did you mean \"%s\"? (keys: ", key, section, near);
    } else {
        snprintf(why, n, "unknown key \"%s\" in [%s] (keys: ", key, section);
    }
    for (size_t i = 0; i <= count; i++) {
        used = strnlen(why, n);
        snprintf(why + used, n - used, "%s%s", i == 0 ? "" : i < count ? ", " : ")", i < count ? keys[i].name : "");
    }
}

/* ---- what a table says about its keys -------------------------------------------- */

bool conf_key_defaults(const struct conf_key *keys, size_t count, void *obj, char *why, size_t n)
{
    char reason[CONF_WHY_MAX];
    for (size_t i = 0; i < count; i++) {
        if (keys[i].def != NULL && !conf_key_set(&keys[i], obj, keys[i].def, (struct conf_at){NULL, 0}, reason,
                                                 sizeof reason)) {
            return conf_fail(why, n, "the default of %s does not parse (a bug): %s", keys[i].name, reason);
        }
    }
    return true;
}

const char *conf_key_bounds(const struct conf_key *key, char *buf, size_t size)
{
    char lo[32], hi[32];
    buf[0] = '\0';
    /* 0 to the field's own limit is no bound worth saying (a CAN id's 32 bits). */
    if (key->kind == CONF_BOOL || key->max == 0 || (key->min == 0 && key->max >= UINT32_MAX)) {
        return buf;
    }
    if (key->kind == CONF_MS && conf_bare_unit(key->name) == NULL) {
        snprintf(buf, size, "%s..%s", format_duration(key->min * 1000u, lo, sizeof lo),
                 format_duration(key->max * 1000u, hi, sizeof hi));
    } else {
        snprintf(buf, size, "%llu..%llu", (unsigned long long)key->min, (unsigned long long)key->max);
    }
    return buf;
}

static const char *key_form(const struct conf_key *key)
{
    if (key->form != NULL) {
        return key->form;
    }
    switch (key->kind) {
    case CONF_UINT: return "N";
    case CONF_BOOL: return "yes|no";
    case CONF_MS: return "DURATION";
    default: return "VALUE";
    }
}

void conf_key_print(FILE *out, const char *section, const struct conf_key *keys, size_t count)
{
    char bounds[80];
    for (size_t i = 0; i < count; i++) {
        const struct conf_key *k = &keys[i];
        conf_key_bounds(k, bounds, sizeof bounds);
        fprintf(out, "%s\t%s\t%s\t%s%s%s\t%s\t%s\n", section, k->name, key_form(k), k->def ? k->def : "(",
                k->def ? "" : k->absent ? k->absent : "none", k->def ? "" : ")", bounds[0] ? bounds : "-",
                k->help ? k->help : "-");
    }
}

void conf_key_usage(FILE *out, const struct conf_key *keys, size_t count)
{
    char bounds[80], left[64];
    for (size_t i = 0; i < count; i++) {
        const struct conf_key *k = &keys[i];
        conf_key_bounds(k, bounds, sizeof bounds);
        snprintf(left, sizeof left, "%s = %s", k->name, key_form(k));
        fprintf(out, "  %-30s (%s%s%s%s)\n      %s\n", left, k->def ? "default " : "",
                k->def ? k->def : k->absent ? k->absent : "none", bounds[0] ? "; " : "", bounds,
                k->help ? k->help : "");
    }
}
