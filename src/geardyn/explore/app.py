"""The explorer's page, a Bokeh server application.

Why Bokeh server: it is a maintained, pure-Python framework for scientific web applications
whose figures report the browser's interactions (box zoom as a ``RangesUpdate`` event, clicks as
``Tap`` events, widget changes) to Python callbacks on the server, where geardyn runs. The whole
page is built from Python; there is no hand-written JavaScript.

Every browser tab is one session with its own :class:`~geardyn.explore.state.ExplorerState`;
computations run in a worker thread (:class:`~geardyn.explore.runner.Runner`) and reach the page
through ``doc.add_next_tick_callback``, so the page never waits on them.
"""

from __future__ import annotations

import html
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np

from geardyn.explore.compute import (
    DiagramView,
    OrbitView,
    compute_diagram,
    compute_orbit,
    diagram_view,
    orbit_request,
    stiffness_view,
)
from geardyn.explore.overlay import curve_marks
from geardyn.explore.runner import Runner
from geardyn.explore.state import CONTINUATIONS, INTERPRETATIONS, DiagramRequest, ExplorerState
from geardyn.plotting.bifurcation import PERIOD_CLASSES, REGIME_COLORS

__all__ = ["ExplorerSession", "make_application"]

_ERROR_STYLE = "color:#b00020"
#: Plot area width and left border (px), the same for the diagram and its contact bands so that
#: their parameter axes line up.
FRAME_WIDTH, BORDER_LEFT = 760, 60


def _class_data(view: DiagramView | None, cls: int) -> dict[str, Any]:
    if view is None:
        return {"x": [], "y": []}
    mask = view.period_class == cls
    return {"x": view.x[mask], "y": view.y[mask]}


def _band_data(view: DiagramView, mesh: str) -> dict[str, Any]:
    regimes = view.contact.get(mesh, np.array([], dtype=str))
    colors = [REGIME_COLORS.get(r, REGIME_COLORS["unbounded"]) for r in regimes]
    return {"x": view.values[: len(regimes)], "color": colors, "regime": list(regimes)}


def _padded(points: np.ndarray, orbit: np.ndarray) -> dict[str, float]:
    """Range of the section ``points``, padded by 5 % of the whole ``orbit``'s extent (so a
    period-1 point sits in a window of the orbit's scale, not of round-off)."""
    pts = points[np.isfinite(points)]
    whole = orbit[np.isfinite(orbit)]
    if not pts.size:
        return {"start": 0.0, "end": 1.0}
    lo, hi = float(np.min(pts)), float(np.max(pts))
    pad = max(0.05 * (float(np.ptp(whole)) if whole.size else 0.0), 0.05 * (hi - lo),
              1e-9 * max(1.0, abs(lo)))
    return {"start": lo - pad, "end": hi + pad}


class ExplorerSession:
    """The widgets, figures and callbacks of one browser session."""

    def __init__(self, doc, state: ExplorerState, ds,
                 describe_error: Callable[[BaseException], str]):
        self.doc = doc
        self.state = state
        # the diagram computed before the session, taken as this session's (same study, window
        # and settings; the request holds this session's model, which later changes replace)
        self.ds, self.request = ds, state.diagram_request()
        self.runner = Runner(describe_error)
        self._pending: DiagramRequest | None = None
        self._syncing = False
        self._pending_orbit = None
        self.describe_error = describe_error
        self._build()
        self._show_diagram(ds, self.request)
        doc.on_session_destroyed(lambda _ctx: self.runner.shutdown())

    # ------------------------------------------------------------------ layout
    def _build(self) -> None:
        from bokeh.events import RangesUpdate, Tap
        from bokeh.layouts import column, row
        from bokeh.models import (
            BoxZoomTool,
            Button,
            ColumnDataSource,
            DataRange1d,
            Div,
            HoverTool,
            PanTool,
            Range1d,
            Select,
            TapTool,
            TextInput,
        )
        from bokeh.plotting import figure

        st = self.state
        w = st.window
        self.x_range = Range1d(w.start, w.stop, name="x_range")
        tools = [BoxZoomTool(dimensions="width"), TapTool(), PanTool(dimensions="width")]
        fig = figure(frame_height=360, frame_width=FRAME_WIDTH, min_border_left=BORDER_LEFT,
                     x_range=self.x_range, y_range=DataRange1d(),
                     tools=tools, active_drag=tools[0], name="diagram",
                     x_axis_label=st.param, y_axis_label=st.effective_study.plot_state,
                     title="bifurcation diagram: box-zoom to recompute a window, click a point")
        self.point_sources = {}
        for cls, label, color in PERIOD_CLASSES:
            src = ColumnDataSource({"x": [], "y": []}, name=f"points_{cls}")
            self.point_sources[cls] = src
            fig.scatter("x", "y", source=src, size=7 if cls == -1 else 2.5, color=color,
                        marker="inverted_triangle" if cls == -1 else "circle",
                        legend_label=label)
        legend = fig.legend[0]
        legend.label_text_font_size = "8pt"
        legend.title = "period"
        fig.add_layout(legend, "right")
        self.marker = ColumnDataSource({"x": []}, name="marker")
        fig.ray("x", 0, source=self.marker, length=0, angle=np.pi / 2, color="black",
                line_dash="dashed")
        fig.ray("x", 0, source=self.marker, length=0, angle=-np.pi / 2, color="black",
                line_dash="dashed")
        fig.add_tools(HoverTool(tooltips=[(st.param, "@x{0.0000}"), ("point", "@y{0.0000}")],
                                renderers=fig.renderers[:len(PERIOD_CLASSES)]))
        # the given two-parameter curves where they cross the diagram (geardyn.explore.overlay)
        self.curve_source = ColumnDataSource({"x": [], "label": [], "color": []},
                                             name="curve_marks")
        for angle in (np.pi / 2, -np.pi / 2):
            fig.ray("x", 0, source=self.curve_source, length=0, angle=angle, color="color",
                    line_width=1.5, line_alpha=0.8)
        fig.on_event(RangesUpdate, self._on_ranges)
        fig.on_event(Tap, self._on_tap)
        self.diagram = fig

        self.bands, self.band_sources = [], {}
        for mesh in (str(m) for m in self.ds["mesh"].values):
            src = ColumnDataSource({"x": [], "color": [], "regime": []}, name=f"band_{mesh}")
            band = figure(frame_height=14, frame_width=FRAME_WIDTH, min_border_left=BORDER_LEFT,
                          x_range=self.x_range, tools="",
                          toolbar_location=None, y_range=(0, 1), name=f"band_fig_{mesh}")
            band.rect("x", 0.5, width=1.0, height=1.0, color="color", source=src,
                      name=f"band_rect_{mesh}")
            band.yaxis.visible = False
            band.xaxis.visible = False
            band.title.text = f"contact loss {mesh}"
            band.title.text_font_size = "8pt"
            self.bands.append(band)
            self.band_sources[mesh] = src
        legend = " ".join(f'<span style="background:{c};padding:0 6px">{n}</span>'
                          for n, c in REGIME_COLORS.items())
        bands_legend = Div(text=f"contact loss: {legend}")

        self.progress = Div(text="", name="progress", width=900)
        self.message = Div(text="", name="message", width=900)
        self.back_button = Button(label="Back", name="back", width=80)
        self.back_button.on_click(self._on_back)
        self.window_input = TextInput(title="window START:STOP (same number of points)",
                                      value=f"{w.start:g}:{w.stop:g}", name="window", width=260)
        self.window_input.on_change("value", self._on_window_text)
        self.window_message = Div(text="", name="window_message", width=260)
        self.save_button = Button(label="Save view (NetCDF + PNG)", name="save", width=200)
        self.save_button.on_click(self._on_save)
        self.saved = Div(text="", name="saved", width=900)
        self.command = Div(text="", name="command", width=900)

        self.inputs, self.input_messages = {}, {}
        controls = [self._control(name, TextInput, Div, column) for name in st.main_params()]
        self._widgets = (Select, TextInput, Div, column)
        geometry = self._geometry_controls()
        self.continuation = Select(title="continuation", value=st.continuation,
                                   options=list(CONTINUATIONS), name="continuation", width=120)
        self.continuation.on_change("value", self._on_continuation)
        controls.append(self.continuation)
        if st.model_kind.paper_device:
            interp = st.interpretation or st.study.study.interpretation
            self.interpretation = Select(title="interpretation", value=interp,
                                         options=list(INTERPRETATIONS), name="interpretation",
                                         width=140)
            self.interpretation.on_change("value", self._on_interpretation)
            self.interpretation_message = Div(text="", width=140)
            controls.append(column(self.interpretation, self.interpretation_message))

        orbit_figs = self._orbit_figures(figure, ColumnDataSource)
        self.orbit_text = Div(text="click a point of the diagram to see its orbit",
                              name="orbit_text", width=900)
        top = row(self.back_button, column(self.window_input, self.window_message),
                  self.save_button)
        extra = []
        self.geometry_row = row(*geometry, name="geometry")
        if geometry:
            extra.append(column(Div(text="<b>geometry and faults</b> (study-file keys)"),
                                self.geometry_row))
        self.stiffness_fig = None
        stiffness_panel = self._stiffness_figure(figure, ColumnDataSource, Div, column)
        self.layout = column(
            Div(text=f"<b>geardyn explore</b>: {html.escape(st.study.study.name)}"),
            top, self.progress, self.message, row(*controls), *extra, fig, *self.bands,
            bands_legend, *([stiffness_panel] if stiffness_panel is not None else []),
            self.command, self.saved, self.orbit_text,
            row(orbit_figs[0], orbit_figs[1]), row(orbit_figs[2], orbit_figs[3]),
            name="layout")
        self.doc.add_root(self.layout)
        self.doc.title = f"geardyn explore: {st.study.study.name}"

    def _geometry_controls(self) -> list:
        """The geometry and fault controls of the current view (a choice where the key has
        :meth:`~ExplorerState.choices`, else a text box)."""
        Select, TextInput, Div, column = self._widgets  # noqa: N806
        st = self.state
        return [self._control(name, Select if st.choices(name) else TextInput, Div, column)
                for name in st.geometry_params()]

    def _control(self, name: str, widget, Div, column):  # noqa: N803
        """A text box (``widget`` TextInput) or a choice (Select, for a control with
        :meth:`~ExplorerState.choices`) for the parameter or geometry key ``name`` and its
        message line."""
        st = self.state
        kw = {"options": list(st.choices(name))} if st.choices(name) else {}
        box = widget(title=name, value=str(st.current_value(name)), name=f"param_{name}",
                     width=150, description=st.param_help(name) or None, **kw)
        box.on_change("value", partial(self._on_param, name))
        msg = Div(text="", name=f"param_{name}_message", width=150)
        self.inputs[name], self.input_messages[name] = box, msg
        return column(box, msg)

    def _stiffness_figure(self, figure, ColumnDataSource, Div, column):  # noqa: N803
        """The mesh stiffness panel of a model built from geometry (None for other models):
        per mesh (its colour) the drive and coast flank, the table and the model's series, the
        faulty meshes thick, and the faults' line."""
        from bokeh.palettes import Category10_10

        st = self.state
        view = stiffness_view(st.model)
        self.stiffness_sources, self.stiffness_lines = {}, {}
        if view is None and not st.geometry_params():
            return None
        meshes = ([m.mesh for m in view.meshes] if view is not None
                  else [str(m) for m in getattr(st.model, "mesh_names", ())])
        fig = figure(frame_height=240, frame_width=FRAME_WIDTH, min_border_left=BORDER_LEFT,
                     tools="pan,wheel_zoom,box_zoom,reset", name="stiffness_fig",
                     title=view.title() if view is not None else "mesh stiffness",
                     x_axis_label="mesh cycles (of the forcing period)",
                     y_axis_label="mesh stiffness [N/m]")
        for k, mesh in enumerate(meshes):
            src = ColumnDataSource({"cycle": [], "drive": [], "coast": [], "drive_series": [],
                                    "coast_series": []}, name=f"stiffness_{mesh}")
            self.stiffness_sources[mesh] = src
            color = Category10_10[k % 10]
            self.stiffness_lines[mesh] = [
                fig.line("cycle", column_name, source=src, color=color, line_dash=dash,
                         legend_label=f"{mesh} {flank}")
                for column_name, dash, flank in (
                    ("drive", "solid", "drive"), ("drive_series", "dashed", "drive"),
                    ("coast", "dotted", "coast"), ("coast_series", "dotdash", "coast"))]
        legend = fig.legend[0]
        legend.label_text_font_size = "8pt"
        legend.click_policy = "hide"
        fig.add_layout(legend, "right")
        self.stiffness_fig = fig
        self.stiffness_faults = Div(text="", name="stiffness_faults", width=900)
        self._show_stiffness(st.model)
        return column(fig, Div(text="solid: the table; dashed: the model's series (drive "
                               "flank); dotted, dash-dot: the coast flank's; thick: a faulty "
                               "mesh"), self.stiffness_faults)

    def _show_stiffness(self, model) -> None:
        """The stiffness panel shows ``model``'s stiffness (empty, said so, for a model
        without potential-energy tables)."""
        if self.stiffness_fig is None:
            return
        view = stiffness_view(model)
        if view is None:
            for src in self.stiffness_sources.values():
                src.data = {k: [] for k in src.data}
            self.stiffness_fig.title.text = "mesh stiffness"
            self.stiffness_faults.text = ("no potential-energy stiffness tables in this model "
                                          "(stiffness = iso: the ISO 6336-1 waves)")
            return
        for mesh in view.meshes:
            self.stiffness_sources[mesh.mesh].data = {
                "cycle": mesh.cycle, "drive": mesh.drive, "coast": mesh.coast,
                "drive_series": mesh.drive_series, "coast_series": mesh.coast_series}
            for line in self.stiffness_lines[mesh.mesh]:
                line.glyph.line_width = 3 if mesh.faulty else 1
        self.stiffness_fig.title.text = view.title()
        faulty = ", ".join(m.mesh for m in view.meshes if m.faulty)
        self.stiffness_faults.text = "faults: " + html.escape(view.faults) + (
            f" (faulty meshes: {html.escape(faulty)})" if faulty else "")

    def _orbit_figures(self, figure, ColumnDataSource) -> list:  # noqa: N803
        from bokeh.models import LabelSet, Range1d

        self.orbit_sources = {
            "time": ColumnDataSource({"t": [], "x": []}, name="orbit_time"),
            "phase": ColumnDataSource({"x": [], "v": []}, name="orbit_phase"),
            "section": ColumnDataSource({"x": [], "v": []}, name="orbit_section"),
            "spectrum": ColumnDataSource({"f": [], "a": []}, name="orbit_spectrum"),
            "peaks": ColumnDataSource({"f": [], "a": [], "label": []}, name="orbit_peaks"),
        }
        s = self.orbit_sources
        kw = {"height": 280, "width": 450, "tools": "pan,wheel_zoom,box_zoom,reset"}
        time = figure(title="time history", x_axis_label="t", name="orbit_time_fig", **kw)
        time.line("t", "x", source=s["time"])
        phase = figure(title="phase portrait (dots: Poincaré section)", name="orbit_phase_fig",
                       **kw)
        phase.line("x", "v", source=s["phase"], alpha=0.6)
        phase.scatter("x", "v", source=s["section"], color="red", size=5)
        section = figure(title="Poincaré section (one point per forcing period)",
                         x_range=Range1d(0, 1), y_range=Range1d(0, 1),
                         name="orbit_section_fig", **kw)
        section.scatter("x", "v", source=s["section"], color="red", size=4)
        spectrum = figure(title="amplitude spectrum (frequency / Ω)", y_axis_type="log",
                          y_range=Range1d(1e-10, 1.0), name="orbit_spectrum_fig", **kw)
        spectrum.line("f", "a", source=s["spectrum"])
        spectrum.add_layout(LabelSet(x="f", y="a", text="label", source=s["peaks"],
                                     text_font_size="8pt", y_offset=3, text_align="center"))
        self.orbit_figs = [time, phase, section, spectrum]
        return self.orbit_figs

    # ------------------------------------------------------------------ showing results
    def _show_diagram(self, ds, request: DiagramRequest) -> None:
        view = diagram_view(ds, request.plot_state)
        self.ds, self.request = ds, request
        for cls, src in self.point_sources.items():
            src.data = _class_data(view, cls)
        for mesh, src in self.band_sources.items():
            src.data = _band_data(view, mesh)
        for band in self.bands:
            band.renderers[0].glyph.width = view.width
        self._show_stiffness(request.model)
        self.curve_source.data = curve_marks(self.state.curves, request.param,
                                             self.state.current_value)
        w = request.window
        self._shown = (w.start, w.stop)
        self.x_range.update(start=w.start, end=w.stop)
        self.window_input.value = f"{w.start:g}:{w.stop:g}"
        self.command.text = ("reproduce: <code>" + html.escape(self.state.command())
                             + "</code>")
        self.back_button.disabled = not self.state.history
        self.progress.text = (f"ready: {w.num} values of {request.param} in "
                              f"[{w.start:.6g}, {w.stop:.6g}], continuation "
                              f"{request.continuation}")

    def _show_orbit(self, orbit: OrbitView) -> None:
        s = self.orbit_sources
        s["time"].data = {"t": orbit.time, "x": orbit.x}
        s["phase"].data = {"x": orbit.x, "v": orbit.v}
        s["section"].data = {"x": orbit.section_x, "v": orbit.section_v}
        amp = orbit.amplitude
        floor = float(np.max(amp)) * 1e-10 if amp.size and np.max(amp) > 0 else 1e-300
        s["spectrum"].data = {"f": orbit.frequency, "a": np.maximum(amp, floor)}
        if amp.size and np.max(amp) > 0:  # room above the highest peak for its label
            self.orbit_figs[3].y_range.update(start=float(np.max(amp)) * 1e-9,
                                              end=float(np.max(amp)) * 30.0)
        # a period-1 section is one point: show it at the scale of the orbit, not of round-off
        section = self.orbit_figs[2]
        for rng, points, orbit_values in ((section.x_range, orbit.section_x, orbit.x),
                                          (section.y_range, orbit.section_v, orbit.v)):
            rng.update(**_padded(points, orbit_values))
        s["peaks"].data = {"f": [p[0] for p in orbit.peaks], "a": [p[1] for p in orbit.peaks],
                           "label": [p[2] for p in orbit.peaks]}
        self.orbit_figs[0].yaxis.axis_label = orbit.state
        for fig in self.orbit_figs[1:3]:
            fig.xaxis.axis_label = orbit.state
            fig.yaxis.axis_label = orbit.velocity or f"d{orbit.state}/dt"
        notes = "".join(f"<br>{html.escape(n)}" for n in orbit.notes)
        self.orbit_text.text = html.escape(orbit.summary()) + notes

    # ------------------------------------------------------------------ requests
    def _later(self, fn, *args) -> None:
        """Run ``fn(*args)`` on the document's thread (from the worker)."""
        self.doc.add_next_tick_callback(partial(fn, *args))

    def recompute(self) -> None:
        """Compute the current view's diagram in the worker; the page keeps the last one."""
        try:
            request = self.state.diagram_request()
        except Exception as exc:
            self._set_message(self.describe_error(exc))
            return
        w = request.window
        self.progress.text = (f"computing {w.num} values of {request.param} in "
                              f"[{w.start:.6g}, {w.stop:.6g}] …")
        self.marker.data = {"x": []}

        def job(progress):
            return compute_diagram(request, progress)

        # results reach the page on its own thread, and only for the newest request (a
        # superseded one that finished meanwhile is dropped there)
        self._pending = request
        self.runner.submit(
            job, on_done=lambda ds: self._later(self._diagram_done, request, ds),
            on_error=lambda msg: self._later(self._diagram_failed, request, msg),
            on_progress=lambda d, t: self._later(self._diagram_progress, request, d, t),
            key="diagram")

    def _diagram_progress(self, request: DiagramRequest, done: int, total: int) -> None:
        if request is self._pending:
            pct = 100.0 * done / max(total, 1)
            self.progress.text = (f"computing … <progress value='{done}' max='{total}'>"
                                  f"</progress> {done}/{total} ({pct:.0f}%)")

    def _diagram_done(self, request: DiagramRequest, ds) -> None:
        if request is self._pending:
            self._set_message("")
            self._show_diagram(ds, request)

    def _diagram_failed(self, request: DiagramRequest, message: str) -> None:
        if request is self._pending:
            self._set_message(f"computation failed: {message}; the last good view is kept")
            self.state.restore(self.request)
            self._sync_controls()
            self._show_diagram(self.ds, self.request)

    def _sync_controls(self) -> None:
        """The controls show the state's values (without triggering their callbacks)."""
        self._syncing = True
        try:
            for name, box in self.inputs.items():
                box.value = str(self.state.current_value(name))
            self.continuation.value = self.state.continuation
            if self.state.model_kind.paper_device:
                self.interpretation.value = (self.state.interpretation
                                             or self.state.study.study.interpretation)
        finally:
            self._syncing = False

    def _set_message(self, text: str) -> None:
        self.message.text = f'<span style="{_ERROR_STYLE}">{html.escape(text)}</span>' \
            if text else ""

    # ------------------------------------------------------------------ callbacks
    def _on_ranges(self, event) -> None:
        x0, x1 = event.x0, event.x1
        if x0 is None or x1 is None:
            return
        span = abs(self._shown[1] - self._shown[0])
        if abs(x0 - self._shown[0]) <= 1e-9 * span and abs(x1 - self._shown[1]) <= 1e-9 * span:
            return
        self._zoom(x0, x1, self.window_message)

    def _zoom(self, x0: float, x1: float, where) -> None:
        msg = self.state.zoom(x0, x1)
        if msg is not None:
            where.text = f'<span style="{_ERROR_STYLE}">{html.escape(msg)}</span>'
            return
        where.text = ""
        self._shown = (self.state.window.start, self.state.window.stop)
        self.recompute()

    def _on_window_text(self, _attr, _old, new: str) -> None:
        if self._syncing:
            return
        parts = new.replace(",", ":").split(":")
        try:
            x0, x1 = (float(p) for p in parts[:2])
            if len(parts) != 2:
                raise ValueError
        except ValueError:
            self.window_message.text = (f'<span style="{_ERROR_STYLE}">window: expected '
                                        f'START:STOP (got {html.escape(new)})</span>')
            return
        w = self.state.window
        if (x0, x1) == (float(f"{w.start:g}"), float(f"{w.stop:g}")):
            return
        self._zoom(x0, x1, self.window_message)

    def _on_back(self) -> None:
        if self.state.back():
            self._shown = (self.state.window.start, self.state.window.stop)
            self.recompute()

    def _on_tap(self, event) -> None:
        if event.x is None:
            return
        req = orbit_request(self.request, self.ds, float(event.x))
        self.marker.data = {"x": [req.value]}
        self.orbit_text.text = f"computing the orbit at {req.param} = {req.value:.6g} …"

        self._pending_orbit = req
        self.runner.submit(lambda _progress: compute_orbit(req),
                           lambda orbit: self._later(self._orbit_done, req, orbit),
                           lambda msg: self._later(self._orbit_failed, req, msg), key="orbit")

    def _orbit_done(self, req, orbit: OrbitView) -> None:
        if req is self._pending_orbit:
            self._show_orbit(orbit)

    def _orbit_failed(self, req, message: str) -> None:
        if req is self._pending_orbit:
            self.orbit_text.text = (f'<span style="{_ERROR_STYLE}">orbit failed: '
                                    f'{html.escape(message)}</span>')

    def _on_param(self, name: str, _attr, _old, new: str) -> None:
        if self._syncing:
            return
        msg = self.state.set_override(name, new)
        box = self.input_messages[name]
        if msg is not None:
            box.text = f'<span style="{_ERROR_STYLE}">{html.escape(msg)}</span>'
            return
        box.text = ""
        if name.endswith(".kind"):  # the fault's fields are the new kind's
            stale = [n for n in self.inputs if n not in self.state.geometry_params()
                     and n not in self.state.main_params()]
            for n in stale:
                del self.inputs[n], self.input_messages[n]
            self.geometry_row.children = self._geometry_controls()
        self._show_stiffness(self.state.model)
        self.recompute()

    def _on_continuation(self, _attr, _old, new: str) -> None:
        if self._syncing:
            return
        if self.state.set_continuation(new) is None:
            self.recompute()

    def _on_interpretation(self, _attr, _old, new: str) -> None:
        if self._syncing:
            return
        msg = self.state.set_interpretation(new)
        self.interpretation_message.text = (
            f'<span style="{_ERROR_STYLE}">{html.escape(msg)}</span>' if msg else "")
        if msg is None:
            self.recompute()

    def _on_save(self) -> None:
        try:
            paths = self.state.save(self.ds) if self._view_is_current() \
                else None
        except Exception as exc:
            self.saved.text = (f'<span style="{_ERROR_STYLE}">save failed: '
                               f'{html.escape(self.describe_error(exc))}</span>')
            return
        if paths is None:
            self.saved.text = "the view is still being computed; save it when it is ready"
            return
        self.saved.text = "wrote " + ", ".join(html.escape(str(p)) for p in paths)

    def _view_is_current(self) -> bool:
        """The shown diagram is the state's current view (no computation pending)."""
        req = self.request
        st = self.state
        return (req.window == st.window and req.continuation == st.continuation
                and req.model is st.model)


def make_application(make_state: Callable[[], ExplorerState], ds,
                     describe_error: Callable[[BaseException], str] = str):
    """The Bokeh application: every session starts from a fresh state and the diagram ``ds``
    already computed for the same view."""
    from bokeh.application import Application
    from bokeh.application.handlers.function import FunctionHandler

    def session(doc) -> None:
        ExplorerSession(doc, make_state(), ds, describe_error)

    return Application(FunctionHandler(session))
