"""Print the README's CLI option tables from the parameter specs: ``.venv/bin/python docs/cli_reference.py``.

The tables are generated from the same ``Params`` specs that build the CLI options and the GUI's
sliders, so the README cannot drift from the code (``tests/test_readme.py`` checks every option is
documented).
"""

from __future__ import annotations

import sys

from weft.core import registry
from weft.core.params import specs


def _default(spec) -> str:
    d = spec.default
    if d is None:
        return "auto"
    if isinstance(d, tuple):
        return f"{d[0]}x{d[1]}"
    if isinstance(d, bool):
        return "on" if d else "off"
    return str(d)


def _range(spec) -> str:
    if spec.kind == "choice":
        return " \\| ".join(f"`{c}`" for c in spec.choices)
    if spec.kind == "bool":
        return "true / false"
    if spec.kind == "size":
        return f"`WxH`, sides {spec.range_text()}"
    return spec.range_text()


def method_table(name: str) -> str:
    method = registry.get(name)
    lines = [f"`weft {name}` inputs: " + ", ".join(
        (f"`{i.name.upper()}`" if i.is_positional else f"`--{i.name.replace('_', '-')} IMAGE`")
        + ("" if i.required else " (optional)") for i in method.inputs), "",
        "| option | symbol | range | default | meaning |", "| --- | --- | --- | --- | --- |"]
    for spec in specs(method.params):
        lines.append(f"| `{spec.option}` | {spec.symbol} | {_range(spec)} | {_default(spec)} | {spec.help} |")
    return "\n".join(lines)


START, END = "<!-- cli-reference:start -->", "<!-- cli-reference:end -->"


def reference() -> str:
    """The generated block for every registered method."""
    return "\n\n".join(f"### weft {name}\n\n{method_table(name)}" for name in registry.methods())


def readme_with_reference(text: str) -> str:
    """``text`` (the README) with the block between the markers replaced by :func:`reference`."""
    head, rest = text.split(START, 1)
    _, tail = rest.split(END, 1)
    return f"{head}{START}\n{reference()}\n{END}{tail}"


def main(argv: list[str]) -> int:
    if argv == ["--write-readme"]:
        from pathlib import Path

        readme = Path(__file__).resolve().parent.parent / "README.md"
        readme.write_text(readme_with_reference(readme.read_text(encoding="utf-8")), encoding="utf-8")
        print(f"updated {readme}")
    else:
        print(reference())
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
