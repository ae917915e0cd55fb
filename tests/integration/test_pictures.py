"""The README's pictures exist, were made by scripts/make_pictures.py, and are current."""

from __future__ import annotations

import importlib.util
import json

from tests.conftest import ROOT


def _script():
    spec = importlib.util.spec_from_file_location("make_pictures", ROOT / "scripts" / "make_pictures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_pictures_exist_and_are_current():
    script = _script()
    record = json.loads((ROOT / "docs" / "pictures.json").read_text())
    for name in script.PICTURES:
        path = ROOT / "docs" / name
        assert path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
        assert script.file_hash(path) == record["pictures"][name], f"{name} was not made by scripts/make_pictures.py"
    assert record["inputs_sha256"] == script.inputs_hash(), "the drawing code changed: run scripts/make_pictures.py"


def test_staleness_check_sees_a_change(tmp_path):  # negative control
    import shutil

    script = _script()
    for entry in script.INPUTS:
        source = ROOT / entry
        target = tmp_path / entry
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copytree(source, target) if source.is_dir() else shutil.copy(source, target)
    before = script.inputs_hash(tmp_path)
    assert before == script.inputs_hash()
    with open(tmp_path / "robodyn" / "viz" / "plots.py", "a") as handle:
        handle.write("\n# changed\n")
    assert script.inputs_hash(tmp_path) != before
