"""Strict JSON request bodies: ``application/json`` (or ``+json``), UTF-8, numbers only (no ``NaN``/``Infinity``), at
most ``MAX_DEPTH`` levels deep. Errors say where: the field (``body``, or ``spec`` for a study spec) plus line and
column in the text, never a bare character offset.

Python's ``json`` module accepts ``NaN`` and ``Infinity`` and recurses once per nesting level, so a body of a few
hundred thousand ``[`` would exhaust the interpreter's stack; both are refused before anything is validated.
"""

from __future__ import annotations

import email.message
import json
import re
from typing import Any

MAX_DEPTH = 64  # a case document is about 6 levels deep
MAX_EXACT_INTEGER = 2**53  # whole numbers a float holds exactly
# A JSON string (skipped whole, so brackets and words inside strings do not count), or a bracket, or a constant.
_TOKENS = re.compile(r'"(?:[^"\\]|\\.)*"|[\[\]{}]|-?Infinity|NaN')


class BodyError(ValueError):
    """A request body that is not acceptable JSON: ``status`` (415 or 422), ``field`` and a message."""

    def __init__(self, status: int, field: str, message: str) -> None:
        super().__init__(message)
        self.status = status
        self.field = field


def is_json_type(content_type: str | None) -> bool:
    """Whether a ``Content-Type`` header names JSON (``application/json``, ``application/merge-patch+json`` …)."""
    if not content_type:
        return False
    message = email.message.Message()
    message["content-type"] = content_type
    subtype = message.get_content_subtype()
    return message.get_content_maintype() == "application" and (subtype == "json" or subtype.endswith("+json"))


def check_json_type(content_type: str | None) -> None:
    """Raise a 415 ``BodyError`` naming ``Content-Type`` unless the header names JSON."""
    if not is_json_type(content_type):
        given = f"{content_type!r}" if content_type else "no content type"
        raise BodyError(415, "Content-Type", f"the body must be JSON: send 'Content-Type: application/json' "
                                             f"(got {given})")


def line_column(text: str, position: int) -> tuple[int, int]:
    """1-based (line, column) of a character offset."""
    line = text.count("\n", 0, position) + 1
    return line, position - (text.rfind("\n", 0, position) + 1) + 1


def _where(text: str, position: int) -> str:
    line, column = line_column(text, position)
    return f"line {line} column {column}"


def _scan(text: str, field: str, max_depth: int) -> None:
    """Refuse ``NaN``/``Infinity`` and nesting deeper than ``max_depth`` (outside strings), naming the place."""
    depth = 0
    for token in _TOKENS.finditer(text):
        kind = token.group()
        if kind in "[{":
            depth += 1
            if depth > max_depth:
                raise BodyError(422, field, f"nested deeper than {max_depth} levels at {_where(text, token.start())}")
        elif kind in "]}":
            depth -= 1
        elif kind[0] != '"':
            raise BodyError(422, field, f"{kind} at {_where(text, token.start())} is not a JSON number (JSON has no "
                                        "NaN or Infinity; send a finite number)")


def _number(text: str) -> float | int:
    """A JSON number written with a fraction or exponent: an ``int`` when it is a whole number (JSON Schema's
    ``integer`` is any number without a fractional part, so ``3.0`` is one; float fields take ints), else a float."""
    value = float(text)
    return int(value) if value.is_integer() and abs(value) <= MAX_EXACT_INTEGER else value


def parse_json(data: bytes | str, field: str = "body", max_depth: int = MAX_DEPTH) -> Any:
    """The JSON value of ``data``; ``BodyError`` (422, ``field``) for anything that is not strict JSON."""
    if isinstance(data, bytes):
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as error:
            raise BodyError(422, field, f"is not UTF-8 text (byte {error.start})") from None
    else:
        text = data
    try:
        value = json.loads(text, parse_float=_number)
    except json.JSONDecodeError as error:
        raise BodyError(422, field, f"invalid JSON at line {error.lineno} column {error.colno}: {error.msg}") from None
    except RecursionError:
        value = None  # _scan names the place
    except ValueError as error:  # an integer over Python's digit limit (``sys.get_int_max_str_digits``)
        raise BodyError(422, field, f"a number is too long: {str(error).split(';')[0]}") from None
    _scan(text, field, max_depth)
    return value
