"""Named parameter sets. Presets are data: add one here and every command, the API and
the GUI can use it by name.

``paper`` is Table I of the ICRA 2011 paper. The extracted text lost ``l0``; it keeps
``d_hat = 2.42``, so ``l0 = d / 2.42`` (model.md §1).
"""

from __future__ import annotations

from types import MappingProxyType

from sim_core.params import PhysicalParams
from sim_core.validation import ParameterError

PRESETS = MappingProxyType(
    {
        "paper": PhysicalParams(
            mass=1.54,
            leg_length=0.54 / 2.42,
            stiffness=525.0,
            wall_distance=0.54,
            gravity=0.98,
            c_zeta=1.0,
            c_psi=1.0,
            mu=2.0,
        ),
    }
)

DEFAULT_PRESET = "paper"


def get_preset(name: str) -> PhysicalParams:
    """The physical parameters of preset ``name``; a clear error names the known presets."""
    try:
        return PRESETS[name]
    except KeyError:
        known = ", ".join(sorted(PRESETS))
        raise ParameterError("preset", f"unknown preset {name!r}; known presets: {known}") from None
