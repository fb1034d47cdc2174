#!/usr/bin/python3
"""Plots a sweep's results (kanegen sweep ... -o DIR): a histogram of every
metric and of every dispersed value (DIR/histograms.png) and each recorded
percentile envelope (DIR/envelope_<column>.png). Debian's python3 with numpy
and matplotlib:

    /usr/bin/python3 scripts/plot_sweep.py DIR
"""
import csv
import glob
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

if len(sys.argv) != 2:
    sys.exit(__doc__)
d = sys.argv[1]
rows = list(csv.DictReader(open(os.path.join(d, "runs.csv"))))
summary = json.load(open(os.path.join(d, "summary.json")))
names = list(summary["metrics"]) + list(summary["dispersions"])
ok = [r for r in rows if r["status"] == "ok"]
n = len(names)
cols = min(3, max(1, n))
fig, axes = plt.subplots(math.ceil(n / cols), cols, figsize=(4.5 * cols, 3.2 * math.ceil(n / cols)), squeeze=False)
for ax, name in zip(axes.flat, names):
    x = np.array([float(r[name]) for r in ok])
    x = x[np.isfinite(x)]
    ax.hist(x, bins=min(40, max(5, len(x) // 10)))
    missing = len(ok) - len(x)
    ax.set_title(name + (f" ({missing} runs: never)" if missing else ""), fontsize=9)
    ax.set_ylabel("runs")
for ax in list(axes.flat)[n:]:
    ax.axis("off")
fig.suptitle(f"{summary['model']}: {summary['runs']} runs, {summary['failed']} failed")
fig.tight_layout()
fig.savefig(os.path.join(d, "histograms.png"), dpi=100)
print(os.path.join(d, "histograms.png"))
for path in sorted(glob.glob(os.path.join(d, "envelope_*.csv"))):
    col = os.path.basename(path)[len("envelope_"):-4]
    e = list(csv.DictReader(open(path)))
    t = np.array([float(r["t"]) for r in e])
    fig, ax = plt.subplots(figsize=(7, 4))
    for lo, hi, a in (("min", "max", 0.15), ("p5", "p95", 0.35)):
        ax.fill_between(t, [float(r[lo]) for r in e], [float(r[hi]) for r in e], alpha=a, color="C0", label=f"{lo} - {hi}")
    ax.plot(t, [float(r["p50"]) for r in e], color="C0", label="median")
    ax.set_xlabel("t (s)")
    ax.set_ylabel(col)
    ax.legend()
    fig.tight_layout()
    out = os.path.join(d, f"envelope_{col}.png")
    fig.savefig(out, dpi=100)
    print(out)
