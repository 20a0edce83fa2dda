#!/usr/bin/env python3
"""Generate the FMI 2 and FMI 3 model descriptions, the FMI 3 build
description and the C variable table of one model from its TOML file, the
single source of truth for every variable.

    generate.py MODEL.toml OUTDIR --fmi2-sources a.c ... --fmi3-sources b.c ...

writes OUTDIR/fmi2/modelDescription.xml, OUTDIR/fmi3/modelDescription.xml,
OUTDIR/fmi3/buildDescription.xml and OUTDIR/<Model>_variables.h.
Only the Python standard library is used, so the build needs nothing else.
"""

import argparse
import hashlib
import math
import re
import sys
import tomllib
import uuid
from pathlib import Path
from xml.sax.saxutils import quoteattr

GENERATION_TOOL = "rate-limiter-fmus modelDescription/generate.py"
REPO = Path(__file__).resolve().parent.parent
MODEL_HEADER = REPO / "fmu_src" / "model.h"
# the licence: LICENSE ships in every FMU as documentation/licenses/license.txt (cmake/Fmu.cmake), the entry
# point the FMI 3 standard names; both versions' descriptions name it
LICENSE = REPO / "LICENSE"
LICENSE_IN_FMU = "documentation/licenses/license.txt"


def licence_attributes():
    """copyright and license of fmiModelDescription (FMI 2 and FMI 3), from the LICENSE file."""
    text = LICENSE.read_text(encoding="utf-8")
    if not text.startswith("BSD 2-Clause License\n"):
        sys.exit(f"{LICENSE}: not the BSD 2-Clause licence that generate.py names")
    copyright_line = next(line for line in text.splitlines() if line.startswith("Copyright (c) "))
    return {"copyright": copyright_line, "license": f"BSD-2-Clause (the text: {LICENSE_IN_FMU})"}


def max_variables():
    """The size of the core's variable table (FMU_MAX_VARIABLES)."""
    return int(re.search(r"#define FMU_MAX_VARIABLES (\d+)", MODEL_HEADER.read_text()).group(1))


TYPES = {"Real", "Integer", "Boolean", "Enumeration"}
CAUSALITIES = {"independent", "parameter", "input", "output"}
VARIABILITIES = {"continuous", "discrete", "fixed", "tunable"}
FMI3_ELEMENT = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "Enumeration": "Enumeration"}
UNITS = {"s": 'BaseUnit s="1"', "1/s": 'BaseUnit s="-1"'}
# FMI 3's input Clock of Scheduled Execution: the PLC's cyclic interrupt (OB), one model partition that runs one
# cycle per tick. Not a value of the core's table: its value reference is the first after the variables'. Periodic,
# its interval cycleTime, a fixed parameter: intervalVariability "fixed" without intervalDecimal, so that the importer
# asks fmi3GetIntervalDecimal and fmi3GetShiftDecimal in Initialization Mode (FMI 3.0.2, 2.2.9.3, fixed periodic
# Clock); the first tick one cycle after the start, as Co-Simulation's first step and Model Exchange's first event.
CLOCK_NAME = "cyclicInterrupt"
CLOCK_DESCRIPTION = (
    "The PLC's cyclic interrupt (OB) in Scheduled Execution: each activation runs one PLC cycle; "
    "interval and shift cycleTime (fmi3GetIntervalDecimal, fmi3GetShiftDecimal)"
)


def clock_vr(model):
    return len(model["variable"])


LOG_CATEGORIES = [
    ("logStatusError", "Errors: a call that failed and why"),
    ("logStatusWarning", "Warnings: a change of the block's status word"),
    ("logEvents", "Information: initialisation and status cleared"),
]


def load(path):
    model = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    variables = model["variable"]
    for index, v in enumerate(variables):
        where = f"{path}: variable {v.get('name')!r}"
        if v["vr"] != index:
            sys.exit(f"{where}: value references must be 0, 1, 2, ... in file order")
        if v["type"] not in TYPES or v["causality"] not in CAUSALITIES or v["variability"] not in VARIABILITIES:
            sys.exit(f"{where}: unknown type, causality or variability")
        if v["type"] == "Enumeration" and v.get("declaredType") not in model.get("enumerations", {}):
            sys.exit(f"{where}: Enumeration needs a declaredType from [enumerations]")
        if v["causality"] in ("input", "parameter") and "start" not in v:
            sys.exit(f"{where}: inputs and parameters need a start value")
        if isinstance(v.get("start"), float) and math.isinf(v["start"]):
            sys.exit(
                f"{where}: an infinite start value (FMI Library and OMSimulator refuse it); "
                "the largest finite double (1.7976931348623157e308) can mean 'no limit'"
            )
        if v["causality"] in ("output", "independent") and "start" in v:
            sys.exit(f"{where}: outputs are calculated and take no start value")
        if v.get("unit") and v["unit"] not in UNITS:
            sys.exit(f"{where}: unit {v['unit']!r} is not defined in generate.py")
    names = [v["name"] for v in variables]
    if len(set(names)) != len(names) or CLOCK_NAME in names:
        sys.exit(f"{path}: variable names must be unique, and none {CLOCK_NAME!r} (the clock's)")
    if not variables or variables[0]["name"] != "time" or variables[0]["causality"] != "independent":
        sys.exit(f"{path}: value reference 0 must be the independent variable time (the core publishes it there)")
    if len(variables) > max_variables():
        sys.exit(
            f"{path}: {len(variables)} variables; the core's table holds {max_variables()} "
            f"(FMU_MAX_VARIABLES in {MODEL_HEADER.name})"
        )
    return model


def token(path):
    digest = hashlib.md5(Path(path).read_bytes()).digest()
    return "{" + str(uuid.UUID(bytes=digest)) + "}"


def xml_number(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return "NaN"
        if math.isinf(value):
            return "INF" if value > 0 else "-INF"
        return repr(value)
    return str(value)


def c_number(value):
    if isinstance(value, bool):
        return "1.0" if value else "0.0"
    value = float(value)
    if math.isnan(value):
        return "NAN"
    if math.isinf(value):
        return "INFINITY" if value > 0 else "-INFINITY"
    return repr(value)


def attributes(**pairs):
    return "".join(
        f" {k}={quoteattr(xml_number(v) if not isinstance(v, str) else v)}" for k, v in pairs.items() if v is not None
    )


def variable_attributes(v):
    """A variable's own attributes (FMI 2's ScalarVariable; FMI 3's variable element begins with them)."""
    return dict(
        name=v["name"],
        valueReference=v["vr"],
        description=v.get("description"),
        causality=v["causality"],
        variability=v["variability"],
    )


def type_attributes(v):
    """Its type's attributes (FMI 2's type element; FMI 3's variable element ends with them)."""
    keys = ("declaredType", "unit", "min", "max", "start")
    return {key: v.get(key) for key in keys}


def used_units(model):
    return sorted({v["unit"] for v in model["variable"] if v.get("unit")})


def common_head(model, version):
    m = model["model"]
    out = []
    units = used_units(model)
    if units:
        out.append("  <UnitDefinitions>")
        for unit in units:
            out.append(f"    <Unit name={quoteattr(unit)}><{UNITS[unit]}/></Unit>")
        out.append("  </UnitDefinitions>")
    enums = model.get("enumerations", {})
    if enums:
        out.append("  <TypeDefinitions>")
        for name, enum in enums.items():
            indent = "        " if version == 2 else "      "
            items = "".join(
                f"\n{indent}<Item{attributes(name=i['name'], value=i['value'], description=i.get('description'))}/>"
                for i in enum["items"]
            )
            if version == 2:
                out.append(f"    <SimpleType{attributes(name=name, description=enum.get('description'))}>")
                out.append(f"      <Enumeration>{items}\n      </Enumeration>")
                out.append("    </SimpleType>")
            else:
                enumeration = attributes(name=name, description=enum.get("description"))
                out.append(f"    <EnumerationType{enumeration}>{items}\n    </EnumerationType>")
        out.append("  </TypeDefinitions>")
    out.append("  <LogCategories>")
    for name, description in LOG_CATEGORIES:
        out.append(f"    <Category{attributes(name=name, description=description)}/>")
    out.append("  </LogCategories>")
    de = m.get("defaultExperiment", {})
    experiment = attributes(startTime=de.get("startTime"), stopTime=de.get("stopTime"), stepSize=de.get("stepSize"))
    out.append(f"  <DefaultExperiment{experiment}/>")
    return out


def fmi2_description(model, guid, sources):
    m = model["model"]
    root = attributes(modelName=m["identifier"], guid=guid, description=m["description"], **licence_attributes())
    states = 'canGetAndSetFMUstate="true" canSerializeFMUstate="true" canBeInstantiatedOnlyOncePerProcess="false"'
    identifier = attributes(modelIdentifier=m["identifier"])
    out = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<fmiModelDescription fmiVersion="2.0"{root}{attributes(generationTool=GENERATION_TOOL)}'
        ' variableNamingConvention="flat" numberOfEventIndicators="0">',
        # Model Exchange (docs/fmi.md): no states, no event indicators, the cycle ends are time events
        f'  <ModelExchange{identifier} completedIntegratorStepNotNeeded="true" {states}>',
    ]
    source_files = (
        ["    <SourceFiles>"] + [f"      <File{attributes(name=s)}/>" for s in sources] + ["    </SourceFiles>"]
    )
    out += source_files + ["  </ModelExchange>"]
    out += [f'  <CoSimulation{identifier} canHandleVariableCommunicationStepSize="true" {states}>']
    out += source_files + ["  </CoSimulation>"]
    out += common_head(model, 2)
    out.append("  <ModelVariables>")
    for index, v in enumerate(model["variable"], start=1):
        out.append(f"    <!-- index {index} -->")
        out.append(f"    <ScalarVariable{attributes(**variable_attributes(v))}>")
        out.append(f"      <{v['type']}{attributes(**type_attributes(v))}/>")
        out.append("    </ScalarVariable>")
    out.append("  </ModelVariables>")
    outputs = [i for i, v in enumerate(model["variable"], start=1) if v["causality"] == "output"]
    out.append("  <ModelStructure>")
    out.append("    <Outputs>")
    out += [f'      <Unknown index="{i}"/>' for i in outputs]
    out.append("    </Outputs>")
    out.append("    <InitialUnknowns>")
    out += [f'      <Unknown index="{i}"/>' for i in outputs]
    out.append("    </InitialUnknowns>")
    out.append("  </ModelStructure>")
    out.append("</fmiModelDescription>")
    return "\n".join(out) + "\n"


# FMI 3's interfaces ship as two FMUs of one binary (docs/fmi.md, Scheduled Execution): Co-Simulation and Model
# Exchange without a Clock, as FMI 2's, since a Co-Simulation FMU that declares Clocks must have Event Mode (FMI 3.0,
# 4.4) and some Co-Simulation importers cannot load a Clock; Scheduled Execution alone, with its Clock. The folder
# under the build tree that each is written to and packaged from (cmake/Fmu.cmake names the same).
FMI3_VARIANTS = {"fmi3": "CoSimulation+ModelExchange", "fmi3-se": "ScheduledExecution"}


def fmi3_description(model, instantiation_token, variant):
    """The FMI 3 model description of one variant (a key of FMI3_VARIANTS)."""
    scheduled = FMI3_VARIANTS[variant] == "ScheduledExecution"
    m = model["model"]
    root = attributes(
        modelName=m["identifier"],
        instantiationToken=instantiation_token,
        description=m["description"],
        **licence_attributes(),
    )
    states = 'canGetAndSetFMUState="true" canSerializeFMUState="true" canBeInstantiatedOnlyOncePerProcess="false"'
    identifier = attributes(modelIdentifier=m["identifier"])
    out = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<fmiModelDescription fmiVersion="3.0"{root}{attributes(generationTool=GENERATION_TOOL)}'
        ' variableNamingConvention="flat">',
    ]
    if scheduled:
        out.append(f"  <ScheduledExecution{identifier} {states}/>")
    else:
        out.append(f'  <ModelExchange{identifier} needsCompletedIntegratorStep="false" {states}/>')
        out.append(
            f'  <CoSimulation{identifier} canHandleVariableCommunicationStepSize="true" {states}'
            ' hasEventMode="false" providesIntermediateUpdate="false"/>'
        )
    out += common_head(model, 3)
    out.append("  <ModelVariables>")
    for v in model["variable"]:
        element = FMI3_ELEMENT[v["type"]]
        out.append(f"    <{element}{attributes(**variable_attributes(v), **type_attributes(v))}/>")
    clock = attributes(
        name=CLOCK_NAME,
        valueReference=clock_vr(model),
        description=CLOCK_DESCRIPTION,
        causality="input",
        variability="discrete",
        intervalVariability="fixed",
        priority=0,
    )
    if scheduled:
        out.append(f"    <Clock{clock}/>")
    out.append("  </ModelVariables>")
    outputs = [v["vr"] for v in model["variable"] if v["causality"] == "output"]
    out.append("  <ModelStructure>")
    out += [f'    <Output valueReference="{vr}"/>' for vr in outputs]
    out += [f'    <InitialUnknown valueReference="{vr}"/>' for vr in outputs]
    out.append("  </ModelStructure>")
    out.append("</fmiModelDescription>")
    return "\n".join(out) + "\n"


def fmi3_build_description(model, sources):
    """sources/buildDescription.xml (FMI 3.0, Build Configurations): the sources to compile, the same list
    as the FMI 2 model description's SourceFiles. A product model lists its one translation unit, which
    includes the rest and keeps everything but the FMI functions static."""
    identifier = model["model"]["identifier"]
    files = "\n".join(f"      <SourceFile{attributes(name=s)}/>" for s in sources)
    description = (
        f"Any platform. A shared library defines no FMI3_FUNCTION_PREFIX; linked into one binary "
        f"with other FMUs, each FMU's is its modelIdentifier and _ ({identifier}_)"
    )
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiBuildDescription fmiVersion="3.0">
  <BuildConfiguration{attributes(modelIdentifier=identifier, description=description)}>
    <SourceFileSet language="C99">
{files}
    </SourceFileSet>
  </BuildConfiguration>
</fmiBuildDescription>
"""


C_TYPE = {"Real": "FMU_REAL", "Integer": "FMU_INTEGER", "Boolean": "FMU_BOOLEAN", "Enumeration": "FMU_ENUMERATION"}
C_CAUSALITY = {
    "independent": "FMU_INDEPENDENT",
    "parameter": "FMU_PARAMETER",
    "input": "FMU_INPUT",
    "output": "FMU_OUTPUT",
}
C_VARIABILITY = {
    "continuous": "FMU_CONTINUOUS",
    "discrete": "FMU_DISCRETE",
    "fixed": "FMU_FIXED",
    "tunable": "FMU_TUNABLE",
}


def c_header(model, instantiation_token, toml_name):
    identifier = model["model"]["identifier"]
    guard = f"{identifier.upper()}_VARIABLES_H"
    enum = "\n".join(f"    VR_{v['name']} = {v['vr']}," for v in model["variable"])
    rows = []
    for v in model["variable"]:
        low = v.get("min", -math.inf)
        high = v.get("max", math.inf)
        if v["type"] == "Enumeration":
            values = [i["value"] for i in model["enumerations"][v["declaredType"]]["items"]]
            low, high = max(min(values), low), min(max(values), high)
        rows.append(
            f'    {{ "{v["name"]}", {C_TYPE[v["type"]]}, {C_CAUSALITY[v["causality"]]}, '
            f"{C_VARIABILITY[v['variability']]}, {c_number(v.get('start', 0.0))}, {c_number(low)}, {c_number(high)} }},"
        )
    table = "\n".join(rows)
    return f"""/* Generated by modelDescription/generate.py from {toml_name}; do not edit. */
#ifndef {guard}
#define {guard}

#include <math.h>
#include "model.h"

#define MODEL_IDENTIFIER "{identifier}"
#define MODEL_TOKEN "{instantiation_token}"
#define MODEL_CLOCK_NAME "{CLOCK_NAME}"
#define MODEL_CLOCK_VR {clock_vr(model)}

enum {{
{enum}
    MODEL_VARIABLE_COUNT = {len(model["variable"])}
}};

/* compile-time checks (a negative array size fails): the core's table
 * holds this model, and time is value reference 0 */
typedef char modelVariableCountFits[MODEL_VARIABLE_COUNT <= FMU_MAX_VARIABLES ? 1 : -1];
typedef char modelTimeIsValueReference0[VR_time == 0 ? 1 : -1];

static const FmuVariable modelVariables[MODEL_VARIABLE_COUNT] = {{
{table}
}};

#endif
"""


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("model", type=Path)
    parser.add_argument("outdir", type=Path)
    parser.add_argument("--fmi2-sources", nargs="+", default=[])
    parser.add_argument("--fmi3-sources", nargs="+", default=[])
    args = parser.parse_args()

    model = load(args.model)
    tok = token(args.model)
    identifier = model["model"]["identifier"]
    files = {
        args.outdir / "fmi2" / "modelDescription.xml": fmi2_description(model, tok, args.fmi2_sources),
        **{
            args.outdir / variant / "modelDescription.xml": fmi3_description(model, tok, variant)
            for variant in FMI3_VARIANTS
        },
        args.outdir / "fmi3" / "buildDescription.xml": fmi3_build_description(model, args.fmi3_sources),
        args.outdir / f"{identifier}_variables.h": c_header(model, tok, args.model.name),
    }
    for path, text in files.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        if not path.exists() or path.read_text(encoding="utf-8") != text:
            path.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
