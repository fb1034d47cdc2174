#!/usr/bin/python3
"""Regenerates the measured block of docs/from_nastran.md: `kanegen import nastran` run on the shared
Simcenter Nastran SOL 103 run (tests/data/fea/pynastran_beam_modes), its printed checks pasted between the
markers. Run: /usr/bin/python3 scripts/nastran_import_report.py [--kanegen build/bin/kanegen]"""
import argparse
import os
import re
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "tests", "data", "fea", "pynastran_beam_modes")
DOC = os.path.join(ROOT, "docs", "from_nastran.md")

ap = argparse.ArgumentParser()
ap.add_argument("--kanegen", default=os.path.join(ROOT, "build", "bin", "kanegen"))
a = ap.parse_args()
with tempfile.TemporaryDirectory() as d:
    out = os.path.join(d, "rod.modal.yaml")
    r = subprocess.run([a.kanegen, "import", "nastran", "beam_modes.dat", "--modes", "beam_modes.f06", "-o", out],
                       cwd=DATA, capture_output=True, text=True, check=True)
text = r.stdout.replace(out, "rod.modal.yaml") + r.stderr
block = ("<!-- measured: scripts/nastran_import_report.py -->\n```\n$ kanegen import nastran beam_modes.dat "
         "--modes beam_modes.f06 -o rod.modal.yaml\n" + text + "```\n<!-- end measured -->")
doc = open(DOC).read()
new = re.sub(r"<!-- measured: scripts/nastran_import_report.py -->.*?<!-- end measured -->", lambda m: block, doc,
             flags=re.S)
if new == doc and block not in doc:
    raise SystemExit("docs/from_nastran.md: the measured block's markers are missing")
open(DOC, "w").write(new)
print("docs/from_nastran.md: measured block regenerated")
