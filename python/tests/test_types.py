"""The TypedDicts of the stubs against the JSON Schemas of the documents (`glossmeter schema --output-format
...`, derived from the library's document types): each TypedDict has exactly the properties of its definition,
and exactly its required ones required, so a field added to a document and missing in Python fails here."""
import json
import subprocess

import pytest

import glossmeter
from conftest import ROOT, cli_binary

# (TypedDict, the output whose schema defines it, its definition in the schema's $defs; None: the top object)
TYPES = [
    (glossmeter.Reading, "measure", "ReadingDoc"),
    (glossmeter.Envelope, "measure", "EnvelopeDoc"),
    (glossmeter.EnvelopeVariation, "measure", "VariationDoc"),
    (glossmeter.BudgetLine, "measure", "BudgetLineDoc"),
    (glossmeter.Sheet, "sheet", None),
    (glossmeter.SheetInfo, "sheet", "SheetDoc"),
    (glossmeter.SheetRow, "sheet", "SheetRowDoc"),
    (glossmeter.CompareReport, "compare", None),
    (glossmeter.SheetInfo, "compare", "SheetDoc"),
    (glossmeter.Comparison, "compare", "ComparisonDoc"),
    (glossmeter.Allowance, "compare", "AllowanceDoc"),
    (glossmeter.AllowancePart, "compare", "AllowancePartDoc"),
    (glossmeter.BudgetLine, "compare", "BudgetLineDoc"),
    (glossmeter.VerdictRule, "compare", "RuleDoc"),
    (glossmeter.CompareSummary, "compare", "SummaryDoc"),
    (glossmeter.ColourDifference, "compare", "ColourDifferenceDoc"),
    (glossmeter.Baseline, "compare", "BaselineDoc"),
    (glossmeter.Drift, "compare", "DriftDoc"),
    (glossmeter.SweepPoint, "sweep", None),
    (glossmeter.SweepReading, "sweep", "SweepReadingDoc"),
    (glossmeter.FitReport, "fit", "FitDoc"),
    (glossmeter.FitParameter, "fit", "ParameterDoc"),
    (glossmeter.FitTarget, "fit", "TargetDoc"),
    (glossmeter.ProfileReport, "profile", None),
    (glossmeter.Material, "profile", "ProfileMaterialDoc"),
    (glossmeter.ProfileBudget, "profile", "ProfileBudgetDoc"),
    (glossmeter.ProfileRow, "profile", "ProfileRowDoc"),
    (glossmeter.ConvergenceReport, "convergence", None),
    (glossmeter.Material, "convergence", "ProfileMaterialDoc"),
    (glossmeter.ConvergenceReference, "convergence", "ReferenceDoc"),
    (glossmeter.ConvergenceTiming, "convergence", "TimingDoc"),
    (glossmeter.ConvergenceRow, "convergence", "ConvergenceRowDoc"),
]


def definition(output, name):
    schema = glossmeter.schema(output)
    return schema if name is None else schema["$defs"][name]


@pytest.mark.parametrize("typed, output, name", TYPES, ids=lambda x: getattr(x, "__name__", str(x)))
def test_each_typed_dict_has_the_fields_of_its_schema(typed, output, name):
    d = definition(output, name)
    keys = set(typed.__required_keys__) | set(typed.__optional_keys__)
    assert keys == set(d["properties"]), (sorted(keys ^ set(d["properties"])))
    assert set(typed.__required_keys__) == set(d.get("required", [])), typed.__name__


def test_the_reading_type_has_the_data_uncertainty_of_measured_tables():
    # Lost once from the hand-written type (docs/accuracy.md §Data uncertainty of measured tables).
    assert "data_uncertainty" in glossmeter.Reading.__optional_keys__
    readings = glossmeter.measure(ROOT / "fixtures" / "materials" / "rgl" / "beckmann-iso-32.json", "astm-d523-60")
    assert all(set(r) <= set(glossmeter.Reading.__annotations__) | set(glossmeter.Reading.__optional_keys__)
               for r in readings)
    assert any("data_uncertainty" in r for r in readings)


def test_every_definition_of_the_documents_has_its_typed_dict():
    """A new nested document (a new $defs entry) needs its TypedDict too: the definitions not listed are the
    ones Python never returns (`measure` returns the readings alone; a fit that cannot run raises)."""
    never = {("measure", name) for name in ["MeasureDoc", "MaterialDoc", "BaselineDoc", "DriftDoc", "BatchDoc",
                                            "BatchMaterialDoc", "BatchReadingDoc"]}
    never |= {("fit", name) for name in ["FitFailureDoc", "FreeParameterDoc", "TargetAskedDoc"]}
    listed = {(output, name) for _, output, name in TYPES}
    for output in {o for _, o, _ in TYPES}:
        for name in glossmeter.schema(output).get("$defs", {}):
            assert (output, name) in never | listed, (output, name)


@pytest.mark.parametrize("output", ["measure", "compare", "sweep", "fit", "profile", "convergence", "sheet"])
def test_the_schemas_are_the_command_line_s(output):
    exe = cli_binary()
    if exe is None:
        pytest.skip("the release CLI is not built (cargo build --release); .ci/run builds it first")
    p = subprocess.run([exe, "schema", "--output-format", output], capture_output=True, text=True, check=True)
    assert json.loads(p.stdout) == glossmeter.schema(output)
