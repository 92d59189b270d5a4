"""The noise a job climbs under, as a request gives it: :class:`~sim_core.model.noise.NoiseModel`'s
fields with its defaults and ranges (SIGMA_LIMITS, ASYMMETRY_LIMITS), one home for every job kind."""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from backend.schemas.common import Strict
from sim_core.model.noise import ASYMMETRY_LIMITS, SIGMA_LIMITS, NoiseModel

_NOISE = NoiseModel()  # the noise's defaults


class NoiseIn(Strict):
    psi0_deg: Annotated[
        float,
        Field(ge=0.0, lt=SIGMA_LIMITS["psi0_deg"], description="the leg angle's standard deviation at touchdown [deg]"),
    ] = _NOISE.psi0_deg
    zeta0: Annotated[
        float,
        Field(ge=0.0, lt=SIGMA_LIMITS["zeta0"], description="the leg length's standard deviation at touchdown [l0]"),
    ] = _NOISE.zeta0
    velocity: Annotated[
        float,
        Field(
            ge=0.0,
            lt=SIGMA_LIMITS["velocity"],
            description="each section-state component's standard deviation after a jump [sqrt(g l0)]",
        ),
    ] = _NOISE.velocity
    pitch_drift_deg: Annotated[
        float,
        Field(
            ge=0.0,
            lt=SIGMA_LIMITS["pitch_drift_deg"],
            description="the standard deviation of the pitch random walk's step a jump [deg]",
        ),
    ] = _NOISE.pitch_drift_deg
    asymmetry_psi0_deg: Annotated[
        float,
        Field(
            gt=-ASYMMETRY_LIMITS["asymmetry_psi0_deg"],
            lt=ASYMMETRY_LIMITS["asymmetry_psi0_deg"],
            description="the right leg's constant leg-angle offset [deg]",
        ),
    ] = _NOISE.asymmetry_psi0_deg
    asymmetry_zeta0: Annotated[
        float,
        Field(
            gt=-ASYMMETRY_LIMITS["asymmetry_zeta0"],
            lt=ASYMMETRY_LIMITS["asymmetry_zeta0"],
            description="the right leg's constant leg-length offset [l0]",
        ),
    ] = _NOISE.asymmetry_zeta0
