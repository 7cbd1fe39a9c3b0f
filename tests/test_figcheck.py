"""The figure checker (tests/figcheck.py) finds what it is meant to find: figures built to
collide give findings of the right kind, and the same figures laid out apart give none."""

from __future__ import annotations

import numpy as np
import pytest

from tests.figcheck import findings, missing_units, outside_axes

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


def test_a_legend_beside_each_axes_of_a_row_squeezes_it():
    """Issue 29: kinetic beside potential on a 1x2 grid, each legend outside its axes on the
    right: laid out, each plot keeps about a third of its width. Nothing overlaps, nothing is
    cut: only the share of the box the data keep tells."""
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.5))
    t = np.linspace(0, 2, 100)
    for ax in axes:
        for name in ("K_cm, centre of mass", "K_int, relative to the centre of mass"):
            ax.plot(t, np.sin(3 * t), label=name)
        ax.set(xlabel="t [s]", ylabel="E [J]")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    fig.tight_layout()
    found = findings(fig)
    assert {f.kind for f in found} == {"squeezed"} and len(found) == 2
    assert all("of its box's width" in f.first for f in found)
    for ax in axes:
        ax.get_legend().remove()
        ax.legend(loc="upper left", fontsize=8)
    ax.set_ylim(-1, 3)
    axes[0].set_ylim(-1, 3)
    fig.tight_layout()
    assert findings(fig) == []


def test_a_short_axes_under_a_tall_title_is_squeezed_too():
    fig, ax = plt.subplots(figsize=(6, 3))
    ax.plot([0, 1], [0, 1])
    ax.set_title("\n".join(["a title of many lines"] * 9), fontsize=8)
    ax.set(xlabel="t [s]", ylabel="x [m]")
    fig.tight_layout()
    assert [f.kind for f in findings(fig)] == ["squeezed"]
    assert "height" in findings(fig)[0].first


def test_data_other_than_lines_under_text():
    """A filled area, bars, a colour mesh and scatter markers are data as much as a curve:
    a text or a legend on them is found; a span marking a stretch of the axis is not data."""
    fig, ax = plt.subplots(figsize=(6, 3.5))
    x = np.linspace(0, 1, 50)
    ax.fill_between(x, 0, 0.8, alpha=0.3, label="filled")
    ax.set(xlim=(0, 1), ylim=(0, 1), xlabel="t [s]", ylabel="E [J]")
    ax.text(0.5, 0.5, "on the fill", ha="center")
    fig.tight_layout()
    found = findings(fig)
    assert [f.kind for f in found] == ["data/text"] and "FillBetween" in found[0].first
    ax.texts[0].set_position((0.5, 0.9))          # above the fill
    assert findings(fig) == []
    ax.axvspan(0.4, 0.6, color="0.9", zorder=0)  # a marked stretch under the text: fine
    assert findings(fig) == []
    ax.bar([0.5], [0.95], width=0.2)
    assert [f.kind for f in findings(fig)] == ["data/text"]
    ax.patches[-1].remove()
    ax.scatter([0.5], [0.91], s=30)
    assert [f.kind for f in findings(fig)] == ["data/text"]


def test_a_legend_on_a_colour_map():
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.pcolormesh(np.arange(6), np.arange(5), np.random.default_rng(1).random((4, 5)))
    ax.plot([], [], "r--", label="w*dt = 2")
    ax.set(xlabel="k [N/m]", ylabel="dt [s]")
    ax.legend(loc="upper right")
    found = findings(fig)
    assert [f.kind for f in found] == ["data/legend"] and "QuadMesh" in found[0].first
    ax.set_ylim(0, 6)                             # a band above the map
    assert findings(fig) == []


def test_what_a_figure_on_the_users_axes_puts_outside_them():
    _, (a, b) = plt.subplots(1, 2, figsize=(8, 3))
    for ax in (a, b):
        ax.plot([0, 1], [0, 1], label="a line")
        ax.set(xlabel="t [s]", ylabel="x [m]", ylim=(0, 2))
    a.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0))
    a.set_title("a title much wider than the axes it stands on, into its neighbour's")
    a.annotate("a note", xy=(0.5, 1.02), xycoords="axes fraction")
    kinds = [(f.kind, f.first.split(": ")[-1][:6]) for f in outside_axes(a)]
    assert kinds == [("outside its axes", "legend"), ("outside its axes", "text '"),
                     ("outside its axes", "text '")]
    assert outside_axes(b) == []
    b.legend(loc="upper left")
    assert outside_axes(b) == []


def test_the_one_solver_stability_map_as_it_was():
    """Issue 29: ``dumbbell stability --solvers euler-cromer`` drew one panel on 5.8 x 4.6 in
    with the margins set by hand for any number of panels (left 5.5 %): the y tick labels
    lost their first digit (10^4 read "0^4") and the figure's title ran off both ends. The
    checker finds each (the suite drew the map with two solvers only, where those margins
    happen to hold)."""
    fig, axes = plt.subplots(1, 1, figsize=(5.8, 4.6), squeeze=False)
    ax = axes[0, 0]
    ax.pcolormesh([0, 1, 2], [0.5, 20, 2e4], [[1, 2], [3, 4]])
    ax.set_yscale("log")
    ax.set(xlabel="w*dt [1]", ylabel="mass ratio mB/mA [1]")
    fig.subplots_adjust(left=0.055, right=0.9, bottom=0.25, top=0.86)
    fig.suptitle("Stability of the explicit spring step: 2000 steps per run, no floor, no "
                 "gravity; 'unstable' = non-finite or energy error > 1000", fontsize=10)
    cut = [f.first for f in findings(fig) if f.kind == "cut off"]
    assert any("figure text 'Stability" in c for c in cut)
    assert any("y tick '$\\\\mathdefault{10^{4}}$'" in c for c in cut), cut
    assert any("y label" in c for c in cut)
