"""The editor in headless Chromium without a GPU: slider change -> new preview image, and an idle tab's CPU, per
3D view mode.

Runs the editor in process on a temporary copy of a few stock cases and opens it in Debian's Chromium (software
WebGL through SwiftShader, as on a machine without a graphics card; the page finds it from the WebGL renderer
string). For each 3D view mode (``off``: what such a tab starts with, ``light``, ``full``), set as the panel's
*3D view* switch would:

- idle: the CPU seconds all Chromium processes spend per second of wall time over ``--idle-s`` seconds with
  nothing changing, in cores (and the editor server's, in this process);
- slider: ``--changes`` presses of the arrow key on the focused *Sun altitude* slider, each after the last
  settled; the latency of a change is from the key event to the first new preview image in the page (a draft
  in the default quality), and to the last one (the exact frame), both read from the page's own clock.

Prints p50 / p95 in milliseconds and cores per mode.

    python bench/editor_browser.py [--modes off light full] [--changes 10] [--idle-s 10] [--screenshots DIR] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import psutil

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from app.editor import EditorTab, launch_editor  # noqa: E402
from app.settings import Settings  # noqa: E402
from app.state import AppState  # noqa: E402

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-sync",
                 "--disable-background-networking", "--disable-component-update", "--use-angle=swiftshader",
                 "--enable-unsafe-swiftshader"]
CASES = ["30_shadow/fence_shadow/00_uphill_rural_noon/03_level3.json", "00_clean/00_straight_urban.json"]
SUN_ALTITUDE = "[role=slider][aria-valuemin='-10'][aria-valuemax='90']"
WAIT_S = 180.0
SETTLE_S = 1.5  # after the exact frame arrived: the page has drawn it
# Records, on the page's clock, every key press and every new preview image (the panel's <img> gets a new blob).
WATCH = """() => {
  window.__keys = []; window.__images = [];
  document.addEventListener("keydown", () => window.__keys.push(performance.now()), true);
  new MutationObserver((records) => {
    for (const record of records) {
      const img = record.target;
      if (record.attributeName === "src" && img.tagName === "IMG" && img.src.startsWith("blob:")) {
        window.__images.push(performance.now());
      }
    }
  }).observe(document.body, {attributes: true, attributeFilter: ["src"], subtree: true});
}"""


def chromium_seconds() -> float:
    """CPU seconds used so far by every Chromium process this process started."""
    total = 0.0
    for child in psutil.Process(os.getpid()).children(recursive=True):
        try:
            if "chrom" in child.name():
                times = child.cpu_times()
                total += times.user + times.system
        except psutil.NoSuchProcess:
            continue
    return total


def idle_cores(seconds: float) -> dict[str, float]:
    """Cores used by Chromium and by this process (the editor server) while nothing changes."""
    me = psutil.Process(os.getpid())
    browser0, server0, wall0 = chromium_seconds(), sum(me.cpu_times()[:2]), time.perf_counter()
    time.sleep(seconds)
    wall = time.perf_counter() - wall0
    return {"browser_cores": round((chromium_seconds() - browser0) / wall, 3),
            "server_cores": round((sum(me.cpu_times()[:2]) - server0) / wall, 3)}


def settle(tab: EditorTab) -> None:
    assert tab.preview.wait_idle(WAIT_S)
    time.sleep(SETTLE_S)


def slider_latencies(page, tab: EditorTab, changes: int) -> dict[str, list[float]]:
    """ms from each key press to the first and to the last new preview image before the next press."""
    page.locator(SUN_ALTITUDE).first.focus()
    first, last = [], []
    for index in range(changes):
        page.keyboard.press("ArrowRight" if index % 2 == 0 else "ArrowLeft")
        time.sleep(0.3)
        settle(tab)
        keys, images = page.evaluate("() => [window.__keys, window.__images]")
        pressed = keys[-1]
        after = [t for t in images if t > pressed]
        if after:
            first.append(after[0] - pressed)
            last.append(after[-1] - pressed)
    return {"first_image_ms": first, "exact_image_ms": last}


def stats(values: list[float]) -> dict[str, float]:
    if not values:
        return {"n": 0}
    return {"p50": round(float(np.median(values)), 1), "p95": round(float(np.percentile(values, 95)), 1),
            "n": len(values)}


def measure(args: argparse.Namespace, tmp: Path) -> dict:
    from playwright.sync_api import sync_playwright

    scenes = tmp / "scenes"
    for relative in CASES:
        (scenes / relative).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(REPO / "scenes" / relative, scenes / relative)
    state = AppState.open(Settings(data_dir=tmp / "data", scenes_dir=scenes, port=0, editor_port=0))
    editor = launch_editor(state, host="127.0.0.1", port=0)
    results: dict = {}
    try:
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, headless=True, args=CHROMIUM_ARGS)
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.set_default_timeout(WAIT_S * 1000)
            page.goto(f"http://127.0.0.1:{editor.port}/")
            tab = editor.tab(timeout=WAIT_S)
            if tab.start is not None:
                tab.start.close()  # the start screen would take the keyboard
            page.locator("img[src^='blob:']").first.wait_for()
            page.evaluate(WATCH)
            results["renderer"] = page.evaluate("() => document.cookie")
            results["started_with"] = tab.view.mode
            settle(tab)
            for mode in args.modes:
                tab.display.set_view_mode(mode)
                settle(tab)
                time.sleep(3.0)  # meshes sent to the page when the view came on are drawn
                if args.screenshots is not None:
                    args.screenshots.mkdir(parents=True, exist_ok=True)
                    page.screenshot(path=str(args.screenshots / f"editor_view_{mode}.png"))
                idle = idle_cores(args.idle_s)
                latencies = slider_latencies(page, tab, args.changes)
                results[mode] = {**idle, **{name: stats(values) for name, values in latencies.items()}}
            browser.close()
    finally:
        editor.stop()
    return results


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--modes", nargs="+", choices=("off", "light", "full"), default=["off", "light", "full"])
    parser.add_argument("--changes", type=int, default=10, help="slider changes per mode")
    parser.add_argument("--idle-s", type=float, default=10.0, help="seconds of idle CPU measured per mode")
    parser.add_argument("--screenshots", type=Path, default=None, help="folder for a screenshot per mode")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    if not Path(CHROMIUM).exists():
        print("Debian chromium is not installed (scripts/install-chromium installs it)", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory(prefix="lanevil-bench-") as tmp:
        results = measure(args, Path(tmp))
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        for name, value in results.items():
            print(f"{name:>12}: {value}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
