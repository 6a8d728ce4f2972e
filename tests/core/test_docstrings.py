"""Every public function of ``weft.core`` documents its parameters (a numpydoc Parameters section).

Public: a module-level function without a leading underscore, in a module whose path has no
component with one (``weft.core._kernels`` is private). A function without parameters needs none.
"""

import ast
import re
from pathlib import Path

CORE = Path(__file__).resolve().parents[2] / "core"
SECTION = re.compile(r"^Parameters\n-{3,}$", re.M)


def _public_functions():
    for path in sorted(CORE.rglob("*.py")):
        parts = path.relative_to(CORE).with_suffix("").parts
        if any(p.startswith("_") and p != "__init__" for p in parts):
            continue
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
                yield path.relative_to(CORE.parent), node


def _has_parameters(node: ast.FunctionDef) -> bool:
    a = node.args
    return bool(a.posonlyargs or a.args or a.kwonlyargs or a.vararg or a.kwarg)


def test_public_core_functions_have_a_parameters_section():
    functions = list(_public_functions())
    assert len(functions) > 150  # the walk found the package
    missing = [
        f"{path}:{node.lineno} {node.name}"
        for path, node in functions
        if _has_parameters(node) and not SECTION.search(ast.get_docstring(node) or "")
    ]
    assert not missing, "public functions without a numpydoc Parameters section:\n" + "\n".join(missing)
