#!/usr/bin/python3
"""Plot a `kanegen simulate` CSV time history (interface.md) into PNG files; with --model, also its 3D view
(`kanegen view`: <prefix>_view.html, one offline HTML file; the run's events table RUN.events.csv beside the
CSV names its events).

    plot_simulation.py OUT.csv [--model MODEL.yaml] [--axis x|y|z] [--prefix P] -o DIR

Writes, when the columns are there:
  P_omega_<body>.png     angular velocity components of every free body (body frame),
                         and |omega| along / across the chosen body axis (log scale)
  P_nutation_<body>.png  nutation angle of every free body: angle between its body axis
                         (--axis, default z) and the angular momentum H, in body axes
  P_energy.png           T, V and T + V
  P_momentum.png         |H| and its relative drift
  P_reactions.png        joint reaction force and torque magnitudes per body
  P_joints_<type>.png    joint coordinates, one plot per joint type (revolute, universal,
                         gimbal, prismatic, cylindrical, planar; without --model: angles,
                         displacements); a coordinate that spins (more than a turn, its
                         rate of one sign, e.g. a reaction wheel) is plotted as its rate
                         in P_spinning.png instead, so it does not swamp the others
  P_modes.png            modal coordinates, one panel per flexible body
  P_sensor_<name>.png    each sensor of the model (outputs with a name), its components;
                         attitude_lvlh as roll, pitch, yaw relative to the orbit frame in
                         degrees, orbit_elements as a [km], e, i/raan/argp and nu [deg]
  P_inputs.png           the model's named inputs (motor torques, thrusts, ...)
A coordinate's rate is the column of its name with _rate (model-format.md, Joints).
P is the model name (from --model) or the CSV file stem, unless --prefix is given.
Prints the files written. Exit status 2 on a missing file or column.
Run with /usr/bin/python3 (needs numpy, matplotlib; PyYAML for --model).
"""
import argparse
import math
import os
import shutil
import subprocess
import sys

import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DPI = 100
QUAT = ("qw", "qx", "qy", "qz")
OMEGA = ("wx", "wy", "wz")
WRENCH = ("fx", "fy", "fz", "tx", "ty", "tz")
AXES = {"x": 0, "y": 1, "z": 2}


class InputError(Exception):
    """A missing or unusable input: reported with exit status 2."""


# ---------------------------------------------------------------- rotations

def save_atomically(fig, path, **kw):
    """The PNG appears complete or not at all: written beside the target, then renamed."""
    import os
    import tempfile
    d = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".kanegen-", suffix=".png", dir=d)
    os.close(fd)
    try:
        fig.savefig(tmp, format="png", **kw)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise

def quat_to_R(w, x, y, z):
    """R(quat) of dynamics.md (child -> parent components); arrays broadcast. Normalizes."""
    n = np.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def rot_axis(a, th):
    a = np.asarray(a, float)
    a = a / np.linalg.norm(a)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(th) * K + (1 - math.cos(th)) * K @ K


def rotation_of(spec):
    """Joint-frame rotation of a model file (model-format.md), as a 3x3 matrix."""
    if not spec:
        return np.eye(3)
    if "rpy" in spec:
        r, p, y = spec["rpy"]
        return rot_axis([0, 0, 1], y) @ rot_axis([0, 1, 0], p) @ rot_axis([1, 0, 0], r)
    if "matrix" in spec:
        return np.asarray(spec["matrix"], float)
    if "axis_angle" in spec:
        a, th = spec["axis_angle"]
        return rot_axis(a, th)
    if "quaternion" in spec:
        return quat_to_R(*[float(v) for v in spec["quaternion"]])
    raise InputError(f"unknown rotation {spec!r}")


# ---------------------------------------------------------------- inputs
class History:
    """The CSV of `kanegen simulate`: a header of unique names, then rows."""

    def __init__(self, path):
        if not os.path.isfile(path):
            raise InputError(f"{path}: no such file")
        with open(path) as f:
            header = f.readline().strip()
        if not header:
            raise InputError(f"{path}: empty file, expected a kanegen simulate CSV")
        self.path = path
        self.names = [h.strip() for h in header.split(",")]
        # a CSV from before 2026-12-01 named a rate as its coordinate: its second column of a name is the rate
        seen = set()
        for i, n in enumerate(self.names):
            if n in seen and f"{n}_rate" not in self.names:
                self.names[i] = f"{n}_rate"
            seen.add(n)
        try:
            self.data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
        except ValueError as e:
            raise InputError(f"{path}: unreadable CSV data ({e})")
        if self.data.shape[0] == 0:
            raise InputError(f"{path}: no data rows")
        if self.data.shape[1] != len(self.names):
            raise InputError(f"{path}: {self.data.shape[1]} values per row but {len(self.names)} header names")
        self.index = {}
        for i, n in enumerate(self.names):
            self.index.setdefault(n, []).append(i)
        self.require(["t"], "the time column")
        self.t = self.col("t")

    def has(self, *names):
        return all(n in self.index for n in names)

    def col(self, name, occurrence=0):
        return self.data[:, self.index[name][occurrence]]

    def require(self, names, what):
        missing = [n for n in names if n not in self.index]
        if missing:
            raise InputError(f"{self.path}: missing column(s) {', '.join(missing)} ({what})")


def load_model(path):
    if not os.path.isfile(path):
        raise InputError(f"{path}: no such file")
    try:
        import yaml
    except ImportError:
        raise InputError("--model needs PyYAML (run with /usr/bin/python3)")
    with open(path) as f:
        try:
            m = yaml.safe_load(f)
        except yaml.YAMLError as e:
            raise InputError(f"{path}: not valid YAML ({e})")
    if not isinstance(m, dict) or not isinstance(m.get("bodies"), list):
        raise InputError(f"{path}: no 'bodies' list; expected a kanegen model file")
    return m


# ---------------------------------------------------------------- plots
def finish(fig, ax_list, path, written):
    for ax in ax_list:
        ax.grid(True, alpha=0.4)
    fig.tight_layout()
    save_atomically(fig, path, dpi=DPI)
    plt.close(fig)
    written.append(path)


def plot_omega(h, body, axis, out, written):
    w = np.stack([h.col(f"{body}.{c}") for c in OMEGA], 1)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for k, c in enumerate(OMEGA):
        a1.plot(h.t, w[:, k], lw=0.6, label=f"$\\omega_{c[1]}$")
    a1.set_ylabel("angular velocity [rad/s]")
    a1.set_title(f"{body}: angular velocity in body axes")
    a1.legend(loc="best")
    i = AXES[axis]
    along = np.abs(w[:, i])
    across = np.sqrt(np.sum(np.delete(w, i, axis=1) ** 2, 1))
    a2.semilogy(h.t, np.maximum(along, 1e-300), lw=0.8, label=f"|$\\omega_{axis}$| (along body {axis})")
    a2.semilogy(h.t, np.maximum(across, 1e-300), lw=0.8, label=f"transverse |$\\omega$| (across body {axis})")
    a2.set_xlabel("time [s]")
    a2.set_ylabel("|angular velocity| [rad/s]")
    a2.legend(loc="best")
    finish(fig, (a1, a2), os.path.join(out, f"{h.prefix}_omega_{body}.png"), written)


def nutation(h, body, axis, R_J):
    q = [h.col(f"{body}.{c}") for c in QUAT]
    R = quat_to_R(*q)                                   # 3x3xN, body -> joint frame
    R = np.einsum("ij,jkn->ikn", R_J, R)                # body -> N (parent is ground)
    H = np.stack([h.col("Hx"), h.col("Hy"), h.col("Hz")], 0)   # 3xN, N components
    HB = np.einsum("jin,jn->in", R, H)                  # R^T H: body components
    Hn = np.linalg.norm(HB, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.where(Hn > 0, HB[AXES[axis]] / Hn, np.nan)
    return np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))


def plot_nutation(h, body, axis, R_J, out, written):
    th = nutation(h, body, axis, R_J)
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot(h.t, th, lw=1.0, color="C3")
    ax.axhline(45, ls="--", lw=0.8, color="gray")
    ax.axhline(90, ls=":", lw=0.8, color="gray")
    msg = f"{body}: nutation (body {axis} vs H) start {th[0]:.2f} deg, end {th[-1]:.2f} deg"
    above = np.nonzero(th > 45)[0]
    if th[0] < 45 and above.size:
        k = above[0]
        # linear interpolation of the 45 deg crossing
        t45 = h.t[k - 1] + (45 - th[k - 1]) * (h.t[k] - h.t[k - 1]) / (th[k] - th[k - 1])
        ax.axvline(t45, ls="--", lw=0.8, color="C0")
        ax.annotate(f"45° at t = {t45:.0f} s", (t45, 45), xytext=(8, -18), textcoords="offset points")
        msg += f", crosses 45 deg at t = {t45:.1f} s"
    print(msg)
    ax.set_ylim(0, 95)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("nutation angle [deg]")
    ax.set_title(f"{body}: angle between body {axis} axis and angular momentum H")
    finish(fig, (ax,), os.path.join(out, f"{h.prefix}_nutation_{body}.png"), written)


def plot_energy(h, out, written):
    T, V = h.col("T"), h.col("V")
    E = T + V
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    a1.plot(h.t, T, lw=2.0, label="T (kinetic)")
    a1.plot(h.t, V, lw=2.0, label="V (potential)")
    a1.plot(h.t, E, "--", lw=1.0, color="k", label="E = T + V")
    a1.set_ylabel("energy [J]")
    a1.set_title("energy")
    a1.legend(loc="best")
    scale = max(abs(E[0]), np.max(np.abs(T)), 1e-300)
    a2.plot(h.t, (E - E[0]) / scale, lw=0.8, color="k")
    a2.set_ylabel("(E - E(0)) / max(|E(0)|, max T)")
    a2.set_xlabel("time [s]")
    a2.set_title("energy change")
    finish(fig, (a1, a2), os.path.join(out, f"{h.prefix}_energy.png"), written)


def plot_momentum(h, out, written):
    H = np.stack([h.col("Hx"), h.col("Hy"), h.col("Hz")], 1)
    Hn = np.linalg.norm(H, axis=1)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for k, c in enumerate("xyz"):
        a1.plot(h.t, H[:, k], lw=0.8, label=f"$H_{c}$")
    a1.plot(h.t, Hn, lw=1.2, color="k", label="|H|")
    a1.set_ylabel("angular momentum [N·m·s]")
    a1.set_title("angular momentum about N's origin (N components)")
    a1.legend(loc="best")
    if Hn[0] > 0:
        a2.plot(h.t, (Hn - Hn[0]) / Hn[0], lw=0.8, color="k")
        a2.set_ylabel("(|H| - |H(0)|) / |H(0)|")
        print(f"|H| relative drift: max {np.max(np.abs(Hn - Hn[0])) / Hn[0]:.2e}")
    else:
        a2.plot(h.t, Hn - Hn[0], lw=0.8, color="k")
        a2.set_ylabel("|H| - |H(0)| [N·m·s]")
    a2.set_xlabel("time [s]")
    a2.set_title("change of |H| (zero when no external torque acts)")
    finish(fig, (a1, a2), os.path.join(out, f"{h.prefix}_momentum.png"), written)


def plot_reactions(h, bodies, out, written):
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for b in bodies:
        f = np.sqrt(sum(h.col(f"{b}.{c}") ** 2 for c in WRENCH[:3]))
        t = np.sqrt(sum(h.col(f"{b}.{c}") ** 2 for c in WRENCH[3:]))
        a1.plot(h.t, f, lw=0.7, label=b)
        a2.plot(h.t, t, lw=0.7, label=b)
    a1.set_ylabel("|force| [N]")
    a1.set_title("joint reaction on each body from its parent")
    a2.set_ylabel("|torque about joint point| [N·m]")
    a2.set_xlabel("time [s]")
    for a in (a1, a2):
        a.legend(loc="best", fontsize="small", ncol=2)
    finish(fig, (a1, a2), os.path.join(out, f"{h.prefix}_reactions.png"), written)


def spins(h, name):
    """A coordinate that turns more than a full turn with a rate of one sign (a wheel)."""
    rate = f"{name}_rate"
    if not name.rsplit(".", 1)[-1].startswith("angle") or not h.has(rate):
        return False
    q, r = h.col(name), h.col(rate)
    return np.ptp(q) > 2 * math.pi and (np.all(r >= 0) or np.all(r <= 0))  # a wheel spun up from rest too


def plot_lines(h, names, title, ylabel, path, written):
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for n in names:
        ax.plot(h.t, h.col(n), lw=0.7, label=n)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(loc="best", fontsize="small", ncol=2)
    finish(fig, (ax,), path, written)


UNITS = {"revolute": "rad", "universal": "rad", "gimbal": "rad", "prismatic": "m", "cylindrical": "rad, m",
         "planar": "m, rad", "angle": "rad", "displacement": "m"}


def plot_joints(h, groups, out, written):
    """groups: {joint type: [coordinate names]}; spinning coordinates go to one plot of rates."""
    spinning = []
    for kind, coords in groups.items():
        still = [n for n in coords if not spins(h, n)]
        spinning += [n for n in coords if n not in still]
        if still:
            plot_lines(h, still, f"{kind} joint coordinates", f"coordinate [{UNITS.get(kind, 'rad or m')}]",
                       os.path.join(out, f"{h.prefix}_joints_{kind}.png"), written)
    if spinning:
        plot_lines(h, [f"{n}_rate" for n in spinning], "spinning joints: rates (their angles grow without bound)",
                   "rate [rad/s]", os.path.join(out, f"{h.prefix}_spinning.png"), written)


def plot_modes(h, modal, out, written):
    """modal: {body: [eta names]}: one panel per flexible body."""
    fig, axes = plt.subplots(len(modal), 1, figsize=(8, 2.6 * len(modal) + 1), sharex=True, squeeze=False)
    for ax, (body, names) in zip(axes[:, 0], modal.items()):
        for n in names:
            ax.plot(h.t, h.col(n), lw=0.7, label=n.rsplit(".", 1)[-1])
        ax.set_ylabel("modal coordinate")
        ax.set_title(f"{body}: modal coordinates")
        ax.legend(loc="best", fontsize="small", ncol=3)
    axes[-1, 0].set_xlabel("time [s]")
    finish(fig, list(axes[:, 0]), os.path.join(out, f"{h.prefix}_modes.png"), written)


def columns_of(h, name):
    """A port's columns: NAME itself (a scalar) or NAME.<component>, in CSV order."""
    return [n for n in h.names if n == name or n.startswith(name + ".")]


# what docs/gnc.md, "Named outputs", says each sensor type reports
SENSOR_UNITS = {"attitude": "quaternion of R_NB", "angular_velocity": "rad/s, body axes", "position": "m, N",
                "velocity": "m/s, N", "acceleration": "m/s², body axes", "specific_force": "m/s², body axes",
                "reaction": "N, N m, body axes", "deflection": "m, body axes",
                "angular_velocity_lvlh": "rad/s, body axes, relative to LVLH", "com_position": "m, N",
                "com_velocity": "m/s, N"}


def plot_attitude_lvlh(h, name, out, written):
    """An attitude_lvlh sensor as roll, pitch and yaw relative to the orbit frame, in degrees."""
    cols = [f"{name}.{c}" for c in ("roll", "pitch", "yaw")]
    h.require(cols, f"sensor {name}")
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for c in cols:
        ax.plot(h.t, np.degrees(h.col(c)), lw=0.7, label=c)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"{name} [deg: rotation vector of R_LB]")
    ax.set_title(f"sensor {name}: attitude relative to LVLH")
    ax.legend(loc="best", fontsize="small")
    finish(fig, (ax,), os.path.join(out, f"{h.prefix}_sensor_{name}.png"), written)


def plot_orbit_elements(h, name, out, written):
    """An orbit_elements sensor in four panels: a [km], e, the plane and perigee angles, the true anomaly [deg]."""
    h.require([f"{name}.{c}" for c in ("a", "e", "i", "raan", "argp", "nu")], f"sensor {name}")
    fig, axs = plt.subplots(4, 1, figsize=(8, 9), sharex=True)
    axs[0].plot(h.t, h.col(f"{name}.a") / 1e3, lw=0.7)
    axs[0].set_ylabel("a [km]")
    axs[1].plot(h.t, h.col(f"{name}.e"), lw=0.7)
    axs[1].set_ylabel("e")
    for c in ("i", "raan", "argp"):
        axs[2].plot(h.t, np.degrees(h.col(f"{name}.{c}")), lw=0.7, label=f"{name}.{c}")
    axs[2].set_ylabel("[deg]")
    axs[2].legend(loc="best", fontsize="small")
    axs[3].plot(h.t, np.degrees(h.col(f"{name}.nu")), lw=0.7)
    axs[3].set_ylabel("nu [deg]")
    axs[3].set_xlabel("time [s]")
    axs[0].set_title(f"sensor {name}: osculating orbit elements")
    finish(fig, axs, os.path.join(out, f"{h.prefix}_sensor_{name}.png"), written)


def plot_sensors(h, sensors, out, written):
    for name, kind in sensors:
        if kind == "attitude_lvlh":
            plot_attitude_lvlh(h, name, out, written)
            continue
        if kind == "orbit_elements":
            plot_orbit_elements(h, name, out, written)
            continue
        cols = columns_of(h, name)
        h.require(cols or [name], f"sensor {name}")
        plot_lines(h, cols, f"sensor {name} ({kind})", f"{name} [{SENSOR_UNITS.get(kind, 'SI units')}]",
                   os.path.join(out, f"{h.prefix}_sensor_{name}.png"), written)


def plot_inputs(h, inputs, out, written):
    cols = [c for n in inputs for c in columns_of(h, n)]
    h.require(cols or inputs, "the model's inputs")
    plot_lines(h, cols, "inputs", "value [N, N m or as declared]", os.path.join(out, f"{h.prefix}_inputs.png"),
               written)


# ---------------------------------------------------------------- main
def joint_coordinates(h, body):
    """The body's joint coordinates in the CSV: its columns with a rate column (model-format.md)."""
    return [n for n in h.names if n.startswith(body + ".") and not n.endswith("_rate") and h.has(n + "_rate")
            and not n[len(body) + 1:].startswith("eta")]


def find_kanegen(given):
    """The kanegen program: --kanegen, else the one beside this script (bin/ of its install or build tree), else
    the one on PATH; None if there is none."""
    if given:
        return given
    here = os.path.dirname(os.path.abspath(__file__))
    for rel in (("..", "..", "..", "bin", "kanegen"), ("..", "build", "bin", "kanegen")):
        p = os.path.normpath(os.path.join(here, *rel))
        if os.access(p, os.X_OK):
            return p
    return shutil.which("kanegen")


def write_view(args, prefix, written):
    """The run's 3D view (kanegen view: one offline HTML file) beside the plots."""
    exe = find_kanegen(args.kanegen)
    if not exe:
        print("note: no kanegen program found (--kanegen): no 3D view written", file=sys.stderr)
        return
    path = os.path.join(args.output, f"{prefix}_view.html")
    cmd = [exe, "view", args.model, args.csv, "-o", path]
    events = os.path.splitext(args.csv)[0] + ".events.csv"
    if os.path.exists(events):
        cmd[4:4] = ["--events", events]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise InputError(f"kanegen view: {r.stderr.strip()}")
    written.append(path)


def run(args):
    h = History(args.csv)
    model = load_model(args.model) if args.model else None
    h.prefix = args.prefix or (model.get("name") if model and model.get("name") else
                               os.path.splitext(os.path.basename(args.csv))[0])

    free, reaction_bodies, rot_J, groups, modal, sensors, inputs = [], [], {}, {}, {}, [], []
    if model:
        outputs = model.get("outputs") or []
        for b in model["bodies"]:
            name, joint = b.get("name"), b.get("joint") or {}
            jt = joint.get("type")
            if jt == "free":
                h.require([f"{name}.{c}" for c in QUAT + OMEGA], f"free body {name}")
                free.append(name)
                if b.get("parent") == "ground":
                    rot_J[name] = rotation_of(joint.get("rotation"))
            elif jt not in ("fixed", "ball") and "motion" not in joint:
                coords = joint_coordinates(h, name)
                if not coords:
                    raise InputError(f"{h.path}: no coordinate columns of {name}'s {jt} joint")
                groups.setdefault(jt, []).extend(coords)
            etas = [n for n in h.names if n.startswith(f"{name}.eta") and not n.endswith("_rate")]
            if b.get("flexible"):
                if not etas:
                    raise InputError(f"{h.path}: no modal coordinate columns of flexible body {name}")
                modal[name] = etas
            if "reactions" in outputs:
                reaction_bodies.append(name)
        for o in outputs:
            if isinstance(o, dict) and o.get("name"):
                sensors.append((o["name"], o.get("type", "sensor")))
        inputs = [i["name"] for i in (model.get("inputs") or []) if isinstance(i, dict) and i.get("name")]
        if "energy" in outputs:
            h.require(["T", "V"], "the model's outputs list energy")
        if "momentum" in outputs:
            h.require(["Hx", "Hy", "Hz"], "the model's outputs list momentum")
        if reaction_bodies:
            h.require([f"{b}.{c}" for b in reaction_bodies for c in WRENCH],
                      "the model's outputs list reactions")
    else:
        # no model: bodies are recognized by their columns, coordinates by their rate columns
        for n in h.names:
            b, _, c = n.rpartition(".")
            if c == "qw" and h.has(*[f"{b}.{x}" for x in QUAT + OMEGA]) and b not in free:
                free.append(b)
                rot_J[b] = np.eye(3)     # assumed: parent ground, identity joint rotation
            if c == "fx" and h.has(*[f"{b}.{x}" for x in WRENCH]) and b not in reaction_bodies:
                reaction_bodies.append(b)
            if b and not c.endswith("_rate") and h.has(n + "_rate"):
                if c.startswith("eta"):
                    modal.setdefault(b, []).append(n)
                elif c.startswith("angle"):
                    groups.setdefault("angle", []).append(n)
                elif c in ("disp", "x", "y"):
                    groups.setdefault("displacement", []).append(n)

    os.makedirs(args.output, exist_ok=True)
    written = []
    for b in free:
        plot_omega(h, b, args.axis, args.output, written)
    if h.has("T", "V"):
        plot_energy(h, args.output, written)
    if h.has("Hx", "Hy", "Hz"):
        plot_momentum(h, args.output, written)
        for b in free:
            if b in rot_J:
                plot_nutation(h, b, args.axis, rot_J[b], args.output, written)
            else:
                print(f"note: {b} is free but not attached to ground; no nutation plot", file=sys.stderr)
    if reaction_bodies:
        plot_reactions(h, reaction_bodies, args.output, written)
    if groups:
        plot_joints(h, groups, args.output, written)
    if modal:
        plot_modes(h, modal, args.output, written)
    if sensors:
        plot_sensors(h, sensors, args.output, written)
    if inputs:
        plot_inputs(h, inputs, args.output, written)
    if not written:
        raise InputError(f"{args.csv}: nothing to plot (no free-body, energy, momentum, reaction, joint, "
                         "sensor or input columns)")
    if args.model:
        write_view(args, h.prefix, written)
    print("wrote:")
    for p in written:
        print("  " + p)


def main(argv=None):
    ap = argparse.ArgumentParser(description="Plot a kanegen simulate CSV time history into PNG files.")
    ap.add_argument("csv", help="CSV written by `kanegen simulate`")
    ap.add_argument("--model", help="the model YAML (gives the body list, joint frames and file prefix)")
    ap.add_argument("-o", "--output", required=True, help="directory for the PNG files (created if needed)")
    ap.add_argument("--axis", choices=("x", "y", "z"), default="z",
                    help="body axis taken as the long (spin) axis for the nutation angle (default z)")
    ap.add_argument("--prefix", help="file name prefix (default: model name or CSV stem)")
    ap.add_argument("--kanegen", help="the kanegen program that writes the 3D view beside the plots (with --model; "
                                      "default: the one beside this script, else on PATH)")
    args = ap.parse_args(argv)
    try:
        run(args)
    except InputError as e:
        print(f"plot_simulation.py: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
