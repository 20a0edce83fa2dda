"""Channels matched to an FMU's variables.

A channel means the variable named by the last component of its name:
MAIN.fbRamp.delayedValue, "DB_Ramp".delayedValue and
Application.PLC_PRG.fbRamp.delayedValue all mean delayedValue (the same
name in another case too, when that is the only such variable). A map
(RecordingOptions.maps; the command's --map VARIABLE=CHANNEL) says it
where the names differ: CHANNEL is a channel's name (channels of a file
that share a name are NAME#COLUMN, _grid.unique_names), its name as
written or symbol, or #N, the channel in column N. A CHANNEL that means
several channels is refused with each of them and how to name one. A
channel of an input or a tunable parameter drives the FMU, one of an
output is compared, any other is listed as ignored with the reason."""

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


def _at_column(wanted):
    """N of a map's CHANNEL written #N (the channel in column N), else None."""
    return int(wanted[1:]) if wanted[:1] == "#" and wanted[1:].isdigit() else None


def _candidates(recording, wanted):
    """The channels a map's CHANNEL may mean: the one of that name, else
    those of that name as written or symbol, else the one in column N for
    #N, else those whose name's or symbol's last component it is; more
    than one is ambiguous."""
    named = [c for c in recording.channels if c.name == wanted]
    if len(named) == 1:
        return named
    exact = [c for c in recording.channels if wanted in (c.name, c.symbol, c.written)]
    if exact:
        return exact
    column = _at_column(wanted)
    if column is not None:
        return [c for c in recording.channels if c.column and c.column == column]  # (MDF's are 0: none)
    return [c for c in recording.channels if wanted in _last_components(c)]


def _last_components(channel):
    """The last components of a channel's symbol, name as written and name: the variable each may mean."""
    names = (channel.symbol, channel.written, channel.name)
    return list(dict.fromkeys(last_component(n) for n in names if n))


def _where(recording, channel):
    """A candidate's symbol and column (of its file where the recording has several), or its file."""
    said = [f"symbol {channel.symbol!r}"] if channel.symbol else []
    if not channel.column:
        return ", ".join(said + [f"in {channel.file}"])
    of = f" of {channel.file}" if len(recording.paths) > 1 else ""
    return ", ".join(said + [f"column {channel.column}{of}"])


def _means_only(recording, wanted, channel):
    """Whether a map's CHANNEL wanted means that channel alone."""
    found = _candidates(recording, wanted)
    return len(found) == 1 and found[0] is channel


def _ambiguous(recording, mapping, candidates, names):
    """The refusal of a map that means several channels: each of them, and how to name one."""
    variable, wanted = mapping
    listed = "; ".join(f"{c.name!r} ({_where(recording, c)})" for c in candidates)
    alone = [c for c in candidates if _means_only(recording, c.name, c)]
    at_column = [c for c in candidates if c.column and _means_only(recording, f"#{c.column}", c)]
    ways = []
    if alone:
        ways.append(f"by its name, e.g. {name_of(names, maps=(variable, alone[0].name))}")
    if at_column:
        ways.append(f"by its column, e.g. {name_of(names, maps=(variable, f'#{at_column[0].column}'))}")
    how = (
        "map one " + ", or ".join(ways)
        if ways
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


def _missing(recording, mapping, names):
    """The refusal of a map whose CHANNEL means no channel: the channels there are (with their columns for #N)."""
    wanted = mapping[1]
    if _at_column(wanted) is None:
        there = ", ".join(c.name for c in recording.channels)
        missing = f"no channel {wanted!r} (its channels: {there})"
    else:
        columns = [f"{c.name} (column {c.column})" for c in recording.channels if c.column]
        there = ", ".join(columns) if columns else "its channels have no columns (MDF): name one"
        missing = f"no channel in column {wanted[1:]} ({there})"
    return InputError(f"{name_of(names, maps=mapping)}: {recording.label} has {missing}")


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
            raise _missing(recording, (variable, wanted), names)
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
        for candidate in _last_components(channel):
            if candidate in variables:
                variable = candidate
            elif len(folded.get(candidate.lower(), [])) == 1:
                variable = folded[candidate.lower()][0]
            if variable:
                break
        if variable is None:
            result.ignored.append((channel, f"no variable of {label} is named {_last_components(channel)[0]!r}"))
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
