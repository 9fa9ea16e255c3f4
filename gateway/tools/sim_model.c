/* SPDX-License-Identifier: MIT */
/* sim_model.c: see sim_model.h. */
#include "sim_model.h"

#include <math.h>
#include <string.h>

#define G 9.80665

/* UR5e: standard Denavit-Hartenberg parameters (Universal Robots'
 * published table) and link masses. */
static const double dh_d[6] = {0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996};
static const double dh_a[6] = {0.0, -0.425, -0.3922, 0.0, 0.0, 0.0};
static const double dh_alpha[6] = {M_PI / 2, 0.0, 0.0, M_PI / 2, -M_PI / 2, 0.0};
static const double link_mass[6] = {3.761, 8.058, 2.846, 1.37, 1.3, 0.365};
#define PAYLOAD_MASS 1.0
static const double payload_cog[3] = {0.0, 0.0, 0.05};

/* Joint drive: reflected inertia [kg m^2], viscous [Nm s/rad] and Coulomb
 * [Nm] friction, torque constant through the gearbox [Nm/A]. */
static const double joint_inertia[6] = {2.0, 3.5, 1.0, 0.12, 0.12, 0.05};
static const double joint_viscous[6] = {2.0, 2.0, 1.5, 0.6, 0.6, 0.6};
static const double joint_coulomb[6] = {3.0, 3.0, 2.5, 1.0, 1.0, 1.0};
static const double torque_constant[6] = {13.0, 13.0, 13.0, 9.3, 9.3, 9.3};
/* A pose in the middle of the workspace, clear of singularities. */
static const double home_pose[6] = {0.0, -1.57, 1.57, -1.57, -1.57, 0.0};

static uint64_t splitmix64(uint64_t x)
{
    x += UINT64_C(0x9E3779B97F4A7C15);
    x = (x ^ (x >> 30)) * UINT64_C(0xBF58476D1CE4E5B9);
    x = (x ^ (x >> 27)) * UINT64_C(0x94D049BB133111EB);
    return x ^ (x >> 31);
}

/* Uniform in [0, 1) from a 64-bit hash. */
static double unit(uint64_t h)
{
    return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

/* Deterministic measurement noise in [-1, 1) for (seed, packet, channel). */
static double noise(const sim_model *m, uint64_t index, unsigned channel)
{
    uint64_t h = splitmix64(m->seed ^ splitmix64(index * UINT64_C(0x100000001B3) + channel));
    return 2.0 * unit(h) - 1.0;
}

void sim_model_init(sim_model *m, uint64_t seed, double rate_hz)
{
    uint64_t state = seed;
    memset(m, 0, sizeof *m);
    m->seed = seed;
    m->rate_hz = rate_hz;
    m->start_time = SIM_MODEL_START_TIME;
    for (int j = 0; j < 6; j++) {
        m->home[j] = home_pose[j] + 0.2 * (unit(splitmix64(state++)) - 0.5);
        for (int h = 0; h < SIM_MODEL_HARMONICS; h++) {
            /* Lower harmonics swing wider; wrist joints move more than the base. */
            double scale = (j < 3 ? 0.35 : 0.6) / (double)(h + 1);
            m->amp[j][h] = scale * (0.4 + 0.6 * unit(splitmix64(state++)));
            m->omega[j][h] = 2.0 * M_PI * (0.05 + 0.1 * (h + 1) * unit(splitmix64(state++)));
            m->phase[j][h] = 2.0 * M_PI * unit(splitmix64(state++));
        }
        m->temp_base[j] = 24.0 + 3.0 * unit(splitmix64(state++));
    }
}

double sim_model_time(const sim_model *m, uint64_t index)
{
    return m->start_time + (double)index / m->rate_hz;
}

void sim_model_joints(const sim_model *m, double t, double q[6], double qd[6], double qdd[6])
{
    for (int j = 0; j < 6; j++) {
        double p = m->home[j], v = 0.0, a = 0.0;
        for (int h = 0; h < SIM_MODEL_HARMONICS; h++) {
            double w = m->omega[j][h];
            double s = sin(w * t + m->phase[j][h]);
            double c = cos(w * t + m->phase[j][h]);
            p += m->amp[j][h] * s;
            v += m->amp[j][h] * w * c;
            a -= m->amp[j][h] * w * w * s;
        }
        q[j] = p;
        if (qd != NULL) {
            qd[j] = v;
        }
        if (qdd != NULL) {
            qdd[j] = a;
        }
    }
}

/* The frames of the chain: origin[i] and z axis[i] of frame i (0 = base),
 * and the rotation of the flange. */
typedef struct chain {
    double origin[7][3];
    double z[7][3];
    double rot[3][3];
} chain;

static void forward(const double q[6], chain *c)
{
    double T[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
    for (int k = 0; k < 3; k++) {
        c->origin[0][k] = 0.0;
        c->z[0][k] = k == 2 ? 1.0 : 0.0;
    }
    for (int i = 0; i < 6; i++) {
        double ct = cos(q[i]), st = sin(q[i]);
        double ca = cos(dh_alpha[i]), sa = sin(dh_alpha[i]);
        double A[3][4] = {{ct, -st * ca, st * sa, dh_a[i] * ct},
                          {st, ct * ca, -ct * sa, dh_a[i] * st},
                          {0.0, sa, ca, dh_d[i]}};
        double N[3][4];
        for (int r = 0; r < 3; r++) {
            for (int col = 0; col < 4; col++) {
                N[r][col] = T[r][0] * A[0][col] + T[r][1] * A[1][col] + T[r][2] * A[2][col] +
                            (col == 3 ? T[r][3] : 0.0);
            }
        }
        memcpy(T, N, sizeof T);
        for (int k = 0; k < 3; k++) {
            c->origin[i + 1][k] = T[k][3];
            c->z[i + 1][k] = T[k][2];
        }
    }
    for (int r = 0; r < 3; r++) {
        for (int col = 0; col < 3; col++) {
            c->rot[r][col] = T[r][col];
        }
    }
}

static void rotation_vector(const double R[3][3], double rv[3])
{
    double cosine = (R[0][0] + R[1][1] + R[2][2] - 1.0) / 2.0;
    double angle;
    cosine = cosine > 1.0 ? 1.0 : cosine < -1.0 ? -1.0 : cosine;
    angle = acos(cosine);
    if (angle < 1e-9) {
        rv[0] = (R[2][1] - R[1][2]) / 2.0;
        rv[1] = (R[0][2] - R[2][0]) / 2.0;
        rv[2] = (R[1][0] - R[0][1]) / 2.0;
    } else if (M_PI - angle < 1e-6) {
        /* Near a half turn the antisymmetric part vanishes: use the diagonal. */
        double x = sqrt(fmax(0.0, (R[0][0] + 1.0) / 2.0));
        double y = sqrt(fmax(0.0, (R[1][1] + 1.0) / 2.0));
        double z = sqrt(fmax(0.0, (R[2][2] + 1.0) / 2.0));
        if (x >= y && x >= z) {
            y = copysign(y, R[0][1]);
            z = copysign(z, R[0][2]);
        } else if (y >= z) {
            x = copysign(x, R[0][1]);
            z = copysign(z, R[1][2]);
        } else {
            x = copysign(x, R[0][2]);
            y = copysign(y, R[1][2]);
        }
        rv[0] = x * angle;
        rv[1] = y * angle;
        rv[2] = z * angle;
    } else {
        double k = angle / (2.0 * sin(angle));
        rv[0] = k * (R[2][1] - R[1][2]);
        rv[1] = k * (R[0][2] - R[2][0]);
        rv[2] = k * (R[1][0] - R[0][1]);
    }
}

void sim_model_fk(const double q[6], double pose[6], double elbow[3])
{
    chain c;
    forward(q, &c);
    for (int k = 0; k < 3; k++) {
        pose[k] = c.origin[6][k];
        if (elbow != NULL) {
            elbow[k] = c.origin[2][k];
        }
    }
    rotation_vector(c.rot, pose + 3);
}

/* Joint torques holding the arm and payload against gravity in pose q. */
static void gravity_torques(const double q[6], double tau[6])
{
    chain c;
    double com[7][3];
    double mass[7];
    forward(q, &c);
    for (int i = 0; i < 6; i++) {
        for (int k = 0; k < 3; k++) {
            com[i][k] = (c.origin[i][k] + c.origin[i + 1][k]) / 2.0;
        }
        mass[i] = link_mass[i];
    }
    for (int k = 0; k < 3; k++) {
        com[6][k] = c.origin[6][k] + c.rot[k][0] * payload_cog[0] + c.rot[k][1] * payload_cog[1] +
                    c.rot[k][2] * payload_cog[2];
    }
    mass[6] = PAYLOAD_MASS;
    for (int j = 0; j < 6; j++) {
        const double *z = c.z[j], *o = c.origin[j];
        double t = 0.0;
        for (int i = j; i < 7; i++) {
            double rx = com[i][0] - o[0], ry = com[i][1] - o[1];
            /* z component of z x r, times the weight. */
            t += mass[i] * G * (z[0] * ry - z[1] * rx);
        }
        tau[j] = t;
    }
}

static void joint_torques(const double q[6], const double qd[6], const double qdd[6], double tau[6])
{
    gravity_torques(q, tau);
    for (int j = 0; j < 6; j++) {
        tau[j] += joint_inertia[j] * qdd[j] + joint_viscous[j] * qd[j] + joint_coulomb[j] * tanh(qd[j] / 0.02);
    }
}

/* TCP speed (linear, then angular as a rotation vector rate) and linear
 * acceleration by central differences of the kinematics along the path. */
static void tcp_motion(const sim_model *m, double t, double speed[6], double accel[3])
{
    const double h = 1e-4, ha = 1e-3;
    double q[6], before[6], after[6], mid[6];
    chain cb, ca;
    double dR[3][3], rv[3];

    sim_model_joints(m, t - h, q, NULL, NULL);
    forward(q, &cb);
    sim_model_joints(m, t + h, q, NULL, NULL);
    forward(q, &ca);
    /* Angular velocity: the rotation from R(t-h) to R(t+h), in base frame. */
    for (int r = 0; r < 3; r++) {
        for (int col = 0; col < 3; col++) {
            dR[r][col] = ca.rot[r][0] * cb.rot[col][0] + ca.rot[r][1] * cb.rot[col][1] +
                         ca.rot[r][2] * cb.rot[col][2];
        }
    }
    rotation_vector(dR, rv);
    for (int k = 0; k < 3; k++) {
        speed[k] = (ca.origin[6][k] - cb.origin[6][k]) / (2.0 * h);
        speed[3 + k] = rv[k] / (2.0 * h);
    }
    sim_model_joints(m, t - ha, q, NULL, NULL);
    sim_model_fk(q, before, NULL);
    sim_model_joints(m, t + ha, q, NULL, NULL);
    sim_model_fk(q, after, NULL);
    sim_model_joints(m, t, q, NULL, NULL);
    sim_model_fk(q, mid, NULL);
    for (int k = 0; k < 3; k++) {
        accel[k] = (after[k] - 2.0 * mid[k] + before[k]) / (ha * ha);
    }
}

static double square_wave(double t, double period)
{
    return fmod(floor(t / (period / 2.0)), 2.0);
}

/* One packet's motion: targets at t, actuals SIM_MODEL_LAG_S later, and
 * the noise channels drawn so far (their order fixes every value). */
typedef struct motion {
    uint64_t index;
    double t, ta;
    double qt[6], qdt[6], qddt[6], qa[6], qda[6], qdda[6];
    double speed_t[6], speed_a[6], accel[3];
    unsigned ch;
} motion;

static double next_noise(const sim_model *m, motion *mo)
{
    return noise(m, mo->index, mo->ch++);
}

/* Joint targets and actuals, torques, currents, voltages, temperatures.
 * Returns the sum of the actual currents' magnitudes. */
static double fill_joints(const sim_model *m, motion *mo, urrt_state *st)
{
    double tau_t[6], tau_a[6];
    double current_sum = 0.0;
    joint_torques(mo->qt, mo->qdt, mo->qddt, tau_t);
    joint_torques(mo->qa, mo->qda, mo->qdda, tau_a);
    for (int j = 0; j < 6; j++) {
        st->q_target[j] = mo->qt[j];
        st->qd_target[j] = mo->qdt[j];
        st->qdd_target[j] = mo->qddt[j];
        st->m_target[j] = tau_t[j];
        st->i_target[j] = tau_t[j] / torque_constant[j];
        st->q_actual[j] = mo->qa[j];
        st->qd_actual[j] = mo->qda[j];
        st->i_actual[j] = tau_a[j] / torque_constant[j] + 0.03 * next_noise(m, mo);
        st->i_control[j] = st->i_actual[j] + 0.01 * next_noise(m, mo);
        st->v_actual[j] = 47.6 + 0.05 * next_noise(m, mo) - 0.02 * fabs(st->i_actual[j]);
        current_sum += fabs(st->i_actual[j]);
        /* Warm up over the first quarter hour, then breathe with the load. */
        st->motor_temperatures[j] = m->temp_base[j] + 8.0 * (1.0 - exp(-mo->t / 900.0)) +
                                    0.3 * sin(2.0 * M_PI * mo->t / 300.0 + j);
        st->joint_modes[j] = 253.0;
    }
    return current_sum;
}

/* TCP pose and speed, target and actual (and the 1.x names for them). */
static void fill_tcp(const sim_model *m, motion *mo, urrt_state *st)
{
    double scratch[3];
    sim_model_fk(mo->qt, st->tool_vector_target, NULL);
    sim_model_fk(mo->qa, st->tool_vector_actual, NULL);
    tcp_motion(m, mo->t, mo->speed_t, mo->accel);
    tcp_motion(m, mo->ta, mo->speed_a, scratch);
    for (int k = 0; k < 6; k++) {
        st->tcp_speed_target[k] = mo->speed_t[k];
        st->tcp_speed_actual[k] = mo->speed_a[k];
        st->tool_vector[k] = st->tool_vector_actual[k];
        st->tcp_speed[k] = mo->speed_a[k];
    }
}

/* The force sensor feels the payload's weight and inertia, plus noise. */
static void fill_force(const sim_model *m, motion *mo, urrt_state *st)
{
    const double *accel = mo->accel;
    double f[3] = {PAYLOAD_MASS * accel[0], PAYLOAD_MASS * accel[1], PAYLOAD_MASS * (accel[2] + G)};
    double r[3];
    chain c;
    forward(mo->qa, &c);
    for (int k = 0; k < 3; k++) {
        r[k] = c.rot[k][0] * payload_cog[0] + c.rot[k][1] * payload_cog[1] + c.rot[k][2] * payload_cog[2];
    }
    st->tcp_force[0] = f[0] + 0.4 * next_noise(m, mo);
    st->tcp_force[1] = f[1] + 0.4 * next_noise(m, mo);
    st->tcp_force[2] = f[2] + 0.4 * next_noise(m, mo);
    st->tcp_force[3] = r[1] * f[2] - r[2] * f[1] + 0.02 * next_noise(m, mo);
    st->tcp_force[4] = r[2] * f[0] - r[0] * f[2] + 0.02 * next_noise(m, mo);
    st->tcp_force[5] = r[0] * f[1] - r[1] * f[0] + 0.02 * next_noise(m, mo);
    /* The accelerometer measures specific force in the tool frame. */
    for (int k = 0; k < 3; k++) {
        st->tool_accelerometer[k] = c.rot[0][k] * accel[0] + c.rot[1][k] * accel[1] +
                                    c.rot[2][k] * (accel[2] + G) + 0.05 * next_noise(m, mo);
    }
}

/* Digital I/O, the controller's own figures and the modes. */
static void fill_status(const sim_model *m, motion *mo, urrt_generation gen, urrt_state *st)
{
    const double t = mo->t;
    /* Inputs: a few sensors switching at their own pace, tool input 0 too. */
    st->digital_input_bits[0] = square_wave(t, 2.0) * 1 + square_wave(t, 5.0) * 2 + square_wave(t + 0.3, 1.4) * 4 +
                                16.0 + square_wave(t, 6.0) * 65536.0;
    /* Outputs: a gripper following joint 6's direction, a lamp blinking. */
    st->digital_outputs[0] = (mo->qdt[5] > 0.0 ? 1.0 : 0.0) + square_wave(t, 8.0) * 2 + 256.0;
    st->controller_timer[0] = 0.0004 + 0.0001 * next_noise(m, mo);
    st->test_value[0] = 0.0;
    st->robot_mode[0] = gen == URRT_GEN_1X ? 0.0 /* CB2 RUNNING */ : 7.0 /* RUNNING */;
    st->safety_mode[0] = 1.0;   /* NORMAL */
    st->safety_status[0] = 1.0; /* NORMAL */
    st->program_state[0] = 2.0; /* PLAYING */
    st->speed_scaling[0] = 1.0;
}

/* Momentum and the supply: voltages sag and current rises with the load. */
static void fill_power(const sim_model *m, motion *mo, double current_sum, urrt_state *st)
{
    const double *v = mo->speed_a;
    /* Roughly the moving mass of forearm, wrist and payload. */
    st->linear_momentum_norm[0] = (link_mass[2] + link_mass[3] + link_mass[4] + link_mass[5] + PAYLOAD_MASS) *
                                  sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    st->v_main[0] = 48.2 + 0.05 * next_noise(m, mo);
    st->v_robot[0] = 48.0 + 0.05 * next_noise(m, mo) - 0.01 * current_sum;
    st->i_robot[0] = 0.6 + 0.35 * current_sum + 0.02 * next_noise(m, mo);
}

/* The elbow's position, and its velocity by central difference. */
static void fill_elbow(const sim_model *m, const motion *mo, urrt_state *st)
{
    const double h = 1e-4;
    double q[6], scratch[6], before[3], after[3];
    sim_model_fk(mo->qa, scratch, st->elbow_position);
    sim_model_joints(m, mo->ta - h, q, NULL, NULL);
    sim_model_fk(q, scratch, before);
    sim_model_joints(m, mo->ta + h, q, NULL, NULL);
    sim_model_fk(q, scratch, after);
    for (int k = 0; k < 3; k++) {
        st->elbow_velocity[k] = (after[k] - before[k]) / (2.0 * h);
    }
}

/* Reserved and unused columns, and the payload the arm carries. */
static void fill_constants(urrt_state *st)
{
    static const double inertia[6] = {0.0021, 0.0021, 0.0012, 0.0, 0.0, 0.0};
    for (int k = 0; k < 6; k++) {
        st->reserved_103[k] = 0.0;
        st->reserved_112[k] = 0.0;
        st->payload_inertia[k] = inertia[k];
    }
    for (int k = 0; k < 15; k++) {
        st->unused_53[k] = 0.0;
    }
    st->reserved_120[0] = 0.0;
    st->reserved_121[0] = 0.0;
    for (int k = 0; k < 3; k++) {
        st->reserved_140[k] = 0.0;
        st->payload_cog[k] = payload_cog[k];
    }
    st->payload_mass[0] = PAYLOAD_MASS;
}

void sim_model_state(const sim_model *m, uint64_t index, urrt_generation gen, urrt_state *st)
{
    motion mo = {.index = index, .t = (double)index / m->rate_hz, .ch = 0};
    double current_sum;

    mo.ta = mo.t - SIM_MODEL_LAG_S;
    urrt_state_clear(st);
    st->time[0] = sim_model_time(m, index);
    sim_model_joints(m, mo.t, mo.qt, mo.qdt, mo.qddt);
    sim_model_joints(m, mo.ta, mo.qa, mo.qda, mo.qdda);
    /* The order of the fills is the order of the noise channels. */
    current_sum = fill_joints(m, &mo, st);
    fill_tcp(m, &mo, st);
    fill_force(m, &mo, st);
    fill_status(m, &mo, gen, st);
    fill_power(m, &mo, current_sum, st);
    fill_elbow(m, &mo, st);
    fill_constants(st);
}
