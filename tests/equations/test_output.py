"""Hostile joint and robot names cannot hijack any output of the symbolic equations."""

from __future__ import annotations

import ctypes
import dataclasses
import importlib.util
import json
import os
import shutil
import subprocess
import sys
from xml.sax.saxutils import quoteattr

import numpy as np
import pytest

import robodyn
from robodyn.common.text import comment_text, identifier, latex_text
from robodyn.common.text import printable as terminal_text
from robodyn.equations import derive_equations, render

CANARY = "CANARY"
NAMES = [
    'j2"""\nimport os; os.system(\'touch CANARY\')\n"""',
    '*/\n__attribute__((constructor)) void x(){system("touch CANARY");}\n/*',
    "cr\rname\x9b2J ??/",
    "tex $\\ {} ^_&%#~ end",
]
ROBOT = 'r"""\nimport os; os.system(\'touch CANARY\')\n"""*/ void y(){system("touch CANARY");} /*'
#: The last link's name.
LINK = 'tip"""\nimport os; os.system(\'touch CANARY\')\n#*/\x9b'
#: Not representable in XML 1.0, so put into the equations after the derivation.
ANSI = "\x1b[31mred\x1b[0m"


def _attr(text: str) -> str:
    return quoteattr(text, {"\n": "&#10;", "\r": "&#13;", "\t": "&#9;"})


def hostile_urdf() -> str:
    links = "".join(
        f'<link name="l{i}"><inertial><origin xyz="0.1 0.02 0.03"/><mass value="{1 + 0.3 * i}"/>'
        '<inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.02" iyz="0" izz="0.015"/></inertial></link>'
        for i in range(1, 5)
    )
    joints = "".join(
        f'<joint name={_attr(name)} type="{"prismatic" if i == 3 else "revolute"}"><parent link="l{i - 1}"/>'
        f'<child link="l{i}"/><origin xyz="0.2 0 0.1" rpy="0.3 0 0"/><axis xyz="0 1 0"/>'
        '<limit lower="-1" upper="1" effort="10" velocity="1"/></joint>'
        for i, name in enumerate(NAMES, start=1)
    )
    text = f'<?xml version="1.0"?><robot name={_attr(ROBOT)}><link name="l0"/>{links}{joints}</robot>'
    return text.replace('"l4"', _attr(LINK))


@pytest.fixture(scope="module")
def hostile():
    equations = derive_equations(hostile_urdf(), form="compact")
    return dataclasses.replace(equations, joint_names=[*equations.joint_names[:-1], equations.joint_names[-1] + ANSI])


def test_identifiers_are_safe_and_collision_free():
    taken: set[str] = set()
    names = [identifier(n, taken, prefix="q_") for n in ["a b", "a_b", "a-b", "", "1x", *NAMES]]
    assert len(set(names)) == len(names)
    assert all(n.isidentifier() and n.isascii() for n in names)
    assert identifier("for").isidentifier() and identifier("for") != "for"


@pytest.mark.parametrize("name", [*NAMES, ROBOT, ANSI, "\u2028x\u202e"])
def test_escapes_leave_nothing_dangerous(name):
    comment = comment_text(name)
    assert comment.isascii() and comment.isprintable()
    assert not any(bad in comment for bad in ('"', "*/", "/*", "\\", "??", "\n", "\r"))
    terminal = terminal_text(name)
    assert terminal.isprintable() and "\x1b" not in terminal and "\x9b" not in terminal and "\u2028" not in terminal
    tex = latex_text(name)
    assert tex.isascii() and "\n" not in tex and "$" not in tex.replace(r"\$", "")


def test_negative_control_raw_names_would_break_out():
    """The hostile names really do close a docstring and a C comment when not escaped."""
    assert '"""' in NAMES[0] and "*/" in NAMES[1]
    with pytest.raises(SyntaxError):
        compile(f'"""{NAMES[0]}"""\n"""', "<raw>", "exec")


def test_generated_python_imports_computes_and_runs_nothing(hostile, tmp_path, monkeypatch, rng):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "hostile_dynamics.py"
    path.write_text(render(hostile, "python"))
    spec = importlib.util.spec_from_file_location("hostile_dynamics", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert not (tmp_path / CANARY).exists()
    assert hostile.joint_names == module.JOINT_NAMES
    robot = robodyn.load(hostile_urdf())
    q = robot.random_configuration(rng, 5)
    v, a = rng.normal(size=(2, 5, robot.nv))
    tau = module.inverse_dynamics(q, v, a)
    assert np.max(np.abs(tau - robot.inverse_dynamics(q, v, a))) < 1e-9 * max(1.0, np.max(np.abs(tau)))


@pytest.mark.skipif(shutil.which("gcc") is None, reason="needs a C compiler")
def test_generated_c_compiles_with_werror_runs_and_runs_nothing(hostile, tmp_path, rng):
    source, library = tmp_path / "hostile.c", tmp_path / "libhostile.so"
    source.write_text(render(hostile, "c"))
    subprocess.run(
        ["gcc", "-std=c99", "-Wall", "-Werror", "-shared", "-fPIC", str(source), "-o", str(library), "-lm"],
        check=True,
        cwd=tmp_path,
    )
    # Load it in a separate process running in tmp_path: a constructor would run on load.
    script = (
        "import ctypes, sys, numpy as np\n"
        f"lib = ctypes.CDLL({str(library)!r})\n"
        "p = ctypes.POINTER(ctypes.c_double)\n"
        "q, v, a, tau = (np.array(x, dtype=float) for x in (sys.argv[1:5], sys.argv[5:9], sys.argv[9:13], [0] * 4))\n"
        "lib.inverse_dynamics(*(x.ctypes.data_as(p) for x in (q, v, a, tau)))\n"
        "print(' '.join(repr(float(t)) for t in tau))\n"
    )
    robot = robodyn.load(hostile_urdf())
    q = robot.random_configuration(rng)
    v, a = rng.normal(size=(2, robot.nv))
    out = subprocess.run(
        [sys.executable, "-c", script, *(repr(float(x)) for x in np.concatenate([q, v, a]))],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=True,
        env={**os.environ, "PATH": os.environ.get("PATH", "")},
    ).stdout
    assert not (tmp_path / CANARY).exists()
    tau = np.array([float(t) for t in out.split()])
    assert np.max(np.abs(tau - robot.inverse_dynamics(q, v, a))) < 1e-9 * max(1.0, np.max(np.abs(tau)))
    assert ctypes  # ctypes is used in the child


def test_text_json_and_latex_escape_every_name(hostile):
    text = render(hostile, "text")
    assert "\x1b" not in text and "\x9b" not in text and "\r" not in text
    assert all(line.isprintable() for line in text.splitlines())
    data = json.loads(render(hostile, "json"))
    assert data["joint_names"] == hostile.joint_names and data["robot"] == hostile.robot
    tex = render(hostile, "latex")
    assert tex.isascii() and "\x1b" not in tex and "touch CANARY" in tex  # shown, escaped
    assert r"system(\textquotedbl{}touch CANARY\textquotedbl{})" in tex


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="needs pdflatex (make tex)")
def test_hostile_latex_compiles(hostile, tmp_path):
    from robodyn.equations.render_latex import compile_latex

    pdf, log = compile_latex(render(hostile, "latex"), tmp_path)
    assert pdf.stat().st_size > 0 and "! " not in log
    assert not (tmp_path / CANARY).exists()


def test_kept_parameters_named_after_a_hostile_link_are_safe(tmp_path):
    equations = derive_equations(hostile_urdf(), form="compact", keep_params=True)
    assert any(owner == LINK for _, owner, _ in equations.labels.values())
    assert all(symbol.name.isidentifier() for symbol in equations.parameters)
    text = render(equations, "text")
    assert all(line.isprintable() for line in text.splitlines()) and "\x9b" not in text
    assert render(equations, "latex").isascii()
    assert all(name.isidentifier() for name in json.loads(render(equations, "json"))["parameters"])


def test_kinematics_of_a_hostile_frame_are_safe(tmp_path, monkeypatch):
    from robodyn.equations.kinematics import derive_kinematics, render_kinematics

    monkeypatch.chdir(tmp_path)
    kinematics = derive_kinematics(hostile_urdf(), LINK)
    namespace: dict = {}
    exec(compile(render_kinematics(kinematics, "python"), "kinematics.py", "exec"), namespace)
    assert not (tmp_path / CANARY).exists()
    assert namespace["frame_position"](np.zeros(4)).shape == (3,)
    assert all(line.isprintable() for line in render_kinematics(kinematics, "text").splitlines())
    assert render_kinematics(kinematics, "latex").isascii()
    assert json.loads(render_kinematics(kinematics, "json"))["frame"] == LINK
