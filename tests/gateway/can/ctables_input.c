/* SPDX-License-Identifier: MIT */
/*
 * ctables_input: a firmware's receiving side over the [input] tables that
 * urrt-gateway --print-c-tables wrote, for tests/gateway/can/check_dbc_input.py.
 * The tables are included (TABLES, a path), so that this file is compiled
 * with them under lib/'s warnings and sees lib's urrt_plcin_desc type;
 * it uses lib/ alone (urrt_can, urrt_rtde's names), as the tables' comment
 * says a firmware does:
 *
 *   describe     prints each [input]: "INPUT id=0x.. flags=N len=N timeout_ms=N
 *                silence=N value=%.17g robot=N regs=NAME,NAME,..." and per
 *                signal "SIGNAL reg=NAME"
 *   (no argument) reads lines "INDEX HEX" (a payload of [input] INDEX) and
 *                prints per register of its recipe "NAME=VALUE": a mask's
 *                bits gathered from its signals (raw shifted up by the
 *                mask's first bit), any other value urrt_can_unpack'ed,
 *                "refused" outside min..max; "bad" for a payload of another
 *                length
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include TABLES

static void put_name(unsigned var)
{
    char name[URRT_RTDE_NAME_MAX];
    if (urrt_rtde_var_name((int)var, name, sizeof name) < 0) {
        printf("?%u", var);
    } else {
        printf("%s", name);
    }
}

static void describe(void)
{
    for (size_t i = 0; i < urrt_gateway_input_count; i++) {
        const urrt_plcin_desc *in = &urrt_gateway_inputs[i];
        printf("INPUT id=0x%lX flags=%u len=%u timeout_ms=%lu silence=%u value=%.17g robot=%u regs=",
               (unsigned long)in->id, (unsigned)in->flags, (unsigned)in->len, (unsigned long)in->timeout_ms,
               (unsigned)in->silence, in->silence_value, (unsigned)in->robot);
        for (size_t k = 0; k < in->reg_count; k++) {
            if (k > 0) {
                putchar(',');
            }
            put_name(in->regs[k]);
        }
        putchar('\n');
        for (size_t s = 0; s < in->signal_count; s++) {
            printf("SIGNAL reg=");
            put_name(in->vars[s]);
            putchar('\n');
        }
    }
}

/* Register k of input in from payload data, printed as NAME=VALUE. */
static void put_register(const urrt_plcin_desc *in, size_t k, const uint8_t *data)
{
    uint64_t word = 0;
    double value = 0;
    int mask = 0;
    int refused = 0;
    for (size_t s = 0; s < in->signal_count; s++) {
        const urrt_can_signal *sig = &in->signals[s];
        if (in->vars[s] != in->regs[k]) {
            continue;
        }
        if ((sig->flags & URRT_CAN_SIG_BITMASK) != 0u) {
            uint64_t raw = 0;
            mask = 1;
            if (urrt_can_get_raw(sig, data, in->len, &raw) < 0) {
                refused = 1;
            }
            word |= raw << URRT_CAN_SIG_MASK_FIRST(sig->flags);
        } else if (urrt_can_unpack(sig, data, in->len, &value) < 0 || !(value >= sig->min) ||
                   !(value <= sig->max)) {
            refused = 1;
        }
    }
    put_name(in->regs[k]);
    if (refused) {
        printf("=refused");
    } else if (mask) {
        printf("=%llu", (unsigned long long)word);
    } else {
        printf("=%.17g", value);
    }
}

static int decode(void)
{
    char line[512];
    while (fgets(line, sizeof line, stdin) != NULL) {
        char *end;
        unsigned long index = strtoul(line, &end, 10);
        uint8_t data[64];
        size_t len = 0;
        const urrt_plcin_desc *in;
        if (end == line || index >= urrt_gateway_input_count) {
            fprintf(stderr, "ctables_input: bad line %s", line);
            return 1;
        }
        in = &urrt_gateway_inputs[index];
        while (*end == ' ') {
            end++;
        }
        while (len < sizeof data && end[0] != '\0' && end[0] != '\n' && end[1] != '\0') {
            char hex[3] = {end[0], end[1], '\0'};
            data[len++] = (uint8_t)strtoul(hex, NULL, 16);
            end += 2;
        }
        if (len != in->len) {
            printf("bad\n");
            continue;
        }
        for (size_t k = 0; k < in->reg_count; k++) {
            if (k > 0) {
                putchar(' ');
            }
            put_register(in, k, data);
        }
        putchar('\n');
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "describe") == 0) {
        describe();
        return 0;
    }
    return decode();
}
