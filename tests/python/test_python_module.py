#!/usr/bin/python3
"""`import kanegen` (python/kanegen_python.cpp) checked against the C++ side
and against physics; run by ctest with Debian's python3 and numpy:

    test_python_module.py --build BUILD_DIR --slew-sim PATH

  - eval: the generated and generic engines agree; u_dot solves M u_dot = F;
  - the same PD slew controller written in Python gives the trajectory of
    the C++ simulator with it compiled in (examples/gnc_slew);
  - linearize: a pendulum's A is the closed form;
  - the LQR example (reduced horizon) settles and leaves the arrays quiet.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

import numpy as np

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--slew-sim", required=True)
args = ap.parse_args()
sys.path.insert(0, os.path.join(args.build, "python"))
import kanegen  # noqa: E402

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SLEW = os.path.join(ROOT, "models", "gnc", "slew_spacecraft.yaml")
failures = []


def check(cond, what):
    print(("ok    " if cond else "FAIL  ") + what)
    if not cond:
        failures.append(what)


# ---- eval: both engines, M u_dot = F
gen = kanegen.Model(SLEW)
gnr = kanegen.Model(SLEW, engine="generic")
state = dict(q={"bus.qw": 0.9, "bus.qx": 0.1, "bus.qy": -0.3, "bus.qz": 0.3, "array_a.eta1": 0.01},
             u={"bus.wx": 0.02, "bus.wz": -0.01, "rw_z.angle": 30.0}, inputs={"motor_x": 0.1, "motor_z": -0.2})
a, b = gen.eval(**state), gnr.eval(**state)
check(np.abs(a["udot"] - b["udot"]).max() <= 1e-12 * np.abs(b["udot"]).max(), "eval: generated u_dot = generic u_dot")
check(np.abs(a["M"] @ a["udot"] - a["F"]).max() <= 1e-12 * np.abs(a["F"]).max(), "eval: M u_dot = F")
ya, yb = np.array(list(a["outputs"].values())), np.array(list(b["outputs"].values()))
check(np.abs(ya - yb).max() <= 1e-12 * np.abs(yb).max(), "eval: outputs agree between the engines")
check(abs(np.linalg.norm(ya[:4]) - 1) <= 1e-14, "eval: the star tracker's quaternion is a unit quaternion")

# ---- the PD slew of examples/gnc_slew/slew_controller.cpp, in Python
INERTIA = np.array([995.0, 380.0, 875.0])
BW, ZETA, TMAX = 0.05, 0.9, 0.3
half = math.radians(30.0) / 2
tw, tz = math.cos(half), math.sin(half)
att, gyro = gen.output_names.index("star_tracker.qw"), gen.output_names.index("gyro.x")


def pd(t, q, u, y):
    w0, x0, y0, z0 = y[att:att + 4]
    # conj(target) (x) q with target = [tw, 0, 0, tz]
    e = np.array([tw * w0 + tz * z0, tw * x0 + tz * y0, tw * y0 - tz * x0, tw * z0 - tz * w0])
    if e[0] < 0:
        e = -e
    torque = -(INERTIA * BW * BW * 2.0 * e[1:] + INERTIA * 2.0 * ZETA * BW * y[gyro:gyro + 3])
    peak = np.abs(torque).max()
    if peak > TMAX:
        torque *= TMAX / peak
    return -torque


T_END = 60.0
with tempfile.TemporaryDirectory() as d:
    out = os.path.join(d, "slew.csv")
    subprocess.run([args.slew_sim, "--t-end", str(T_END), "--dt-out", "0.5", "--no-progress", "-o", out], check=True,
                   stderr=subprocess.DEVNULL)
    rows = list(csv.DictReader(open(out)))
run = gen.simulate(T_END, dt_out=0.5, controller=pd, period=0.1)
worst, worst_col = 0.0, ""
for col in rows[0].keys():
    c = np.array([float(r[col]) for r in rows])
    p = run[col]
    # columns that stay at round-off (translation, cross-axis wheels) are compared absolutely
    scale = max(np.abs(c).max(), 1e-6)
    diff = np.abs(c - p).max() / scale if len(c) == len(p) else math.inf
    if diff > worst:
        worst, worst_col = diff, col
print(f"      Python PD vs C++ PD: largest difference {worst:.2e} (column {worst_col}, relative to its peak or 1e-6)")
check(len(rows) == len(run["t"]) and worst <= 1e-7, "simulate: the Python controller reproduces the C++ simulator's run")
# every name once; the groups hold the coordinate and its rate apart
check(len(set(run["columns"])) == len(run["columns"]), "simulate: no column name repeats")
check(set(run["q"]) == set(gen.q_names) and set(run["u"]) == set(gen.u_names)
      and not np.array_equal(run["q"]["rw_z.angle"], run["u"]["rw_z.angle_rate"]),
      "simulate: q and u grouped by name, a rate never under its coordinate's name")
check(set(run["outputs"]) == set(gen.output_names), "simulate: outputs grouped by name")

# ---- linearize: pendulum closed form
pend = kanegen.Model(os.path.join(ROOT, "models", "pendulum.yaml"))
lin = pend.linearize(q=[math.pi / 2])
check(lin["equilibrium"] and abs(lin["A"][1, 0] + 9.81) <= 1e-13 and lin["A"][0, 1] == 1.0,
      "linearize: pendulum A = [0 1; -g/L 0] hanging")

# ---- events: the probe separation model's events and latch as the CLI reports them
sep = kanegen.Model(os.path.join(ROOT, "models", "probe_separation.yaml"), engine="generic")
srun = sep.simulate(8.0, dt_out=0.1, integrator="rkf78")
names = [e["name"] for e in srun["events"]]
latch = srun["events"][-1] if srun["events"] else {}
check(names == ["eject", "separation"] and latch.get("energy_lost", 0) > 0
      and abs(srun["q"]["plate.disp"][-1] - 0.2) < 1e-9 and srun["u"]["plate.disp_rate"][-1] == 0.0,
      "simulate: events fire in Python as in the CLI (eject, then separation at the end of the stroke, latched)")
# a state with the plate free from the start: the eject event then finds it free (ignored), the spring drives at once
free_run = sep.simulate(2.0, dt_out=0.1, integrator="rkf78", locked=["probe"])
check([e["name"] for e in free_run["events"]] == ["separation"] and free_run["events"][0]["t"] < 1.0,
      "simulate: locked= sets the locks at the start (the plate free, the separation within the first second)")
ev_l = sep.eval(locked=["plate", "probe"])
ev_f = sep.eval(locked=[])
check(np.all(ev_l["udot"][6:] == 0.0) and abs(ev_f["udot"][6]) > 1.0,
      "eval: locked= gives the reduced system's u_dot (0 for the locked speeds), [] none locked")

# ---- the LQR example, reduced
r = subprocess.run([sys.executable, os.path.join(ROOT, "examples", "python", "lqr_slew.py"), "--t-end", "200"],
                   check=True, capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=os.path.join(args.build, "python")))
res = json.loads(r.stdout.strip().splitlines()[-1])
print("      LQR example:", res)
check(res["closed_loop_slowest_pole"] < 0, "LQR: the linear closed loop is stable")
check(res["settling_time_s"] < 200 and res["final_error_deg"] < 0.01, "LQR: the nonlinear flexible slew settles")
check(res["peak_tip_deflection_m"] < 1e-3, "LQR: array tips stay within 1 mm")
check(res["peak_motor_torque_Nm"] <= 0.3 + 1e-12, "LQR: the torque limit holds")

print(f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)
