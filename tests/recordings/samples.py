"""Sample recordings of the Siemens block and of RateLimiter as each
recorder exports them, written from each export's documented structure
(see fmutrace/src/fmutrace/recordings/*.py for the sources) by this
script, never by fmutrace. `python tests/recordings/samples.py` writes
them beside it; tests/fmutrace/test_recordings.py checks that the files are what
it writes.

The values are worked by hand from the blocks' rules (docs/rules.md for the cycle
rules, docs/fmi.md for the time model and docs/models.md for the vendor readings)
for a 250 ms cyclic interrupt (a binary fraction: the FMU's cycle length
is exact, and so is every value below); tests/fmutrace/test_recordings.py checks
them against the tests' independent oracle as well.

Each row is one cycle k (0, 1, ...) as a recorder writes it: the input
the cycle read and the output it produced.
"""

from datetime import datetime, timedelta, timezone
from pathlib import Path

HERE = Path(__file__).resolve().parent
CYCLE = 0.25  # s

# LGF_LimRateOfChangeCI: setChangeRate 4/s is 1.0 per 250 ms cycle; delayedValue starts at 0 (the
# block's static value) and moves towards value by at most 1.0 a cycle.
SIEMENS = {
    "value": [0, 0, 3.5, 3.5, 3.5, 3.5, 3.5, 3.5, -1.5, -1.5, -1.5, -1.5, -1.5, -1.5],
    "setChangeRate": [4] * 14,
    "delayedValue": [0, 0, 1, 2, 3, 3.5, 3.5, 3.5, 2.5, 1.5, 0.5, -0.5, -1.5, -1.5],
    "status": [0] * 14,
}
# RateLimiter with its defaults (rateUpPar = rateDownPar = 1 per ratePeriod 1 s: 0.25 a cycle, initMode 2:
# y starts at u). rampActive: decided by rule 6 and y != u.
RATE_LIMITER = {
    "u": [0, 2, 2, 2, 2, 2, 2, 2, 2, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5],
    "y": [0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 1.75, 2, 1.75, 1.5, 1.25, 1, 0.75, 0.5, 0.5],
    "rampActive": [0, 1, 1, 1, 1, 1, 1, 1, 0, 1, 1, 1, 1, 1, 0, 0],
}
START = datetime(2026, 11, 20, 13, 0, 0, tzinfo=timezone.utc)  # 14:00 CET
FILETIME_EPOCH = datetime(1601, 1, 1, tzinfo=timezone.utc)
OLE_EPOCH = datetime(1899, 12, 30, tzinfo=timezone.utc)


def _num(value, comma=False):
    text = repr(float(value))
    text = text[:-2] if text.endswith(".0") else text
    return text.replace(".", ",") if comma else text


def _filetime(seconds):
    moment = START + timedelta(seconds=seconds)
    return (moment - FILETIME_EPOCH) // timedelta(microseconds=1) * 10


def twincat_every_cycle():
    """Scope View, timelines 'All' (a time column per channel), tab, decimal comma, ms from the first
    point, 'Include EOF-Tag'."""
    channels = [
        ("value", "MAIN.fbRamp.value"),
        ("setChangeRate", "MAIN.fbRamp.setChangeRate"),
        ("delayedValue", "MAIN.fbRamp.delayedValue"),
    ]
    start, end = _filetime(0), _filetime(13 * CYCLE)
    lines = [
        "Name\tLGF_Ramp",
        "File\tC:\\TwinCAT\\3.1\\Scope\\LGF_Ramp.csv",
        f"Starttime of export\t{start}\tFreitag, 20. November 2026\t14:00:00.000",
        f"Endtime of export\t{end}\tFreitag, 20. November 2026\t14:00:03.250",
        "",
        "",
    ]
    properties = [
        ("Name", lambda n, s: n),
        ("SymbolComment", lambda n, s: ""),
        ("Data-Type", lambda n, s: "REAL64"),
        ("SampleTime[ms]", lambda n, s: "250"),
        ("VariableSize", lambda n, s: "8"),
        ("SymbolBased", lambda n, s: "True"),
        ("IndexGroup", lambda n, s: "16448"),
        ("IndexOffset", lambda n, s: "385040"),
        ("SymbolName", lambda n, s: s),
        ("NetID", lambda n, s: "5.80.201.232.1.1"),
        ("Port", lambda n, s: "851"),
        ("Offset", lambda n, s: "0"),
        ("ScaleFactor", lambda n, s: "1"),
        ("BitMask", lambda n, s: "0xffffffffffffffff"),
        ("Unit", lambda n, s: "(None)"),
        ("Unit ScaleFactor", lambda n, s: "1"),
        ("Unit Offset", lambda n, s: "0"),
    ]
    for key, value in properties:
        lines.append("\t".join(f"{key}\t{value(n, s)}" for n, s in channels))
    lines.append("")
    for k in range(14):
        ms = _num(k * 250)
        lines.append("\t".join(f"{ms}\t{_num(SIEMENS[n][k], comma=True)}" for n, _ in channels))
    lines.append("EOF")
    return "\r\n".join(lines) + "\r\n"


def twincat_outputs_every_third_cycle():
    """Scope View, timelines 'For each sampletime', 'Full Timestamp' (FILETIME), decimal point: the
    inputs sampled every 250 ms cycle, delayedValue every 750 ms; the slower group's rows end early."""
    start, end = _filetime(0), _filetime(13 * CYCLE)
    lines = [
        "Name\tLGF_Ramp_slow_output",
        "File\tC:\\TwinCAT\\3.1\\Scope\\LGF_Ramp_slow_output.csv",
        f"Starttime of export\t{start}\tFreitag, 20. November 2026\t14:00:00.000",
        f"Endtime of export\t{end}\tFreitag, 20. November 2026\t14:00:03.250",
        "",
        "",
        "Name\tvalue\tsetChangeRate\tName\tdelayedValue",
        "Data-Type\tREAL64\tREAL64\tData-Type\tREAL64",
        "SampleTime[ms]\t250\t250\tSampleTime[ms]\t750",
        "SymbolName\tMAIN.fbRamp.value\tMAIN.fbRamp.setChangeRate\tSymbolName\tMAIN.fbRamp.delayedValue",
        "NetID\t5.80.201.232.1.1\t5.80.201.232.1.1\tNetID\t5.80.201.232.1.1",
        "",
    ]
    for k in range(14):
        row = f"{_filetime(k * CYCLE)}\t{_num(SIEMENS['value'][k])}\t{_num(SIEMENS['setChangeRate'][k])}"
        if k % 3 == 0:
            row += f"\t{_filetime(k * CYCLE)}\t{_num(SIEMENS['delayedValue'][k])}"
        lines.append(row)
    return "\n".join(lines) + "\n"


def codesys23():
    """CODESYS 2.3 'Trace in ASCII file': title, project, names, blanks between values; the first
    column counts cycles (the trace sampled every cycle)."""
    lines = [
        "Ramp trace",
        "D:\\PROJECTS\\RAMP_TEST.PRO",
        "Cycle PLC_PRG.fbRamp.u PLC_PRG.fbRamp.y PLC_PRG.fbRamp.rampActive",
    ]
    for k in range(16):
        active = "TRUE" if RATE_LIMITER["rampActive"][k] else "FALSE"
        lines.append(f"{k} {_num(RATE_LIMITER['u'][k])} {_num(RATE_LIMITER['y'][k])} {active}")
    return "\r\n".join(lines) + "\r\n"


def codesys_v3():
    """CODESYS V3 trace exported as text: the trace's data, ';' and a decimal comma (German Windows),
    UTF-8 with a BOM, time in microseconds."""
    lines = [
        "Trace: RampTrace",
        "Application: Device.Application",
        "Task: MainTask (250 ms)",
        "",
        "Time [µs];Application.PLC_PRG.fbRamp.u;Application.PLC_PRG.fbRamp.y;Application.PLC_PRG.fbRamp.rampActive",
    ]
    for k in range(16):
        active = "TRUE" if RATE_LIMITER["rampActive"][k] else "FALSE"
        lines.append(f"{k * 250000};{_num(RATE_LIMITER['u'][k], True)};{_num(RATE_LIMITER['y'][k], True)};{active}")
    return "\ufeff" + "\r\n".join(lines) + "\r\n"


def tia_portal():
    """TIA Portal trace CSV: metadata lines, a sample index, ms relative to the trigger (negative before
    it), TRUE/FALSE, the status WORD as 16#...; ';' and a decimal comma; Windows-1252."""
    lines = [
        "Trace;Rampe_OB30",
        "Gerät;PLC_1 [CPU 1516-3 PN/DP]",
        "Aufzeichnung;jeder Zyklus von OB30 (250 ms)",
        'Auslöser;"DB_Ramp".value > 0,0',
        "",
        'Index;Time [ms];"DB_Ramp".value;"DB_Ramp".setChangeRate;"DB_Ramp".enDefaultOutValue;'
        '"DB_Ramp".delayedValue;"DB_Ramp".status',
    ]
    for k in range(14):
        lines.append(
            f"{k};{(k - 2) * 250};{_num(SIEMENS['value'][k], True)};{_num(SIEMENS['setChangeRate'][k], True)};"
            f"FALSE;{_num(SIEMENS['delayedValue'][k], True)};16#{SIEMENS['status'][k]:04X}"
        )
    return "\r\n".join(lines) + "\r\n"


def _ole(seconds):
    days = (START + timedelta(seconds=seconds) - OLE_EPOCH) / timedelta(days=1)
    return f"{days * 1e6:.4f}".replace(".", ",")


def wincc():
    """WinCC data log: a row per tag and time stamp, ';' and a decimal comma, Time_ms as OLE days times
    1e6 to four decimals (a few microseconds off the cycle), a $RT_OFF$ marker; UTF-16 with a BOM.
    The HMI tags are named DB_Ramp_value and so on."""
    lines = [
        '"VarName";"TimeString";"VarValue";"Validity";"Time_ms"',
        f'"$RT_OFF$";"20.11.2026 13:59:59";2;1;{_ole(-1)}',
    ]
    for k in range(14):
        stamp = (START + timedelta(hours=1, seconds=k * CYCLE)).strftime("%d.%m.%Y %H:%M:%S")
        for name in ("value", "setChangeRate", "delayedValue"):
            lines.append(f'"DB_Ramp_{name}";"{stamp}";{_num(SIEMENS[name][k], True)};1;{_ole(k * CYCLE)}')
    return "\ufeff" + "\r\n".join(lines) + "\r\n"


def niagara(name):
    """One Niagara history: Timestamp, Trend Flags, Status, Value; the file of delayedValue names its
    history in a line before the table."""
    lines = ["History,/RampStation/delayedValue"] if name == "delayedValue" else []
    lines.append("Timestamp,Trend Flags,Status,Value")
    for k in range(14):
        moment = START + timedelta(hours=1, seconds=k * CYCLE)
        stamp = (
            moment.strftime("%d-%b-%y %I:%M:%S.")
            + f"{moment.microsecond // 1000:03d} "
            + moment.strftime("%p")
            + " CET"
        )
        flags = "{start}" if k == 0 else "{}"
        lines.append(f"{stamp},{flags},{{ok}},{_num(SIEMENS[name][k])}")
    return "\n".join(lines) + "\n"


def plain_tab():
    lines = ["time\tu\ty"] + [
        f"{_num(k * CYCLE)}\t{_num(RATE_LIMITER['u'][k])}\t{_num(RATE_LIMITER['y'][k])}" for k in range(16)
    ]
    return "\n".join(lines) + "\n"


def plain_space():
    lines = ["time PLC_PRG.fbRamp.u PLC_PRG.fbRamp.y"] + [
        f"{_num(k * CYCLE):>6} {_num(RATE_LIMITER['u'][k]):>4} {_num(RATE_LIMITER['y'][k]):>5}" for k in range(16)
    ]
    return "\n".join(lines) + "\n"


def modbusscope():
    """ModbusScope's data file (File > Export Data...), as its DataFileExporter writes it from version
    3.6.0 on (the ModbusScope/ModbusScope repository at tag 3.6.0,
    src/importexport/datafileexporter.cpp, read for its layout): comment lines '//' of the log's
    settings (one TCP connection), '//', the rows Property, Color, Expression and Axis (0 the left
    value axis, 1 the right), '//', the notes with a '//' after them, then the label row 'Time (ms)'
    and a line per poll: the time in whole ms since logging started, the values to at most three
    decimals. The locale's decimal mark is ',', so the separator is ';'; written on Windows (the
    exporter's text mode: CR LF). Register 40001 (the PLC writes y * 100 into it) is plotted three
    times, each labelled 'Register 40001' with its own expression and axis: the raw count, y, and y
    per minute on the right axis (the label row is line 19, as in the export the issue saw refused);
    Register 40002 is u * 100, shown as u. The poll interval is the PLC's cycle, polled 12 ms after
    logging started, each poll in step with the PLC."""
    y, u = RATE_LIMITER["y"], RATE_LIMITER["u"]
    lines = [
        "//ModbusScope version;3.6.0",
        "//Start time;20-11-2026 14:00:00",
        "//End time;20-11-2026 14:00:04",
        "//Settings (Connection ID 1);192.168.0.10:502",
        "//Slave ID (Connection ID 1);1",
        "//Time-out (Connection ID 1);1000",
        "//Consecutive max (Connection ID 1);125",
        "//Poll interval;250",
        f"//Communication success;{len(y)}",
        "//Communication errors;0",
        "//",
        "//Property;Register 40001;Register 40001;Register 40001;Register 40002",
        "//Color;#000000;#0000ff;#00ffff;#00ff00",
        '//Expression;"${40001}";"${40001}/100";"${40001}*60/100";"${40002}/100"',
        "//Axis;0;0;1;0",
        "//",
        '//Note;2012;2;"y reaches u"',
        "//",
        "Time (ms);Register 40001;Register 40001;Register 40001;Register 40002",
    ]
    for k in range(len(y)):
        cells = [y[k] * 100, y[k], y[k] * 60, u[k]]
        lines.append(f"{12 + k * 250};" + ";".join(_num(c, True) for c in cells))
    return "\r\n".join(lines) + "\r\n"


SAMPLES = {
    # file: (text, encoding)
    "twincat_siemens.csv": (twincat_every_cycle, "utf-8"),
    "twincat_siemens_outputs_every_3rd_cycle.csv": (twincat_outputs_every_third_cycle, "utf-8"),
    "codesys23_ratelimiter.txt": (codesys23, "cp1252"),
    "codesys_v3_ratelimiter.csv": (codesys_v3, "utf-8"),
    "tia_portal_siemens.csv": (tia_portal, "cp1252"),
    "wincc_siemens.csv": (wincc, "utf-16-le"),
    "niagara_siemens/value.csv": (lambda: niagara("value"), "utf-8"),
    "niagara_siemens/setChangeRate.csv": (lambda: niagara("setChangeRate"), "utf-8"),
    "niagara_siemens/history_3.csv": (lambda: niagara("delayedValue"), "utf-8"),
    "plain_ratelimiter.tsv": (plain_tab, "utf-8"),
    "plain_ratelimiter_spaces.txt": (plain_space, "utf-8"),
    "modbusscope_ratelimiter.csv": (modbusscope, "utf-8"),
}


def sample_bytes(name):
    make, encoding = SAMPLES[name]
    return make().encode(encoding)


def write_mdf(path, outputs_every=1, perturb=None):
    """An MDF4 file of the Siemens recording written by asammdf's own writer: the inputs in one channel
    group, delayedValue in another with its own time base (every outputs_every-th cycle). perturb:
    (cycle, amount) added to delayedValue."""
    import numpy as np
    from asammdf import MDF, Signal

    cycles = np.arange(14)
    times = cycles * CYCLE
    out = cycles[::outputs_every]
    delayed = np.array(SIEMENS["delayedValue"], dtype=float)[::outputs_every]
    if perturb:
        delayed[list(out).index(perturb[0])] += perturb[1]
    mdf = MDF(version="4.10")
    mdf.append(
        [
            Signal(np.array(SIEMENS["value"], dtype=float), times, name="MAIN.fbRamp.value"),
            Signal(np.array(SIEMENS["setChangeRate"], dtype=float), times, name="MAIN.fbRamp.setChangeRate"),
        ],
        comment="inputs every cycle",
    )
    mdf.append([Signal(delayed, out * CYCLE, name="MAIN.fbRamp.delayedValue")], comment="output")
    mdf.save(str(path), overwrite=True)
    mdf.close()
    return path


def main():
    for name in SAMPLES:
        path = HERE / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(sample_bytes(name))
        print(path)


if __name__ == "__main__":
    main()
