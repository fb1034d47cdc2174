#!/usr/bin/python3
"""`import kanegen` (python/kanegen_python.cpp) checked against the C++ side
and against physics; run by ctest with Debian's python3 and numpy:

    test_python_module.py --build BUILD_DIR --slew-sim PATH

  - eval: the generated and generic engines agree; u_dot solves M u_dot = F;
  - the same PD slew controller written in Python gives the trajectory of
    the C++ simulator with it compiled in (examples/gnc_slew);
  - results as data: a Run (t, q, u, inputs, outputs by name, columns, the
    summary as a dict: the wheel motors keep H);
  - runtime parameters changed from Python without a compile (the JIT cache
    untouched), per call or for good, equal to the generic engine's;
  - a closed-loop sweep in the C++ simulator (slew_sim sweep): the same
    tables on 1 and 2 threads, merged shards and mpirun; from Python with
    the law in Python: the same draws and metrics; run k alone = the table;
  - linearize: a pendulum's A is the closed form; frame="lvlh" gives the CLI's
    linear model about the orbit frame;
  - Run.view writes the 3D view's page the CLI writes for the same run; Model.view the initial state;
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
ap.add_argument("--mpirun", default="")
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

# ---- the PD slew of examples/gnc_slew/slew_controller.cpp, in Python (examples/gnc_slew/slew_pd.py)
sys.path.insert(0, os.path.join(ROOT, "examples", "gnc_slew"))
from slew_pd import pd_law  # noqa: E402
pd = pd_law(gen.output_names)


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
check(len(set(run.columns)) == len(run.columns), "simulate: no column name repeats")
check(set(run.q) == set(gen.q_names) and set(run.u) == set(gen.u_names)
      and not np.array_equal(run.q["rw_z.angle"], run.u["rw_z.angle_rate"]),
      "simulate: q and u grouped by name, a rate never under its coordinate's name")
check(set(run.outputs) == set(gen.output_names), "simulate: outputs grouped by name")

check(run.summary["integrator"] == "cvode-adams" or run.summary["integrator"] != "", "simulate: the summary names the integrator")
check(run.summary["H_drift"] < 1e-9 and math.isnan(run.summary["energy_drift"])
      and "energy not conserved" in run.summary["accuracy"],
      f"simulate: internal motor torques keep H ({run.summary['H_drift']:.1e}); energy ruled out, said why")
check(run.q.values.shape == (len(run.t), gen.nq) and run.q.names == gen.q_names
      and np.array_equal(run.q.values[:, gen.q_names.index("bus.qz")], run.q["bus.qz"]),
      "simulate: Signals as a 2-D array with names, and by name")

# ---- runtime parameters from Python, no compile
cache = os.environ.get("KANEGEN_CACHE_DIR", "")


def cache_listing():
    if not cache or not os.path.isdir(cache):
        return None
    # this model's entries only: tests running beside this one fill the same cache with other models
    return sorted((f, os.path.getmtime(os.path.join(cache, f))) for f in os.listdir(cache)
                  if f.startswith("slew_spacecraft"))


before = cache_listing()
check("array_a.damping_ratio1" in gen.parameter_names and "bus.inertia.zz" in gen.parameter_names,
      "parameters: the model's own and its damping ratios are runtime parameters")
nominal = gen.parameters
base = gen.simulate(20.0, dt_out=0.5, controller=pd, period=0.1)
stiff = gen.simulate(20.0, dt_out=0.5, controller=pd, period=0.1,
                     parameters={"array_a.damping_ratio": 0.05, "bus.inertia.zz": 700.0})
check(gen.parameters == nominal, "parameters=: for that call only")
gen.set_parameters({"array_a.damping_ratio": 0.05, "bus.inertia.zz": 700.0})
again = gen.simulate(20.0, dt_out=0.5, controller=pd, period=0.1)
gnr.set_parameters({"array_a.damping_ratio": [0.05, 0.05, 0.05], "bus.inertia.zz": 700.0})
ref = gnr.simulate(20.0, dt_out=0.5, controller=pd, period=0.1)
d_tip = np.abs(base["tip_a.z"] - stiff["tip_a.z"]).max()
d_same = np.abs(again["tip_a.z"] - stiff["tip_a.z"]).max()
d_gen = np.abs(ref["star_tracker.qz"] - again["star_tracker.qz"]).max()
check(d_tip > 1e-6 and d_same == 0.0 and d_gen < 1e-8,
      f"set_parameters: the changed run differs ({d_tip:.1e}), per call = set ({d_same}), generated = generic ({d_gen:.1e})")
check(before is None or cache_listing() == before, "parameters changed without a compile (the JIT cache untouched)")
gen.set_parameters(nominal)
try:
    gen.set_parameters({"bus.mass": 700.0})
    check(False, "set_parameters refuses a value the code keeps constant")
except KeyError as e:
    check("parameters=['bus.mass']" in str(e), "set_parameters: a value the code keeps constant is refused, saying how")
heavy = kanegen.Model(SLEW, engine="generic", parameters=["bus.mass"])
heavy.set_parameters({"bus.mass": 1200.0})
check(abs(heavy.eval(inputs={"motor_x": 0.0})["M"][0, 0] - (1200.0 + 12.0 + 40.0)) < 1e-9,
      "Model(parameters=[...]): more runtime parameters (bus.mass: M's translational entry)")

# ---- a closed-loop sweep: C++ (the controller compiled into slew_sim) and Python
SWEEP = os.path.join(ROOT, "tests", "data", "sweeps", "slew_closed_loop.yaml")
TABLES = ["runs.csv", "summary.json", "summary.md", "envelope_star_tracker.qz.csv"]


def slew_sweep(*extra, prefix=()):
    r = subprocess.run([*prefix, args.slew_sim, "sweep", SWEEP, "--no-progress", *extra], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stdout, r.stderr)
    return r.returncode == 0


def same(a, b):
    return all(open(os.path.join(a, f), "rb").read() == open(os.path.join(b, f), "rb").read() for f in TABLES)


with tempfile.TemporaryDirectory() as d:
    t1, t2, s0, s1, merged, mpi, pyd = (os.path.join(d, n) for n in ("t1", "t2", "s0", "s1", "m", "mpi", "py"))
    check(slew_sweep("-o", t1, "--threads", "1") and slew_sweep("-o", t2, "--threads", "2") and same(t1, t2),
          "closed-loop sweep (slew_sim sweep): identical tables on 1 and 2 threads")
    check(slew_sweep("-o", s0, "--shard", "0/2") and slew_sweep("-o", s1, "--shard", "1/2")
          and slew_sweep("--merge", s0, s1, "-o", merged) and same(t1, merged),
          "closed-loop sweep: two shards merged give identical tables")
    if args.mpirun:
        check(slew_sweep("-o", mpi, prefix=(args.mpirun, "--allow-run-as-root", "--oversubscribe", "-np", "3"))
              and same(t1, mpi), "closed-loop sweep under mpirun -np 3: identical tables")
    rows = list(csv.DictReader(open(os.path.join(t1, "runs.csv"))))
    check(len(rows) == 6 and all(r["status"] == "ok" for r in rows), "closed-loop sweep: 6 runs, all ok")
    py = kanegen.sweep(SWEEP, controller=pd, period=0.1, output=pyd)
    same_draws = all(float(rows[k][n]) == py["values"][n][k] for k in range(6)
                     for n in ("bus.inertia.xx", "bus.inertia.zz", "array_damping"))
    worst = max(abs(float(rows[k][n]) - py["metrics"][n][k]) / max(1e-6, abs(float(rows[k][n])))
                for k in range(6) for n in ("final_qz", "peak_rate_z", "peak_tip_a"))
    check(same_draws and worst < 1e-7,
          f"kanegen.sweep with the law in Python: the same draws, metrics within {worst:.1e} of the C++ sweep")
    check(max(abs(float(r["Hz_final"])) for r in rows) < 1e-9,
          "closed-loop sweep: H_z stays 0 under the wheel motors in every run")
    one = os.path.join(d, "run3.csv")
    subprocess.run([args.slew_sim, "sweep", SWEEP, "--run", "3", "-o", one], check=True, capture_output=True)
    last = list(csv.DictReader(open(one)))[-1]
    check(float(last["star_tracker.qz"]) == float(rows[3]["final_qz"]),
          "closed-loop sweep: run 3 replayed alone ends where the table says")
    # run 3 by hand: a Python model with run 3's values, simulated once
    r3 = gen.simulate(60.0, dt_out=0.5, controller=pd, period=0.1, integrator="rkf78", rtol=1e-10, atol=1e-12,
                      parameters={"bus.inertia.xx": float(rows[3]["bus.inertia.xx"]),
                                  "bus.inertia.yy": float(rows[3]["bus.inertia.yy"]),
                                  "bus.inertia.zz": float(rows[3]["bus.inertia.zz"]),
                                  "array_a.damping_ratio": float(rows[3]["array_damping"]),
                                  "array_b.damping_ratio": float(rows[3]["array_damping"])})
    check(abs(r3["star_tracker.qz"][-1] - float(rows[3]["final_qz"])) < 1e-8,
          "closed-loop sweep: run 3 equals a single simulate of its draw")

# ---- linearize: pendulum closed form
pend = kanegen.Model(os.path.join(ROOT, "models", "pendulum.yaml"))
lin = pend.linearize(q=[math.pi / 2])
check(lin["equilibrium"] and abs(lin["A"][1, 0] + 9.81) <= 1e-13 and lin["A"][0, 1] == 1.0,
      "linearize: pendulum A = [0 1; -g/L 0] hanging")

# ---- linearize about the orbit frame (frame="lvlh"): the CLI's linear model, the same names
gg_path = os.path.join(ROOT, "models", "gravity_gradient_boom.yaml")
lin_o = kanegen.Model(gg_path, engine="generic").linearize(frame="lvlh")
cli_o = json.loads(subprocess.run([os.path.join(args.build, "bin", "kanegen"), "linearize", gg_path, "--frame", "lvlh",
                                   "--engine", "generic", "--quiet"], check=True, capture_output=True,
                                  text=True).stdout)
A_cli = np.array(cli_o["A"])
check(lin_o["frame"] == "lvlh" and lin_o["state_names"] == cli_o["state_names"]
      and lin_o["state_names"][:3] == ["q.bus.lvlh.x", "q.bus.lvlh.y", "q.bus.lvlh.z"]
      and np.max(np.abs(lin_o["A"] - A_cli)) <= 1e-12 * np.max(np.abs(A_cli)),
      "linearize(frame='lvlh'): the CLI's A and state names (the root relative to the orbit frame)")

# ---- events: the probe separation model's events and latch as the CLI reports them
sep = kanegen.Model(os.path.join(ROOT, "models", "probe_separation.yaml"), engine="generic")
srun = sep.simulate(8.0, dt_out=0.1, integrator="rkf78")
names = [e["name"] for e in srun.events]
latch = srun.events[-1] if srun.events else {}
check(names == ["eject", "separation"] and latch.get("energy_lost", 0) > 0
      and abs(srun.q["plate.disp"][-1] - 0.2) < 1e-9 and srun.u["plate.disp_rate"][-1] == 0.0,
      "simulate: events fire in Python as in the CLI (eject, then separation at the end of the stroke, latched)")
# a state with the plate free from the start: the eject event then finds it free (ignored), the spring drives at once
free_run = sep.simulate(2.0, dt_out=0.1, integrator="rkf78", locked=["probe"])
check([e["name"] for e in free_run.events] == ["separation"] and free_run.events[0]["t"] < 1.0,
      "simulate: locked= sets the locks at the start (the plate free, the separation within the first second)")
ev_l = sep.eval(locked=["plate", "probe"])
ev_f = sep.eval(locked=[])
check(np.all(ev_l["udot"][6:] == 0.0) and abs(ev_f["udot"][6]) > 1.0,
      "eval: locked= gives the reduced system's u_dot (0 for the locked speeds), [] none locked")

# ---- the 3D view from Python: Run.view gives the page the CLI gives for the same run's CSV; Model.view the
# initial state
def page_data(path):
    text = open(path).read()
    start = text.index("const KANEGEN_VIEW = ") + len("const KANEGEN_VIEW = ")
    return json.loads(text[start:text.index(";</script>", start)].replace("<\\/", "</"))


with tempfile.TemporaryDirectory() as d:
    page = srun.view(os.path.join(d, "sep.html"), frames=30)
    csv_path = os.path.join(d, "sep.csv")
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        cols = srun.columns
        w.writerow(list(cols))
        for k in range(len(srun)):
            w.writerow([repr(float(cols[n][k])) for n in cols])
    ev_path = os.path.join(d, "sep.events.csv")
    with open(ev_path, "w") as f:
        f.write("t,name,action,bodies,energy_lost\n")
        for e in srun.events:
            f.write(f"{e['t']!r},{e['name']},{e['action']},{e['bodies']},{e['energy_lost']!r}\n")
    subprocess.run([os.path.join(args.build, "bin", "kanegen"), "view", os.path.join(ROOT, "models", "probe_separation.yaml"),
                    csv_path, "--events", ev_path, "--frames", "30", "-o", os.path.join(d, "cli.html")],
                   check=True, capture_output=True)
    py_data, cli_data = page_data(page), page_data(os.path.join(d, "cli.html"))
    same = all(py_data[k] == cli_data[k] for k in ("t", "rows", "poses", "joints", "nodes", "events", "locked", "columns"))
    check(page.endswith("sep.html") and same and len(py_data["t"]) <= 30 + 2 * len(srun.events),
          f"Run.view: the page's frames ({len(py_data['t'])}), poses, events and locks are the CLI's for the same run")
    m0 = page_data(sep.view(os.path.join(d, "model.html")))
    check(len(m0["t"]) == 1 and len(m0["bodies"]) == len(cli_data["bodies"]), "Model.view: the initial state, every body")

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
