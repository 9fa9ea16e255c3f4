/* SPDX-License-Identifier: MIT */
/*
 * fuzz_can_in: the gateway's inputs from a PLC as untrusted input (libFuzzer,
 * ASan + UBSan): received [input] frames of any id, length and kind through
 * lib/urrt_plcin (as gateway/can/can_in.c describes them) into their input
 * recipes, and, through the CANopen
 * node of the configuration's twin (gateway/can/co_run.c over lib/urrt_co),
 * any NMT command, RPDO and SDO request (the new objects 0x2200.., 0x1400..,
 * 0x1600.., 0x1016 among them), the node's variables then taken as
 * gateway/urrt-gateway/plc_in.c takes them, with any of them absent.
 *
 * The fuzzer's bytes are a script of records, each one byte of kind and
 * what it needs. After every take, what a recipe holds is checked against
 * the rules, independently of the code under test's own arithmetic where
 * the rule allows:
 *   - each register holds a value, was refused, or is absent: the three
 *     counts add up to the recipe's registers, refused as urrt_plcin_take says;
 *   - a register's value is one its type takes (INT32 in range, BOOL 0/1,
 *     a DOUBLE finite) and, from a quantity, within each of its signals'
 *     min..max; a mask holds no bit its signals do not carry;
 *   - a register whose signal was absent holds no value;
 *   - the input is fresh after it, and its package due to a new session;
 *   - lib's own look through the node (urrt_plcin_node) keeps the same
 *     value rules, is fresh after a write it took, not after falling silent,
 *     and holds nothing after falling silent with on_silence = stop.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "can_in.h"
#include "config.h"
#include "urrt_co.h"

/* The plain configuration: classic and FD frames, 11- and 29-bit ids, Intel
 * and Motorola, scaling, float32, masks split by bits=, BOOLs, doubles. */
static const char plain_ini[] =
    "[robot arm]\nhost = 127.0.0.1\nsource = rtde\n"
    "[can]\ninterface = log:/dev/null\nfd = yes\ndata_bitrate = 2000000\nheartbeat_id = 0x7F0\n"
    "[input cmd]\nid = 0x18FF1234\nextended = yes\nfd = yes\nlength = 16\ntimeout_ms = 250\non_silence = value 0\n"
    "signal = input_double_register_30 @7|16 motorola signed factor=0.01 offset=0.5 min=-100 max=200\n"
    "signal = input_bit_registers32_to_63 @16|8 intel unsigned bits=8-15 name=mask_hi\n"
    "signal = input_bit_registers32_to_63 @24|4 intel unsigned bits=0-3 name=mask_lo\n"
    "signal = input_int_register_25 @32|32 intel signed name=count\n"
    "signal = input_double_register_31 @64|32 intel float32 name=speed\n"
    "signal = input_bit_register_100 @96|1 intel unsigned name=flag\n"
    "[input job]\nid = 0x200\ntimeout_ms = 100\n"
    "signal = input_int_register_24 @0|16 intel unsigned max=9999 name=job\n"
    "signal = input_bit_register_64 @16|2 intel unsigned name=start\n"
    "signal = input_int_register_26 @24|32 intel unsigned factor=-3 offset=7 name=wide\n"
    "signal = input_bit_registers0_to_31 @56|8 intel unsigned bits=24-31 name=top\n";

/* The CANopen twin: two RPDOs. */
static const char canopen_ini[] =
    "[robot arm]\nhost = 127.0.0.1\nsource = rtde\n"
    "[can]\ninterface = log:/dev/null\nbitrate = 500000\n"
    "[canopen]\nnode_id = 5\nnmt_start = operational\n"
    "[frame answer]\nperiod_ms = 20\nsignal = input_int_register_24 @0|16 intel unsigned name=echo\n"
    "[input job]\ntimeout_ms = 100\n"
    "signal = input_int_register_24 @0|16 intel unsigned max=9999 name=job\n"
    "signal = input_bit_register_64 @16|8 intel unsigned name=start\n"
    "signal = input_int_register_27 @24|32 intel signed factor=2 name=twice\n"
    "[input more]\ntimeout_ms = 50\n"
    "signal = input_bit_registers32_to_63 @0|16 intel unsigned bits=16-31 name=bits\n"
    "signal = input_int_register_28 @16|8 intel signed min=-5 max=5 name=small\n";

static gw_config plain, canopen;
/* Per [input]: lib's description of it, its state, its recipe. */
struct input {
    urrt_plcin_desc d;
    uint16_t vars[URRT_PLCIN_MAX_SIGNALS];
    urrt_plcin st;
    urrt_rtde_in in;
};
static struct input plain_in[8], canopen_in[URRT_CO_MAX_RPDOS];
/* The same [input]s taken by lib's look through the node (urrt_plcin_node). */
static struct input node_in[URRT_CO_MAX_RPDOS];

static void die(const char *what)
{
    fprintf(stderr, "fuzz_can_in: %s\n", what);
    abort();
}

static void load(gw_config *cfg, const char *text, const char *name, struct input *in)
{
    FILE *f = fmemopen((void *)text, strlen(text), "r");
    if (f == NULL || gw_config_load_stream(cfg, f, name, stderr) != 0) {
        die("a configuration of the harness does not load");
    }
    fclose(f);
    for (size_t i = 0; i < cfg->can.input_count; i++) {
        if (urrt_rtde_in_init(&in[i].in, cfg->can.inputs[i].regs, cfg->can.inputs[i].reg_count) != URRT_OK) {
            die("an [input]'s recipe is refused by lib");
        }
        can_in_desc(&cfg->can.inputs[i], in[i].vars, &in[i].d);
    }
}

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    urrt_log_init("fuzz_can_in", URRT_LOG_ERR);
    load(&plain, plain_ini, "plain.ini", plain_in);
    load(&canopen, canopen_ini, "canopen.ini", canopen_in);
    for (size_t i = 0; i < canopen.can.input_count; i++) {
        node_in[i] = canopen_in[i];
        node_in[i].d.vars = node_in[i].vars;
    }
    if (canopen.co_run == NULL) {
        die("the CANopen twin has no node");
    }
    return 0;
}

static bool given(const urrt_rtde_in *in, size_t k)
{
    return (in->given[k / 8u] >> (k % 8u) & 1u) != 0;
}

static uint64_t be(const uint8_t *p, unsigned n)
{
    uint64_t v = 0;
    for (unsigned i = 0; i < n; i++) {
        v = v << 8 | p[i];
    }
    return v;
}

/* Register k's value as it would be packed, checked against its type and
 * its signals. */
static void check_value(const struct can_map_frame *f, const urrt_rtde_in *in, size_t k)
{
    const uint8_t *p = in->data + in->offset[k];
    uint64_t carried = 0;
    bool mask = false;
    double value = 0;
    switch (urrt_rtde_var_type(f->regs[k])) {
    case URRT_RTDE_T_BOOL:
        if (p[0] > 1u) {
            die("a BOOL register holds neither 0 nor 1");
        }
        value = p[0];
        break;
    case URRT_RTDE_T_UINT32:
        value = (double)be(p, 4);
        break;
    case URRT_RTDE_T_INT32:
        value = (double)(int32_t)(uint32_t)be(p, 4);
        break;
    case URRT_RTDE_T_DOUBLE: {
        uint64_t bits = be(p, 8);
        memcpy(&value, &bits, sizeof value);
        if (!isfinite(value)) {
            die("a DOUBLE register holds a value that is not finite");
        }
        break;
    }
    default: die("a register of a type no input register has");
    }
    for (size_t i = 0; i < f->count; i++) {
        const urrt_can_signal *sig = &f->sigs[i];
        if (f->meta[i].var != f->regs[k]) {
            continue;
        }
        if (f->meta[i].bitmask) {
            mask = true;
            carried |= (sig->length >= 64 ? ~UINT64_C(0) : (UINT64_C(1) << sig->length) - 1u)
                       << URRT_CAN_SIG_MASK_FIRST(sig->flags);
        } else if (!(value >= sig->min) || !(value <= sig->max)) {
            die("a register holds a value outside its signal's min..max");
        }
    }
    if (mask && ((uint64_t)value & ~carried) != 0) {
        die("a mask register holds a bit no signal carries");
    }
}

/* The take of f's registers from raws, then every rule of the header. */
static void take_and_check(const struct can_map_frame *f, struct input *input, const uint64_t *raws,
                           uint64_t absent, uint64_t now)
{
    urrt_rtde_in *in = &input->in;
    size_t refused = urrt_plcin_take(&input->d, &input->st, in, raws, absent, now), held = 0, missing = 0;
    if (!input->st.fresh || !urrt_plcin_due(&input->d, &input->st, true, input->st.session + 1u, now, UINT64_MAX)) {
        die("an input just taken is not fresh, or its package not due to a new session");
    }
    for (size_t k = 0; k < f->reg_count; k++) {
        bool gone = false;
        for (size_t i = 0; i < f->count && i < 64; i++) {
            gone = gone || (f->meta[i].var == f->regs[k] && (absent >> i & 1u) != 0);
        }
        if (gone && given(in, k)) {
            die("a register whose signal is absent holds a value");
        }
        missing += gone;
        if (given(in, k)) {
            held++;
            check_value(f, in, k);
        }
    }
    if (held + refused + missing != f->reg_count) {
        die("held, refused and absent registers do not add up to the recipe");
    }
}

static void emit(void *ctx, const urrt_can_frame *frame, uint64_t now_us)
{
    (void)ctx, (void)frame, (void)now_us;
}

/* A frame for an [input] of the plain configuration: which one, length,
 * FD, then the payload. */
static size_t plain_frame(const uint8_t *p, size_t n)
{
    urrt_can_frame frame;
    uint64_t raws[URRT_PLCIN_MAX_SIGNALS];
    const struct can_map_frame *f;
    size_t used;
    if (n < 3) {
        return n;
    }
    f = &plain.can.inputs[p[0] % plain.can.input_count];
    memset(&frame, 0, sizeof frame);
    frame.id = f->id;
    frame.extended = f->extended;
    frame.fd = (p[1] & 0x80u) != 0;
    frame.len = (uint8_t)(p[1] & 0x7Fu) <= URRT_CAN_MAX_LEN ? (uint8_t)(p[1] & 0x7Fu) : URRT_CAN_MAX_LEN;
    used = 2u + (frame.len < n - 2u ? frame.len : n - 2u);
    memcpy(frame.data, p + 2, used - 2u);
    struct input *input = &plain_in[f - plain.can.inputs];
    if (urrt_plcin_raws(&input->d, frame.data, frame.len, frame.fd, raws)) {
        take_and_check(f, input, raws, 0, 1000000);
    } else if (frame.len == f->len && frame.fd == f->fd) {
        die("a frame of the configured length and kind is not used");
    }
    return used;
}

/* [input] i through lib's look at the node, then the rules: every value held
 * is one its register and signals take; a look that took is fresh after it
 * unless it fell silent; one that fell silent is not fresh, and with
 * on_silence = stop holds no value. */
static void node_look(const struct can_map_frame *f, size_t i, uint64_t now)
{
    struct input *input = &node_in[i];
    urrt_plcin_rpdo rpdo = {co_run_node(canopen.co_run), (uint16_t)co_run_input_first_var(canopen.co_run, i),
                            (uint8_t)i};
    urrt_plcin_look look;
    urrt_plcin_node(&input->d, &rpdo, &input->st, &input->in, now, &look);
    for (size_t k = 0; k < f->reg_count; k++) {
        if (given(&input->in, k)) {
            check_value(f, &input->in, k);
        }
    }
    if (look.why != URRT_PLCIN_STILL) {
        if (input->st.fresh) {
            die("an input that fell silent is fresh");
        }
        for (size_t k = 0; f->silence == URRT_PLCIN_STOP && k < f->reg_count; k++) {
            if (given(&input->in, k)) {
                die("on_silence = stop, and a register still holds a value");
            }
        }
    } else if (look.took && !input->st.fresh) {
        die("a look that took a write left the input not fresh");
    }
}

/* A frame to the CANopen node (NMT, an RPDO, an SDO request, anything), the
 * clock moved on, then each [input] taken from the node's variables with
 * the absent mask the fuzzer gives. */
static size_t node_frame(const uint8_t *p, size_t n, uint64_t *now)
{
    static const uint32_t ids[] = {0x000, 0x080, 0x205, 0x305, 0x605, 0x701, 0x185};
    urrt_co *co = co_run_node(canopen.co_run);
    uint8_t data[8] = {0};
    size_t len, used;
    if (n < 4) {
        return n;
    }
    len = p[1] % 9u;
    used = 3u + (len < n - 3u ? len : n - 3u);
    memcpy(data, p + 3, used - 3u);
    *now += (uint64_t)p[2] * 1000u;
    urrt_co_on_frame(co, ids[p[0] % (sizeof ids / sizeof ids[0])], 0, data, used - 3u, *now, emit, NULL);
    (void)urrt_co_run(co, *now, emit, NULL);
    for (size_t i = 0; i < canopen.can.input_count; i++) {
        const struct can_map_frame *f = &canopen.can.inputs[i];
        uint64_t raws[URRT_CO_RPDO_MAX_MAPPED];
        uint64_t absent = 0;
        for (size_t k = 0; k < f->count && k < URRT_CO_RPDO_MAX_MAPPED; k++) {
            raws[k] = co_run_input_raw(canopen.co_run, i, k);
            absent |= (uint64_t)((p[0] >> k & 1u) && (p[2] & 1u)) << k;
        }
        take_and_check(f, &canopen_in[i], raws, absent, *now);
        node_look(f, i, *now);
    }
    return used;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint64_t now = 1000000;
    urrt_co *co = co_run_node(canopen.co_run);
    (void)urrt_co_start(co, now, emit, NULL); /* power-on: every object to its default */
    for (size_t i = 0; i < plain.can.input_count; i++) {
        urrt_rtde_in_forget(&plain_in[i].in);
        urrt_plcin_init(&plain_in[i].st);
    }
    for (size_t i = 0; i < canopen.can.input_count; i++) {
        urrt_rtde_in_forget(&canopen_in[i].in);
        urrt_plcin_init(&canopen_in[i].st);
        urrt_rtde_in_forget(&node_in[i].in);
        urrt_plcin_init(&node_in[i].st);
    }
    while (size > 1) {
        size_t used = (data[0] & 1u) == 0 ? plain_frame(data + 1, size - 1) : node_frame(data + 1, size - 1, &now);
        data += 1 + used;
        size -= 1 + used;
    }
    return 0;
}
