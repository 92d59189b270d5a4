"""Which model a request means (backend/services/presets.py): a built-in preset, a calibration stored
by name (its fitted robot, offsets and nondimensional numbers), or an error naming the field and the
presets there are."""

import asyncio
import dataclasses
import subprocess
import sys

import pytest

from backend.jobs.mjtf import MJTFJobCreate
from backend.schemas import ModelIn
from backend.services.presets import FITTED, ResolvedModel, preset_resolved, resolve_model, with_preset_resolved
from backend.store.models import ModelPreset
from sim_core.model.controls import NO_OFFSETS, LegOffsets
from sim_core.model.errors import ParameterError
from sim_core.model.presets import PRESETS

PAPER = PRESETS["paper"]
FITTED_ROBOT = dataclasses.replace(PAPER, stiffness=600.0, c_zeta=1.3, c_psi=0.7)  # what a fit might find
OFFSETS = LegOffsets(psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))


@pytest.fixture
def stored(session):
    """A calibration stored as ``table.v1``, refining the paper preset."""
    session.add(
        ModelPreset(name="table.v1", base="paper", physical=dataclasses.asdict(FITTED_ROBOT), offsets=OFFSETS.to_dict(),
                    fit={}, runs=[1, 2], code_version="test")
    )  # fmt: skip
    session.commit()
    return session


def test_a_built_in_preset_is_its_robot_without_offsets_or_fitted_numbers():
    resolved = resolve_model(None, "paper")
    assert resolved == ResolvedModel("paper", PAPER)
    assert resolved.offsets == NO_OFFSETS and resolved.fitted == {}
    assert resolved.model() == PAPER.to_model()


def test_overrides_replace_the_models_numbers_and_none_leaves_them():
    model = resolve_model(None, "paper").model(alpha=40.0, mu=None, c_psi=0.5)
    paper = PAPER.to_model()
    assert (model.alpha, model.c_psi) == (40.0, 0.5)
    assert (model.mu, model.d_hat, model.c_zeta) == (paper.mu, paper.d_hat, paper.c_zeta)


def test_a_stored_calibration_is_its_fitted_robot_offsets_and_base(stored):
    resolved = resolve_model(stored, "table.v1")
    assert (resolved.preset, resolved.robot, resolved.offsets) == ("paper", FITTED_ROBOT, OFFSETS)
    fitted_model = FITTED_ROBOT.to_model()
    assert resolved.fitted == {name: getattr(fitted_model, name) for name in FITTED}
    assert set(resolved.fitted) == {"alpha", "c_zeta", "c_psi"}
    assert resolved.model().alpha == pytest.approx(fitted_model.alpha)
    assert fitted_model.alpha != pytest.approx(PAPER.to_model().alpha), "the fitted robot, not the base's"


def test_an_unknown_name_without_a_store_names_the_field_and_the_built_in_presets():
    with pytest.raises(ParameterError) as unknown:
        resolve_model(None, "table.v1")
    assert unknown.value.field == "preset"
    assert str(unknown.value) == "preset: unknown preset 'table.v1'; known presets: paper"


def test_an_unknown_name_lists_the_stored_presets_too_under_the_field_asked_for(stored):
    with pytest.raises(ParameterError) as unknown:
        resolve_model(stored, "nothing", field="model.preset")
    assert unknown.value.field == "model.preset"
    assert unknown.value.message == "unknown preset 'nothing'; known presets: paper, table.v1"


def test_a_built_in_preset_needs_neither_the_store_nor_sqlalchemy():
    code = (
        "import sys\n"
        "from backend.services.presets import resolve_model\n"
        "resolve_model(None, 'paper')\n"
        "print(sorted(name for name in ('sqlalchemy', 'backend.repositories.calibrations') if name in sys.modules))"
    )
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert loaded == "[]"


def test_a_job_keeps_a_stored_presets_numbers_where_it_does_not_override_them(stored):
    body = MJTFJobCreate(zeta0s=[0.9], model=ModelIn(preset="table.v1", c_psi=0.2))
    resolved = with_preset_resolved(stored, body)
    fitted = resolve_model(stored, "table.v1").fitted
    assert resolved.model.preset == "paper", "the base: the job reads the same if the preset is deleted"
    assert (resolved.model.alpha, resolved.model.c_zeta) == (fitted["alpha"], fitted["c_zeta"])
    assert resolved.model.c_psi == 0.2, "the request's override stays"
    assert body.model.preset == "table.v1", "the request itself is not changed"


def test_a_job_on_a_built_in_preset_passes_through_and_an_unknown_one_names_model_preset(session):
    body = MJTFJobCreate(zeta0s=[0.9])
    assert with_preset_resolved(session, body) is body
    with pytest.raises(ParameterError) as unknown:
        with_preset_resolved(session, MJTFJobCreate(zeta0s=[0.9], model=ModelIn(preset="nothing")))
    assert unknown.value.field == "model.preset"


def test_an_async_caller_resolves_a_built_in_preset_without_a_session_and_a_stored_one_in_one(stored):
    calls = []

    async def in_session(work, *args):
        calls.append(work)
        return work(stored, *args)

    built_in = MJTFJobCreate(zeta0s=[0.9])
    assert asyncio.run(preset_resolved(in_session, built_in)) is built_in and calls == []
    on_stored = MJTFJobCreate(zeta0s=[0.9], model=ModelIn(preset="table.v1"))
    assert asyncio.run(preset_resolved(in_session, on_stored)).model.preset == "paper"
    assert calls == [with_preset_resolved]
