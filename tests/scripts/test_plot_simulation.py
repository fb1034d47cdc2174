#!/usr/bin/python3
"""plot_simulation.py on a run of the slew spacecraft with one wheel spinning
and another spun up from rest by a motor input held: it writes a plot per sensor, the inputs, the modal
coordinates and the revolute joints; the spinning wheel is moved to the plot
of rates (its angle grows by ~1000 rad) while the slow wheels stay in the
joint plot; a missing column is refused with exit status 2. The
gravity-gradient boom satellite's orbit-frame sensors: roll/pitch/yaw relative to
LVLH and the osculating elements get their own plots.

    test_plot_simulation.py --kanegen build/bin/kanegen
"""
import argparse
import importlib.util
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
MODEL = os.path.join(ROOT, "models", "gnc", "slew_spacecraft.yaml")
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--kanegen", required=True)
    a = ap.parse_args()
    spec = importlib.util.spec_from_file_location("plot_simulation", os.path.join(ROOT, "scripts", "plot_simulation.py"))
    ps = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ps)
    with tempfile.TemporaryDirectory() as tmp:
        state = os.path.join(tmp, "state.json")
        with open(state, "w") as f:
            json.dump({"u": {"rw_x.angle_rate": 50.0, "bus.wz": 0.01}, "inputs": {"motor_y": 0.01}}, f)
        csv = os.path.join(tmp, "slew.csv")
        r = subprocess.run([a.kanegen, "simulate", MODEL, "--engine", "generic", "--state", state, "--t-end", "20",
                            "--dt-out", "0.1", "-o", csv], capture_output=True, text=True)
        check(r.returncode == 0, f"simulate ran ({r.stderr.strip()[-200:]})")
        out = os.path.join(tmp, "plots")
        r = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "plot_simulation.py"), csv, "--model", MODEL,
                            "-o", out, "--kanegen", a.kanegen], capture_output=True, text=True)
        check(r.returncode == 0, "plot_simulation.py ran: " + r.stderr.strip())
        pngs = sorted(os.listdir(out)) if os.path.isdir(out) else []
        check("slew_spacecraft_view.html" in pngs, "wrote the 3D view beside the plots (slew_spacecraft_view.html)")
        for name in ("sensor_star_tracker", "sensor_gyro", "sensor_tip_a", "sensor_tip_b", "inputs", "modes",
                     "joints_revolute", "spinning", "momentum", "omega_bus"):
            check(f"slew_spacecraft_{name}.png" in pngs, f"wrote slew_spacecraft_{name}.png")
        h = ps.History(csv)
        check(ps.spins(h, "rw_x.angle"), "the wheel at 50 rad/s spins (plotted as its rate)")
        check(ps.spins(h, "rw_y.angle"), "the wheel the motor spins up from rest (25 rad in 20 s) spins too")
        check(not ps.spins(h, "rw_z.angle"), "the wheel at rest does not")
        check(ps.joint_coordinates(h, "rw_y") == ["rw_y.angle"], "rw_y's coordinate found by its rate column")
        check(ps.columns_of(h, "gyro") == ["gyro.x", "gyro.y", "gyro.z"], "a sensor's columns by its name")
        check(ps.columns_of(h, "motor_y") == ["motor_y"], "an input's column by its name")
        # without the model: coordinates recognized by their rate columns
        out2 = os.path.join(tmp, "plots2")
        r = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "plot_simulation.py"), csv, "-o", out2],
                           capture_output=True, text=True)
        pngs2 = sorted(os.listdir(out2)) if os.path.isdir(out2) else []
        check(r.returncode == 0 and "slew_joints_angle.png" in pngs2 and "slew_spinning.png" in pngs2
              and "slew_modes.png" in pngs2, f"without --model: joints, spinning, modes ({pngs2})")
        # a CSV of the older names (a rate named as its coordinate): read the same way
        old = os.path.join(tmp, "old.csv")
        with open(csv) as f, open(old, "w") as g:
            header, rest = f.readline(), f.read()
            g.write(",".join(c[:-len("_rate")] if c.endswith("_rate") else c for c in header.strip().split(",")) + "\n")
            g.write(rest)
        ho = ps.History(old)
        check(ho.names == h.names and ps.spins(ho, "rw_x.angle"), "an older CSV (rates named as coordinates): same columns")
        # a CSV without a sensor's columns: refused, nothing claimed
        cut = os.path.join(tmp, "cut.csv")
        with open(csv) as f, open(cut, "w") as g:
            for line in f:
                g.write(",".join(line.rstrip("\n").split(",")[:-6]) + "\n")  # drop tip_a, tip_b
        r = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "plot_simulation.py"), cut, "--model", MODEL,
                            "-o", os.path.join(tmp, "plots3")], capture_output=True, text=True)
        check(r.returncode == 2 and "tip_a" in r.stderr, "missing sensor columns: exit 2 naming the sensor: " + r.stderr.strip())
        # in orbit: the orbit-frame sensors of the gravity-gradient boom satellite
        boom = os.path.join(ROOT, "models", "gravity_gradient_boom.yaml")
        bcsv = os.path.join(tmp, "boom.csv")
        r = subprocess.run([a.kanegen, "simulate", boom, "--engine", "generic", "--t-end", "600", "--dt-out", "10",
                            "-o", bcsv], capture_output=True, text=True)
        check(r.returncode == 0, f"simulate the boom satellite ran ({r.stderr.strip()[-200:]})")
        bout = os.path.join(tmp, "boom_plots")
        r = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "plot_simulation.py"), bcsv, "--model", boom,
                            "-o", bout], capture_output=True, text=True)
        check(r.returncode == 0, "plot_simulation.py ran on the boom satellite: " + r.stderr.strip())
        bpngs = sorted(os.listdir(bout)) if os.path.isdir(bout) else []
        for name in ("sensor_att", "sensor_rate", "sensor_com", "sensor_osc"):
            check(f"gravity_gradient_boom_{name}.png" in bpngs, f"wrote gravity_gradient_boom_{name}.png")
        # an attitude_lvlh sensor without its rotation vector columns: refused naming them
        bh = ps.History(bcsv)
        cut = os.path.join(tmp, "boom_cut.csv")
        keep = [k for k, n in enumerate(bh.names) if n not in ("att.roll", "att.pitch", "att.yaw")]
        with open(bcsv) as f, open(cut, "w") as g:
            for line in f:
                cells = line.rstrip("\n").split(",")
                g.write(",".join(cells[k] for k in keep) + "\n")
        r = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "plot_simulation.py"), cut, "--model", boom,
                            "-o", os.path.join(tmp, "boom_plots2")], capture_output=True, text=True)
        check(r.returncode == 2 and "att.roll" in r.stderr, "missing roll/pitch/yaw: exit 2 naming them: " + r.stderr.strip())
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
