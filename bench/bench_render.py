"""Renderer benchmark: median ms/frame at 1280x720 and 640x360 over the stock cases in scenes/.

Run from the repository root: ``python bench/bench_render.py [--json]`` (same output as ``lanevil bench``).
"""

from __future__ import annotations

import sys

from lanevil_core.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
