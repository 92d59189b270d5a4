"""``parkour plan --mfpt``: how often the placement law's climbs of a plan fail, by splitting, and
the mean jumps to failure of climbs made again and again (:mod:`sim_core.planning.plan_splitting`)."""

from __future__ import annotations

from cli.options import option_named, progress_bar, refuse_given
from sim_core.model.errors import ParameterError

MAX_MONTE_CARLO = 100_000


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


def plan_mfpt_document(model, world, plan, goal: float, noise, splitting, monte_carlo: int | None) -> dict:
    """The estimate as ``parkour plan --json`` gives it under ``"mfpt"``, with Monte-Carlo beside it
    where asked (``monte_carlo`` attempts, seeds after the splitting's)."""
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
