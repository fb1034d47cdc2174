#!/usr/bin/env python3
"""The peers' translators against kanegen: MuJoCo's and Simbody's u-dot of every
joint type they have (tests/data/peers/joint_library_peers.yaml: a free base with
a gimbal, a universal on it, a cylindrical with a planar on it, a ball with a
revolute on it; arbitrary frames, per-coordinate springs and dampers, gravity)
equal kanegen's generic u-dot at random states, and the shipped
models/gimbaled_spacecraft.yaml at its initial state. Non-orthogonal gimbal axes
are refused by the Simbody peer (exit 2) and still translated by MuJoCo's."""
import argparse
import json
import math
import os
import random
import subprocess
import sys
import tempfile

import yaml

MODEL = "tests/data/peers/joint_library_peers.yaml"


def run(cmd, expect=0):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != expect:
        sys.exit(f"FAIL: {' '.join(cmd)}: exit {p.returncode} (expected {expect})\n{p.stderr}")
    return p.stdout


def random_state(model, rng):
    """A state with every coordinate and speed non-zero (quaternions random units)."""
    q, u = {}, {}
    for b in model["bodies"]:
        n, t = b["name"], b["joint"]["type"]
        coords = {"free": ["x", "y", "z"], "gimbal": ["angle1", "angle2", "angle3"],
                  "universal": ["angle1", "angle2"], "cylindrical": ["angle", "disp"],
                  "planar": ["x", "y", "angle"], "revolute": ["angle"], "prismatic": ["disp"]}.get(t, [])
        for c in coords:
            q[f"{n}.{c}"] = rng.uniform(-1, 1)
            u[f"{n}.{c}_rate"] = rng.uniform(-1, 1)
        if t in ("free", "ball"):
            v = [rng.gauss(0, 1) for _ in range(4)]
            s = math.sqrt(sum(x * x for x in v))
            for c, x in zip(("qw", "qx", "qy", "qz"), v):
                q[f"{n}.{c}"] = x / s
            for c in ("wx", "wy", "wz"):
                u[f"{n}.{c}"] = rng.uniform(-1, 1)
        if t == "free":
            for c in ("x", "y", "z"):
                u.pop(f"{n}.{c}_rate")
                u[f"{n}.v{c}"] = rng.uniform(-1, 1)
    return {"t": 0, "q": q, "u": u}


def check(kanegen, peers, model_path, state, tmp, tol=1e-12):
    args = [model_path]
    if state is not None:
        path = os.path.join(tmp, "state.json")
        with open(path, "w") as f:
            json.dump(state, f)
        args += ["--state", path]
    ref = os.path.join(tmp, "ref.json")
    with open(ref, "w") as f:
        f.write(run([kanegen, "eval", *args, "--engine", "generic"]))
    worst = {}
    for name, exe in peers.items():
        out = json.loads(run([exe, *args, "--check", ref, "--tol", str(tol)]))
        worst[name] = out["max_rel_diff"]
    return worst


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--kanegen", required=True)
    ap.add_argument("--mujoco")
    ap.add_argument("--simbody")
    a = ap.parse_args()
    peers = {k: v for k, v in (("mujoco", a.mujoco), ("simbody", a.simbody)) if v}
    if not peers:
        sys.exit("FAIL: no peer given")
    with open(MODEL) as f:
        model = yaml.safe_load(f)
    rng = random.Random(7)
    with tempfile.TemporaryDirectory() as tmp:
        worst = {k: 0.0 for k in peers}
        for _ in range(5):
            for k, v in check(a.kanegen, peers, MODEL, random_state(model, rng), tmp).items():
                worst[k] = max(worst[k], v)
        print("joint library, 5 random states: max relative u-dot difference",
              ", ".join(f"{k} {v:.2e}" for k, v in worst.items()))
        for k, v in check(a.kanegen, peers, "models/gimbaled_spacecraft.yaml", None, tmp).items():
            print(f"gimbaled_spacecraft: {k} {v:.2e}")

        # Non-orthogonal gimbal axes: MuJoCo composes any axes; Simbody's Gimbal has
        # orthogonal ones only, so its peer refuses rather than translate wrongly.
        skew = dict(model)
        skew["bodies"] = [dict(b) for b in model["bodies"]]
        gim = next(b for b in skew["bodies"] if b["name"] == "gim")
        gim["joint"] = {k: v for k, v in gim["joint"].items() if k != "sequence"}
        gim["joint"]["axes"] = [[0, 0, 1], [0.6, 0.8, 0], [1, 0, 0]]
        skew_path = os.path.join(tmp, "skew.yaml")
        with open(skew_path, "w") as f:
            yaml.safe_dump(skew, f)
        if "mujoco" in peers:
            print("skewed gimbal: mujoco",
                  f"{check(a.kanegen, {'mujoco': peers['mujoco']}, skew_path, random_state(skew, rng), tmp)['mujoco']:.2e}")
        if "simbody" in peers:
            run([peers["simbody"], skew_path], expect=2)
            print("skewed gimbal: simbody refuses (exit 2)")
    print("OK")


if __name__ == "__main__":
    main()
