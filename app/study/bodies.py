"""What the study's JSON routes answer, for the OpenAPI document: the routes build plain dicts from the records
(``Study.to_dict``, ``StudyItem.to_dict``, ``stats.summarize``), and these models describe them, reusing the
record dataclasses' fields."""

from __future__ import annotations

from typing import Any, get_type_hints

from pydantic import BaseModel, Field, create_model
from pydantic.dataclasses import dataclass

from ..api.job_bodies import JobState
from .records import Study, StudyItem
from .stats import Score


@dataclass(frozen=True)
class StudyRow(Study):
    """A study in the organiser's list."""

    participants: int


@dataclass(frozen=True)
class ItemBody(StudyItem):
    image_url: str


@dataclass(frozen=True)
class StudyDetail(StudyRow):
    """A study with its items, its pages' URLs and its render job (null when none is running or known)."""

    participant_url: str
    results_url: str
    items: list[ItemBody]
    job: JobState | None


class ParticipantCounts(BaseModel):
    total: int
    included: int
    excluded: int
    excluded_by_reason: dict[str, int] = Field(description="incomplete, gold, trap -> raters excluded for it")


class RatingCounts(BaseModel):
    total: int
    used: int = Field(description="ratings of test items by included raters")


class StudyResults(BaseModel):
    study: Study
    participants: ParticipantCounts
    ratings: RatingCounts
    groups: dict[str, dict[str, Score]] = Field(description="grouping (e.g. by type, by severity) -> group -> MOS")


class StudyCounts(BaseModel):
    training_items: int
    rated_items: int


class Preparing(BaseModel):
    done: int
    total: int


def _study_fields(*names: str) -> dict[str, Any]:
    """``create_model`` fields: these fields of ``Study``, typed as the record types them."""
    hints = get_type_hints(Study)
    return {name: (hints[name], ...) for name in names}


OpenStudy = create_model(
    "OpenStudy", __base__=StudyCounts, __doc__="A study open to participants, as the ``/study`` page lists it.",
    participant_url=(str, ...), **_study_fields("id", "title", "question", "viewing_ms"))
PublicStudy = create_model(
    "PublicStudy", __base__=StudyCounts, __doc__="What a participant sees before consenting.",
    preparing=(Preparing | None, Field(description="images rendered so far while the study is rendering")),
    **_study_fields("id", "title", "question", "consent_text", "instructions", "viewing_ms", "width", "height",
                    "status"))


class PlanItem(BaseModel):
    item_id: int
    training: bool
    image_url: str


class ParticipantPlan(BaseModel):
    """A participant's item order and progress."""

    participant_id: str
    study_id: str
    viewing_ms: int
    question: str
    completed: bool
    rated: list[int] = Field(description="ids of the items rated so far")
    items: list[PlanItem]


class RatingBody(BaseModel):
    id: int
    item_id: int
    rating: int


class Completed(BaseModel):
    participant_id: str
    completed: bool
