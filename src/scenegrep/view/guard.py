"""What ``scenegrep serve`` accepts from a request: the checks that keep other web pages, other
host names and other files out (see the README's Security paragraph).

Each check raises :class:`Refused` with the HTTP status and a one-line reason:

- every request: ``Host`` is the bound address and port (a DNS-rebinding page has its own name);
- API requests: the server's token (``X-Scenegrep-Token``), which only its own page holds;
- POST requests: ``Origin``, when present, is the server's own (browsers always send it on a
  POST; a page elsewhere cannot forge it), ``Content-Type: application/json`` (which a page
  elsewhere cannot send without a CORS preflight, never granted), and a body length from 0 to
  ``MAX_BODY`` bytes.

Messages sent to the page name no absolute path: :func:`public_message`.
"""

from __future__ import annotations

import hmac
import re
from email.message import Message
from http import HTTPStatus
from pathlib import Path

from ..dataset.catalog import within

MAX_BODY = 1 << 20
"""The largest request body accepted, in bytes."""

TIME_LIMIT = 300.0
"""Default seconds a query may run."""

TOKEN_HEADER = "X-Scenegrep-Token"

_ABSOLUTE = re.compile(r"(?<![\w.~-])/(?:[^\s/:'\"]+/)+")
"""The folders of an absolute path in a message (the file name after them is kept)."""


class Refused(Exception):
    """A request refused with an HTTP ``status`` and a one-line ``reason``."""

    def __init__(self, status: HTTPStatus, reason: str):
        super().__init__(reason)
        self.status = status
        self.reason = reason


def check_host(headers: Message, address: str) -> None:
    """``Host`` must be ``address`` (``127.0.0.1:PORT``), as the page's own URL names it."""
    if headers.get("Host") != address:
        raise Refused(HTTPStatus.FORBIDDEN, f"this server answers only requests for http://{address}/")


def check_token(headers: Message, token: str) -> None:
    """The API needs the token the server put in its page."""
    if not hmac.compare_digest(headers.get(TOKEN_HEADER, "").encode(), token.encode()):
        raise Refused(HTTPStatus.FORBIDDEN, "missing or wrong API token: use the page this server serves")


def check_post(headers: Message, address: str) -> int:
    """The checks of a state-changing request; returns the body's length in bytes."""
    origin = headers.get("Origin")
    if origin is not None and origin != f"http://{address}":
        raise Refused(HTTPStatus.FORBIDDEN, "requests from other web pages are refused")
    if headers.get_content_type() != "application/json" or headers.get("Content-Type") is None:
        raise Refused(HTTPStatus.UNSUPPORTED_MEDIA_TYPE, "the request must be Content-Type: application/json")
    return body_length(headers)


def body_length(headers: Message) -> int:
    """The declared ``Content-Length``: required, a whole number from 0 to :data:`MAX_BODY`."""
    text = headers.get("Content-Length")
    if text is None:
        raise Refused(HTTPStatus.LENGTH_REQUIRED, "the request needs a Content-Length")
    if not text.strip().isdigit():
        raise Refused(HTTPStatus.BAD_REQUEST, f"bad Content-Length {text[:20]!r}")
    if int(text) > MAX_BODY:
        raise Refused(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, f"the request is larger than {MAX_BODY} bytes")
    return int(text)


def dataset_file(root: Path, value: object, option: str) -> str:
    """An option naming a file (``vocabulary``, a program's ``param map``): a relative path to a
    regular file inside the dataset folder at ``root`` (symbolic links resolved), returned as given."""
    if not isinstance(value, str):
        raise Refused(HTTPStatus.BAD_REQUEST, f"option {option!r} must name a file inside the dataset")
    target = within(root, value)
    if Path(value).is_absolute() or target is None or not target.is_file():
        raise Refused(HTTPStatus.BAD_REQUEST, f"option {option!r} must name a file inside the dataset: {value!r}")
    return value


def public_message(text: str, root: Path) -> str:
    """A message for the page: paths inside the dataset relative to it, the dataset itself as
    ``DATASET``, and other absolute paths reduced to their file names."""
    for base in dict.fromkeys((str(root), str(root.resolve()))):
        text = text.replace(base + "/", "").replace(base, "DATASET")
    return _ABSOLUTE.sub("", text)
