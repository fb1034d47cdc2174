#!/usr/bin/python3
"""Fuzz kanegen's input handling: mutated model, modal and STATE.json files,
simulate's output paths, and a run through gimbal lock.

    fuzz_inputs.py --kanegen BIN --seed S --budget-seconds T
                   [--report report.json] [--keep-failures DIR] [--timeout 10]
                   [--case N]

Seeds: every models/**/*.yaml (not *.modal.yaml; models/spinup/ files with more
than 20 bodies are skipped to keep runs fast) and tests/reference/*/*.yaml with
their state*.json (not *.expected.json). A modal file a model names is mutated
too, through that model. Every model also gets a STATE.json seed built from the
names and values `BIN eval MODEL --engine generic` prints (its initial state).

Each case copies one seed (the model plus the modal files it names, at the
same relative paths) into a temporary directory, mutates one file, and runs
there, with a timeout per run:
    model or modal mutated:  BIN check MODEL;  BIN eval MODEL --engine generic
    STATE.json mutated:      BIN eval MODEL --engine generic --state STATE.json
Two more case kinds run simulate, unmutated files, in the same way:
    cli (simulate's output paths, issue 34; any seed; --events only for a seed
    whose model has an events: list, else -o alone):
        BIN simulate MODEL --engine generic --t-end 0.05 --dt-out 0.01
            --no-progress -o PATH [--events PATH] [--state STATE.json]
        (--t-end 0.05 after the state's t with --state; each option spelled
        -o X, --output X, --output=X, --events X or --events=X). One path is
        at fault, the other (if any) is a good distinct path:
          c_same_file    -o and --events on one file (as given, ./x, sub/../x,
                         the absolute path)
          c_input_file   an output on an input: the model, a modal file it
                         names, the --state file (as given, ./x, sub/../x, the
                         absolute path, a symbolic link to it)
          c_empty_path   '' (or --output=, --events=)
          c_missing_dir  a path in a directory that does not exist, or under a
                         file (MODEL/out.csv)
          c_directory    a path that is a directory (., .., sub, sub/, ./sub/..,
                         the case directory, a modal file's directory)
        all "invalid": exit 2, every message line names an option
        (^(--[a-z][a-z0-9-]*|-o): ; CLI11's own "Run with --help for more
        information." line is let pass), one of them the option at fault (-o
        or --output, or --events; either for c_same_file), and NOTHING written:
        every file in the case directory byte-identical, no file, directory or
        link added or removed. A hard link to an input is "either": refused
        (nothing written) or exit 0 with the link replaced and the input as it
        was. The control, c_control, gives distinct valid paths ("valid": exit
        0, each output written and non-empty, nothing else changed).
    gimbal (a model generated here, GIMBAL_MODEL, as the test "a gimbal
    oscillating through lock" in tests/apps/test_cli.cpp: a gimbal xyz joint
    with a spring on its middle angle, rest 1.67, from angle2 = 1.45 (or 1.3,
    1.5, 1.55), so it passes pi/2):
        BIN simulate gimbal_oscillator.yaml --engine generic --integrator I
            --t-end 2 --dt-out DT --no-progress -o out.csv [--events ev.csv]
        I from rk4, dopri5, rkf78, cvode-bdf; DT from 0.31, 0.01, 0.07, 1, 2.5
        or random in [0.003, 3]. Expected ("lock"): exit 1, a message with
        "gimbal lock", and nothing written (no out.csv, no ev.csv).
The case kinds with a handful of pairs (s_events and c_same_file: two seeds;
gimbal: one) are
scheduled EVENTS_WEIGHT and GIMBAL_WEIGHT times a round so that a 30 s budget,
a third of a round, sees them.

Every mutation declares what the tool must do with it:
    valid    exit 0 (eval: and strict JSON on stdout: no null, NaN, Infinity)
    invalid  exit 2, every message line located
    either   exit 0 or 2; eval may also exit 1 if the message names a
             non-finite quantity or a singular mass matrix (NONFINITE_RE):
             huge but finite values (u = 1e200, gravity 1.7e308) are "either",
             so that null in eval's JSON is caught, and exit 1 must say why
For STATE.json the expectation is not declared by the operator but computed by
an oracle: strict JSON (RFC 8259: no duplicate keys, no NaN/Infinity, numbers
within double range, UTF-8, a UTF-8 BOM allowed since kanegen drops it) and the
STATE.json rules of interface.md / model-format.md (keys t, q, u, tau only;
names from the model; numbers only; a quaternion all or none, and non-zero);
a valid state with a value beyond HUGE = 1e3 (quaternion components aside, as
they are normalized) is "either".

Operators (MODEL_OPS for model and modal files, STATE_OPS for STATE.json):
text-level (t_*: delete, duplicate, swap lines, truncate, insert random bytes
with control characters and invalid UTF-8, re-indent, tab indent, second
document, document markers, CR/CRLF/mixed line breaks, comments, whitespace,
BOM) and structure-level through PyYAML's node positions, so the rest of the
file keeps its text and lines (s_*: numbers replaced by strings, null, lists,
NaN/inf/1e400, huge, tiny, -0, negative, other notations; keys dropped, added,
given twice; types swapped; nesting 33..100000 deep in flow and block style;
names (keywords, digits, 300 characters, bad characters); parents; joint types;
axes; rotations; inertia; masses; list lengths; outputs; prescribed motion;
initial quaternions; node ids; flexible blocks; modal normalization;
second_order symmetry; huge gravity; events). The j_* operators do the same for
STATE.json (duplicate keys, deep nesting, unknown names, wrong types, number
range, huge values, quaternions tiny/huge/zero/partial/5e-324, valid edits).

s_events (models with a top-level events: list only: models/array_deployment.yaml,
models/probe_separation.yaml; model-format.md, Locks and events):
    lock: [] or release: [] on an event (an empty action list)    invalid
    when: {coordinate: B.qw|qx|qy|qz} (a free or ball joint's
      quaternion component)                                        invalid
    when: {coordinate: another position, angle or modal coordinate} valid
    at: another finite time >= 0 (0, 1e-9, 3.5, 86400.0, ...)      valid
    at: .nan, .inf, -.inf, 1e400; a string; null                  invalid
    at: negative (-1.0, -1e-9, -1e300)                             either
      (the spec only says "at: T (s) fires at time T"; kanegen refuses it)

Choices this harness makes where the spec is silent (change them here):
  * a leading-zero integer in YAML ("010") is decimal ten, as YAML 1.2 core;
    written for an integer value it is "valid";
  * a quoted number ("1.5") in YAML is "either";
  * a UTF-8 BOM at the start of a file, CR-only, CRLF and mixed line breaks,
    '%YAML 1.2', an explicit '---' first and '...' last are "valid";
  * C0 control characters (other than tab and line breaks), DEL and invalid
    UTF-8 anywhere in a YAML file are "invalid" (YAML 1.2 c-printable);
  * a tab that indents a block line is "invalid" (YAML forbids it);
  * null where a number is expected is "invalid"; 1e-400 (underflows to 0)
    is "either"; subnormals such as 5e-324 are ordinary numbers;
  * dropping a body's com or inertia, or a beam's elements or modes, is
    "either": model-format.md gives no default, kanegen has one;
  * an event's negative at: is "either" (above);
  * an output path that is a hard link to an input is "either" (above); a
    symbolic link to one is "invalid", as kanegen refuses to write through any
    symbolic link.

Outcome of each run (one class per run; the first that applies):
    crash          killed by a signal, or an exit status not in {0, 1, 2}
    timeout        still running after --timeout seconds (killed)
    written-on-refusal  (cli, gimbal) a run that exits non-zero changed the
                   case directory (a file written, created or removed)
    wrongly-refused  exit 2 for a "valid" mutation
    silent-accept  exit 0 for an "invalid" mutation
    exit1-on-input exit 1 where 0 or 2 was due (any expectation), except eval
                   exiting 1 with a message that matches NONFINITE_RE for an
                   "either" mutation
    unlocated      exit 2 and some message line (stderr, non-empty lines) is
                   not located, or stderr is empty
    null-in-json   eval exit 0 but stdout is not strict JSON (null, NaN,
                   Infinity, or not parseable)
    wrong-files    (cli) exit 0, but an output is missing or empty, or a file
                   other than the outputs changed (an input, say)
    missed-lock    (gimbal) not exit 1 with a message naming gimbal lock
    ok-valid       exit 0 as allowed (and strict JSON for eval)
    ok-refused     exit 2 as allowed, every line located (cli: every line
                   names an option, one of them the option at fault)
    ok-nonfinite   eval exit 1 naming a non-finite quantity (or a singular
                   mass matrix) for an "either" mutation
    ok-stopped     (gimbal) exit 1 naming gimbal lock, nothing written
For cli and gimbal runs "unlocated" means a refusal whose messages do not all
name an option or name none of the options at fault, and "silent-accept" exit
0 for a path that must be refused.
The run fails (exit 1) when any class other than ok-valid, ok-refused,
ok-nonfinite and ok-stopped has a count.

A message line is located when it matches LOCATED_RE
    ^(?P<file>[^:\\n]+):(?P<line>[1-9][0-9]*): (?P<field>[^:\\n]+): \\S
(file, a positive line number, a non-empty field without a colon, then the
message) and os.path.basename(file) is the name of one of the case's files
(model, modal or state), or when it names an option: ^(--[a-z][a-z0-9-]*|-o): \\S
A field is "anything up to the next colon", so a message of the form
"f.yaml:3: YAML syntax error: x" passes with "YAML syntax error" as its field,
while "f.yaml:3: a second YAML document; ..." (no field) and "f.json: q.x: ..."
(no line) do not, nor does a field that prints a user's key with a colon in
it unquoted ("f.yaml:8: descri:]ption: unknown key ...").

Deterministic for a seed: case N is the same mutation (or run) whatever the budget (the
values of the synthesized STATE.json seeds come from BIN's eval output, so
they may differ between binaries). --case N runs only case N (to reproduce).
"""

import argparse
import glob
import json
import math
import os
import random
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter, defaultdict

try:
    import yaml  # only for its composer (node positions); no types are resolved with it
except ImportError:  # pragma: no cover
    yaml = None

# --------------------------------------------------------------------------
# rules

LOCATED_RE = re.compile(r"^(?P<file>[^:\n]+):(?P<line>[1-9][0-9]*): (?P<field>[^:\n]+): \S")
OPTION_RE = re.compile(r"^(--[a-z][a-z0-9-]*|-o): \S")
NONFINITE_RE = re.compile(r"(?i)(non-?finite|not finite|\bnan\b|\binf\b|\binfinity\b|overflow|singular)")

OK_CLASSES = ["ok-valid", "ok-refused", "ok-nonfinite", "ok-stopped"]
FAIL_CLASSES = ["crash", "timeout", "written-on-refusal", "wrongly-refused", "silent-accept", "exit1-on-input",
                "unlocated", "null-in-json", "wrong-files", "missed-lock"]
ALL_CLASSES = OK_CLASSES + FAIL_CLASSES

NUM_RE = re.compile(r"^[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?$")
INT_RE = re.compile(r"^[-+]?[0-9]+$")
STRING_KEYS = {"name", "parent", "description", "type", "direction", "modal"}

CPP_KEYWORDS = ["class", "int", "double", "new", "delete", "this", "auto", "register", "template", "operator",
                "namespace", "return", "struct", "union", "virtual", "typename", "const", "static", "void",
                "and", "or", "not", "xor", "bool", "true_", "std", "main", "inline", "signed", "default"]

# --------------------------------------------------------------------------
# text helpers (text is str; invalid UTF-8 bytes are lone surrogates, written with surrogateescape)


def encode(text):
    return text.encode("utf-8", "surrogateescape")


def decode(data):
    return data.decode("utf-8", "surrogateescape")


def has_bad_utf8(text):
    return any("\udc80" <= c <= "\udcff" for c in text)


def is_c0_or_del(c):
    o = ord(c)
    return (o < 0x20 and c not in "\t\n\r") or o == 0x7F


def line_starts(text):
    starts = [0]
    for i, c in enumerate(text):
        if c == "\n":
            starts.append(i + 1)
    return starts


def apply_edits(text, edits):
    """Applies (start, end, replacement) edits that do not overlap."""
    out = text
    last = None
    for s, e, r in sorted(edits, key=lambda x: (x[0], x[1]), reverse=True):
        if last is not None and e > last:
            raise ValueError("overlapping edits")
        out = out[:s] + r + out[e:]
        last = s
    return out


def fmt_num(x):
    return repr(float(x))


# --------------------------------------------------------------------------
# YAML structure (positions from PyYAML's composer; types decided here, YAML 1.2 core style)


class YDoc:
    """A composed YAML file: the node tree with positions, and a walk of it."""

    def __init__(self, text):
        self.text = text
        self.root = yaml.compose(text, Loader=yaml.SafeLoader)
        self.items = []  # (path tuple, node, key node or None, parent mapping node or None)
        self.maps = []  # (path, mapping node)
        if self.root is not None:
            self._walk(self.root, (), None, None)

    def _walk(self, node, path, key, parent):
        self.items.append((path, node, key, parent))
        if isinstance(node, yaml.MappingNode):
            self.maps.append((path, node))
            for k, v in node.value:
                kv = k.value if isinstance(k, yaml.ScalarNode) else "?"
                self._walk(v, path + (kv,), k, node)
        elif isinstance(node, yaml.SequenceNode):
            for i, v in enumerate(node.value):
                self._walk(v, path + (i,), None, node)

    def data(self):
        return to_py(self.root)


def to_py(node):
    if node is None:
        return None
    if isinstance(node, yaml.ScalarNode):
        v = node.value
        if node.style is None:
            if NUM_RE.match(v):
                return int(v) if INT_RE.match(v) else float(v)
            if v in ("true", "True", "TRUE"):
                return True
            if v in ("false", "False", "FALSE"):
                return False
            if v in ("", "~", "null", "Null", "NULL"):
                return None
        return v
    if isinstance(node, yaml.SequenceNode):
        return [to_py(x) for x in node.value]
    if isinstance(node, yaml.MappingNode):
        return {to_py(k): to_py(v) for k, v in node.value}
    return None


def path_str(path):
    s = ""
    for p in path:
        s += f"[{p}]" if isinstance(p, int) else (("." if s else "") + str(p))
    return s


def last_key(path):
    for p in reversed(path):
        if not isinstance(p, int):
            return p
    return None


def is_block(node):
    return isinstance(node, (yaml.MappingNode, yaml.SequenceNode)) and not node.flow_style


def value_span(text, node, key):
    """(start, end, suffix): the text of a value, ready to be replaced by a one-line flow value + suffix."""
    if not is_block(node):
        return node.start_mark.index, node.end_mark.index, ""
    if key is not None:
        start = text.index(":", key.end_mark.index) + 1
        prefix = " "
    else:
        start = node.start_mark.index
        prefix = ""
    end = node.end_mark.index
    ls = text.rfind("\n", 0, end) + 1
    if ls > start and text[ls:end].strip() == "":
        return start, ls, "\n"
    return start, end, ""


def replace_value(doc, node, key, repl):
    s, e, suffix = value_span(doc.text, node, key)
    prefix = " " if is_block(node) and key is not None else ""
    return apply_edits(doc.text, [(s, e, prefix + repl + suffix)])


def pair_delete_edit(text, mapping, k, v):
    """Edit that removes key k (with value v) from mapping."""
    if mapping.flow_style:
        s, e = k.start_mark.index, v.end_mark.index
        m = re.match(r"\s*,[ \t]*", text[e:])
        if m:
            e += m.end()
        else:
            m = re.search(r",\s*$", text[mapping.start_mark.index:s])
            if m:
                s = mapping.start_mark.index + m.start()
        return (s, e, "")
    s = k.start_mark.index
    ls = text.rfind("\n", 0, s) + 1
    whole_line = text[ls:s].strip() == ""
    if is_block(v):
        end = v.end_mark.index
        el = text.rfind("\n", 0, end) + 1
        if el > s and text[el:end].strip() == "":
            e = el  # start of the line of the next token, so the deleted text ends with a newline
        else:
            e = end
        if whole_line:
            return (ls, e, "")
        return (s, max(s, e - 1) if text[e - 1:e] == "\n" else e, "")
    nl = text.find("\n", v.end_mark.index)
    if nl < 0:
        nl = len(text)
    if whole_line:
        return (ls, min(nl + 1, len(text)), "")
    return (s, nl, "")


def pair_insert_edit(text, mapping, pair_text):
    """Edit that adds 'key: value' (one line) as the first entry of mapping."""
    if not mapping.value:
        if mapping.flow_style:
            return (mapping.start_mark.index, mapping.end_mark.index, "{" + pair_text + "}")
        return None
    k0 = mapping.value[0][0]
    if mapping.flow_style:
        return (k0.start_mark.index, k0.start_mark.index, pair_text + ", ")
    return (k0.start_mark.index, k0.start_mark.index, pair_text + "\n" + " " * k0.start_mark.column)


def single_line(text, node):
    return "\n" not in text[node.start_mark.index:node.end_mark.index]


# --------------------------------------------------------------------------
# seeds


class SeedFile:
    def __init__(self, rel, text):
        self.rel = rel
        self.text = text
        self._doc = None
        self._doc_err = None

    @property
    def doc(self):
        if self._doc is None and self._doc_err is None and yaml is not None:
            try:
                self._doc = YDoc(self.text)
            except Exception as e:  # noqa: BLE001 - a seed PyYAML cannot read gets text mutations only
                self._doc_err = e
        return self._doc


class Seed:
    def __init__(self, name, model_rel, files, states, source_dir):
        self.name = name  # e.g. models/explorer1.yaml
        self.model_rel = model_rel  # file name of the model inside the case directory
        self.files = files  # rel -> SeedFile (model and modal files)
        self.states = states  # list of (file name, text)
        self.source_dir = source_dir
        self.q_names, self.u_names = [], []
        self.free_bodies, self.prescribed = [], []
        self.n_bodies = 0
        self.data = None

    @property
    def model(self):
        return self.files[self.model_rel]

    def modal_rels(self):
        return [r for r in self.files if r != self.model_rel]


def collect_seeds(repo):
    paths = []
    for p in sorted(glob.glob(os.path.join(repo, "models", "**", "*.yaml"), recursive=True)):
        if not p.endswith(".modal.yaml"):
            paths.append((p, []))
    for p in sorted(glob.glob(os.path.join(repo, "tests", "reference", "*", "*.yaml"))):
        if p.endswith(".modal.yaml"):
            continue
        d = os.path.dirname(p)
        states = [s for s in sorted(glob.glob(os.path.join(d, "state*.json"))) if not s.endswith(".expected.json")]
        paths.append((p, states))
    seeds, skipped = [], []
    for p, states in paths:
        rel_name = os.path.relpath(p, repo)
        with open(p, "rb") as f:
            text = decode(f.read())
        model = SeedFile(os.path.basename(p), text)
        data = None
        if model.doc is not None:
            try:
                data = model.doc.data()
            except Exception:  # noqa: BLE001
                data = None
        bodies = data.get("bodies", []) if isinstance(data, dict) else []
        bodies = bodies if isinstance(bodies, list) else []
        if rel_name.startswith("models/spinup/") and len(bodies) > 20:
            skipped.append(rel_name)
            continue
        files = {model.rel: model}
        ok = True
        for b in bodies:
            fl = b.get("flexible") if isinstance(b, dict) else None
            if isinstance(fl, dict) and isinstance(fl.get("modal"), str):
                mrel = os.path.normpath(fl["modal"])
                if mrel.startswith("..") or os.path.isabs(mrel):
                    ok = False
                    continue
                src = os.path.join(os.path.dirname(p), mrel)
                if os.path.isfile(src):
                    with open(src, "rb") as f:
                        files[mrel] = SeedFile(mrel, decode(f.read()))
        if not ok:
            skipped.append(rel_name + " (modal path outside its directory)")
            continue
        st = []
        for s in states:
            with open(s, "rb") as f:
                st.append((os.path.basename(s), decode(f.read())))
        seed = Seed(rel_name, model.rel, files, st, os.path.dirname(p))
        seed.data = data
        seed.n_bodies = len(bodies)
        for b in bodies:
            if not isinstance(b, dict):
                continue
            j = b.get("joint") if isinstance(b.get("joint"), dict) else {}
            if j.get("motion") is not None and j.get("type") in ("revolute", "prismatic"):
                seed.prescribed.append(f"{b.get('name')}.{'angle' if j.get('type') == 'revolute' else 'disp'}")
        seeds.append(seed)
    return seeds, skipped


# --------------------------------------------------------------------------
# running


class Runner:
    def __init__(self, binary, timeout, workdir):
        self.binary = os.path.abspath(binary)
        self.timeout = timeout
        self.workdir = workdir
        self.env = dict(os.environ)
        self.env["KANEGEN_CACHE_DIR"] = os.path.join(workdir, "cache")
        self.env.setdefault("LC_ALL", "C")

    def write_case(self, files):
        d = os.path.join(self.workdir, "case")
        if os.path.isdir(d):
            shutil.rmtree(d)
        os.makedirs(d)
        for rel, text in files.items():
            full = os.path.join(d, rel)
            os.makedirs(os.path.dirname(full), exist_ok=True)
            with open(full, "wb") as f:
                f.write(encode(text))
        return d

    def run(self, args, cwd):
        t0 = time.monotonic()
        p = subprocess.Popen([self.binary] + args, cwd=cwd, env=self.env, stdin=subprocess.DEVNULL,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
        timed_out = False
        try:
            out, err = p.communicate(timeout=self.timeout)
        except subprocess.TimeoutExpired:
            timed_out = True
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            out, err = p.communicate()
        return {"rc": p.returncode, "stdout": decode(out), "stderr": decode(err), "timed_out": timed_out,
                "seconds": time.monotonic() - t0}


def strict_output_json(text):
    def bad(_):
        raise ValueError("NaN or Infinity")

    obj = json.loads(text, parse_constant=bad)

    def walk(x):
        if x is None:
            raise ValueError("null")
        if isinstance(x, dict):
            for v in x.values():
                walk(v)
        elif isinstance(x, list):
            for v in x:
                walk(v)

    walk(obj)
    return obj


def unlocated_lines(stderr, case_files):
    names = {os.path.basename(r) for r in case_files}
    bad = []
    lines = [l.rstrip("\r") for l in stderr.split("\n") if l.strip()]
    if not lines:
        return ["(no message on stderr)"]
    for l in lines:
        m = LOCATED_RE.match(l)
        if m and os.path.basename(m.group("file")) in names:
            continue
        if OPTION_RE.match(l):
            continue
        bad.append(l)
    return bad


def crash_or_timeout(res):
    rc = res["rc"]
    if res["timed_out"]:
        return "timeout", f"killed after {res['seconds']:.1f} s"
    if rc is None or rc < 0 or rc not in (0, 1, 2):
        sig = ""
        if rc is not None and rc < 0:
            try:
                sig = " (" + signal.Signals(-rc).name + ")"
            except ValueError:
                pass
        return "crash", f"exit status {rc}{sig}"
    return None


def classify(expect, cmd, res, case_files):
    """One outcome class for one run, and a short reason."""
    rc, err = res["rc"], res["stderr"]
    r = crash_or_timeout(res)
    if r:
        return r
    if rc == 2:
        if expect == "valid":
            return "wrongly-refused", "exit 2 for a valid input"
        bad = unlocated_lines(err, case_files)
        if bad:
            return "unlocated", "unlocated: " + bad[0][:300]
        return "ok-refused", ""
    if rc == 0:
        if expect == "invalid":
            return "silent-accept", "exit 0 for an invalid input"
        if cmd == "eval":
            try:
                strict_output_json(res["stdout"])
            except (ValueError, RecursionError) as e:
                return "null-in-json", f"eval output is not strict JSON ({e})"
        return "ok-valid", ""
    # rc == 1
    if cmd == "eval" and expect == "either" and NONFINITE_RE.search(err):
        return "ok-nonfinite", ""
    return "exit1-on-input", "exit 1: " + (err.strip().split("\n")[0][:300] if err.strip() else "(no message)")


# --------------------------------------------------------------------------
# STATE.json oracle


class StateInfo:
    def __init__(self, q_names, u_names, free_bodies, prescribed):
        self.q_names = list(q_names)
        self.u_names = list(u_names)
        self.free = list(free_bodies)
        self.prescribed = list(prescribed)


# A state value (other than a quaternion component) beyond this makes the state "either": the
# dynamics may overflow (exit 1 naming the quantity) or the mass matrix may be numerically
# singular there (a 1e30 modal coordinate with foreshortening, say).
HUGE = 1e3


class _Dup(Exception):
    pass


def strict_json_load(text):
    """Parses STATE.json text strictly; returns (object, underflow) or raises."""
    if has_bad_utf8(text):
        raise ValueError("invalid UTF-8")
    if text.startswith("\ufeff"):
        text = text[1:]  # kanegen drops a UTF-8 BOM
    flags = {"underflow": False}

    def pairs(p):
        keys = [k for k, _ in p]
        if len(set(keys)) != len(keys):
            raise _Dup("duplicate key")
        return dict(p)

    def const(s):
        raise ValueError("non-JSON constant " + s)

    def pfloat(s):
        x = float(s)
        if not math.isfinite(x):
            raise ValueError("out of range " + s)
        if x == 0.0 and re.search(r"[1-9]", s.split("e")[0].split("E")[0]):
            flags["underflow"] = True
        return x

    def pint(s):
        x = int(s)
        float(x)  # OverflowError when out of double range
        return x

    try:
        obj = json.loads(text, object_pairs_hook=pairs, parse_constant=const, parse_float=pfloat, parse_int=pint)
    except (ValueError, _Dup, RecursionError, OverflowError) as e:
        raise ValueError(str(e)) from None
    return obj, flags["underflow"]


def state_expectation(text, info):
    try:
        obj, underflow = strict_json_load(text)
    except ValueError:
        return "invalid"
    if not isinstance(obj, dict):
        return "invalid"

    def isnum(x):
        return isinstance(x, (int, float)) and not isinstance(x, bool)

    huge = False
    for k in obj:
        if k not in ("t", "q", "u", "tau"):
            return "invalid"
    if "t" in obj:
        if not isnum(obj["t"]):
            return "invalid"
        huge |= abs(float(obj["t"])) > HUGE
    quat = {f"{b}.{c}" for b in info.free for c in ("qw", "qx", "qy", "qz")}
    for sec, names in (("q", info.q_names), ("u", info.u_names), ("tau", info.u_names)):
        if sec not in obj:
            continue
        v = obj[sec]
        if not isinstance(v, dict):
            return "invalid"
        seen = set()
        for name, x in v.items():
            # a speed may be named by its older name (a rate under its coordinate's name)
            if sec != "q" and name not in names and name + "_rate" in names:
                name = name + "_rate"
            if name not in names or not isnum(x) or name in seen:
                return "invalid"
            seen.add(name)
            if not (sec == "q" and name in quat):
                huge |= abs(float(x)) > HUGE
    q = obj.get("q", {})
    for b in info.free:
        comps = [f"{b}.{c}" for c in ("qw", "qx", "qy", "qz")]
        given = [c in q for c in comps]
        if any(given) and not all(given):
            return "invalid"
        if all(given) and all(float(q[c]) == 0.0 for c in comps):
            return "invalid"
    return "either" if huge or underflow else "valid"


# --------------------------------------------------------------------------
# mutation operators
#
# A model/modal operator is f(rng, seed, sf) -> (text, expect, detail) or None when it does
# not apply; sf is the SeedFile mutated (the model or one of its modal files).
# A state operator is f(rng, seed, state_text, info) -> (text, detail) or None; its
# expectation comes from state_expectation().

CONTROL_POOL = ["\x00", "\x01", "\x07", "\x08", "\x0b", "\x0c", "\x1b", "\x1f", "\x7f"]
BAD_UTF8_POOL = ["\udcff", "\udc80", "\udcc3", "\udce2\udc82", "\udcf0\udc9f\udc98", "\udcc0\udcaf", "\udced\udca0\udc80"]
OTHER_POOL = ["é", "\u2028", "\u00a0", "\ufeff", "\u0085", "\u0086", "\r", "\t", "\u202e", "𝛼", "漢",
              ":", "{", "}", "[", "]", "&", "*", "!", "|", ">", "'", '"', "%", "@", "`", "#", ",", "-", "?", " "]


def random_bytes(rng, n):
    out = []
    for _ in range(n):
        r = rng.random()
        pool = CONTROL_POOL if r < 0.3 else BAD_UTF8_POOL if r < 0.55 else OTHER_POOL
        out.append(rng.choice(pool))
    return "".join(out)


def insertion_invalid(s):
    return any(is_c0_or_del(c) for c in s) or has_bad_utf8(s)


def yaml_line_kind(line):
    s = line.strip()
    if not s:
        return "blank"
    if s.startswith("#"):
        return "comment"
    return "content"


def yaml_same_data(a, b):
    """True when PyYAML reads both texts to the same data (a self-check for 'valid' text edits)."""
    if yaml is None:
        return True
    try:
        da = YDoc(a.lstrip("\ufeff")).data()
        db = YDoc(b.lstrip("\ufeff")).data()
    except Exception:  # noqa: BLE001
        return False
    return da == db


# ---- text-level, models and modal files


def t_delete_line(rng, seed, sf):
    lines = sf.text.split("\n")
    idx = [i for i, l in enumerate(lines) if l.strip()]
    if not idx:
        return None
    i = rng.choice(idx)
    kind = yaml_line_kind(lines[i])
    out = "\n".join(lines[:i] + lines[i + 1:])
    return out, "valid" if kind == "comment" else "either", f"deleted line {i + 1}: {lines[i][:60]!r}"


def pair_lines(doc):
    """line index -> True for lines that hold exactly one block-mapping 'key: one-line value' pair."""
    res = {}
    if doc is None:
        return res
    text = doc.text
    for _, m in doc.maps:
        if m.flow_style:
            continue
        for k, v in m.value:
            if is_block(v) or k.start_mark.line != v.end_mark.line:
                continue
            ls = text.rfind("\n", 0, k.start_mark.index) + 1
            if text[ls:k.start_mark.index].strip() == "":
                res[k.start_mark.line] = True
    return res


def t_duplicate_line(rng, seed, sf):
    lines = sf.text.split("\n")
    idx = [i for i, l in enumerate(lines) if l.strip()]
    if not idx:
        return None
    i = rng.choice(idx)
    kind = yaml_line_kind(lines[i])
    out = "\n".join(lines[:i + 1] + [lines[i]] + lines[i + 1:])
    if kind == "comment":
        expect = "valid"
    elif i in pair_lines(sf.doc):
        expect = "invalid"  # the same key twice in one mapping
    else:
        expect = "either"
    return out, expect, f"duplicated line {i + 1}: {lines[i][:60]!r}"


def t_swap_lines(rng, seed, sf):
    lines = sf.text.split("\n")
    idx = [i for i in range(len(lines) - 1) if lines[i].strip() and lines[i + 1].strip() and lines[i] != lines[i + 1]]
    if not idx:
        return None
    i = rng.choice(idx)
    lines[i], lines[i + 1] = lines[i + 1], lines[i]
    return "\n".join(lines), "either", f"swapped lines {i + 1} and {i + 2}"


def t_truncate(rng, seed, sf):
    raw = encode(sf.text)
    n = rng.choice([0, rng.randrange(len(raw)), rng.randrange(len(raw)), rng.randrange(len(raw))])
    cut = decode(raw[:n])
    rest = [l for l in cut.split("\n") if yaml_line_kind(l) == "content"]
    expect = "invalid" if not rest or has_bad_utf8(cut) else "either"
    return cut, expect, f"truncated to {n} of {len(raw)} bytes"


def t_insert_bytes(rng, seed, sf):
    s = random_bytes(rng, rng.choice([1, 1, 2, 4, 16]))
    pos = rng.randrange(len(sf.text) + 1)
    out = sf.text[:pos] + s + sf.text[pos:]
    return out, "invalid" if insertion_invalid(s) else "either", f"inserted {s!r} at char {pos}"


def t_reindent(rng, seed, sf):
    lines = sf.text.split("\n")
    idx = [i for i, l in enumerate(lines) if yaml_line_kind(l) == "content"]
    if not idx:
        return None
    i = rng.choice(idx)
    l = lines[i]
    if rng.random() < 0.5 and l.startswith(" "):
        n = rng.choice([1, 2])
        lines[i] = l[min(n, len(l) - len(l.lstrip(" "))):]
        what = f"dedented line {i + 1} by {n}"
    else:
        n = rng.choice([1, 2, 3])
        lines[i] = " " * n + l
        what = f"indented line {i + 1} by {n}"
    return "\n".join(lines), "either", what


def t_tab_indent(rng, seed, sf):
    lines = sf.text.split("\n")
    pl = pair_lines(sf.doc)
    idx = [i for i in pl if lines[i].startswith("  ")]
    if not idx:
        return None
    i = rng.choice(sorted(idx))
    l = lines[i]
    lines[i] = "\t" + l.lstrip(" ")
    return "\n".join(lines), "invalid", f"indented line {i + 1} with a tab"


def ensure_nl(text):
    return text if text.endswith("\n") or not text else text + "\n"


def t_second_document(rng, seed, sf):
    v = rng.randrange(4)
    extra = rng.choice(["name: other\n", "bodies: []\n", ensure_nl(sf.text), "x: 1\n"])
    if v == 0:
        return ensure_nl(sf.text) + "---\n" + extra, "invalid", "a second document after '---'"
    if v == 1:
        return ensure_nl(sf.text) + "...\n" + extra, "invalid", "content after '...'"
    if v == 2:
        return ensure_nl(sf.text) + "--- " + extra, "invalid", "'--- content' after the document"
    lines = sf.text.split("\n")
    idx = [i for i in range(1, len(lines)) if lines[i] and not lines[i][0].isspace() and yaml_line_kind(lines[i]) == "content"
           and any(yaml_line_kind(x) == "content" for x in lines[:i])]
    if not idx:
        return None
    i = rng.choice(idx)
    marker = rng.choice(["---", "..."])
    out = "\n".join(lines[:i] + [marker] + lines[i:])
    return out, "invalid", f"'{marker}' inserted before line {i + 1} (splits the document)"


def t_doc_markers(rng, seed, sf):
    v = rng.randrange(4)
    t = ensure_nl(sf.text)
    if v == 0:
        out, what = "---\n" + t, "explicit '---' first"
    elif v == 1:
        out, what = t + "...\n", "'...' last"
    elif v == 2:
        out, what = "%YAML 1.2\n---\n" + t + "...\n# trailing comment\n", "%YAML 1.2, ---, ..., comment"
    else:
        out, what = "--- # start\n" + t + "...\n", "'--- # comment' first and '...' last"
    return out, "valid", what


def t_line_endings(rng, seed, sf):
    v = rng.randrange(3)
    t = sf.text.replace("\r\n", "\n")
    if v == 0:
        return t.replace("\n", "\r"), "valid", "CR-only line breaks"
    if v == 1:
        return t.replace("\n", "\r\n"), "valid", "CRLF line breaks"
    parts = t.split("\n")
    out = parts[0]
    for p in parts[1:]:
        out += rng.choice(["\n", "\r\n", "\r"]) + p
    return out, "valid", "mixed LF, CRLF and CR line breaks"


def protected_lines(sf):
    """Lines inside multi-line scalars and flow collections (no comment line is inserted before them)."""
    prot = set()
    if sf.doc is None:
        return prot
    for _, n, _, _ in sf.doc.items:
        if (isinstance(n, yaml.ScalarNode) or not is_block(n)) and n.end_mark.line > n.start_mark.line:
            prot.update(range(n.start_mark.line + 1, n.end_mark.line + 1))
    return prot


def t_comments(rng, seed, sf):
    lines = sf.text.split("\n")
    prot = protected_lines(sf)
    cands = [i for i in range(len(lines) + 1) if i not in prot]
    comments = ["# a comment", "# ünïcødé ✓ — 漢字 𝛼", "#", "# " + "x" * 5000, "   # indented comment",
                "# key: value [ { ' \" & * !", "# \t tab"]
    out_lines = list(lines)
    n = rng.choice([1, 3])
    for _ in range(n):
        i = rng.choice(cands)
        out_lines.insert(i, rng.choice(comments))
    # trailing comments on content lines (after a space)
    if rng.random() < 0.5 and sf.doc is not None:
        pl = sorted(pair_lines(sf.doc))
        if pl:
            i = rng.choice(pl)
            if "#" not in lines[i]:
                j = out_lines.index(lines[i]) if lines[i] in out_lines else None
                if j is not None:
                    out_lines[j] = out_lines[j] + "  # trailing ünïcødé"
    out = "\n".join(out_lines)
    return out, "valid", f"{n} comment line(s) added"


def t_whitespace(rng, seed, sf):
    v = rng.randrange(4)
    lines = sf.text.split("\n")
    if v == 0:
        out = "\n".join(l + " " * rng.choice([0, 1, 3]) if l.strip() else l for l in lines)
        what = "trailing spaces"
    elif v == 1:
        out = sf.text.rstrip("\n")
        what = "no final line break"
    elif v == 2:
        out = ensure_nl(sf.text) + "\n\n   \n"
        what = "blank lines at the end"
    else:
        out = "\ufeff" + sf.text
        what = "UTF-8 BOM first"
    return out, "valid", what


# ---- structure-level (need PyYAML's composer)


def numeric_leaves(sf):
    doc = sf.doc
    if doc is None:
        return []
    out = []
    for path, n, key, parent in doc.items:
        if isinstance(n, yaml.ScalarNode) and n.style is None and NUM_RE.match(n.value) and last_key(path) not in STRING_KEYS:
            out.append((path, n, key))
    return out


def s_num_replace(rng, seed, sf):
    leaves = numeric_leaves(sf)
    if not leaves:
        return None
    path, n, key = rng.choice(leaves)
    kinds = [
        ("string", "invalid", ["abc", "1.0.0", "12abc", "one", "1,5", "1e", "--1", "0x1G", "yes", "true", ".", "1 2"]),
        ("quoted", "either", ['"1.5"', "'2'"]),
        ("null", "invalid", ["null", "~"]),
        ("list", "invalid", ["[[1.0]]", "{a: 1}"]),
        ("nonfinite", "invalid", [".nan", ".NaN", ".inf", "-.inf", ".Inf", "1e400", "-1e400", "1e999", "1.8e308"]),
        ("huge", "either", ["1e200", "-1e200", "1.7976931348623157e308", "1e300", "-1.7e308"]),
        ("tiny", "either", ["1e-300", "5e-324", "2.2250738585072014e-308", "1e-160", "-1e-200"]),
        ("underflow", "either", ["1e-400"]),
        ("negzero", "either", ["-0", "-0.0"]),
        ("negative", "either", None),
        ("hexoct", "either", ["0x10", "0o17", "0b1", "1_000"]),
    ]
    name, expect, pool = rng.choice(kinds)
    if pool is None:
        v = n.value
        repl = v[1:] if v.startswith("-") else "-" + v.lstrip("+")
    else:
        repl = rng.choice(pool)
    out = replace_value(sf.doc, n, key, repl)
    return out, expect, f"{path_str(path)}: {n.value} -> {repl[:40]} ({name})"


def s_num_valid_forms(rng, seed, sf):
    """The same number written another way: exponent form, '+' sign, leading-zero integer, int for float."""
    leaves = numeric_leaves(sf)
    if not leaves:
        return None
    path, n, key = rng.choice(leaves)
    v = n.value
    if INT_RE.match(v):
        sign = "-" if v.startswith("-") else ""
        digits = v.lstrip("+-")
        repl = rng.choice([sign + "0" + digits, sign + "00" + digits, ("+" + digits) if not sign else sign + "0" + digits])
        what = "leading zero / plus sign on an integer (decimal, as YAML 1.2)"
    else:
        x = float(v)
        choice = rng.randrange(4)
        if choice == 0:
            repl = f"{x:.17e}"
        elif choice == 1:
            repl = f"{x:.17E}"
        elif choice == 2 and x >= 0:
            repl = "+" + repr(x)
        elif x == int(x) and abs(x) < 1e15:
            repl = str(int(x))
        else:
            repl = repr(x)
        what = "same value, other notation"
    if repl == v:
        return None
    out = replace_value(sf.doc, n, key, repl)
    return out, "valid", f"{path_str(path)}: {v} -> {repl} ({what})"


REQUIRED_KEYS = {
    # (context, key): refused when missing
    ("top", "name"), ("top", "bodies"), ("body", "name"), ("body", "parent"), ("body", "joint"), ("joint", "type"),
    ("modal", "nodes"), ("modal", "modes"), ("node", "id"), ("node", "position"), ("node", "mass"),
    ("mode", "frequency"), ("mode", "shapes"), ("beam", "length"), ("beam", "direction"), ("beam", "mass_per_length"),
    ("beam", "EI"), ("spinup", "rate"), ("spinup", "duration"), ("sine", "amplitude"), ("sine", "frequency"),
    # and a rigid body's mass (below). Optional ("either" when dropped): description, gravity, initial,
    # outputs, position, rotation, stiffness, damping, rest, motion, damping_ratio, modes (subset),
    # foreshortening, mass_normalized, second_order, GJ, EA, a node's inertia, and also a body's com and
    # inertia and a beam's elements and modes, for which model-format.md gives no default but kanegen has one
}


def mapping_context(sf, path, seed):
    is_modal = sf.rel != seed.model_rel
    if path == ():
        return "modal" if is_modal else "top"
    if is_modal:
        if len(path) == 2 and path[0] == "nodes":
            return "node"
        if len(path) == 2 and path[0] == "modes":
            return "mode"
        return "other"
    if len(path) == 2 and path[0] == "bodies":
        return "body"
    if len(path) == 3 and path[0] == "bodies" and path[2] == "joint":
        return "joint"
    if path and path[-1] in ("beam", "spinup", "sine", "flexible"):
        return path[-1]
    return "other"


def s_drop_key(rng, seed, sf):
    doc = sf.doc
    if doc is None:
        return None
    cands = [(p, m, k, v) for p, m in doc.maps for k, v in m.value]
    if not cands:
        return None
    path, m, k, v = rng.choice(cands)
    ctx = mapping_context(sf, path, seed)
    expect = "invalid" if (ctx, k.value) in REQUIRED_KEYS else "either"
    d = to_py(m) if isinstance(m, yaml.MappingNode) else {}
    d = d if isinstance(d, dict) else {}
    # a revolute/prismatic joint's axis is required
    if ctx == "joint" and k.value == "axis" and d.get("type") in ("revolute", "prismatic"):
        expect = "invalid"
    # a rigid body (no flexible:) needs its mass
    if ctx == "body" and k.value == "mass" and "flexible" not in d:
        expect = "invalid"
    # every mode gives a shape for every node (a massless node without inertia may omit it: docs/decisions.md)
    if sf.rel != seed.model_rel and path and path[-1] == "shapes":
        expect = "either" if to_py(k) in massless_nodes(doc) else "invalid"
    # a body left with neither flexible: nor a rigid part
    if ctx == "body" and k.value == "flexible" and "mass" not in d:
        expect = "invalid"
    # a flexible block needs modal: or beam:
    if ctx == "flexible" and k.value in ("modal", "beam") and not ({"modal", "beam"} - {k.value}) & set(d):
        expect = "invalid"
    try:
        out = apply_edits(doc.text, [pair_delete_edit(doc.text, m, k, v)])
    except ValueError:
        return None
    return out, expect, f"dropped {path_str(path + (k.value,))}"


UNKNOWN_KEYS = ["colour", "massa", "Mass", "axes", "zz_extra", "comment", "inertia_", "joint2", "Name", "x-y"]


def s_add_key(rng, seed, sf):
    doc = sf.doc
    if doc is None:
        return None
    cands = [(p, m) for p, m in doc.maps if m.value or m.flow_style]
    if not cands:
        return None
    path, m = rng.choice(cands)
    existing = {k.value for k, _ in m.value if isinstance(k, yaml.ScalarNode)}
    key = rng.choice([u for u in UNKNOWN_KEYS if u not in existing])
    if path and path[-1] == "shapes" or path and path[-1] == "second_order":
        key = rng.choice(["999", "zz"])
    val = rng.choice(["1", "0.0", "[0, 0, 0]", "{a: 1}", "x"])
    e = pair_insert_edit(doc.text, m, f"{key}: {val}")
    if e is None:
        return None
    return apply_edits(doc.text, [e]), "invalid", f"unknown key {path_str(path + (key,))}"


def s_dup_key(rng, seed, sf):
    doc = sf.doc
    if doc is None:
        return None
    cands = []
    for p, m in doc.maps:
        for k, v in m.value:
            if not is_block(v) and single_line(doc.text, k) and k.start_mark.line == v.end_mark.line:
                cands.append((p, m, k, v))
    if not cands:
        return None
    path, m, k, v = rng.choice(cands)
    pair = doc.text[k.start_mark.index:v.end_mark.index]
    if rng.random() < 0.5 and isinstance(v, yaml.ScalarNode) and NUM_RE.match(v.value or ""):
        # the same key with another value: which one wins must not be a silent choice
        pair = doc.text[k.start_mark.index:k.end_mark.index] + ": " + ("0.5" if v.value != "0.5" else "0.25")
    e = pair_insert_edit(doc.text, m, pair)
    if e is None:
        return None
    return apply_edits(doc.text, [e]), "invalid", f"{path_str(path + (k.value,))} given twice"


def s_swap_type(rng, seed, sf):
    doc = sf.doc
    if doc is None:
        return None
    cands = []
    for path, n, key, parent in doc.items:
        if path == ():
            continue
        if isinstance(n, yaml.MappingNode):
            cands.append((path, n, key, ["[1, 2, 3]", "7", "abc", "[]"]))
        elif isinstance(n, yaml.SequenceNode):
            cands.append((path, n, key, ["{zz: 1}", "abc", "{}"]))
        elif isinstance(n, yaml.ScalarNode) and last_key(path) in STRING_KEYS and not isinstance(path[-1], int):
            cands.append((path, n, key, ["[x]", "{a: b}", "[]"]))
    if not cands:
        return None
    path, n, key, pool = rng.choice(cands)
    repl = rng.choice(pool)
    out = replace_value(doc, n, key, repl)
    return out, "invalid", f"{path_str(path)} -> {repl}"


def s_deep_nesting(rng, seed, sf):
    doc = sf.doc
    if doc is None:
        return None
    cands = [(p, n, k) for p, n, k, _ in doc.items if p != () and not is_block(n)]
    if not cands:
        return None
    path, n, key = rng.choice(cands)
    depth = rng.choice([33, 200, 5000, 100000])
    form = rng.randrange(3)
    if form == 0:
        repl = "[" * depth + "1" + "]" * depth
        what = f"[[...]] {depth} deep"
    elif form == 1:
        repl = "{a: " * depth + "1" + "}" * depth
        what = f"{{a: {{a: ...}}}} {depth} deep"
    else:
        repl = "[" + "{a: [" * (depth // 2) + "1" + "]}" * (depth // 2) + "]"
        what = f"[{{a: [...]}}] {depth} deep"
    out = apply_edits(doc.text, [(n.start_mark.index, n.end_mark.index, repl)])
    return out, "invalid", f"{path_str(path)}: {what}"


def s_deep_block_nesting(rng, seed, sf):
    doc = sf.doc
    if doc is None:
        return None
    cands = [(p, n, k) for p, n, k, parent in doc.items
             if p != () and isinstance(n, yaml.ScalarNode) and k is not None and not parent.flow_style]
    if not cands:
        return None
    path, n, key = rng.choice(cands)
    depth = rng.choice([100, 3000, 100000])
    # on the next line, indented under the key: "key:\n    - - - ... 1" (sequences of sequences)
    start = doc.text.index(":", key.end_mark.index) + 1
    repl = "\n" + " " * (key.start_mark.column + 2) + "- " * depth + "1"
    out = apply_edits(doc.text, [(start, n.end_mark.index, repl)])
    return out, "invalid", f"{path_str(path)}: block sequences '- - - ...' {depth} deep"


def bodies_nodes(doc):
    """(index, body mapping node) for bodies[i]."""
    if doc is None or not isinstance(doc.root, yaml.MappingNode):
        return []
    for k, v in doc.root.value:
        if k.value == "bodies" and isinstance(v, yaml.SequenceNode):
            return [(i, b) for i, b in enumerate(v.value) if isinstance(b, yaml.MappingNode)]
    return []


def get(node, key):
    if isinstance(node, yaml.MappingNode):
        for k, v in node.value:
            if isinstance(k, yaml.ScalarNode) and k.value == key:
                return k, v
    return None, None


def rename_body_edits(doc, old, new):
    edits = []
    for _, b in bodies_nodes(doc):
        for key in ("name", "parent"):
            k, v = get(b, key)
            if isinstance(v, yaml.ScalarNode) and v.value == old:
                edits.append((v.start_mark.index, v.end_mark.index, new))
    for section in ("inputs", "outputs"):  # named inputs and sensors refer to bodies and joints too
        _, seq = get(doc.root, section)
        if isinstance(seq, yaml.SequenceNode):
            for e in seq.value:
                for key in ("body", "joint"):
                    k, v = get(e, key)
                    if isinstance(v, yaml.ScalarNode) and v.value == old:
                        edits.append((v.start_mark.index, v.end_mark.index, new))
    _, init = get(doc.root, "initial")
    if isinstance(init, yaml.MappingNode):
        for _, sec in init.value:
            if isinstance(sec, yaml.MappingNode):
                for k, _ in sec.value:
                    if isinstance(k, yaml.ScalarNode) and k.value.startswith(old + "."):
                        edits.append((k.start_mark.index, k.end_mark.index, new + k.value[len(old):]))
    return edits


def body_names(doc):
    out = []
    for _, b in bodies_nodes(doc):
        _, v = get(b, "name")
        if isinstance(v, yaml.ScalarNode):
            out.append(v.value)
    return out


def s_names(rng, seed, sf):
    """Model and body names: valid unusual ones (keywords, digits first for the model, 300 characters) and invalid ones."""
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    names = body_names(doc)
    target = rng.choice(["model", "body"]) if names else "model"
    if target == "model":
        k, v = get(doc.root, "name")
        if not isinstance(v, yaml.ScalarNode):
            return None
        options = [
            (rng.choice(CPP_KEYWORDS), "valid", "C++ keyword"),
            ("3body", "valid", "digit first"), ("2", "valid", "digits only"), ("_x", "valid", "underscore first"),
            ("a" * 300, "valid", "300 characters"), ("x" + "_" * 40 + "y", "valid", "many underscores"),
            ("Pendulum", "invalid", "upper case"), ("my-model", "invalid", "hyphen"), ('"my model"', "invalid", "space"),
            ('""', "invalid", "empty"), ("modèle", "invalid", "non-ASCII letter"),
            ('"ab\\x01c"', "invalid", "control character (escaped)"), ("ab\x01c", "invalid", "raw control character"),
            ("ab\udcffc", "invalid", "invalid UTF-8"), ('"a/b"', "invalid", "slash"), ('"../x"', "invalid", "path"),
        ]
        new, expect, what = rng.choice(options)
        out = apply_edits(doc.text, [(v.start_mark.index, v.end_mark.index, new)])
        return out, expect, f"model name -> {new[:40]!r} ({what})"
    old = rng.choice(names)
    options = [
        (rng.choice(CPP_KEYWORDS), "valid", "C++ keyword"), ("b" * 300, "valid", "300 characters"),
        ("x9_", "valid", "digits and underscore"),
        ("ground", "invalid", "reserved 'ground'"), ("1" + old, "invalid", "digit first"), ("_" + old, "invalid", "underscore first"),
        (old.capitalize(), "invalid", "upper case"), (old + "-2", "invalid", "hyphen"), (old + ".x", "invalid", "dot"),
        ('"' + old + ' x"', "invalid", "space"), (old + "é", "invalid", "non-ASCII"), ('""', "invalid", "empty"),
        ('"' + old + '\\x01"', "invalid", "control character (escaped)"), (old + "\x01", "invalid", "raw control character"),
        (old + "\udcff", "invalid", "invalid UTF-8"), ('"' + old + '\\u202e"', "invalid", "bidi override"),
    ]
    new, expect, what = rng.choice(options)
    if new in names:
        return None
    edits = rename_body_edits(doc, old, new)
    if not edits:
        return None
    return apply_edits(doc.text, edits), expect, f"body '{old}' renamed to {new[:40]!r} ({what}), references too"


def s_duplicate_body_name(rng, seed, sf):
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    bn = bodies_nodes(doc)
    if len(bn) < 2:
        return None
    i, j = sorted(rng.sample(range(len(bn)), 2))
    _, vi = get(bn[i][1], "name")
    _, vj = get(bn[j][1], "name")
    if not isinstance(vi, yaml.ScalarNode) or not isinstance(vj, yaml.ScalarNode):
        return None
    out = apply_edits(doc.text, [(vj.start_mark.index, vj.end_mark.index, vi.value)])
    return out, "invalid", f"bodies[{j}].name = bodies[{i}].name = {vi.value}"


def s_parent(rng, seed, sf):
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    bn = bodies_nodes(doc)
    names = body_names(doc)
    if not bn:
        return None
    i, b = rng.choice(bn)
    _, v = get(b, "parent")
    _, nv = get(b, "name")
    if not isinstance(v, yaml.ScalarNode) or not isinstance(nv, yaml.ScalarNode):
        return None
    opts = [("nobody", "unknown body"), (nv.value, "itself"), ("Ground", "upper-case ground")]
    later = names[i + 1:]
    if later:
        opts.append((rng.choice(later), "a later body (not parents-first)"))
    new, what = rng.choice(opts)
    out = apply_edits(doc.text, [(v.start_mark.index, v.end_mark.index, new)])
    return out, "invalid", f"bodies[{i}].parent -> {new} ({what})"


def joints(doc):
    out = []
    for i, b in bodies_nodes(doc):
        k, j = get(b, "joint")
        if isinstance(j, yaml.MappingNode):
            out.append((i, b, k, j))
    return out


def s_joint_type(rng, seed, sf):
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    js = [(i, b, k, j) for i, b, k, j in joints(doc) if isinstance(get(j, "type")[1], yaml.ScalarNode)]
    if not js:
        return None
    i, b, k, j = rng.choice(js)
    _, t = get(j, "type")
    if rng.random() < 0.5:
        new = rng.choice(["hinge", "Revolute", "spherical", '"revolute "', "free6", "rev"])
        expect = "invalid"
    else:
        new = rng.choice([x for x in ("revolute", "prismatic", "fixed", "free") if x != t.value])
        expect = "either"
    out = apply_edits(doc.text, [(t.start_mark.index, t.end_mark.index, new)])
    return out, expect, f"bodies[{i}].joint.type {t.value} -> {new}"


def s_axis(rng, seed, sf):
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    cands = []
    for i, b, k, j in joints(doc):
        ka, a = get(j, "axis")
        if isinstance(a, yaml.SequenceNode) and len(a.value) == 3 and all(
                isinstance(x, yaml.ScalarNode) and NUM_RE.match(x.value) for x in a.value):
            cands.append((i, ka, a))
    if not cands:
        return None
    i, ka, a = rng.choice(cands)
    v = [float(x.value) for x in a.value]
    nrm = math.sqrt(sum(x * x for x in v))
    kind = rng.randrange(6)
    if kind == 0:
        new, expect, what = [0.0, 0.0, 0.0], "invalid", "zero"
    elif kind == 1:
        new, expect, what = [2 * x for x in v], "invalid", "norm 2"
    elif kind == 2:
        new, expect, what = [x * (1 + 4e-7) / nrm for x in v], "valid", "norm 1 + 4e-7 (normalized)"
    elif kind == 3:
        new, expect, what = [x * (1 + 1e-4) / nrm for x in v], "invalid", "norm 1 + 1e-4"
    elif kind == 4:
        new, expect, what = [x * 1e-160 for x in v], "invalid", "norm 1e-160"
    else:
        new, expect, what = [x * 1e200 for x in v], "invalid", "norm 1e200"
    repl = "[" + ", ".join(fmt_num(x) for x in new) + "]"
    out = replace_value(doc, a, ka, repl)
    return out, expect, f"bodies[{i}].joint.axis -> {repl} ({what})"


def random_unit_quat(rng):
    q = [rng.gauss(0, 1) for _ in range(4)]
    n = math.sqrt(sum(x * x for x in q))
    return [x / n for x in q]


def s_rotation(rng, seed, sf):
    """Joint rotations: add a quaternion rotation (unit, near-unit, tiny, huge, zero, partial), or break one."""
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    js = joints(doc)
    if not js:
        return None
    i, b, k, j = rng.choice(js)
    kr, r = get(j, "rotation")
    q = random_unit_quat(rng)
    kind = rng.randrange(8)
    if kind == 0:
        new, expect, what = q, "valid", "unit"
    elif kind == 1:
        new, expect, what = [x * (1 + 5e-7) for x in q], "valid", "norm 1 + 5e-7"
    elif kind == 2:
        new, expect, what = [x * 1e-160 for x in q], "invalid", "tiny (norm 1e-160)"
    elif kind == 3:
        new, expect, what = [x * 1e200 for x in q], "invalid", "huge (norm 1e200)"
    elif kind == 4:
        new, expect, what = [0.0, 0.0, 0.0, 0.0], "invalid", "zero"
    elif kind == 5:
        new, expect, what = q[:3], "invalid", "3 components"
    elif kind == 6:
        new, expect, what = None, "invalid", "two forms"
    else:
        new, expect, what = None, "invalid", "unknown form"
    if kind == 6:
        text = "{rpy: [0, 0, 0], quaternion: [1, 0, 0, 0]}"
    elif kind == 7:
        text = "{euler: [0, 0, 0]}"
    else:
        text = "{quaternion: [" + ", ".join(fmt_num(x) for x in new) + "]}"
    if r is not None:
        out = replace_value(doc, r, kr, text)
    else:
        e = pair_insert_edit(doc.text, j, "rotation: " + text)
        if e is None:
            return None
        out = apply_edits(doc.text, [e])
    return out, expect, f"bodies[{i}].joint.rotation -> {text[:70]} ({what})"


def s_matrix_rotation(rng, seed, sf):
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    js = joints(doc)
    if not js:
        return None
    i, b, k, j = rng.choice(js)
    kr, r = get(j, "rotation")
    kind = rng.randrange(4)
    M = [[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]
    c, s = math.cos(0.3), math.sin(0.3)
    R = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
    if kind == 0:
        M, expect, what = R, "valid", "proper rotation"
    elif kind == 1:
        M, expect, what = [[2 * x for x in row] for row in R], "invalid", "scaled by 2"
    elif kind == 2:
        M, expect, what = [R[0], R[1], [0.0, 0.0, -1.0]], "invalid", "determinant -1"
    else:
        M, expect, what = [R[0], R[1]], "invalid", "2 rows"
    text = "{matrix: [" + ", ".join("[" + ", ".join(fmt_num(x) for x in row) + "]" for row in M) + "]}"
    if r is not None:
        out = replace_value(doc, r, kr, text)
    else:
        e = pair_insert_edit(doc.text, j, "rotation: " + text)
        if e is None:
            return None
        out = apply_edits(doc.text, [e])
    return out, expect, f"bodies[{i}].joint.rotation -> matrix ({what})"


def s_inertia(rng, seed, sf):
    doc = sf.doc
    if doc is None:
        return None
    cands = []
    for path, n, key, parent in doc.items:
        if last_key(path) == "inertia" and isinstance(n, yaml.SequenceNode) and len(n.value) == 6 and all(
                isinstance(x, yaml.ScalarNode) and NUM_RE.match(x.value) for x in n.value) and not isinstance(path[-1], int):
            cands.append((path, n, key))
    if not cands:
        return None
    path, n, key = rng.choice(cands)
    I = [float(x.value) for x in n.value]
    body = path[0] == "bodies"
    kind = rng.randrange(6 if body else 5)
    s = max(max(abs(x) for x in I), 1e-3)
    if kind == 0:
        new, expect, what = [s, s, s, 2 * s, 0.0, 0.0], "invalid", "not positive semi-definite"
    elif kind == 1:
        new, expect, what = [s, s, 3 * s, 0.0, 0.0, 0.0], "invalid", "triangle inequality violated"
    elif kind == 2:
        new, expect, what = [-s, s, s, 0.0, 0.0, 0.0], "invalid", "negative moment"
    elif kind == 3:
        new, expect, what = I[:5], "invalid", "5 numbers"
    elif kind == 4:
        new, expect, what = [[I[0], I[3], I[4]], [I[3] + s, I[1], I[5]], [I[4], I[5], I[2]]], "invalid", "3x3 not symmetric"
    else:
        new, expect, what = [[I[0], I[3], I[4]], [I[3], I[1], I[5]], [I[4], I[5], I[2]]], "valid", "the same as a 3x3 list"
    if new and isinstance(new[0], list):
        repl = "[" + ", ".join("[" + ", ".join(fmt_num(x) for x in row) + "]" for row in new) + "]"
    else:
        repl = "[" + ", ".join(fmt_num(x) for x in new) + "]"
    out = replace_value(doc, n, key, repl)
    return out, expect, f"{path_str(path)} -> {repl[:80]} ({what})"


def s_mass(rng, seed, sf):
    doc = sf.doc
    if doc is None:
        return None
    cands = [(p, n, k) for p, n, k, _ in doc.items if last_key(p) in ("mass", "mass_per_length", "length")
             and isinstance(n, yaml.ScalarNode) and NUM_RE.match(n.value) and not isinstance(p[-1], int)]
    if not cands:
        return None
    path, n, key = rng.choice(cands)
    x = float(n.value)
    if x == 0:
        repl = "-1.0"
    else:
        repl = fmt_num(-abs(x))
    out = replace_value(doc, n, key, repl)
    return out, "invalid", f"{path_str(path)}: {n.value} -> {repl} (negative)"


def s_list_length(rng, seed, sf):
    doc = sf.doc
    if doc is None:
        return None
    fixed = {"gravity", "com", "axis", "position", "rpy", "inertia", "EI", "quaternion", "damping_ratio"}
    cands = []
    for path, n, key, parent in doc.items:
        lk = last_key(path)
        if isinstance(n, yaml.SequenceNode) and n.flow_style and n.value and all(
                isinstance(x, yaml.ScalarNode) and NUM_RE.match(x.value) for x in n.value):
            if lk in fixed or (isinstance(path[-1], int) and len(path) >= 2) or lk in ("matrix",):
                cands.append((path, n, key))
            elif len(path) >= 2 and path[-2] == "shapes":
                cands.append((path, n, key))
    if not cands:
        return None
    path, n, key = rng.choice(cands)
    vals = [x.value for x in n.value]
    if rng.random() < 0.5 and len(vals) > 1:
        new, what = vals[:-1], "one number fewer"
    else:
        new, what = vals + ["0.0"], "one number more"
    repl = "[" + ", ".join(new) + "]"
    out = replace_value(doc, n, key, repl)
    return out, "invalid", f"{path_str(path)}: {what}"


def s_outputs(rng, seed, sf):
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    k, v = get(doc.root, "outputs")
    kind = rng.randrange(3)
    if kind == 0:
        repl, expect, what = "[energy, torques]", "invalid", "unknown output"
    elif kind == 1:
        repl, expect, what = "[Energy]", "invalid", "upper case"
    else:
        repl, expect, what = "[]", "either", "empty"
    if v is None:
        return ensure_nl(doc.text) + "outputs: " + repl + "\n", expect, f"outputs: {repl} ({what})"
    return replace_value(doc, v, k, repl), expect, f"outputs -> {repl} ({what})"


def s_motion(rng, seed, sf):
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    js = [(i, b, k, j) for i, b, k, j in joints(doc)
          if isinstance(get(j, "type")[1], yaml.ScalarNode) and get(j, "type")[1].value in ("revolute", "prismatic")]
    if not js:
        return None
    i, b, k, j = rng.choice(js)
    _, nm = get(b, "name")
    name = nm.value if isinstance(nm, yaml.ScalarNode) else "?"
    jt = get(j, "type")[1].value
    coord = f"{name}.{'angle' if jt == 'revolute' else 'disp'}"
    km, m = get(j, "motion")
    has_spring = any(get(j, x)[1] is not None for x in ("stiffness", "damping", "rest"))
    init = seed.data.get("initial") if isinstance(seed.data, dict) else None
    named_in_initial = isinstance(init, dict) and any(
        isinstance(sec, dict) and coord in sec for sec in init.values())
    options = [
        ("{spinup: {rate: 1.0, duration: 0}}", "invalid", "spinup with duration 0"),
        ("{polynomial: []}", "invalid", "no coefficients"),
        ("{polynomial: [0, 1, 2, 3, 4, 5, 6, 7, 8]}", "invalid", "9 coefficients"),
        ("{sine: {amplitude: 0.1, frequency: 1.0}, polynomial: [0.0]}", "invalid", "two kinds"),
        ("{spin: {rate: 1.0}}", "invalid", "unknown kind"),
        ("{sine: {amplitude: 0.1}}", "invalid", "sine without frequency"),
    ]
    dof_left = len(seed.u_names) >= 2
    # a joint torque input on a prescribed joint is refused (no degree of freedom to drive)
    inputs = seed.data.get("inputs") if isinstance(seed.data, dict) else None
    driven = isinstance(inputs, list) and any(isinstance(e, dict) and e.get("joint") == name for e in inputs)
    ok_expect = "invalid" if (has_spring or named_in_initial or driven) else ("valid" if dof_left else "either")
    options += [("{sine: {amplitude: 0.1, frequency: 1.0}}", ok_expect, "sine"),
                ("{polynomial: [0.1, 0.2]}", ok_expect, "polynomial"),
                ("{spinup: {rate: 2.0, duration: 5.0}}", ok_expect, "spinup")]
    repl, expect, what = rng.choice(options)
    if m is not None:
        if expect != "invalid":
            expect = "invalid" if has_spring else "either"
        out = replace_value(doc, m, km, repl)
    else:
        e = pair_insert_edit(doc.text, j, "motion: " + repl)
        if e is None:
            return None
        out = apply_edits(doc.text, [e])
    return out, expect, f"bodies[{i}].joint.motion -> {repl} ({what}; spring {has_spring}, in initial {named_in_initial})"


def s_initial_quaternion(rng, seed, sf):
    """A free joint's quaternion in the model's initial: block (norm must be within 1e-6 of 1)."""
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel or not seed.free_bodies:
        return None
    body = rng.choice(seed.free_bodies)
    comps = [f"{body}.q{c}" for c in "wxyz"]
    q = random_unit_quat(rng)
    kind = rng.randrange(7)
    if kind == 0:
        vals, expect, what = q, "valid", "unit"
    elif kind == 1:
        vals, expect, what = [x * (1 - 5e-7) for x in q], "valid", "norm 1 - 5e-7"
    elif kind == 2:
        vals, expect, what = [x * 1e-160 for x in q], "invalid", "tiny (1e-160)"
    elif kind == 3:
        vals, expect, what = [x * 1e200 for x in q], "invalid", "huge (1e200)"
    elif kind == 4:
        vals, expect, what = [0.0] * 4, "invalid", "zero"
    elif kind == 5:
        vals, expect, what = [0.5, 0.5, 0.5, 0.5][:rng.choice([1, 2, 3])], "invalid", "partial"
    else:
        vals, expect, what = [5e-324, 0.0, 0.0, 0.0], "invalid", "norm 5e-324"
    given = dict(zip(comps, vals))
    ki, init = get(doc.root, "initial")
    if isinstance(init, yaml.MappingNode):  # initial.orbit with attitude: lvlh sets the root's quaternion
        ko, orb = get(init, "orbit")
        if isinstance(orb, yaml.MappingNode):
            ka, att = get(orb, "attitude")
            if isinstance(att, yaml.ScalarNode) and att.value == "lvlh":
                expect, what = "invalid", what + ", but set by initial.orbit's attitude: lvlh"
    edits = []
    if isinstance(init, yaml.MappingNode):
        kq, qn = get(init, "q")
        if isinstance(qn, yaml.MappingNode):
            existing = {}
            for k, v in qn.value:
                existing[k.value] = (k, v)
            adds = []
            for c in comps:
                if c in existing:
                    k, v = existing[c]
                    if c in given:
                        edits.append((v.start_mark.index, v.end_mark.index, fmt_num(given[c])))
                    else:
                        edits.append(pair_delete_edit(doc.text, qn, k, v))
                elif c in given:
                    adds.append(f"{c}: {fmt_num(given[c])}")
            if adds:
                if not qn.value:
                    return None
                sep = ", " if qn.flow_style else "\n" + " " * qn.value[0][0].start_mark.column
                edits.append(pair_insert_edit(doc.text, qn, sep.join(adds)))
        elif qn is None:
            if not init.value:
                return None
            e = pair_insert_edit(doc.text, init, "q: {" + ", ".join(f"{c}: {fmt_num(x)}" for c, x in given.items()) + "}")
            edits.append(e)
        else:
            return None
        try:
            out = apply_edits(doc.text, edits)
        except ValueError:
            return None
    elif init is None:
        out = ensure_nl(doc.text) + "initial:\n  q: {" + ", ".join(f"{c}: {fmt_num(x)}" for c, x in given.items()) + "}\n"
    else:
        return None
    return out, expect, f"initial q of {body}: quaternion {what}"


def massless_nodes(doc):
    """Ids of modal nodes with zero mass and no inertia (their shapes may be left out: docs/decisions.md)."""
    try:
        data = doc.data()
        return {n.get("id") for n in data.get("nodes", []) if isinstance(n, dict)
                and not n.get("mass") and not n.get("inertia")}
    except Exception:  # noqa: BLE001
        return set()


def s_node_refs(rng, seed, sf):
    """Node ids: a joint at a missing node, a mode without a node's shape, an extra shape, duplicate node ids."""
    doc = sf.doc
    if doc is None:
        return None
    if sf.rel == seed.model_rel:
        cands = []
        for i, b, k, j in joints(doc):
            kn, n = get(j, "node")
            if isinstance(n, yaml.ScalarNode):
                cands.append((i, n))
        if not cands:
            return None
        i, n = rng.choice(cands)
        new = rng.choice(["999", "0", "-1", "abc"])
        out = apply_edits(doc.text, [(n.start_mark.index, n.end_mark.index, new)])
        return out, "invalid", f"bodies[{i}].joint.node -> {new} (no such node)"
    kind = rng.randrange(3)
    _, nodes = get(doc.root, "nodes")
    _, modes = get(doc.root, "modes")
    if kind == 0 and isinstance(modes, yaml.SequenceNode) and modes.value:
        mi = rng.randrange(len(modes.value))
        _, shapes = get(modes.value[mi], "shapes")
        if isinstance(shapes, yaml.MappingNode) and len(shapes.value) > 1:
            k, v = rng.choice(shapes.value)
            out = apply_edits(doc.text, [pair_delete_edit(doc.text, shapes, k, v)])
            expect = "either" if to_py(k) in massless_nodes(doc) else "invalid"
            return out, expect, f"modes[{mi}].shapes: node {k.value} left out"
    if kind == 1 and isinstance(nodes, yaml.SequenceNode) and len(nodes.value) > 1:
        ni = rng.randrange(len(nodes.value))
        _, idn = get(nodes.value[ni], "id")
        if isinstance(idn, yaml.ScalarNode):
            other = [get(x, "id")[1] for x in nodes.value if x is not nodes.value[ni]]
            other = [o.value for o in other if isinstance(o, yaml.ScalarNode)]
            new = rng.choice(other + ["999"])
            out = apply_edits(doc.text, [(idn.start_mark.index, idn.end_mark.index, new)])
            what = "duplicate id" if new != "999" else "id not in the shapes"
            return out, "invalid", f"nodes[{ni}].id {idn.value} -> {new} ({what})"
    if isinstance(modes, yaml.SequenceNode) and modes.value:
        mi = rng.randrange(len(modes.value))
        _, shapes = get(modes.value[mi], "shapes")
        if isinstance(shapes, yaml.MappingNode) and shapes.value:
            e = pair_insert_edit(doc.text, shapes, "999: [0, 0, 0, 0, 0, 0]")
            if e:
                return apply_edits(doc.text, [e]), "invalid", f"modes[{mi}].shapes: shape for unlisted node 999"
    return None


def s_flexible(rng, seed, sf):
    """A flexible body's modal path, modes subset, beam parameters and damping ratio."""
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    cands = []
    for i, b in bodies_nodes(doc):
        _, fl = get(b, "flexible")
        if isinstance(fl, yaml.MappingNode):
            cands.append((i, fl))
    if not cands:
        return None
    i, fl = rng.choice(cands)
    opts = []
    km, modal = get(fl, "modal")
    if isinstance(modal, yaml.ScalarNode):
        opts += [(km, modal, "missing.modal.yaml", "invalid", "no such file"),
                 (km, modal, seed.model_rel, "invalid", "the model file itself"),
                 (km, modal, ".", "invalid", "a directory"),
                 (km, modal, '""', "invalid", "empty path")]
    kmo, modes = get(fl, "modes")
    if isinstance(modes, yaml.SequenceNode):
        opts += [(kmo, modes, "[0]", "invalid", "mode 0"), (kmo, modes, "[99]", "invalid", "mode 99"),
                 (kmo, modes, "[]", "invalid", "empty list"), (kmo, modes, "[1, 1]", "invalid", "mode twice")]
    kb, beam = get(fl, "beam")
    if isinstance(beam, yaml.MappingNode):
        for key, bad in (("direction", "w"), ("direction", "X"), ("elements", "0"), ("elements", "-3"),
                         ("modes", "0"), ("length", "0"), ("EI", "[2.0, -1.0]")):
            kk, vv = get(beam, key)
            if vv is not None:
                opts.append((kk, vv, bad, "invalid", f"beam.{key} = {bad}"))
    kd, dr = get(fl, "damping_ratio")
    if dr is not None:
        opts += [(kd, dr, "-0.1", "invalid", "negative damping ratio"), (kd, dr, "abc", "invalid", "not a number")]
    kf, fs = get(fl, "foreshortening")
    if fs is not None:
        opts.append((kf, fs, "maybe", "invalid", "not a boolean"))
    if not opts:
        return None
    k, v, repl, expect, what = rng.choice(opts)
    return replace_value(doc, v, k, repl), expect, f"bodies[{i}].flexible: {what}"


def modal_masses(data):
    nodes = {n["id"]: n for n in data.get("nodes", []) if isinstance(n, dict)}
    out = []
    for m in data.get("modes", []):
        tot = 0.0
        for nid, s in (m.get("shapes") or {}).items():
            n = nodes.get(nid, {})
            mass = float(n.get("mass", 0.0) or 0.0)
            t, r = s[:3], s[3:]
            tot += mass * sum(x * x for x in t)
            I = n.get("inertia")
            if isinstance(I, list) and len(I) == 6:
                J = [[I[0], I[3], I[4]], [I[3], I[1], I[5]], [I[4], I[5], I[2]]]
                tot += sum(r[a] * J[a][b] * r[b] for a in range(3) for b in range(3))
        out.append(tot)
    return out


def s_modal_normalization(rng, seed, sf):
    doc = sf.doc
    if doc is None or sf.rel == seed.model_rel:
        return None
    try:
        data = doc.data()
        masses = modal_masses(data)
    except Exception:  # noqa: BLE001
        return None
    if not masses:
        return None
    normalized = all(abs(m - 1) <= 1e-6 for m in masses)
    k, v = get(doc.root, "mass_normalized")
    declared = True if v is None else to_py(v)
    if declared is True:
        return None if normalized is False else (
            (replace_value(doc, v, k, "false") if v is not None else ensure_nl(doc.text) + "mass_normalized: false\n"),
            "valid", "mass_normalized: false on normalized modes")
    if not normalized:
        return replace_value(doc, v, k, "true"), "invalid", "mass_normalized: true on modes of modal mass " + \
            ", ".join(f"{m:.4g}" for m in masses)
    return None


def s_second_order(rng, seed, sf):
    doc = sf.doc
    if doc is None or sf.rel == seed.model_rel:
        return None
    cands = []
    for path, n, key, parent in doc.items:
        if path and path[0] == "second_order" and isinstance(n, yaml.SequenceNode) and len(n.value) >= 2 and all(
                isinstance(r, yaml.SequenceNode) for r in n.value):
            cands.append((path, n, key))
    if not cands:
        return None
    path, n, key = rng.choice(cands)
    try:
        M = [[float(x.value) for x in r.value] for r in n.value]
    except ValueError:
        return None
    s = max(1.0, max(abs(x) for r in M for x in r))
    M[0][1] += s
    repl = "[" + ", ".join("[" + ", ".join(fmt_num(x) for x in r) + "]" for r in M) + "]"
    return replace_value(doc, n, key, repl), "invalid", f"{path_str(path)}: not symmetric"


def s_gravity_huge(rng, seed, sf):
    """Huge but finite gravity or initial speed: eval must exit 0 with finite numbers or 1 naming the quantity."""
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    k, g = get(doc.root, "gravity")
    val = rng.choice(["1e200", "-1.7e308", "1e154", "1.7976931348623157e308"])
    if isinstance(g, yaml.SequenceNode) and len(g.value) == 3:
        idx = rng.randrange(3)
        n = g.value[idx]
        return apply_edits(doc.text, [(n.start_mark.index, n.end_mark.index, val)]), "either", \
            f"gravity[{idx}] -> {val}"
    if g is None:
        return ensure_nl(doc.text) + f"gravity: [0, 0, {val}]\n", "either", f"gravity: [0, 0, {val}]"
    return None



def events_nodes(doc):
    """(index, event mapping node) for the top-level events: list."""
    if doc is None or not isinstance(doc.root, yaml.MappingNode):
        return []
    _, ev = get(doc.root, "events")
    if not isinstance(ev, yaml.SequenceNode):
        return []
    return [(i, e) for i, e in enumerate(ev.value) if isinstance(e, yaml.MappingNode)]


def s_events(rng, seed, sf):
    """The events: list (model-format.md, Locks and events): an empty lock:/release: list, a state event on a
    quaternion component or on another coordinate, the time of a time event."""
    doc = sf.doc
    if doc is None or sf.rel != seed.model_rel:
        return None
    evs = events_nodes(doc)
    if not evs:
        return None
    kind = rng.choice(["empty_action", "quat_coordinate", "other_coordinate", "at_valid", "at_bad"])
    if kind == "empty_action":
        i, e = rng.choice(evs)
        action = rng.choice(["lock", "release"])
        k, v = get(e, action)
        if v is not None:
            out = replace_value(doc, v, k, "[]")
        else:
            edit = pair_insert_edit(doc.text, e, f"{action}: []")
            if edit is None:
                return None
            out = apply_edits(doc.text, [edit])
        return out, "invalid", f"events[{i}].{action}: [] (an empty action list)"
    if kind in ("quat_coordinate", "other_coordinate"):
        cands = []
        for i, e in evs:
            _, w = get(e, "when")
            k, c = get(w, "coordinate")
            if isinstance(c, yaml.ScalarNode):
                cands.append((i, k, c))
        quat = [n for n in seed.q_names if re.search(r"\.q[wxyz]$", n)]
        if kind == "quat_coordinate":
            names, expect, what = quat, "invalid", "a component of a free or ball joint's quaternion"
        else:
            prescribed = set(seed.prescribed)
            names, expect, what = [n for n in seed.q_names if n not in quat and n not in prescribed], "valid", \
                "another coordinate (a position, an angle or a modal coordinate)"
        if not cands or not names:
            return None
        i, k, c = rng.choice(cands)
        name = rng.choice(names)
        if name == c.value:
            return None
        out = replace_value(doc, c, k, name)
        return out, expect, f"events[{i}].when.coordinate: {c.value} -> {name} ({what})"
    times = []
    for i, e in evs:
        k, v = get(e, "at")
        if isinstance(v, yaml.ScalarNode):
            times.append((i, k, v))
    if not times:
        return None
    i, k, v = rng.choice(times)
    if kind == "at_valid":
        name, expect, pool = "another finite time", "valid", ["0", "0.0", "1e-9", "0.25", "3.5", "7", "12.75", "2.5e2",
                                                                "1e3", "86400.0"]
    else:
        # model-format.md says no more than "at: T (s) fires at time T": a negative time is "either" (kanegen
        # refuses it); a time that is no finite number is refused as any number is
        name, expect, pool = rng.choice([
            ("negative", "either", ["-1.0", "-0.5", "-1e-9", "-10", "-1e300"]),
            ("nonfinite", "invalid", [".nan", ".NaN", ".inf", "-.inf", "1e400"]),
            ("string", "invalid", ["ten", "abc", "'later'", "10 s", "now", "1.0.0"]),
            ("null", "invalid", ["null", "~"]),
        ])
    repl = rng.choice(pool)
    if repl == v.value:
        return None
    out = replace_value(doc, v, k, repl)
    return out, expect, f"events[{i}].at: {v.value} -> {repl} ({name})"


MODEL_OPS = [
    ("t_delete_line", t_delete_line), ("t_duplicate_line", t_duplicate_line), ("t_swap_lines", t_swap_lines),
    ("t_truncate", t_truncate), ("t_insert_bytes", t_insert_bytes), ("t_reindent", t_reindent),
    ("t_tab_indent", t_tab_indent), ("t_second_document", t_second_document), ("t_doc_markers", t_doc_markers),
    ("t_line_endings", t_line_endings), ("t_comments", t_comments), ("t_whitespace", t_whitespace),
    ("s_num_replace", s_num_replace), ("s_num_valid_forms", s_num_valid_forms), ("s_drop_key", s_drop_key),
    ("s_add_key", s_add_key), ("s_dup_key", s_dup_key), ("s_swap_type", s_swap_type),
    ("s_deep_nesting", s_deep_nesting), ("s_deep_block_nesting", s_deep_block_nesting), ("s_names", s_names),
    ("s_duplicate_body_name", s_duplicate_body_name), ("s_parent", s_parent), ("s_joint_type", s_joint_type),
    ("s_axis", s_axis), ("s_rotation", s_rotation), ("s_matrix_rotation", s_matrix_rotation),
    ("s_inertia", s_inertia), ("s_mass", s_mass), ("s_list_length", s_list_length), ("s_outputs", s_outputs),
    ("s_motion", s_motion), ("s_initial_quaternion", s_initial_quaternion), ("s_node_refs", s_node_refs),
    ("s_flexible", s_flexible), ("s_modal_normalization", s_modal_normalization),
    ("s_second_order", s_second_order), ("s_gravity_huge", s_gravity_huge), ("s_events", s_events),
]
# structure operators that also apply to modal files, and those that apply to modal files only
MODAL_TOO = {"s_num_replace", "s_num_valid_forms", "s_drop_key", "s_add_key", "s_dup_key", "s_swap_type",
             "s_deep_nesting", "s_deep_block_nesting", "s_inertia", "s_mass", "s_list_length", "s_node_refs"}
MODAL_ONLY = {"s_modal_normalization", "s_second_order"}
# operators that are formatting-only and "valid": self-checked with PyYAML (same data), else downgraded
FORMAT_ONLY = {"t_doc_markers", "t_line_endings", "t_comments", "t_whitespace", "s_num_valid_forms"}
# operators (model and cli) for models with a top-level events: list only (two seeds), each pair
# scheduled this many times a round, so that a 30 s budget (about a third of a round) sees them
EVENTS_ONLY = {"s_events", "c_same_file"}
EVENTS_WEIGHT = 12

# ---- STATE.json


def json_text(obj, indent=1):
    return json.dumps(obj, indent=indent)


def state_obj(text):
    try:
        return strict_json_load(text)[0]
    except ValueError:
        return None


def render_members(members, indent="  "):
    """Members as list of (key, raw value text) -> JSON object text (keys may repeat)."""
    if not members:
        return "{}"
    return "{\n" + ",\n".join(f"{indent}{json.dumps(k)}: {v}" for k, v in members) + "\n" + indent[:-1] + "}"


def state_sections(obj):
    return [s for s in ("q", "u", "tau") if isinstance(obj.get(s), dict) and obj[s]]


def rebuild_state(obj, override=None):
    """Renders a state object, with raw-text overrides {(section, name): raw} and extra members."""
    override = override or {}
    top = []
    for k, v in obj.items():
        if isinstance(v, dict):
            mem = []
            for n, x in v.items():
                mem.append((n, override.get((k, n), json.dumps(x))))
            for (sec, n), raw in override.items():
                if sec == k and n not in v:
                    mem.append((n, raw))
            top.append((k, render_members(mem, "   ")))
        else:
            top.append((k, override.get((k, None), json.dumps(v))))
    return render_members(top, " ")


def j_text_ops(rng, seed, text, info):
    v = rng.randrange(9)
    lines = text.split("\n")
    if v == 0 and len(lines) > 1:
        i = rng.randrange(len(lines))
        return "\n".join(lines[:i] + lines[i + 1:]), f"deleted line {i + 1}: {lines[i][:50]!r}"
    if v == 1:
        i = rng.randrange(len(lines))
        return "\n".join(lines[:i + 1] + [lines[i]] + lines[i + 1:]), f"duplicated line {i + 1}: {lines[i][:50]!r}"
    if v == 2 and len(lines) > 2:
        i = rng.randrange(len(lines) - 1)
        lines[i], lines[i + 1] = lines[i + 1], lines[i]
        return "\n".join(lines), f"swapped lines {i + 1} and {i + 2}"
    if v == 3:
        raw = encode(text)
        n = rng.randrange(len(raw) + 1)
        return decode(raw[:n]), f"truncated to {n} of {len(raw)} bytes"
    if v == 4:
        s = random_bytes(rng, rng.choice([1, 2, 4]))
        pos = rng.randrange(len(text) + 1)
        return text[:pos] + s + text[pos:], f"inserted {s!r} at char {pos}"
    if v == 5:
        kind = rng.randrange(5)
        if kind == 0:
            return text.replace("\n", "\r"), "CR-only line breaks"
        if kind == 1:
            return text.replace("\n", "\r\n"), "CRLF line breaks"
        if kind == 2:
            return "\ufeff" + text, "UTF-8 BOM first"
        if kind == 3:
            obj = state_obj(text)
            if obj is None:
                return None
            return json.dumps(obj, separators=(",", ":")), "minified on one line"
        return "\n\n  " + text.replace("\n", "\n\t") + "\n \n", "extra whitespace and tabs"
    if v == 6:
        g = rng.choice(["x", "}", ",", "{}", "// comment", "# comment", "\x00", "null", "\n{\"t\": 0}", "]"])
        return text.rstrip() + g, f"trailing {g!r}"
    if v == 7:
        g = rng.choice(["", " ", "\n", "\ufeff", "null", "[]", "\"q\"", "42", "true", "{", "{\"q\": {}"])
        return g, f"whole file {g!r}"
    # a number written another way (valid or not per JSON)
    nums = list(re.finditer(r"(?<=: )-?[0-9][0-9.eE+-]*", text))
    if not nums:
        return None
    m = rng.choice(nums)
    x = m.group(0)
    try:
        fx = float(x)
    except ValueError:
        return None
    forms = [f"{fx:.17e}", f"{fx:.17E}", "+" + x.lstrip("-"), "0" + x.lstrip("-"), x + ".", ".5",
             "-0", "-0.0", "0x10", repr(fx) + "e0", x.replace("e", "E"), "1_0"]
    f = rng.choice(forms)
    return text[:m.start()] + f + text[m.end():], f"number {x} written as {f}"


def j_dup_key(rng, seed, text, info):
    obj = state_obj(text)
    if not isinstance(obj, dict):
        return None
    secs = state_sections(obj)
    if secs and rng.random() < 0.8:
        sec = rng.choice(secs)
        name = rng.choice(list(obj[sec]))
        members = list(obj[sec].items())
        raw_members = [(k, json.dumps(v)) for k, v in members] + [(name, json.dumps(0.123))]
        top = [(k, render_members(raw_members, "   ") if k == sec else json.dumps(v)) for k, v in obj.items()]
        return render_members(top, " "), f"{sec}.{name} given twice"
    top = [(k, json.dumps(v)) for k, v in obj.items()]
    key = rng.choice([k for k, _ in top] or ["t"])
    top.append((key, json.dumps(obj.get(key, 0.0))))
    return render_members(top, " "), f"top-level {key} given twice"


def j_deep_nesting(rng, seed, text, info):
    obj = state_obj(text)
    depth = rng.choice([3, 33, 1000, 100000])
    kind = rng.randrange(3)
    if kind == 0 or not isinstance(obj, dict):
        return "[" * depth + "]" * depth if rng.random() < 0.5 else '{"q":' * depth + "{}" + "}" * depth, \
            f"root nested {depth} deep"
    secs = state_sections(obj)
    if not secs:
        return None
    sec = rng.choice(secs)
    name = rng.choice(list(obj[sec]))
    raw = "[" * depth + "1" + "]" * depth if kind == 1 else '{"a":' * depth + "1" + "}" * depth
    return rebuild_state(obj, {(sec, name): raw}), f"{sec}.{name} nested {depth} deep"


def j_unknown_name(rng, seed, text, info):
    obj = state_obj(text)
    if not isinstance(obj, dict):
        return None
    if rng.random() < 0.15:
        key = rng.choice(["v", "Q", "extra", "qdot", "", "T"])
        top = [(k, json.dumps(v)) for k, v in obj.items()] + [(key, "{}" if key != "T" else "0")]
        return render_members(top, " "), f"unknown top-level key {key!r}"
    sec = rng.choice(["q", "u", "tau"])
    names = info.q_names if sec == "q" else info.u_names
    others = info.u_names if sec == "q" else info.q_names
    pool = ["nope", "", "x" * 300, "link1.angle ", "ünï.angle", "a\u0001b", "ground.angle"]
    pool += [n for n in others if n not in names][:3]
    pool += [n.upper() for n in names[:2]]
    pool += [n + "x" for n in names[:2]]
    pool += info.prescribed
    name = rng.choice([p for p in pool if p not in names] or ["nope"])
    o = dict(obj)
    sec_obj = dict(o.get(sec) or {})
    sec_obj[name] = 0.25
    o[sec] = sec_obj
    return json_text(o), f"{sec}.{name!r} (not a {sec} name of the model)"


def j_wrong_type(rng, seed, text, info):
    obj = state_obj(text)
    if not isinstance(obj, dict):
        return None
    raws = ['"0.5"', "null", "true", "[0.5]", "{}", '""', "false"]
    secs = state_sections(obj)
    r = rng.random()
    if r < 0.2:
        sec = rng.choice(["t", "q", "u", "tau"])
        raw = rng.choice(['"0"', "[]", "5", "null", '"q"', "true"] if sec != "t" else ['"0"', "null", "[0]", "{}"])
        o = {k: json.dumps(v) for k, v in obj.items()}
        o[sec] = raw
        return render_members(list(o.items()), " "), f"{sec} -> {raw}"
    if r < 0.3:
        raw = rng.choice(["[" + text + "]", '"state"', "42", "null", "true", "[]"])
        return raw, f"root {raw[:20]!r}"
    if not secs:
        return None
    sec = rng.choice(secs)
    name = rng.choice(list(obj[sec]))
    raw = rng.choice(raws)
    return rebuild_state(obj, {(sec, name): raw}), f"{sec}.{name} -> {raw}"


def j_number_range(rng, seed, text, info):
    obj = state_obj(text)
    if not isinstance(obj, dict):
        return None
    raws = ["1e400", "-1e400", "1e309", "NaN", "Infinity", "-Infinity", "1" + "0" * 400,
            "1e200", "-1e200", "1.7976931348623157e308", "1e300",
            "5e-324", "1e-310", "1e-400", "-0", "-0.0", "1E-5", "2.5e+00"]
    raw = rng.choice(raws)
    secs = state_sections(obj)
    if rng.random() < 0.15 or not secs:
        o = {k: json.dumps(v) for k, v in obj.items()}
        o["t"] = raw
        return render_members(list(o.items()), " "), f"t -> {raw[:30]}"
    sec = rng.choice(secs)
    name = rng.choice(list(obj[sec]))
    return rebuild_state(obj, {(sec, name): raw}), f"{sec}.{name} -> {raw[:30]}"


def j_huge_speed(rng, seed, text, info):
    obj = state_obj(text)
    if not isinstance(obj, dict) or not info.u_names:
        return None
    sec = rng.choice(["u", "u", "q", "tau"])
    names = info.u_names if sec != "q" else [n for n in info.q_names if not re.search(r"\.q[wxyz]$", n)]
    if not names:
        return None
    name = rng.choice(names)
    raw = rng.choice(["1e200", "-1e200", "1e155", "1.7976931348623157e308", "1e30", "1e100"])
    return rebuild_state(obj, {(sec, name): raw}), f"{sec}.{name} -> {raw}"


def j_quaternion(rng, seed, text, info):
    obj = state_obj(text)
    if not isinstance(obj, dict) or not info.free:
        return None
    body = rng.choice(info.free)
    comps = [f"{body}.q{c}" for c in "wxyz"]
    q = random_unit_quat(rng)
    kind = rng.randrange(11)
    if kind == 0:
        vals, what = [x * 1e-160 for x in q], "tiny (1e-160)"
    elif kind == 1:
        vals, what = [x * 1e200 for x in q], "huge (1e200)"
    elif kind == 2:
        vals, what = ["5e-324", "0", "0", "0"], "norm 5e-324"
    elif kind == 3:
        vals, what = ["1.7976931348623157e308"] * 4, "all 1.797e308 (norm overflows naively)"
    elif kind == 4:
        vals, what = ["0", "0", "0", "0.0"], "zero"
    elif kind == 5:
        vals, what = ["1"] + [None] * 3, "partial (qw only)"
    elif kind == 6:
        vals, what = [q[0], q[1], q[2], None], "partial (no qz)"
    elif kind == 7:
        vals, what = [2 * x for x in q], "norm 2"
    elif kind == 8:
        vals, what = [-x for x in q], "negated unit"
    elif kind == 9:
        vals, what = ["1e-310", "1e-310", "0", "0"], "subnormal components"
    else:
        vals, what = ["1", "0", "0", "0"], "identity as integers"
    o = dict(obj)
    qsec = dict(o.get("q") or {})
    for c in comps:
        qsec.pop(c, None)
    o["q"] = qsec
    override = {}
    for c, x in zip(comps, vals):
        if x is None:
            continue
        override[("q", c)] = x if isinstance(x, str) else fmt_num(x)
    return rebuild_state(o, override), f"{body} quaternion {what}"


def j_valid_edits(rng, seed, text, info):
    """Edits that keep a state valid: drop a section or a non-quaternion name, {}, unicode escapes in keys."""
    obj = state_obj(text)
    if not isinstance(obj, dict):
        return None
    kind = rng.randrange(4)
    if kind == 0:
        return "{}", "empty object"
    if kind == 1 and state_sections(obj):
        sec = rng.choice(state_sections(obj))
        o = dict(obj)
        del o[sec]
        return json_text(o), f"section {sec} left out"
    if kind == 2 and state_sections(obj):
        sec = rng.choice(state_sections(obj))
        name = rng.choice(list(obj[sec]))
        o = dict(obj)
        o[sec] = {k: v for k, v in obj[sec].items() if k != name}
        return json_text(o), f"{sec}.{name} left out"
    secs = state_sections(obj)
    if not secs:
        return None
    sec = rng.choice(secs)
    name = rng.choice(list(obj[sec]))
    esc = "".join(f"\\u{ord(c):04x}" if i % 2 == 0 else c for i, c in enumerate(name))
    top = []
    for k, v in obj.items():
        if k == sec:
            mem = [(n, json.dumps(x)) for n, x in v.items()]
            body = "{\n" + ",\n".join(("   \"" + esc + "\"" if n == name else "   " + json.dumps(n)) + ": " + x
                                     for n, x in mem) + "\n  }"
            top.append((k, body))
        else:
            top.append((k, json.dumps(v)))
    return render_members(top, " "), f"{sec}.{name} key written with \\u escapes"


STATE_OPS = [
    ("j_text", j_text_ops), ("j_dup_key", j_dup_key), ("j_deep_nesting", j_deep_nesting),
    ("j_unknown_name", j_unknown_name), ("j_wrong_type", j_wrong_type), ("j_number_range", j_number_range),
    ("j_huge_value", j_huge_speed), ("j_quaternion", j_quaternion), ("j_valid_edits", j_valid_edits),
]

# ---- simulate's output paths (target "cli") and the gimbal-lock run (target "gimbal")
#
# A run operator is f(rng, seed) -> dict or None:
#   argv        the command (after BIN); "@CASE@" is replaced by the case directory's absolute path
#   expect      "invalid" (exit 2, one message naming an option of opts, nothing written), "valid" (exit 0,
#               the outputs written, nothing else changed), "either" (exit 0 or 2; on exit 0 only outputs
#               and may_change may change) or "lock" (exit 1 naming gimbal lock, nothing written)
#   detail, opts (the options a refusal may name), outputs, may_change (paths relative to the case directory),
#   setup       ("dir", path) | ("symlink", path, target) | ("hardlink", path, existing file), made before the run
#   files       extra files written into the case directory (a STATE.json)

SIM_ARGS = ["--engine", "generic", "--t-end", "0.05", "--dt-out", "0.01", "--no-progress"]
CLI11_HINT = "Run with --help for more information."  # the line CLI11 adds after its own messages (--output=)
OPT_NAMES = {"-o": ["-o", "--output"], "--events": ["--events"]}


def has_events(seed):
    return isinstance(seed.data, dict) and isinstance(seed.data.get("events"), list) and bool(seed.data["events"])


def opt_args(rng, opt, path):
    """The option with its value, in one of the spellings the CLI takes."""
    form = rng.choice(["-o", "--output", "--output="] if opt == "-o" else ["--events", "--events="])
    return [form + path] if form.endswith("=") else [form, path]


def sim_args(seed, state_text=None):
    """simulate MODEL and SIM_ARGS; with a STATE.json, --t-end 0.05 after its t (so that --t-end is no fault)."""
    args = ["simulate", seed.model_rel] + SIM_ARGS
    if state_text is not None:
        t0 = 0.0
        obj = state_obj(state_text)
        if isinstance(obj, dict) and isinstance(obj.get("t"), (int, float)):
            t0 = float(obj["t"])
        args[args.index("--t-end") + 1] = repr(t0 + 0.05)
    return args


def sim_run(rng, seed, bad_opt, bad_path, expect, detail, setup=(), files=None, state=None, state_text=None,
            may_change=()):
    """A simulate run with bad_path given to bad_opt; the other output (if any) gets a good distinct path, which
    may be written when the run exits 0 ("either")."""
    argv = sim_args(seed, state_text)
    if state:
        argv += ["--state", state]
    may_change = list(may_change)
    outs = {"-o": None, "--events": None}
    outs[bad_opt] = bad_path
    if bad_opt == "--events" or (has_events(seed) and rng.random() < 0.5):
        other = "--events" if bad_opt == "-o" else "-o"
        outs[other] = rng.choice(["fine.csv", "good_out.csv"]) if other == "-o" else "fine_events.csv"
        may_change.append(outs[other])
    order = [o for o in ("-o", "--events") if outs[o] is not None]
    rng.shuffle(order)
    for o in order:
        argv += opt_args(rng, o, outs[o])
    return {"argv": argv, "expect": expect, "detail": detail, "opts": OPT_NAMES[bad_opt], "outputs": [],
            "may_change": may_change, "setup": list(setup), "files": files or {}}


def pick_bad_opt(rng, seed):
    return "--events" if has_events(seed) and rng.random() < 0.5 else "-o"


def c_same_file(rng, seed):
    """-o and --events on one file, spelled the same or otherwise (./x, sub/../x, the absolute path)."""
    if not has_events(seed):
        return None
    name = rng.choice(["out.csv", "run.csv", "sub/x.csv"])
    spelled, setup = rng.choice([(name, []), ("./" + name, []), ("sub/../" + name, [("dir", "sub")]),
                                 ("@CASE@/" + name, [])])
    if name.startswith("sub/"):
        setup = [("dir", "sub")]
    a, b = (name, spelled) if rng.random() < 0.5 else (spelled, name)
    argv = ["simulate", seed.model_rel] + SIM_ARGS + opt_args(rng, "-o", a) + opt_args(rng, "--events", b)
    return {"argv": argv, "expect": "invalid", "detail": f"-o {a} --events {b} (the same file)",
            "opts": OPT_NAMES["-o"] + OPT_NAMES["--events"], "outputs": [], "may_change": [], "setup": setup,
            "files": {}}


def c_input_file(rng, seed):
    """An output on an input: the model, a modal file it names, or the --state file; spelled as given, ./x,
    sub/../x, the absolute path, or through a symbolic link ("invalid"); through a hard link "either" (a new
    name of the same file: refused, or written by replacing the link, the input left as it was)."""
    cands = [("the model", seed.model_rel, None)] + [("a modal file", r, None) for r in seed.modal_rels()]
    if seed.states:
        cands.append(("the --state file", seed.states[0][0], seed.states[0]))
    what, target, st = rng.choice(cands)
    files = {st[0]: st[1]} if st else None
    state = None
    if st:
        state = rng.choice([st[0], "./" + st[0]])
    opt = pick_bad_opt(rng, seed)
    kind = rng.randrange(6)
    setup, may_change, expect = [], [], "invalid"
    if kind == 0:
        path = target
    elif kind == 1:
        path = "./" + target
    elif kind == 2:
        path, setup = "sub/../" + target, [("dir", "sub")]
    elif kind == 3:
        path = "@CASE@/" + target
    elif kind == 4:
        path, setup = "link_to_input", [("symlink", "link_to_input", target)]
    else:
        path, setup, may_change, expect = "hard_link", [("hardlink", "hard_link", target)], ["hard_link"], "either"
    return sim_run(rng, seed, opt, path, expect, f"{opt} {path}: {what} ({target})", setup=setup, files=files,
                   state=state, state_text=st[1] if st else None, may_change=may_change)


def c_empty_path(rng, seed):
    opt = pick_bad_opt(rng, seed)
    return sim_run(rng, seed, opt, "", "invalid", f"{opt} '' (an empty path)")


def c_missing_dir(rng, seed):
    """A path in a directory that does not exist (or whose parent is a file)."""
    opt = pick_bad_opt(rng, seed)
    path = rng.choice(["nodir/out.csv", "no/such/dir/out.csv", "nodir/", "out.csv/x.csv", seed.model_rel + "/out.csv",
                       "@CASE@/nodir/out.csv", "sub/nodir/out.csv"])
    setup = [("dir", "sub")] if path.startswith("sub/") else []
    return sim_run(rng, seed, opt, path, "invalid", f"{opt} {path} (a missing directory)", setup=setup)


def c_directory(rng, seed):
    opt = pick_bad_opt(rng, seed)
    dirs = [".", "..", "sub", "sub/", "./sub/..", "@CASE@", "@CASE@/sub"]
    dirs += sorted({os.path.dirname(r) for r in seed.modal_rels() if os.path.dirname(r)})
    path = rng.choice(dirs)
    setup = [("dir", "sub")] if "sub" in path else []
    return sim_run(rng, seed, opt, path, "invalid", f"{opt} {path} (a directory)", setup=setup)


def c_control(rng, seed):
    """Distinct valid paths: exit 0, both written, nothing else changed."""
    o = rng.choice(["out.csv", "sub/out.csv", "@CASE@/out.csv", "run 1.csv", "r\u00e9sultat.csv", ".hidden.csv"])
    argv = ["simulate", seed.model_rel] + SIM_ARGS
    pairs = [("-o", o)]
    outputs = [o.replace("@CASE@/", "")]
    if has_events(seed):
        e = rng.choice(["events.csv", "sub/events.csv", "@CASE@/ev.csv", "sub/../ev2.csv"])
        pairs.append(("--events", e))
        outputs.append(os.path.normpath(e.replace("@CASE@/", "")))
    rng.shuffle(pairs)
    for opt, path in pairs:
        argv += opt_args(rng, opt, path)
    setup = [("dir", "sub")] if any("sub" in p for _, p in pairs) else []
    return {"argv": argv, "expect": "valid", "detail": " ".join(f"{a} {b}" for a, b in pairs) + " (distinct, valid)",
            "opts": [], "outputs": outputs, "may_change": [], "setup": setup, "files": {}}


CLI_OPS = [
    ("c_same_file", c_same_file), ("c_input_file", c_input_file), ("c_empty_path", c_empty_path),
    ("c_missing_dir", c_missing_dir), ("c_directory", c_directory), ("c_control", c_control),
]

# A gimbal oscillating through lock (tests/apps/test_cli.cpp, "a gimbal oscillating through lock"): only the middle
# angle moves, about rest 1.67 > pi/2, from angle2 = THETA0 < pi/2, so it reaches lock (|det Gamma| = 1e-6) at
# t of about 0.22 s for 1.45; every integrator must stop there with exit 1, naming gimbal lock, writing nothing.
GIMBAL_MODEL = """name: gimbal_oscillator
bodies:
  - name: bob
    parent: ground
    joint: {{type: gimbal, sequence: xyz, stiffness: [0, 0.5, 0], rest: [0, 1.67, 0]}}
    mass: 1.0
    inertia: [0.01, 0.02, 0.03, 0, 0, 0]
initial:
  q: {{bob.angle2: {theta0}}}
"""
GIMBAL_WEIGHT = 12  # one pair, scheduled this many times a round


def g_gimbal_lock(rng, seed):
    integrator = rng.choice(["rk4", "dopri5", "rkf78", "cvode-bdf"])
    dt_out = rng.choice(["0.31", "0.01", "0.07", "1", "2.5", repr(round(rng.uniform(0.003, 3.0), 4))])
    argv = ["simulate", seed.model_rel, "--engine", "generic", "--integrator", integrator, "--t-end", "2",
            "--dt-out", dt_out, "--no-progress"] + opt_args(rng, "-o", "out.csv")
    outputs = ["out.csv"]
    if rng.random() < 0.3:
        argv += opt_args(rng, "--events", "ev.csv")
        outputs.append("ev.csv")
    theta0 = rng.choice(["1.45", "1.45", "1.3", "1.5", "1.55"])
    return {"argv": argv, "expect": "lock", "detail": f"angle2 from {theta0}: --integrator {integrator} "
            f"--dt-out {dt_out}" + (" --events ev.csv" if len(outputs) > 1 else ""),
            "opts": [], "outputs": [], "may_change": [], "setup": [],
            "files": {seed.model_rel: GIMBAL_MODEL.format(theta0=theta0)}}


GIMBAL_OPS = [("g_gimbal_lock", g_gimbal_lock)]


def gimbal_seed():
    rel = "gimbal_oscillator.yaml"
    return Seed("(generated) " + rel, rel, {rel: SeedFile(rel, GIMBAL_MODEL.format(theta0="1.45"))}, [], "")


def setup_case(d, setup):
    for item in setup:
        full = os.path.join(d, item[1])
        if item[0] == "dir":
            os.makedirs(full, exist_ok=True)
        elif item[0] == "symlink":
            os.symlink(item[2], full)
        elif item[0] == "hardlink":
            os.link(os.path.join(d, item[2]), full)


def snapshot(d):
    """Every path under d: ("dir",), ("link", target) or ("file", bytes)."""
    snap = {}
    for root, dirs, files in os.walk(d):
        for n in dirs + files:
            full = os.path.join(root, n)
            rel = os.path.relpath(full, d)
            if os.path.islink(full):
                snap[rel] = ("link", os.readlink(full))
            elif os.path.isdir(full):
                snap[rel] = ("dir",)
            else:
                with open(full, "rb") as f:
                    snap[rel] = ("file", f.read())
    return snap


def changed_paths(before, after):
    return sorted(p for p in set(before) | set(after) if before.get(p) != after.get(p))


def classify_run(case, res, before, after):
    """One outcome class for a "cli" or "gimbal" run (see the docstring), and a short reason."""
    r = crash_or_timeout(res)
    if r:
        return r
    run = case.run
    changed = changed_paths(before, after)
    rc, err = res["rc"], res["stderr"]
    lines = [l.rstrip("\r") for l in err.split("\n") if l.strip()]
    first = lines[0][:300] if lines else "(no message)"
    if rc != 0 and changed:
        return "written-on-refusal", f"exit {rc}, yet changed: {', '.join(changed[:4])}"
    if case.expect == "lock":
        if rc == 1 and "gimbal lock" in err:
            return "ok-stopped", ""
        return "missed-lock", f"exit {rc}; expected exit 1 naming gimbal lock: {first}"
    if rc == 2:
        if case.expect == "valid":
            return "wrongly-refused", "exit 2 for valid paths: " + first
        if not lines:
            return "unlocated", "unlocated: (no message on stderr)"
        bad = [l for l in lines if not OPTION_RE.match(l) and l != CLI11_HINT]
        if bad:
            return "unlocated", "names no option: " + bad[0][:300]
        if not any(l.split(":", 1)[0] in run["opts"] for l in lines):
            return "unlocated", f"names none of {'/'.join(run['opts'])}: {first}"
        return "ok-refused", ""
    if rc == 0:
        if case.expect == "invalid":
            return "silent-accept", "exit 0 for an output path that must be refused"
        allowed = set(run["outputs"]) | set(run["may_change"])
        extra = [p for p in changed if p not in allowed]
        missing = [p for p in run["outputs"] if after.get(p, ("",))[0] != "file" or not after[p][1]]
        if extra or missing:
            return "wrong-files", (f"not written (or empty): {', '.join(missing)}; " if missing else "") + \
                (f"changed besides the outputs: {', '.join(extra[:4])}" if extra else "")
        return "ok-valid", ""
    return "exit1-on-input", "exit 1: " + first


# --------------------------------------------------------------------------
# cases


class Case:
    def __init__(self, idx, seed, target, target_rel, op, expect, detail, files, state_rel, run=None):
        self.idx, self.seed, self.target, self.target_rel = idx, seed, target, target_rel
        self.op, self.expect, self.detail = op, expect, detail
        self.files, self.state_rel = files, state_rel
        self.run = run  # a run operator's dict ("cli" and "gimbal" cases), else None


def make_case(idx, rng, seed, target, op_name, fn):
    files = {rel: sf.text for rel, sf in seed.files.items()}
    if target in ("cli", "gimbal"):
        run = fn(rng, seed)
        if run is None:
            return None
        files.update(run["files"])
        return Case(idx, seed, target, seed.model_rel, f"{target}.{op_name}", run["expect"], run["detail"], files,
                    None, run)
    if target == "state":
        if not seed.states:
            return None
        sname, stext = rng.choice(seed.states)
        info = StateInfo(seed.q_names, seed.u_names, seed.free_bodies, seed.prescribed)
        r = fn(rng, seed, stext, info)
        if r is None:
            return None
        text, detail = r
        expect = state_expectation(text, info)
        files[sname] = text
        return Case(idx, seed, "state", sname, "state." + op_name, expect, detail, files, sname)
    if target == "model":
        sf = seed.model
    else:
        mods = seed.modal_rels()
        if not mods:
            return None
        sf = seed.files[rng.choice(mods)]
    r = fn(rng, seed, sf)
    if r is None:
        return None
    text, expect, detail = r
    if expect == "valid" and op_name in FORMAT_ONLY and not yaml_same_data(sf.text, text):
        expect, detail = "either", detail + " [self-check: PyYAML reads other data; downgraded to either]"
    files[sf.rel] = text
    return Case(idx, seed, target, sf.rel, f"{target}.{op_name}", expect, detail, files, None)


def build_pairs(seeds, gimbal=None):
    """Every (seed, target, operator) pair; one round of the schedule visits each once (a weighted pair, as often
    as its weight)."""
    pairs = []
    for s in seeds:
        for name, fn in MODEL_OPS:
            if name in EVENTS_ONLY:
                if has_events(s):
                    pairs += [(s, "model", name, fn)] * EVENTS_WEIGHT
                continue
            if name not in MODAL_ONLY:
                pairs.append((s, "model", name, fn))
            if s.modal_rels() and (name.startswith("t_") or name in MODAL_TOO | MODAL_ONLY):
                pairs.append((s, "modal", name, fn))
        if s.states:
            for name, fn in STATE_OPS:
                pairs.append((s, "state", name, fn))
        for name, fn in CLI_OPS:
            if name in EVENTS_ONLY:
                if has_events(s):
                    pairs += [(s, "cli", name, fn)] * EVENTS_WEIGHT
                continue
            pairs.append((s, "cli", name, fn))
    if gimbal is not None:
        for name, fn in GIMBAL_OPS:
            pairs += [(gimbal, "gimbal", name, fn)] * GIMBAL_WEIGHT
    return pairs


def schedule(rng, pairs):
    """Yields (index, pair, dead set) forever: each round visits every live pair once, shuffled."""
    dead = set()
    while True:
        order = list(range(len(pairs)))
        rng.shuffle(order)
        live = 0
        for i in order:
            if i in dead:
                continue
            live += 1
            yield i, pairs[i], dead
        if live == 0:
            return


def generate_cases(rng, pairs):
    idx = 0
    misses = Counter()
    for i, (seed, target, name, fn), dead in schedule(rng, pairs):
        case = None
        for _ in range(3):  # a few tries with other random choices
            case = make_case(idx, rng, seed, target, name, fn)
            if case is not None:
                break
        if case is None:
            misses[i] += 1
            if misses[i] >= 2:
                dead.add(i)
            continue
        yield case
        idx += 1


# --------------------------------------------------------------------------
# main


def prepare_seeds(runner, seeds, log):
    """Runs eval on every unmutated seed for its names and initial values; builds STATE.json seeds for models."""
    for s in seeds:
        d = runner.write_case({rel: sf.text for rel, sf in s.files.items()})
        res = runner.run(["eval", s.model_rel, "--engine", "generic"], d)
        try:
            out = strict_output_json(res["stdout"]) if res["rc"] == 0 else None
        except (ValueError, RecursionError):
            out = None
        if out is None:
            log(f"note: seed {s.name}: eval exit {res['rc']}; no names, no STATE.json seed "
                f"({res['stderr'].strip()[:200]})")
            continue
        s.q_names = list(out.get("q_names", []))
        s.u_names = list(out.get("u_names", []))
        s.free_bodies = [n[:-3] for n in s.q_names if n.endswith(".qw")]
        if not s.states:
            st = {"t": 0.0, "q": dict(zip(s.q_names, out.get("q", []))), "u": dict(zip(s.u_names, out.get("u", []))),
                  "tau": {n: 0.0 for n in s.u_names}}
            s.states = [("state.json", json_text(st))]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--kanegen", required=True, help="the kanegen binary under test")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--budget-seconds", type=float, default=60.0,
                    help="no new case starts after this many seconds (a case may add up to 2 timeouts)")
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds per run before it counts as a timeout")
    ap.add_argument("--report", help="write a JSON report here")
    ap.add_argument("--keep-failures", metavar="DIR", help="copy every failing case (files, command, output) here")
    ap.add_argument("--keep-per-class", type=int, default=40, help="at most this many kept cases per class")
    ap.add_argument("--case", type=int, help="run only case N of this seed (to reproduce)")
    ap.add_argument("--repo", default=os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")))
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)

    t_start = time.monotonic()
    log = (lambda *a: None) if args.quiet else (lambda *a: print(*a, file=sys.stderr, flush=True))
    if yaml is None:
        log("note: PyYAML missing: structure-level operators are skipped")
    if not os.access(args.kanegen, os.X_OK):
        print(f"--kanegen: {args.kanegen} is not an executable file", file=sys.stderr)
        return 2

    seeds, skipped = collect_seeds(args.repo)
    workdir = tempfile.mkdtemp(prefix="kanegen-fuzz-")
    runner = Runner(args.kanegen, args.timeout, workdir)
    try:
        prepare_seeds(runner, seeds, log)
        log(f"{len(seeds)} seed models ({sum(len(s.modal_rels()) for s in seeds)} modal files, "
            f"{sum(len(s.states) for s in seeds)} states); skipped: {', '.join(skipped) or 'none'}")

        rng = random.Random(args.seed)
        counts = Counter()
        by_op = defaultdict(Counter)
        by_seed = defaultdict(Counter)
        examples = defaultdict(list)
        kept = Counter()
        n_cases = n_runs = 0
        slowest = (0.0, None)
        budget_end = t_start + args.budget_seconds
        pairs = build_pairs(seeds, gimbal_seed())
        log(f"{len(pairs)} (seed, file, operator) pairs per round")
        for case in generate_cases(rng, pairs):
            if args.case is not None:
                if case.idx < args.case:
                    continue
                if case.idx > args.case:
                    break
            elif time.monotonic() > budget_end:
                break
            d = runner.write_case(case.files)
            cmds = []
            if case.run is not None:
                setup_case(d, case.run["setup"])
                cmds.append(("simulate", [a.replace("@CASE@", d) for a in case.run["argv"]]))
            elif case.target == "state":
                cmds.append(("eval", ["eval", case.seed.model_rel, "--engine", "generic", "--state", case.state_rel]))
            else:
                cmds.append(("check", ["check", case.seed.model_rel]))
                cmds.append(("eval", ["eval", case.seed.model_rel, "--engine", "generic"]))
            n_cases += 1
            for cmd, argv_ in cmds:
                before = snapshot(d) if case.run is not None else None
                res = runner.run(argv_, d)
                n_runs += 1
                if res["seconds"] > slowest[0]:
                    slowest = (res["seconds"], f"case {case.idx} {case.op} {cmd}")
                if case.run is not None:
                    cls, why = classify_run(case, res, before, snapshot(d))
                else:
                    cls, why = classify(case.expect, cmd, res, case.files.keys())
                counts[cls] += 1
                by_op[case.op][cls] += 1
                by_seed[case.seed.name][cls] += 1
                if args.case is not None or cls in FAIL_CLASSES:
                    ex = {"case": case.idx, "seed": case.seed.name, "file": case.target_rel, "op": case.op,
                          "mutation": case.detail, "expect": case.expect, "command": "kanegen " + shlex.join(argv_),
                          "exit": res["rc"], "why": why, "stderr": res["stderr"][:1200],
                          "stdout_head": res["stdout"][:300]}
                    if by_op[case.op][cls] <= 8:  # the first few of each operator and class
                        examples[cls].append(ex)
                    if args.case is not None:
                        print(json.dumps({"class": cls, **ex}, indent=1))
                    if args.keep_failures and cls in FAIL_CLASSES and kept[cls] < args.keep_per_class:
                        kept[cls] += 1
                        dest = os.path.join(args.keep_failures, cls, f"{case.idx:06d}-{case.op}-{cmd}")
                        if os.path.exists(dest):
                            shutil.rmtree(dest)
                        shutil.copytree(d, dest, symlinks=True)
                        with open(os.path.join(dest, "REPRO.txt"), "w", encoding="utf-8") as f:
                            f.write(f"cd {dest} && {runner.binary} {shlex.join(argv_)}\n"
                                    f"# seed {args.seed} case {case.idx} ({case.seed.name}, {case.target_rel}): "
                                    f"{case.op}: {case.detail}\n# expected: {case.expect}; got exit {res['rc']}: "
                                    f"{cls}: {why}\n")
                        with open(os.path.join(dest, "stderr.txt"), "wb") as f:
                            f.write(encode(res["stderr"][:100000]))
                        with open(os.path.join(dest, "stdout.txt"), "wb") as f:
                            f.write(encode(res["stdout"][:100000]))
        elapsed = time.monotonic() - t_start
    finally:
        shutil.rmtree(workdir, ignore_errors=True)

    # ---- report
    cols = [c for c in ALL_CLASSES if counts[c]] or ["ok-valid"]
    short = {"ok-valid": "ok-val", "ok-refused": "ok-ref", "ok-nonfinite": "ok-nf", "ok-stopped": "ok-stp",
             "crash": "crash", "timeout": "tmout", "written-on-refusal": "writtn", "wrongly-refused": "wr-ref",
             "silent-accept": "silent", "exit1-on-input": "exit1", "unlocated": "unloc", "null-in-json": "null",
             "wrong-files": "wr-fil", "missed-lock": "nolock"}
    w = max([len(o) for o in by_op] + [10])
    out = []
    out.append(f"kanegen fuzz: seed {args.seed}, {n_cases} cases, {n_runs} runs, {elapsed:.1f} s "
               f"(budget {args.budget_seconds:g} s), binary {args.kanegen}")
    out.append("")
    out.append("outcome class        runs")
    for c in ALL_CLASSES:
        out.append(f"  {c:<18} {counts[c]:6d}{'   <- failure' if c in FAIL_CLASSES and counts[c] else ''}")
    out.append("")
    out.append(f"{'operator':<{w}} " + " ".join(f"{short[c]:>6}" for c in cols))
    for op in sorted(by_op):
        out.append(f"{op:<{w}} " + " ".join(f"{by_op[op][c]:6d}" for c in cols))
    out.append(f"{'total':<{w}} " + " ".join(f"{counts[c]:6d}" for c in cols))
    failing = {c: counts[c] for c in FAIL_CLASSES if counts[c]}
    if failing:
        out.append("")
        out.append("examples:")
        for c in FAIL_CLASSES:
            seen_ops = set()
            shown = 0
            for ex in examples[c]:
                if ex["op"] in seen_ops or shown >= 4:
                    continue
                seen_ops.add(ex["op"])
                shown += 1
                msg = ex["stderr"].strip().split("\n")[0][:160] if ex["stderr"].strip() else "(no stderr)"
                out.append(f"  [{c}] case {ex['case']} {ex['seed']} {ex['file']} {ex['op']}: {ex['mutation'][:110]}")
                out.append(f"      {ex['command'][:80]} -> exit {ex['exit']}; expected {ex['expect']}; {msg}")
    print("\n".join(out))

    if args.report:
        rep = {
            "seed": args.seed, "binary": args.kanegen, "budget_seconds": args.budget_seconds,
            "elapsed_seconds": round(elapsed, 2), "cases": n_cases, "runs": n_runs,
            "slowest_run": {"seconds": round(slowest[0], 3), "what": slowest[1]},
            "seeds": [s.name for s in seeds], "skipped_seeds": skipped,
            "classes": {c: counts[c] for c in ALL_CLASSES},
            "by_operator": {op: dict(by_op[op]) for op in sorted(by_op)},
            "by_seed": {s: dict(by_seed[s]) for s in sorted(by_seed)},
            "examples": {c: examples[c] for c in FAIL_CLASSES if examples[c]},
            "rules": {"located": LOCATED_RE.pattern, "option": OPTION_RE.pattern, "nonfinite": NONFINITE_RE.pattern},
        }
        with open(args.report, "w", encoding="utf-8") as f:
            json.dump(rep, f, indent=1)
    return 1 if failing else 0


if __name__ == "__main__":
    sys.exit(main())
