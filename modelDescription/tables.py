#!/usr/bin/env python3
"""The tables of docs/ that restate a model description, generated from the
models' TOML files (the single source of truth), between the markers

    <!-- generated: variables <Model> -->  ...  <!-- end generated -->

    tables.py DOC.md MODEL.toml ... [--write]

Without --write it exits 1 and names the stale tables if the document
differs from what the TOML files give (the test runs it so); with --write
it rewrites them (cmake --build build --target docs), and a model that has
no table yet gets a section with one at the end. Standard library only.
"""

import argparse
import re
import sys
from pathlib import Path

from generate import load, xml_number  # this folder's generator: one reading of the TOML

FMI_TYPE = {"Real": "Real / Float64", "Integer": "Integer / Int32", "Boolean": "Boolean"}
MARKER = re.compile(r"(<!-- generated: variables (\w+) -->\n)(.*?)(<!-- end generated -->)", re.S)


def literal(value):
    """A value as the model description writes it, integers without ".0"."""
    text = xml_number(value)
    infinite = {"INF": "+inf", "-INF": "-inf"}
    if text in infinite:
        return infinite[text]
    return text.removesuffix(".0") if isinstance(value, float) else text


def fmi_type(v, model):
    if v["type"] == "Enumeration":
        items = model["enumerations"][v["declaredType"]]["items"]
        text = f"Enumeration `{v['declaredType']}` (" + ", ".join(f"{i['name']} {i['value']}" for i in items) + ")"
    else:
        text = FMI_TYPE[v["type"]]
    for bound in ("min", "max"):
        if bound in v:
            text += f", {bound} {literal(v[bound])}"
    return text


def causality(v):
    return v["causality"] + (f", {v['variability']}" if v["causality"] == "parameter" else "")


def table(model):
    """The variable table: with the vendor's pin, type and default when the
    TOML gives them (the vendor models), else with each variable's meaning."""
    variables = model["variable"]
    vendor = any("vendor" in v for v in variables)
    if vendor:
        rows = [
            "| vendor pin | data type | default | FMU variable | FMI type | causality | start | unit |",
            "|---|---|---|---|---|---|---|---|",
        ]
    else:
        rows = ["| name | vr | causality | type | start | unit | meaning |", "|---|---|---|---|---|---|---|"]
    for v in variables:
        if v["causality"] == "independent" and vendor:
            continue
        start = literal(v["start"]) if "start" in v else ""
        unit = v.get("unit", "")
        if vendor:
            pin = v.get("vendor", {})
            rows.append(
                f"| {pin.get('pin', '')} | {pin.get('type', '')} | {pin.get('default', '')} | "
                f"`{v['name']}` (vr {v['vr']}) | {fmi_type(v, model)} | {causality(v)} | {start} | {unit} |"
            )
        else:
            rows.append(
                f"| `{v['name']}` | {v['vr']} | {causality(v)} | {fmi_type(v, model)} | {start} | {unit} | "
                f"{v.get('description', '')} |"
            )
    return "\n".join(rows) + "\n"


def render(document, models):
    def replace(match):
        name = match.group(2)
        if name not in models:
            sys.exit(f"{name}: no TOML file given for this table")
        return match.group(1) + table(models[name]) + match.group(4)

    text = MARKER.sub(replace, document)
    tabled = {m.group(2) for m in MARKER.finditer(document)}
    for name in sorted(set(models) - tabled):
        text += (
            f"\n### {name}\n\n{models[name]['model']['description']}\n\n"
            f"<!-- generated: variables {name} -->\n{table(models[name])}<!-- end generated -->\n"
        )
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("document", type=Path)
    parser.add_argument("models", type=Path, nargs="+")
    parser.add_argument("--write", action="store_true")
    args = parser.parse_args()
    models = {}
    for path in args.models:
        model = load(path)
        models[model["model"]["identifier"]] = model
    text = args.document.read_text(encoding="utf-8")
    fresh = render(text, models)
    if args.write:
        if fresh != text:
            args.document.write_text(fresh, encoding="utf-8")
        return 0
    if fresh != text:
        stale = [
            m.group(2)
            for m, n in zip(MARKER.finditer(text), MARKER.finditer(fresh), strict=False)
            if m.group(0) != n.group(0)
        ]
        stale += sorted(set(models) - {m.group(2) for m in MARKER.finditer(text)})
        print(f"{args.document}: stale tables {stale}; run cmake --build build --target docs")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
