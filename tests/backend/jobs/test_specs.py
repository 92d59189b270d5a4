"""Stored job specs: their own versioned record, readable whatever the request schema becomes."""

import pytest
from pydantic import ValidationError

from backend.jobs import JOB_KINDS, decode, spec_of
from backend.jobs.basin import BasinJobCreate
from backend.jobs.control_study import ControlStudyJobCreate
from backend.jobs.gaits import GaitSearchJobCreate
from backend.jobs.loop_mfpt import LoopMfptJobCreate, LoopMfptSpec
from backend.jobs.mfpt import MfptJobCreate
from backend.jobs.mjtf import MJTFJobCreate, MJTFSpec
from backend.jobs.specs import SPEC_VERSION, LegSpec, NoiseSpec, StateSpec, UnreadableSpec, encode
from backend.jobs.sweep import SweepJobCreate
from backend.jobs.viability import ViabilityJobCreate

LEGS = [{"psi0_deg": 30.0, "zeta0": 0.9}]
REQUESTS = [
    MJTFJobCreate(zeta0s=[0.88, 0.9], trials=4, guess={"xdot": -0.93, "ydot": -0.2}),
    SweepJobCreate(kind="sweep", steps=3, basin_grid=0),
    BasinJobCreate(kind="basin", controls=LEGS, grid=4, jumps=5, jump_limit=20),
    GaitSearchJobCreate(kind="gaits", controls=LEGS, grid=2),
    ControlStudyJobCreate(kind="control-study", controllers=["lqr", "pid"], seeds=3, noise={"velocity": 0.02}),
    MfptJobCreate(kind="mfpt", zeta0=0.96, start={"xdot": -0.9, "ydot": 0.1}, grid=12, noise={"pitch_drift_deg": 0}),
    LoopMfptJobCreate(kind="loop-mfpt", controller="pid", target_m=0.5, noise={"velocity": 0.05}, replicas=20, seed=7),
    ViabilityJobCreate(kind="viability", states=12, actions=5, psi0_low_deg=20.0, zeta0_high=0.95),
]


@pytest.mark.parametrize("request_body", REQUESTS, ids=lambda body: body.kind)
def test_a_request_is_stored_as_a_versioned_spec_that_reads_back_the_same(request_body):
    spec = spec_of(request_body)
    stored = encode(spec)
    assert stored["version"] == SPEC_VERSION and stored["kind"] == request_body.kind
    assert decode(stored) == spec
    assert "experiment_id" not in stored, "the job's row holds its experiment"


def test_an_unversioned_spec_of_before_reads_as_version_0():
    old = {"kind": "mjtf", "experiment_id": None, "model": {"preset": "paper", "alpha": None}, "psi0_deg": 30.0,
           "zeta0s": [0.9], "trials": 8, "cap": 1000, "seed": 3, "guess": None}  # fmt: skip
    spec = decode(old)
    assert spec == MJTFSpec(zeta0s=(0.9,), seed=3) and spec.noise == NoiseSpec(), "missing fields: their defaults"


def test_a_spec_the_request_schema_now_refuses_still_reads():
    stored = encode(MJTFSpec(zeta0s=(0.9, 0.9), trials=100_000, cap=100_000))  # repeated, and over the budget
    with pytest.raises(ValidationError):
        JOB_KINDS["mjtf"](**{k: v for k, v in stored.items() if k != "version"})
    assert decode(stored).zeta0s == (0.9, 0.9) and decode(stored).trials == 100_000


def test_a_newer_or_unknown_spec_is_refused_with_a_reason():
    with pytest.raises(UnreadableSpec, match="version 2 is newer"):
        decode({"version": 2, "kind": "mjtf", "zeta0s": [0.9]})
    with pytest.raises(UnreadableSpec, match="unknown job kind 'no-such-kind'"):
        decode({"version": 1, "kind": "no-such-kind"})


def test_parts_decode_to_their_types():
    spec = decode(encode(spec_of(REQUESTS[2])))
    assert spec.controls == (LegSpec(30.0, 0.9),) and spec.guess is None
    assert decode(encode(spec_of(REQUESTS[0]))).guess == StateSpec(-0.93, -0.2)


def test_a_controllers_mfpt_spec_keeps_its_law_splitting_and_no_pitch_drift():
    spec = decode(encode(spec_of(REQUESTS[6])))
    assert spec == LoopMfptSpec(controller="pid", target_m=0.5, noise=NoiseSpec(velocity=0.05, pitch_drift_deg=0.0),
                                replicas=20, seed=7)  # fmt: skip
    assert decode({"version": 1, "kind": "loop-mfpt"}).noise.pitch_drift_deg == 0.0, "its default: no drift"
