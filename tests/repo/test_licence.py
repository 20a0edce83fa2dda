"""The licence: LICENSE is the BSD 2-Clause licence, every FMU the build makes
(the products and the fixtures) carries its text as
documentation/licenses/license.txt (the FMI 3 standard's entry point) and
names it and the copyright in its model description, where an importer
reads them; the products' documentation and the README name it too."""

import zipfile
from xml.etree import ElementTree

import pytest
from fmpy import read_model_description

from support.fmu_driver import BUILD_DIR, MODELS, REPO, fmu_file

LICENSE = (REPO / "LICENSE").read_bytes()
COPYRIGHT = "Copyright (c) 2026, the Rate limiter FMUs authors"
FIXTURES = [("fixtures", "FirstOrderLag"), ("fixtures", "Faulty"), ("benchmarks", "PassThrough")]
FMUS = [fmu_file(model, version) for model in MODELS for version in (2, 3)] + [
    BUILD_DIR / folder / f"fmi{version}" / f"{model}.fmu" for folder, model in FIXTURES for version in (2, 3)
]


def test_the_licence_is_bsd_2_clause():
    text = LICENSE.decode()
    assert text.startswith("BSD 2-Clause License\n\n" + COPYRIGHT + "\n")
    assert "1. Redistributions of source code must retain the above copyright notice" in text
    assert "2. Redistributions in binary form must reproduce the above copyright notice" in text
    assert "3." not in text and "endorse or promote" not in text  # the 3-clause licence's third condition
    assert 'THIS SOFTWARE IS PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS "AS IS"' in text


@pytest.mark.parametrize("fmu", FMUS, ids=lambda p: str(p.relative_to(BUILD_DIR)))
def test_every_fmu_carries_the_licence_and_names_it(fmu):
    with zipfile.ZipFile(fmu) as z:
        assert z.read("documentation/licenses/license.txt") == LICENSE
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
    assert root.get("copyright") == COPYRIGHT
    assert root.get("license") == "BSD-2-Clause (the text: documentation/licenses/license.txt)"
    description = read_model_description(str(fmu))  # as an importer reads it
    assert (description.copyright, description.license) == (root.get("copyright"), root.get("license"))


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_the_documentation_names_the_licence(model, version):
    with zipfile.ZipFile(fmu_file(model, version)) as z:
        page = z.read("documentation/index.html").decode()
    assert "<h2>Licence</h2>" in page
    assert COPYRIGHT in page and "BSD-2-Clause" in page
    assert '<a href="licenses/license.txt">' in page  # beside index.html in documentation/


def test_the_readme_names_the_licence():
    readme = (REPO / "README.md").read_text()
    assert "[BSD-2-Clause](LICENSE)" in readme
