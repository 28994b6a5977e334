"""What a background job's routes answer (exports, drives, the study's rendering job): its state and its URLs."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from ..jobs import JobStatus


class JobState(BaseModel):
    """A background job's state (``Job.to_dict``); the job's inputs (``case_id`` …) come with it."""

    model_config = ConfigDict(extra="allow")

    id: str
    kind: str
    status: JobStatus
    done: int = Field(description="steps done (frames of an export, steps of a drive)")
    total: int
    progress: float = Field(description="done / total, 0..1")
    error: str | None = Field(description="why the job failed, or null")
    created_at: float = Field(description="seconds since the epoch")
    finished_at: float | None = Field(description="seconds since the epoch, or null while it runs")


class JobBody(JobState):
    """A job's state and its URLs."""

    links: dict[str, str] = Field(description="self: the job's URL (and download: its zip, for an export)")
