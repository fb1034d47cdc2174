#!/usr/bin/python3
"""Regenerates docs/speed.md (and docs/img/speed_work_precision.png) from one run
on this machine:

  /usr/bin/python3 scripts/speed_report.py [--build build] [--quick]

1. u-dot per evaluation on the arbitrary-geometry bench models
   (../shared/bench-models/ and a 128-body chain of scripts/make_bench_chain.py):
   kanegen generated (JIT, -O2 and -march=native), kanegen generic and MuJoCo
   timed interleaved in one process (bench/peers/mujoco_peer.cpp), Simbody in a
   separate process right after (bench/peers/simbody_peer.cpp; it cannot share
   a process with SUNDIALS 6). Every engine's u-dot is checked against kanegen's
   to 1e-12 before it is timed.
2. Work-precision on chain_8 over 10 s: final-state error against the reference
   end state of ../shared/bench-models/ against wall time, MuJoCo's RK4 at a
   sweep of steps and kanegen's integrators at a sweep of tolerances.
3. `kanegen simulate` with the generated and the generic engine, same
   integrator and tolerances, every model in models/ (alternating, median of 3).
4. Generation + JIT compile from a cold cache: wall time and the largest
   compiler process, chains of 32, 64 and 128 bodies.
5. bench/speed_report.cpp: generated vs generic on every model of models/ and
   tests/reference/, and the SD/FAST pin chains.
"""
import argparse
import datetime
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "bench-models")
SDFAST_OPS = {7: 2070, 15: 6490, 30: 14000}  # SD/FAST's better form (docs/decisions.md)
AUTO_RUN_CAP_S = 120  # a method slower than this (with its --estimate-error rerun) on a 10 s run has lost


def run(cmd, env=None, timeout=3600):
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)
    return r.returncode, r.stdout, r.stderr


def udot_ops(kanegen, model):
    with tempfile.TemporaryDirectory() as d:
        _, out, err = run([kanegen, "generate", model, "-o", os.path.join(d, "m.hpp")])
        m = re.search(r"u_dot (\d+) operations \((\w+) form, ([^)]*)\)", out + err)
        if not m:
            return None, "?"
        code = "compact" if m.group(3).startswith("compact") else "straight-line"
        return int(m.group(1)), f"{m.group(2)}, {code}"


PEER_PROCESSES = 3


def least_of_runs(runs):
    """One peer result from several processes: each time the least over them (ns_* the median of the medians),
    the rest from the first."""
    j = dict(runs[0])
    for k in j:
        vals = [r[k] for r in runs if isinstance(r.get(k), (int, float))]
        if k.startswith("min_ns_") and vals:
            j[k] = min(vals)
        elif k.startswith("ns_") and vals:
            j[k] = sorted(vals)[len(vals) // 2]
    # the compiler served: the one of the process whose baseline was fastest
    best = min(runs, key=lambda r: r.get("min_ns_generated_baseline") or float("inf"))
    for k in ("udot_compiler_generated", "udot_compiler_generated_baseline"):
        j[k] = best.get(k)
    return j


def peer_processes(bindir, models, quick):
    """The MuJoCo peer's processes of every model, PEER_PROCESSES passes over the models (one process of each
    model per pass): MuJoCo's time (and ours) moves between processes by up to 1.5x (code and data placement),
    more than within one, and the machine's load comes in spells of minutes; passes spread each model's
    processes over the whole run, so that one spell does not fall on all of one model's processes (run back
    to back, bus_4's three gave 396-410 ns in the report at 7dd69f5, 255-265 in three of four processes
    rerun alone). Returns {model path: ([parsed outputs], last stderr)}; a model whose process fails is not run
    again."""
    out = {m: ([], "") for m in models}
    mj = os.path.join(bindir, "kanegen_peer_mujoco")
    if not os.path.exists(mj):
        return out
    failed = set()
    # an empty JIT cache, as an outside rerun starts with: the first process of a model builds its libraries
    # and races the u-dot candidates (engine/udot_candidates.hpp), the later ones load what that race chose
    # (a user's cache could hold the choice of an older race, or of a busier moment)
    with tempfile.TemporaryDirectory(prefix="kanegen_speed_cache_") as cache:  # removed on every way out
        env = dict(os.environ, KANEGEN_CACHE_DIR=cache)
        for _ in range(1 if quick else PEER_PROCESSES):
            for m in models:
                if m in failed:
                    continue
                code, o, err = run([mj, m, "--kanegen", "--native", "--rounds", "11" if quick else "31"], env=env)
                if code != 0:
                    failed.add(m)
                    out[m] = (out[m][0], err)
                    continue
                out[m] = (out[m][0] + [json.loads(o)], err)
    return out


def peer_udot_rows(bindir, models, quick):
    """One row per model: the peer's processes (peer_processes), then Simbody's."""
    procs = peer_processes(bindir, models, quick)
    rows = []
    for m in models:
        peer_udot(bindir, m, quick, rows, procs[m])
    return rows


def peer_udot(bindir, model, quick, rows, processes):
    name = os.path.splitext(os.path.basename(model))[0]
    ops, form = udot_ops(os.path.join(bindir, "kanegen"), model)
    row = dict(model=name, ops=ops, form=form, floor=floor_ops(model))
    mj = os.path.join(bindir, "kanegen_peer_mujoco")
    if os.path.exists(mj):
        runs, err = processes
        if runs:
            j = least_of_runs(runs)
            row["process_ratios"] = [r["min_ns_mujoco"] / r["min_ns_generated_baseline"] for r in runs
                                     if r.get("min_ns_mujoco") and r.get("min_ns_generated_baseline")]
            row.update({k: j.get(k) for k in ("ns_mujoco", "ns_generated", "ns_generated_native", "ns_generated_baseline", "ns_generic",
                                               "min_ns_mujoco", "min_ns_generated", "min_ns_generated_native",
                                               "min_ns_generated_baseline", "min_ns_generic",
                                               "max_rel_diff_generated", "kanegen_jit_seconds",
                                               "udot_compiler_generated", "udot_compiler_generated_baseline",
                                               "ns_generated_baseline_own",
                                               "min_ns_generated_baseline_own",
                                               "backward_error_mujoco", "cond_M")})
            row["nu"] = len(j["u_names"])
        if not runs or len(runs) < (1 if quick else PEER_PROCESSES):
            row["mujoco_error"] = (err.strip().splitlines() or ["?"])[-1]
    sb = os.path.join(bindir, "kanegen_peer_simbody")
    if os.path.exists(sb):
        with tempfile.TemporaryDirectory() as d:
            ref = os.path.join(d, "ref.json")
            c, out, _ = run([os.path.join(bindir, "kanegen"), "eval", model, "--engine", "generic"])
            open(ref, "w").write(out)
            code, out, err = run([sb, model, "--check", ref, "--time", "2000" if quick else "20000"])
            if code == 0:
                j = json.loads(out)
                row["ns_simbody"] = j.get("ns_per_eval")
                row["simbody_diff"] = j.get("max_rel_diff")
                row["simbody_backward"] = j.get("backward_error")
            else:
                row["simbody_error"] = (err.strip().splitlines() or ["?"])[-1]
    print(f"  {name}: {row}", file=sys.stderr)
    rows.append(row)


def bw(b, r):
    """The backward error, shown where the forward difference exceeds 1e-12."""
    if b is None or r.get("max_rel_diff_generated", 0) <= 1e-12:
        return ""
    return f" (backward {b:.0e}, cond(M) {r.get('cond_M', float('nan')):.0e})"


def fmt_ns(v):
    return "—" if v is None else f"{v:,.0f}"


def ratio(a, b):
    return "—" if a is None or b is None or b == 0 else f"{a / b:.1f}×"


def spread(r):
    """The range of the headline ratio over the peer's processes."""
    pr = r.get("process_ratios") or []
    return "—" if len(pr) < 2 else f"{min(pr):.1f}–{max(pr):.1f}×"


def floor_ops(model_path):
    """The operation floor of ../shared/perf/udot-floor-analysis.md for a model of revolute joints only (None
    for others, e.g. a free base): the cheaper of Featherstone's articulated-body count in joint-local frames,
    429 n - 348, and the composite route for a chain (RNEA 174 n - 135, CRBA 16 n^2 + 59 n - 75, dense LTDL and
    two solves n^3/3 + 2.5 n^2), plus 6 n for sin/cos and the springs."""
    text = open(model_path).read()
    joints = [j for j in re.findall(r"type: (\w+)", text) if j != "fixed"]  # (a prismatic joint costs the same)
    if not joints or any(j not in ("revolute", "prismatic") for j in joints):
        return None
    n = len(joints)
    composite = 174 * n - 135 + 16 * n * n + 59 * n - 75 + n ** 3 / 3 + 2.5 * n * n
    return round(min(429 * n - 348, composite) + 6 * n)


def udot_section(rows, provenance):
    """The u-dot table; `provenance`: the line saying when and how this section was measured on its own (None
    when the page's first line says it)."""
    def t(r, k):  # the least slice where the run gave it, else the median
        return r.get("min_" + k, r.get(k))

    L = ["## u-dot per evaluation against MuJoCo and Simbody", ""]
    if provenance:
        L += [provenance, ""]
    L += ["Arbitrary geometry: the models of `../shared/bench-models/` (random revolute axes, rotated joint "
          "frames, full inertias, springs, gravity; `bus_4` a free bus with four hinged panels) and "
          "`chain_24_seed7`, another draw of `scripts/make_bench_chain.py`. ns per evaluation, the *least* of "
          "the interleaved slices (1 ms batches; the least is what an undisturbed rerun measures, the median "
          "follows the machine's load): kanegen's generated u-dot compiled for baseline x86-64 alone "
          "(*baseline*: the instruction set of Debian's MuJoCo build, and what a harness compiling the header at "
          "-O2 gets; the headline ratio), at the JIT's default flags (*dispatched*: an AVX2 clone picked at load "
          "time on this CPU) and with `--native` (`-march=native`), kanegen's generic engine and MuJoCo 2.2's "
          "`mj_forward` interleaved in one process; Simbody 3.7 (`realize` to Acceleration) in its own process "
          "afterwards (its median). The JIT cache starts empty, as an outside rerun's: a model's first process builds "
          "its libraries and races the u-dot candidates, the later ones load the choice. Each model's peer runs in 3 processes (1 with --quick), one per pass over all the "
          "models, so that a spell of load on the machine does not fall on all of one model's processes: MuJoCo's "
          "time and ours move between processes by up to 1.5x (code and data placement), more than within one; the times are the "
          "least over the processes, the ratio their quotient, *per process* the range of the processes' own "
          "ratios. *baseline* and *dispatched* name the u-dot served where it is not the library's own (g++'s "
          "build of the code in *u-dot ops*): the JIT builds a u-dot of 2,000 operations or more also with clang++ "
          "and in the other code (compact code beside straight-line; straight-line beside compact code of at most "
          "6,000 operations), races them all at the initial state and serves the fastest only when measured 5 % faster "
          "(engine/udot_candidates.hpp, docs/decisions.md); *own baseline* is then the library's own u-dot, timed "
          "in the same slices. "
          "*code*: straight-line, or compact (kernels shared by bodies of one shape, "
          "docs/decisions.md); *floor*: for one-degree-of-freedom joints, the cheaper of Featherstone's articulated-body count "
          "in joint-local frames, 429 n − 348, and the composite route for a chain (RNEA + CRBA + dense LTDL; a tree's is cheaper), "
          "plus 6 n for sin/cos and springs (`../shared/perf/udot-floor-analysis.md`), and the operations "
          "against it. u-dot of MuJoCo and Simbody checked against kanegen's before timing: "
          "largest relative difference (last columns), accepted up to 1e-12, or, where M is ill-conditioned (two "
          "correct solvers then differ by up to cond(M)·1e-16), a normwise backward error of the peer's u-dot in "
          "kanegen's M u-dot = F below 1e-14 (given in brackets with cond(M)).", "",
          "| model | nu | u-dot ops (form, code) | floor (ops / floor) | baseline | ns/op | own baseline | dispatched | native | "
          "generic | MuJoCo | **MuJoCo / baseline** | per process | MuJoCo / dispatched | MuJoCo / native | Simbody | "
          "Simbody / baseline | diff MuJoCo | diff Simbody |",
          "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        fl = r.get("floor")
        fl_txt = "—" if not fl or not r.get("ops") else f"{fl:,} ({r['ops'] / fl:.2f})"
        if "mujoco_error" in r:
            L.append(f"| {r['model']} | | {r['ops']} ({r['form']}) | {fl_txt} | MuJoCo run failed: "
                     f"{r['mujoco_error']} | | | | | | | | | | | | | | |")
            continue
        sd = r.get("simbody_diff")
        base = t(r, "ns_generated_baseline")
        per_op = "—" if base is None or not r.get("ops") else f"{base / r['ops']:.3f}"

        def served(k):  # the compiler of the u-dot served, where not the main one
            c = r.get("udot_compiler_" + k)
            return "" if c in (None, "main") else f" ({c})"
        L.append(f"| {r['model']} | {r.get('nu', '')} | {r['ops']:,} ({r['form']}) | {fl_txt} | "
                 f"{fmt_ns(base)}{served('generated_baseline')} | {per_op} | "
                 f"{fmt_ns(t(r, 'ns_generated_baseline_own')) if served('generated_baseline') else '='} | "
                 f"{fmt_ns(t(r, 'ns_generated'))}{served('generated')} | "
                 f"{fmt_ns(t(r, 'ns_generated_native'))} | {fmt_ns(t(r, 'ns_generic'))} | "
                 f"{fmt_ns(t(r, 'ns_mujoco'))} | **{ratio(t(r, 'ns_mujoco'), base)}** | {spread(r)} | "
                 f"{ratio(t(r, 'ns_mujoco'), t(r, 'ns_generated'))} | "
                 f"{ratio(t(r, 'ns_mujoco'), t(r, 'ns_generated_native'))} | {fmt_ns(r.get('ns_simbody'))} | "
                 f"{ratio(r.get('ns_simbody'), base)} | "
                 f"{r.get('max_rel_diff_generated', float('nan')):.1e}{bw(r.get('backward_error_mujoco'), r)} | "
                 f"{'—' if sd is None else format(sd, '.1e')}{bw(r.get('simbody_backward'), r)} |")
    L.append("")
    return L


def udot_models(work):
    """The u-dot section's models: the bench models and another draw of the chain generator."""
    tree_draw = os.path.join(work, "chain_24_seed7.yaml")
    run([sys.executable, os.path.join(ROOT, "scripts", "make_bench_chain.py"), "24", "--seed", "7", "-o", tree_draw])
    return [os.path.join(SHARED, m + ".yaml") for m in
            ("chain_2", "chain_4", "chain_8", "chain_16", "chain_32", "chain_64", "tree_15", "bus_4")] + [tree_draw]


def loadavg():
    return float(open("/proc/loadavg").read().split()[0])


def rewrite_udot_section(rows, provenance):
    """docs/speed.md with its u-dot section replaced (the other sections as their runs wrote them)."""
    path = os.path.join(ROOT, "docs", "speed.md")
    lines = open(path).read().split("\n")
    start = next(i for i, l in enumerate(lines) if l.startswith("## u-dot per evaluation"))
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
    lines[start:end] = udot_section(rows, provenance)
    note = " The u-dot section was measured again on its own (`--only udot`; its first line says when)."
    for i, l in enumerate(lines):
        if l.startswith("**Every figure on this page") and note.strip() not in l:
            lines[i] = l + note
            break
    with open(path, "w") as f:
        f.write("\n".join(lines))


def work_precision(bindir, img):
    mj = os.path.join(bindir, "kanegen_peer_mujoco")
    code, out, err = run([mj, os.path.join(SHARED, "chain_8.yaml"), "--work-precision",
                          os.path.join(SHARED, "chain_8_t10_reference.json"), "--t-end", "10"])
    if code != 0:
        return None, err
    wp = json.loads(out)["work_precision"]
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for name, pts in wp.items():
        if name == "wall_to_reach":
            continue
        ax.loglog([p["wall"] for p in pts], [max(p["error"], 1e-16) for p in pts], "o-", label=name)
    for target in (1e-6, 1e-8):
        ax.axhline(target, color="gray", lw=0.5)
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("max |x(10 s) − x_ref| over q, u")
    ax.set_title("chain_8 (../shared/bench-models), 10 s: error against wall time")
    ax.grid(True, which="both", lw=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(img, dpi=100)
    return wp, ""


def simulate_ratios(bindir, quick):
    """Both engines, the integrator auto picks, over a horizon long enough to time (>= 0.2 s generated)."""
    kanegen = os.path.join(bindir, "kanegen")
    rows = []
    models = sorted(f for f in os.listdir(os.path.join(ROOT, "models")) if f.endswith(".yaml"))
    wall_re = re.compile(r"rhs evals, \d+ jac evals, ([0-9.e+-]+) s")
    for f in models:
        path = os.path.join(ROOT, "models", f)
        with tempfile.TemporaryDirectory() as d:
            csv = os.path.join(d, "o.csv")

            def sim(t_end, extra):
                code, _, err = run([kanegen, "simulate", path, "-o", csv, "--t-end", repr(t_end), "--dt-out",
                                    repr(t_end / 100), "--no-progress"] + extra)
                w = wall_re.search(err)
                return code, err, (float(w.group(1)) if w else None)

            t_end = 10.0
            code, err, w = sim(t_end, ["--engine", "generated"])
            if code != 0 or w is None:
                rows.append(dict(model=f[:-5], error=(err.strip().splitlines() or ["?"])[-1]))
                continue
            integ = next((l.split(":")[0].strip() for l in err.splitlines() if "rhs evals" in l), "?")
            if w < 0.2:
                t_end = min(t_end * 0.2 / max(w, 1e-4), 1e4)
            walls = {"generated": [], "generic": []}
            for _ in range(1 if quick else 3):
                for eng in ("generated", "generic"):
                    code, _, w = sim(t_end, ["--engine", eng, "--integrator", integ])
                    if code == 0 and w is not None:
                        walls[eng].append(w)
        row = dict(model=f[:-5], t_end=t_end, integrator=integ,
                   generated=statistics.median(walls["generated"]) if walls["generated"] else None,
                   generic=statistics.median(walls["generic"]) if walls["generic"] else None)
        print(f"  simulate {row}", file=sys.stderr)
        rows.append(row)
    return rows


def error_estimates(bindir):
    """simulate's --estimate-error at the defaults against the error kanegen bench measures (its own reference)."""
    kanegen = os.path.join(bindir, "kanegen")
    rows = []
    for f in sorted(f for f in os.listdir(os.path.join(ROOT, "models")) if f.endswith(".yaml")):
        path = os.path.join(ROOT, "models", f)
        t_end = 10.0
        with tempfile.TemporaryDirectory() as d:
            code, _, err = run([kanegen, "simulate", path, "--t-end", repr(t_end), "--dt-out", repr(t_end / 50),
                                "--no-progress", "--estimate-error", "--engine", "generated",
                                "-o", os.path.join(d, "o.csv")])
            est = re.search(r"estimated error ([0-9.e+-]+)", err)
            integ = next((l.split(":")[0].strip() for l in err.splitlines() if "rhs evals" in l), "?")
            drift = re.search(r"accuracy: (.*)", err)
            code2, _, err2 = run([kanegen, "bench", path, "--engines", "generated", "--integrators", integ,
                                  "--tolerances", "1e-10", "--repeats", "1", "--no-plot", "--t-end", repr(t_end),
                                  "--out", d])
            true = None
            csvs = [x for x in os.listdir(d) if x.endswith("_work_precision.csv")]
            if code2 == 0 and csvs:
                import csv as csvmod
                for r in csvmod.DictReader(open(os.path.join(d, csvs[0]))):
                    if r["integrator"] == integ and r["error"]:
                        true = float(r["error"])
        rows.append(dict(model=f[:-5], integrator=integ, estimate=float(est.group(1)) if est else None, true=true,
                         accuracy=drift.group(1) if drift else ""))
        print(f"  estimate {rows[-1]}", file=sys.stderr)
    return rows


def per_step_overhead(bindir):
    """kanegen simulate of chain_8 over 10 s, one output, each integrator at rtol 1e-8: wall per rhs evaluation."""
    kanegen = os.path.join(bindir, "kanegen")
    model = os.path.join(SHARED, "chain_8.yaml")
    rows = []
    for integ in ("rkf78", "dopri5", "arkode-erk", "cvode-adams", "cvode-bdf", "rk4"):
        with tempfile.TemporaryDirectory() as d:
            extra = ["--h", "0.001"] if integ == "rk4" else ["--rtol", "1e-8", "--atol", "1e-10"]
            walls = []
            for _ in range(3):
                code, _, err = run([kanegen, "simulate", model, "--t-end", "10", "--dt-out", "10", "--no-progress",
                                    "--engine", "generated", "--integrator", integ, "-o", os.path.join(d, "o.csv")]
                                   + extra)
                m = re.search(r"(\d+) steps, (\d+) rhs evals, (\d+) jac evals, ([0-9.]+) s", err)
                if code == 0 and m:
                    walls.append((float(m.group(4)), int(m.group(1)), int(m.group(2)), int(m.group(3))))
            if walls:
                w, steps, evals, jacs = sorted(walls)[len(walls) // 2]
                rows.append(dict(integrator=integ, wall=w, steps=steps, evals=evals, jacs=jacs,
                                 ns_per_eval=w / evals * 1e9))
                print(f"  overhead {rows[-1]}", file=sys.stderr)
    return rows


COLD_START = [("flexible_spacecraft", 300.0), ("spacecraft_arrays", 300.0), ("gimbaled_spacecraft", 300.0),
              ("explorer1", 60.0)]


def cold_start(bindir):
    """simulate from a cold cache: --engine auto (generic at once, handover) against --engine generated
    (compile first), the warm generated run and the generic engine alone."""
    kanegen = os.path.join(bindir, "kanegen")
    rows = []
    first_re = re.compile(r"integrating on the generic engine from ([0-9.]+) s on")
    for name, t_end in COLD_START:
        path = os.path.join(ROOT, "models", name + ".yaml")
        row = dict(model=name, t_end=t_end)
        with tempfile.TemporaryDirectory() as d:
            csv = os.path.join(d, "o.csv")

            def sim(cache, extra):
                env = dict(os.environ, KANEGEN_CACHE_DIR=os.path.join(d, cache))
                t0 = time.time()
                code, _, err = run([kanegen, "simulate", path, "--t-end", repr(t_end), "--no-progress", "-o", csv]
                                   + extra, env=env)
                return code, time.time() - t0, err

            code, wall, err = sim("auto", [])
            m = first_re.search(err)
            row["auto_first_step"] = float(m.group(1)) if m else None
            row["auto_wall"] = wall if code == 0 else None
            row["auto_handover"] = "then generated" in err
            # let the background build finish before timing anything else
            auto_dir = os.path.join(d, "auto")

            def built():
                return os.path.isdir(auto_dir) and any(f.endswith(".json") for f in os.listdir(auto_dir))
            t0 = time.time()
            while time.time() - t0 < 600 and not built():
                time.sleep(0.2)
            row["auto_build_done_after"] = wall + time.time() - t0 if built() and code == 0 else None
            code, wall, err = sim("generated", ["--engine", "generated"])
            row["generated_cold_wall"] = wall if code == 0 else None
            m = re.search(r"compiled \S+ in ([0-9.]+) s", err)
            row["compile"] = float(m.group(1)) if m else None
            code, wall, _ = sim("generated", ["--engine", "generated"])
            row["generated_warm_wall"] = wall if code == 0 else None
            code, wall, _ = sim("generated", ["--engine", "generic"])
            row["generic_wall"] = wall if code == 0 else None
        print(f"  cold start {row}", file=sys.stderr)
        rows.append(row)
    return rows


METHODS = ["rkf78", "dopri5", "cvode-bdf", "cvode-bdf2", "cvode-adams", "arkode-erk", "arkode-dirk"]


def auto_suite(work):
    """The models auto is judged on: models/, models/extreme/, and variants of the
    physical Explorer I (stiffer and more damped whips; a higher spin)."""
    suite = [os.path.join(ROOT, "models", f) for f in sorted(os.listdir(os.path.join(ROOT, "models")))
             if f.endswith(".yaml")]
    suite += [os.path.join(ROOT, "models", "extreme", f)
              for f in sorted(os.listdir(os.path.join(ROOT, "models", "extreme"))) if f.endswith(".yaml")]
    base = open(os.path.join(ROOT, "models", "extreme", "explorer1_damped_whips.yaml")).read()
    variants = {
        "whips_stiff_damped": [("EI: [0.7952156404, 0.7952156404]", "EI: [3.1808625616, 3.1808625616]"),
                               ("damping_ratio: 0.05", "damping_ratio: 0.2")],
        "whips_high_spin": [("bus.wz: 78.539816339744831", "bus.wz: 157.07963267948966")],
    }
    for name, subs in variants.items():
        text = base.replace("name: explorer1_damped_whips", "name: " + name)
        for a, b in subs:
            assert a in text, a
            text = text.replace(a, b)
        path = os.path.join(work, name + ".yaml")
        open(path, "w").write(text)
        suite.append(path)
    return suite


def auto_against_methods(bindir, work, quick, only_models=None):
    """Every model of auto_suite over 10 s at the defaults (generated engine, --estimate-error):
    auto against every named adaptive method, wall time (integration) and estimated error."""
    kanegen = os.path.join(bindir, "kanegen")
    wall_re = re.compile(r"rhs evals, \d+ jac evals, ([0-9.e+-]+) s")
    est_re = re.compile(r"estimated error ([0-9.e+-]+)")
    rows = []
    for path in auto_suite(work):
        name = os.path.splitext(os.path.basename(path))[0]
        if only_models and name not in only_models:
            continue
        # the generated code (with the Jacobians of the implicit methods) built first, outside the time cap
        run([kanegen, "compile", path, "--derivatives"], timeout=3600)
        row = dict(model=name, methods={})
        with tempfile.TemporaryDirectory() as d:
            for method in ["auto"] + METHODS:
                walls, est, pick = [], None, None
                over_cap = False
                for _ in range(1 if quick else 2):
                    try:
                        code, _, err = run([kanegen, "simulate", path, "--t-end", "10", "--dt-out", "0.1",
                                            "--no-progress", "--engine", "generated", "--integrator", method,
                                            "--estimate-error", "-o", os.path.join(d, "o.csv")],
                                           timeout=AUTO_RUN_CAP_S)
                    except subprocess.TimeoutExpired:
                        over_cap = True
                        break
                    w, e = wall_re.search(err), est_re.search(err)
                    if code != 0 or not w:
                        break
                    walls.append(float(w.group(1)))
                    est = float(e.group(1)) if e else None
                    pick = next((l.split(":")[0].strip() for l in err.splitlines() if "rhs evals" in l), None)
                    if walls[-1] > 5.0:  # a slow method: one run is precise enough
                        break
                row["methods"][method] = dict(wall=min(walls) if walls else None, error=est, pick=pick,
                                              over_cap=over_cap)
        print(f"  auto {row}", file=sys.stderr)
        rows.append(row)
    return rows


def read_log(path):
    """The rows an earlier run printed on stderr (the dicts after each section's label)."""
    import ast
    rows, sims, ests, over, cold, autos, comp = [], [], [], [], [], [], []
    for line in open(path):
        line = line.strip()
        for prefix, dest in (("simulate ", sims), ("estimate ", ests), ("overhead ", over), ("cold start ", cold),
                             ("auto ", autos), ("compile ", comp)):
            if line.startswith(prefix + "{"):
                dest.append(ast.literal_eval(line[len(prefix):]))
                break
        else:
            m = re.match(r"[\w-]+: (\{'model'.*\})$", line)
            if m and "ns_mujoco" in line or (m and "mujoco_error" in line):
                rows.append(ast.literal_eval(m.group(1)))
    return rows, sims, ests, over, cold, autos, comp


def compile_costs(bindir, chains):
    kanegen = os.path.join(bindir, "kanegen")
    rows = []
    for n, path in chains:
        with tempfile.TemporaryDirectory() as cache:
            log = os.path.join(cache, "rss.log")
            env = dict(os.environ, KANEGEN_CACHE_DIR=os.path.join(cache, "jit"),
                       CXX=f"/usr/bin/time -f %M -a -o {log} c++")
            t0 = time.time()
            code, _, err = run([kanegen, "eval", path], env=env)
            wall = time.time() - t0
            rss = [int(x) for x in open(log).read().split()] if os.path.exists(log) else []
            rows.append(dict(n=n, wall=wall, ok=code == 0, max_rss_mb=max(rss) / 1024 if rss else None,
                             two_largest_mb=sum(sorted(rss)[-2:]) / 1024 if rss else None,
                             ops=udot_ops(kanegen, path)[0], err="" if code == 0 else err.strip()[-300:]))
            print(f"  compile {rows[-1]}", file=sys.stderr)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--quick", action="store_true", help="fewer rounds and repeats, no 128-body compile")
    ap.add_argument("--from-log", action="append", help="write the page from the stderr log of an earlier "
                    "(possibly interrupted) run instead of measuring; the sections it did not reach are left out. "
                    "Repeat to merge the logs of runs of separate sections (e.g. one from --only auto)")
    ap.add_argument("--log-commit", help="with --from-log: the commit(s) those runs measured")
    ap.add_argument("--models", help="with --only auto or udot: these models only (comma-separated; udot then "
                    "prints the section instead of writing the page); with auto a later "
                    "log's rows replace an earlier one's in --from-log")
    ap.add_argument("--only", choices=["auto", "udot"], help="measure one section only: auto prints its rows on "
                    "stderr (for --from-log) and writes no page; udot rewrites the u-dot section of docs/speed.md in "
                    "place, with its own provenance (when, commit, load average)")
    a = ap.parse_args()
    bindir = os.path.join(a.build, "bin")
    started = time.time()
    commit = run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"])[1].strip()
    dirty = run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"])[1].strip()
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    cxx = run(["c++", "--version"])[1].splitlines()[0]

    if a.only == "udot":
        work = tempfile.mkdtemp(prefix="kanegen_speed_")
        load_before = loadavg()
        print("u-dot against the peers", file=sys.stderr)
        rows = peer_udot_rows(bindir, [m for m in udot_models(work) if not a.models or
                                       os.path.splitext(os.path.basename(m))[0] in a.models.split(",")], a.quick)
        shutil.rmtree(work, ignore_errors=True)
        provenance = (f"*This section: `/usr/bin/python3 scripts/speed_report.py --only udot"
                      f"{' --quick' if a.quick else ''}` on {datetime.datetime.now():%Y-%m-%d %H:%M} (commit {commit}"
                      f"{' + local changes' if dirty else ''}; {(time.time() - started) / 60:.0f} min), {cpu} "
                      f"({os.cpu_count()} cores), {cxx}; load average {load_before:.2f} before, {loadavg():.2f} "
                      "after (1 min).*")
        if a.models:
            print("\n".join(udot_section(rows, provenance)))
            print("(--models: the page is not written)", file=sys.stderr)
            return
        rewrite_udot_section(rows, provenance)
        print(f"rewrote the u-dot section of docs/speed.md in {(time.time() - started) / 60:.1f} min", file=sys.stderr)
        return
    if a.only == "auto":
        work = tempfile.mkdtemp(prefix="kanegen_speed_")
        print("auto against every method", file=sys.stderr)
        auto_against_methods(bindir, work, a.quick, a.models.split(",") if a.models else None)
        shutil.rmtree(work, ignore_errors=True)
        print(f"auto section done in {(time.time() - started) / 60:.1f} min (commit {commit}"
              f"{' + local changes' if dirty else ''}); write the page with --from-log", file=sys.stderr)
        return
    if a.from_log:
        rows, sims, ests, over, cold, autos, comp = [], [], [], [], [], [], []
        for path in a.from_log:
            parts = read_log(path)
            for dest, got in zip((rows, sims, ests, over, cold, autos, comp), parts):
                dest.extend(got)
        # a model measured again in a later log replaces its earlier row (keeping the suite's order)
        latest = {r["model"]: r for r in autos}
        autos = [latest[m] for m in dict.fromkeys(r["model"] for r in autos)]
        wp, wp_err, sr = None, "not in the logs this page was written from", ""
        started = max(os.path.getmtime(p) for p in a.from_log)
        commit = a.log_commit or "?"
        dirty = ""
    else:
        work = tempfile.mkdtemp(prefix="kanegen_speed_")
        chain128 = os.path.join(work, "chain_128.yaml")
        run([sys.executable, os.path.join(ROOT, "scripts", "make_bench_chain.py"), "128", "--seed", "1", "-o", chain128])
        print("u-dot against the peers", file=sys.stderr)
        rows = peer_udot_rows(bindir, udot_models(work), a.quick)
        print("work-precision", file=sys.stderr)
        img = os.path.join(ROOT, "docs", "img", "speed_work_precision.png")
        wp, wp_err = work_precision(bindir, img)
        print("simulate", file=sys.stderr)
        sims = simulate_ratios(bindir, a.quick)
        print("error estimates", file=sys.stderr)
        ests = error_estimates(bindir)
        print("per-step overhead", file=sys.stderr)
        over = per_step_overhead(bindir)
        print("cold start", file=sys.stderr)
        cold = cold_start(bindir)
        print("auto against every method", file=sys.stderr)
        autos = auto_against_methods(bindir, work, a.quick)
        print("compile", file=sys.stderr)
        chains = [(32, os.path.join(SHARED, "chain_32.yaml")), (64, os.path.join(SHARED, "chain_64.yaml"))]
        if not a.quick:
            chains.append((128, chain128))
        comp = compile_costs(bindir, chains)
        print("speed_report (generated vs generic, pin chains)", file=sys.stderr)
        _, sr, _ = run([os.path.join(bindir, "kanegen_speed_report"), "--chains", "2,7,15,30"] +
                       (["--quick"] if a.quick else []))
        shutil.rmtree(work, ignore_errors=True)
    L = ["# Speed", "",
         "<!-- GENERATED by scripts/speed_report.py: do not edit; rerun the script. -->", "",
         (f"**Every figure on this page comes from the logs of {len(a.from_log)} run(s) of `/usr/bin/python3 "
          f"scripts/speed_report.py` (an interrupted full run, and `--only` runs of single sections), the last "
          f"ended {datetime.datetime.fromtimestamp(started):%Y-%m-%d %H:%M} (commit(s) {commit}); the sections "
          "no log reached are left out (written with `--from-log`), on " if a.from_log else
          f"**Every figure on this page comes from one run of `/usr/bin/python3 scripts/speed_report.py` on "
          f"{datetime.datetime.now():%Y-%m-%d %H:%M} (commit {commit}{' + local changes' if dirty else ''}; "
          f"{(time.time() - started) / 60:.0f} min{', quick mode' if a.quick else ''}), on ") + f"{cpu} "
         f"({os.cpu_count()} cores, shared and noisy), {cxx}.** Ratios measured in one process are steadier "
         "than absolute times.", ""]
    L += udot_section(rows, None)
    if wp:
        L += ["## Work-precision: chain_8 over 10 s", "",
              "![work-precision](img/speed_work_precision.png)", "",
              "Error: max over q and u of |x(10 s) − x_ref| against `chain_8_t10_reference.json`. MuJoCo: RK4 "
              "(`mj_step`) at steps 0.02 … 1e-4 s; kanegen: the generated engine through `integrate()` at rtol "
              "1e-5 … 1e-12 (atol = rtol/100). Wall time to reach an error (log-log interpolation between sweep "
              "points):", "",
              "| method | wall to reach 1e-6 | wall to reach 1e-8 | MuJoCo RK4 / this (1e-6) | (1e-8) |",
              "|---|---:|---:|---:|---:|"]
        reach = wp["wall_to_reach"]
        mj = reach.get("mujoco_rk4", {})
        for name, v in reach.items():
            def w(x):
                return "not reached" if x is None else f"{x * 1e3:.2f} ms"
            L.append(f"| {name} | {w(v.get('1e-06'))} | {w(v.get('1e-08'))} | "
                     f"{ratio(mj.get('1e-06'), v.get('1e-06'))} | {ratio(mj.get('1e-08'), v.get('1e-08'))} |")
        L.append("")
    else:
        L += ["## Work-precision", "", f"not measured: {wp_err.strip()[-300:]}", ""]
    L += ["## `kanegen simulate`: generated against generic engine", "",
          "Every model in `models/`, 100 output rows, at the default tolerances with the integrator that "
          "`--integrator auto` picks, both engines with that integrator, over a horizon long enough that the "
          "generated run takes about 0.2 s (10 s at least; integration wall time from the summary, median of "
          "alternating runs):", "",
          "| model | t_end [s] | integrator | generated [s] | generic [s] | generic / generated |",
          "|---|---:|---|---:|---:|---:|"]
    for s in sims:
        if "error" in s:
            L.append(f"| {s['model']} | | failed: {s['error']} | | | |")
            continue
        L.append(f"| {s['model']} | {s['t_end']:.4g} | {s['integrator']} | {s['generated']:.4g} | "
                 f"{s['generic']:.4g} | {ratio(s['generic'], s['generated'])} |")
    L.append("")
    L += ["## Error estimate against the error `kanegen bench` measures", "",
          "Every model in `models/` over 10 s at the defaults (`--integrator auto`, rtol 1e-10, atol 1e-12; 50 "
          "output intervals): the summary's `--estimate-error` figure against the error that `kanegen bench` "
          "measures for the same integrator and tolerance against its own reference run (generated engine), "
          "and the summary's accuracy line:", "",
          "| model | integrator | estimate | bench error | estimate / bench | summary |", "|---|---|---:|---:|---:|---|"]
    for e in ests:
        est, tr = e["estimate"], e["true"]
        q = "—" if est is None or tr is None or tr == 0 else f"{est / tr:.2g}"
        L.append(f"| {e['model']} | {e['integrator']} | {'—' if est is None else format(est, '.2e')} | "
                 f"{'—' if tr is None else format(tr, '.2e')} | {q} | {e['accuracy'].replace('|', chr(92) + '|')} |")
    L.append("")
    c8 = next((r for r in rows if r["model"] == "chain_8"), {})
    u8 = c8.get("ns_generated")
    L += ["## Cost per right-hand side inside `simulate`", "",
          "`kanegen simulate` of chain_8 over 10 s (generated engine, one output row), each integrator at rtol "
          "1e-8 (rk4: h = 1 ms): integration wall time per right-hand-side evaluation, against the bare u-dot "
          f"measured above ({fmt_ns(u8)} ns); the difference is the integrator's own work and the engine "
          "adapter's (copies, quaternion handling, checks) per evaluation.", "",
          "| integrator | steps | rhs evals | jac evals | wall [s] | ns per rhs eval | overhead per eval [ns] |",
          "|---|---:|---:|---:|---:|---:|---:|"]
    for o in over:
        L.append(f"| {o['integrator']} | {o['steps']:,} | {o['evals']:,} | {o['jacs']:,} | {o['wall']:.4f} | "
                 f"{o['ns_per_eval']:,.0f} | {fmt_ns(o['ns_per_eval'] - u8) if u8 else '—'} |")
    L.append("")
    def sec(x):
        return "—" if x is None else f"{x:.2f} s"

    L += ["## A first run: cold start", "",
          "`kanegen simulate` of each model from a cold cache, rkf78 at the defaults (the integrator auto picks "
          "here), one run each. *auto*: the default `--engine auto`, which starts on the generic engine at once "
          "while `kanegen compile --background` builds the generated code (first step: when integration began, "
          "as the command reports it; wall: the command's; the build finishes later, \"built\"). *generated, "
          "cold*: `--engine generated`, which compiles first (the behaviour before). *warm*: the next run, "
          "cached. *generic*: `--engine generic`.", "",
          "| model | horizon | auto: first step | auto: wall | auto handed over | built after | generated, cold | "
          "(compile) | generated, warm | generic |",
          "|---|---:|---:|---:|---|---:|---:|---:|---:|---:|"]
    for r in cold:
        L.append(f"| {r['model']} | {r['t_end']:g} s | {sec(r.get('auto_first_step'))} | {sec(r.get('auto_wall'))} | "
                 f"{'yes' if r.get('auto_handover') else 'no'} | {sec(r.get('auto_build_done_after'))} | "
                 f"{sec(r.get('generated_cold_wall'))} | {sec(r.get('compile'))} | "
                 f"{sec(r.get('generated_warm_wall'))} | {sec(r.get('generic_wall'))} |")
    L.append("")

    if autos:
        L += auto_section(autos)
    if comp:
        L += compile_section(comp)
    if sr:
        L += pins_section(sr)
    with open(os.path.join(ROOT, "docs", "speed.md"), "w") as f:
        f.write("\n".join(L))
    print(f"wrote docs/speed.md in {(time.time() - started) / 60:.1f} min", file=sys.stderr)


def auto_section(autos):
    L = []
    L += ["## `--integrator auto` against every method", "",
          "Every model of `models/` and `models/extreme/` and two variants of the physical Explorer I "
          "(`whips_stiff_damped`: EI x4, 20 % damping; `whips_high_spin`: twice the spin), 10 s at the defaults "
          "(rtol 1e-10, atol 1e-12), generated engine, `--estimate-error` (the run again at tolerances 100x "
          "tighter). Each cell: integration wall time (best of the runs) / estimated error. *ratio*: auto's wall "
          "time over the fastest method whose estimated error is at most 10x auto's; *err ratio*: auto's "
          "estimated error over that method's.", "",
          "| model | auto picks | auto | " + " | ".join(METHODS) + " | ratio | err ratio |",
          "|---|---|---:|" + "---:|" * len(METHODS) + "---:|---:|"]
    worst_ratio, worst_name = 0.0, ""
    for r in autos:
        ms = r["methods"]
        a0 = ms.get("auto", {})

        def cell(v):
            if v and v.get("over_cap"):
                return f"> {AUTO_RUN_CAP_S} s"
            if not v or v.get("wall") is None:
                return "failed"
            e = v.get("error")
            return f"{v['wall']:.3g} s / {'—' if e is None else format(e, '.1e')}"

        ratio_s, err_s = "—", "—"
        if a0.get("wall") is not None and a0.get("error") is not None:
            ok = [(v["wall"], m, v["error"]) for m, v in ms.items() if m != "auto" and v.get("wall") is not None
                  and v.get("error") is not None and v["error"] <= 10 * max(a0["error"], 1e-300)]
            if ok:
                w, m, e = min(ok)
                rr = a0["wall"] / w
                ratio_s, err_s = f"{rr:.2f} ({m})", f"{a0['error'] / max(e, 1e-300):.2g}"
                if rr > worst_ratio:
                    worst_ratio, worst_name = rr, r["model"]
        L.append(f"| {r['model']} | {a0.get('pick') or '—'} | {cell(a0)} | " +
                 " | ".join(cell(ms.get(m)) for m in METHODS) + f" | {ratio_s} | {err_s} |")
    L += ["", f"Worst ratio: {worst_ratio:.2f} ({worst_name}). Times below ~0.05 s are within the noise of "
          "process start-up and a shared machine.", ""]

    return L


def compile_section(comp):
    L = []
    L += ["## Generation and JIT compilation, cold cache", "",
          "`kanegen eval` of a bench chain with an empty JIT cache (generation, compilation of every part in "
          "parallel on the 2 cores, link, one evaluation). Memory: the largest compiler process, and the sum "
          "of the two largest (an upper bound of the peak with two compiles at a time).", "",
          "| bodies | u-dot ops | wall [s] | largest compiler [MB] | two largest [MB] |",
          "|---:|---:|---:|---:|---:|"]
    for c in comp:
        if not c["ok"]:
            L.append(f"| {c['n']} | {c['ops']} | failed: {c['err']} | | |")
            continue
        L.append(f"| {c['n']} | {c['ops']:,} | {c['wall']:.1f} | {c['max_rss_mb']:.0f} | {c['two_largest_mb']:.0f} |")
    L.append("")
    return L


def pins_section(sr):
    L = []
    L += ["## Generated against generic on every model, and pin chains", "",
          "From `build/bin/kanegen_speed_report --chains 2,7,15,30` (bench/speed_report.cpp): axis-aligned pin "
          "chains (axes cycling z, y, x) and the models of `models/` and `tests/reference/`.", "",
          sr.strip().replace("\n## ", "\n### ").replace("## ", "### ", 1), ""]
    pins = {}
    for line in sr.splitlines():
        m = re.match(r"\| (\d+) \| (\d+) \((\w+)\) \| (\d+) \| (\d+) \|", line)
        if m:
            pins[int(m.group(1))] = (int(m.group(2)), m.group(3), int(m.group(5)))
    if pins:
        L += ["### Against SD/FAST", "",
              "SD/FAST's generated derivative routine for pin chains of 7 / 15 / 30 bodies takes about 2,070 / "
              "6,490 / 14,000 operations in its better form (published counts). kanegen's u-dot for the same "
              "chains, this run:", "",
              "| bodies | SD/FAST ops | kanegen ops | form | kanegen ns |", "|---:|---:|---:|---|---:|"]
        for n, sd in SDFAST_OPS.items():
            if n in pins:
                L.append(f"| {n} | {sd:,} | {pins[n][0]:,} | {pins[n][1]} | {pins[n][2]:,} |")
        L.append("")
    return L


if __name__ == "__main__":
    main()
