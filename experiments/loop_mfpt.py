"""A controller's mean first-passage time, as the control study sets its climb up: the law named,
designed for the model (:func:`experiments.control_study.laws_for`), started where the study's
trials start, its MFPT estimated by splitting (:mod:`sim_core.robustness.splitting`).

``parkour mfpt --controller NAME`` calls :func:`run`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from experiments.control_study import Config as StudyConfig
from experiments.control_study import laws_for
from sim_core.chunks import Progress
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams
from sim_core.robustness.splitting import LoopMfpt, SplittingOptions, check_metastable, loop_mfpt


@dataclass(frozen=True)
class Config:
    """The law by name, the height it holds [m], the climb's nominal leg angle [deg] and first
    zeta0, the noise (no pitch drift) and how hard the splitting works."""

    controller: str = "lqr"
    target_m: float = 0.55
    psi0_deg: float = 35.0
    start_zeta0: float = 0.9
    noise: NoiseModel = field(default_factory=lambda: NoiseModel(pitch_drift_deg=0.0))
    options: SplittingOptions = field(default_factory=SplittingOptions)


def run(model: ModelParams, leg_length: float, config: Config, progress: Progress | None = None) -> dict:
    """The ``parkour mfpt --controller`` JSON: :meth:`sim_core.robustness.splitting.LoopMfpt.to_dict` with the
    climb's controls, start and target in metres. ``leg_length`` [m] converts the target.

    Raises:
        ParameterError: an unknown controller, a target out of the chute, noise splitting cannot
            take; naming the field.
    """
    check_metastable(config.noise)
    study = StudyConfig(controllers=(config.controller,), target_m=config.target_m, psi0_deg=config.psi0_deg,
                        start_zeta0=config.start_zeta0, noise=config.noise)  # fmt: skip
    climb, (law,) = laws_for(model, study, leg_length)
    result: LoopMfpt = loop_mfpt(model, law, climb.start, config.start_zeta0, config.noise, config.options, progress)
    return {
        **result.to_dict(),
        "target_m": config.target_m,
        "controls": {"psi0_deg": config.psi0_deg, "zeta0": config.start_zeta0},
        "start": [float(value) for value in climb.start],
    }
