"""Channels matched to an FMU's variables.

A channel means the variable named by the last component of its name:
MAIN.fbRamp.delayedValue, "DB_Ramp".delayedValue and
Application.PLC_PRG.fbRamp.delayedValue all mean delayedValue (the same
name in another case too, when that is the only such variable). A map
(RecordingOptions.maps; the command's --map VARIABLE=CHANNEL) says it
where the names differ. A channel of an input or a tunable parameter
drives the FMU, one of an output is compared, any other is listed as
ignored with the reason."""

from dataclasses import dataclass, field

from .._errors import InputError
from .._names import Names, name_of


def components(name):
    """The dot-separated parts of a name, dots inside double quotes kept."""
    parts, current, quoted = [], "", False
    for char in name.strip():
        if char == '"':
            quoted = not quoted
        elif char == "." and not quoted:
            parts.append(current)
            current = ""
            continue
        current += char
    parts.append(current)
    return [p.strip().strip('"') for p in parts]


def last_component(name):
    return components(name)[-1]


@dataclass
class Plan:
    drives: list = field(default_factory=list)  # (variable name, Channel): inputs and tunable parameters
    compares: list = field(default_factory=list)  # (variable name, Channel): outputs
    ignored: list = field(default_factory=list)  # (Channel, why)

    def describe(self):
        lines = []
        if self.drives:
            lines.append("drives: " + ", ".join(_pair(v, c) for v, c in self.drives))
        if self.compares:
            lines.append("compared: " + ", ".join(_pair(v, c) for v, c in self.compares))
        for channel, why in self.ignored:
            lines.append(f"ignored: {channel.name} ({why})")
        return lines


def _column(channel):
    return f" (column {channel.column} of {channel.file})" if channel.column else f" (in {channel.file})"


def _pair(variable, channel):
    return variable if channel.name == variable else f"{variable} <- {channel.name}"


def _role(variable):
    if variable.causality == "input":
        return "drive", None
    if variable.causality == "parameter" and variable.variability == "tunable":
        return "drive", None
    if variable.causality == "output":
        return "compare", None
    return None, f"a {variable.variability} {variable.causality} of the FMU: it can neither drive nor be compared"


def _candidates(recording, wanted):
    """The channels a map's CHANNEL may mean: the one of that name, else
    those of that symbol, else those whose name's or symbol's last
    component it is; more than one is ambiguous."""
    named = [c for c in recording.channels if c.name == wanted]
    if len(named) == 1:
        return named
    exact = [c for c in recording.channels if wanted in (c.name, c.symbol)]
    if exact:
        return exact
    return [c for c in recording.channels if wanted in (last_component(c.name), last_component(c.symbol or c.name))]


def _ambiguous(recording, mapping, candidates, names):
    """The refusal of a map that means several channels: each of them, and how to name one."""
    variable, wanted = mapping
    listed = "; ".join(
        f"{c.name!r} ("
        + (f"symbol {c.symbol!r}, " if c.symbol else "")
        + (f"column {c.column})" if c.column else f"in {c.file})")
        for c in candidates
    )
    unique = [c for c in candidates if sum(o.name == c.name for o in recording.channels) == 1]
    how = (
        f"map one by its name, e.g. {name_of(names, maps=(variable, unique[0].name))}"
        if unique
        else "their names are not unique either: export them under names of their own"
    )
    return InputError(
        f"{name_of(names, maps=mapping)}: {len(candidates)} channels of {recording.label} are {wanted!r}: "
        f"{listed}; {how}"
    )


def _all_mean(recording, variable, found, names):
    """The refusal of several channels that mean one variable: each of them, and how to choose one."""
    listed = [f"{c.name!r}{_column(c)}" for c in found]
    channels = " and ".join([", ".join(listed[:-1]), listed[-1]])
    say = f"say which with {name_of(names, maps=(variable, 'CHANNEL'))}"
    example = name_of(names, maps=(variable, found[0].name))
    return InputError(
        f"{recording.label}: channels {channels} {'both' if len(found) == 2 else 'all'} mean {variable}: "
        f"{say}, e.g. {example}"
    )


def plan(recording, variables, label, maps=(), names: Names = ()):
    """The Plan of a recording for an FMU whose variables (name ->
    fmpy ScalarVariable) are given; maps: (VARIABLE, CHANNEL) pairs;
    names: the caller's words for the settings (RecordingOptions.names)."""
    taken = {}  # variable -> channel
    for variable, wanted in maps:
        if variable not in variables:
            raise InputError(f"{name_of(names, maps=(variable, wanted))}: {label} has no variable {variable!r}")
        candidates = _candidates(recording, wanted)
        if not candidates:
            raise InputError(
                f"{name_of(names, maps=(variable, wanted))}: {recording.label} has no channel {wanted!r} "
                f"(its channels: {', '.join(c.name for c in recording.channels)})"
            )
        if len(candidates) > 1:
            raise _ambiguous(recording, (variable, wanted), candidates, names)
        taken[variable] = candidates[0]
    mapped = {id(c) for c in taken.values()}
    folded: dict[str, list[str]] = {}
    for name in variables:
        folded.setdefault(name.lower(), []).append(name)
    result = Plan()
    matches: dict[str, list] = {}  # variable -> the unmapped channels that mean it
    for channel in recording.channels:
        if id(channel) in mapped:
            continue
        if not len(channel.values):
            result.ignored.append((channel, "no samples"))
            continue
        variable = None
        for candidate in dict.fromkeys(
            (last_component(channel.symbol) if channel.symbol else None, last_component(channel.name))
        ):
            if candidate is None:
                continue
            if candidate in variables:
                variable = candidate
            elif len(folded.get(candidate.lower(), [])) == 1:
                variable = folded[candidate.lower()][0]
            if variable:
                break
        if variable is None:
            result.ignored.append(
                (channel, f"no variable of {label} is named {last_component(channel.symbol or channel.name)!r}")
            )
            continue
        matches.setdefault(variable, []).append(channel)
    for variable, found in matches.items():
        if variable in taken:
            result.ignored += [(c, f"{variable} is mapped to {taken[variable].name!r}") for c in found]
        elif len(found) > 1:
            raise _all_mean(recording, variable, found, names)
        else:
            taken[variable] = found[0]
    for variable, channel in taken.items():
        role, why = _role(variables[variable])
        if role == "drive":
            result.drives.append((variable, channel))
        elif role == "compare":
            result.compares.append((variable, channel))
        else:
            result.ignored.append((channel, f"{variable} is {why}"))
    order = {id(c): i for i, c in enumerate(recording.channels)}
    result.drives.sort(key=lambda p: order[id(p[1])])
    result.compares.sort(key=lambda p: order[id(p[1])])
    result.ignored.sort(key=lambda p: order[id(p[0])])
    return result
