"""``parkour reproduce``: regenerate the paper's figures, their data and a paper-vs-ours report.

Each figure module (``fig7``, ``fig8``, ``fig11``, ``fig12``) is a declarative ``Config`` plus
``run``/``plot``/``table``/``data``/``claims``/``notes``; this module runs the requested ones
and writes, into one directory, ``NAME.png``, ``NAME.svg``, ``NAME.csv``, ``NAME.json`` (with
the configuration, the model and the code version) and ``report.md`` covering the figures of
this run. The figure modules load when a figure runs, not when the names are listed.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from pathlib import Path
from types import ModuleType

from experiments.manifest import code_version, metadata
from experiments.report import markdown_section, write_outputs
from sim_core.chunks import ChunkMap, in_process
from sim_core.model.params import PhysicalParams
from sim_core.model.validation import ParameterError

FIGURES = ("fig7", "fig8", "fig11", "fig12")  # each a module experiments.<name>, in report order


def figure_module(name: str) -> ModuleType:
    """The study of figure ``name`` (one of :data:`FIGURES`)."""
    return importlib.import_module(f"experiments.{figure_names([name])[0]}")


def figure_names(requested: Sequence[str]) -> list[str]:
    """Validate names; ``all`` expands to every figure, in order."""
    names: list[str] = []
    for name in requested:
        if name == "all":
            names.extend(FIGURES)
        elif name in FIGURES:
            names.append(name)
        else:
            raise ParameterError("figure", f"must be one of {', '.join([*FIGURES, 'all'])}, got {name!r}")
    if not names:
        raise ParameterError("figure", "name at least one figure, or all")
    return list(dict.fromkeys(names))


def reproduce(
    names: Sequence[str],
    out: Path,
    robot: PhysicalParams,
    *,
    quick: bool = False,
    chunk_map: ChunkMap = in_process,
    progress: Callable[[str, int, int], None] | None = None,
) -> list[Path]:
    """Run the figures ``names`` and write their outputs and ``report.md`` into ``out``."""
    names = figure_names(names)
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ParameterError("out", f"must be a directory, got the file {out}")
    written: list[Path] = []
    sections: list[str] = []
    model = robot.to_model()
    for name in names:
        module = figure_module(name)
        config = module.Config.quick() if quick else module.Config()

        def report(done: int, total: int, name: str = name) -> None:
            if progress is not None:
                progress(name, done, total)

        result = module.run(robot, config, chunk_map=chunk_map, progress=report)
        claims = module.claims(result)
        document = {"figure": name, **metadata(model, config), "data": module.data(result), "claims": claims}
        written += write_outputs(name, out, figure=module.plot(result), columns=module.table(result), document=document)
        sections.append(markdown_section(module.TITLE, name, claims, module.notes(result)))
    header = [
        "# ParkourLab: the paper's figures, reproduced",
        "",
        "Degani et al., ICRA 2011, against ParkourLab's simulation of the `paper` preset "
        f"(alpha = {model.alpha:.2f}, d_hat = {model.d_hat:g}, c_zeta = {model.c_zeta:.3f}, "
        f"c_psi = {model.c_psi:.3f}, mu = {model.mu:g}).",
        f"Code version `{code_version()}`{' — quick (coarse) configuration' if quick else ''}. "
        "Regenerate with `parkour reproduce " + " ".join(names) + f" --out {out}`.",
        "",
    ]
    report_path = out / "report.md"
    report_path.write_text("\n".join(header + sections))
    return [*written, report_path]
