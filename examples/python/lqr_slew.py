#!/usr/bin/python3
"""LQR attitude control of the flexible spacecraft, designed on kanegen's
linear model and closed on the nonlinear one (docs/gnc.md).

  1. kanegen.Model(...).linearize(): the exact continuous-time A, B about rest
     (attitude as a small rotation: no quaternion constraint);
  2. keep the states the wheels can steer: attitude, bus rate and the arrays'
     modes (translation and the wheels' own angle and speed are cyclic: the
     total angular momentum is conserved, so they are not stabilizable);
  3. scipy's continuous algebraic Riccati equation gives K;
  4. the nonlinear flexible model is simulated with u = -K x as a digital
     controller at 10 Hz with torque saturation, slewing 30 deg about z.

Run:  PYTHONPATH=build/python /usr/bin/python3 examples/python/lqr_slew.py [--t-end 300] [--plot slew_lqr.png]
Prints the settling time (attitude error below 0.1 deg for good) and the peak
array tip deflection, as JSON on the last line.
"""
import argparse
import json
import math
import os
import sys

import numpy as np
import scipy.linalg

import kanegen

HERE = os.path.dirname(os.path.abspath(__file__))
MODEL = os.path.join(HERE, "..", "..", "models", "gnc", "slew_spacecraft.yaml")
SLEW_DEG = 30.0
MAX_TORQUE = 0.3  # N m per wheel motor
PERIOD = 0.1      # s: 10 Hz


def quat_mul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                     w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                     w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def design(model):
    lin = model.linearize()
    names = lin["state_names"]
    keep = [i for i, n in enumerate(names)
            if n.startswith(("q.bus.r", "u.bus.w")) or ".eta" in n]
    A = lin["A"][np.ix_(keep, keep)]
    B = lin["B"][keep, :]
    kept = [names[i] for i in keep]
    # weights (SI units): attitude and bus rate against torque, the arrays' modes lightly
    Q = np.diag([1e6 if n.startswith("q.bus.r") else 1e8 if n.startswith("u.bus.w") else 1e2 for n in kept])
    R = np.eye(B.shape[1]) * 1e4
    P = scipy.linalg.solve_continuous_are(A, B, Q, R)
    K = np.linalg.solve(R, B.T @ P)
    closed = np.linalg.eigvals(A - B @ K)
    return K, kept, closed, lin


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--t-end", type=float, default=300.0)
    ap.add_argument("--plot", default="")
    ap.add_argument("--engine", default="generated")
    args = ap.parse_args()

    model = kanegen.Model(MODEL, engine=args.engine)
    K, kept, closed, lin = design(model)
    assert max(closed.real) < 0, "LQR closed loop not stable"
    half = math.radians(SLEW_DEG) / 2
    target_conj = np.array([math.cos(half), 0.0, 0.0, -math.sin(half)])
    qi = {n: i for i, n in enumerate(model.q_names)}
    ui = {n: i for i, n in enumerate(model.u_names)}

    def state_of(q, u):
        e = quat_mul(target_conj, q[qi["bus.qw"]:qi["bus.qw"] + 4] / np.linalg.norm(q[qi["bus.qw"]:qi["bus.qw"] + 4]))
        if e[0] < 0:
            e = -e
        x = []
        for n in kept:
            kind, name = n[0], n[2:]
            if name.startswith("bus.r"):
                x.append(2.0 * e[1 + "xyz".index(name[-1])])
            else:
                x.append(q[qi[name]] if kind == "q" else u[ui[name]])
        return np.array(x)

    def law(t, q, u, y):
        w = -K @ state_of(q, u)  # the wheel motor torques (B's inputs)
        peak = np.max(np.abs(w))
        if peak > MAX_TORQUE:
            w *= MAX_TORQUE / peak  # saturate, keeping the direction
        return w

    run = model.simulate(args.t_end, dt_out=0.5, controller=law, period=PERIOD)
    t = run["t"]
    qw, qz = run["star_tracker.qw"], run["star_tracker.qz"]
    qx, qy = run["star_tracker.qx"], run["star_tracker.qy"]
    def angle(e):  # rotation angle of a quaternion, accurate near zero
        return 2 * math.degrees(math.atan2(np.linalg.norm(e[1:]), abs(e[0])))

    err = np.array([angle(quat_mul(target_conj, [a, b, c, d])) for a, b, c, d in zip(qw, qx, qy, qz)])
    outside = np.nonzero(err > 0.1)[0]
    settling = float(t[outside[-1] + 1]) if len(outside) and outside[-1] + 1 < len(t) else (0.0 if not len(outside) else math.inf)
    tips = np.array([np.hypot(np.hypot(run[f"tip_{s}.x"], run[f"tip_{s}.y"]), run[f"tip_{s}.z"]) for s in "ab"])
    result = {
        "closed_loop_slowest_pole": float(max(closed.real)),
        "settling_time_s": settling,
        "final_error_deg": float(err[-1]),
        "peak_tip_deflection_m": float(tips.max()),
        "peak_motor_torque_Nm": float(max(np.abs(run[f"motor_{a}"]).max() for a in "xyz")),
        "rhs_evals": run.summary["rhs_evals"],
        "wall_seconds": run.summary["wall_seconds"],
    }
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
        ax[0].semilogy(t, np.maximum(err, 1e-6))
        ax[0].axhline(0.1, color="gray", ls=":")
        ax[0].set_ylabel("attitude error (deg)")
        for a in "xyz":
            ax[1].plot(t, run[f"motor_{a}"], label=f"motor_{a}")
        ax[1].set_ylabel("wheel motor torque (N m)")
        ax[1].legend()
        ax[2].plot(t, tips[0] * 1e3, label="array a tip")
        ax[2].plot(t, tips[1] * 1e3, label="array b tip")
        ax[2].set_ylabel("tip deflection (mm)")
        ax[2].set_xlabel("t (s)")
        ax[2].legend()
        fig.suptitle("LQR slew of 30 deg, nonlinear flexible model (kanegen, Python)")
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
