"""The figure checker (tests/figcheck.py) finds what it is meant to find: figures built to
collide give findings of the right kind, and the same figures laid out apart give none."""

from __future__ import annotations

import numpy as np
import pytest

from tests.figcheck import findings, missing_units

plt = pytest.importorskip("matplotlib.pyplot")


@pytest.fixture(autouse=True)
def close_all():
    yield
    plt.close("all")


def kinds(fig) -> list[str]:
    return sorted({f.kind for f in findings(fig)})


def test_a_clean_figure_has_no_findings():
    fig, ax = plt.subplots(figsize=(6, 3.5))
    t = np.linspace(0, 2, 200)
    ax.plot(t, np.sin(3 * t), label="sin 3t")
    ax.set_ylim(-1.2, 2.2)
    ax.legend(loc="upper right")
    ax.text(0.05, 1.8, "a note above the curve")
    ax.set(xlabel="t [s]", ylabel="y [m]", title="clean")
    fig.tight_layout()
    assert findings(fig) == [] and missing_units(fig) == []


def test_text_on_text():
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.text(0.5, 0.5, "first impact, t = 0.4518 s", transform=ax.transAxes)
    ax.text(0.52, 0.51, "second note", transform=ax.transAxes)
    assert kinds(fig) == ["text/text"]


def test_tick_labels_that_touch_read_as_one_number():
    """The inset of the 2D energy figure: '-0.25' and '0.00' 1 px apart read '-0.250.00'."""
    fig = plt.figure(figsize=(10, 8.6))
    ax = fig.add_axes((0.75, 0.6, 0.1, 0.3))
    ax.set_xlim(-0.4, 0.45)
    ax.set_xticks([-0.25, 0.0, 0.25])
    ax.set_xlabel("x [m]")
    found = findings(fig)
    assert found and {f.kind for f in found} == {"text/text"}
    assert all("x tick" in f.first and "x tick" in f.second for f in found)
    ax.set_xticks([-0.25, 0.25])
    assert findings(fig) == []


def test_text_under_a_legend():
    """Notebook cell 18 of the textbook notebook: the first-impact note under the legend."""
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot([0, 1], [0, 0.2], label="a line with a long legend entry")
    ax.set_ylim(0, 1)
    ax.legend(loc="upper left")
    ax.annotate("first impact", xy=(0.02, 0.93), xycoords="axes fraction")
    assert kinds(fig) == ["text/legend"]


def test_legends_on_each_other():
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot([0, 1], [0, 0.1], label="one")
    ax.legend(loc="upper right")
    fig.legend(["two"], loc="upper right", bbox_to_anchor=(0.9, 0.88))
    assert "text/legend" in kinds(fig)


def test_a_line_through_text_and_through_a_legend():
    fig, ax = plt.subplots(figsize=(6, 3.5))
    t = np.linspace(0, 1, 50)
    ax.plot(t, 0.5 + 0 * t, label="flat line")
    ax.text(0.5, 0.5, "a label on the line", ha="center", va="center")
    ax.set_ylim(0, 1)
    assert kinds(fig) == ["line/text"]
    ax.texts[0].remove()
    ax.legend(loc="center")
    assert kinds(fig) == ["line/legend"]
    ax.get_legend().set_loc("upper right")
    assert findings(fig) == []


def test_markers_count_even_without_a_line_and_lines_are_clipped_to_their_axes():
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot([0.5], [0.5], "o", ms=12)
    ax.text(0.5, 0.5, "x", ha="center", va="center")
    ax.set(xlim=(0, 1), ylim=(0, 1))
    assert kinds(fig) == ["line/text"]
    ax.texts[0].remove()
    # Outside the view limits the line is clipped: under the axis label it does not count.
    ax.plot([-1, 2], [-0.1, -0.1])
    ax.set_xlabel("x [m]")
    fig.tight_layout()
    assert findings(fig) == []


def test_lines_of_a_twin_axis_and_gaps_in_a_line():
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot([0, 1], [0, 1], label="left")
    ax.set(xlim=(0, 1), ylim=(0, 1))
    ax.legend(loc="upper left")
    right = ax.twinx()
    right.plot([0, 1], [0.9, 0.9], label="right axis")
    right.set_ylim(0, 1)
    assert [f.kind for f in findings(fig)] == ["line/legend"]
    right.lines[0].set_ydata([np.nan, np.nan])     # nothing left to draw
    # A gap where the legend is: the pieces on either side are not joined across it.
    right.plot([-0.5, -0.1, np.nan, 0.4, 1.0], [0.93] * 5)
    assert findings(fig) == []
    right.plot([-0.5, -0.1, 0.4, 1.0], [0.93] * 4)
    assert [f.kind for f in findings(fig)] == ["line/legend"]


def test_text_cut_off_at_the_edge():
    fig, _ = plt.subplots(figsize=(6, 3.5))
    fig.text(0.95, 0.5, "this runs off the page")
    assert kinds(fig) == ["cut off"]


def test_a_text_box_counts_whole():
    """A note drawn in a box covers its box, not only its letters."""
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot([0, 1], [0.62, 0.62])
    ax.set(xlim=(0, 1), ylim=(0, 1))
    ax.text(0.5, 0.5, "note", bbox={"boxstyle": "round,pad=2", "fc": "white"})
    assert kinds(fig) == ["line/text"]


def test_axes_without_units_are_named():
    fig, (a, b) = plt.subplots(1, 2, figsize=(8, 3))
    a.plot([0, 1], [0, 1])
    a.set(xlabel="t [s]", ylabel="E(t) / E(0) - 1")
    b.plot([0, 1], [0, 1])
    b.set(xlabel="time (s)", ylabel="ratio [1]")
    missing = missing_units(fig)
    assert len(missing) == 2
    assert "y axis 'E(t) / E(0) - 1'" in missing[0] and "x axis 'time (s)'" in missing[1]


def test_an_annotation_arrow_may_reach_the_data_but_its_words_may_not():
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot([0, 1], [0, 1])
    ax.set(xlim=(0, 1), ylim=(0, 1), xlabel="t [s]", ylabel="x [m]")
    ax.annotate("the end", xy=(1, 1), xytext=(0.1, 0.8), arrowprops={"arrowstyle": "->"})
    fig.tight_layout()
    assert findings(fig) == []
    ax.annotate("on the line", xy=(0.5, 0.5), ha="center", va="center")
    assert kinds(fig) == ["line/text"]


def test_problems_lists_findings_and_missing_units_as_lines():
    from tests.figcheck import problems

    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot([0, 1], [0.5, 0.5])
    ax.text(0.5, 0.5, "on it", ha="center", va="center")
    found = problems(fig)
    assert len(found) == 3 and found[0].startswith("line/text")
    assert all("has no [unit]" in line for line in found[1:])
