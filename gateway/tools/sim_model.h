/* SPDX-License-Identifier: MIT */
/*
 * sim_model.h: the deterministic robot behind urrt-sim.
 *
 * A UR5e-like arm following smooth joint trajectories (sums of sines, so
 * that velocity and acceleration are their exact derivatives). Every value
 * of packet k is a function of (seed, k) alone: a test, or another program,
 * can recompute what the simulator sent from the seed and the packet's index
 * (which its time column gives: SIM_MODEL_START_TIME + index / rate).
 *
 * Consistency the model keeps: targets lead actuals by SIM_MODEL_LAG_S;
 * torques are inertia * acceleration + friction + gravity of the arm in its
 * current pose; currents are torque over a torque constant; the TCP pose is
 * the forward kinematics of the joint positions (UR5e DH parameters) and
 * the TCP speed its derivative; temperatures drift slowly; modes say
 * RUNNING/NORMAL/PLAYING in the numbering of the packet's generation.
 */
#ifndef URRT_SIM_MODEL_H
#define URRT_SIM_MODEL_H

#include <stdint.h>

#include "urrt.h"

#define SIM_MODEL_HARMONICS 3
/* Actuals follow targets this much later (a servo's tracking delay). */
#define SIM_MODEL_LAG_S 0.004
/* Controller time of packet 0, as if the controller had booted a while ago. */
#define SIM_MODEL_START_TIME 1000.0

typedef struct sim_model {
    uint64_t seed;
    double rate_hz;
    double start_time;
    double home[6];
    double amp[6][SIM_MODEL_HARMONICS];
    double omega[6][SIM_MODEL_HARMONICS];
    double phase[6][SIM_MODEL_HARMONICS];
    double temp_base[6];
} sim_model;

void sim_model_init(sim_model *m, uint64_t seed, double rate_hz);

/* Controller time (the time column) of packet index. */
double sim_model_time(const sim_model *m, uint64_t index);

/* Every field of packet index, for a packet of the given generation (robot
 * mode numbering and the 1.x-only fields depend on it). */
void sim_model_state(const sim_model *m, uint64_t index, urrt_generation gen, urrt_state *st);

/* Joint positions, velocities and accelerations at t seconds after packet 0. */
void sim_model_joints(const sim_model *m, double t, double q[6], double qd[6], double qdd[6]);

/* UR5e forward kinematics: the TCP pose (x, y, z, rotation vector) of q;
 * elbow (may be NULL) receives the elbow position. */
void sim_model_fk(const double q[6], double pose[6], double elbow[3]);

#endif
