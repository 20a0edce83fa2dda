"""A case run and compared on whole arrays, the independent check of the
pipeline's chunks: the FMU's result of Runner.run (the fast loop, else
fmpy's) compared by comparison.compare_traces on the whole traces."""

from fmutrace._cases import load_case
from fmutrace._comparison import compare_traces
from fmutrace._errors import SimulationError
from fmutrace._fmpy import Experiment, Signals


def on_the_whole(folder, runner, fmu, mode):
    """(status, messages, failing deviations, result) of the case run and compared on whole arrays."""
    case = load_case(folder, fmu)
    o = case.options
    try:
        result = runner.run(
            Experiment(o["StartTime"], o["StopTime"], o["StepSize"], o["RelTol"]),
            Signals(case.inputs, case.start_values, case.outputs),
        )
    except SimulationError as error:
        return "error", [str(error)], [], None
    comparison = compare_traces(result, case.reference, mode)
    status = "pass" if comparison.passed else "fail"
    return status, comparison.messages(), [d for d in comparison.deviations if not d.passed], result
