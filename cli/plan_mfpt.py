"""``parkour plan --mfpt``: how often the placement law's climbs of a plan fail, by splitting, and
the mean jumps to failure of climbs made again and again (:mod:`sim_core.planning.plan_splitting`);
beside it, plain Monte-Carlo and, for rare failures, importance sampling
(:mod:`sim_core.planning.plan_importance`)."""

from __future__ import annotations

from dataclasses import dataclass

from cli.options import note, option_named, progress_bar, refuse_given
from sim_core.model.errors import ParameterError

MAX_MONTE_CARLO = 100_000
MAX_IMPORTANCE = 100_000
DEFAULT_IS_SCALE = 1.5  # × 2 over a 4-jump climb's 22 draws already leaves the weights degenerate (docs/worlds.md)


@dataclass(frozen=True)
class ImportanceRequest:
    """``--importance-sampling`` and its options, checked: climbs, the scale, the kinds of draw it
    widens, touchdown 0's alone or not."""

    trials: int
    scale: float
    scaled: tuple[str, ...]
    first_leg_only: bool


def check_mfpt_options(mfpt: bool, replicas, runs, replans, monte_carlo, seed: int):
    """The splitting's options (None without --mfpt); an option given without --mfpt, or out of
    range, is an error naming it."""
    if not mfpt:
        refuse_given({"--replicas": replicas, "--runs": runs, "--replans": replans, "--monte-carlo": monte_carlo},
                     "needs --mfpt")  # fmt: skip
        return None
    from sim_core.planning.plan_splitting import PlanSplitting

    if monte_carlo is not None and not 1 <= monte_carlo <= MAX_MONTE_CARLO:
        raise ParameterError("--monte-carlo", f"must be in [1, {MAX_MONTE_CARLO}], got {monte_carlo}")
    chosen = {"replicas": replicas, "runs": runs, "max_replans": replans}
    with (
        option_named("--replicas", "replicas"),
        option_named("--runs", "runs"),
        option_named("--replans", "max_replans"),
    ):
        return PlanSplitting(seed=seed, **{name: value for name, value in chosen.items() if value is not None})


def check_importance_options(mfpt: bool, trials, scale, draws, first_leg: bool) -> ImportanceRequest | None:
    """``--importance-sampling`` and its options (None where not asked); one given without what it
    needs, or out of range, is an error naming it."""
    given = {"--is-scale": scale, "--is-draws": draws, "--is-first-leg": True if first_leg else None}
    if not mfpt:
        refuse_given({"--importance-sampling": trials, **given}, "needs --mfpt")
        return None
    if trials is None:
        refuse_given(given, "needs --importance-sampling")
        return None
    from sim_core.model.noise_rules import TALLY_KINDS
    from sim_core.planning.plan_importance import kind_scales

    if not 2 <= trials <= MAX_IMPORTANCE:  # 2: a sample's standard error
        raise ParameterError("--importance-sampling", f"must be in [2, {MAX_IMPORTANCE}], got {trials}")
    scale = DEFAULT_IS_SCALE if scale is None else scale
    scaled = TALLY_KINDS if draws is None else tuple(kind.strip() for kind in draws.split(",") if kind.strip())
    with option_named("--is-scale", "scale"), option_named("--is-draws", "scaled"):
        kind_scales(scale, scaled)
    return ImportanceRequest(trials, float(scale), scaled, first_leg)


def plan_mfpt_document(model, world, plan, goal: float, noise, splitting, monte_carlo: int | None,
                       importance: ImportanceRequest | None = None) -> dict:  # fmt: skip
    """The estimate as ``parkour plan --json`` gives it under ``"mfpt"``, with Monte-Carlo beside it
    where asked (``monte_carlo`` attempts, seeds after the splitting's) and importance sampling
    (``importance``'s climbs, seeds after those)."""
    from sim_core.planning.plan_splitting import plan_mfpt, plan_monte_carlo

    with progress_bar(f"MFPT of the plan: {splitting.runs} splitting runs") as bar:
        document = {
            "method": "splitting",
            **plan_mfpt(model, world, plan, goal, noise, splitting, progress=bar).to_dict(),
        }
    if monte_carlo is not None:
        first = splitting.seed + splitting.runs * splitting.replicas  # seeds no splitting attempt started from
        with progress_bar(f"Monte-Carlo: {monte_carlo} attempts") as bar:
            document["monte_carlo"] = plan_monte_carlo(model, world, plan, goal, noise, splitting, monte_carlo, first,
                                                       progress=bar).to_dict()  # fmt: skip
    if importance is not None:
        from sim_core.planning.plan_importance import plan_importance

        first = splitting.seed + splitting.runs * splitting.replicas + (monte_carlo or 0)  # seeds no other climb used
        with progress_bar(f"Importance sampling: {importance.trials} climbs") as bar:
            estimate = plan_importance(model, world, plan, goal, noise, splitting, importance.trials, first,
                                       importance.scale, scaled=importance.scaled,
                                       first_leg_only=importance.first_leg_only, progress=bar)  # fmt: skip
        document["importance_sampling"] = estimate.to_dict()
        if estimate.warning is not None:
            note(f"importance sampling: {estimate.warning}")
    return document


def print_mfpt(document: dict) -> None:
    low, high = document["failure_chance_ci95"]
    print(f"a climb fails with chance {document['failure_chance']:.3g} (95% {low:.3g} - {high:.3g}); "
          f"{document['mean_attempt_jumps']:.1f} jumps a climb")  # fmt: skip
    if document["mfpt_jumps"] is None:
        print("no splitting run reached a failure: the mean jumps to failure are beyond what they can tell")
    else:
        interval = document["ci95"]
        upper = "inf" if interval[1] is None else f"{interval[1]:.3g}"
        print(f"mean jumps to failure, climbing it again and again: {document['mfpt_jumps']:.4g} "
              f"(95% {interval[0]:.3g} - {upper}), {document['seconds']:.1f} s")  # fmt: skip
    if "monte_carlo" in document:
        check = document["monte_carlo"]
        low, high = check["failure_chance_ci95"]
        print(f"Monte-Carlo: {check['failures']} of {check['trials']} climbs failed, "
              f"chance {check['failure_chance']:.3g} (95% {low:.3g} - {high:.3g})")  # fmt: skip
    if "importance_sampling" in document:
        sampled = document["importance_sampling"]
        low, high = sampled["failure_chance_ci95"]
        upper = "?" if high is None else f"{high:.3g}"
        where = " at touchdown 0" if sampled["first_leg_only"] else ""
        warned = "" if sampled["warning"] is None else " (warned above)"
        print(f"importance sampling ({sampled['trials']} climbs, {', '.join(sampled['scaled'])} × "
              f"{sampled['scale']:g}{where}): chance {sampled['failure_chance']:.3g} (95% {low:.3g} - {upper}), "
              f"{sampled['failures_under_proposal']} failed under the proposal, effective sample size "
              f"{sampled['effective_sample_size']:.0f}, effective failures "
              f"{sampled['effective_failures']:.1f}{warned}")  # fmt: skip
