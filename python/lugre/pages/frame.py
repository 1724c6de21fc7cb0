"""The frame every page shares: styles, tables, figures, paragraphs."""

from __future__ import annotations

import datetime as _dt
from html import escape
from typing import Any

__all__: list[str] = []

_CSS = """
:root{--fg:#1d2329;--muted:#5b6670;--line:#d5dbe0;--ok:#1f7a3d;--warn:#9a5b00;--bad:#a3222b;
--bg:#fff;--card:#f6f8fa}
*{box-sizing:border-box}
body{font:16px/1.5 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;color:var(--fg);
background:var(--bg);margin:0;padding:1rem}
main{max-width:56rem;margin:0 auto}
h1{font-size:1.5rem;margin:.2rem 0 .6rem}
h2{font-size:1.2rem;margin:2rem 0 .5rem;border-bottom:1px solid var(--line);padding-bottom:.2rem}
h3{font-size:1.05rem;margin:1.4rem 0 .4rem}
.verdict{background:var(--card);border-left:.35rem solid var(--warn);padding:.8rem 1rem;
border-radius:.3rem;font-size:1.05rem}
.verdict.ok{border-left-color:var(--ok)}
.meta{color:var(--muted);font-size:.85rem}
.scroll{overflow-x:auto}
table{border-collapse:collapse;margin:.4rem 0;font-size:.95rem}
th,td{border-bottom:1px solid var(--line);padding:.3rem .6rem;text-align:left;vertical-align:top}
th{background:var(--card);font-weight:600}
td.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
figure{margin:.6rem 0}
figure img{width:100%;height:auto;border:1px solid var(--line);border-radius:.2rem}
figcaption{color:var(--muted);font-size:.85rem}
.bar{display:flex;height:1.4rem;border-radius:.2rem;overflow:hidden;margin:.4rem 0}
.bar span{display:block;height:100%}
.legend span.sw{display:inline-block;width:.8rem;height:.8rem;margin-right:.3rem;
vertical-align:middle;border-radius:.15rem}
.finding{border:1px solid var(--line);border-radius:.4rem;padding:.2rem 1rem .8rem;margin:1rem 0}
ul{padding-left:1.3rem}
@media (max-width:40rem){body{font-size:15px;padding:.6rem}th,td{padding:.25rem .35rem}}
"""

_COLOURS = ["#c0392b", "#2471a3", "#d68910", "#7d3c98", "#138d75", "#a04000", "#566573"]


# --------------------------------------------------------------------------------------
# Page frame
# --------------------------------------------------------------------------------------


def _page(title: str, body: str, subtitle: str = "") -> str:
    from .._version import __version__

    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
        f"<title>{escape(title)}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n<main>\n"
        f"<h1>{escape(title)}</h1>\n"
        + (f"<p class=\"meta\">{subtitle}</p>\n" if subtitle else "")
        + body
        + f"\n<p class=\"meta\">Written by lugre {escape(__version__)} on {stamp}.</p>\n"
        "</main>\n</body>\n</html>\n"
    )


def _table(head: list[str], rows: list[list[str]], numeric: set[int] | None = None) -> str:
    """A table; cells are HTML already (escape text before)."""
    numeric = numeric or set()
    h = "".join(f"<th>{c}</th>" for c in head)
    body = "".join(
        "<tr>" + "".join(f"<td class=\"n\">{c}</td>" if j in numeric else f"<td>{c}</td>"
                         for j, c in enumerate(r)) + "</tr>"
        for r in rows
    )
    return f"<div class=\"scroll\"><table><thead><tr>{h}</tr></thead><tbody>{body}</tbody></table></div>"


def _figure(uri: str | None, caption: str) -> str:
    if not uri:
        return ""
    return (f"<figure><img src=\"{uri}\" alt=\"{escape(caption)}\">"
            f"<figcaption>{escape(caption)}</figcaption></figure>")


def _p(text: str) -> str:
    return f"<p>{escape(text)}</p>"


def _safe_figure(make: Any, *args: Any, **kw: Any) -> str | None:
    """A figure, or ``None`` when its data are unusable (the page is written anyway)."""
    try:
        return str(make(*args, **kw))
    except (ValueError, KeyError, TypeError, IndexError):
        return None
