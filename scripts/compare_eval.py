#!/usr/bin/python3
"""Compare two `kanegen eval` JSON documents by name (reference README rules):
each quantity relative to its largest entry; u-dot by the residual |M udot - F|."""
import json, sys
import numpy as np

def by_name(doc, key, names_key):
    return dict(zip(doc[names_key], doc[key]))

def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(np.max(np.abs(b)) if b.size else 0.0, 1e-300)
    return float(np.max(np.abs(a - b)) / scale) if b.size else 0.0

def compare(got, exp):
    out = {}
    qn, un = exp["q_names"], exp["u_names"]
    gq, gu = got["q_names"], got["u_names"]
    pq = [gq.index(n) for n in qn]
    pu = [gu.index(n) for n in un]
    out["q"] = rel(np.asarray(got["q"])[pq], exp["q"])
    out["qdot"] = rel(np.asarray(got["qdot"])[pq], exp["qdot"])
    M = np.asarray(got["M"])[np.ix_(pu, pu)]
    out["M"] = rel(M, exp["M"])
    F = np.asarray(got["F"])[pu]
    out["F"] = rel(F, exp["F"])
    ud = np.asarray(got["udot"])[pu]
    Me, Fe = np.asarray(exp["M"]), np.asarray(exp["F"])
    out["udot_residual"] = float(np.linalg.norm(Me @ ud - Fe) / (np.linalg.norm(Me) * np.linalg.norm(ud) + np.linalg.norm(Fe)))
    if "energy" in exp:
        out["energy"] = rel([got["energy"]["T"], got["energy"]["V"]], [exp["energy"]["T"], exp["energy"]["V"]])
    if "momentum" in exp:
        out["p"] = rel(got["momentum"]["p"], exp["momentum"]["p"])
        out["H"] = rel(got["momentum"]["H"], exp["momentum"]["H"])
    if "reactions" in exp:
        for b, r in exp["reactions"].items():
            g = got["reactions"][b]
            out["R." + b] = rel(g["force"] + g["torque"], r["force"] + r["torque"])
    return out

if __name__ == "__main__":
    got = json.load(open(sys.argv[1])); exp = json.load(open(sys.argv[2]))
    res = compare(got, exp)
    worst = max(res.values())
    for k, v in res.items():
        print(f"  {k:20s} {v:.2e}{'  <-- FAIL' if v > 1e-9 else ''}")
    sys.exit(0 if worst < 1e-9 else 1)
