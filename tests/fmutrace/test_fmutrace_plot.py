"""A report's figure drawn on a reused layout (fmutrace._plot keeps one
figure per layout in a process and only clears and refills it) is the
picture a freshly built figure gives, pixel for pixel: cases of each
layout drawn one after the other in the same process, a layout reused by
a case with other lines, limits, band, zoom and texts than the case before."""

import io

import numpy as np
import pytest
from matplotlib.image import imread

from fmutrace import Exact, Tolerance
from fmutrace import _plot as plot
from fmutrace._comparison import comparison_mode

TUBE = comparison_mode(tube_time=0.02, tube_value=0.01)


def ramp_case(title, signals=1, inputs=True, zoom=False, band=False, steps=200, scale=1.0, deviations=True):
    """A Figure of a ramp towards a step of its input, per signal its
    result off the reference by a deviation that grows with the signal's
    number (lines of their own values, not a fixed picture)."""
    t = np.arange(steps) * 0.01
    u = np.where(t < 0.5, 0.0, scale)
    reference = np.minimum(np.maximum(t - 0.5, 0.0) * 2.0, 1.0) * scale
    case_inputs = [("u", t, u)] if inputs else []
    shown, devs, zoomed = [], [], []
    for k in range(signals):
        name = f"y{k}"
        offset = (k + 1) * 1e-3 * scale
        result = reference + np.where(t > 0.8, offset, 0.0)
        shown.append(
            (
                name,
                (t, reference + k),
                (t, result + k),
                (t, reference + k - 0.05, reference + k + 0.05) if band else None,
            )
        )
        devs.append((name, t, result - reference))
        window = slice(60, 101)
        zoomed.append(
            (
                name,
                t[window],
                result[window],
                reference[window] - 1e-4,
                reference[window] + 1e-4,
                (result - reference)[window],
            )
        )
    return plot.Figure(title, case_inputs, shown, devs if deviations else [], (float(t[81]), zoomed) if zoom else None)


CASES = [
    ("passing, one signal", ramp_case("ramp on FMI 2.0"), Exact()),
    ("another passing case of the same layout", ramp_case("ramp x10 on FMI 2.0", scale=10.0, steps=120), Exact()),
    ("failing with its zoom", ramp_case("failing ramp on FMI 3.0", zoom=True), Exact()),
    (
        "three panels, failing with its zoom",
        ramp_case("three outputs on FMI 3.0", signals=3, zoom=True),
        Tolerance(rel_tol=1e-9),
    ),
    ("another failing case with its zoom", ramp_case("failing ramp x5", zoom=True, scale=5.0, steps=140), Exact()),
    ("three panels, band drawn, zoom", ramp_case("tube, failing", signals=3, band=True, zoom=True), TUBE),
    ("three panels, band drawn", ramp_case("tube on FMI 2.0", signals=3, band=True, scale=-2.0), TUBE),
    ("no input, zoom", ramp_case("no input", inputs=False, zoom=True, steps=150), Exact()),
    ("no input, one signal", ramp_case("no input again", inputs=False, scale=3.0), Exact()),
    (
        "no input, no deviation to draw (an empty axis)",
        ramp_case("nothing compared", inputs=False, deviations=False),
        Exact(),
    ),
    ("the first case again", ramp_case("ramp on FMI 2.0"), Exact()),
]


def pixels(png: bytes):
    return imread(io.BytesIO(png), format="png")


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:No artists with labels found")
def test_a_reused_layout_draws_what_a_new_figure_draws():
    plot._layouts().clear()
    reused_layouts = 0
    for what, figure, mode in CASES:
        layouts_before = len(plot._layouts())
        reused = pixels(plot.draw(figure, mode, "rl"))
        reused_layouts += len(plot._layouts()) == layouts_before
        fresh = pixels(plot.draw(figure, mode, "rl", reuse=False))
        assert reused.shape == fresh.shape, what
        different = np.argwhere((reused != fresh).any(axis=-1))
        assert not len(different), f"{what}: {len(different)} pixels differ, the first at (row, column) {different[0]}"
    # the cases above reuse a layout drawn before by another case five times
    assert reused_layouts == 5


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:No artists with labels found")
def test_the_cases_above_are_different_pictures():
    """The comparison above could fail: each case draws its own picture,
    so a layout that kept the case before's lines or limits would differ."""
    plot._layouts().clear()
    images = [plot.draw(figure, mode, "rl") for _, figure, mode in CASES[:-1]]
    assert len(set(images)) == len(images)
    assert plot.draw(CASES[-1][1], CASES[-1][2], "rl") == images[0]
