"""The 3D view reads recordings and live state through the services (backend/services/view.py),
never the store or the robot's internals: no module under frontend/viewer imports backend.store
or backend.robot, at module level or inside a function. (The same rule as an import-linter
contract belongs in pyproject.toml; this holds it until then, and names the line that breaks it.)
"""

import ast
from pathlib import Path

VIEWER = Path(__file__).resolve().parents[3] / "frontend" / "viewer"
FORBIDDEN = ("backend.store", "backend.robot")


def imported(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, module) of every import in ``tree``: ``import a.b`` and ``from a.b import c`` as
    ``a.b`` and ``a.b.c`` (``from backend import store`` is ``backend.store``)."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found += [(node.lineno, f"{node.module}.{alias.name}") for alias in node.names]
    return found


def breaks_the_rule(module: str) -> bool:
    return any(module == name or module.startswith(name + ".") for name in FORBIDDEN)


def test_the_check_sees_every_form_of_import():
    tree = ast.parse(
        "import backend.store.models\nfrom backend import robot\ndef f():\n    from backend.robot.messages import Leg\n"
    )
    assert [module for _line, module in imported(tree) if breaks_the_rule(module)] == [
        "backend.store.models", "backend.robot", "backend.robot.messages.Leg",
    ]  # fmt: skip
    assert not breaks_the_rule("backend.services.view.stored_path") and not breaks_the_rule("backend.storage")


def test_no_viewer_module_imports_the_store_or_the_robot():
    modules = sorted(VIEWER.rglob("*.py"))
    assert len(modules) > 10, f"found only {len(modules)} modules under {VIEWER}"
    broken = [
        f"{path.relative_to(VIEWER.parents[1])}:{line} imports {module}"
        for path in modules
        for line, module in imported(ast.parse(path.read_text(), filename=str(path)))
        if breaks_the_rule(module)
    ]
    assert broken == [], "read them through backend/services/view.py instead:\n" + "\n".join(broken)
