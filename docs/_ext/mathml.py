"""Math as MathML, converted from LaTeX when the site is built (latex2mathml): every browser
renders it natively, with no script and no network, where MathJax would load from a CDN.

A formula latex2mathml cannot convert is a warning at its source line (an error under ``-W``)."""

from __future__ import annotations

from typing import Any

from docutils import nodes
from latex2mathml.converter import convert
from sphinx.util import logging

logger = logging.getLogger(__name__)


def _mathml(node: nodes.Element, latex: str, display: str) -> str:
    try:
        return convert(latex, display=display)
    except Exception as e:  # noqa: BLE001 - latex2mathml raises its own and builtin errors alike
        logger.warning("math: cannot convert %r to MathML: %s", latex, e, location=node)
        return f"<code>{latex}</code>"


def visit_math(self: Any, node: nodes.Element) -> None:
    self.body.append(f'<span class="math">{_mathml(node, node.astext(), "inline")}</span>')
    raise nodes.SkipNode


def visit_displaymath(self: Any, node: nodes.Element) -> None:
    self.body.append(f'<div class="math">{_mathml(node, node.astext(), "block")}</div>')
    raise nodes.SkipNode


def setup(app: Any) -> dict[str, Any]:
    app.add_html_math_renderer("mathml", (visit_math, None), (visit_displaymath, None))
    return {"parallel_read_safe": True, "parallel_write_safe": True}
