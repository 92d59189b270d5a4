"""``parkour mfpt --controller``: a closed-loop law's MFPT by splitting (:mod:`experiments.loop_mfpt`)."""

from __future__ import annotations

from cli.options import ModelSetup, option_named, parse_controls, print_json, progress_bar
from sim_core.model.noise import NoiseModel
from sim_core.model.validation import ParameterError


def controller_mfpt(
    setup: ModelSetup, noise: NoiseModel, controller: str, controls: str, target: float | None, splitting: dict,
    as_json: bool,
) -> None:  # fmt: skip
    """Run and print; ``splitting``: the options given (None: the default)."""
    from experiments.loop_mfpt import Config, run
    from sim_core.control.registry import NAMES
    from sim_core.robustness.splitting import SplittingOptions

    if controller not in NAMES:
        raise ParameterError("--controller", f"must be one of {', '.join(NAMES)}, got {controller!r}")
    schedule = parse_controls(controls)
    if len(schedule) != 1:
        raise ParameterError(
            "--controls", f"with --controller, one PSI0:ZETA0 (nominal psi0, first zeta0), got {controls!r}"
        )
    with option_named("--replicas", "replicas"), option_named("--runs", "runs"), option_named("--seed", "seed"):
        options = SplittingOptions(**{name: value for name, value in splitting.items() if value is not None})
    leg = schedule.legs[0]
    config = Config(controller=controller, target_m=0.55 if target is None else target, psi0_deg=leg.psi0_deg,
                    start_zeta0=leg.zeta0, noise=noise, options=options)  # fmt: skip
    with (
        option_named("--pitch-drift", "noise.pitch_drift_deg"),
        option_named("--target", "target"),
        progress_bar(f"MFPT of {controller}: {options.runs} splitting runs") as bar,
    ):
        payload = run(setup.model, setup.robot.scales.length, config, progress=bar)
    if as_json:
        print_json(payload)
        return
    if payload["mfpt_jumps"] is None:
        bound = payload["mfpt_at_least_jumps"]
        held = "" if bound is None else (f"; more than {bound:.3g} jumps (95%: no failure in the "
                                         f"{payload['failure_free_jumps']} jumps the long runs held)")  # fmt: skip
        print(f"{controller}: no splitting run reached a failure; MFPT beyond what they can reach{held}")
        return
    low, high = payload["ci95"]
    upper = "inf" if high is None else f"{high:.3g}"  # a t interval on the rate open above
    print(f"{controller}: MFPT {payload['mfpt_jumps']:.4g} jumps (95% {low:.3g} - {upper}), "
          f"lambda2 {payload['lambda2']:.8f}, {payload['seconds']:.1f} s")  # fmt: skip
