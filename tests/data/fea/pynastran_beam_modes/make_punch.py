#!/usr/bin/env python3
"""Writes beam_modes_eigenvectors.pch: the eigenvectors and eigenvalues that beam_modes.f06 prints, laid
out as NASTRAN's punch file (SOL 103, DISP(PUNCH)=ALL): 80-column lines, the line counter in columns 73-80,
"$EIGENVECTOR" blocks headed by "$EIGENVALUE = ... MODE = n", a "<grid> G T1 T2 T3" row and a "-CONT-" row
"R1 R2 R3" per grid. An "$ELEMENT FORCES" block of the same layout comes first (the reader must skip it; its
rows are those of the pyNastran repository's beam_modes.pch, models/beam_modes, BSD-3). The run did not punch
its eigenvectors, so this file is derived, not NASTRAN's own: it tests the punch layout, and that the same
numbers read from either file give the same modal data. Run: python3 make_punch.py (in this folder)."""
import re

lines = open("beam_modes.f06").read().splitlines()
eig = {}
table = False
for s in lines:
    if "R E A L   E I G E N V A L U E S" in s:
        table = True
        continue
    w = s.split()
    if table and len(w) == 7 and w[0].isdigit():
        eig[int(w[0])] = w[2]
    elif table and eig and not w:
        continue
    elif table and eig and w and not w[0].isdigit() and w[0] not in ("MODE", "NO."):
        table = False
vectors = {}
k = 0
while k < len(lines):
    m = re.search(r"R E A L   E I G E N V E C T O R   N O \.\s+(\d+)", lines[k])
    if m:
        n = int(m.group(1))
        rows = vectors.setdefault(n, [])
        k += 1
        while k < len(lines):
            w = lines[k].split()
            if w and w[0] == "POINT" or not w:
                k += 1
                continue
            if len(w) == 8 and w[0].isdigit():
                rows.append((int(w[0]), [float(x) for x in w[2:]]))
                k += 1
                continue
            break
        continue
    k += 1

out = []
def emit(text):
    out.append(f"{text:<72}{len(out) + 1:>8}")

def header(kind):
    emit("$TITLE   = SIMPLE BEAM EXAMPLE")
    emit("$SUBTITLE= MODES")
    emit("$LABEL   =")
    emit(kind)
    emit("$REAL OUTPUT")
    emit("$SUBCASE ID =           1")

header("$ELEMENT FORCES")
emit("$ELEMENT TYPE =          34  BAR")
emit("$EIGENVALUE =  8.2327765E+06  MODE =     1")
emit("         1              1.146587E+05      7.685664E+05      1.001748E+05")
emit("-CONT-                  6.714796E+05      1.448392E+04      9.708680E+04")
emit("-CONT-                  1.193920E-09      9.946595E-10")
for n in sorted(vectors):
    header("$EIGENVECTOR")
    emit(f"$EIGENVALUE = {float(eig[n]):14.7E}  MODE = {n:5d}")
    for grid, v in vectors[n]:
        emit(f"{grid:10d}       G{v[0]:18.6E}{v[1]:18.6E}{v[2]:18.6E}")
        emit(f"-CONT-{'':12}{v[3]:18.6E}{v[4]:18.6E}{v[5]:18.6E}")
open("beam_modes_eigenvectors.pch", "w").write("\n".join(out) + "\n")
