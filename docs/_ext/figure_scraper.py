"""A sphinx-gallery image scraper for the figures geardyn's plotting functions return.

geardyn draws with ``matplotlib.figure.Figure`` directly (no pyplot, nothing global), so the
stock matplotlib scraper, which saves pyplot's open figures, does not see them. This one saves
every Figure bound to a name in the example's globals that it has not saved before, in the order
of the names' first binding, after each code block.
"""

from __future__ import annotations

from typing import Any


def scrape(block: Any, block_vars: dict[str, Any], gallery_conf: dict[str, Any],
           **kwargs: Any) -> str:
    """Save the example's new Figures and return the reST that shows them."""
    from matplotlib.figure import Figure
    from sphinx_gallery.scrapers import figure_rst

    paths = []
    iterator = block_vars["image_path_iterator"]
    for value in list(block_vars["example_globals"].values()):
        if not isinstance(value, Figure) or getattr(value, "_gallery_saved", False):
            continue
        path = next(iterator)
        value.savefig(path, dpi=110)
        value._gallery_saved = True
        paths.append(path)
    return figure_rst(paths, gallery_conf["src_dir"])
