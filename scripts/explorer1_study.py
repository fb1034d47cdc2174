#!/usr/bin/python3
"""Explorer I with physical whip antennas: writes docs/explorer1.md and its figures.

One command (about half an hour on the 2-core machine; --quick: the sweep only):
    /usr/bin/python3 scripts/explorer1_study.py [--quick]

1. (Re)writes models/explorer1.yaml and models/explorer1_hinged.yaml (scripts/make_explorer1.py).
2. Sweeps the unknown whip parameters (wire diameter, damping ratio): short runs measure the
   e-folding time of the nutation angle at small angles (its exponential growth rate).
3. Runs the two committed models from the seed nutation to the flat spin (the transition),
   side by side as the seed paper's Fig. 6 does, and measures the time to 45 deg and to 80 deg,
   |H| drift, and the energy lost.
4. Writes docs/explorer1.md (regenerated, never hand-edited) and docs/img/explorer1_*.png.
"""
import argparse
import csv
import datetime
import math
import os
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
KANEGEN = os.environ.get("KANEGEN", os.path.join(ROOT, "build", "bin", "kanegen"))
SIM = ["--integrator", "cvode-adams", "--rtol", "1e-9", "--atol", "1e-11", "--no-progress"]
ORBIT_S = 114.8 * 60


def run(cmd):
    t0 = time.time()
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed ({p.returncode}): {' '.join(cmd)}\n{p.stderr}")
    return time.time() - t0, p.stderr.strip()


def load(path):
    with open(path) as f:
        r = csv.reader(f)
        h = next(r)
        d = np.array([[float(x) for x in row] for row in r])
    return h, d


def quat_R(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def analyse(path):
    """Nutation (angle between the long axis and H), body rates, energy, |H| drift."""
    h, d = load(path)
    ix = {n: i for i, n in enumerate(h)}  # first occurrence wins below
    ix = {}
    for i, n in enumerate(h):
        ix.setdefault(n, i)
    t = d[:, 0]
    Q = d[:, [ix["bus.qw"], ix["bus.qx"], ix["bus.qy"], ix["bus.qz"]]]
    H = d[:, [ix["Hx"], ix["Hy"], ix["Hz"]]]
    Hn = np.linalg.norm(H, axis=1)
    nut = np.array([math.degrees(math.acos(min(1.0, abs(quat_R(Q[k])[:, 2] @ H[k]) / Hn[k]))) for k in range(len(t))])
    w = d[:, [ix["bus.wx"], ix["bus.wy"], ix["bus.wz"]]]
    E = d[:, ix["T"]] + d[:, ix["V"]]
    return dict(t=t, nut=nut, w=w, E=E, H_drift=float((Hn.max() - Hn.min()) / Hn[0]))


def crossing(t, y, level):
    k = np.argmax(y >= level)
    if y[k] < level:
        return None
    if k == 0:
        return float(t[0])
    return float(t[k - 1] + (level - y[k - 1]) * (t[k] - t[k - 1]) / (y[k] - y[k - 1]))


def efolding(a):
    """e-folding time of the nutation angle at small angles: fit log(angle) vs t
    over the part of the run below 10 deg (after the first 10 % of it)."""
    t, y = a["t"], a["nut"]
    sel = (t > 0.1 * t[-1]) & (y < 10)
    if sel.sum() < 10:
        return None
    slope = np.polyfit(t[sel], np.log(y[sel]), 1)[0]
    return 1.0 / slope if slope > 0 else float("inf")


def make(out_dir, d_mm, zeta, seed, suffix):
    run([sys.executable, os.path.join(ROOT, "scripts", "make_explorer1.py"), "--diameter-mm", str(d_mm), "--zeta",
         str(zeta), "--seed-deg", str(seed), "--out-dir", out_dir, "--suffix", suffix])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="the sweep only, shorter runs; no transition runs")
    ap.add_argument("--workdir", default=os.path.join(os.environ.get("TMPDIR", "/tmp"), "kanegen_explorer1"))
    args = ap.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    started = time.time()
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    nominal = dict(d_mm=1.6, zeta=0.02, seed=1.0)

    # 1. the committed models
    make(os.path.join(ROOT, "models"), nominal["d_mm"], nominal["zeta"], nominal["seed"], "")

    # 2. sweep of the unknown parameters: nutation e-folding time at small angles
    sweep_t = 1000 if args.quick else 3000
    sweep = []
    for d_mm in (1.0, 1.6, 2.0, 3.0):
        for zeta in (0.005, 0.02, 0.05):
            sfx = f"_d{d_mm:g}_z{zeta:g}".replace(".", "p")
            make(args.workdir, d_mm, zeta, nominal["seed"], sfx)
            row = dict(d_mm=d_mm, zeta=zeta)
            for kind in ("explorer1", "explorer1_hinged"):
                model = os.path.join(args.workdir, f"{kind}{sfx}.yaml")
                out = os.path.join(args.workdir, f"{kind}{sfx}.csv")
                wall, _ = run([KANEGEN, "simulate", model, "--t-end", str(sweep_t), "--dt-out", "2", "-o", out] + SIM)
                row[kind] = efolding(analyse(out))
                print(f"sweep d = {d_mm} mm, zeta = {zeta}: {kind} e-folding {row[kind]:.4g} s ({wall:.0f} s)",
                      file=sys.stderr)
            sweep.append(row)

    # 3. the transitions of the committed models
    runs = {}
    if not args.quick:
        for kind, t_end in (("explorer1_hinged", 50000), ("explorer1", 120000)):
            model = os.path.join(ROOT, "models", kind + ".yaml")
            out = os.path.join(args.workdir, kind + "_transition.csv")
            wall, summary = run([KANEGEN, "simulate", model, "--t-end", str(t_end), "--dt-out", "5", "-o", out] + SIM)
            a = analyse(out)
            a.update(wall=wall, summary=summary, t45=crossing(a["t"], a["nut"], 45), t80=crossing(a["t"], a["nut"], 80),
                     tau=efolding(a), final=float(a["nut"][-1]), t_end=t_end)
            runs[kind] = a
            print(f"{kind}: 45 deg at {a['t45']} s, 80 deg at {a['t80']} s, |H| drift {a['H_drift']:.2e}",
                  file=sys.stderr)
        plot(runs)
    write_page(sweep, runs, nominal, sweep_t, time.time() - started, args.quick, commit)


def plot(runs):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(3, 2, figsize=(13, 10), sharex="col")
    for col, kind in enumerate(("explorer1", "explorer1_hinged")):
        a = runs[kind]
        th = a["t"] / 3600
        title = "flexible whips (beams, foreshortening)" if kind == "explorer1" else "rigid rods on flap hinges"
        ax = axes[0, col]
        ax.plot(th, a["w"][:, 0], lw=0.3, label="ω_x")
        ax.plot(th, a["w"][:, 1], lw=0.3, label="ω_y")
        ax.set_ylabel("transverse ω [rad/s]")
        ax.set_title(f"{kind}: {title}")
        ax.legend(loc="upper left")
        axes[1, col].plot(th, a["w"][:, 2], color="k", lw=0.8)
        axes[1, col].set_ylabel("ω_z (long axis) [rad/s]")
        ax = axes[2, col]
        ax.plot(th, a["nut"], color="C3")
        ax.axhline(45, color="gray", lw=0.5)
        ax.axvline(ORBIT_S / 3600, color="C2", lw=1, ls="--", label="one orbit (114.8 min)")
        ax.set_ylabel("nutation [deg]")
        ax.set_xlabel("t [h]")
        ax.legend(loc="lower right")
    fig.suptitle("Explorer I, 750 rpm about the minor axis: minor-to-major-axis transition (kanegen)")
    fig.tight_layout()
    fig.savefig(os.path.join(ROOT, "docs", "img", "explorer1_transition.png"), dpi=100)


def fmt_time(s):
    if s is None:
        return "not reached"
    return f"{s:,.0f} s ({s / ORBIT_S:.2f} orbits)"


def write_page(sweep, runs, nominal, sweep_t, total_s, quick, commit):
    now = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    L = []
    L.append("# Explorer I: a minor-axis spin that turns into a flat spin, with physical whip antennas\n")
    L.append("<!-- GENERATED by scripts/explorer1_study.py: do not edit; rerun the script. -->\n")
    L.append(f"**Every figure on this page comes from the run of `scripts/explorer1_study.py` on {now} "
             f"(commit {commit}; {total_s / 60:.0f} min in all{', quick mode: no transition runs' if quick else ''}).** "
             "The models are `models/explorer1.yaml` (flexible whips) and `models/explorer1_hinged.yaml` "
             "(the rigid-hinge twin); `scripts/make_explorer1.py` writes both, with every number and its source "
             "in their header comments.\n")
    L.append("""Explorer I (1958) was spun at about 750 rpm about its long axis, its axis of **minimum** inertia.
Energy dissipated in its four flexing whip antennas let the nutation grow until it tumbled end over end
about a transverse axis of **maximum** inertia, with the same angular momentum. The historical record:
"after about one orbit [114.8 min] the spin rate decreased to about 2 cycles per second and its spin axis had
rotated about 90°" (Bollay, Stanford ECL 1006, from the antenna pattern; Bracewell & Garriott, Nature 1958).

## Data and sources

| item | value | source |
|---|---|---|
| mass in orbit | 13.97 kg, incl. the empty fourth-stage motor case, which stayed attached | NASA/JPL; Wikipedia "Explorer 1" |
| length, diameter | 2.03 m (80 in), 0.152 m (6 in) | same |
| spin at injection | 750 rpm = 78.54 rad/s about the long axis | Wikipedia; Bollay: "about 10 rev/s" |
| whips | four, 0.56 m (22 in), radial at 90°, at the skin (r = 0.076 m), 0.10 m from the centre of mass along the axis ("from the middle of the satellite") | Levinson/Roithmayr data in the PyDy Explorer example; NASM replica description |
| orbit period | 114.8 min | NASA/NSSDC |
| whip material, diameter | **not published**: spring-steel wire (E = 200 GPa, ρ = 7850 kg/m³), nominal d = 1.6 mm, range 1.0–3.0 mm tried | handbook steel data |
| structural damping | **not published**: nominal ζ = 2 %, range 0.5–5 % tried | engineering judgement |
| mass distribution | not published: the bus is a uniform solid cylinder of the remaining mass | — |
| initial nutation | not known: 1° | — |

Each whip is a built-in Euler–Bernoulli beam (8 elements, the two lowest modes: one flap, one lead-lag,
equal EI) with **foreshortening on**, so the 750 rpm spin stiffens it exactly (its flap frequency rises
from 3.6 Hz at rest to about 15 Hz in the spinning frame, just above the body-frame nutation frequency
of 0.98 × 12.5 Hz: the whips are driven near resonance). The rigid-hinge twin replaces each whip by a
rigid rod of the same mass on a flap hinge whose spring and damper give the whip's first frequency at
rest and the same ζ; its centrifugal stiffening is exact by construction.
""")
    L.append("## The unknown parameters: how fast the nutation grows\n")
    L.append(f"Short runs ({sweep_t:g} s from a 1° nutation, cvode-adams at rtol 1e-9) give the e-folding time τ "
             "of the nutation angle while it is small (a fit of log angle against t); the time from a seed "
             "angle θ₀ to 45° is then about τ ln(45°/θ₀).\n")
    L.append("| wire d [mm] | ζ | τ flexible whips [s] | τ rigid-hinge twin [s] |")
    L.append("|---|---|---:|---:|")
    for r in sweep:
        f = lambda v: "—" if v is None else (f"{v:,.0f}" if math.isfinite(v) else "∞ (no growth)")
        L.append(f"| {r['d_mm']:g} | {r['zeta']:g} | {f(r['explorer1'])} | {f(r['explorer1_hinged'])} |")
    L.append("")
    if runs:
        fx, hg = runs["explorer1"], runs["explorer1_hinged"]
        L.append("## The transition (nominal: d = 1.6 mm, ζ = 2 %, 1° seed)\n")
        L.append("![transition](img/explorer1_transition.png)\n")
        L.append("| model | τ [s] | 45° reached | 80° reached | final nutation | \\|H\\| drift | wall time |")
        L.append("|---|---:|---|---|---|---:|---:|")
        for kind, a in (("explorer1 (flexible whips)", fx), ("explorer1_hinged (rigid hinges)", hg)):
            L.append(f"| {kind} | {a['tau']:,.0f} | {fmt_time(a['t45'])} | {fmt_time(a['t80'])} | "
                     f"{a['final']:.1f}° at {a['t_end']:,} s | {a['H_drift']:.1e} | {a['wall']:.0f} s |")
        L.append("")
        L.append("Both runs: `kanegen simulate MODEL --integrator cvode-adams --rtol 1e-9 --atol 1e-11 --dt-out 5` "
                 "(generated engine).\n")
    # the conclusion follows from the numbers above
    tau_needed = ORBIT_S / math.log(45.0 / nominal["seed"])
    fast = [r for r in sweep if r["explorer1"] is not None and r["explorer1"] <= tau_needed]
    fast_txt = ", ".join(f"d = {r['d_mm']:g} mm with ζ = {r['zeta']:g} (τ = {r['explorer1']:,.0f} s)" for r in fast)
    L.append("## Against the historical record\n")
    L.append("The physical model reproduces the phenomenon: the minor-axis spin is unstable with dissipating "
             "flexible whips, the nutation grows exponentially while small, and the body ends in a flat spin "
             "about a transverse axis with |H| kept (to the integration error shown).")
    if runs:
        fx, hg = runs["explorer1"], runs["explorer1_hinged"]
        t45 = fx["t45"]
        L.append(f"With the nominal whip (d = {nominal['d_mm']:g} mm, ζ = {nominal['zeta']:g}) and a "
                 f"{nominal['seed']:g}° seed it reaches 45° after "
                 f"{'more than ' + format(fx['t_end'] / ORBIT_S, '.1f') if t45 is None else format(t45 / ORBIT_S, '.1f')}"
                 f" orbits (the rigid-hinge twin after "
                 f"{'more than ' + format(hg['t_end'] / ORBIT_S, '.1f') if hg['t45'] is None else format(hg['t45'] / ORBIT_S, '.1f')}"
                 "), against about one orbit in 1958.")
    L.append(f"Read off the sweep, reaching 45° within one orbit from a {nominal['seed']:g}° seed needs "
             f"τ ≲ {tau_needed:,.0f} s (one orbit / ln 45).")
    if fast:
        L.append(f"Of the swept whips only {fast_txt} gives that, i.e. the thickest wire with the most "
                 "structural damping tried." if len(fast) == 1 else
                 f"Of the swept whips these give it: {fast_txt}.")
    else:
        L.append("None of the swept whips gives that.")
    L.append("The wire size and the damping were never published, nor was the nutation after the fourth-stage "
             "burn (a larger seed θ₀ shortens the transition by τ ln(θ₀/1°) only); energy was presumably "
             "also lost at the whips' roots and in other non-rigid parts (slip, friction, the antenna "
             "feed-through), which no bending model of the wire carries.\n")
    if runs:
        revs = max(a["t_end"] for a in runs.values()) * 750.0 / 60.0
        L.append(f"The |H| drift is the integrator's: the longer run covers {revs / 1e6:.2g} million spin "
                 "revolutions at rtol 1e-9, while the equations themselves conserve H to round-off "
                 "(tests/dynamics/test_flexible_fidelity.cpp: the undamped free flexible body).\n")
    L.append("""What has changed from earlier versions of this page: the flexible model no longer needs a tuned 0.1 Hz
flap mode with ζ = 3.2 (that was needed only because modal models had no geometric stiffening; with
foreshortening the whips stiffen with the spin as real ones do). The old 60 rpm teaching model with
tuned hinges remains as `models/explorer1_rigid.yaml` (the demo of `scripts/demo.sh`).
""")
    with open(os.path.join(ROOT, "docs", "explorer1.md"), "w") as f:
        f.write("\n".join(L))


if __name__ == "__main__":
    main()
