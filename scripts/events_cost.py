#!/usr/bin/python3
"""The cost of a run per time event (issue 34): a hinge locked and released
alternately N times, N = 1,000 / 10,000 / 100,000, run by `kanegen simulate`
(generic engine, rk4, an event every second); prints wall time, time per event and peak memory.

    events_cost.py --kanegen build/bin/kanegen [--counts 1000 10000 100000]
"""
import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time


def model_text(n, spacing):
    head = """name: many_events
gravity: [0, -9.81, 0]
bodies:
  - name: b
    parent: ground
    mass: 1
    com: [0, -1, 0]
    inertia: [0.01, 0.01, 0.01, 0, 0, 0]
    joint: {type: revolute, axis: [0, 0, 1]}
initial:
  q: {b.angle: 0.5}
events:
"""
    # compact (100,000 events stay below the 4 MiB model-file limit)
    lines = [f"- {{name: e{k},at: {spacing * (k + 1):.9g},{'release' if k % 2 else 'lock'}: [b]}}\n" for k in range(n)]
    return head + "".join(lines)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--kanegen", required=True)
    ap.add_argument("--counts", type=int, nargs="+", default=[1000, 10000, 100000])
    args = ap.parse_args()
    spacing = 1.0  # s between events; rk4 steps of 0.25 s
    print(f"{'events':>8} {'wall s':>8} {'us/event':>9} {'peak MB':>8}")
    with tempfile.TemporaryDirectory() as d:
        for n in args.counts:
            path = os.path.join(d, f"events_{n}.yaml")
            with open(path, "w") as f:
                f.write(model_text(n, spacing))
            t_end = spacing * (n + 1)
            cmd = ["/usr/bin/time", "-f", "%M", args.kanegen, "simulate", path, "--engine", "generic",
                   "--integrator", "rk4", "--h", "0.25", "--t-end", f"{t_end:.9g}", "--dt-out", f"{t_end:.9g}",
                   "--no-progress", "-o", os.path.join(d, "out.csv")]
            t0 = time.monotonic()
            r = subprocess.run(cmd, capture_output=True, text=True)
            wall = time.monotonic() - t0
            if r.returncode != 0:
                sys.exit(f"kanegen failed on {n} events:\n{r.stderr}")
            peak_mb = int(r.stderr.strip().splitlines()[-1]) / 1024
            print(f"{n:>8} {wall:>8.2f} {1e6 * wall / n:>9.1f} {peak_mb:>8.0f}")


if __name__ == "__main__":
    main()
