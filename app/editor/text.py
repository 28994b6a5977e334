"""Text from cases, the store and error messages, made safe to show in viser's markdown.

viser renders ``gui.add_markdown`` content (and ``.content =``) as markdown that may carry HTML, links and images;
a case title, an id, an illusion field or an exception message quoting one must show as the characters it is,
never as a tag, a link or an image. Every such text passes through ``escape_markdown`` before it is put into a
markdown string; the editor's own formatting (``**bold**``) stays outside it.
"""

from __future__ import annotations

import string

# HTML's special characters as character references (markdown shows them as the characters; HTML cannot open a
# tag or an attribute with them), every other ASCII punctuation character backslash-escaped (CommonMark shows it
# literally: no emphasis, link, image, autolink, heading, list or table can start).
_ENTITIES = {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;"}
_TABLE = {ord(char): _ENTITIES.get(char, "\\" + char) for char in string.punctuation}
# Line breaks would start new blocks (a heading, a code block, a list): shown as spaces instead.
_TABLE.update({ord("\n"): " ", ord("\r"): " ", ord("\t"): " "})


def escape_markdown(text: object) -> str:
    """``str(text)`` as markdown that renders exactly those characters, on one line."""
    return str(text).translate(_TABLE)
