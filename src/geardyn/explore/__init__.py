"""``geardyn explore``: an interactive bifurcation explorer in the browser.

:mod:`~geardyn.explore.state` (the view and its changes), :mod:`~geardyn.explore.compute` (the
computations, calls of the public API), :mod:`~geardyn.explore.runner` (a worker thread where a
new request supersedes the running one) are plain Python; :mod:`~geardyn.explore.app` and
:mod:`~geardyn.explore.server` are the Bokeh server page on top of them.
"""

from geardyn.explore.state import ExplorerState, Window

__all__ = ["ExplorerState", "Window"]
