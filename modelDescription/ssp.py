#!/usr/bin/env python3
"""The SSP 1.0 package of a system described in a TOML file
(modelDescription/systems/RateLimiterLoop.toml): SystemStructure.ssd with the
components, their connectors (kind and type from the FMUs' model
descriptions) and connections, the parameter values in an SSV file per
component (bound to it: the binding every importer tested reads), both
FMUs under resources/. Beside the standard content the system carries
OMSimulator's annotation naming its master algorithm (a fixed-step master
at the system's step size): OMSimulator refuses a system without one. The zip's entries are sorted and time-stamped
2000-01-01, so the same inputs give the same bytes.

    ssp.py <system.toml> <build dir> <out.ssp>
"""

import sys
import tomllib
import zipfile
from pathlib import Path
from xml.sax.saxutils import quoteattr

from fmpy import read_model_description

SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
OMS = "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"
TYPES = {
    "Real": "Real",
    "Float64": "Real",
    "Integer": "Integer",
    "Int32": "Integer",
    "Boolean": "Boolean",
    "String": "String",
}
KINDS = {"input": "input", "output": "output", "parameter": "parameter"}
STAMP = (2000, 1, 1, 0, 0, 0)


def connector(variable):
    kind = KINDS[variable.causality]
    type_name = TYPES.get(variable.type)
    if type_name is None:  # an enumeration: its type's name
        element = f"<ssc:Enumeration name={quoteattr(variable.declaredType.name)}/>"
    else:
        element = f"<ssc:{type_name}/>"
    return f'          <ssd:Connector name={quoteattr(variable.name)} kind="{kind}">{element}</ssd:Connector>'


def parameter_value(variable, value):
    type_name = TYPES.get(variable.type, "Integer")
    literal = str(value).lower() if isinstance(value, bool) else repr(value)
    return f'    <ssv:Parameter name={quoteattr(variable.name)}><ssv:{type_name} value="{literal}"/></ssv:Parameter>'


def package(system_toml, build_dir, out):
    spec = tomllib.loads(Path(system_toml).read_text())
    system = spec["system"]
    connected = {}
    for c in spec["connection"]:
        for end in (c["from"], c["to"]):
            element, name = end.split(".", 1)
            connected.setdefault(element, []).append(name)
    components, files = [], {}
    for component in spec["component"]:
        fmu = Path(build_dir) / component["fmu"]
        variables = {v.name: v for v in read_model_description(str(fmu)).modelVariables}
        names = [
            n
            for n in variables
            if n in connected.get(component["name"], [])
            or n in component["parameters"]
            or variables[n].causality == "output"
        ]
        connectors = [connector(variables[n]) for n in names if variables[n].causality in KINDS]
        ssv_name = f"resources/{component['name']}.ssv"
        files[ssv_name] = "\n".join(
            [
                '<?xml version="1.0" encoding="UTF-8"?>',
                f'<ssv:ParameterSet xmlns:ssc="{SSC}" xmlns:ssv="{SSV}" version="1.0"'
                f" name={quoteattr(system['name'])}>",
                "  <ssv:Parameters>",
            ]
            + [parameter_value(variables[n], v) for n, v in component["parameters"].items()]
            + ["  </ssv:Parameters>", "</ssv:ParameterSet>", ""]
        )
        files[f"resources/{fmu.name}"] = fmu.read_bytes()
        components.append(
            "\n".join(
                [
                    f'      <ssd:Component name={quoteattr(component["name"])} type="application/x-fmu-sharedlibrary" '
                    f'source="resources/{fmu.name}">',
                    "        <ssd:Connectors>",
                ]
                + connectors
                + [
                    "        </ssd:Connectors>",
                    "        <ssd:ParameterBindings>",
                    f'          <ssd:ParameterBinding source="{ssv_name}"/>',
                    "        </ssd:ParameterBindings>",
                    "      </ssd:Component>",
                ]
            )
        )
    connections = []
    for c in spec["connection"]:
        (start, start_connector), (end, end_connector) = c["from"].split(".", 1), c["to"].split(".", 1)
        connections.append(
            f'      <ssd:Connection startElement="{start}" startConnector="{start_connector}" '
            f'endElement="{end}" endConnector="{end_connector}"/>'
        )
    files["SystemStructure.ssd"] = "\n".join(
        [
            '<?xml version="1.0" encoding="UTF-8"?>',
            f'<ssd:SystemStructureDescription xmlns:ssc="{SSC}" xmlns:ssd="{SSD}" xmlns:oms="{OMS}" version="1.0" '
            f"name={quoteattr(system['name'])}>",
            f"  <ssd:System name={quoteattr(system['name'])} description={quoteattr(system['description'])}>",
            "    <ssd:Elements>",
        ]
        + components
        + ["    </ssd:Elements>", "    <ssd:Connections>"]
        + connections
        + [
            "    </ssd:Connections>",
            "    <ssd:Annotations>",
            '      <ssc:Annotation type="org.openmodelica">',
            "        <oms:Annotations>",
            "          <oms:SimulationInformation>",
            f'            <oms:FixedStepMaster description="oms-ma" stepSize="{system["stepSize"]!r}" '
            'relativeTolerance="1e-06"/>',
            "          </oms:SimulationInformation>",
            "        </oms:Annotations>",
            "      </ssc:Annotation>",
            "    </ssd:Annotations>",
            "  </ssd:System>",
            f'  <ssd:DefaultExperiment startTime="{system["startTime"]!r}" stopTime="{system["stopTime"]!r}"/>',
            "</ssd:SystemStructureDescription>",
            "",
        ]
    )
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
        for name in sorted(files):
            info = zipfile.ZipInfo(name, STAMP)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            data = files[name]
            z.writestr(info, data.encode() if isinstance(data, str) else data)


if __name__ == "__main__":
    package(*sys.argv[1:])
