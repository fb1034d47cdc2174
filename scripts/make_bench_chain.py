#!/usr/bin/python3
"""Writes an arbitrary-geometry serial chain like those of ../shared/bench-models/:
random unit revolute axes, joint frames rotated by random roll-pitch-yaw, random
joint positions, masses, centres of mass and full (physical) inertia tensors,
joint springs and dampers, gravity, fixed base. Another draw (--seed) gives
another model of the same kind, for the speed targets' "any others made the
same way".

  /usr/bin/python3 scripts/make_bench_chain.py N [--seed S] [-o FILE]
"""
import argparse
import math
import random
import sys


def unit(rng):
    while True:
        v = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in v))
        if n > 1e-3:
            return [x / n for x in v]


def inertia(rng, mass):
    """Full inertia about the com: R diag(a, b, c) R^T with triangle inequalities."""
    while True:
        d = [rng.uniform(0.2, 1.0) * mass * 0.02 for _ in range(3)]
        if d[0] + d[1] > d[2] and d[1] + d[2] > d[0] and d[0] + d[2] > d[1]:
            break
    # random rotation from a random unit quaternion
    q = [rng.gauss(0, 1) for _ in range(4)]
    n = math.sqrt(sum(x * x for x in q))
    w, x, y, z = (c / n for c in q)
    R = [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
         [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
         [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
    I = [[sum(R[i][k] * d[k] * R[j][k] for k in range(3)) for j in range(3)] for i in range(3)]
    return [I[0][0], I[1][1], I[2][2], I[0][1], I[0][2], I[1][2]]


def chain(n, seed):
    rng = random.Random(seed)
    out = [f"name: chain_{n}",
           f"description: {n}-link serial chain, random revolute axes, frames and inertias, joint springs and "
           f"dampers, gravity, fixed base (scripts/make_bench_chain.py {n} --seed {seed})",
           "gravity: [0, 0, -9.81]", "", "bodies:"]
    for i in range(1, n + 1):
        axis = unit(rng)
        pos = [0, 0, 0] if i == 1 else [rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), rng.uniform(-0.5, 0.5)]
        rpy = [rng.uniform(-math.pi, math.pi), rng.uniform(-math.pi / 2, math.pi / 2), rng.uniform(-math.pi, math.pi)]
        m = rng.uniform(0.5, 2.0)
        com = [rng.uniform(-0.2, 0.2) for _ in range(3)]
        out.append(f"  - name: link{i}")
        out.append(f"    parent: {'ground' if i == 1 else f'link{i - 1}'}")
        out.append(f"    joint: {{type: revolute, axis: {axis!r}, position: {pos!r}, rotation: {{rpy: {rpy!r}}}, "
                   f"stiffness: {rng.uniform(0.1, 2.0)!r}, damping: {rng.uniform(0.05, 0.2)!r}, "
                   f"rest: {rng.uniform(-0.25, 0.25)!r}}}")
        out.append(f"    mass: {m!r}")
        out.append(f"    com: {com!r}")
        out.append(f"    inertia: {inertia(rng, m)!r}")
    q = ", ".join(f"link{i}.angle: {rng.uniform(-0.5, 0.5)!r}" for i in range(1, n + 1))
    out += ["initial:", f"  q: {{{q}}}", "outputs: [energy]", ""]
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("n", type=int)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("-o", "--output")
    a = ap.parse_args()
    text = chain(a.n, a.seed)
    if a.output:
        with open(a.output, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
