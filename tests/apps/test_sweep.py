#!/usr/bin/python3
"""kanegen sweep (docs/sweeps.md) end to end, on tests/data/sweeps/double_pendulum.yaml:

  - the same tables from 1 thread, 2 threads, `mpirun -np 3` (when kanegen was
    built with MPI) and two shards merged: byte for byte;
  - the draws follow their distributions (means within 4 standard errors,
    truncation and choice sets respected) and depend only on seed and index;
  - a run replayed alone (--run K) gives the table's metrics for K;
  - an interrupted sweep resumes and ends with the same tables: one cut by
    hand, one killed with SIGKILL while it runs, and (under mpirun) one whose
    worker rank was killed, which stops the job;
  - a run that passes its wall-time limit (run_time_limit:) is recorded as
    failed with its reason, and the sweep completes;
  - runs that fail (a dispersed mass below zero) are recorded, the sweep goes on.

    test_sweep.py --kanegen BUILD/bin/kanegen [--mpirun /usr/bin/mpirun]
"""
import argparse
import csv
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ap = argparse.ArgumentParser()
ap.add_argument("--kanegen", required=True)
ap.add_argument("--mpirun", default="")
args = ap.parse_args()
ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SWEEP = os.path.join(ROOT, "tests", "data", "sweeps", "double_pendulum.yaml")
TABLES = ["runs.csv", "summary.json", "summary.md", "envelope_link1.angle.csv"]
failures = []


def check(cond, what):
    print(("ok    " if cond else "FAIL  ") + what)
    if not cond:
        failures.append(what)


def sweep(*extra, prefix=()):
    r = subprocess.run([*prefix, args.kanegen, "sweep", *extra, "--no-progress"], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stdout, r.stderr)
    return r


def same(a, b):
    return all(open(os.path.join(a, f), "rb").read() == open(os.path.join(b, f), "rb").read() for f in TABLES)


tmp = tempfile.mkdtemp(prefix="kanegen_sweep_test_")
try:
    d1, d2, d3, dm = (os.path.join(tmp, n) for n in ("t1", "t2", "mpi", "merged"))
    check(sweep(SWEEP, "-o", d1, "--threads", "1").returncode == 0, "sweep on 1 thread")
    check(sweep(SWEEP, "-o", d2, "--threads", "2").returncode == 0, "sweep on 2 threads")
    check(same(d1, d2), "1 thread and 2 threads: identical tables")
    if args.mpirun:
        r = sweep(SWEEP, "-o", d3, prefix=(args.mpirun, "--allow-run-as-root", "--oversubscribe", "-np", "3"))
        check(r.returncode == 0, "sweep under mpirun -np 3")
        check(r.returncode == 0 and same(d1, d3), "1 thread and mpirun -np 3: identical tables")
    s0, s1 = os.path.join(tmp, "s0"), os.path.join(tmp, "s1")
    check(sweep(SWEEP, "-o", s0, "--shard", "0/2").returncode == 0 and sweep(SWEEP, "-o", s1, "--shard", "1/2").returncode == 0,
          "two shards")
    check(sweep(SWEEP, "--merge", s0, s1, "-o", dm).returncode == 0 and same(d1, dm), "shards merged: identical tables")

    r = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "plot_sweep.py"), d1], capture_output=True, text=True)
    check(r.returncode == 0 and os.path.getsize(os.path.join(d1, "histograms.png")) > 10000 and
          os.path.exists(os.path.join(d1, "envelope_link1.angle.png")), "plot_sweep.py draws the histograms and envelopes")

    rows = list(csv.DictReader(open(os.path.join(d1, "runs.csv"))))
    check(len(rows) == 1000 and [int(r["run"]) for r in rows] == list(range(1000)), "1000 rows, by run index")
    check(all(r["status"] == "ok" for r in rows), "every run ok")
    m1 = [float(r["link1.mass"]) for r in rows]
    mean = sum(m1) / len(m1)
    sd = math.sqrt(sum((x - mean) ** 2 for x in m1) / (len(m1) - 1))
    check(abs(mean - 1.0) < 4 * 0.05 / math.sqrt(1000) and abs(sd - 0.05) < 0.1 * 0.05,
          f"normal, relative: link1.mass mean {mean:.5f}, std {sd:.5f} (nominal 1, sigma 5 %)")
    m2 = [float(r["link2.mass"]) for r in rows]
    check(all(0.6 * 0.8 - 1e-12 <= x <= 0.6 * 1.2 + 1e-12 for x in m2), "truncated normal: within +-20 %")
    cx = [float(r["link2.com.x"]) for r in rows]
    check(all(0.38 <= x <= 0.42 for x in cx) and abs(sum(cx) / 1000 - 0.4) < 4 * 0.04 / math.sqrt(12 * 1000),
          "uniform, absolute: 0.4 +- 0.02, mean in the middle")
    check(set(r["gravity.z"] for r in rows) == {repr(v) for v in (-9.78, -9.81, -9.83)} or
          {round(float(r["gravity.z"]), 12) for r in rows} == {-9.78, -9.81, -9.83}, "choice: the three values only")

    # a run replayed alone: its own metrics
    one = os.path.join(tmp, "run123.csv")
    check(sweep(SWEEP, "--run", "123", "-o", one).returncode == 0, "--run 123 writes its CSV")
    hist = list(csv.reader(open(one)))
    header, last = hist[0], hist[-1]
    check(float(last[header.index("link1.angle")]) == float(rows[123]["final_angle1"]),
          "--run 123: the final angle equals the table's")

    # an interrupted sweep resumes: keep 300 results and half a line
    dr = os.path.join(tmp, "resume")
    shutil.copytree(d1, dr)
    lines = open(os.path.join(dr, "results.tsv")).read().splitlines(True)
    open(os.path.join(dr, "results.tsv"), "w").write("".join(lines[:301]) + lines[301][: len(lines[301]) // 2])
    for f in TABLES:
        os.remove(os.path.join(dr, f))
    r = sweep(SWEEP, "-o", dr, "--threads", "2")
    check(r.returncode == 0 and "resuming: 300 runs already done, 700 to go" in r.stderr, "resumed with 700 runs to go")
    check(same(d1, dr), "resumed sweep: identical tables")

    def done_lines(d):
        p = os.path.join(d, "results.tsv")
        return sum(1 for _ in open(p)) - 1 if os.path.exists(p) else 0

    def kill_when(d, proc, n, victim):
        """SIGKILL `victim()` once d/results.tsv holds n runs; False if the sweep ended first."""
        deadline = time.time() + 300
        while proc.poll() is None and time.time() < deadline:
            if done_lines(d) >= n:
                os.kill(victim(), signal.SIGKILL)
                proc.wait()
                return True
            time.sleep(0.02)
        proc.wait()
        return False

    # a sweep killed with SIGKILL mid-run, then started again: the same tables (runs 20 times
    # longer than SWEEP's, so that the kill lands mid-sweep)
    LONG = os.path.join(tmp, "long.yaml")
    open(LONG, "w").write(open(SWEEP).read().replace("model: ../../../models/", "model: " + os.path.join(ROOT, "models") + "/")
                          .replace("runs: 1000", "runs: 200").replace("t_end: 2.0", "t_end: 400.0"))
    dl = os.path.join(tmp, "long")
    check(sweep(LONG, "-o", dl, "--threads", "2").returncode == 0, "a longer sweep, uninterrupted")
    dk = os.path.join(tmp, "killed")
    p = subprocess.Popen([args.kanegen, "sweep", LONG, "-o", dk, "--threads", "2", "--no-progress"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    killed = kill_when(dk, p, 60, lambda: p.pid)
    kept = done_lines(dk)
    check(killed and 60 <= kept < 200, f"SIGKILL after {kept} runs")
    r = sweep(LONG, "-o", dk, "--threads", "2")
    check(r.returncode == 0 and "resuming:" in r.stderr, "restarted: resumes (" + r.stderr.strip()[:80] + ")")
    check(same(dl, dk), "SIGKILLed and resumed: identical tables")

    if args.mpirun:
        # a worker rank killed: Open MPI ends the job; what rank 0 recorded stays, the rerun resumes
        dw = os.path.join(tmp, "worker_killed")
        p = subprocess.Popen([args.mpirun, "--allow-run-as-root", "--oversubscribe", "-np", "3", args.kanegen, "sweep",
                              LONG, "-o", dw, "--no-progress"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

        victim = {}

        def worker():
            for pid in os.listdir("/proc"):
                try:
                    env = open(f"/proc/{pid}/environ", "rb").read().split(b"\0")
                    cmd = open(f"/proc/{pid}/cmdline", "rb").read()
                except OSError:
                    continue
                if b"OMPI_COMM_WORLD_RANK=1" in env and b"sweep" in cmd and dw.encode() in cmd:
                    victim["rank 1"] = int(pid)
                    return int(pid)
            victim["mpirun"] = p.pid
            return p.pid  # not found: kill the whole job instead (the resume is still checked)

        killed = kill_when(dw, p, 60, worker)
        kept = done_lines(dw)
        check(killed and p.returncode != 0 and 60 <= kept < 200 and "rank 1" in victim,
              f"{', '.join(victim)} killed after {kept} runs: the job stopped")
        r = sweep(LONG, "-o", dw, prefix=(args.mpirun, "--allow-run-as-root", "--oversubscribe", "-np", "3"))
        check(r.returncode == 0 and "resuming:" in r.stderr and same(dl, dw),
              "rerun under mpirun after a killed worker: resumes to identical tables")

    # a run past its wall-time limit is a failed run with its reason; the sweep completes
    hung = os.path.join(tmp, "hung.yaml")
    text = open(SWEEP).read().replace("model: ../../../models/", "model: " + os.path.join(ROOT, "models") + "/")
    text = text.replace("runs: 1000", "runs: 6\nrun_time_limit: 0.02").replace("t_end: 2.0", "t_end: 1.0e4")
    open(hung, "w").write(text)
    dh = os.path.join(tmp, "hung")
    t0 = time.time()
    r = sweep(hung, "-o", dh, "--threads", "2")
    hrows = list(csv.DictReader(open(os.path.join(dh, "runs.csv")))) if r.returncode == 0 else []
    check(r.returncode == 0 and len(hrows) == 6 and
          all("wall-time limit of 0.02 s" in h["status"] for h in hrows) and time.time() - t0 < 60,
          "runs past run_time_limit: recorded as failed with the reason, the sweep completes")

    # failures are recorded, the sweep goes on
    bad = os.path.join(tmp, "bad.yaml")
    text = open(SWEEP).read().replace("model: ../../../models/", "model: " + os.path.join(ROOT, "models") + "/")
    text = text.replace("runs: 1000", "runs: 50").replace(
        "{parameter: link1.mass, distribution: normal, sigma: 0.05, relative: true}",
        "{parameter: link1.mass, distribution: normal, sigma: 1.0}")
    open(bad, "w").write(text)
    db = os.path.join(tmp, "bad")
    r = sweep(bad, "-o", db)
    brows = list(csv.DictReader(open(os.path.join(db, "runs.csv"))))
    nfail = sum(r_["status"] != "ok" for r_ in brows)
    check(r.returncode == 0 and len(brows) == 50 and 0 < nfail < 50 and
          all("expected a mass >= 0" in r_["status"] for r_ in brows if r_["status"] != "ok"),
          f"failed runs recorded with their reason ({nfail} of 50), the others ran")
    summary = json.load(open(os.path.join(db, "summary.json")))
    check(summary["failed"] == nfail, "the summary counts them")
finally:
    shutil.rmtree(tmp, ignore_errors=True)
print(f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)
