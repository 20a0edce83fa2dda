"""The report read in a real browser: Debian's headless Chromium, driven
through chromedriver by selenium (tests/requirements.txt), on pages opened
from file:// with the network closed. A passing campaign, a failing one
(a name made of HTML among its cases) and a long trace: no console error,
the summary's numbers, the filter, the failing signal's plot framed on
its first deviation, a long trace's finer level loaded as the reader
zooms in, and no horizontal scrolling at 1366 x 768 (screenshots into
$FMUTRACE_SHOTS when set, to look at).

The FMU is the PassThrough fixture: y(t + h) = u(t), y = 0 before the
first step; the first deviations are where the references are made to
differ."""

import os
import shutil
import struct
import time
from pathlib import Path

import numpy as np
import pytest

from fmutrace import RunOptions, compare
from support.fmu_driver import BUILD_DIR

PASS_THROUGH = BUILD_DIR / "benchmarks" / "fmi2" / "PassThrough.fmu"
PASS_THROUGH_3 = BUILD_DIR / "benchmarks" / "fmi3" / "PassThrough.fmu"
CHROMIUM, CHROMEDRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"  # Debian's (cmake/TestTools.cmake)
OPT = "StartTime,0\nStopTime,0.5\nStepSize,0.1\nRelTol,1e-6\n"
INPUT = "time,u\n0,1\n0.2,3\n"
REF = "time,y\n0,0\n0.1,1\n0.2,1\n0.3,3\n0.4,3\n0.5,3\n"
# 50 s of it: y = 3 from t = 0.3 on; the reference's t = 30 made to differ
LONGER_OPT = OPT.replace("StopTime,0.5", "StopTime,50")
LONGER_REF = REF + "".join(f"{k / 10:g},{2 if k == 300 else 3}\n" for k in range(6, 501))
HOSTILE = "<img src=x onerror=window.hurt=1> & <b>bold</b>"
RED = "rgba(187, 0, 0, 1)"  # report.css's #b00: a status that is not a pass


def write_case(folder, ref=REF, inputs=INPUT, opt=OPT):
    folder.mkdir(parents=True)
    (folder / "PassThrough_ref.csv").write_text(ref)
    (folder / "PassThrough_in.csv").write_text(inputs)
    (folder / "PassThrough_ref.opt").write_text(opt)


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    for program in (CHROMIUM, CHROMEDRIVER):
        assert os.access(program, os.X_OK), f"{program} is needed (Debian: apt-get install chromium chromium-driver)"
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for argument in (
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--hide-scrollbars",
        f"--user-data-dir={tmp_path_factory.mktemp('chromium')}",
        "--window-size=1366,768",
    ):
        options.add_argument(argument)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(options=options, service=Service(CHROMEDRIVER))
    driver.set_window_size(1366, 768)
    yield driver
    driver.quit()


def open_page(browser, path):
    """The page at path opened, its console's messages so far read (and cleared)."""
    browser.get(Path(path).as_uri())
    browser.get_log("browser")  # (earlier pages' messages)
    browser.get(Path(path).as_uri())
    return browser


def console_errors(browser):
    return [entry for entry in browser.get_log("browser") if entry["level"] == "SEVERE"]


def no_horizontal_scrolling(browser, shot):
    """The page fits 1366 x 768's width; its screenshot (into $FMUTRACE_SHOTS if set) 1366 pixels wide."""
    width = browser.execute_script("return [document.documentElement.scrollWidth, window.innerWidth]")
    assert width[0] <= width[1], width
    png = browser.get_screenshot_as_png()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and struct.unpack(">I", png[16:20])[0] == width[1]
    if os.environ.get("FMUTRACE_SHOTS"):
        Path(os.environ["FMUTRACE_SHOTS"], shot).write_bytes(png)


def number(browser, status):
    return int(browser.find_element("id", f"count-{status}").text)


def visible_rows(browser):
    rows = browser.find_elements("css selector", "#cases tbody tr")
    return [r.get_attribute("data-status") for r in rows if r.is_displayed()]


def wait_for(browser, script, seconds=10):
    """The value of script once true (a page's scripts run after its load)."""
    deadline = time.monotonic() + seconds
    while not (value := browser.execute_script(script)):
        assert time.monotonic() < deadline, f"never true: {script}"
        time.sleep(0.05)
    return value


def cases_shown(browser):
    rows = browser.find_elements("css selector", "#cases tbody tr")
    return [(r.find_element("tag name", "a").text, r.get_attribute("data-fmu")) for r in rows if r.is_displayed()]


def test_a_passing_campaign(browser, tmp_path):
    """Three cases on the FMI 2 and FMI 3 PassThrough: counted per FMU and
    per model, filtered by FMU, sorted by name."""
    for name in ("one", "two", "three"):
        write_case(tmp_path / "cases" / name)
    fmus = [PASS_THROUGH, PASS_THROUGH_3]
    campaign = compare(fmus, [tmp_path / "cases"], report=tmp_path / "report", run=RunOptions(jobs=1))
    assert campaign.passed
    open_page(browser, tmp_path / "report" / "index.html")
    assert (number(browser, "total"), number(browser, "pass"), number(browser, "fail")) == (6, 6, 0)
    verdict = browser.find_element("id", "verdict")
    assert verdict.get_attribute("data-verdict") == "pass" and verdict.text.startswith("PASS 6 of 6 cases pass")
    for status in ("fail", "error", "invalid"):  # none: not an alarm
        count = browser.find_element("id", f"count-{status}")
        assert count.value_of_css_property("color") != RED and int(count.value_of_css_property("font-weight")) < 700
    summary = (tmp_path / "report" / "summary.md").read_text()
    assert summary.startswith("# fmutrace: PASS\n") and "| case | FMU | result | seconds |\n" in summary  # no plot
    per_fmu, per_model = (t.text.splitlines() for t in browser.find_elements("css selector", "table.counts"))
    assert per_fmu[2:] == ["PassThrough (FMI 2) 3 0 0 0", "PassThrough (FMI 3) 3 0 0 0"], per_fmu
    assert per_model[2:] == ["PassThrough 6 0 0 0"], per_model
    assert visible_rows(browser) == ["pass"] * 6
    no_horizontal_scrolling(browser, "passing_index.png")
    browser.find_element("css selector", "#f-fmu option:nth-child(3)").click()
    assert cases_shown(browser) == [(name, "PassThrough (FMI 3)") for name in ("one", "three", "two")]
    browser.find_element("xpath", "//th[text()='case']").click()  # ascending, then descending
    browser.find_element("xpath", "//th[text()='case']").click()
    assert cases_shown(browser) == [(name, "PassThrough (FMI 3)") for name in ("two", "three", "one")]
    assert console_errors(browser) == []
    browser.find_element("link text", "two").click()
    wait_for(browser, "return document.getElementById('plots').dataset.xmax")
    assert len(browser.execute_script("return window.fmutraceCharts")) == 2  # inputs, y; y's deviation said:
    assert browser.find_element("css selector", ".deviation-none").text == (
        "y: deviation\nnone: result - ref is 0 at every compared sample"
    )
    assert console_errors(browser) == []


def test_a_failing_campaign(browser, tmp_path):
    """Of four cases one differs (y at t = 30 of 50 s is 2, not 3): it
    comes first, the filter on 'not pass' hides the passes, and its page
    opens with y's plot framed on t = 30 (the 40 samples each side that
    the zoom keeps). A name of HTML is shown as text."""
    for name in ("a", "b", HOSTILE):
        write_case(tmp_path / "cases" / name)
    write_case(tmp_path / "cases" / "differs", ref=LONGER_REF, opt=LONGER_OPT)
    campaign = compare([PASS_THROUGH], [tmp_path / "cases"], report=tmp_path / "report", run=RunOptions(jobs=1))
    assert campaign.counts()["fail"] == 1
    open_page(browser, tmp_path / "report" / "index.html")
    assert (number(browser, "total"), number(browser, "pass"), number(browser, "fail")) == (4, 3, 1)
    verdict = browser.find_element("id", "verdict")
    assert verdict.get_attribute("data-verdict") == "fail" and verdict.text.startswith("FAIL ")
    count = browser.find_element("id", "count-fail")
    assert count.value_of_css_property("color") == RED and int(count.value_of_css_property("font-weight")) >= 700
    summary = (tmp_path / "report" / "summary.md").read_text()
    rows = [line for line in summary.splitlines() if line.startswith("| ") and "PassThrough" in line]
    assert summary.startswith("# fmutrace: FAIL\n") and rows[0].startswith("| differs |"), summary  # failures first
    assert all(row.count(" | ") == 3 for row in rows), rows  # case, FMU, result, seconds: no empty plot column
    assert visible_rows(browser) == ["fail", "pass", "pass", "pass"]
    assert HOSTILE in browser.find_element("id", "cases").text  # as text, not markup
    assert browser.execute_script("return document.images.length === 0 && window.hurt === undefined")
    no_horizontal_scrolling(browser, "failing_index.png")
    browser.find_element("css selector", "#f-status option[value='!pass']").click()
    assert visible_rows(browser) == ["fail"]
    browser.find_element("css selector", "#f-status option[value='']").click()
    browser.find_element("id", "f-text").send_keys("<b>")
    assert visible_rows(browser) == ["pass"]
    assert console_errors(browser) == []

    open_page(browser, tmp_path / "report" / "index.html")  # (the filter as it was)
    browser.find_element("link text", "differs").click()
    low, high = (
        float(v)
        for v in wait_for(
            browser, "var d = document.getElementById('plots').dataset; return d.xmax && [d.xmin, d.xmax]"
        )
    )
    assert 25 < low <= 30 <= high < 35, (low, high)
    assert "y differs first at t=30.0" in browser.find_element("tag name", "body").text
    no_horizontal_scrolling(browser, "failing_case.png")
    assert console_errors(browser) == []

    open_page(browser, tmp_path / "report" / "index.html")
    browser.find_element("link text", HOSTILE).click()  # (its page's file name: the name made safe)
    wait_for(browser, "return document.getElementById('plots').dataset.xmax")
    assert HOSTILE in browser.find_element("tag name", "h1").text
    assert browser.execute_script("return document.images.length === 0 && window.hurt === undefined")
    assert console_errors(browser) == []


@pytest.mark.slow
def test_a_long_trace_opens_framed_and_refines_as_it_is_zoomed(browser, tmp_path):
    """A trace of 360,001 steps of 10 ms (an hour) whose reference is off
    by one at t = 2500 s: its page's data stays small (the overview under
    a megabyte), opens framed on t = 2500 within seconds, and zooming
    out of the frame and in elsewhere loads the finer level there."""
    n = 360_000
    t = np.arange(n + 1) / 100.0
    u = np.round(50 * np.sin(t / 100.0) + 2 * np.sin(3.1 * t), 6)
    y = np.concatenate(([0.0], u[:-1]))
    y[250_000] += 1.0
    folder = tmp_path / "cases" / "hour"
    folder.mkdir(parents=True)
    np.savetxt(folder / "PassThrough_in.csv", np.column_stack([t, u]), delimiter=",", header="time,u", comments="")
    np.savetxt(folder / "PassThrough_ref.csv", np.column_stack([t, y]), delimiter=",", header="time,y", comments="")
    (folder / "PassThrough_ref.opt").write_text(f"StartTime,0\nStopTime,{n / 100}\nStepSize,0.01\nRelTol,1e-6\n")
    campaign = compare([PASS_THROUGH], [tmp_path / "cases"], report=tmp_path / "report", run=RunOptions(jobs=1))
    [outcome] = campaign.cases
    assert outcome.status == "fail" and "first at t=2500.0" in outcome.messages[0], outcome.messages
    data = tmp_path / "report" / outcome.plot_data
    assert data.stat().st_size < 1 << 20
    shutil.rmtree(tmp_path / "cases")  # (the page needs none of them)

    started = time.monotonic()
    open_page(browser, data.with_name("hour.html"))
    low, high = (
        float(v)
        for v in wait_for(
            browser, "var d = document.getElementById('plots').dataset; return d.xmax && [d.xmin, d.xmax]"
        )
    )
    assert time.monotonic() - started < 10
    assert low <= 2500 <= high and high - low < 10, (low, high)
    reference_framed = browser.execute_script(
        "var u = window.fmutraceCharts[1], n = 0;"  # (0: the inputs; 1: y; series 1: its reference)
        "for (var i = 0; i < u.data[0].length; i++) { if (u.data[0][i] >= arguments[0] && u.data[0][i] <= arguments[1]"
        " && u.data[1][i] !== null) { n++; } } return n",
        low,
        high,
    )
    assert reference_framed >= 81, reference_framed  # the 40 compared samples each side at full resolution
    no_horizontal_scrolling(browser, "long_case.png")
    before = browser.execute_script("return window.fmutraceCharts[1].data[0].length")
    browser.execute_script("window.fmutraceCharts[0].setScale('x', {min: 1000, max: 1100})")
    wait_for(browser, "return document.getElementById('plots').dataset.tilesLoaded")
    in_view = browser.execute_script(
        "return window.fmutraceCharts[1].data[0].filter(function (t) { return t >= 1000 && t <= 1100; }).length"
    )
    assert browser.execute_script("return window.fmutraceCharts[1].data[0].length") > before
    assert in_view > 100, in_view  # the overview has about 4 points per 6 s column there: 60 or so
    no_horizontal_scrolling(browser, "long_case_zoomed.png")
    assert console_errors(browser) == []


# each curve of y's plot (series 1: the reference, 2: the result) as uPlot drew it (its path in canvas pixels),
# stroked alone in black on a canvas of the plot's size: its pixels
CURVE_PIXELS = """
var u = window.fmutraceCharts[1], k = arguments[0], canvas = document.createElement("canvas");
canvas.width = u.ctx.canvas.width;
canvas.height = u.ctx.canvas.height;
var ctx = canvas.getContext("2d");
ctx.lineWidth = u.series[k].width * uPlot.pxRatio;
ctx.strokeStyle = "#000";
ctx.stroke(u.series[k]._paths.stroke);
return Array.from(ctx.getImageData(0, 0, canvas.width, canvas.height).data.filter((_, i) => i % 4 === 3));
"""


def legend_values(browser, chart):
    return browser.execute_script(
        "return Array.from(window.fmutraceCharts[arguments[0]].root.querySelectorAll('.u-value'))"
        ".map(function (v) { return v.textContent; })",
        chart,
    )


def test_a_bit_for_bit_pass_draws_reference_and_result_as_one_curve(browser, tmp_path):
    """Reference and result are the same samples: both drawn as values held
    until the next sample, their curves' pixels are the same; the legend
    shows values before the cursor is over the plot; the deviation, 0
    throughout, is said, not drawn on an axis without a scale."""
    write_case(tmp_path / "cases" / "same")
    campaign = compare([PASS_THROUGH], [tmp_path / "cases"], report=tmp_path / "report", run=RunOptions(jobs=1))
    assert campaign.passed
    open_page(browser, tmp_path / "report" / "index.html")
    browser.find_element("link text", "same").click()
    wait_for(browser, "return document.getElementById('plots').dataset.xmax")
    reference, result = (np.array(browser.execute_script(CURVE_PIXELS, k)) for k in (1, 2))
    assert (reference > 0).sum() > 500  # (a curve across the plot)
    assert np.array_equal(reference, result)
    values = legend_values(browser, 1)  # t, y reference, y result
    assert len(values) == 3 and "--" not in values and values[1] == values[2], values
    assert browser.find_elements("css selector", ".deviation-none")
    no_horizontal_scrolling(browser, "passing_case.png")
    assert console_errors(browser) == []


def test_a_failing_deviation_plot_has_a_labelled_scale(browser, tmp_path):
    """y is 3 from t = 0.3 on; the reference says 3.000001 at t = 0.4: the
    deviation of -1e-6 there has ticks that tell its size (not '0' alone)
    and its axis says what it is; the legend shows the values at the first
    deviation."""
    write_case(tmp_path / "cases" / "off", ref=REF.replace("0.4,3\n", "0.4,3.000001\n"))
    campaign = compare([PASS_THROUGH], [tmp_path / "cases"], report=tmp_path / "report", run=RunOptions(jobs=1))
    assert campaign.counts()["fail"] == 1
    open_page(browser, tmp_path / "report" / "index.html")
    browser.find_element("link text", "off").click()
    wait_for(browser, "return document.getElementById('plots').dataset.xmax")
    label, ticks = browser.execute_script(
        "var a = window.fmutraceCharts[2].axes[1]; return [a.label, a._values]"  # (2: y's deviation)
    )
    assert label == "result - ref"
    numbers = [float(t) for t in ticks if t]
    assert len(set(numbers)) >= 2 and any(abs(v) >= 1e-7 for v in numbers), ticks
    assert all(abs(v) <= 1e-5 for v in numbers), ticks  # (the scale of the deviation, not 0 to 100)
    values = legend_values(browser, 1)
    assert values[1:] == ["3.000001", "3"], values  # (at t = 0.4)
    no_horizontal_scrolling(browser, "failing_deviation.png")
    assert console_errors(browser) == []
