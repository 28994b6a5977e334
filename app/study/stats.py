"""Study results: rater screening (gold, trap, completeness) and MOS with t-based 95 % confidence intervals.

Screening (as in the P.808 toolkit): a rater is excluded when they

- ``incomplete``: did not rate every non-training item (gold and trap items included), or
- ``gold``: rated any gold item outside its accepted range, or
- ``trap``: gave any trap item a rating other than the one its banner asked for.

A rater may fail for several reasons; each reason is counted, and ``excluded`` counts raters once.
The MOS of a group is the mean of all individual ratings that included raters gave to the group's ``test`` items
(gold, trap and training items never enter a MOS); its 95 % confidence interval is
``MOS ± t(0.975, n - 1) · s / √n`` with ``s`` the sample standard deviation (ddof = 1) of those ``n`` ratings.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from scipy import stats as scipy_stats

from .records import Participant, Rating, StudyItem

CONFIDENCE = 0.95
REASONS = ("incomplete", "gold", "trap")


@dataclass(frozen=True)
class Score:
    """MOS of ``n`` ratings with its standard deviation and 95 % CI (None where undefined: n = 0, or n = 1)."""

    n: int
    mos: float | None
    std: float | None
    ci_low: float | None
    ci_high: float | None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def score(ratings: Sequence[int]) -> Score:
    """MOS, sample standard deviation and t-distribution 95 % CI of ``ratings``."""
    n = len(ratings)
    if n == 0:
        return Score(0, None, None, None, None)
    values = np.asarray(ratings, dtype=np.float64)
    mos = float(values.mean())
    if n == 1:
        return Score(1, mos, None, None, None)
    std = float(values.std(ddof=1))
    half = float(scipy_stats.t.ppf(0.5 + CONFIDENCE / 2, n - 1)) * std / math.sqrt(n)
    return Score(n, mos, std, mos - half, mos + half)


def screen(items: Sequence[StudyItem], ratings: Mapping[int, int]) -> list[str]:
    """The exclusion reasons of one rater (``ratings``: item id -> rating); empty when the rater is kept."""
    reasons = []
    if any(item.scored and item.id not in ratings for item in items):
        reasons.append("incomplete")
    if any(item.role == "gold" and item.id in ratings
           and not (item.gold_min or 1) <= ratings[item.id] <= (item.gold_max or 5) for item in items):
        reasons.append("gold")
    if any(item.role == "trap" and item.id in ratings and ratings[item.id] != item.trap_answer for item in items):
        reasons.append("trap")
    return reasons


def ratings_by_participant(ratings: Iterable[Rating]) -> dict[str, dict[int, int]]:
    """participant id -> (item id -> rating)."""
    table: dict[str, dict[int, int]] = defaultdict(dict)
    for rating in ratings:
        table[rating.participant_id][rating.item_id] = rating.rating
    return table


def exclusions(items: Sequence[StudyItem], participants: Sequence[Participant],
               ratings: Iterable[Rating]) -> dict[str, list[str]]:
    """participant id -> exclusion reasons (empty list: included), for every participant of the study."""
    table = ratings_by_participant(ratings)
    return {participant.id: screen(items, table.get(participant.id, {})) for participant in participants}


def _grouped(items: Sequence[StudyItem], ratings: Sequence[Rating],
             key: Callable[[StudyItem], str | None]) -> dict[str, Score]:
    by_id = {item.id: item for item in items}
    groups: dict[str, list[int]] = defaultdict(list)
    for item in items:
        group = key(item)
        if item.role == "test" and group is not None:
            groups.setdefault(group, [])
    for rating in ratings:
        item = by_id[rating.item_id]
        group = key(item)
        if item.role == "test" and group is not None:
            groups[group].append(rating.rating)
    return {group: score(values) for group, values in sorted(groups.items())}


def _illusion(item: StudyItem) -> str | None:
    return (item.illusion_type or "clean") if item.source == "synthetic" else None


def _severity(item: StudyItem) -> str | None:
    return str(item.severity or 0) if item.source == "synthetic" else None


GROUPINGS: dict[str, Callable[[StudyItem], str | None]] = {
    "overall": lambda item: "all",
    "source": lambda item: item.source,
    "illusion_type": _illusion,
    "severity": _severity,
    "item": lambda item: str(item.id),
}


def summarize(items: Sequence[StudyItem], participants: Sequence[Participant],
              ratings: Sequence[Rating]) -> dict[str, Any]:
    """Screening counts and the MOS table of every grouping (over included raters' ratings only)."""
    reasons = exclusions(items, participants, ratings)
    included = {pid for pid, why in reasons.items() if not why}
    kept = [rating for rating in ratings if rating.participant_id in included]
    counts = {
        "total": len(participants),
        "included": len(included),
        "excluded": len(participants) - len(included),
        "excluded_by_reason": {reason: sum(reason in why for why in reasons.values()) for reason in REASONS},
    }
    groups = {name: {group: result.to_dict() for group, result in _grouped(items, kept, key).items()}
              for name, key in GROUPINGS.items()}
    test_ids = {item.id for item in items if item.role == "test"}
    used = sum(1 for rating in kept if rating.item_id in test_ids)
    return {"participants": counts, "ratings": {"total": len(ratings), "used": used}, "groups": groups}
