"""The provenance and JSON helpers every output uses."""

import json
import math
import re
from dataclasses import dataclass

import numpy as np

from experiments.manifest import code_version, json_safe, metadata


@dataclass(frozen=True)
class _Config:
    zeta0: float
    seeds: tuple[int, ...]


def test_json_safe_turns_nan_and_infinities_into_null():
    assert json_safe([math.nan, math.inf, -math.inf, 1.5]) == [None, None, None, 1.5]
    assert json_safe(np.array([np.nan, 2.0])) == [None, 2.0]
    assert json_safe(np.float64("inf")) is None


def test_json_safe_converts_numpy_types_to_python_ones():
    converted = json_safe({"n": np.int64(3), "x": np.float32(0.5), "ok": np.bool_(True), "a": np.arange(2)})
    assert converted == {"n": 3, "x": 0.5, "ok": True, "a": [0, 1]}
    assert [type(converted[key]) for key in ("n", "x", "ok")] == [int, float, bool]
    assert isinstance(converted["a"][0], int)


def test_json_safe_recurses_into_containers_and_dataclasses():
    value = {1: (_Config(math.nan, (1, 2)), [np.array([[math.inf]])]), "s": "text", "none": None}
    assert json_safe(value) == {"1": [{"zeta0": None, "seeds": [1, 2]}, [[[None]]]], "s": "text", "none": None}
    json.dumps(json_safe(value), allow_nan=False)  # strict JSON


def test_code_version_is_one_line_naming_the_checkout():
    version = code_version()
    assert version and "\n" not in version
    assert re.fullmatch(r"[0-9a-f]{7,40}(-dirty)?|.*-g[0-9a-f]{7,40}(-dirty)?|parkourlab \S+", version), version


def test_metadata_is_the_manifest_of_a_study():
    manifest = metadata({"alpha": 77.6}, _Config(0.9, (1,)))
    assert set(manifest) == {"config", "model", "code_version", "created"}
    assert manifest["code_version"] == code_version()
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\+00:00", manifest["created"]), "UTC, to the second"
