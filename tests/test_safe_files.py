"""Safe files: recipes and sessions are JSON only (no pickle, no eval), relative paths
resolve against the file that names them (never the current directory), and a bad file is refused in
one line naming the file and the problem: status 2, no traceback, no output written, nothing run."""

import ast
import json
import os
import pickle
import shutil
from pathlib import Path

import numpy as np
import pytest
from weft.app.cli import main
from weft.core.errors import WeftError
from weft.core.image import load_image, read_recipe, save_image
from weft.core.params import MAX_FILE_BYTES
from weft.core.session import read_session

ROOT = Path(__file__).resolve().parents[1]
UNSAFE_MODULES = {
    "pickle",
    "cPickle",
    "_pickle",
    "shelve",
    "marshal",
    "dill",
    "cloudpickle",
    "jsonpickle",
    "joblib",
    "yaml",
}
UNSAFE_CALLS = {"eval", "exec", "compile", "__import__"}
SQUARE = [[2, 2, 29, 2], [2, 29, 29, 29], [2, 2, 2, 29], [29, 2, 29, 29]]  # feature lines: the identity
QUILT = {"mode": "random", "block": 8, "size": [24, 24]}  # fast, and every output pixel is copied


# --- no unpickling, no evaluation, anywhere in weft ------------------------------------------------


def _offences(source: str, filename: str = "<test>") -> list[str]:
    """Imports of deserializers that can run code, and calls that evaluate text, in ``source``."""
    found = []
    for node in ast.walk(ast.parse(source, filename)):
        where = f"{filename}:{getattr(node, 'lineno', 0)}"
        if isinstance(node, ast.Import):
            found += [f"{where}: import {a.name}" for a in node.names if a.name.split(".")[0] in UNSAFE_MODULES]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            if node.module.split(".")[0] in UNSAFE_MODULES:
                found.append(f"{where}: from {node.module} import ...")
        elif isinstance(node, ast.Call):
            func = node.func
            if isinstance(func, ast.Name) and func.id in UNSAFE_CALLS:
                found.append(f"{where}: {func.id}(...)")
            elif (
                isinstance(func, ast.Attribute)
                and func.attr in UNSAFE_CALLS
                and isinstance(func.value, ast.Name)
                and func.value.id in ("builtins", "__builtins__")
            ):
                found.append(f"{where}: {func.value.id}.{func.attr}(...)")
            for kw in node.keywords:  # numpy.load(..., allow_pickle=True) and the like
                if kw.arg == "allow_pickle" and not (isinstance(kw.value, ast.Constant) and kw.value.value is False):
                    found.append(f"{where}: allow_pickle=...")
    return found


def test_the_checker_finds_what_it_looks_for():
    source = (
        "import pickle\nfrom shelve import open\nimport yaml.loader\nx = eval('1')\nexec('x = 2')\n"
        "builtins.__import__('os')\nnp.load(f, allow_pickle=True)\n"
        "app.exec()\nast.literal_eval('1')\nimport json\nnp.load(f)\n"
    )
    assert [o.split(": ", 1)[1] for o in _offences(source)] == [
        "import pickle",
        "from shelve import ...",
        "import yaml.loader",
        "eval(...)",
        "exec(...)",
        "builtins.__import__(...)",
        "allow_pickle=...",
    ]


def test_no_module_of_weft_unpickles_or_evaluates_text():
    files = sorted((ROOT / "core").rglob("*.py")) + sorted((ROOT / "app").rglob("*.py"))
    assert len(files) > 20 and any(f.name == "cli.py" for f in files)
    offences = []
    for f in files:
        offences += _offences(f.read_text(encoding="utf-8"), str(f.relative_to(ROOT)))
    assert offences == []


# --- helpers ---------------------------------------------------------------------------------------


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line(err: str) -> str:
    assert err.endswith("\n") and err.count("\n") == 1, err
    assert "Traceback" not in err and err.startswith("weft: "), err
    return err


def _image(path: Path, seed: int, side: int = 24) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    save_image(path, np.random.default_rng(seed).random((side, side, 3)).astype(np.float32))
    return path


def _recipe(path: Path, **fields) -> Path:
    data = {"weft": 1, "method": "quilt", "params": dict(QUILT), "inputs": {"texture": "tex.png"}, "seed": 5}
    data.update(fields)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data))
    return path


@pytest.fixture
def sentinel(tmp_path):
    """A file that exists only if something in a payload was executed."""
    path = tmp_path / "EXECUTED"
    yield path
    assert not path.exists(), "a payload in a recipe or session was executed"


class _Exploit:
    """Unpickling this creates the sentinel file."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return (open, (self.path, "w"))


def _bad_payloads(sentinel: Path, good: dict) -> dict[str, tuple[bytes, str]]:
    """name -> (file bytes, a fragment the one-line message must contain)."""
    shell = f"__import__('os').system('touch {sentinel}')"
    dump = json.dumps
    seed = f'"seed": {good["seed"]}'
    assert seed in dump(good)
    return {
        "pickle": (pickle.dumps(_Exploit(sentinel)), "not UTF-8"),
        "pickle_protocol0": (pickle.dumps(_Exploit(sentinel), protocol=0), "not valid JSON"),
        "python_code": (shell.encode(), "not valid JSON"),
        "python_dict": (repr(dict(good, seed=None)).encode(), "not valid JSON"),  # None, single quotes
        "yaml": (b"weft: 1\nmethod: quilt\ninputs:\n  texture: tex.png\n", "not valid JSON"),
        "truncated": (dump(good).encode()[:40], "not valid JSON"),
        "empty": (b"", "not valid JSON"),
        "not_an_object": (b"[1, 2, 3]", "must be a JSON object"),
        "a_string": (dump(shell).encode(), "must be a JSON object"),
        "nan": (dump(good).replace(seed, '"seed": NaN').encode(), "NaN is not a JSON number"),
        "infinity": (dump(good).replace(seed, '"seed": -Infinity').encode(), "-Infinity is not a JSON number"),
        "huge_number": (dump(good).replace(seed, '"seed": ' + "9" * 5000).encode(), "not valid JSON"),
        "deeply_nested": (b'{"weft": 1, "x": ' + b"[" * 200_000 + b"]" * 200_000 + b"}", "nested too deeply"),
        "nul_in_path": (dump(dict(good, inputs={k: "a\0b.png" for k in good["inputs"]})).encode(), "not a file path"),
    }


# --- recipes: bad files ----------------------------------------------------------------------------


def test_bad_recipe_files_are_refused_in_one_line_and_nothing_runs(tmp_path, capsys, sentinel):
    _image(tmp_path / "tex.png", 0)
    good = json.loads(_recipe(tmp_path / "good.json").read_text())
    out = tmp_path / "out.png"
    assert run(["run", tmp_path / "good.json", "-o", out], capsys)[0] == 0  # the control works
    out.unlink()
    for name, (data, fragment) in _bad_payloads(sentinel, good).items():
        path = tmp_path / f"{name}.json"
        path.write_bytes(data)
        code, stdout, err = run(["run", path, "-o", out], capsys)
        assert code == 2, (name, err)
        assert f"{name}.json" in one_line(err) and fragment in err, (name, err)
        assert stdout == "" and not out.exists(), name


@pytest.mark.parametrize(
    "fields, fragment",
    [
        ({"params": [1, 2]}, '"params" must be a JSON object'),
        ({"params": {"block": "8"}}, "parameter 'block' = '8' must be an integer"),
        ({"params": {"block": 8.0}}, "parameter 'block' = 8.0 must be an integer"),
        ({"params": {"mode": "__import__('os')"}}, "parameter 'mode' = \"__import__('os')\" is not one of"),
        ({"params": {"blok": 8}}, "unknown parameter blok for QuiltParams"),
        ({"params": {"block": True}}, "parameter 'block' = True must be an integer"),
        ({"inputs": ["tex.png"]}, '"inputs" must map input names to file paths'),
        ({"inputs": {"texture": 7}}, '"inputs" must map input names to file paths'),
        ({"inputs": {"texture": ""}}, "recipe input 'texture' = '' is not a file path"),
        (
            {"inputs": {"texture": "tex.png", "bogus": "tex.png"}},
            "recipe names input 'bogus', which quilt does not take",
        ),
        ({"inputs": {}}, "recipe names no texture image for quilt"),
        ({"seed": "7"}, "recipe \"seed\" = '7' must be a non-negative integer"),
        ({"seed": True}, 'recipe "seed" = True must be a non-negative integer'),
        ({"seed": 2**64}, f'recipe "seed" = {2**64} must be a non-negative integer below 2**63'),
        ({"region": [1, 2]}, 'recipe "region" = [1, 2] must be [x, y, side]'),
        ({"method": 3}, 'recipe has no "method"'),
        ({"method": "teleport"}, "unknown method 'teleport'"),
        ({"method": "__import__('os').system('true')"}, "unknown method \"__import__('os').system('true')\""),
        ({"weft": 2}, "this version of weft reads recipes of version 1"),
    ],
)
def test_recipe_fields_of_the_wrong_kind_are_refused_naming_the_file(tmp_path, capsys, fields, fragment):
    _image(tmp_path / "tex.png", 0)
    path = _recipe(tmp_path / "bad.json", **fields)
    out = tmp_path / "out.png"
    code, stdout, err = run(["run", path, "-o", out], capsys)
    assert code == 2
    assert one_line(err).startswith(f"weft: {path}: ") and fragment in err, err
    assert stdout == "" and not out.exists()


def test_a_huge_recipe_is_refused_by_its_size(tmp_path, capsys):
    _image(tmp_path / "tex.png", 0)
    path = _recipe(tmp_path / "huge.json")
    with open(path, "a") as f:  # still a valid recipe: only a size limit can refuse it
        f.write(" " * (50 * 2**20))
    out = tmp_path / "out.png"
    code, stdout, err = run(["run", path, "-o", out], capsys)
    assert code == 2
    assert one_line(err) == f"weft: {path}: 50.0 MB is too large for a recipe file (the limit is 10 MB); not read\n"
    assert stdout == "" and not out.exists()
    assert MAX_FILE_BYTES == 10 * 2**20


def test_a_png_carrying_a_huge_recipe_is_refused(tmp_path, capsys):
    _image(tmp_path / "tex.png", 0)
    good = json.loads(_recipe(tmp_path / "r.json").read_text())
    png = tmp_path / "carrier.png"
    save_image(png, np.zeros((8, 8, 3), np.float32), recipe=json.dumps(good) + " " * (MAX_FILE_BYTES + 10))
    out = tmp_path / "out.png"
    code, _, err = run(["run", png, "-o", out], capsys)
    assert code == 2 and one_line(err) == f"weft: {png}: recipe is longer than the 10 MB limit\n"
    assert not out.exists()


def test_a_png_carrying_a_bad_recipe_is_refused(tmp_path, capsys, sentinel):
    png = tmp_path / "carrier.png"
    out = tmp_path / "out.png"
    for text, fragment in [
        (f"__import__('os').system('touch {sentinel}')", "recipe is not valid JSON"),
        ('{"weft": 1, "method": "quilt", "seed": NaN}', "NaN is not a JSON number"),
        ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
    ]:
        save_image(png, np.zeros((8, 8, 3), np.float32), recipe=text)
        code, _, err = run(["run", png, "-o", out], capsys)
        assert code == 2 and one_line(err).startswith(f"weft: {png}: ") and fragment in err, err
        assert not out.exists()


def test_a_byte_order_mark_is_not_an_error(tmp_path, capsys):
    _image(tmp_path / "tex.png", 0)
    path = _recipe(tmp_path / "bom.json")
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())  # as Windows Notepad saves UTF-8
    code, _, err = run(["run", path, "-o", tmp_path / "out.png"], capsys)
    assert code == 0, err


def test_a_recipe_folder_or_unreadable_recipe_is_refused(tmp_path, capsys):
    out = tmp_path / "out.png"
    folder = tmp_path / "folder.json"
    folder.mkdir()
    code, _, err = run(["run", folder, "-o", out], capsys)
    assert code == 2 and one_line(err) == f"weft: {folder}: is a directory, not a recipe file\n"
    assert not out.exists()


# --- recipes: paths resolve against the recipe, not the current directory --------------------------


def _direct(tex: Path, out: Path, capsys) -> np.ndarray:
    code, _, err = run(
        ["quilt", tex, "-o", out, "--mode", "random", "--block", "8", "--size", "24x24", "--seed", "5"], capsys
    )
    assert code == 0, err
    return load_image(out).image


@pytest.fixture
def elsewhere(tmp_path, monkeypatch):
    """The current directory: another folder, holding decoys with the same names as the inputs."""
    cwd = tmp_path / "elsewhere"
    _image(cwd / "tex.png", 99)
    _image(cwd / "sub" / "tex.png", 98)
    (cwd / "lines.json").write_text(
        json.dumps({"image_lines": SQUARE, "frontal_lines": SQUARE, "frontal_size": [32, 32]})
    )
    monkeypatch.chdir(cwd)
    return cwd


def test_relative_recipe_inputs_resolve_against_the_recipe_folder(tmp_path, capsys, elsewhere):
    tex = _image(tmp_path / "project" / "sub" / "tex.png", 0)
    expected = _direct(tex, tmp_path / "direct.png", capsys)
    assert not np.array_equal(expected, _direct(elsewhere / "sub" / "tex.png", tmp_path / "decoy.png", capsys))
    recipe = _recipe(tmp_path / "project" / "r.json", inputs={"texture": "sub/tex.png"})
    out = tmp_path / "out.png"
    code, _, err = run(["run", recipe, "-o", out], capsys)
    assert code == 0, err
    assert np.array_equal(load_image(out).image, expected)
    # ... also when the recipe is named by a relative path from the current directory
    rel = os.path.relpath(recipe, elsewhere)
    assert rel.startswith("..")
    code, _, err = run(["run", rel, "-o", tmp_path / "out2.png"], capsys)
    assert code == 0, err
    assert np.array_equal(load_image(tmp_path / "out2.png").image, expected)


def test_absolute_recipe_inputs_still_work(tmp_path, capsys, elsewhere):
    tex = _image(tmp_path / "images" / "tex.png", 0)
    expected = _direct(tex, tmp_path / "direct.png", capsys)
    recipe = _recipe(tmp_path / "recipes" / "r.json", inputs={"texture": str(tex)})
    out = tmp_path / "out.png"
    code, _, err = run(["run", recipe, "-o", out], capsys)
    assert code == 0, err
    assert np.array_equal(load_image(out).image, expected)


def test_an_exported_png_moved_with_its_inputs_still_runs(tmp_path, capsys, monkeypatch):
    first = tmp_path / "first"
    _image(first / "tex.png", 0)
    monkeypatch.chdir(first)
    exported = first / "result.png"
    _direct(Path("tex.png"), exported, capsys)
    assert json.loads(read_recipe(exported))["inputs"] == {"texture": "tex.png"}
    moved = tmp_path / "moved"
    monkeypatch.chdir(tmp_path)
    shutil.move(first, moved)
    decoys = tmp_path / "decoys"
    _image(decoys / "tex.png", 99)
    monkeypatch.chdir(decoys)
    again = tmp_path / "again.png"
    code, _, err = run(["run", moved / "result.png", "-o", again], capsys)
    assert code == 0, err
    assert np.array_equal(load_image(again).image, load_image(moved / "result.png").image)


def test_nfpt_lines_file_resolves_against_the_recipe_folder(tmp_path, capsys, elsewhere):
    project = tmp_path / "project"
    _image(project / "photo.png", 0, side=32)
    lines = [[3, 3, 28, 4], [3, 28, 28, 27], [3, 3, 4, 28], [28, 4, 27, 27]]  # not the decoy's lines
    (project / "lines.json").write_text(
        json.dumps({"image_lines": lines, "frontal_lines": SQUARE, "frontal_size": [32, 32]})
    )
    nfpt = {"lines": "lines.json", "size": [24, 24], "block": 12, "overlap": 3}
    recipe = _recipe(project / "r.json", method="nfpt", params=nfpt, inputs={"photo": "photo.png"})
    out, direct = tmp_path / "out.png", tmp_path / "direct.png"
    code, _, err = run(["run", recipe, "-o", out], capsys)
    assert code == 0, err
    code, _, err = run(
        [
            "nfpt",
            project / "photo.png",
            "--lines",
            project / "lines.json",
            "--size",
            "24x24",
            "--block",
            "12",
            "--overlap",
            "3",
            "--seed",
            "5",
            "-o",
            direct,
        ],
        capsys,
    )
    assert code == 0, err
    assert np.array_equal(load_image(out).image, load_image(direct).image)


# --- recipes naming files that are not there -------------------------------------------------------


@pytest.mark.parametrize(
    "method, inputs, missing",
    [
        ("quilt", {"texture": "tex.png", "target": "gone.png"}, "target"),
        ("quilt", {"texture": "sub/gone.png"}, "texture"),
        ("fast", {"texture": "tex.png", "target": "../elsewhere/tex.png/gone.png"}, "target"),
    ],
)
def test_a_recipe_naming_a_missing_image_says_which(tmp_path, capsys, elsewhere, method, inputs, missing):
    _image(tmp_path / "project" / "tex.png", 0)
    _image(elsewhere / "gone.png", 1)  # a file of that name in the current directory must not be taken
    params = QUILT if method == "quilt" else {}
    recipe = _recipe(tmp_path / "project" / "r.json", method=method, params=params, inputs=inputs)
    out = tmp_path / "out.png"
    code, stdout, err = run(["run", recipe, "-o", out], capsys)
    assert code == 2
    written = inputs[missing]
    resolved = str(tmp_path / "project" / written)
    assert one_line(err) == f"weft: {recipe}: the {missing} image {resolved} does not exist\n"
    assert stdout == "" and not out.exists()


def test_an_exported_png_whose_input_is_gone_says_which(tmp_path, capsys):
    _image(tmp_path / "tex.png", 0)
    exported = tmp_path / "result.png"
    _direct(tmp_path / "tex.png", exported, capsys)
    (tmp_path / "tex.png").unlink()
    out = tmp_path / "out.png"
    code, _, err = run(["run", exported, "-o", out], capsys)
    assert code == 2
    assert one_line(err) == f"weft: {exported}: the texture image {tmp_path / 'tex.png'} does not exist\n"
    assert not out.exists()


def test_a_recipe_naming_a_missing_lines_file_says_which(tmp_path, capsys, elsewhere):
    project = tmp_path / "project"
    _image(project / "photo.png", 0, side=32)
    assert (elsewhere / "lines.json").is_file()  # the current directory's lines.json must not be taken
    nfpt = {"lines": "lines.json", "size": [24, 24], "block": 12, "overlap": 3}
    recipe = _recipe(project / "r.json", method="nfpt", params=nfpt, inputs={"photo": "photo.png"})
    out = tmp_path / "out.png"
    code, stdout, err = run(["run", recipe, "-o", out], capsys)
    assert code == 2
    assert one_line(err) == (
        f"weft: {recipe}: parameter 'lines' names lines.json, but {project / 'lines.json'} does not exist\n"
    )
    assert stdout == "" and not out.exists()
    # an absolute path that is not there either
    recipe = _recipe(
        project / "r.json",
        method="nfpt",
        params=dict(nfpt, lines=str(tmp_path / "no" / "l.json")),
        inputs={"photo": "photo.png"},
    )
    code, _, err = run(["run", recipe, "-o", out], capsys)
    assert code == 2 and "parameter 'lines' names" in one_line(err) and str(tmp_path / "no" / "l.json") in err
    assert not out.exists()


# --- sessions: the same files, read by the studio --------------------------------------------------


def _session(**fields) -> dict:
    data = {
        "weft_session": 1,
        "method": "fast",
        "params": {"fast": {"p": 0.4}},
        "inputs": {"texture": "tex.png"},
        "prototype": None,
        "lines": {"image_lines": [], "frontal_lines": [], "frontal_size": [512, 512]},
        "seed": 3,
    }
    data.update(fields)
    return data


def test_a_good_session_reads_with_paths_relative_to_it(tmp_path, elsewhere):
    path = tmp_path / "project" / "s.weft.json"
    path.parent.mkdir()
    path.write_text(
        json.dumps(_session(inputs={"texture": "tex.png", "target": "sub/t.png", "photo": str(tmp_path / "abs.png")}))
    )
    data = read_session(path)
    assert data.inputs == {
        "texture": str(tmp_path / "project" / "tex.png"),
        "target": str(tmp_path / "project" / "sub" / "t.png"),
        "photo": str(tmp_path / "abs.png"),
    }
    assert data.params["fast"].p == 0.4 and data.seed == 3 and data.method == "fast"


def test_bad_session_files_are_refused_in_one_line(tmp_path, sentinel):
    for name, (data, fragment) in _bad_payloads(sentinel, _session()).items():
        path = tmp_path / f"{name}.weft.json"
        path.write_bytes(data)
        with pytest.raises(WeftError) as e:
            read_session(path)
            pytest.fail(f"{name}: accepted")
        message = str(e.value)
        assert message.startswith(f"{path}: ") and "\n" not in message, (name, message)
        fragment = {"must be a JSON object": "not a weft session file (version 1)"}.get(fragment, fragment)
        assert fragment in message, (name, message)


@pytest.mark.parametrize(
    "fields, fragment",
    [
        ({"method": "teleport"}, "unknown method 'teleport'"),
        ({"params": [1]}, "params must be an object"),
        ({"params": {"fast": [1]}}, "fast: FastParams: parameters must be a JSON object"),
        ({"params": {"fast": {"p": "0.3"}}}, "fast: parameter 'p' = '0.3' must be a number"),
        ({"params": {"fast": {"zzz": 1}}}, "fast: unknown parameter zzz for FastParams"),
        ({"inputs": ["tex.png"]}, "inputs must be an object"),
        ({"inputs": {"bogus": "tex.png"}}, "unknown input 'bogus'"),
        ({"inputs": {"texture": 3}}, "input 'texture' = 3 is not a file path"),
        ({"prototype": ["a", 1, 2]}, "prototype = ['a', 1, 2] must be [x, y, side]"),
        ({"prototype": [1, 2, 0]}, "prototype = [1, 2, 0] must be [x, y, side]"),
        ({"prototype": {"x": 1}}, "prototype = {'x': 1} must be [x, y, side]"),
        ({"lines": [1]}, "lines must be an object"),
        ({"lines": {"image_lines": "abc"}}, "image_lines must be a list of [x1, y1, x2, y2]"),
        ({"lines": {"frontal_lines": [[1, 2, 3]]}}, "frontal_lines[0] = [1, 2, 3] must be [x1, y1, x2, y2]"),
        ({"lines": {"frontal_size": [0]}}, "frontal_size = [0] must be [width, height]"),
        ({"seed": -1}, "seed = -1 must be an integer in 0..2147483647"),
        ({"seed": 2**40}, f"seed = {2**40} must be an integer in 0..2147483647"),
        ({"seed": "3"}, "seed = '3' must be an integer"),
        ({"weft_session": 2}, "not a weft session file (version 1)"),
    ],
)
def test_session_fields_of_the_wrong_kind_are_refused_naming_the_file(tmp_path, fields, fragment):
    path = tmp_path / "s.weft.json"
    path.write_text(json.dumps(_session(**fields)))
    with pytest.raises(WeftError) as e:
        read_session(path)
    assert str(e.value).startswith(f"{path}: ") and fragment in str(e.value) and "\n" not in str(e.value)


def test_a_huge_session_is_refused_by_its_size(tmp_path):
    path = tmp_path / "huge.weft.json"
    with open(path, "w") as f:
        f.write(json.dumps(_session()) + " " * (50 * 2**20))
    with pytest.raises(WeftError) as e:
        read_session(path)
    assert str(e.value) == f"{path}: 50.0 MB is too large for a weft session file (the limit is 10 MB); not read"
