"""The PD slew law of examples/gnc_slew/slew_controller.cpp written in Python,
for kanegen.Model.simulate(controller=...) and kanegen.sweep(controller=...):
30 deg about the bus z axis, bandwidth 0.05 rad/s, damping 0.9, 0.3 N m per
wheel motor. The same constants as the C++ law; the test suite and
scripts/sweep_report.py compare the two.

    from slew_pd import pd_law
    law = pd_law(model.output_names)      # law(t, q, u, y) -> the three motor torques
"""
import math

import numpy as np

INERTIA = np.array([995.0, 380.0, 875.0])  # kg m^2, the bus with its arrays (slew_controller.cpp)
BANDWIDTH, DAMPING, MAX_TORQUE, SLEW_DEG = 0.05, 0.9, 0.3, 30.0


def pd_law(output_names):
    att, gyro = output_names.index("star_tracker.qw"), output_names.index("gyro.x")
    half = math.radians(SLEW_DEG) / 2
    tw, tz = math.cos(half), math.sin(half)

    def law(t, q, u, y):
        w0, x0, y0, z0 = y[att:att + 4]
        # conj(target) (x) q with target = [tw, 0, 0, tz]
        e = np.array([tw * w0 + tz * z0, tw * x0 + tz * y0, tw * y0 - tz * x0, tw * z0 - tz * w0])
        if e[0] < 0:
            e = -e
        torque = -(INERTIA * BANDWIDTH ** 2 * 2.0 * e[1:] + INERTIA * 2.0 * DAMPING * BANDWIDTH * y[gyro:gyro + 3])
        peak = np.abs(torque).max()
        if peak > MAX_TORQUE:
            torque *= MAX_TORQUE / peak
        return -torque  # the wheels' motor torques: the reaction on the bus is the control torque

    return law
