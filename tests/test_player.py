"""The interactive player (issue 31): the page, opened in headless Chromium.

One browser for the module (closed whatever happens); every wait is for an event (the page
drawn, a value shown, play stopped), never for a clock. Without Chromium these tests skip
(CI, where the variable CI is set, fails instead: .ci/run installs it)."""

from __future__ import annotations

import json
import math
import os
import re

import numpy as np
import pytest
from PIL import Image, ImageSequence

import dumbbell
from dumbbell.animation.bars import fixed
from dumbbell.animation.player import (
    exact_float32,
    json_for_script,
    page,
    player,
    shown_digits,
)
from dumbbell.animation.render import render_gif, sample_every
from tests import browser as B
from tests.conftest import SCENES

#: The textbook's first impact (s): sqrt(2 h0 / g).
FIRST_IMPACT = math.sqrt(2 * 1.0 / 9.8)


@pytest.fixture(scope="module")
def chromium():
    why = B.unavailable()
    if why is not None:
        if os.environ.get("CI"):
            pytest.fail(f"CI must run the browser tests: {why}")
        pytest.skip(why)
    with B.launched() as b:
        yield b


def _run(scene, t_end, solver=None):
    """A run sampled as ``dumbbell play`` and ``dumbbell render`` sample it."""
    s = dumbbell.load_scene(scene) if isinstance(scene, str) else scene
    return dumbbell.simulate(s, solver, t_end=t_end,
                             every=sample_every(s.run.dt, 25, t_end, s.run.every))


@pytest.fixture(scope="module")
def textbook_run():
    return _run(str(SCENES / "textbook-1d.toml"), 2.0)


@pytest.fixture(scope="module")
def textbook_page(textbook_run, tmp_path_factory):
    path = tmp_path_factory.mktemp("player") / "textbook.html"
    player(textbook_run).save(path)
    return path


@pytest.fixture
def opened(chromium, textbook_page):
    o = B.open_player(chromium, textbook_page)
    yield o
    o.page.close()


def _expected(traj, t_shown: str, names, decimals: int) -> dict[str, str]:
    j = int(np.argmin(np.abs(traj.t - float(t_shown))))
    return {name: fixed(float(traj[name][j]), decimals) for name in names}


# --- the page alone ------------------------------------------------------------------------


def test_the_page_loads_offline_without_errors_or_requests(opened):
    assert opened.console == []
    assert opened.requests == [opened.url]   # the file itself, nothing else
    assert opened.refused == []
    assert opened.page.inner_text("#title") == "Bouncing dumbbell, textbook section 13.5.1"


def test_the_first_impact_shows_the_trajectorys_own_values(opened, textbook_run):
    """Next impact from t = 0 stops at the first sample after the impact at 0.4518 s; the
    bars' numbers (drawn and in the table, one function) are the trajectory's values there
    to the digits shown. The fragment #t=0.4518 shows the same sample."""
    o = opened
    before = o.shown()
    o.page.click("#next-impact")
    shown = o.wait_shown(before)
    assert abs(float(shown) - FIRST_IMPACT) <= 0.001 and float(shown) >= FIRST_IMPACT
    names = ["K_cm", "K_int", "U_g", "U_spring", "E"]
    values = {name: o.table()[(0, name)] for name in names}
    assert values == _expected(textbook_run, shown, names, 2)
    assert values["K_cm"] == "0.00" and values["K_int"] == "1.96"     # K_cm went into K_int
    o.page.goto(o.url + "#t=0.4518")
    o.page.wait_for_selector("body[data-ready]")
    assert o.shown() == shown and {n: o.table()[(0, n)] for n in names} == values
    assert o.console == []


def test_every_energy_prints_in_the_page_as_python_prints_it():
    """The page keeps energies as float32 chosen to print as the float64 values do with the
    bars' rule; values that sit on a rounding edge of float32 included."""
    rng = np.random.default_rng(3)
    v = np.concatenate([rng.normal(0, 3, 20000), np.arange(-300, 300) / 200 + 1e-9,
                        np.array([0.125, -0.125, 2.675, 1e-17, -1e-17, 0.0])])
    for d in (0, 2, 3, 4):
        v32, same = exact_float32(v, d)
        assert same
        page_digits = np.floor(v32.astype(float) * 10.0**d + 0.5)
        python = np.array([float(fixed(float(x), d).replace(".", "")) for x in v])
        assert np.array_equal(page_digits, python)
        assert np.array_equal(shown_digits(v, d), python)
        assert np.max(np.abs(v32 - v)) <= 1e-6 * np.max(np.abs(v)) + 1e-12


def test_keyboard_and_controls_do_what_their_labels_say(opened):
    o = opened
    p = o.page
    assert p.get_attribute("#play", "aria-keyshortcuts") == "Space"
    p.focus("#play")
    p.keyboard.press(" ")                                     # space: play
    p.wait_for_function("window.dumbbellPlayer.state().playing")
    p.keyboard.press(" ")                                     # space again: pause
    p.wait_for_function("!window.dumbbellPlayer.state().playing")
    p.keyboard.press("Home")
    p.wait_for_function("document.body.dataset.shown === '0.000'")
    for k in (1, 2):                                          # right arrow: one frame (1/25 s)
        before = o.shown()
        p.keyboard.press("ArrowRight")
        assert float(o.wait_shown(before)) == pytest.approx(k / 25)
    before = o.shown()
    p.keyboard.press("ArrowLeft")                             # left: one frame back
    assert float(o.wait_shown(before)) == pytest.approx(1 / 25)
    before = o.shown()
    p.keyboard.press("Shift+ArrowRight")                      # with shift: one sample (1 ms)
    assert float(o.wait_shown(before)) == pytest.approx(1 / 25 + 0.001)
    before = o.shown()
    p.keyboard.press("]")                                     # next impact
    assert float(o.wait_shown(before)) == pytest.approx(FIRST_IMPACT, abs=0.001)
    before = o.shown()
    p.keyboard.press("]")
    second = float(o.wait_shown(before))
    assert second > FIRST_IMPACT + 0.01
    before = o.shown()
    p.keyboard.press("[")                                     # previous impact
    assert float(o.wait_shown(before)) == pytest.approx(FIRST_IMPACT, abs=0.001)
    before = o.shown()
    p.click("#back")                                          # the buttons
    assert float(o.wait_shown(before)) == pytest.approx(0.44)
    before = o.shown()
    p.click("#forward")
    assert float(o.wait_shown(before)) == pytest.approx(0.48)
    before = o.shown()
    p.fill("#time", "1.25")                                   # the slider: that time
    assert o.wait_shown(before) == "1.250"
    p.focus("#time")
    before = o.shown()
    p.keyboard.press("ArrowRight")                            # its arrows: one frame
    assert o.wait_shown(before) == "1.280"
    p.select_option("#speed", "4")
    assert o.state()["speed"] == 4
    labels = [p.inner_text(f"label[for={i}]") for i in ("time", "speed", "loop")]
    assert [s.split()[0] for s in labels] == ["time", "speed", "loop"]
    # Loop off: playing stops at the end, on the last sample.
    p.uncheck("#loop")
    p.keyboard.press("End")
    p.evaluate("window.dumbbellPlayer.seek(1.9)")
    p.click("#play")
    p.wait_for_function("!window.dumbbellPlayer.state().playing")
    assert o.shown() == "2.000"
    assert o.console == []


def test_a_screenshot_puts_the_particles_where_the_gif_frame_puts_them(chromium, tmp_path):
    """At frame k's time the page draws A and B within 2 px of the GIF's frame k (in the
    GIF's pixels: the page's canvas scaled back), in 1D and in 2D."""
    for scene, frames_at in (("textbook-1d", (0, 11, 12, 30)), ("tilted-2d", (0, 12, 30))):
        traj = _run(str(SCENES / f"{scene}.toml"), 1.4)
        gif, html = tmp_path / f"{scene}.gif", tmp_path / f"{scene}.html"
        render_gif(traj, gif, quiet=True, fps=25, size="640x360", t_end=1.4)
        player(traj, fps=25, size="640x360").save(html)
        with Image.open(gif) as im:
            gif_frames = [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(im)]
        o = B.open_player(chromium, html)
        try:
            scene_w = o.page.evaluate("JSON.parse(document.getElementById('player-data')"
                                      ".textContent).picture.layout.scene_w")
            for k in frames_at:
                before = o.shown()
                o.page.evaluate(f"window.dumbbellPlayer.seek({k / 25})")
                if k:
                    o.wait_shown(before)
                shot = tmp_path / f"{scene}-{k}.png"
                o.page.locator("#view").screenshot(path=str(shot))
                page_rgb = np.asarray(Image.open(shot).convert("RGB"))
                factor = page_rgb.shape[1] / 640
                for name in ("A", "B"):
                    rgb = np.array(dumbbell.animation.palette.TERM_RGB[name])
                    want = _centre(gif_frames[k][:, :scene_w], rgb)
                    got = _centre(page_rgb[:, :round(scene_w * factor)], rgb) / factor
                    assert np.hypot(*(got - want)) <= 2.0, (scene, k, name, got, want)
            assert o.console == [] and o.refused == []
        finally:
            o.page.close()


def _centre(rgb: np.ndarray, colour: np.ndarray) -> np.ndarray:
    """The mean (x, y) of the pixels of exactly ``colour``."""
    ys, xs = np.nonzero(np.all(rgb == colour, axis=2))
    assert len(xs), colour
    return np.array([xs.mean(), ys.mean()])


def test_runs_side_by_side_stay_on_one_clock(chromium, tmp_path):
    """Two solvers on one clock: playing, stepping and jumping, each run shows its sample
    nearest the one clock (the same time here: both sampled every 1 ms)."""
    s = dumbbell.load_scene(str(SCENES / "textbook-1d.toml"))
    runs = [_run(s, 1.0, name) for name in ("euler-cromer", "exact")]
    path = tmp_path / "two.html"
    player(runs).save(path)
    o = B.open_player(chromium, path)
    try:
        p = o.page
        assert p.inner_text("#readout-head") .split("\t")[1:] == ["euler-cromer", "exact"] or \
            [c.strip() for c in p.inner_text("#readout-head").split("\n")[1:]] \
            == ["euler-cromer", "exact"]
        for action in ("]", "ArrowRight", "ArrowRight", "Shift+ArrowRight"):
            before = o.shown()
            p.keyboard.press(action)
            o.wait_shown(before)
            table = o.table()
            assert table[(0, "t")] == table[(1, "t")] == o.shown()
        p.click("#play")
        p.wait_for_function("window.dumbbellPlayer.state().t > 0.3")
        p.click("#play")
        p.wait_for_function("!window.dumbbellPlayer.state().playing")
        st = o.state()
        assert abs(st["shown"][0] - st["shown"][1]) <= 0.0005 + 1e-12
        assert abs(st["shown"][0] - st["t"]) <= 0.0005 + 1e-12
        # The bars follow the run chosen; the table shows both.
        p.select_option("#run", "1")
        assert o.state()["run"] == 1
        assert o.console == [] and o.refused == []
    finally:
        p.close()


def test_hostile_titles_and_names_are_shown_as_text(chromium, tmp_path, textbook_run):
    """A title and run labels that are markup, quotes, script closers, line separators and
    very long text: the page shows them as text, runs none of them and asks for nothing."""
    import dataclasses

    evil = ('</script><script>window.__pwned = 1</script><img src=x onerror="window.__pwned'
            '=2"> "quotes" \'single\' & \u2028\u2029 <!-- ' + "long " * 400)
    traj = dataclasses.replace(textbook_run,
                               scene=dataclasses.replace(textbook_run.scene, title=evil))
    path = tmp_path / "evil.html"
    player([traj, traj], labels=[evil[:300], "<b>bold</b>"]).save(path)
    text = path.read_text(encoding="utf-8")
    data = text.split('id="player-data">', 1)[1].split("</script>", 1)[0]
    assert "<" not in data and "\u2028" not in data
    o = B.open_player(chromium, path)
    try:
        assert o.page.evaluate("window.__pwned") is None
        assert o.page.inner_text("#title") == evil.replace("\u2028", "").replace("\u2029", "") \
            or o.page.evaluate("document.getElementById('title').textContent") == evil
        heads = o.page.eval_on_selector_all("#readout th[data-run]", "t => t.map(x => x.textContent)")
        assert heads == [evil[:300], "<b>bold</b>"]
        assert o.page.evaluate("document.querySelectorAll('#player img, #player b').length") == 0
        assert o.console == [] and o.refused == [] and o.requests == [o.url]
    finally:
        o.page.close()


def test_json_in_the_page_cannot_close_its_script():
    s = json_for_script({"a": "</script><!-- \u2028 \u2029 & >"})
    assert "<" not in s and ">" not in s and "&" not in s and "\u2028" not in s
    assert json.loads(s) == {"a": "</script><!-- \u2028 \u2029 & >"}
    out = page({"title": "x"}, '</title><script>alert(1)</script>')
    assert "<title>&lt;/title&gt;&lt;script&gt;" in out


def test_a_notebook_shows_the_player_in_a_frame_of_its_own(textbook_run):
    p = player(textbook_run, t_end=0.5)
    shown = p._repr_html_()
    assert shown.startswith("<iframe srcdoc=\"") and "<script" not in shown
    assert re.search(r"Player: [\d,]+ bytes", repr(p))


# --- a recorded pymunk space --------------------------------------------------------------------


def _space_recording(path, title="", units=("m", "kg", "s"), frames=30):
    """A ball falling onto a floor, a box on a spring: a circle, a polygon, a segment and a
    spring, recorded through ``path`` (its suffix chooses the file)."""
    import pymunk

    from dumbbell import spaces

    space = pymunk.Space()
    space.gravity = (0, -9.8)
    ball = pymunk.Body(1.0, pymunk.moment_for_circle(1.0, 0, 0.1))
    ball.position = (0.8, 0.5)
    box = pymunk.Body(1.0, pymunk.moment_for_box(1.0, (0.2, 0.2)))
    box.position = (-0.6, 0.3)
    space.add(ball, pymunk.Circle(ball, 0.1), box, pymunk.Poly.create_box(box, (0.2, 0.2)),
              pymunk.Segment(space.static_body, (-1, -0.5), (1.5, -0.5), 0.02),
              pymunk.DampedSpring(space.static_body, box, (-0.6, 0.8), (0, 0), 0.3, 50.0, 0.0))
    with spaces.Recorder(space, path, title=title, units=units) as rec:
        for _ in range(frames):
            spaces.step(space, 1 / 25, substeps=20)
            rec.capture()
    return rec


def test_a_recorded_space_plays_with_its_own_values_at_the_gifs_pixels(chromium, tmp_path):
    """Recorder(space, 'x.html'): the page loads offline and clean; at frame k's time the
    table shows the recording's values with the bars' decimals, and the ball is drawn within
    2 px of where the recording's GIF painter draws it in frame k."""
    from dumbbell.animation import recording as R
    from dumbbell.animation.palette import blend
    from dumbbell.animation.pens import BODY_INKS

    path = tmp_path / "space.html"
    rec = _space_recording(path)
    r = rec.recording()
    painter = R.painter_of(r)
    o = B.open_player(chromium, path)
    try:
        assert o.console == [] and o.refused == [] and o.requests == [o.url]
        fill = np.array(blend(BODY_INKS[0], 0.33))
        gif_frames = [np.asarray(painter.frame(k).convert("RGB")) for k in range(r.n)]
        for k in (0, 9, 21):
            before = o.shown()
            o.page.evaluate(f"window.dumbbellPlayer.seek({r.t[k]})")
            if k:
                o.wait_shown(before)
            table = o.table()
            for name in r.energy:
                assert table[(0, name)] == painter.bars.scale.text(float(r.energy[name][k])), (k, name)
            shot = tmp_path / f"space-{k}.png"
            o.page.locator("#view").screenshot(path=str(shot))
            page_rgb = np.asarray(Image.open(shot).convert("RGB"))
            factor = page_rgb.shape[1] / r.size[0]
            want = _centre(gif_frames[k][:, :painter.scene_w], fill)
            got = _centre(page_rgb[:, :round(painter.scene_w * factor)], fill) / factor
            assert np.hypot(*(got - want)) <= 2.0, (k, got, want)
        assert o.console == []
        # A space has no impacts to jump to: both impact buttons are disabled and say so.
        assert o.page.evaluate("['prev-impact', 'next-impact'].map(i => [document."
                               "getElementById(i).disabled, document.getElementById(i)."
                               "title])") == [[True, "No impacts in this run"]] * 2
    finally:
        o.page.close()


def test_a_hostile_title_or_unit_of_a_recording_is_text(chromium, tmp_path):
    evil = '</script><img src=x onerror="window.__pwned=1">"\'&\u2028' + "very long " * 300
    path = tmp_path / "evil-space.html"
    _space_recording(path, title=evil, units=("<i>m</i>", "kg", "s"), frames=5)
    o = B.open_player(chromium, path)
    try:
        assert o.page.evaluate("window.__pwned") is None
        assert o.page.evaluate("document.getElementById('title').textContent") == evil
        heads = o.page.eval_on_selector_all("#readout tbody th", "t => t.map(x => x.textContent)")
        assert any("<i>m</i>" in h for h in heads)
        assert o.page.evaluate("document.querySelectorAll('#player img, #player i').length") == 0
        assert o.console == [] and o.refused == [] and o.requests == [o.url]
    finally:
        o.page.close()


# --- the command and the data, without a browser ------------------------------------------------


def test_play_writes_one_page_and_refuses_bad_input_in_one_line(tmp_path, capsys):
    from dumbbell.cli import main

    scene = str(SCENES / "textbook-1d.toml")
    out = tmp_path / "tb.html"
    assert main(["play", scene, "--t-end", "0.5", "-o", str(out), "-q"]) == 0
    text = out.read_text(encoding="utf-8")
    assert text.startswith("<!DOCTYPE html>") and 'name="generator" content="dumbbell player"' in text
    assert "http://" not in text.split("<script>")[1] and "https://" not in text
    two = tmp_path / "two.html"
    assert main(["play", scene, "--t-end", "0.3", "--solvers", "euler-cromer", "exact",
                 "-o", str(two), "-q"]) == 0
    assert two.read_text(encoding="utf-8").count('"label":') == 2
    capsys.readouterr()
    for argv in (["-o", str(tmp_path / "x.gif")], ["--solvers", "nope", "-o", str(out)],
                 ["--solvers", "exact", "exact", "-o", str(out)], ["--fps", "0"]):
        try:
            status = main(["play", scene, "--t-end", "0.2", "-q", *argv])
        except SystemExit as exc:  # argparse's own refusals
            status = exc.code
        assert status == 2, argv
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1, (argv, err)
    assert not (tmp_path / "x.gif").exists()


def test_a_long_run_is_thinned_keeping_the_frames_times(textbook_run):
    from dumbbell.animation.player import run_of

    run = run_of(textbook_run, ["E"], 2.0, "x", max_samples=300, fps=25)
    assert len(run.t) <= 300
    frame_times = np.arange(50) / 25
    assert np.all(np.min(np.abs(run.t[:, None] - frame_times[None, :]), axis=0) < 1e-9)
    kept = np.searchsorted(textbook_run.t, run.t)
    assert np.array_equal(run.energy["E"], textbook_run["E"][kept])   # the run's own values
