"""The module as a whole: what it exports, docstrings, and the README's example running as
written."""

import inspect
import os
import re

import keyanim
from conftest import REPO


def test_exports_and_versions():
    assert set(keyanim.__all__) == {"Bank", "Clip", "Dataset", "Error", "Motion", "RigCache", "encode",
                                    "format_version", "measure_error", "read_bvh", "write_bank"}
    assert re.fullmatch(r"\d+\.\d+\.\d+", keyanim.__version__)
    assert re.fullmatch(r"\d+\.\d+", keyanim.format_version)
    assert issubclass(keyanim.Error, ValueError)


def test_every_public_name_has_a_docstring():
    assert keyanim.__doc__
    for name in keyanim.__all__:
        obj = getattr(keyanim, name)
        if isinstance(obj, str):
            continue
        assert (obj.__doc__ or "").strip(), name
        if inspect.isclass(obj):
            for member, value in vars(obj).items():
                if member.startswith("_") or not (callable(value) or hasattr(value, "__get__")):
                    continue  # (Error's attribute defaults)
                assert (getattr(value, "__doc__", None) or "").strip(), "%s.%s" % (name, member)


def test_readme_example_runs(tmp_path, monkeypatch):
    text = (REPO / "README.md").read_text()
    python = text.split("## Python", 1)[1]
    code = python.split("```python\n", 1)[1].split("```", 1)[0]
    os.symlink(REPO / "data", tmp_path / "data")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    assert (tmp_path / "scratch" / "copy.bvh").exists()
