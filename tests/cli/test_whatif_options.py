"""Every option of `robodyn whatif` alone, reading back what it printed, and crossed pairwise.

Each run's table (JSON read with the json module, or the text) is what
:func:`robodyn.sim.whatif.what_if` gives for the same options, and holds what can be told
without it: a row a material × payload × force in sweep order; a payload adds exactly its
mass to the robot's (the oblique robot's mass is its URDF's, read with ElementTree); a load at
a frame changes only the torques of the joints that carry that frame (those after it keep
their peaks: the kinematic tree's law, the negative control of ``--frame``); a force changes
those of some joint that carries it. Each option alone changes what it says against the run
with none.

The robots: the generated RP arm (whose materials ``--materials`` sets) and the oblique test
robot (3-D, oblique axes, a prismatic joint; ``whatif`` takes no xacro options).
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from robodyn.sim.whatif import what_if
from tests.cli.model_options import OBLIQUE, refused_in_one_line, run_command
from tests.pairwise import pairwise, uncovered_pairs

pytestmark = pytest.mark.slow  # about 0.1 s of CPU a run

#: Per model: an inner frame (``--frame``), and the joints that do not carry it.
INNER = {"rp_arm": ("link1", ("joint2",)), "oblique": ("arm", ("j_extend", "j_tool"))}
DEFAULT_MATERIALS = ("abs", "aluminium", "steel")

#: Each option's values; the first is the default (the option left out).
FACTORS: dict[str, tuple | list] = {
    "model": ("rp_arm", "oblique"),
    "materials": (None, ("aluminium", "2000")),
    "payloads": ((0.0, 0.5, 2.0), (0.0, 1.5)),
    "force": (None, (0.0, 5.0, -20.0)),
    "frame": (None, "inner"),
    "duration": (1.5, 0.8),
    "json": (False, True),
}
DEFAULT = {name: values[0] for name, values in FACTORS.items()}


def valid(run: dict) -> bool:
    """Materials apply to the generated RP arm only."""
    return not (run.get("materials") and run.get("model") == "oblique")


RUNS = pairwise(FACTORS, valid)


def test_the_runs_cover_every_valid_pair_and_are_few():
    assert uncovered_pairs(RUNS, FACTORS, valid) == []
    assert len(RUNS) <= 9 and all(valid(run) for run in RUNS)  # not the 96 of all combinations


def library_table(options: dict):
    model = str(OBLIQUE) if options["model"] == "oblique" else "rp_arm"
    forces = ((0.0, 0.0, 0.0),) + ((options["force"],) if options["force"] else ())
    frame = INNER[options["model"]][0] if options["frame"] else None
    return what_if(
        model, materials=options["materials"], payloads=options["payloads"], forces=forces,
        duration=options["duration"], frame=frame,
    )  # fmt: skip


def run_cli(options: dict) -> dict:
    """Run the command; its table as the JSON's dict (the text's is checked against the library's)."""
    argv = ["whatif", *([str(OBLIQUE)] if options["model"] == "oblique" else [])]
    argv += ["--materials", ",".join(options["materials"])] if options["materials"] else []
    argv += ["--payloads", ",".join(map(str, options["payloads"]))] if options["payloads"] != DEFAULT["payloads"] else []
    argv += ["--force=" + ",".join(map(str, options["force"]))] if options["force"] else []
    argv += ["--frame", INNER[options["model"]][0]] if options["frame"] else []
    argv += ["--duration", str(options["duration"])] if options["duration"] != DEFAULT["duration"] else []
    code, printed, error = run_command([*argv, *(["--json"] if options["json"] else [])])
    assert code == 0, error
    expected = library_table(options)
    if options["json"]:
        table = json.loads(printed)
        assert table == json.loads(json.dumps(expected.to_dict()))
        return table
    assert printed == expected.text() + "\n"
    assert printed.startswith(f"{expected.robot}: one rest-to-rest motion of {options['duration']:g} s")
    return json.loads(json.dumps(expected.to_dict()))  # the numbers the text shows, to check below


def check_run(options: dict) -> dict:
    table = run_cli(options)
    rows, names = table["rows"], table["joint_names"]
    materials = options["materials"] or (DEFAULT_MATERIALS if options["model"] == "rp_arm" else ("as loaded",))
    forces = [[0.0, 0.0, 0.0], *([list(options["force"])] if options["force"] else [])]
    sweep = [(m, p, f) for m in materials for p in options["payloads"] for f in forces]
    assert [(r["material"], r["payload_kg"], r["force_N"]) for r in rows] == [(m, float(p), f) for m, p, f in sweep]
    for row in rows:  # a payload adds its mass
        unloaded = next(r for r in rows if r["material"] == row["material"] and r["payload_kg"] == 0.0)
        assert row["robot_mass_kg"] == pytest.approx(unloaded["robot_mass_kg"] + row["payload_kg"], abs=1e-12)
    if options["model"] == "oblique":
        masses = [float(m.attrib["value"]) for m in ET.parse(OBLIQUE).getroot().iter("mass")]
        assert rows[0]["robot_mass_kg"] == pytest.approx(sum(masses), rel=1e-12)
    frame_free = [names.index(n) for n in INNER[options["model"]][1]] if options["frame"] else []
    for material in materials:  # the joints after the frame do not feel its load
        peaks = np.array([r["peak_torque"] for r in rows if r["material"] == material])
        np.testing.assert_allclose(peaks[:, frame_free], peaks[:1, frame_free].repeat(len(peaks), 0), rtol=1e-9)
        if options["force"]:  # a force changes some joint that carries it
            assert np.abs(peaks[1::2] - peaks[0::2]).max() > 1e-3
    return table


ALONE = [(name, value) for name, values in FACTORS.items() for value in values[1:]]


@pytest.fixture(scope="module")
def default_table():
    return check_run(DEFAULT)


@pytest.mark.parametrize(("option", "value"), ALONE, ids=[f"{name}={value}" for name, value in ALONE])
def test_each_option_alone_changes_what_it_says_and_nothing_else(option, value, default_table):
    table = check_run(DEFAULT | {option: value})
    rows, default_rows = table["rows"], default_table["rows"]
    if option == "json":
        assert table == default_table
    elif option == "force":  # a row more a variant; those without the force are the default's
        assert rows[0::2] == default_rows
    elif option == "payloads":  # the payload 0 rows are the default's
        assert [r for r in rows if r["payload_kg"] == 0.0] == [r for r in default_rows if r["payload_kg"] == 0.0]
        assert len(rows) == 2 * len(DEFAULT_MATERIALS)
    elif option == "frame":  # the unloaded rows are the default's, the loaded ones not
        assert [r for r in rows if r["payload_kg"] == 0.0] == [r for r in default_rows if r["payload_kg"] == 0.0]
        assert all(r != d for r, d in zip(rows, default_rows, strict=True) if r["payload_kg"] > 0)
    elif option == "materials":
        assert rows[:3] == default_rows[3:6]  # aluminium is aluminium
        assert [r["material"] for r in rows[3:]] == ["2000"] * 3
    else:  # duration, model: every peak changes
        assert all(r["peak_torque"] != d["peak_torque"] for r, d in zip(rows, default_rows, strict=False))


@pytest.mark.parametrize("run", RUNS[1:], ids=[str(k) for k in range(1, len(RUNS))])
def test_the_options_crossed_pairwise_print_the_librarys_table(run):
    check_run(run)


@pytest.mark.parametrize(
    ("argv", "names"),
    [
        ([str(OBLIQUE), "--materials", "steel"], ("materials",)),
        (["--force", "1,2"], ("--force", "3 values")),
        (["--frame", "base_link"], ("base_link",)),
        (["--payloads=-1"], ("--payloads",)),
    ],
)
def test_what_whatif_cannot_do_is_one_line(argv, names):
    refused_in_one_line(["whatif", *argv], *names)


def test_plot_alone_draws_a_png_and_says_so(tmp_path):
    """``--plot`` (matplotlib: left out of the crossed runs) writes the bar chart and adds
    its key to the JSON, nothing else."""
    plot = tmp_path / "whatif.png"
    code, printed, error = run_command(["whatif", "--payloads", "0,1", "--plot", str(plot), "--json"])
    assert code == 0, error
    head = plot.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and int.from_bytes(head[16:20], "big") > 200
    _, without, _ = run_command(["whatif", "--payloads", "0,1", "--json"])
    assert json.loads(printed) == json.loads(without) | {"plot": str(plot)}
