"""How much of each test drive shows its illusion: for every original of the stock library, the share of its
level-5 case's frames on which the illusion changes at least ``IN_VIEW_SHARE`` of the lane band
(``illusion_effect.shown_share``, every ``--step``-th frame tried at 160x90), per type (mean, minimum) and over the
library.

The full test split scores every frame of every case, so a frame where the illusion has not come into view yet, or
has been passed, counts as a perturbed image that shows nothing: this is the share of the split's perturbed
frames that actually show their illusion at level 5.

Usage: ``python experiments/in_view.py [--step 5] [--types pedestrian,bicycle] [--json]``
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

from lanevil_core.illusions import REGISTRY
from lanevil_core.library.stock import ORIGINALS, original_case
from lanevil_core.pipeline.illusion_effect import shown_share, with_illusion


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--step", type=int, default=5, help="try every STEP-th frame of each drive (default 5)")
    parser.add_argument("--types", default="", help="comma-separated illusion types (default: every type)")
    parser.add_argument("--json", action="store_true", help="print the shares as JSON")
    args = parser.parse_args(argv)
    types = [t for t in args.types.split(",") if t] or sorted(REGISTRY)
    unknown = sorted(set(types) - set(REGISTRY))
    if unknown:
        parser.error(f"--types: unknown {', '.join(unknown)}")
    started = time.perf_counter()
    shares: dict[str, list[float]] = {}
    for name in types:
        for index in range(len(ORIGINALS[name])):
            clean = original_case(name, index)
            shares.setdefault(name, []).append(shown_share(with_illusion(clean, {"type": name, "severity": 5}),
                                                           args.step))
    if args.json:
        print(json.dumps(shares, indent=1))
        return 0
    print(f"{'type':24s} {'originals':>9s} {'mean':>6s} {'min':>6s}")
    for name, values in shares.items():
        print(f"{name:24s} {len(values):9d} {100 * statistics.mean(values):5.1f}% {100 * min(values):5.1f}%")
    every = [v for values in shares.values() for v in values]
    print(f"{'all':24s} {len(every):9d} {100 * statistics.mean(every):5.1f}% {100 * min(every):5.1f}%")
    print(f"({time.perf_counter() - started:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
