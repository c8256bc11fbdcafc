"""Serve the explorer: compute the first diagram, start the Bokeh server on one address, print
it, and run until interrupted."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

from geardyn.explore.compute import compute_diagram
from geardyn.explore.state import ExplorerState

__all__ = ["LOCAL_HOSTS", "host_warning", "serve"]

#: Addresses that reach only this machine.
LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1")


def host_warning(host: str, save_dir: Path) -> str | None:
    """The warning printed when the explorer is bound to an address other machines reach."""
    if host in LOCAL_HOSTS:
        return None
    return (f"warning: serving on {host}: the explorer is reachable from other machines and "
            "has no authentication; anyone who reaches it can run computations and write "
            f"files under {save_dir}")


def serve(make_state: Callable[[], ExplorerState], *, port: int = 5006,
          host: str = "127.0.0.1", show: bool = False,
          describe_error: Callable[[BaseException], str] = str,
          echo: Callable[[str], None] = print) -> None:
    """Start the explorer server for the states ``make_state()`` gives (one per browser
    session) on ``host:port`` and block until interrupted. ``show`` opens a browser tab."""
    from bokeh.server.server import Server

    from geardyn.explore.app import make_application

    state = make_state()
    warning = host_warning(host, state.save_dir)
    if warning is not None:
        print(warning, file=sys.stderr)
    request = state.diagram_request()
    w = request.window
    echo(f"computing the first diagram: {w.num} values of {request.param} in "
         f"[{w.start:g}, {w.stop:g}] (the first run compiles the kernels) ...")
    ds = compute_diagram(request)
    app = make_application(make_state, ds, describe_error)
    shown = f"[{host}]" if ":" in host else host
    origins = [f"{shown}:{port}"] + ([f"localhost:{port}", f"127.0.0.1:{port}"]
                                     if host in LOCAL_HOSTS else [])
    server = Server({"/": app}, port=port, address=host, allow_websocket_origin=origins,
                    num_procs=1)
    server.start()
    echo(f"geardyn explore: serving {state.study.study.name} at http://{shown}:{port}/ "
         "(Ctrl-C to stop)")
    sys.stdout.flush()
    if show:
        server.io_loop.add_callback(server.show, "/")
    try:
        server.io_loop.start()
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
