#!/usr/bin/python3
"""Explorer I, flexible against rigid-hinge antennas: one figure, two columns.

    plot_explorer_compare.py FLEX.csv RIGID.csv [--body bus] [--labels A B] -o OUT.png
                             [--antennas OUT2.png] [--tip-shape S]

Both CSVs come from `kanegen simulate` of models/explorer1.yaml and
models/explorer1_rigid.yaml (outputs energy and momentum). Rows of the figure:
the bus angular velocity components in body axes (the paper's Fig. 6), the
nutation angle (bus z axis against H), the relative drift of |H|, and T.
With --antennas, a second figure: the flexible antenna ant1's modal
coordinates (times --tip-shape, the tip displacement per unit eta, if given)
and the rigid antenna ant1's hinge angle (times its length, 0.56 m).
Prints, for each run: the 45-degree crossing time (linear interpolation), the
final nutation angle (last sample and mean over the last 5 % of the run), the
largest |H| relative drift, T at the start and end and whether T + V ever rises.
Run with /usr/bin/python3 (numpy, matplotlib). Exit status 2 on a missing file
or column.
"""
import argparse
import os
import sys

import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_simulation import History, InputError, nutation  # noqa: E402

DPI = 100


def metrics(h, body):
    h.require([f"{body}.{c}" for c in ("qw", "qx", "qy", "qz", "wx", "wy", "wz")] + ["Hx", "Hy", "Hz", "T", "V"],
              "bus attitude and rates, energy and momentum")
    th = nutation(h, body, "z", np.eye(3))
    t = h.t
    t45 = float("nan")
    above = np.nonzero(th > 45)[0]
    if th[0] < 45 and above.size:
        k = above[0]
        t45 = t[k - 1] + (45 - th[k - 1]) * (t[k] - t[k - 1]) / (th[k] - th[k - 1])
    H = np.sqrt(h.col("Hx") ** 2 + h.col("Hy") ** 2 + h.col("Hz") ** 2)
    dH = H / H[0] - 1
    T = h.col("T")
    E = T + h.col("V")
    tail = max(1, len(t) // 20)
    return dict(t=t, th=th, t45=t45, th_end=th[-1], th_tail=float(np.mean(th[-tail:])), dH=dH,
                dH_max=float(np.max(np.abs(dH))), T=T, T0=T[0], T1=T[-1], dE_max=float(np.max(np.diff(E))),
                H0=H[0])


def summary(label, m):
    return (f"{label}: 45 deg at t = {m['t45']:.1f} s; final nutation {m['th_end']:.2f} deg "
            f"(mean of the last 5 %: {m['th_tail']:.2f} deg) at t = {m['t'][-1]:.0f} s; "
            f"|H| = {m['H0']:.5f}, largest relative drift {m['dH_max']:.2e}; "
            f"T {m['T0']:.5f} -> {m['T1']:.5f} J ({100 * (m['T1'] / m['T0'] - 1):.1f} %); "
            f"largest step of T + V {m['dE_max']:+.1e} J")


def compare(hs, labels, body, out):
    ms = [metrics(h, body) for h in hs]
    fig, axes = plt.subplots(4, 2, figsize=(13, 11), sharex="col", sharey="row")
    for c, (h, m, lab) in enumerate(zip(hs, ms, labels)):
        a = axes[0, c]
        for k, comp in enumerate(("wx", "wy", "wz")):
            a.plot(h.t, h.col(f"{body}.{comp}"), lw=0.5, color=f"C{k}", label=f"$\\omega_{comp[1]}$",
                   rasterized=True)
        a.set_title(lab)
        a.set_ylabel("bus angular velocity\n(body axes) [rad/s]")
        a.legend(loc="upper right")
        a = axes[1, c]
        a.plot(m["t"], m["th"], lw=0.8, color="C3", rasterized=True)
        a.axhline(45, ls="--", lw=0.7, color="gray")
        a.axhline(90, ls=":", lw=0.7, color="gray")
        if np.isfinite(m["t45"]):
            a.axvline(m["t45"], ls="--", lw=0.7, color="C0")
            a.annotate(f"45° at {m['t45']:.0f} s", (m["t45"], 45), xytext=(6, -16), textcoords="offset points")
        a.annotate(f"end: {m['th_end']:.2f}°", (m["t"][-1], m["th_end"]), xytext=(-70, -18),
                   textcoords="offset points")
        a.set_ylim(0, 95)
        a.set_ylabel("nutation: bus z vs H [deg]")
        a = axes[2, c]
        a.plot(m["t"], m["dH"], lw=0.8, color="C4", rasterized=True)
        a.set_ylabel("|H| relative drift")
        a.ticklabel_format(axis="y", style="sci", scilimits=(0, 0))
        a = axes[3, c]
        a.semilogy(m["t"], m["T"], lw=0.8, color="C2", rasterized=True)
        a.set_ylabel("kinetic energy T [J]")
        a.set_xlabel("time [s]")
    for a in axes.flat:
        a.grid(True, alpha=0.4)
    fig.tight_layout()
    fig.savefig(out, dpi=DPI)
    plt.close(fig)
    return ms


def antennas(hf, hr, labels, tip_shape, out):
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    s = tip_shape if tip_shape else 1.0
    unit = "tip displacement [m]" if tip_shape else "modal coordinate"
    for k, (n, lab) in enumerate((("ant1.eta1", "flap (eta1)"), ("ant1.eta2", "lead-lag (eta2)"))):
        hf.require([n], "the flexible antenna's modal coordinates")
        a1.plot(hf.t, s * hf.col(n), lw=0.5, color=f"C{k}", label=lab, rasterized=True)
    a1.set_title(f"{labels[0]}: antenna ant1")
    a1.set_ylabel(unit)
    a1.legend(loc="upper right")
    hr.require(["ant1.angle"], "the rigid antenna's hinge angle")
    a2.plot(hr.t, 0.56 * hr.col("ant1.angle"), lw=0.5, color="C3", label="0.56 m x hinge angle", rasterized=True)
    a2.set_title(f"{labels[1]}: antenna ant1")
    a2.set_ylabel("tip displacement [m]")
    a2.set_xlabel("time [s]")
    a2.legend(loc="upper right")
    for a in (a1, a2):
        a.grid(True, alpha=0.4)
    fig.tight_layout()
    fig.savefig(out, dpi=DPI)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description="Explorer I: flexible against rigid-hinge antennas, side by side.")
    ap.add_argument("flex_csv", help="kanegen simulate CSV of models/explorer1.yaml")
    ap.add_argument("rigid_csv", help="kanegen simulate CSV of models/explorer1_rigid.yaml")
    ap.add_argument("-o", "--output", required=True, help="PNG of the two-column comparison")
    ap.add_argument("--antennas", help="also write this PNG of the antenna deflections")
    ap.add_argument("--tip-shape", type=float, default=None,
                    help="tip displacement per unit modal coordinate of the flexible antenna (m)")
    ap.add_argument("--body", default="bus", help="the free body (default bus)")
    ap.add_argument("--labels", nargs=2, default=("flexible antennas (explorer1)",
                                                  "rigid hinged antennas (explorer1_rigid)"))
    args = ap.parse_args(argv)
    try:
        hs = [History(args.flex_csv), History(args.rigid_csv)]
        d = os.path.dirname(args.output)
        if d:
            os.makedirs(d, exist_ok=True)
        ms = compare(hs, args.labels, args.body, args.output)
        for lab, m in zip(args.labels, ms):
            print(summary(lab, m))
        print(args.output)
        if args.antennas:
            antennas(hs[0], hs[1], args.labels, args.tip_shape, args.antennas)
            print(args.antennas)
    except InputError as e:
        print(f"plot_explorer_compare.py: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
