"""CSV exports of a study: every raw rating, and the MOS summary table."""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from .records import Rating, StudyItem

RAW_COLUMNS = ("rating_id", "participant_id", "included", "exclusion_reasons", "item_id", "position", "role",
               "source", "case_id", "frame", "upload_name", "illusion_type", "category", "severity", "rating",
               "response_ms", "created_at")
SUMMARY_COLUMNS = ("grouping", "group", "n", "mos", "std", "ci_low", "ci_high")


def _csv(columns: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    writer.writerows(["" if value is None else value for value in row] for row in rows)
    return buffer.getvalue()


def raw_ratings_csv(items: Sequence[StudyItem], ratings: Sequence[Rating],
                    reasons: Mapping[str, Sequence[str]]) -> str:
    """One row per stored rating (training items included), with the rater's screening outcome."""
    by_id = {item.id: item for item in items}
    rows = []
    for rating in ratings:
        item = by_id[rating.item_id]
        why = reasons.get(rating.participant_id, [])
        rows.append((rating.id, rating.participant_id, int(not why), ";".join(why), item.id, item.position,
                     item.role, item.source, item.case_id, item.frame, item.upload_name, item.illusion_type,
                     item.category, item.severity, rating.rating, rating.response_ms, f"{rating.created_at:.3f}"))
    return _csv(RAW_COLUMNS, rows)


def summary_csv(groups: Mapping[str, Mapping[str, Mapping[str, Any]]]) -> str:
    """One row per (grouping, group) of ``summarize(...)["groups"]``; numbers rounded to 4 decimals."""
    def fmt(value: float | None) -> str | None:
        return None if value is None else f"{value:.4f}"

    rows = [(grouping, group, result["n"], fmt(result["mos"]), fmt(result["std"]), fmt(result["ci_low"]),
             fmt(result["ci_high"])) for grouping, table in groups.items() for group, result in table.items()]
    return _csv(SUMMARY_COLUMNS, rows)
