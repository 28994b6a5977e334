"""Panel inputs generated from a pydantic model's fields: an illusion's own parameters, and every section of the
case (road, ego, scene, weather, camera).

Numbers with a default get a number box (bounded by the field's constraints, which the hint names); optional
numbers ("empty = from the severity table", "empty = none") a text box where empty means None; choices a dropdown;
flags a checkbox; a nested model (a camera's lens, bonnet, sensor) a folder of its own inputs; anything else
(colours, lists) a JSON text box. Every input carries the field's description as its hover hint. A change is
reported as the field's path (``("lens", "k1")``) and the new value.
"""

from __future__ import annotations

import functools
import json
import types
from collections.abc import Callable
from typing import Annotated, Any, Literal, Union, get_args, get_origin

import numpy as np
import viser
from pydantic import BaseModel

from .placement import field_bounds

DEFAULT_OPTION = "(from severity)"
OWN_WIDGETS = ("type", "severity")  # the type is fixed; severity has its own slider
FieldChange = Callable[[str, Any], None]
PathChange = Callable[[tuple[str, ...], Any], None]
NOT_SET = "(none: tick it to add)"  # the note of an optional nested model that is absent


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


def bounds_text(low: float, high: float) -> str:
    """`` (min–max)`` of a bounded number for its hint ('' when unbounded)."""
    if not np.isfinite(low) and not np.isfinite(high):
        return ""
    return f" ({low:g} – {high:g})" if np.isfinite(low) and np.isfinite(high) else \
        f" ({'≥ ' + format(low, 'g') if np.isfinite(low) else '≤ ' + format(high, 'g')})"


def nested_model(annotation: Any) -> type[BaseModel] | None:
    """The model class of a field holding a nested model (optional or not), else None."""
    inner, _optional = _unwrap_optional(annotation)
    return inner if isinstance(inner, type) and issubclass(inner, BaseModel) else None


class ModelInputs:
    """The inputs of one pydantic model's fields inside a folder (nested models in sub-folders); rebuilt when the
    shown model class changes, updated in place otherwise. ``skip`` names fields shown elsewhere."""

    def __init__(self, gui: viser.GuiApi, folder: viser.GuiFolderHandle, on_change: PathChange,
                 skip: tuple[str, ...] = ()) -> None:
        self.gui = gui
        self.folder = folder
        self.on_change = on_change
        self.skip = skip
        self.model: type[BaseModel] | None = None
        self.handles: dict[str, Any] = {}
        self.children: dict[str, ModelInputs] = {}
        self._notes: dict[str, viser.GuiMarkdownHandle] = {}
        self._readers: dict[str, Callable[[Any], Any]] = {}
        self._writers: dict[str, Callable[[Any], Any]] = {}

    def paths(self) -> set[tuple[str, ...]]:
        """The field path of every input, nested models' included (the model's fields an absent optional
        nested model would show count as reachable: ticking it adds them)."""
        found: set[tuple[str, ...]] = {(name,) for name in self.handles}
        for name, child in self.children.items():
            model = nested_model(self.model.model_fields[name].annotation) if self.model is not None else None
            names = child.handles.keys() if child.model is not None else (model.model_fields if model else ())
            found |= {(name, *path) for path in child.paths()} | {(name, sub) for sub in names}
        return found

    def show(self, instance: BaseModel | None) -> None:
        """Inputs for ``instance`` (None: none); values updated in place when the model class is unchanged."""
        model = type(instance) if instance is not None else None
        if model is not self.model:
            self._clear()
            self.model = model
            if model is not None:
                with self.folder:
                    for name, info in model.model_fields.items():
                        if name not in self.skip:
                            self._add(model, name, info, getattr(instance, name))
        if instance is None:
            return
        for name, handle in self.handles.items():
            handle.value = self._writers[name](getattr(instance, name))
        for name, child in self.children.items():
            value = getattr(instance, name)
            child.show(value)
            self._notes[name].visible = value is None

    def _clear(self) -> None:
        for child in self.children.values():
            child._clear()
            child.folder.remove()
        for handle in [*self.handles.values(), *self._notes.values()]:
            handle.remove()
        self.handles.clear()
        self.children.clear()
        self._notes.clear()
        self._readers.clear()
        self._writers.clear()

    def _nested_change(self, name: str, path: tuple[str, ...], value: Any) -> None:
        self.on_change((name, *path), value)

    def _add(self, model: type[BaseModel], name: str, info: Any, value: Any) -> None:
        inner, optional = _unwrap_optional(info.annotation)
        hint = info.description or name
        label = name.replace("_", " ")
        if nested_model(info.annotation) is not None:
            folder = self.gui.add_folder(label, expand_by_default=False)
            with folder:
                self._notes[name] = self.gui.add_markdown(NOT_SET if optional else "", visible=value is None)
            self.children[name] = ModelInputs(self.gui, folder, functools.partial(self._nested_change, name))
            return
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
                                         step=1 if inner is int else None, hint=hint + bounds_text(low, high))
            self._readers[name], self._writers[name] = inner, inner
        else:
            hint = f"{hint} (empty = default)" if optional else hint
            if inner in (int, float):
                hint += bounds_text(*field_bounds(model, name))
            handle = self.gui.add_text(label, format_text(value), hint=hint)
            self._readers[name] = functools.partial(parse_text, inner=inner)
            self._writers[name] = format_text
        self.handles[name] = handle

        @handle.on_update
        def _(event: viser.GuiEvent, name: str = name) -> None:
            self.on_change((name,), self._readers[name](event.target.value))


class ParamInputs(ModelInputs):
    """The inputs of one illusion type's own parameters (not its type or severity, which have their own)."""

    def __init__(self, gui: viser.GuiApi, folder: viser.GuiFolderHandle, on_change: FieldChange) -> None:
        super().__init__(gui, folder, lambda path, value: on_change(path[0], value), skip=OWN_WIDGETS)
