"""How a message names a setting: in the words of whoever gave it. A
Python caller sets RecordingOptions(step_size=...) or Tube(time=...), the
command sets --step-size or --tube-time; a message says what its reader
wrote. The caller's words travel with the settings that reach the places
where messages are made (RecordingOptions.names, down to the readers in
worker processes); the command gives its flags (cli.FLAGS)."""

from collections.abc import Iterable, Mapping

# setting -> how a Python caller writes it: the object it is set on and its field there
API_NAMES = {
    "step_size": "RecordingOptions.step_size",
    "time_unit": "RecordingOptions.time_unit",
    "timing": "RecordingOptions.timing",
    "cycle_lengths": "RecordingOptions.cycle_lengths",
    "maps": "RecordingOptions.maps",
    "start_values": "RecordingOptions.start_values",
    "rel_tol": "Tolerance.rel_tol",
    "abs_tol": "Tolerance.abs_tol",
    "tube_time": "Tube.time",
    "tube_value": "Tube.value",
    "tube_sides": "Tube.sides",
    "resume": "compare.resume",
    "signals": "Criteria.signals",
}

Names = Mapping[str, str] | Iterable[tuple[str, str]]  # setting -> the caller's word; pairs too


def name_of(names: Names, *settings: str, **values: object) -> str:
    """How the caller writes the settings named, or given with a value:
    a flag of the command ('--tube-time 0.5 --tube-value 0', '--map
    y=Y'), or the object a setting is set on ('Tube(time=0.5, value=0)',
    'RecordingOptions(maps={'y': 'Y'})'; one object's settings together).
    names: setting -> the caller's word (a flag starts with '-'); a
    setting it lacks has its API name. A value: a float (its shortest text),
    a str, or a (name, value) pair of a mapping setting."""
    words = dict(names)
    given = [(s, ...) for s in settings] + list(values.items())
    parts: list[str] = []
    owner = ""
    for setting, value in given:
        word = words.get(setting) or API_NAMES[setting]
        if word.startswith("-"):
            parts.append(word if value is ... else f"{word} {_text(value, flag=True)}")
            owner = ""
            continue
        of, field = word.rsplit(".", 1)
        item = f"{field}={'...' if value is ... else _text(value, flag=False)}"
        if of == owner:
            parts[-1] = f"{parts[-1][:-1]}, {item})"
        else:
            parts.append(f"{of}({item})")
        owner = of
    return " ".join(parts)


def shortest(value) -> str:
    """A number as the shortest text that reads back to the same float
    (repr's), without a trailing '.0': 0.25, 2, 1e-05."""
    written = repr(float(value))
    return written[:-2] if written.endswith(".0") else written


def _text(value, flag):
    if isinstance(value, float):
        return shortest(value)
    if isinstance(value, tuple):
        name, setting = value
        if not flag:
            return f"{{{name!r}: {setting!r}}}"
        pair = f"{name}={setting}"
        # quoted where blanks would split it: as a shell (bash, cmd, PowerShell) takes it back
        return f'"{pair}"' if any(c.isspace() for c in pair) else pair
    return str(value) if flag else repr(value)
