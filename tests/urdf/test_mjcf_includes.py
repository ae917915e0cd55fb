"""MJCF <include file>: read as MuJoCo reads it (the dm_control suite's layout), through
robodyn's file reader; every hostile include one URDFError sentence."""

from __future__ import annotations

import os
import shutil

import pytest

import robodyn
from robodyn.exceptions import URDFError
from tests.conftest import ROOT
from tests.urdf.mujoco_compare import largest_differences, rigid_model

pytestmark = pytest.mark.filterwarnings("ignore::robodyn.exceptions.RobodynWarning")

mujoco = pytest.importorskip("mujoco")

DATA = ROOT / "tests" / "data" / "mjcf"
BODY = '<body name="a"><joint name="j"/><geom size="0.1"/></body>'


def test_a_model_split_over_included_files_equals_mujocos():
    robot = robodyn.load(DATA / "included.xml")
    assert robot.nv == 5 and robot.source.file_format == "mjcf"
    assert max(largest_differences(robot, rigid_model(DATA / "included.xml"))) < 1e-12


def test_a_nested_include_is_found_as_mujoco_finds_it(tmp_path):
    """MuJoCo 4 resolves a name against the main file's folder first, then the including file's."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "main.xml").write_text(f'<mujoco><include file="sub/b.xml"/><worldbody>{BODY}</worldbody></mujoco>')
    (tmp_path / "sub" / "b.xml").write_text('<mujoco><include file="c.xml"/></mujoco>')
    (tmp_path / "sub" / "c.xml").write_text('<mujoco><option gravity="0 0 -1"/></mujoco>')
    for expected in ((0.0, 0.0, -1.0), (0.0, 0.0, -2.0)):
        if expected[2] == -2.0:
            (tmp_path / "c.xml").write_text('<mujoco><option gravity="0 0 -2"/></mujoco>')
        theirs = mujoco.MjModel.from_xml_path(str(tmp_path / "main.xml")).opt.gravity
        assert tuple(theirs) == expected
        assert tuple(robodyn.load(tmp_path / "main.xml").gravity_vector) == expected


def write_model(folder, include: str, extra: dict[str, str] | None = None):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "main.xml").write_text(f'<mujoco><include file="{include}"/><worldbody>{BODY}</worldbody></mujoco>')
    for name, text in (extra or {}).items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text)
    return folder / "main.xml"


def refusal(path) -> str:
    with pytest.raises(URDFError) as raised:
        robodyn.load(path)
    message = str(raised.value)
    assert "\n" not in message
    return message


def test_an_include_out_of_the_models_folder_is_refused(tmp_path):
    (tmp_path / "secret.xml").write_text('<mujoco><option gravity="0 0 0"/></mujoco>')
    assert "outside the model's folder" in refusal(write_model(tmp_path / "model", "../secret.xml"))
    assert "outside the model's folder" in refusal(write_model(tmp_path / "model2", str(tmp_path / "secret.xml")))


def test_a_symlink_out_of_the_folder_is_refused(tmp_path):
    (tmp_path / "secret.xml").write_text('<mujoco><option gravity="0 0 0"/></mujoco>')
    path = write_model(tmp_path / "model", "link.xml")
    os.symlink(tmp_path / "secret.xml", tmp_path / "model" / "link.xml")
    assert "outside the model's folder" in refusal(path)


def test_a_cycle_and_a_second_inclusion_are_refused_as_mujoco_refuses_them(tmp_path):
    cycle = write_model(
        tmp_path / "cycle",
        "a.xml",
        {"a.xml": '<mujoco><include file="b.xml"/></mujoco>', "b.xml": '<mujoco><include file="a.xml"/></mujoco>'},
    )
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_path(str(cycle))
    assert "already included" in refusal(cycle)
    twice = tmp_path / "twice"
    write_model(twice, "a.xml", {"a.xml": "<mujoco/>"})
    (twice / "main.xml").write_text(
        f'<mujoco><include file="a.xml"/><include file="a.xml"/><worldbody>{BODY}</worldbody></mujoco>'
    )
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_path(str(twice / "main.xml"))
    assert "already included" in refusal(twice / "main.xml")


def test_what_robodyns_file_reader_refuses_is_refused_in_an_include(tmp_path):
    assert "no such file" in refusal(write_model(tmp_path / "missing", "nothing.xml"))
    fifo = write_model(tmp_path / "fifo", "pipe.xml")
    os.mkfifo(tmp_path / "fifo" / "pipe.xml")
    assert "not a regular file" in refusal(fifo)
    big = write_model(tmp_path / "big", "big.xml", {"big.xml": "<mujoco>" + " " * 5000 + "</mujoco>"})
    with pytest.raises(URDFError, match=r"more than the limit|bytes together"):
        robodyn.load(big, max_bytes=4000)


def test_a_name_the_file_system_cannot_take_is_one_sentence(tmp_path):
    assert "cannot be" in refusal(write_model(tmp_path, "x" * 5000))  # resolved or read: the system says which
    assert "not a regular file" in refusal(write_model(tmp_path / "dot", "."))


def test_an_include_in_text_is_refused_and_a_wrong_root_too(tmp_path):
    with pytest.raises(URDFError, match="given as text cannot <include>"):
        robodyn.load(f'<mujoco><include file="a.xml"/><worldbody>{BODY}</worldbody></mujoco>')
    assert "root element must be <mujoco>" in refusal(write_model(tmp_path, "a.xml", {"a.xml": "<robot/>"}))


def test_bodies_and_joints_of_included_files_count_towards_the_caps(tmp_path):
    bodies = "".join(f'<body name="b{i}"><joint/><geom size="0.1"/></body>' for i in range(400))
    (tmp_path / "bodies.xml").write_text(f"<mujoco>{bodies}</mujoco>")
    (tmp_path / "main.xml").write_text('<mujoco><worldbody><include file="bodies.xml"/></worldbody></mujoco>')
    assert "more than 300 degrees of freedom" in refusal(tmp_path / "main.xml")


def test_the_suite_layout_copied_elsewhere_still_loads(tmp_path, monkeypatch):
    """Includes are relative to the model, not to the working directory."""
    shutil.copytree(DATA, tmp_path / "copy")
    monkeypatch.chdir(tmp_path)
    assert robodyn.load(tmp_path / "copy" / "included.xml").nv == 5


def test_a_chain_of_more_than_100_includes_is_refused(tmp_path):
    for index in range(102):
        (tmp_path / f"f{index}.xml").write_text(f'<mujoco><include file="f{index + 1}.xml"/></mujoco>')
    (tmp_path / "f102.xml").write_text("<mujoco/>")
    assert "more than 100 included files" in refusal(write_model(tmp_path, "f0.xml"))


def test_includes_nesting_elements_too_deep_together_are_refused(tmp_path):
    for index in range(60):
        nested = f'<default class="a{index}"><default class="b{index}"><include file="f{index + 1}.xml"/></default></default>'
        (tmp_path / f"f{index}.xml").write_text(f"<mujoco>{nested}</mujoco>")
    (tmp_path / "f60.xml").write_text("<mujoco/>")
    assert "deeper than 100 levels" in refusal(write_model(tmp_path, "f0.xml"))
