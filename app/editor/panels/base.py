"""What every panel of the editor shares: the error a user action raises, and small formatting helpers.

A panel (``case.CasePanel``, ``illusions.IllusionsPanel`` …) creates its inputs in the tab's GUI together with
their callbacks, holds the user actions those callbacks call, and brings its inputs up to date in ``sync``.
Panels edit the case through their ``EditorTab`` (``tab.edit``), which keeps the session, the undo history and
the preview; the tab calls every panel's ``sync`` after each change.
"""

from __future__ import annotations

from typing import Any, TypeVar, cast

import numpy as np
import viser

T = TypeVar("T")


class EditError(Exception):
    """A user action that cannot be done; the message is shown in the panel as is."""


def described(changes: dict[str, float]) -> str:
    """``name value, ...`` of an edit's changes, for its undo label."""
    return ", ".join(f"{k} {v:g}" for k, v in changes.items())


def wrap_degrees(angle: float) -> float:
    """``angle`` in -180..180 degrees."""
    return float((angle + 180.0) % 360.0 - 180.0)


def set_clipped(handle: viser.GuiSliderHandle, value: Any) -> None:
    """Show ``value`` on a slider, clipped to the slider's range (a case may hold values beyond it)."""
    set_value(handle, float(np.clip(value, handle.min, handle.max)))


def set_value(handle: viser.GuiInputHandle[T], value: T) -> None:
    """Show ``value`` on an input. viser's props classes declare ``value`` read-only for the type checker although
    every input handle sets it (and sends it to the browser), so the assignment goes through ``Any`` here, once."""
    cast(Any, handle).value = value
