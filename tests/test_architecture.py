"""Architecture rules the suite enforces: the studio knows no method by name; no import cycles."""

import ast
import inspect
from pathlib import Path

from weft.core import registry
from weft.core.params import specs

ROOT = Path(__file__).resolve().parents[1]


#: Input names that are also the plain word the studio uses for any picture (fill's input is called
#: "image", fixed by the fill interface; the studio's "image" labels mean the word, not it).
GENERIC_WORDS = {"image"}


def _method_words() -> dict[str, str]:
    """Every registered method's name, input names and parameter names -> what they are."""
    words = {}
    for method in registry.methods().values():
        words[method.name] = f"method {method.name}"
        for inp in method.inputs:
            if inp.name not in GENERIC_WORDS:
                words.setdefault(inp.name, f"an input of {method.name}")
        for spec in specs(method.params):
            words.setdefault(spec.name, f"a parameter of {method.name}")
    return words


def test_app_gui_names_no_method_input_or_parameter():
    """app/gui is generic over methods: none of its string literals is a method, input or parameter
    name (it learns them from weft.core.registry and each method's studio description)."""
    words = _method_words()
    found = []
    for path in sorted((ROOT / "app" / "gui").rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in words:
                found.append(f"{path.relative_to(ROOT)}:{node.lineno}: {node.value!r} is {words[node.value]}")
    assert not found, "\n".join(found)


def test_the_literal_check_would_catch_a_method_name(tmp_path):
    """The check above is not vacuous: the words it looks for include the studio's methods and inputs."""
    words = _method_words()
    for name, method in registry.studio_methods().items():
        assert name in words and (method.studio.canvas in words or method.studio.canvas in GENERIC_WORDS)
    assert "texture" in words and "mask" in words  # the inputs of the studio's methods that are no plain word


def _imports(path: Path, package: str) -> set[str]:
    """Modules of app/ and core/ that ``path`` imports (at any level, function bodies included)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                if node.level > 1:
                    base = base[: len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
                if node.module is None:
                    out.update(f"{mod}.{a.name}" for a in node.names)
                else:
                    out.add(mod)
                    out.update(f"{mod}.{a.name}" for a in node.names)
            elif node.module:
                out.add(node.module)
                out.update(f"{node.module}.{a.name}" for a in node.names)
    return {m for m in out if m.startswith(("weft.app", "weft.core"))}


def _module_graph() -> dict[str, set[str]]:
    modules = {}
    for top in ("app", "core"):
        for path in (ROOT / top).rglob("*.py"):
            rel = path.relative_to(ROOT).with_suffix("")
            parts = list(rel.parts)
            is_pkg = parts[-1] == "__init__"
            if is_pkg:
                parts = parts[:-1]
            name = ".".join(["weft", *parts])
            modules[name] = (path, name if is_pkg else ".".join(["weft", *parts[:-1]]))
    graph = {}
    for name, (path, package) in modules.items():
        deps = set()
        for imp in _imports(path, package):
            while imp and imp not in modules:  # "weft.core.image.load_image" -> "weft.core.image"
                imp = imp.rpartition(".")[0]
            if imp and imp != name and not name.startswith(imp + "."):  # a package's own __init__ is no cycle
                deps.add(imp)
        graph[name] = deps
    return graph


def test_no_import_cycle_in_app_and_core():
    """Walk every import of app/ and core/ (module level and inside functions): no cycle."""
    graph = _module_graph()
    assert "weft.app.gui.main_window" in graph and "weft.core.registry" in graph
    state: dict[str, int] = {}
    stack: list[str] = []
    cycles = []

    def visit(node: str) -> None:
        state[node] = 1
        stack.append(node)
        for dep in sorted(graph.get(node, ())):
            if state.get(dep) == 1:
                cycles.append(stack[stack.index(dep) :] + [dep])
            elif dep not in state:
                visit(dep)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node)
    assert not cycles, "\n".join(" -> ".join(c) for c in cycles)


def test_public_functions_take_the_options_of_their_params():
    """One source per option: each method's one-call Python function takes exactly its Params'
    options (same names, same defaults), so the two cannot drift apart."""
    from weft.core import affine, fast, nfpt, quilting
    from weft.core.rectify import WarpParams

    cases = [
        (fast.transfer, fast.FastParams, set()),
        (affine.synthesize, affine.AffineParams, set()),
        (nfpt.synthesize, nfpt.NfptParams, {s.name for s in specs(WarpParams)} | {"view", "into_photo"}),
    ]
    for fn, params_cls, not_taken in cases:
        sig = inspect.signature(fn)
        options = {n: p.default for n, p in sig.parameters.items() if p.kind is p.KEYWORD_ONLY}
        wanted = {s.name: s.default for s in specs(params_cls) if s.name not in not_taken}
        taken = {n: d for n, d in options.items() if n in wanted}
        assert taken == wanted, (fn.__qualname__, set(wanted) ^ set(taken))
    # quilting splits its options over synthesis and transfer: each takes Params options with the
    # Params' defaults, and together they take them all
    quilt_specs = {s.name: s.default for s in specs(quilting.QuiltParams)}
    taken = {}
    for fn in (quilting.synthesize, quilting.transfer):
        options = {n: p.default for n, p in inspect.signature(fn).parameters.items() if p.kind is p.KEYWORD_ONLY}
        mine = {n: d for n, d in options.items() if n in quilt_specs}
        assert mine == {n: quilt_specs[n] for n in mine}, fn.__qualname__
        taken.update(mine)
    assert set(taken) == set(quilt_specs)
