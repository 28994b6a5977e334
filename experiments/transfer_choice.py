"""Which of a family's fine-tuned runs ships as ``FAMILY-transfer`` (scripts/models-transfer-world), from the
readings of ``experiments/view_heldout.py --json`` on the validation splits: the two car-height splits first
(``tusimple``, ``dashcam`` presets), then the others. A run qualifies when it matches at least ``--ego`` % of the ego
lines on both car-height splits and its mean TuSimple accuracy over all the splits beats the starting model's; of
those, the most accurate ships. Prints the chosen name (the starting model's when none qualifies) and then each
model's numbers. Synthetic splits only.

    .venv/bin/python experiments/transfer_choice.py --start scnn-transfer out/transfer/choice-scnn-val-*.json
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

CAR_HEIGHT_SPLITS = 2


def choose(tables: list[dict], start: str, ego: float = 50.0) -> tuple[str, dict[str, float]]:
    """The shipped name and every model's mean accuracy over ``tables`` (view_heldout's ``table``s, car-height
    splits first)."""
    names = list(tables[0])
    mean = {name: sum(t[name]["frame"]["accuracy"] for t in tables) / len(tables) for name in names}
    qualified = [name for name in names if name != start and mean[name] > mean[start]
                 and all(t[name]["frame"]["ego"] >= ego for t in tables[:CAR_HEIGHT_SPLITS])]
    return (max(qualified, key=lambda name: mean[name]) if qualified else start), mean


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--start", required=True, help="the starting model's name in the tables")
    parser.add_argument("--ego", type=float, default=50.0, help="share of ego lines on each car-height split (%%)")
    parser.add_argument("tables", nargs="+", type=Path, help="view_heldout.py --json files, car-height splits first")
    args = parser.parse_args()
    tables = [json.loads(path.read_text())["table"] for path in args.tables]
    chosen, mean = choose(tables, args.start, args.ego)
    numbers = "; ".join(f"{name} " + " ".join(f"{t[name]['frame']['ego']:.1f}/{t[name]['frame']['accuracy']:.1f}"
                                               for t in tables) + f" mean accuracy {mean[name]:.2f}"
                        for name in mean)
    print(f"{chosen}   ({numbers})")


if __name__ == "__main__":
    main()
