"""The MFPT jobs' bodies (backend/jobs/mfpt.py, loop_mfpt.py): a controller's MFPT by splitting —
its law one of the four, no pitch drift (sim_core's own words, at the field), replicas x runs bounded
within the work budget. The gait's chain (``mfpt``) is tested with the other kinds (test_kinds.py)."""

import pytest

from backend.jobs import JobCreate, worst_case_jumps
from backend.jobs.loop_mfpt import LOOP_MFPT_MAX_REPLICA_RUNS, LoopMfptJobCreate
from backend.schemas import ControllerKind
from backend.schemas.job_budget import WORK_BUDGET_JUMPS
from sim_core.control.registry import KINDS
from sim_core.model.noise import NoiseModel
from sim_core.model.validation import ParameterError
from sim_core.robustness.splitting import SplittingOptions, check_metastable
from tests.backend.schemas.refusals import accepted, refusal_messages, refused

LOOP = {"kind": "loop-mfpt"}


def test_a_controllers_mfpt_is_its_own_kind_with_no_pitch_drift_by_default():
    job = accepted(JobCreate, LOOP | {"controller": "deadbeat", "noise": {"velocity": 0.05}})
    assert type(job) is LoopMfptJobCreate and job.controller == "deadbeat"
    assert job.noise.pitch_drift_deg == 0.0 and job.noise.velocity == 0.05
    assert [kind.value for kind in ControllerKind] == list(KINDS), "the four laws, sim_core's names"


def test_its_splitting_fields_are_within_sim_cores_ranges():
    """Every body accepted makes SplittingOptions sim_core takes (at the ranges' ends too)."""
    for replicas, runs in ((2, 2), (1000, 20), (312, 64)):
        job = accepted(LoopMfptJobCreate, LOOP | {"replicas": replicas, "runs": runs, "seed": 2**32 - 1})
        SplittingOptions(replicas=job.replicas, runs=job.runs, seed=job.seed)


def test_pitch_drift_is_refused_at_its_field_in_sim_cores_words():
    change = {"noise": {"velocity": 0.05, "pitch_drift_deg": 0.5}}
    assert refused(JobCreate, LOOP | change) == [("loop-mfpt", "noise", "pitch_drift_deg")]
    with pytest.raises(ParameterError) as sim_core:
        check_metastable(NoiseModel(velocity=0.05, pitch_drift_deg=0.5))
    assert sim_core.value.field == "noise.pitch_drift_deg"
    assert sim_core.value.message in refusal_messages(JobCreate, LOOP | change)


@pytest.mark.parametrize(
    ("change", "where", "says"),
    [
        ({"controller": "mpc"}, ("controller",), "'pid', 'pid-pitch', 'lqr', 'deadbeat' or 'placement'"),
        ({"target_m": 0.0}, ("target_m",), "greater than 0"),
        ({"target_m": 2.5}, ("target_m",), "less than or equal to 2"),
        ({"psi0_deg": 70}, ("psi0_deg",), "less than or equal to 60"),
        ({"start_zeta0": 1.0}, ("start_zeta0",), "less than 1"),
        ({"replicas": 1}, ("replicas",), "greater than or equal to 2"),
        ({"replicas": 1001}, ("replicas",), "less than or equal to 1000"),
        ({"runs": 257}, ("runs",), "less than or equal to 256"),
        ({"seed": 2**32}, ("seed",), "less than 4294967296"),
        ({"noise": {"pitch_drift_deg": 30.0}}, ("noise", "pitch_drift_deg"), "less than 30"),
        ({"noise": {"velocity": 0, "psi0_deg": 0, "zeta0": 0}}, ("noise",), "needs some noise"),
        ({"grid": 20}, ("grid",), "Extra inputs are not permitted"),  # the chain's field, not the loop's
    ],
)
def test_a_bad_controller_mfpt_job_is_refused_naming_the_field(change, where, says):
    assert refused(LoopMfptJobCreate, LOOP | change) == [where]
    assert says in refusal_messages(LoopMfptJobCreate, LOOP | change)


def test_replicas_times_runs_is_bounded_within_the_work_budget_and_the_refusal_says_so():
    largest = accepted(LoopMfptJobCreate, LOOP | {"replicas": 1000, "runs": LOOP_MFPT_MAX_REPLICA_RUNS // 1000})
    jumps, formula = worst_case_jumps(largest)
    assert jumps <= WORK_BUDGET_JUMPS and formula.startswith("replicas x runs x ")
    assert refused(LoopMfptJobCreate, LOOP | {"replicas": 1000, "runs": 64}) == [()]
    says = refusal_messages(LoopMfptJobCreate, LOOP | {"replicas": 1000, "runs": 64})
    assert f"replicas x runs must be at most {LOOP_MFPT_MAX_REPLICA_RUNS}" in says and "1000 x 64 = 64000" in says
