"""FMI-LS-REF for the tests: the standard's manifest schema (schema/, as
github.com/modelica/fmi-ls-ref publishes it, with its example) loaded
without a network (its two imports are FMI 3 schemas fmpy ships), and the
SSP 1.0 parameter-value schema fmpy ships."""

from pathlib import Path

SCHEMA_DIR = Path(__file__).resolve().parent / "schema"
EXAMPLE = SCHEMA_DIR / "fmi_ls_ref_manifest_example.xml"
FOLDER = "extra/org.fmi-standard.fmi-ls-ref"


def _fmpy_schemas():
    import fmpy

    return Path(fmpy.__file__).parent


def manifest_schema():
    """The LS-REF manifest schema as an lxml XMLSchema."""
    from lxml import etree

    fmi3 = _fmpy_schemas() / "schema" / "fmi3"

    class LocalImports(etree.Resolver):
        def resolve(self, url, pubid, context):
            name = url.rsplit("/", 1)[-1]
            if name in ("fmi3LayeredStandardManifest.xsd", "fmi3Annotation.xsd"):
                return self.resolve_filename(str(fmi3 / name), context)
            return None

    parser = etree.XMLParser(no_network=True)
    parser.resolvers.add(LocalImports())
    return etree.XMLSchema(etree.parse(str(SCHEMA_DIR / "fmi3LayeredStandardReferenceManifest.xsd"), parser))


def ssv_schema():
    from lxml import etree

    return etree.XMLSchema(etree.parse(str(_fmpy_schemas() / "ssp" / "schema" / "SystemStructureParameterValues.xsd")))
