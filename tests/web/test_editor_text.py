"""``escape_markdown``: text from cases and errors renders as its own characters, never as HTML, a link or an
image (checked with a CommonMark renderer that passes raw HTML through, as a permissive markdown view would)."""

from __future__ import annotations

import html

import pytest
from markdown_it import MarkdownIt

from app.editor.text import escape_markdown

PAYLOADS = [
    '<iframe srcdoc="<script>alert(1)</script>">',
    "<script>alert(1)</script>",
    "[x](javascript:alert(1))",
    "![i](http://evil.example/x.png)",
    "<img src=x onerror=alert(1)>",
    "**bold** _it_ `code` ~~s~~ | a | b |",
    "line one\n# heading\n    code\n- item",
    "www.evil.example and https://evil.example/x",
    "&lt;script&gt; \\<b\\> 'quoted' \"double\"",
]
RENDER = MarkdownIt("commonmark", {"html": True}).enable(["table", "strikethrough"])


@pytest.mark.parametrize("text", PAYLOADS)
def test_escaped_text_renders_as_itself(text: str) -> None:
    rendered = RENDER.render(escape_markdown(text))
    assert rendered.startswith("<p>") and rendered.endswith("</p>\n") and rendered.count("<") == 2
    shown = html.unescape(rendered.removeprefix("<p>").removesuffix("</p>\n"))
    assert shown == text.replace("\n", " ").strip()


def test_plain_words_stay_readable() -> None:
    assert escape_markdown("fence_shadow-03 version 2") == "fence\\_shadow\\-03 version 2"
    assert escape_markdown(42) == "42"
