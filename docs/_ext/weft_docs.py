"""Sphinx directives that build pages from weft's own data, so the site cannot drift from the code.

* ``.. weft-parameters:: METHOD`` -- the method's parameter table from its ``Spec`` objects (the same
  specs that build the CLI options and the studio's sliders);
* ``.. weft-cli:: COMMAND`` -- the ``weft COMMAND --help`` text of a command that is not a method
  (``run``, ``batch``, ``warm-up``), or of ``weft`` itself without an argument;
* ``.. weft-results:: SUITE`` -- the table of ``benchmarks/results/SUITE.json`` with the machine, the
  date and the command that reproduces it, through :mod:`weft_results`; a missing file is said on
  the page, never a failed build.
"""

from __future__ import annotations

import argparse
import io
import os
from contextlib import redirect_stdout

import weft_results
from docutils import nodes
from docutils.parsers.rst import Directive
from docutils.statemachine import StringList


def _cell(text: str) -> str:
    return " ".join(str(text).split()) or " "


def list_table(header: list[str], rows: list[list[str]], widths: list[int] | None = None) -> list[str]:
    """RST lines of a ``list-table`` (cells are inline RST)."""
    lines = [".. list-table::", "   :header-rows: 1"]
    if widths:
        lines.append("   :widths: " + " ".join(str(w) for w in widths))
    lines.append("")
    for row in [header, *rows]:
        for i, cell in enumerate(row):
            lines.append(("   * - " if i == 0 else "     - ") + _cell(cell))
    lines.append("")
    return lines


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
        return ", ".join(f"``{c}``" for c in spec.choices)
    if spec.kind == "bool":
        return "``true``, ``false``"
    if spec.kind == "size":
        return f"``WxH``, sides {spec.range_text()}"
    if spec.kind == "geometry":
        return f"``{spec.type.METAVAR}``"
    return spec.range_text() or ""


def _escape(text: str) -> str:
    return (text or "").replace("\\", "\\\\").replace("*", "\\*").replace("`", "\\`").replace("|", "\\|")


def parameter_lines(method_name: str) -> list[str]:
    """The parameter table of one method: option, paper symbol, range, default, what it changes."""
    from weft.core import registry
    from weft.core.params import specs

    method = registry.get(method_name)
    inputs = ", ".join(
        (f"``{i.name.upper()}``" if i.is_positional else f"``--{i.name.replace('_', '-')} IMAGE``")
        + ("" if i.required else " (optional)")
        + f": {_escape(i.help)}"
        for i in method.inputs
    )
    lines = [f"``weft {method_name}`` -- {_escape(method.summary)}.", "", f"Inputs: {inputs}.", ""]
    rows = [
        [f"``{s.option}``", _escape(s.symbol or ""), _range(s), _default(s), _escape(s.help)]
        for s in specs(method.params)
    ]
    return lines + list_table(["option", "symbol", "range", "default", "what it changes"], rows, [14, 6, 16, 8, 56])


def cli_help(command: str) -> str:
    """``weft COMMAND --help`` as the command line prints it (80 columns)."""
    from weft.app.cli import build_parser

    os.environ["COLUMNS"] = "100"
    parser = build_parser()
    if command in ("", "weft"):
        return parser.format_help()
    for action in parser._actions:  # the subcommands' parsers
        if isinstance(action, argparse._SubParsersAction) and command in action.choices:
            out = io.StringIO()
            with redirect_stdout(out):
                action.choices[command].print_help()
            return out.getvalue()
    raise ValueError(f"weft has no command {command!r}")


class _Generated(Directive):
    required_arguments = 1
    has_content = False

    def lines(self) -> list[str]:
        raise NotImplementedError

    def run(self):
        node = nodes.section()
        node.document = self.state.document
        self.state.nested_parse(
            StringList(self.lines(), source=f"<{self.name} {self.arguments[0]}>"), self.content_offset, node
        )
        return node.children


class ParametersDirective(_Generated):
    def lines(self) -> list[str]:
        return parameter_lines(self.arguments[0])


class CliDirective(_Generated):
    def lines(self) -> list[str]:
        text = cli_help(self.arguments[0])
        return ["::", ""] + ["   " + line for line in text.rstrip().splitlines()] + [""]


class ResultsDirective(_Generated):
    def lines(self) -> list[str]:
        env = self.state.document.settings.env
        path = weft_results.results_path(self.arguments[0])
        env.note_dependency(str(path))
        return weft_results.render(self.arguments[0])


def setup(app):
    app.add_directive("weft-parameters", ParametersDirective)
    app.add_directive("weft-cli", CliDirective)
    app.add_directive("weft-results", ResultsDirective)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
