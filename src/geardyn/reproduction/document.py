"""A small document model rendered both as Markdown and as self-contained HTML (images inlined
as base64), so that ``report.md`` and ``report.html`` hold the same content.

Text may use ``**bold**`` and ```code``` spans; everything else is escaped in HTML.
"""

from __future__ import annotations

import base64
import html
import re
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Document"]

_STATUS_CLASS = {"holds": "ok", "partly holds": "partly", "fails": "bad",
                 "not assessed": "na"}

_CSS = """
body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;
line-height:1.45;color:#222}
table{border-collapse:collapse;margin:1em 0;font-size:0.92em}
th,td{border:1px solid #ccc;padding:0.25em 0.5em;vertical-align:top;text-align:left}
th{background:#f3f3f3}
code{background:#f5f5f5;padding:0 0.2em}
img{max-width:100%;border:1px solid #ddd;margin:0.5em 0}
.ok{background:#d9f2d9}.partly{background:#fff1c7}.bad{background:#f8d0d0}.na{color:#777}
"""


def _inline_html(text: str) -> str:
    out = html.escape(text, quote=False)
    out = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", out)
    return re.sub(r"`([^`]+)`", r"<code>\1</code>", out)


def _cell_html(text: str, tag: str) -> str:
    plain = text.replace("*", "").strip()
    status = next((s for s in _STATUS_CLASS if plain.startswith(s)), None)
    cls = f' class="{_STATUS_CLASS[status]}"' if status and tag == "td" else ""
    return f"<{tag}{cls}>{_inline_html(text)}</{tag}>"


@dataclass
class Document:
    """Blocks in order: headings, paragraphs, bullet lists, tables and images."""

    title: str
    blocks: list[tuple] = field(default_factory=list)

    def heading(self, text: str, level: int = 2) -> None:
        self.blocks.append(("h", level, text))

    def para(self, text: str) -> None:
        self.blocks.append(("p", text))

    def bullets(self, items: list[str]) -> None:
        if items:
            self.blocks.append(("ul", list(items)))

    def table(self, header: list[str], rows: list[list[str]]) -> None:
        self.blocks.append(("table", list(header), [list(r) for r in rows]))

    def image(self, path: Path, alt: str) -> None:
        """An image file; Markdown links it relative to the report, HTML inlines it."""
        self.blocks.append(("img", Path(path), alt))

    # ------------------------------------------------------------------ renderers
    def markdown(self, root: Path) -> str:
        out = [f"# {self.title}", ""]
        for block in self.blocks:
            kind = block[0]
            if kind == "h":
                out += ["#" * block[1] + " " + block[2], ""]
            elif kind == "p":
                out += [block[1], ""]
            elif kind == "ul":
                out += [f"- {item}" for item in block[1]] + [""]
            elif kind == "table":
                header, rows = block[1], block[2]
                out.append("| " + " | ".join(header) + " |")
                out.append("|" + "---|" * len(header))
                out += ["| " + " | ".join(c.replace("|", "\\|") for c in r) + " |" for r in rows]
                out.append("")
            elif kind == "img":
                out += [f"![{block[2]}]({_relative(block[1], root)})", ""]
        return "\n".join(out).rstrip() + "\n"

    def html(self) -> str:
        body = [f"<h1>{_inline_html(self.title)}</h1>"]
        for block in self.blocks:
            kind = block[0]
            if kind == "h":
                body.append(f"<h{block[1]}>{_inline_html(block[2])}</h{block[1]}>")
            elif kind == "p":
                body.append(f"<p>{_inline_html(block[1])}</p>")
            elif kind == "ul":
                items = "".join(f"<li>{_inline_html(i)}</li>" for i in block[1])
                body.append(f"<ul>{items}</ul>")
            elif kind == "table":
                head = "".join(_cell_html(h, "th") for h in block[1])
                rows = "".join("<tr>" + "".join(_cell_html(c, "td") for c in r) + "</tr>"
                               for r in block[2])
                body.append(f"<table><thead><tr>{head}</tr></thead><tbody>{rows}</tbody>"
                            "</table>")
            elif kind == "img":
                data = base64.b64encode(Path(block[1]).read_bytes()).decode("ascii")
                body.append(f'<img alt="{html.escape(block[2])}" '
                            f'src="data:image/png;base64,{data}">')
        return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
                f"<title>{html.escape(self.title)}</title><style>{_CSS}</style></head>"
                "<body>\n" + "\n".join(body) + "\n</body></html>\n")


def _relative(path: Path, root: Path) -> str:
    try:
        return Path(path).resolve().relative_to(Path(root).resolve()).as_posix()
    except ValueError:
        return Path(path).as_posix()
