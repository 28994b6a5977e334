"""Panel inputs for an illusion's own parameters, generated from its pydantic fields.

Numbers with a default get a number box (bounded by the field's constraints); optional numbers ("empty = from the
severity table") a text box where empty means "use the table"; choices a dropdown; flags a checkbox; anything else
(colours, lists) a JSON text box. Every input carries the field's description as its hover hint.
"""

from __future__ import annotations

import functools
import json
import types
from collections.abc import Callable
from typing import Annotated, Any, Literal, Union, get_args, get_origin

import numpy as np
import viser

from lanevil_core.illusions import Illusion

from .placement import field_bounds

DEFAULT_OPTION = "(from severity)"
OWN_WIDGETS = ("type", "severity")  # the type is fixed; severity has its own slider
FieldChange = Callable[[str, Any], None]


def _unwrap_optional(annotation: Any) -> tuple[Any, bool]:
    """(inner annotation without ``Annotated`` metadata such as ``Strict``, whether None is allowed)."""
    optional = False
    if get_origin(annotation) in (Union, types.UnionType):
        args = [arg for arg in get_args(annotation) if arg is not type(None)]
        if len(args) == 1 and len(args) != len(get_args(annotation)):
            annotation, optional = args[0], True
    if get_origin(annotation) is Annotated:
        annotation = get_args(annotation)[0]
    return annotation, optional


def parse_text(raw: str, inner: Any) -> Any:
    """A text box's value as the field expects it: empty -> None, numbers and JSON parsed."""
    raw = raw.strip()
    if raw == "":
        return None
    try:
        if inner in (int, float):
            return float(raw) if inner is float else int(float(raw))
    except ValueError:
        return raw  # the case model reports it, naming the field
    try:
        return json.loads(raw)
    except json.JSONDecodeError:
        return raw


def format_text(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, (int, float, str)) and not isinstance(value, bool):
        return str(value)
    return json.dumps(value)


class ParamInputs:
    """The inputs of one illusion type inside a folder; rebuilt when the selected illusion's type changes."""

    def __init__(self, gui: viser.GuiApi, folder: viser.GuiFolderHandle, on_change: FieldChange) -> None:
        self.gui = gui
        self.folder = folder
        self.on_change = on_change
        self.model: type[Illusion] | None = None
        self.handles: dict[str, Any] = {}
        self._readers: dict[str, Callable[[Any], Any]] = {}
        self._writers: dict[str, Callable[[Any], Any]] = {}

    def show(self, illusion: Illusion | None) -> None:
        """Inputs for ``illusion`` (None: none); values updated in place when the type is unchanged."""
        model = type(illusion) if illusion is not None else None
        if model is not self.model:
            self._clear()
            self.model = model
            if model is not None:
                with self.folder:
                    for name, info in model.model_fields.items():
                        if name not in OWN_WIDGETS:
                            self._add(model, name, info, getattr(illusion, name))
        if illusion is not None:
            for name, handle in self.handles.items():
                handle.value = self._writers[name](getattr(illusion, name))

    def _clear(self) -> None:
        for handle in self.handles.values():
            handle.remove()
        self.handles.clear()
        self._readers.clear()
        self._writers.clear()

    def _add(self, model: type[Illusion], name: str, info: Any, value: Any) -> None:
        inner, optional = _unwrap_optional(info.annotation)
        hint = info.description or name
        label = name.replace("_", " ")
        handle: Any  # a dropdown, checkbox, number or text input
        if get_origin(inner) is Literal:
            options = [str(option) for option in get_args(inner)]
            if optional:
                options = [DEFAULT_OPTION, *options]
            initial = DEFAULT_OPTION if value is None else str(value)
            handle = self.gui.add_dropdown(label, options, initial_value=initial, hint=hint)
            self._readers[name] = lambda raw: None if raw == DEFAULT_OPTION else raw
            self._writers[name] = lambda v: DEFAULT_OPTION if v is None else str(v)
        elif inner is bool and not optional:
            handle = self.gui.add_checkbox(label, bool(value), hint=hint)
            self._readers[name], self._writers[name] = bool, bool
        elif inner is bool:
            options = [DEFAULT_OPTION, "true", "false"]
            handle = self.gui.add_dropdown(label, options, initial_value=DEFAULT_OPTION if value is None
                                           else str(value).lower(), hint=hint)
            self._readers[name] = lambda raw: None if raw == DEFAULT_OPTION else raw == "true"
            self._writers[name] = lambda v: DEFAULT_OPTION if v is None else str(v).lower()
        elif inner in (int, float) and not optional:
            low, high = field_bounds(model, name)
            handle = self.gui.add_number(label, value, min=low if np.isfinite(low) else None,
                                         max=high if np.isfinite(high) else None,
                                         step=1 if inner is int else None, hint=hint)
            self._readers[name], self._writers[name] = inner, inner
        else:
            hint = f"{hint} (empty = default)" if optional else hint
            handle = self.gui.add_text(label, format_text(value), hint=hint)
            self._readers[name] = functools.partial(parse_text, inner=inner)
            self._writers[name] = format_text
        self.handles[name] = handle

        @handle.on_update
        def _(event: viser.GuiEvent, name: str = name) -> None:
            self.on_change(name, self._readers[name](event.target.value))
