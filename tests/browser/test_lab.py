"""The chapters as a student meets them: JupyterLab and the book in headless Chromium.

JupyterLab is started on 127.0.0.1 with a token, serving the student edition of chapter 10 (a
slider, toggle buttons and a checkbox); Chromium, driven by Playwright, runs all its cells, changes
each control once and checks that the figure under them is drawn — not the nearly white PNG that a
callback sharing pyplot's figure with another thread sends on a first move — against the chapter's
static figure of the same experiment.
Then the chapter's page of the book (built from the stored outputs) must show rendered mathematics
and its solutions collapsed.

Needs Chromium (Debian's package ``chromium``; ``.ci/run`` installs it where it can) and the pinned
``playwright``; without them the module is skipped with the reason.
"""

from __future__ import annotations

import base64
import io
import os
import secrets
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import numpy as np
import pytest

from quadlib.teaching.assignments import build_assignment

ROOT = Path(__file__).resolve().parents[2]
CHAPTER = "10_attitude_complementary.ipynb"
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
playwright = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (environment.txt pins it)")
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="no Chromium on this machine: install Debian's package "
                                "'chromium' (as .ci/run does) to run the browser tests")
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]
IDLE = "window.jupyterapp.shell.currentWidget.sessionContext.session.kernel.status === 'idle'"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _inked(png: bytes) -> float:
    """The share of a figure's pixels that are not white (0 for a blank figure)."""
    from PIL import Image

    pixels = np.asarray(Image.open(io.BytesIO(png)).convert("L"), dtype=float)
    return float(np.mean(pixels < 250))


def _png(src: str | None) -> bytes:
    prefix = "data:image/png;base64,"
    return base64.b64decode(src[len(prefix):]) if src and src.startswith(prefix) else b""


@pytest.fixture(scope="module")
def browser():
    with playwright.sync_playwright() as p:
        chromium = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield chromium
        chromium.close()


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """JupyterLab on 127.0.0.1 with a token, serving the student edition of the chapter; its URL."""
    built = tmp_path_factory.mktemp("student")
    build_assignment(ROOT / "notebooks" / CHAPTER, built)  # the student edition, as make student writes it
    root = built / "notebooks"
    token, port = secrets.token_hex(16), _free_port()
    env = dict(os.environ, QUADLIB_PROGRESS="off", JUPYTER_CONFIG_DIR=str(root / ".config"))
    log = (root / "lab.log").open("w")
    server = subprocess.Popen([sys.executable, "-m", "jupyterlab", "--no-browser", "--ip=127.0.0.1", f"--port={port}",
                               f"--IdentityProvider.token={token}", f"--ServerApp.root_dir={root}", "--allow-root",
                               "--LabApp.expose_app_in_browser=True", "--LabApp.news_url=None"],
                              stdout=log, stderr=subprocess.STDOUT, env=env)
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                urllib.request.urlopen(f"http://127.0.0.1:{port}/api/status?token={token}", timeout=1).close()
                break
            except OSError:
                if time.monotonic() > deadline or server.poll() is not None:
                    pytest.fail(f"JupyterLab did not start: {(root / 'lab.log').read_text()[-2000:]}")
                time.sleep(0.3)
        yield f"http://127.0.0.1:{port}/lab/tree/{CHAPTER}?token={token}"
    finally:
        server.terminate()
        try:
            server.wait(15)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
        log.close()


def test_every_control_redraws_its_figure_on_the_first_change(lab, browser):
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    page.goto(lab)
    page.wait_for_function("window.jupyterapp && window.jupyterapp.shell.currentWidget && "
                           "window.jupyterapp.shell.currentWidget.sessionContext?.session?.kernel", timeout=60_000)
    page.wait_for_function(IDLE, timeout=60_000)
    page.evaluate("window.jupyterapp.commands.execute('notebook:run-all-cells')")
    page.wait_for_timeout(1000)
    page.wait_for_function(IDLE, timeout=90_000)
    interact = page.locator(".widget-interact").first
    interact.wait_for(timeout=30_000)
    interact.scroll_into_view_if_needed()
    controls = interact.locator(".noUi-handle, input[type=checkbox], .widget-toggle-buttons button:nth-child(2)")
    below = page.locator("xpath=//div[contains(@class, 'jp-Cell')][.//div[contains(@class, 'widget-interact')]]"
                         "/following-sibling::div[contains(@class, 'jp-Cell')][1]//img").first
    below.wait_for(timeout=30_000)
    static = _png(below.get_attribute("src"))  # the cell after the controls: the experiment at a fixed setting
    assert controls.count() >= 3 and _inked(static) > 0.05, "the chapter's controls or its static figure are missing"
    for i in range(controls.count()):
        before = interact.locator(".widget-output").inner_text()
        control = controls.nth(i)
        control.scroll_into_view_if_needed()
        if "noUi-handle" in (control.get_attribute("class") or ""):
            control.focus()
            page.keyboard.press("ArrowRight")  # one step of a slider: the value is sent when the key is released
        else:
            control.click()  # a checkbox, or a toggle button other than the one selected
        page.wait_for_function("([el, old]) => el.innerText !== old && el.querySelector('img')",
                               arg=[interact.locator(".widget-output").element_handle(), before], timeout=60_000)
        page.wait_for_function(IDLE, timeout=60_000)
        drawn = _png(interact.locator(".widget-output img").first.get_attribute("src"))
        assert len(drawn) > 0.3 * len(static) and _inked(drawn) > 0.5 * _inked(static), \
            f"control {i + 1}: its first change drew a blank figure ({len(drawn)} bytes, {_inked(drawn):.0%} inked)"
    page.close()


def test_the_books_chapter_renders_its_mathematics_and_folds_its_solutions(browser, tmp_path):
    source = tmp_path / "book"
    (source / "chapters").mkdir(parents=True)
    shutil.copy(ROOT / "book" / "conf.py", source / "conf.py")
    shutil.copy(ROOT / "notebooks" / CHAPTER, source / "chapters" / CHAPTER)
    (source / "index.md").write_text("# Book\n\n```{toctree}\n:glob:\n\nchapters/*\n```\n")
    built = subprocess.run([sys.executable, "-m", "sphinx", "-q", "-b", "html", "-D", "nb_execution_mode=off",
                            str(source), str(tmp_path / "html")], capture_output=True, text=True,
                           env=dict(os.environ, MPLBACKEND="module://matplotlib_inline.backend_inline"))
    assert built.returncode == 0, built.stderr[-2000:]
    page = browser.new_page()
    page.goto((tmp_path / "html" / "chapters" / CHAPTER.replace(".ipynb", ".html")).as_uri())
    page.wait_for_function("document.querySelectorAll('mjx-container').length > 20", timeout=30_000)
    assert page.locator("mjx-merror").count() == 0, "a formula did not render"
    solutions = page.locator(".tag_solution details")
    assert solutions.count() >= 3
    for i in range(solutions.count()):
        assert solutions.nth(i).get_attribute("open") is None, "a solution is shown unfolded"
        assert not solutions.nth(i).locator("pre").first.is_visible(), "a folded solution's code is visible"
    page.close()
