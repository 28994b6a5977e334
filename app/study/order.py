"""The order a participant sees the items in: training first, then the rest shuffled per participant.

The shuffle is seeded by the SHA-256 of ``study_id:participant_id``, so a participant who reloads the page gets the
same order back and every participant's order can be reproduced from the database alone.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from typing import Protocol

import numpy as np


class Ordered(Protocol):
    @property
    def id(self) -> int: ...

    @property
    def role(self) -> str: ...

    @property
    def position(self) -> int: ...


def participant_seed(study_id: str, participant_id: str) -> int:
    """A 64-bit seed derived from the two ids."""
    digest = hashlib.sha256(f"{study_id}:{participant_id}".encode("ascii")).digest()
    return int.from_bytes(digest[:8], "little")


def participant_order(items: Sequence[Ordered], study_id: str, participant_id: str) -> list[int]:
    """Item ids in presentation order: ``training`` items by position, then all others in a seeded shuffle."""
    by_position = sorted(items, key=lambda item: item.position)
    training = [item.id for item in by_position if item.role == "training"]
    rest = [item.id for item in by_position if item.role != "training"]
    rng = np.random.default_rng(participant_seed(study_id, participant_id))
    return training + [rest[index] for index in rng.permutation(len(rest))]
