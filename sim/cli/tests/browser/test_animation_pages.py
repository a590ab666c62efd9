"""The `walker … --animate` pages in a real headless browser (Debian's chromium, WebGL on
SwiftShader), driven by Playwright. Run by scripts/browser-tier, which makes the pages and
passes them in WALKER_ANIMATION_PAGES (separated by ':').

Each page must load with no console error and no page error, report ready through its
`window.walker` API, and show the walker: at two times half a step apart, the screenshot's
walker region holds many walker-coloured pixels (the legs are the only saturated colours
besides the green path), and the two screenshots differ substantially there."""

import io
import os

import pytest
from PIL import Image
from playwright.sync_api import sync_playwright

CHROMIUM = os.environ.get("WALKER_CHROMIUM", "/usr/bin/chromium")
ARGS = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox"]
VIEWPORT = {"width": 1000, "height": 700}


def pages():
    listed = os.environ.get("WALKER_ANIMATION_PAGES", "")
    found = [p for p in listed.split(":") if p]
    if not found:
        raise RuntimeError("WALKER_ANIMATION_PAGES names no page (run scripts/browser-tier)")
    return found


@pytest.fixture(scope="module")
def browser():
    # No skip: a browser that cannot start fails the tier.
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


def walker_mask(png):
    """The pixels of the walker's legs in the walker region of a canvas screenshot (right of
    the information panel): saturated, not the green of the path."""
    img = Image.open(io.BytesIO(png)).convert("RGB")
    w, h = img.size
    region = img.crop((int(0.36 * w), 0, w, h))
    mask = set()
    rw = region.size[0]
    px = region.tobytes()
    for i in range(len(px) // 3):
        r, g, b = px[3 * i], px[3 * i + 1], px[3 * i + 2]
        hi, lo = max(r, g, b), min(r, g, b)
        if hi > 40 and (hi - lo) / hi > 0.35 and not (g >= r and g >= b):
            mask.add((i % rw, i // rw))
    return mask


@pytest.mark.parametrize("path", pages(), ids=os.path.basename)
def test_page_loads_and_shows_the_walker_moving(browser, path):
    page = browser.new_page(viewport=VIEWPORT)
    problems = []
    page.on("console", lambda m: problems.append(f"console {m.type}: {m.text}") if m.type == "error" else None)
    page.on("pageerror", lambda e: problems.append(f"page error: {e}"))
    page.goto("file://" + os.path.abspath(path))
    page.wait_for_function("window.walker.ready || window.walker.error !== null", timeout=30000)
    state = page.evaluate("({ready: walker.ready, error: walker.error, d: walker.duration_s, n: walker.frames})")
    assert state["error"] is None, state["error"]
    assert state["ready"] and state["d"] > 0 and state["n"] > 1, state
    # A walk over a floor that steps draws a level under each step; one plane draws none.
    levels = page.evaluate("walker.floorLevels")
    if "step-down" in os.path.basename(path):
        assert levels > 1, f"{levels} floor levels drawn for a floor with a step"
    else:
        assert levels == 0, f"{levels} floor levels drawn on one plane"
    # It plays by itself: walk time advances.
    start = page.evaluate("walker.time()")
    page.wait_for_timeout(700)
    assert page.evaluate("walker.time()") > start, "the page does not play"
    t1 = 0.3 * state["d"]
    t2 = t1 + min(0.4, 0.5 * state["d"])
    masks = []
    for t in (t1, t2):
        page.evaluate(f"walker.seek({t})")
        masks.append(walker_mask(page.locator("#view").screenshot()))
    a, b = masks
    assert len(a) > 300 and len(b) > 300, f"walker pixels {len(a)}, {len(b)}: blank?"
    moved = len(a ^ b) / len(a | b)
    assert moved > 0.3, f"the two times look alike ({moved:.2f} of the walker pixels differ)"
    # A walk that ends in a fall says so at its end; one that ends on another failure says
    # it stopped, and why.
    kinds = page.evaluate("JSON.parse(document.getElementById('walker-data').textContent).events.map(e => e.kind)")
    if "fall" in kinds:
        page.evaluate("walker.seek(walker.duration_s)")
        assert "fell at" in page.inner_text("#banner")
    if "stop" in kinds:
        page.evaluate("walker.seek(walker.duration_s)")
        banner = page.inner_text("#banner")
        assert "simulation ended at" in banner and "fell" not in banner, banner
    if page.evaluate("JSON.parse(document.getElementById('walker-data').textContent).emergency_stop_sent_s") is not None:
        page.evaluate("walker.seek(walker.duration_s)")
        assert "emergency stop sent at" in page.inner_text("#banner")
    # Between two frames of different times the pose is interpolated: halfway it is drawn
    # as neither frame (without interpolation it would be the earlier one, pixel for pixel).
    i = page.evaluate("walker.seek(0.5 * walker.duration_s)")
    t0, t1 = page.evaluate(f"[walker.frameTime({i}), walker.frameTime({i + 1})]")
    if t1 > t0:
        shots = []
        for t in (t0, 0.5 * (t0 + t1)):
            page.evaluate(f"walker.seek({t})")
            shots.append(walker_mask(page.locator("#view").screenshot()))
        assert shots[0] != shots[1], "the pose between two frames is the earlier frame's"
    assert not problems, problems
    page.close()
