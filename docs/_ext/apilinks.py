"""Links from the guide to the reference: an inline literal of a page that names a public object
(``varmech.integrate``, ``check_conservation(traj)``, ``Trajectory.to_xarray``,
``symbolic.from_mechanics``) becomes a link to its API page, so that the pages written in
Markdown link to the reference without a role in every sentence."""

from __future__ import annotations

import re
from typing import Any

from docutils import nodes
from sphinx import addnodes

# A dotted name, optionally called: ``name``, ``name(...)``, ``name()``.
_NAME = re.compile(r"^(?:varmech\.)?([A-Za-z_][\w]*(?:\.[A-Za-z_]\w*)*)(?:\(.*\))?$", re.S)


# Where a name the guide writes without its module is looked for, after the top level.
MODULES = ("charts", "analysis", "analysis.stability", "analysis.sections", "analysis.reference", "symbolic", "events", "scenes")


def api_name(text: str, objects: dict[str, Any]) -> str | None:
    """The documented object ``text`` names (at varmech's top level, else in one of
    :data:`MODULES`), or None."""
    match = _NAME.match(text.strip())
    if match is None:
        return None
    candidates = [f"varmech.{match.group(1)}", *(f"varmech.{module}.{match.group(1)}" for module in MODULES)]
    return next((name for name in candidates if name in objects), None)


def link_literals(app: Any, doctree: nodes.document, docname: str) -> None:
    """Each inline literal of a page outside the reference that names a public object, as a
    link to it."""
    if docname.startswith("api"):
        return
    objects = app.env.get_domain("py").objects
    for node in list(doctree.findall(nodes.literal)):
        if isinstance(node.parent, (nodes.reference, addnodes.pending_xref, addnodes.desc_signature)):
            continue
        name = api_name(node.astext(), objects)
        if name is None:
            continue
        entry = objects[name]
        uri = app.builder.get_relative_uri(docname, entry.docname) + "#" + entry.node_id
        link = nodes.reference("", "", internal=True, refuri=uri, reftitle=name)
        link += node.deepcopy()
        node.replace_self(link)


def setup(app: Any) -> dict[str, Any]:
    app.connect("doctree-resolved", link_literals)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
