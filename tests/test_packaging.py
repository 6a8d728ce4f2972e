"""The distribution installs app/ and core/ as ``weft.app`` and ``weft.core`` and claims
no other top-level import name."""

import os
import pathlib
import subprocess
import sys
import tomllib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]


def test_every_package_of_the_tree_is_listed_under_weft():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    assert config["package-dir"] == {"weft": "."}
    found = {"weft"} | {
        "weft." + ".".join(p.parent.relative_to(ROOT).parts)
        for top in ("app", "core")
        for p in (ROOT / top).rglob("__init__.py")
    }
    assert set(config["packages"]) == found


@pytest.mark.slow
def test_weft_imports_without_top_level_app_or_core(tmp_path):
    """From a folder outside the repository (so the checkout is not on sys.path), the installed
    package imports as weft.* and puts no ``app`` or ``core`` module in sys.modules."""
    code = (
        "import sys, importlib.util\n"
        "import weft.app.cli, weft.core.registry as r\n"
        "r.methods()\n"
        "assert weft.app.cli.main and weft.core.registry.__file__\n"
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in ('app', 'core'))\n"
        "print(bad, importlib.util.find_spec('core'), importlib.util.find_spec('app'))\n"
        "sys.exit(1 if bad or importlib.util.find_spec('core') or importlib.util.find_spec('app') else 0)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr
