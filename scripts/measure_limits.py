#!/usr/bin/python3
"""Writes docs/limits.md: kanegen's input limits and guarantees, with the run
time and peak memory of inputs right at each limit, measured here.

    /usr/bin/python3 scripts/measure_limits.py [--kanegen build/bin/kanegen]

The limits are the constants of model/input_text.hpp, model/modal_data.hpp,
model/model_loader.cpp and apps/common/simulation_cli.hpp; this script reads
them from those files so that the page cannot drift from the code.
"""
import argparse
import datetime
import os
import random
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def constant(path, name):
    """The value of `constexpr ... name = value;` in a source file (digit separators allowed)."""
    text = open(os.path.join(ROOT, path)).read()
    m = re.search(r"\b" + name + r"\s*=\s*([0-9'.eu<x ]+?)\s*;", text)
    if not m:
        sys.exit(f"measure_limits: {name} not found in {path}")
    v = m.group(1).replace("'", "").replace("u", "").strip()
    if "<<" in v:
        a, b = v.split("<<")
        return int(a) << int(b)
    return float(v) if ("e" in v or "." in v) else int(v)


def measure(cmd, cwd):
    """(exit status, wall s, peak RSS MB, first line of output)."""
    t0 = time.time()
    p = subprocess.run(["/usr/bin/time", "-f", "%M"] + cmd, cwd=cwd, capture_output=True, text=True)
    wall = time.time() - t0
    lines = p.stderr.strip().splitlines()
    peak_kb = int(lines[-1]) if lines and lines[-1].isdigit() else 0
    first = (lines[0] if len(lines) > 1 else p.stdout.strip().splitlines()[0] if p.stdout.strip() else "")
    return p.returncode, wall, peak_kb / 1024.0, first


def chain_model(n, joint="{type: revolute, axis: [0, 0, 1], position: [1, 0, 0]}"):
    lines = ["name: chain", "bodies:"]
    for i in range(n):
        parent = "ground" if i == 0 else f"b{i - 1}"
        lines.append(f"  - {{name: b{i}, parent: {parent}, joint: {joint}, mass: 1, "
                     "inertia: [0.1, 0.1, 0.1, 0, 0, 0], com: [0.5, 0, 0]}")
    return "\n".join(lines) + "\n"


def beam_model(elements, modes, foreshortening):
    return ("name: beam\nbodies:\n  - name: b\n    parent: ground\n    joint: {type: revolute, axis: [0, 0, 1]}\n"
            "    flexible:\n"
            f"      beam: {{length: 2, direction: x, mass_per_length: 0.5, EI: [20, 30], elements: {elements}, "
            f"modes: {modes}}}\n"
            f"      foreshortening: {'true' if foreshortening else 'false'}\n")


def modal_file(max_bytes):
    """A modal file of random shapes just under max_bytes (mass_normalized: false)."""
    rnd = random.Random(1)
    nodes = 1500
    head = ["mass_normalized: false", "nodes:"]
    head += [f"  - {{id: {i + 1}, position: [{i * 0.01:.2f}, 0, 0], mass: 0.01}}" for i in range(nodes)]
    head.append("modes:")
    text = "\n".join(head) + "\n"
    m = 0
    while True:
        sh = ", ".join(f"{i + 1}: [0, {rnd.random():.6f}, 0, 0, 0, 0]" for i in range(nodes))
        line = f"  - {{frequency: {m + 1}, shapes: {{{sh}}}}}\n"
        if len((text + line).encode()) > max_bytes:
            return text, nodes, m
        text += line
        m += 1


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--kanegen", default=os.path.join(ROOT, "build", "bin", "kanegen"))
    args = ap.parse_args()
    kg = os.path.abspath(args.kanegen)

    L = dict(
        model_bytes=constant("model/input_text.hpp", "kMaxModelFileBytes"),
        modal_bytes=constant("model/input_text.hpp", "kMaxModalFileBytes"),
        state_bytes=constant("model/input_text.hpp", "kMaxStateFileBytes"),
        nesting=constant("model/input_text.hpp", "kMaxNestingDepth"),
        bodies=constant("model/model_loader.cpp", "kMaxBodies"),
        speeds=constant("model/model_loader.cpp", "kMaxSpeeds"),
        elements=constant("model/model_loader.cpp", "kMaxBeamElements"),
        nodes=constant("model/modal_data.hpp", "kMaxModalNodes"),
        file_modes=constant("model/modal_data.hpp", "kMaxFileModes"),
        shape_entries=constant("model/modal_data.hpp", "kMaxShapeEntries"),
        body_modes=constant("model/modal_data.hpp", "kMaxBodyModes"),
        second_order=constant("model/modal_data.hpp", "kMaxSecondOrderEntries"),
        rows=constant("apps/common/simulation_cli.hpp", "kMaxOutputRows"),
        steps=constant("apps/common/simulation_cli.hpp", "kMaxFixedSteps"),
    )

    rows = []
    with tempfile.TemporaryDirectory(prefix="kanegen-limits-") as d:
        def put(name, text):
            with open(os.path.join(d, name), "w") as f:
                f.write(text)
            return name

        def case(what, cmd, expect):
            st, wall, mb, first = measure([kg] + cmd, d)
            ok = (st == 0) if expect == "runs" else (st == 2)
            rows.append((what, " ".join(["kanegen"] + cmd), st, wall, mb, ok))
            print(f"{what}: exit {st}, {wall:.2f} s, {mb:.0f} MB", file=sys.stderr)

        n = L["bodies"]
        put("chain.yaml", chain_model(n))
        case(f"chain of {n} revolute bodies (the body limit)", ["check", "chain.yaml"], "runs")
        case(f"chain of {n} revolute bodies (the body limit)", ["eval", "chain.yaml", "--engine", "generic"], "runs")
        put("chain_over.yaml", chain_model(n + 1))
        case(f"chain of {n + 1} bodies", ["check", "chain_over.yaml"], "refused")
        nf = L["speeds"] // 6
        put("free.yaml", chain_model(nf, "{type: free}"))
        case(f"{nf} free bodies ({6 * nf} speeds, under the speed limit)", ["eval", "free.yaml", "--engine", "generic"],
             "runs")
        put("free_over.yaml", chain_model(nf + 1, "{type: free}"))
        case(f"{nf + 1} free bodies ({6 * nf + 6} speeds)", ["check", "free_over.yaml"], "refused")
        e, m = L["elements"], L["body_modes"]
        put("beam_plain.yaml", beam_model(e, m, False))
        case(f"beam of {e} elements, {m} modes, foreshortening: false", ["check", "beam_plain.yaml"], "runs")
        mf = int((L["second_order"] / e) ** 0.5)
        put("beam_fs.yaml", beam_model(e, mf, True))
        case(f"beam of {e} elements, {mf} modes, foreshortening on", ["check", "beam_fs.yaml"], "runs")
        put("beam_fs_over.yaml", beam_model(e, mf + 1, True))
        case(f"beam of {e} elements, {mf + 1} modes, foreshortening on", ["check", "beam_fs_over.yaml"], "refused")
        text, nodes, modes = modal_file(L["modal_bytes"])
        put("big.modal.yaml", text)
        put("big.yaml", "name: big\nbodies:\n  - name: b\n    parent: ground\n    joint: {type: revolute, axis: [0, 0, 1]}\n"
            "    flexible: {modal: big.modal.yaml, modes: [1, 2, 3]}\n")
        case(f"modal file of {len(text.encode()) / 2**20:.1f} MB ({nodes} nodes, {modes} modes)", ["check", "big.yaml"],
             "runs")
        per_byte = rows[-1][4] * 2**20 / len(text.encode())
        pad = L["modal_bytes"] + 1024 - len(text.encode())  # a trailing comment: 1 kB over the limit
        put("huge.modal.yaml", text + "#" * (pad - 1) + "\n")
        put("huge.yaml", "name: huge\nbodies:\n  - name: b\n    parent: ground\n    joint: {type: revolute, axis: [0, 0, 1]}\n"
            "    flexible: {modal: huge.modal.yaml}\n")
        case("modal file 1 kB over the size limit", ["check", "huge.yaml"], "refused")
        put("deep.yaml", "name: deep\nbodies: " + "[" * 100000 + "]" * 100000 + "\n")
        case("model nested 100,000 brackets deep", ["check", "deep.yaml"], "refused")
        put("deep.json", '{"t": ' + "[" * 100000 + "]" * 100000 + "}\n")
        put("dp.yaml", open(os.path.join(ROOT, "models", "double_pendulum.yaml")).read())
        case("STATE.json nested 100,000 deep", ["eval", "dp.yaml", "--engine", "generic", "--state", "deep.json"],
             "refused")

    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    now = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    out = []
    out.append("# Limits and guarantees\n")
    out.append("<!-- GENERATED by scripts/measure_limits.py: do not edit; rerun the script. -->\n")
    out.append("kanegen reads models, modal files and states written by people and by other programs (FEA "
               "exports, scripts, sweeps). What it promises about any input, however malformed or large:\n")
    out.append("""- **Exit status.** 0: done. 2: the input or an option is refused; every line of the refusal reads
  `file:line: field: message` (a fault in the text itself names its column as the field, a fault of the
  whole file `(document)`) or `--option: message`, and nothing is written. 1: a failure while running
  (an integrator failure, a non-finite result, a full disk); the message names the simulated time and the
  state, and nothing is left half-written.
- **Nothing half-written.** Every output (CSV, JSON, headers, the JIT cache, plots) is written to an
  unnamed or temporary file and linked into place only when complete; SIGINT, SIGTERM and SIGKILL leave
  no file behind (tests/apps/test_hostile_input.cpp). An output path that is not a regular file
  (a directory, a device, a FIFO) is refused up front.
- **No non-finite number is printed.** `eval` and `simulate` stop with exit 1 and name the quantity (e.g.
  `F[0] (link1.angle)`) when a result overflows, never print `null`, `nan` or `inf`.
- **Text.** Files must be UTF-8 without control characters other than tab and line breaks; CR and CRLF
  line breaks are read as LF; a byte-order mark is dropped; one YAML document per file; integers are
  decimal (`010` is ten). STATE.json is strict JSON: a key given twice is refused with both lines, a
  number beyond double precision is refused, a quaternion of any non-zero finite norm is normalized.
- **Limits checked before anything is allocated**, so that no input can exhaust memory or run for
  hours before it is refused:
""")
    out.append("| limit | value | where |")
    out.append("|---|---:|---|")
    out.append(f"| model file | {L['model_bytes'] // 2**20} MB | `kMaxModelFileBytes` |")
    out.append(f"| modal data file | {L['modal_bytes'] // 2**20} MB | `kMaxModalFileBytes` |")
    out.append(f"| STATE.json | {L['state_bytes'] // 2**20} MB | `kMaxStateFileBytes` |")
    out.append(f"| bracket nesting ([ {{) | {L['nesting']} levels | `kMaxNestingDepth` |")
    out.append(f"| bodies | {L['bodies']:,} | `kMaxBodies` |")
    out.append(f"| generalized speeds (joint coordinates and modes) | {L['speeds']:,} | `kMaxSpeeds` |")
    out.append(f"| built-in beam elements | {L['elements']:,} | `kMaxBeamElements` |")
    out.append(f"| modes kept by one body | {L['body_modes']:,} | `kMaxBodyModes` |")
    out.append(f"| nodes in a modal file | {L['nodes']:,} | `kMaxModalNodes` |")
    out.append(f"| modes in a modal file | {L['file_modes']:,} | `kMaxFileModes` |")
    out.append(f"| shape entries (3 × nodes × modes) | {L['shape_entries']:.0e} | `kMaxShapeEntries` |")
    out.append(f"| foreshortening entries (nodes × axes × modes², for a beam elements × modes²) | "
               f"{L['second_order']:.0e} | `kMaxSecondOrderEntries` |")
    out.append(f"| rows written by `simulate` | {L['rows']:.0e} | `kMaxOutputRows` |")
    out.append(f"| fixed steps of `--integrator rk4` | {L['steps']:.0e} | `kMaxFixedSteps` |")
    out.append("")
    out.append(f"yaml-cpp holds about {per_byte:.0f} bytes of memory per byte of YAML it reads (measured below on "
               "the largest modal file), which is what the file-size limits bound. Every command-line value is "
               "checked against its domain before anything runs (`--t-end` finite and after the initial time, "
               "`--dt-out`, `--atol`, `--h` positive and finite, `--rtol` in (0, 1), `--max-steps` at least 1), "
               "and `simulate --max-steps` bounds the work of an adaptive integrator.\n")
    out.append(f"## Inputs at the limits, measured\n")
    out.append(f"Run by `scripts/measure_limits.py` on {now} (commit {commit}) on the 2-core development "
               "machine; peak memory is the resident set size.\n")
    out.append("| input | command | exit | wall time | peak memory | as promised |")
    out.append("|---|---|---:|---:|---:|---|")
    for what, cmd, st, wall, mb, ok in rows:
        out.append(f"| {what} | `{cmd}` | {st} | {wall:.2f} s | {mb:,.0f} MB | {'yes' if ok else '**NO**'} |")
    out.append("")
    out.append("Generating code for a model is bounded separately (issue 11: docs/speed.md); the JIT refuses "
               "nothing by size but its compile time grows with the model.\n")
    out.append("## How this is tested\n")
    out.append("- `tests/apps/test_hostile_input.cpp`: one test per class of hostile input (nesting, second "
               "documents, STATE.json faults, quaternions, non-finite results, number syntax, command-line "
               "domains, signals, a full disk (needs root to mount a small tmpfs), the limits, a singular "
               "mass matrix).\n"
               "- `tests/apps/fuzz_inputs.py` (in ctest, 60 s): mutates every model, modal file and state of "
               "the repository at random (deleted, duplicated, swapped and retyped keys and values, huge "
               "and non-finite numbers, deep nesting, control characters, invalid UTF-8, truncation, line "
               "endings, second documents, ...), runs `check` and `eval`, and fails on any crash, timeout, "
               "silent acceptance, wrong refusal, unlocated message, exit 1 on bad input or `null` in the "
               "JSON. `--case N` reruns one case.\n")
    with open(os.path.join(ROOT, "docs", "limits.md"), "w") as f:
        f.write("\n".join(out))
    bad = [r for r in rows if not r[5]]
    if bad:
        sys.exit(f"measure_limits: {len(bad)} input(s) not handled as promised (see docs/limits.md)")


if __name__ == "__main__":
    main()
