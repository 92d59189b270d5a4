"""The ParkourBot model and its simulation: what to simulate, and one jump, orbit or path of it (docs/model.md).

- :mod:`.params`, :mod:`.presets`, :mod:`.controls`, :mod:`.walls` — parameters, named sets, leg
  controls, left and right;
- :mod:`.validation`, :mod:`.errors`, :mod:`.failures` — ranges checked with the field named, the errors a user can fix,
  and how a jump fails;
- :mod:`.stance_equations`, :mod:`._dop853`, :mod:`.integrate`, :mod:`.stride` — the compiled kernels: stance, one
  jump, orbits;
- :mod:`.poincare`, :mod:`.trajectory` — the validated map and full paths; :mod:`.reference` the scipy baseline;
- :mod:`.noise`, :mod:`.noise_rules`, :mod:`.noisy_map` — the noise model, how kernels apply it, and the noisy jump
  map on the mid-chute section.

Everything else in sim_core is built on this package; it imports none of them.
"""
