#!/usr/bin/env python3
"""Write the documentation and the icon that go inside an FMU, from the
model's TOML file (the variables) and the staged FMU itself (a typical ramp,
simulated with fmpy):

    document.py MODEL.toml STAGED_FMU_DIR FMI_VERSION STATUS_SOURCE.c PLOT_STAGED_FMU_DIR

writes documentation/index.html and documentation/ramp.png, and the icon:
model.png (FMI 2) or terminalsAndIcons/icon.png (FMI 3). Runs with the
project's venv (fmpy, matplotlib); PNGs carry no time stamps.
"""

import contextlib
import html
import io
import math
import re
import sys
import textwrap
import tomllib
from pathlib import Path
from xml.etree import ElementTree

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from fmpy import simulate_fmu  # noqa: E402

PNG_METADATA = {"Software": None}


def status_codes(source):
    """(code, meaning) from the kernel's rl_status_text, the one place they
    are written."""
    text = Path(source).read_text()
    names = dict(re.findall(r"(RL_STATUS_\w+)\s*=\s*(0x[0-9A-Fa-f]+)", Path(source).with_suffix(".h").read_text()))
    return [
        (int(names[name], 16), meaning)
        for name, meaning in re.findall(r'case (RL_STATUS_\w+): return "([^"]*)";', text)
    ]


def signal_names(model):
    """The first Real input and the first Real output: the ramp plot's signals."""

    def first(causality):
        return next(v["name"] for v in model["variable"] if v["causality"] == causality and v["type"] == "Real")

    return first("input"), first("output")


def ramp_plot(model, stage, path):
    u, y = signal_names(model)
    times = [0.0, 1.0, 5.0]
    values = [0.0, 2.0, -1.0]
    signal = np.array(
        list(zip(times, values, strict=True)) + [(8.0, -1.0)], dtype=[("time", np.float64), (u, np.float64)]
    )
    start = dict(model.get("documentation", {}).get("example", {}))
    with contextlib.redirect_stdout(io.StringIO()):  # fmpy's notes on inputs left at their start values
        result = simulate_fmu(
            str(stage),
            start_time=0.0,
            stop_time=8.0,
            output_interval=0.1,
            input=signal,
            start_values=start,
            output=[y],
            fmi_type="CoSimulation",
        )
    figure, axes = plt.subplots(figsize=(6, 3), dpi=100)
    axes.step(signal["time"], signal[u], where="post", linestyle="--", color="0.5", label=f"{u} (input)")
    axes.plot(result["time"], result[y], color="C0", label=f"{y} (output)")
    axes.set_xlabel("time [s]")
    axes.grid(True, alpha=0.3)
    settings = ", ".join(f"{k} = {v}" for k, v in start.items()) or "defaults"
    title = f"{model['model']['identifier']}: a step up and down ({settings}, 0.1 s steps)"
    axes.set_title("\n".join(textwrap.wrap(title, 90)), fontsize=8)
    axes.legend(loc="best", fontsize=8)
    figure.tight_layout()
    figure.savefig(path, metadata=PNG_METADATA)
    plt.close(figure)


def icon(model, path):
    figure = plt.figure(figsize=(1.28, 1.28), dpi=100)
    axes = figure.add_axes([0, 0, 1, 1])
    axes.set_xlim(0, 1)
    axes.set_ylim(0, 1)
    axes.axis("off")
    axes.add_patch(
        plt.Rectangle((0.04, 0.04), 0.92, 0.92, fill=True, facecolor="white", edgecolor="#1f4e79", linewidth=3)
    )
    axes.plot([0.15, 0.35, 0.35, 0.85], [0.3, 0.3, 0.8, 0.8], color="0.6", linestyle="--", linewidth=1.5)
    axes.plot([0.15, 0.35, 0.65, 0.85], [0.3, 0.3, 0.8, 0.8], color="#1f4e79", linewidth=3)
    axes.text(0.5, 0.12, model["model"]["identifier"][:14], ha="center", va="center", fontsize=7)
    figure.savefig(path, metadata=PNG_METADATA)
    plt.close(figure)


def cell(value):
    if isinstance(value, float) and math.isnan(value):
        return "NaN"
    if isinstance(value, bool):
        return "true" if value else "false"
    return html.escape(str(value)) if value is not None else ""


def licence(stage):
    """The copyright and licence the staged model description names (modelDescription/generate.py writes
    them), as HTML."""
    root = ElementTree.parse(stage / "modelDescription.xml").getroot()
    return (
        f"<p>{html.escape(root.get('copyright'))}. Licence: {html.escape(root.get('license'))}; "
        '<a href="licenses/license.txt">its text</a>.</p>'
    )


INTERFACES = (
    ("CoSimulation", "Co-Simulation"),
    ("ModelExchange", "Model Exchange"),
    ("ScheduledExecution", "Scheduled Execution (the PLC cyclic interrupt OB as an input Clock)"),
)
LS_REF = "extra/org.fmi-standard.fmi-ls-ref"
STANDALONE = '<p>(Also in <a href="fmi-ls-ref.html">fmi-ls-ref.html</a>, as the layered standard recommends.)</p>'


def interfaces(stage, version):
    """What the FMU carries, as a sentence: the interfaces its model
    description declares, its C sources, the layered standard."""
    root = ElementTree.parse(stage / "modelDescription.xml").getroot()
    names = [name for tag, name in INTERFACES if root.find(tag) is not None]
    kinds = ", ".join(names[:-1]) + " and " + names[-1] if len(names) > 1 else names[0]
    carried = [f"FMI {version}.0 {kinds}", "its C sources (<code>sources/</code>, any platform can compile them)"]
    if (stage / LS_REF / "fmi-ls-manifest.xml").exists():
        carried.append("its reference experiments (FMI-LS-REF, below)")
    return "It carries " + ", ".join(carried[:-1]) + " and " + carried[-1] + "."


def experiments(stage, model):
    """The experiments the FMU carries (references.py wrote them), each file
    with its role, its experiments and the one command that runs them: a
    section of index.html, and documentation/fmi-ls-ref.html (where the
    standard recommends it)."""
    files = sorted((stage / LS_REF).glob("*.exp"))
    if not files:
        return ""
    fmu = f"{model['model']['identifier']}.fmu"
    # fmutrace runs Co-Simulation: the Scheduled Execution FMU's experiments run on the FMI 3 FMU of its binary
    scheduled_only = ElementTree.parse(stage / "modelDescription.xml").getroot().find("CoSimulation") is None
    where = (
        " through Co-Simulation, on the FMI 3 FMU of the same name and binary (fmutrace is a Co-Simulation importer; "
        "a Scheduled Execution importer runs them one activation per cycle)"
        if scheduled_only
        else ""
    )
    parts = [
        '<h2 id="reference-experiments">Reference experiments (FMI-LS-REF)</h2>',
        f"<p>The FMU carries its hand-worked reference scenarios in <code>{LS_REF}/</code>: the manifest "
        "<code>fmi-ls-manifest.xml</code> lists every file with its SHA-256 and each reference signal's comparison "
        "criterion (an <code>org.fmutrace</code> annotation), each experiment file (MA-HS-Experiments) its "
        "experiments' times, parameter set (SSP <code>.ssv</code>), stimuli and reference (CSV). Run them all, "
        f"compared with those criteria{where}:</p><pre>fmutrace check {fmu}</pre>"
        f"<p>(<code>--role smoke-test</code> for the smoke test alone; fmutrace is in the project's repository.)</p>",
    ]
    for path in files:
        root = ElementTree.parse(path).getroot()
        parts.append(f"<h3>{html.escape(path.name)}: {html.escape(root.get('description', ''))}</h3><ul>")
        parts += [
            f"<li><code>{html.escape(e.get('name'))}</code>: {html.escape(e.get('description', ''))}</li>"
            for e in root.iterfind("Experiment")
        ]
        parts.append("</ul>")
    for state in sorted((stage / LS_REF / "serialized-state").glob("*.fmustate")):
        parts.append(
            f"<p><code>serialized-state/{html.escape(state.name)}</code>: the FMU's state half-way through the "
            f"experiment <code>{html.escape(state.stem)}</code>, serialized (the manifest gives the step and time): "
            "deserialized on any platform, the experiment's second half meets its reference.</p>"
        )
    return "\n".join(parts)


def clocks(stage):
    """The Clocks of the staged model description (FMI 3: Scheduled Execution's cyclic interrupt), generate.py's."""
    root = ElementTree.parse(stage / "modelDescription.xml").getroot()
    return [clock.attrib for clock in root.iter("Clock")]


def page(model, version, codes, licence_html, carried="", experiments_html="", clock_list=()):
    m = model["model"]
    style = (
        "body{font-family:sans-serif;max-width:60em;margin:2em auto;line-height:1.4}\n"
        "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:.2em .5em;text-align:left;"
        "vertical-align:top}"
    )
    header = "".join(
        f"<th>{name}</th>"
        for name in ("name", "value reference", "causality", "variability", "type", "start", "unit", "description")
    )
    rows = "\n".join(
        f"<tr><td><code>{cell(v['name'])}</code></td><td>{v['vr']}</td><td>{v['causality']}</td>"
        f"<td>{v['variability']}</td><td>{cell(v.get('declaredType', v['type']))}</td><td>{cell(v.get('start'))}</td>"
        f"<td>{cell(v.get('unit'))}</td><td>{cell(v.get('description'))}</td></tr>"
        for v in model["variable"]
    )
    rows += "".join(
        f"\n<tr><td><code>{cell(c['name'])}</code></td><td>{c['valueReference']}</td><td>{c['causality']}</td>"
        f"<td>{c['variability']}</td><td>Clock ({cell(c['intervalVariability'])})</td><td></td><td></td>"
        f"<td>{cell(c.get('description'))}</td></tr>"
        for c in clock_list
    )
    scheduled = "".join(
        f"<p>In Scheduled Execution the cyclic interrupt is the input Clock <code>{cell(c['name'])}</code>: the "
        "importer's scheduler activates it at each tick, and each <code>fmi3ActivateModelPartition</code> runs one "
        "PLC cycle at its activation time, with the outputs Co-Simulation gives after a step of one cycle. Its "
        "interval and the first tick's delay are <code>cycleTime</code> (<code>fmi3GetIntervalDecimal</code>, "
        "<code>fmi3GetShiftDecimal</code> in Initialization Mode). Co-Simulation and Model Exchange are in the FMI 3 "
        "FMU of the same name, the same binary without the Clock (a Co-Simulation FMU with Clocks must have Event "
        "Mode, FMI 3.0 section 4.4).</p>"
        for c in clock_list
    )
    enums = "".join(
        f"<h3>{html.escape(name)}</h3><p>{cell(e.get('description'))}</p><ul>"
        + "".join(
            f"<li><code>{i['value']}</code> {cell(i['name'])}: {cell(i.get('description'))}</li>" for i in e["items"]
        )
        + "</ul>"
        for name, e in model.get("enumerations", {}).items()
    )
    has_status = any(v["name"] in ("status", "error") for v in model["variable"])
    status = (
        (
            "<h2>Status codes</h2><table><tr><th>status</th><th>meaning</th></tr>"
            + "".join(
                f"<tr><td><code>16#{code:04X}</code></td><td>{html.escape(text)}</td></tr>" for code, text in codes
            )
            + "</table><p>16#8000 and above are errors: the output holds its last value, a warning names the cause "
            "in the log, and the status clears when the cause is gone.</p>"
        )
        if has_status
        else ""
    )
    de = m.get("defaultExperiment", {})
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(m["identifier"])}</title>
<style>{style}</style>
</head><body>
<h1>{html.escape(m["identifier"])}</h1>
<p>{html.escape(m.get("description", ""))}. {carried}</p>
<h2>What it does</h2>
<p>Each communication step stands for the PLC's cyclic interrupt: in every cycle the output moves towards the
input by at most the rising or falling rate times the cycle length, or follows it at once where the block's
rules say so (bypass, duration run out, non-finite input, initial delay). With <code>cycleTime</code> &gt; 0 the
block runs whole PLC cycles of that length inside each communication step; time is counted in whole cycles,
so long runs do not drift.</p>
{scheduled}
<p><img src="ramp.png" alt="A typical ramp: the output follows a step of the input at the limited rates"></p>
<h2>Variables</h2>
<table><tr>{header}</tr>
{rows}
</table>
{enums}
{status}
<h2>Default experiment</h2>
<p>start {cell(de.get("startTime"))} s, stop {cell(de.get("stopTime"))} s, step {cell(de.get("stepSize"))} s.</p>
{experiments_html}
<h2>Errors</h2>
<p>A call that cannot be carried out (wrong state, unknown or wrong-type variable, a value outside its range, a
step size that is not finite and positive, a communication point that is not the FMU's time) returns an error
with one log message naming the function and the reason; the instance keeps its last good values and can be
recovered with a saved FMU state or reset.</p>
<h2>Licence</h2>
{licence_html}
</body></html>
"""


def main(toml, stage, version, status_source, plot_stage):
    """plot_stage: a staged FMU of the same binary with Co-Simulation, to draw the ramp (the stage itself,
    but for the Scheduled Execution FMU's, fmi3's)."""
    model = tomllib.loads(Path(toml).read_text(encoding="utf-8"))
    stage = Path(stage).resolve()
    docs = stage / "documentation"
    docs.mkdir(parents=True, exist_ok=True)
    section = experiments(stage, model)
    (docs / "fmi-ls-ref.html").write_text(
        f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(model["model"]["identifier"])}: reference
experiments</title></head><body>
{section or "<p>This FMU carries no reference experiments.</p>"}
<p><a href="index.html">The FMU's documentation</a>.</p>
</body></html>
""",
        encoding="utf-8",
    )
    (docs / "index.html").write_text(
        page(
            model,
            int(version),
            status_codes(status_source),
            licence(stage),
            interfaces(stage, int(version)),
            section.replace("</h2>", f"</h2>\n{STANDALONE}", 1),
            clocks(stage),
        ),
        encoding="utf-8",
    )
    ramp_plot(model, Path(plot_stage).resolve(), docs / "ramp.png")
    if int(version) == 2:
        icon(model, stage / "model.png")
    else:
        (stage / "terminalsAndIcons").mkdir(exist_ok=True)
        icon(model, stage / "terminalsAndIcons" / "icon.png")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
