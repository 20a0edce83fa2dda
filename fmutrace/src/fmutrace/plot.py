"""A case's figure for the report: its inputs, each compared signal
(reference, result, and the band where the mode draws one) and the
deviation, as PNG bytes."""
import io

import numpy as np

from .comparison import Comparison, Mode


def plot_case(case, result, comparison: Comparison, mode: Mode, label: str) -> bytes:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = case.outputs
    has_inputs = case.inputs is not None
    rows = len(names) + 1 + has_inputs
    height = 1.6 * rows + 0.6
    fig, axes = plt.subplots(rows, 1, sharex=True, figsize=(8, height), squeeze=False)
    for ax in axes[:, 0]:
        ax.tick_params(labelsize=7)
    axes = list(axes[:, 0])
    if has_inputs:
        ax = axes.pop(0)
        stop = case.options["StopTime"]
        for name in case.inputs.dtype.names[1:]:
            ax.step(np.append(case.inputs["time"], stop), np.append(case.inputs[name], case.inputs[name][-1]),
                    where="post", label=f"input {name}")
        ax.legend(loc="best", fontsize=7)
    deviation_axis = axes.pop()
    ref = case.reference
    for ax, name in zip(axes, names):
        band = comparison.bands.get(name)
        if band is not None and mode.fills_band:
            ax.fill_between(band.times, band.lower, band.upper, color="0.85", label=mode.name)
        ax.plot(ref["time"], ref[name], **mode.reference_line, label=f"{name} reference")
        ax.step(result["time"], result[name], where="post", color="C1", linewidth=1.2, marker=".", markersize=3,
                label=f"{name} {label}")
        ax.legend(loc="best", fontsize=7)
        if band is not None:
            deviation_axis.plot(band.times, band.deviation, drawstyle="steps-post", label=name)
    deviation_axis.set_ylabel(mode.deviation_label, fontsize=7)
    deviation_axis.legend(loc="best", fontsize=7)
    deviation_axis.set_xlabel("time [s]")
    title = f"{case.name} on {label}" + (f": {case.description}" if case.description else "")
    fig.suptitle(title if len(title) < 110 else title[:107] + "...", fontsize=9)
    # fixed margins: tight_layout would cost more than the rest of the plot
    fig.subplots_adjust(left=0.1, right=0.98, top=1 - 0.45 / height, bottom=0.45 / height, hspace=0.12)
    stream = io.BytesIO()
    fig.savefig(stream, dpi=80, format="png", metadata={"Software": None})
    plt.close(fig)
    return stream.getvalue()
