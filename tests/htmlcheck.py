"""Helpers for the HTML page tests: find anything a page would fetch from elsewhere."""

from __future__ import annotations

import re
from html.parser import HTMLParser

#: Attributes that make a browser fetch something.
_FETCHING = {"src", "href", "srcset", "action", "poster", "data", "background", "xlink:href",
             "formaction", "manifest", "ping", "cite"}
_CSS_URL = re.compile(r"url\(\s*['\"]?([^'\")]+)", re.IGNORECASE)
_CSS_IMPORT = re.compile(r"@import\s+['\"]?([^'\";]+)", re.IGNORECASE)


class _Refs(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.refs: list[str] = []
        self._in_style = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "style":
            self._in_style = True
        for k, v in attrs:
            if v is None:
                continue
            if k.lower() == "srcset":
                self.refs.extend(p.strip().split(" ")[0] for p in v.split(","))
            elif k.lower() in _FETCHING:
                self.refs.append(v.strip())
            if k.lower() == "style":
                self.refs.extend(_CSS_URL.findall(v))

    def handle_endtag(self, tag: str) -> None:
        if tag == "style":
            self._in_style = False

    def handle_data(self, data: str) -> None:
        if self._in_style:
            self.refs.extend(_CSS_URL.findall(data))
            self.refs.extend(_CSS_IMPORT.findall(data))


def external_references(page: str) -> list[str]:
    """Every reference in ``page`` that is not a ``data:`` URI or a ``#fragment``."""
    p = _Refs()
    p.feed(page)
    return [r for r in p.refs if not r.startswith(("data:", "#"))]
