#!/usr/bin/python3
"""Fuzz `kanegen import nastran` (issue 36): the shared SOL 103 run's bulk data,
f06 and punch file, mutated one at a time, must be imported (exit 0, the modal
file written) or refused (exit 2, every message line naming a file of the case,
nothing written); never a crash, a timeout or exit 1.

    fuzz_nastran.py --kanegen BIN --seed S --budget-seconds T [--keep-failures DIR]

Mutations (one per case, on one of beam_modes.dat, cbar_cbeam.blk,
beam_modes.f06, beam_modes_eigenvectors.pch): a line deleted, duplicated or
swapped with the next; a whitespace-separated word (a field, a number) replaced
by junk ('', 'abc', '1.e', '-1', '0', '1e308', 'nan', '1.5-3', a large integer);
the file cut at a random byte; a card renamed to one that is refused (CQUAD4,
CONM1); a byte that is not UTF-8.
"""
import argparse
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "data", "fea", "pynastran_beam_modes")
FILES = ["beam_modes.dat", "cbar_cbeam.blk", "beam_modes.f06", "beam_modes_eigenvectors.pch"]
JUNK = ["", "abc", "1.e", "-1", "0", "1e308", "nan", "1.5-3", "99999999999", "*", ","]


def mutate(text, rng):
    lines = text.split("\n")
    kind = rng.choice(["delete", "duplicate", "swap", "word", "word", "word", "cut", "rename", "byte"])
    k = rng.randrange(len(lines))
    if kind == "delete":
        del lines[k]
    elif kind == "duplicate":
        lines.insert(k, lines[k])
    elif kind == "swap" and k + 1 < len(lines):
        lines[k], lines[k + 1] = lines[k + 1], lines[k]
    elif kind == "word":
        spans = [m.span() for m in re.finditer(r"[^\s,]+", lines[k])]
        if spans:
            a, b = rng.choice(spans)
            lines[k] = lines[k][:a] + rng.choice(JUNK) + lines[k][b:]
    elif kind == "cut":
        return kind, text[: rng.randrange(len(text))]
    elif kind == "rename":
        cards = [i for i, s in enumerate(lines) if re.match(r"(CBAR|CBEAM|CONM2|GRID)\b", s)]
        if cards:
            i = rng.choice(cards)
            lines[i] = re.sub(r"^\w+", rng.choice(["CQUAD4", "CONM1"]), lines[i])
    elif kind == "byte":
        s = lines[k]
        p = rng.randrange(len(s) + 1)
        lines[k] = s[:p] + "\udcff" + s[p:]
    return kind, "\n".join(lines)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--kanegen", required=True)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--budget-seconds", type=float, default=10)
    ap.add_argument("--timeout", type=float, default=20)
    ap.add_argument("--keep-failures")
    a = ap.parse_args()
    a.kanegen = os.path.abspath(a.kanegen)
    rng = random.Random(a.seed)
    texts = {f: open(os.path.join(DATA, f), encoding="utf-8", errors="surrogateescape").read() for f in FILES}
    start, cases, failures = time.time(), 0, []
    counts = {"imported": 0, "refused": 0}
    while time.time() - start < a.budget_seconds:
        cases += 1
        d = tempfile.mkdtemp(prefix="kanegen-fuzz-nastran-")
        try:
            target = rng.choice(FILES)
            kind, text = mutate(texts[target], rng)
            for f in FILES:
                with open(os.path.join(d, f), "w", encoding="utf-8", errors="surrogateescape") as out:
                    out.write(text if f == target else texts[f])
            modes = rng.choice(["beam_modes.f06", "beam_modes_eigenvectors.pch"])
            cmd = [a.kanegen, "import", "nastran", "beam_modes.dat", "--modes", modes, "-o", "out.modal.yaml"]
            try:
                r = subprocess.run(cmd, cwd=d, capture_output=True, text=True, errors="replace", timeout=a.timeout)
                rc, err = r.returncode, r.stderr
            except subprocess.TimeoutExpired:
                rc, err = None, "timeout"
            written = os.path.exists(os.path.join(d, "out.modal.yaml"))
            why = None
            if rc == 0:
                counts["imported"] += 1
                if not written or os.path.getsize(os.path.join(d, "out.modal.yaml")) == 0:
                    why = "exit 0 without the modal file"
            elif rc == 2:
                counts["refused"] += 1
                if written:
                    why = "refused, but the modal file was written"
                for line in err.strip().split("\n"):
                    if line.startswith("Run with --help"):
                        continue
                    if not any(line.startswith(f) for f in FILES + ["--modes", "--root", "-o", "bulk"]):
                        why = "unlocated message: " + line[:200]
                        break
            else:
                why = f"exit {rc}: {err.strip()[:300]}"
            if why:
                failures.append((cases, target, kind, modes, why))
                if a.keep_failures:
                    dest = os.path.join(a.keep_failures, f"case{cases}")
                    shutil.copytree(d, dest, dirs_exist_ok=True)
        finally:
            shutil.rmtree(d, ignore_errors=True)
    print(f"fuzz_nastran: seed {a.seed}: {cases} cases in {time.time() - start:.1f} s: "
          f"{counts['imported']} imported, {counts['refused']} refused, {len(failures)} failures")
    for c, target, kind, modes, why in failures[:20]:
        print(f"  case {c}: {kind} in {target} (modes {modes}): {why}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
