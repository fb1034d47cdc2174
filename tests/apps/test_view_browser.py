#!/usr/bin/python3
"""The 3D view in a real browser (issue 37): `kanegen view` of a short run of a
model, opened offline by headless Chromium (Debian's `chromium`, software
WebGL): the page reports in its DOM (#status) that it drew every body, joint
and node; a screenshot has pixels other than the background where the bodies
are; the last frame's screenshot differs from the first's (the slider's
frame, through view.html?frame=K).

    test_view_browser.py --kanegen BIN [--model M] [--t-end T] [--dt-out H] [--screenshot OUT.png]

Exit 0 passed, 1 failed, 77 skipped (Chromium cannot start here: said why).
--screenshot keeps the first frame's screenshot (docs' image).
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

from PIL import Image, ImageChops

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SKIP = 77
BACKGROUND = (0xF4, 0xF5, 0xF7)


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def browser_args(exe, profile):
    return [exe, "--headless=new", "--no-sandbox", "--use-gl=swiftshader", "--enable-unsafe-swiftshader",
            "--disable-gpu-sandbox", "--no-first-run", "--disable-extensions", "--hide-scrollbars",
            f"--user-data-dir={profile}", "--virtual-time-budget=5000"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--kanegen", required=True)
    ap.add_argument("--model", default=os.path.join(ROOT, "models", "explorer1.yaml"))
    ap.add_argument("--t-end", default="0.5")
    ap.add_argument("--dt-out", default="0.01")
    ap.add_argument("--screenshot")
    ap.add_argument("--screenshot-frame", default="0", help="the frame --screenshot keeps (default 0)")
    ap.add_argument("--events", action="store_true", help="simulate with --events and view with them")
    a = ap.parse_args()
    exe = chromium()
    if not exe:
        print("SKIP: no chromium on PATH (Debian: apt-get install chromium; scripts/install_deps.sh installs it)")
        return SKIP
    failures = []

    def check(ok, what):
        print(("ok    " if ok else "FAIL  ") + what)
        if not ok:
            failures.append(what)

    with tempfile.TemporaryDirectory(prefix="kanegen-view-browser-") as d:
        csv, page = os.path.join(d, "run.csv"), os.path.join(d, "view.html")
        ev = os.path.join(d, "run.events.csv")
        subprocess.run([a.kanegen, "simulate", a.model, "--engine", "generic", "--t-end", a.t_end, "--dt-out",
                        a.dt_out, "--no-progress", "-o", csv] + (["--events", ev] if a.events else []),
                       check=True, capture_output=True)
        subprocess.run([a.kanegen, "view", a.model, csv, "-o", page] + (["--events", ev] if a.events else []),
                       check=True, capture_output=True)
        data = json.loads(re.search(r"const KANEGEN_VIEW = (\{.*?\});</script>", open(page).read(), re.S)
                          .group(1).replace("<\\/", "</"))
        nodes = sum(len(b["nodes"]["ids"]) for b in data["bodies"] if "nodes" in b)
        profile = os.path.join(d, "profile")
        try:
            dom = subprocess.run(browser_args(exe, profile) + ["--dump-dom", "file://" + page], capture_output=True,
                                 text=True, timeout=120)
        except (OSError, subprocess.TimeoutExpired) as e:
            print(f"SKIP: chromium cannot start here ({e})")
            return SKIP
        m = re.search(r'<div id="status"[^>]*>(\{.*?\})</div>', dom.stdout)
        if dom.returncode != 0 and not m:
            print("SKIP: chromium cannot start here: " + dom.stderr.strip().splitlines()[-1:][0] if dom.stderr.strip()
                  else "SKIP: chromium cannot start here (no output)")
            return SKIP
        check(m is not None, "the page reports what it drew (#status)")
        if m:
            status = json.loads(m.group(1))
            print("      " + json.dumps(status))
            check(status["bodies"] == len(data["bodies"]), f"every body drawn ({len(data['bodies'])})")
            check(status["joints"] == len(data["bodies"]), "every joint drawn")
            check(status["nodes"] == nodes, f"every node drawn ({nodes})")
            check(status["frames"] == len(data["t"]), f"every frame loaded ({len(data['t'])})")
            check(status["webgl"], "WebGL context")
        shots = []
        frames = ["0", "-1"] + ([a.screenshot_frame] if a.screenshot and a.screenshot_frame != "0" else [])
        for k, frame in enumerate(frames):
            png = os.path.join(d, f"shot{k}.png")
            subprocess.run(browser_args(exe, profile) + ["--window-size=1100,700", f"--screenshot={png}",
                                                         f"file://{page}?frame={frame}"],
                           capture_output=True, timeout=120)
            check(os.path.exists(png), f"screenshot of frame {frame}")
            if os.path.exists(png):
                shots.append(Image.open(png).convert("RGB"))
        if len(shots) >= 2:
            view = shots[0].crop((0, 0, shots[0].width - 340, shots[0].height))  # the 3D view, not the side panel
            px = view.getdata()
            drawn = sum(1 for p in px if max(abs(p[i] - BACKGROUND[i]) for i in range(3)) > 24)
            share = drawn / (view.width * view.height)
            check(share > 0.01, f"pixels other than the background in the view: {100 * share:.1f} %")
            diff = ImageChops.difference(shots[0], shots[1]).getbbox()
            check(diff is not None, "the last frame's drawing differs from the first's")
            if a.screenshot:
                shots[-1 if len(shots) == 3 else 0].save(a.screenshot)
                print("      screenshot: " + a.screenshot)
    print(f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
