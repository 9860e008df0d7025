# SPDX-License-Identifier: GPL-3.0-or-later
"""The experiment file's JSON Schema (`fiberfluid schema`), checked by an
independent validator (jsonschema, Debian's python3-jsonschema): every shipped
experiment and every experiment the fuzzer starts from is valid; a misspelt
field, a wrong type and a value outside a choice are not, as the reader refuses them."""
import glob
import json
import os

import jsonschema
import pytest

import fiberfluid

SOURCE = os.environ.get("FIBERFLUID_SOURCE_DIR",
                        os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


@pytest.fixture(scope="module")
def validator():
    schema = fiberfluid.schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def documents():
    files = sorted(glob.glob(os.path.join(SOURCE, "experiments", "*.json")))
    files += sorted(glob.glob(os.path.join(SOURCE, "tests", "fuzz", "seeds", "experiment", "*.json")))
    for name in files:
        with open(name) as f:
            try:
                yield name, json.load(f)
            except (ValueError, RecursionError):
                continue  # a seed that is not JSON on purpose (nested too deep)


def test_every_shipped_and_seed_experiment_is_valid(validator):
    checked = 0
    for name, document in documents():
        errors = [f"{list(e.absolute_path)}: {e.message[:200]}" for e in validator.iter_errors(document)]
        assert not errors, f"{name}: {errors}"
        checked += 1
    assert checked >= 30


def test_what_the_reader_refuses_the_schema_refuses(validator):
    with open(os.path.join(SOURCE, "experiments", "liver_paddles.json")) as f:
        good = json.load(f)
    assert validator.is_valid(good)
    for path, value in ((("material", "colour"), "red"),       # an unknown field
                        (("material", "gamma"), "high"),        # a string for a number
                        (("material", "gamma"), -1),            # below its minimum
                        (("stepping", "steps"), 2.5),           # a number for a whole number
                        (("stepping", "scheme"), "implicit"),   # outside the choices
                        (("paddles", 0, "side"), "left"),
                        (("variants", 0, "colour"), 1),
                        # a variant named like a file of the result (issue 43)
                        (("variants", 0, "name"), "summary.json"),
                        (("variants", 0, "name"), "fit_force_3.csv")):
        bad = json.loads(json.dumps(good))
        where = bad
        for key in path[:-1]:
            where = where[key]
        where[path[-1]] = value
        assert not validator.is_valid(bad), path
    # A variant may remove a field with null (a JSON merge patch).
    patched = json.loads(json.dumps(good))
    patched["variants"][0]["fibers"] = None
    assert patched["variants"][1]["material"]["law"]["Y"] is None  # as shipped
    assert validator.is_valid(patched)
    # The law types are the reader's, the force targets' fields are there.
    laws = validator.schema["properties"]["material"]["anyOf"][0]["properties"]["law"]
    assert set(laws["properties"]["type"]["enum"]) >= {"constant", "exponential", "bilinear", "tabulated"}
    targets = validator.schema["properties"]["fit"]["properties"]["targets"]["items"]["properties"]
    assert {"paddle", "support", "axis", "travel_units", "force_units", "weight"} <= set(targets)


def test_the_schema_refuses_what_the_reader_refuses_when_given(validator):
    """Issue 43: fields read only when given, a choice re-read as a string,
    and a field the reader refuses where it is, came out as any value."""
    with open(os.path.join(SOURCE, "experiments", "bending_phantom.json")) as f:
        good = json.load(f)
    assert validator.is_valid(good)

    def changed(change):
        d = json.loads(json.dumps(good))
        change(d)
        return d

    for bad in (changed(lambda d: d["stepping"].update({"control": "banana"})),
                changed(lambda d: d["surface"].update({"generator": "box2"})),
                changed(lambda d: d["surface"].update({"segments": "many"})),
                changed(lambda d: d["loads"][0].update({"schedule": "ramp2"})),
                changed(lambda d: d["supports"][0].update({"vertices": "all"})),
                changed(lambda d: d["surface"].update({"file": 5})),
                changed(lambda d: d.update({"prescribed": [{"where": "x >= 0.1", "layer": "mirror",
                                                            "displacement": [0, 0, 0.01]}]}))):
        assert not validator.is_valid(bad)
    for fine in (changed(lambda d: d["loads"][0].update({"schedule": [0.5, 1]})),
                 changed(lambda d: d["stepping"].update({"control": "arc_length"})),
                 changed(lambda d: d.update({"$schema": "fiberfluid.schema.json"}))):
        assert validator.is_valid(fine), list(validator.iter_errors(fine))[:1]
