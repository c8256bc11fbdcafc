"""``geardyn explore`` in a real browser: the server runs in a subprocess, headless Chromium
(Debian's ``chromium`` and ``chromium-driver``, installed by ``.ci/run``) is driven through
selenium: the page loads, a box zoom recomputes the window, a click shows an orbit, an invalid
parameter is refused next to its control, a valid one recomputes the diagram, Save writes the
files. A screenshot is kept in ``out/test-artifacts/explorer.png`` (with
``GEARDYN_SCREENSHOT=path`` also there, e.g. ``docs/figures/explorer.png``).
"""

from __future__ import annotations

import os
import queue
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import pytest

CHROMIUM, CHROMEDRIVER = Path("/usr/bin/chromium"), Path("/usr/bin/chromedriver")
ROOT = Path(__file__).resolve().parents[1]
ARTIFACTS = ROOT / "out" / "test-artifacts"

if not (CHROMIUM.exists() and CHROMEDRIVER.exists()):
    pytest.skip(f"headless browser test: {CHROMIUM} and {CHROMEDRIVER} are needed (Debian: "
                "apt-get install chromium chromium-driver; .ci/run installs them as root)",
                allow_module_level=True)
webdriver = pytest.importorskip("selenium.webdriver", reason="selenium is not installed "
                                "(pip install -e '.[test]')")

STUDY = """
[study]
name = "gear-pair"
model = "gear_pair"
[params]
zeta = 0.05
kappa = 0.2
Fa = 0.2
[run]
transient = 400.0
[sweep]
param = "Omega"
start = 0.6
stop = 2.4
num = 40
samples = 16
"""
#: --disable-dev-shm-usage: containers give /dev/shm 64 MB, too small for Chromium's renderer
#: (it crashes or hangs); its shared memory goes to /tmp instead.
CHROME_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--disable-quic", "--no-first-run", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--window-size=1250,1750")
#: Seconds the server may take to compute its first diagram (kernels warm: a few seconds).
START_TIMEOUT = 240.0
STEP_TIMEOUT = 60.0


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture()
def server(tmp_path):
    """The explorer serving the tiny study; yields (url, save folder)."""
    yield from _serve(tmp_path, "gear-pair.toml", STUDY)


def _spur_study_text() -> str:
    """The shipped cracked spur pair at small sizes (16 angles per mesh cycle, 38 harmonics,
    short runs, 6 speeds)."""
    from geardyn.io.toml import builtin_study_text

    text = builtin_study_text("spur_pair_cracked")
    for old, new in (("angles = 64", "angles = 16"), ("harmonics = 76", "harmonics = 38"),
                     ("transient_periods = 20", "transient_periods = 5"),
                     ("periods = 32", "periods = 4"), ("num = 41", "num = 6")):
        assert old in text, old
        text = text.replace(old, new)
    return text


@pytest.fixture()
def spur_server(tmp_path):
    """The explorer serving the small cracked spur pair; yields (url, save folder)."""
    yield from _serve(tmp_path, "spur.toml", _spur_study_text())


def _serve(tmp_path: Path, name: str, text: str):
    study = tmp_path / name
    study.write_text(text)
    port = _free_port()
    saved = tmp_path / "saved"
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen(
        [sys.executable, "-m", "geardyn.cli.main", "explore", str(study), "--port", str(port),
         "--save-dir", str(saved)],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    lines: queue.Queue[str] = queue.Queue()
    threading.Thread(target=lambda: [lines.put(x) for x in proc.stdout], daemon=True).start()
    log = []
    deadline = time.monotonic() + START_TIMEOUT
    try:
        while True:
            try:
                line = lines.get(timeout=max(0.1, deadline - time.monotonic()))
            except queue.Empty:
                pytest.fail(f"the server did not start in {START_TIMEOUT} s: {''.join(log)}")
            log.append(line)
            if "serving" in line:
                break
            if proc.poll() is not None:
                pytest.fail(f"the server ended: {''.join(log)}")
        assert f"http://127.0.0.1:{port}/" in line
        yield f"http://127.0.0.1:{port}/", saved
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(10)
        while not lines.empty():
            log.append(lines.get())
        print("server output:\n" + "".join(log))  # shown when the test fails


@pytest.fixture()
def browser():
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = str(CHROMIUM)
    profile = tempfile.mkdtemp(prefix="geardyn-chromium-")
    for flag in (*CHROME_FLAGS, f"--user-data-dir={profile}"):
        opts.add_argument(flag)
    driver = webdriver.Chrome(service=Service(str(CHROMEDRIVER)), options=opts)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


class Page:
    """The explorer page seen through Bokeh's document in the browser (models by name)."""

    def __init__(self, driver):
        self.d = driver

    def js(self, script: str, *args):
        return self.d.execute_script(script, *args)

    def model(self, name: str, attr: str):
        return self.js("const m = Bokeh.documents[0].get_model_by_name(arguments[0]);"
                       "return m[arguments[1]];", name, attr)

    def column(self, source: str, column: str) -> list:
        return self.js("const m = Bokeh.documents[0].get_model_by_name(arguments[0]);"
                       "return Array.from(m.data[arguments[1]]);", source, column)

    def points(self) -> list[tuple[float, float]]:
        """The diagram's (parameter, Poincare point) pairs, sorted."""
        return sorted(xy for cls in (1, 2, 3, 4, 5, 0, -1) for xy in zip(
            self.column(f"points_{cls}", "x"), self.column(f"points_{cls}", "y"), strict=True))

    def wait(self, what: str, check, timeout: float = STEP_TIMEOUT):
        t0 = time.monotonic()
        while time.monotonic() - t0 < timeout:
            try:
                value = check()
            except Exception:  # the page is still loading
                value = None
            if value:
                return value
            time.sleep(0.2)
        raise AssertionError(f"timed out waiting for {what}; progress: "
                             f"{self.model('progress', 'text')!r}, message: "
                             f"{self.model('message', 'text')!r}")

    def ready(self, start: float, stop: float) -> str:
        text = f"in [{start:.6g}, {stop:.6g}]"
        return self.wait(f"the diagram of {text}", lambda: (
            (p := self.model("progress", "text")).startswith("ready") and text in p and p))

    def pixel(self, value: float) -> tuple[int, int]:
        """Page coordinates of parameter ``value`` at mid-height of the diagram."""
        x, y = self.js(
            "const fig = Bokeh.documents[0].get_model_by_name('diagram');"
            "const v = Bokeh.index.find_one(fig); const r = v.el.getBoundingClientRect();"
            "const f = v.frame.bbox;"
            "return [r.left + v.frame.x_scale.compute(arguments[0]), r.top + f.top + "
            "f.height / 2];", value)
        return int(round(x)), int(round(y))

    def drag(self, a: float, b: float) -> None:
        """Box-zoom from parameter value ``a`` to ``b`` with the mouse."""
        from selenium.webdriver.common.actions.action_builder import ActionBuilder

        (x0, y), (x1, _) = self.pixel(a), self.pixel(b)
        chain = ActionBuilder(self.d)
        chain.pointer_action.move_to_location(x0, y).pointer_down()
        for k in range(1, 7):
            chain.pointer_action.move_to_location(x0 + (x1 - x0) * k // 6, y + 2 * k)
        chain.pointer_action.pointer_up()
        chain.perform()

    def click(self, value: float) -> None:
        from selenium.webdriver.common.actions.action_builder import ActionBuilder

        x, y = self.pixel(value)
        chain = ActionBuilder(self.d)
        chain.pointer_action.move_to_location(x, y).click()
        chain.perform()

    def shadow(self, name: str, selector: str):
        """An element inside the shadow DOM of the widget ``name``."""
        return self.js("const m = Bokeh.documents[0].get_model_by_name(arguments[0]);"
                       "return Bokeh.index.find_one(m).shadow_el.querySelector(arguments[1]);",
                       name, selector)

    def type_into(self, name: str, text: str) -> None:
        from selenium.webdriver.common.keys import Keys

        box = self.shadow(name, "input")
        self.js("arguments[0].value = '';", box)  # typing replaces the old text
        box.send_keys(text, Keys.ENTER)


def test_zoom_click_change_a_parameter_and_save(server, browser):
    url, saved = server
    page = Page(browser)
    browser.get(url)
    page.ready(0.6, 2.4)
    first = [x for x, _ in page.points()]
    assert len(first) > 40 and min(first) == pytest.approx(0.6)

    # box zoom: the window is recomputed at full resolution (40 values inside it)
    page.drag(1.0, 1.5)
    window = page.wait("the zoomed window", lambda: (
        (w := page.model("window", "value")) != "0.6:2.4" and w))
    start, stop = (float(v) for v in window.split(":"))
    assert start == pytest.approx(1.0, abs=0.03) and stop == pytest.approx(1.5, abs=0.03)
    page.ready(start, stop)
    zoomed = page.points()
    xs = [x for x, _ in zoomed]
    assert min(xs) == pytest.approx(start) and max(xs) == pytest.approx(stop)
    assert len(set(xs)) == 40
    assert f"--range {start:g}:{stop:g}:40" in page.model("command", "text")

    # click: the orbit nearest the click, its four panels filled
    page.click(1.2)
    summary = page.wait("the orbit", lambda: (
        (t := page.model("orbit_text", "text")).startswith("Omega =") and t))
    assert "contact loss mesh:" in summary and "Floquet multipliers" in summary
    for source, column in (("orbit_time", "t"), ("orbit_phase", "x"), ("orbit_section", "x"),
                           ("orbit_spectrum", "f")):
        assert len(page.column(source, column)) > 8, source
    assert page.column("orbit_peaks", "label"), summary

    # an invalid parameter: the message next to the control, the diagram unchanged
    page.type_into("param_zeta", "-1")
    message = page.wait("the validation message", lambda: (
        (t := page.model("param_zeta_message", "text")) and "-1" in t and t))
    assert "params.zeta" in message and "greater than or equal to 0" in message
    assert page.points() == zoomed

    # a valid one: the diagram is recomputed in the same window
    page.type_into("param_zeta", "0.08")
    page.wait("the message to clear", lambda: page.model("param_zeta_message", "text") == "")
    page.wait("the recomputed diagram", lambda: (
        page.model("progress", "text").startswith("ready") and page.points() != zoomed))
    assert "gear-pair-explore.toml" in page.model("command", "text")

    # save: the files geardyn bifurcation writes, the study with the change
    page.shadow("save", "button").click()
    wrote = page.wait("the saved files", lambda: (
        (t := page.model("saved", "text")).startswith("wrote") and t))
    assert ".nc" in wrote and ".png" in wrote
    assert sorted(p.suffix for p in saved.iterdir()) == [".nc", ".png", ".toml", ".txt"]

    # back: the first window again
    page.shadow("back", "button").click()
    page.ready(0.6, 2.4)
    page.click(2.2)  # period 1 there: its Floquet multipliers by shooting
    summary = page.wait("the orbit", lambda: (
        (t := page.model("orbit_text", "text")).startswith("Omega = 2.2") and t))
    assert "period 1" in summary and "Floquet multipliers (stable)" in summary
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    browser.save_screenshot(str(ARTIFACTS / "explorer.png"))
    if os.environ.get("GEARDYN_SCREENSHOT"):
        shutil.copyfile(ARTIFACTS / "explorer.png", os.environ["GEARDYN_SCREENSHOT"])


def test_a_fault_control_updates_the_stiffness_panel(spur_server, browser):
    """A model built from geometry: the crack depth is a control; a depth deeper than the tooth
    is refused next to it, a shallower one raises the stiffness panel's minimum and recomputes
    the diagram; Save writes the study file with the new depth."""
    url, saved = spur_server
    page = Page(browser)
    browser.get(url)
    page.ready(14000, 24000)
    first = page.points()
    drive = page.column("stiffness_mesh", "drive")
    assert len(drive) == 16 * 19 and len(page.column("stiffness_mesh", "drive_series")) == 16 * 19
    name = "param_faults[0].depth"
    assert page.shadow(name, "input").get_attribute("value") == "2 mm"

    page.type_into(name, "5 mm")
    message = page.wait("the validation message", lambda: (
        (t := page.model(f"{name}_message", "text")) and "faults[0].depth" in t and t))
    assert "faults[0].depth: the crack reaches" in message and "past its centre line" in message
    assert page.column("stiffness_mesh", "drive") == drive and page.points() == first

    page.type_into(name, "0.5 mm")
    page.wait("the message to clear", lambda: page.model(f"{name}_message", "text") == "")
    page.wait("the new stiffness", lambda: min(page.column("stiffness_mesh", "drive")) > min(drive))
    page.wait("the recomputed diagram", lambda: (
        page.model("progress", "text").startswith("ready") and page.points() != first))
    assert "spur_pair_cracked-explore.toml" in page.model("command", "text")
    page.shadow("save", "button").click()
    page.wait("the saved files", lambda: page.model("saved", "text").startswith("wrote"))
    assert 'depth = "0.5 mm"' in (saved / "spur_pair_cracked-explore.toml").read_text()
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    browser.save_screenshot(str(ARTIFACTS / "explorer_geometry.png"))
