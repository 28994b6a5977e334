"""What an organiser sends to create a study, and what a participant sends: pydantic models with field-level checks.

A study is a list of items. An item is a generated frame (``case_id`` + ``frame``, rendered once at creation) or
an uploaded real image (``upload`` = the uploaded file's name), with a role:

- ``test``: a scored stimulus (its ratings make the MOS);
- ``training``: shown first, in the given order, never scored;
- ``gold``: a quality-control item with a known answer range ``expect = [lo, hi]`` (e.g. a garbled frame that
  must be rated <= 2, or a pristine one that must be >= 4); a rater outside the range is excluded;
- ``trap``: an attention check: the image carries a banner "please rate this image N" and ``answer = N``;
  a rater who answers anything else is excluded.

``garble`` scrambles an item's image into an obviously broken one (the usual low-anchor gold item).
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, StrictBool, StrictFloat, StrictInt, model_validator

from lanevil_core.presets import CameraPreset

from ..api.openapi import SERVER_LIMIT
from ..store import ID_PATTERN

Role = Literal["test", "training", "gold", "trap"]
Source = Literal["synthetic", "real"]
ACR_LABELS: dict[int, str] = {5: "Excellent", 4: "Good", 3: "Fair", 2: "Poor", 1: "Bad"}

DEFAULT_QUESTION = "How natural does this road scene look?"
DEFAULT_CONSENT = (
    "You are invited to take part in a short study on how natural road images look. You will see a series of "
    "images, each for a few seconds, and rate each one on a five-point scale. It takes about 10 to 30 minutes. "
    "Taking part is voluntary and you may stop at any time by closing the page. We store only your ratings, "
    "their response times and a random participant number; no name, e-mail address or other personal data. "
    "Nothing is recorded before you agree.")
DEFAULT_INSTRUCTIONS = (
    "Each image is shown for a short time and then hidden. Look at the whole image while it is visible, then "
    "rate it with the buttons or the keys 1 to 5. There are no right or wrong answers: give your first "
    "impression. Some images ask you to give a particular rating; please follow what they say. The first few "
    "images are for practice and are not counted.")


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class ItemSpec(_Strict):
    """One stimulus: a generated frame or an uploaded image, with its role and quality-control answer."""

    case_id: str | None = Field(None, description="stored case to render (synthetic item)",
                                json_schema_extra={"pattern": ID_PATTERN.pattern})
    frame: StrictInt = Field(0, ge=0, description="frame index of the case")
    upload: str | None = Field(None, description="file name of an uploaded real image (real item)")
    role: Role = "test"
    expect: tuple[StrictInt, StrictInt] | None = Field(
        None, description="gold items: inclusive range of accepted ratings"
    )
    answer: StrictInt | None = Field(None, ge=1, le=5, description="trap items: the rating the banner asks for")
    garble: StrictBool = Field(False, description="scramble the image into an obviously broken one")

    @model_validator(mode="after")
    def _consistent(self) -> ItemSpec:
        if (self.case_id is None) == (self.upload is None):
            raise ValueError("give exactly one of case_id (a generated frame) or upload (a real image)")
        if self.role == "gold":
            if self.expect is None:
                raise ValueError("a gold item needs expect = [lowest, highest] accepted rating")
            low, high = self.expect
            if not 1 <= low <= high <= 5:
                raise ValueError("expect must be [lo, hi] with 1 <= lo <= hi <= 5")
        elif self.expect is not None:
            raise ValueError("expect is only for gold items")
        if (self.role == "trap") != (self.answer is not None):
            raise ValueError("a trap item needs answer (1-5), and only trap items have one")
        return self

    @property
    def source(self) -> Source:
        return "synthetic" if self.case_id is not None else "real"


class GeneratedSet(_Strict):
    """Shorthand for many scored synthetic items: every listed case at every listed frame."""

    cases: list[str] = Field(min_length=1,
                             json_schema_extra={"items": {"type": "string", "pattern": ID_PATTERN.pattern}})
    frames: list[StrictInt] = Field([0], min_length=1, json_schema_extra={"items": {"type": "integer", "minimum": 0}})

    @model_validator(mode="after")
    def _frames_non_negative(self) -> GeneratedSet:
        if any(frame < 0 for frame in self.frames):
            raise ValueError("frames must be >= 0")
        return self


class StudySpec(_Strict):
    """The JSON ``spec`` field of ``POST /api/study/studies`` (the images come as multipart ``files``)."""

    title: str = Field(min_length=1, max_length=200)
    question: str = Field(DEFAULT_QUESTION, min_length=1, max_length=300)
    consent_text: str = Field(DEFAULT_CONSENT, min_length=1, max_length=10_000)
    instructions: str = Field(DEFAULT_INSTRUCTIONS, min_length=1, max_length=10_000)
    viewing_seconds: StrictFloat = Field(3.0, ge=0.1, le=30.0, description="how long each image is shown")
    width: StrictInt = Field(1280, ge=16, description="render width of generated items (at most the server's largest)",
                             json_schema_extra={SERVER_LIMIT: "max_width"})
    height: StrictInt = Field(720, ge=16, description="render height of generated items (at most the server's "
                              "largest)", json_schema_extra={SERVER_LIMIT: "max_height"})
    camera: CameraPreset | None = Field(None, description="the camera preset every generated item is seen through "
                                        "(carla is the paper's capture camera, the others real cameras'); empty = "
                                        "each case's own")
    items: list[ItemSpec] = Field(default_factory=list)
    generated: GeneratedSet | None = None
    uploads_as_items: StrictBool = Field(True, description="uploads no item names become scored real items")

    def all_items(self, upload_names: list[str]) -> list[ItemSpec]:
        """``items``, then the ``generated`` cross product, then (if asked) the uploads no item names."""
        items = list(self.items)
        if self.generated:
            items += [ItemSpec(case_id=case_id, frame=frame)
                      for case_id in self.generated.cases for frame in self.generated.frames]
        if self.uploads_as_items:
            named = {item.upload for item in items}
            items += [ItemSpec(upload=name) for name in upload_names if name not in named]
        return items


class ConsentIn(_Strict):
    """A participant's agreement; nothing is stored unless ``consent`` is true."""

    consent: StrictBool = Field(description="must be true: nothing is stored without it",
                                json_schema_extra={"const": True})


class RatingIn(_Strict):
    """One ACR rating of one item."""

    item_id: StrictInt = Field(ge=1)
    rating: StrictInt = Field(ge=1, le=5, description="5 Excellent, 4 Good, 3 Fair, 2 Poor, 1 Bad")
    response_ms: StrictInt | None = Field(None, ge=0, le=3_600_000, description="time from the scale appearing")
