"""The HTML view: one self-contained page (no network access needed) per trace.

The page holds the view's JSON document (:mod:`.payload`), the stylesheet and the script of
``assets/`` inline. The script draws the top-down map (or the image boxes) on a canvas, with a
play button and a scrubbable time line on which the match window is marked, the corresponded
objects highlighted, labelled with the program's names and their paths drawn, their behaviour
labels along the time line, object details on hover and the explanation of the match.
A ``#match=N`` fragment (the results' match number in the trace) selects the match shown first.
"""

from __future__ import annotations

import html
import json
from functools import cache
from importlib import resources
from typing import Any

from .data import TraceView
from .payload import payload


@cache
def asset(name: str) -> str:
    """The text of a file of ``assets/``."""
    return resources.files(__package__).joinpath(f"assets/{name}").read_text(encoding="utf-8")


_SCRIPT_ESCAPES = str.maketrans({"<": "\\u003c", ">": "\\u003e", "&": "\\u0026"})
"""Characters that could end or change a ``<script>`` element (``</script>``, ``<!--``), written as
JSON escapes: the parsed document is the same (``json.dumps`` already escapes U+2028 and U+2029)."""


def script_json(document: Any) -> str:
    """JSON safe to put inside a ``<script>`` element: no ``<``, ``>`` or ``&`` appears literally."""
    return json.dumps(document, separators=(",", ":"), allow_nan=False).translate(_SCRIPT_ESCAPES)


def html_page(title: str, style: str, body: str, attributes: dict[str, str] | None = None) -> str:
    """A whole HTML document: ``title`` (text), ``style`` (CSS) and ``body`` (HTML) with the body
    element's ``attributes``."""
    attributes_text = "".join(f' {name}="{html.escape(value)}"' for name, value in (attributes or {}).items())
    return asset("page.html").format(title=html.escape(title), style=style, attributes=attributes_text, body=body)


def view_page(view: TraceView, back_link: str | None = None, initial_match: int | None = None) -> str:
    """The HTML page of a view; ``back_link`` (a URL) adds a link back to a report or index;
    ``initial_match`` (a match number) is shown first unless the URL's fragment names another."""
    back = "" if back_link is None else f'<a id="back" href="{html.escape(back_link)}">&larr; all results</a>'
    body = asset("view.html").format(back=back, data=script_json(payload(view)), script=asset("view.js"))
    attributes = {} if initial_match is None else {"data-initial-match": str(initial_match)}
    return html_page(f"scenegrep · {view.trace.name}", asset("view.css"), body, attributes)
