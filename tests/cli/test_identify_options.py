"""Every option of `robodyn identify` and `robodyn excite` alone, reading back what they wrote,
and crossed pairwise.

``identify`` is given noise-free torques of the robot loaded with the run's options (its
gravity, locks, floating base; with ``--friction`` its joints' damping and friction too), so
every base parameter it prints must be the URDF's (the independent truth): an option lost
on the way (a gravity, a lock, the friction) shows as a wrong parameter or a refused file.
What it writes is read back with the json module and ElementTree: the JSON's values are the
printed ones, the identified URDF keeps every link the run did not identify and gives the
one it did its mass. ``excite`` writes a trajectory whose torques are the inverse dynamics
(damping and friction included) of the run's robot, sampled at ``--rate`` over
``--duration``, within ``--velocity-limit`` and ``--acceleration-limit`` (the tighter one
binding), equal to :func:`robodyn.ident.run.excite_run` given the same options.

The robots: the oblique test robot and the xacro test arm (mimic joint, ``--xacro-arg``,
``--package``), locked or not, under the default or an oblique gravity; identify also
floating (excite refuses a floating base: one line). Both commands run base-parameter
numerics of about 0.1–1 s a run: the slow tier, but for the refusals.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from robodyn.ident.run import excite_run
from tests.cli.model_options import GRAVITY, OBLIQUE, model_arguments, refused_in_one_line, robot_of, run_command
from tests.differential.cases import random_state_batch
from tests.differential.pairs import expected_header, written_columns
from tests.pairwise import pairwise, uncovered_pairs

SAMPLES = 40
#: The link ``--bodies`` names, per model.
BODIES = {"oblique": ("arm",), "xacro": ("r_upper",)}
#: The oblique robot's links welded into that body: by its fixed joint, and by the lock too.
WELDED = {None: ("arm", "bracket_link"), "locked": ("arm", "bracket_link", "ram")}

#: identify's options; the first value is the default (the option left out).
IDENTIFY: dict[str, tuple | list] = {
    "model": ("oblique", "xacro"),
    "base": (None, "floating"),
    "gravity": (None, GRAVITY),
    "lock": (None, "locked"),
    "method": ("ls", "wls", "physical"),
    "friction": (False, True),
    "bodies": (None, "one link"),
    "out": (False, True),
    "urdf_out": (False, True),
}
IDENTIFY_DEFAULT = {name: values[0] for name, values in IDENTIFY.items()}


def identify_valid(run: dict) -> bool:
    """Only the physical method gives an identified URDF; it writes only a URDF file (not the
    xacro's). A physical run identifies one body: a whole robot's physical fit takes seconds
    (tests/ident has those)."""
    if run.get("urdf_out") and run.get("method", "physical") != "physical":
        return False
    physical = run.get("method") == "physical" or run.get("urdf_out")
    if physical and run.get("bodies", "one link") is None:
        return False
    return not (run.get("urdf_out") and run.get("model") == "xacro")


IDENTIFY_RUNS = pairwise(IDENTIFY, identify_valid)


def test_the_identify_runs_cover_every_valid_pair_and_are_few():
    assert uncovered_pairs(IDENTIFY_RUNS, IDENTIFY, identify_valid) == []
    assert len(IDENTIFY_RUNS) <= 11 and all(identify_valid(run) for run in IDENTIFY_RUNS)


def identify_cli(options: dict, tmp_path):
    """Noise-free torques of the options' robot, identified by the command: what it printed and wrote."""
    robot = robot_of(options)
    q, v, a = random_state_batch(robot, np.random.default_rng(39), SAMPLES)
    tau = robot.inverse_dynamics(q, v, a, joint_friction=options["friction"])
    data = robot_trajectory(robot, q, v, a, tau).save(tmp_path / "data.csv")
    out, urdf_out = tmp_path / "identified.json", tmp_path / "identified.urdf"
    model = model_arguments(options)
    argv = ["identify", model[0], str(data), *model[1:]]  # DATA before any option (argparse's nargs="?")
    argv += ["--method", options["method"]] if options["method"] != "ls" else []
    argv += ["--friction"] if options["friction"] else []
    argv += ["--bodies", BODIES[options["model"]][0]] if options["bodies"] else []
    argv += (["--out", str(out)] if options["out"] else []) + (["--urdf-out", str(urdf_out)] if options["urdf_out"] else [])
    code, printed, error = run_command(argv)
    assert code == 0, error
    return robot, printed, out if options["out"] else None, urdf_out if options["urdf_out"] else None


def robot_trajectory(robot, q, v, a, tau):
    from robodyn.trajectory import Trajectory

    return Trajectory(np.arange(len(q)) * 0.01, q, v, a, tau, list(robot.joint_names), robot.name)


def printed_table(printed: str) -> dict[str, tuple[float, float]]:
    """The printed table: parameter name -> (identified, URDF)."""
    lines = printed.splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith("parameter")) + 1
    rows = [line.split() for line in lines[start:] if line.strip() and not line.startswith("wrote ")]
    return {row[0]: (float(row[1]), float(row[3])) for row in rows}


def check_identify(options: dict, tmp_path) -> dict[str, tuple[float, float]]:
    robot, printed, out, urdf_out = identify_cli(options, tmp_path)
    header = printed.splitlines()[0]
    assert header.startswith(f"{robot.name}: {options['method']} identification of ") and f"from {SAMPLES} samples" in header
    table = printed_table(printed)
    identified, urdf = (np.array(column) for column in zip(*table.values(), strict=True))
    np.testing.assert_allclose(identified, urdf, rtol=1e-4, atol=1e-5 * np.abs(urdf).max())  # six printed digits
    names = list(table)
    assert any(name.startswith(("fv[", "fc[")) for name in names) == options["friction"]
    if options["bodies"]:  # one body's ten parameters (and the friction's)
        link = BODIES[options["model"]][0]
        assert {name[name.index("[") :] for name in names if not name.startswith(("fv[", "fc["))} == {f"[{link}]"}
        if options["model"] == "oblique":  # the welded links' masses in the file
            assert table[f"m[{link}]"][1] == pytest.approx(sum(file_masses(WELDED[options["lock"]])), rel=1e-6)
        elif not options["lock"]:  # the first moment of --xacro-arg upper_mass:=2.1 at its box's centre (0.02, -0.01, 0.3)
            assert table[f"mz[{link}]"][1] == pytest.approx(2.1 * 0.3, rel=1e-6)
    if out is not None:
        written = json.loads(out.read_text())
        assert written["method"] == options["method"] and written["samples"] == SAMPLES
        assert [entry["name"] for entry in written["base_parameters"]] == names
        for entry in written["base_parameters"]:
            assert f"{entry['value']:.6g}" == f"{table[entry['name']][0]:.6g}"
        assert f"wrote {out}" in printed
    else:
        assert "wrote" not in printed.replace(f"wrote {urdf_out}", "")
    if urdf_out is not None:
        check_identified_urdf(options, urdf_out, table)
    return table


def file_masses(links, path=OBLIQUE) -> list[float]:
    """The masses of ``links`` in a URDF (ElementTree; a link without ``<inertial>``: 0)."""
    found = {link.get("name"): link.find("inertial/mass") for link in ET.parse(path).getroot().iter("link")}
    return [float(getattr(found[name], "attrib", {}).get("value", 0.0)) for name in links]


def check_identified_urdf(options: dict, urdf_out, table: dict) -> None:
    """The identified URDF (ElementTree): with ``--bodies`` the links the run did not identify
    keep their ``<inertial>``, and those of the body identified have its mass."""
    original = {link.get("name"): link for link in ET.parse(OBLIQUE).getroot().iter("link")}
    written = {link.get("name"): link for link in ET.parse(urdf_out).getroot().iter("link")}
    assert set(written) == set(original)
    if options["bodies"]:
        welded = WELDED[options["lock"]]
        for name, element in written.items():
            if name not in welded:
                kept, was = element.find("inertial"), original[name].find("inertial")
                assert kept is not None and was is not None and ET.tostring(kept) == ET.tostring(was), name
        assert sum(file_masses(welded, urdf_out)) == pytest.approx(sum(file_masses(welded)), rel=1e-4)


@pytest.fixture(scope="module")
def identify_default(tmp_path_factory):
    return check_identify(IDENTIFY_DEFAULT, tmp_path_factory.mktemp("default"))


IDENTIFY_ALONE = [(name, value) for name, values in IDENTIFY.items() for value in values[1:]]


@pytest.mark.slow
@pytest.mark.parametrize(("option", "value"), IDENTIFY_ALONE, ids=[f"{n}={v}" for n, v in IDENTIFY_ALONE])
def test_each_identify_option_alone_changes_what_it_says(option, value, tmp_path, identify_default):
    physical = {"method": "physical", "bodies": "one link"} if option in ("urdf_out", "method") and value != "wls" else {}
    options = IDENTIFY_DEFAULT | {option: value} | physical
    table = check_identify(options, tmp_path)
    if physical:  # one body's parameters (checked above), fewer than the whole robot's
        assert len(table) < len(identify_default)
    elif option in ("method", "out", "gravity"):  # the same parameters (from other torques)
        assert list(table) == list(identify_default)
    else:
        assert set(table) != set(identify_default)


@pytest.mark.slow
@pytest.mark.parametrize("run", IDENTIFY_RUNS[1:], ids=[str(k) for k in range(1, len(IDENTIFY_RUNS))])
def test_identify_options_crossed_pairwise_find_the_urdfs_parameters(run, tmp_path):
    check_identify(run, tmp_path)


@pytest.mark.slow
def test_identify_friction_left_out_does_not_fit_torques_with_friction(tmp_path):
    """The negative control of the check above: torques with friction, identified without."""
    robot = robot_of(IDENTIFY_DEFAULT)
    q, v, a = random_state_batch(robot, np.random.default_rng(39), SAMPLES)
    data = robot_trajectory(robot, q, v, a, robot.inverse_dynamics(q, v, a, joint_friction=True))
    code, printed, _ = run_command(["identify", str(OBLIQUE), str(data.save(tmp_path / "d.csv"))])
    assert code == 0
    identified, urdf = (np.array(column) for column in zip(*printed_table(printed).values(), strict=True))
    assert np.abs(identified - urdf).max() > 1e-3 * np.abs(urdf).max()


def test_what_identify_would_not_use_is_refused_in_one_line(tmp_path):
    """--base-parameters identifies nothing: DATA, --method, --out, --urdf-out with it were
    silently ignored (no file written); --format without it was too."""
    robot = robot_of(IDENTIFY_DEFAULT)
    q, v, a = random_state_batch(robot, np.random.default_rng(3), 30)
    data = str(robot_trajectory(robot, q, v, a, robot.inverse_dynamics(q, v, a)).save(tmp_path / "d.csv"))
    oblique = str(OBLIQUE)
    out = tmp_path / "base.json"
    refused_in_one_line(["identify", oblique, "--base-parameters", "--out", str(out)], "--base-parameters", "--out")
    refused_in_one_line(["identify", oblique, data, "--base-parameters"], "--base-parameters", "DATA")
    refused_in_one_line(["identify", oblique, "--base-parameters", "--method", "wls"], "--method")
    refused_in_one_line(["identify", oblique, "--base-parameters", "--urdf-out", str(out)], "--urdf-out")
    refused_in_one_line(["identify", oblique, data, "--format", "json"], "--format", "--base-parameters")
    refused_in_one_line(["identify", oblique, data, "--urdf-out", str(out)], "--urdf-out", "physical")
    refused_in_one_line(["identify", oblique, data, "--bodies", "r_upper"], "r_upper")
    assert not out.exists()


# --------------------------------------------------------------------------------------
# robodyn excite
# --------------------------------------------------------------------------------------
#: excite's options; the first value is what every run passes (the command's defaults, a
#: 10 s period at 100 Hz and 60 iterations, take seconds), or the option left out.
EXCITE: dict[str, tuple | list] = {
    "model": ("oblique", "xacro"),
    "gravity": (None, GRAVITY),
    "lock": (None, "locked"),
    "duration_rate": ((2.0, 25.0), (1.5, 40.0)),
    "harmonics": (1, 2),
    "velocity_limit": (None, 0.03),
    "acceleration_limit": (None, "per joint"),
    "seed": (None, 7),
    "out": (".csv", ".npz"),
}
EXCITE_DEFAULT = {name: values[0] for name, values in EXCITE.items()}
#: Crossed pairwise: the options that shape the motion (the model's gravity and lock, the
#: seed and the file's format change nothing else: alone they are enough, at 0.25 s a run).
CROSSED = ("model", "duration_rate", "harmonics", "velocity_limit", "acceleration_limit")
EXCITE_RUNS = [EXCITE_DEFAULT | run for run in pairwise({name: EXCITE[name] for name in CROSSED})]
#: One run with all the others given too (compared with the library, as is a second).
EXCITE_RUNS[1] |= {"gravity": GRAVITY, "lock": "locked", "seed": 7, "out": ".npz"}
ITERATIONS = 3
#: The crossed runs compared with the library given the same options (each costs a run more).
COMPARED = (1, 3)


def test_the_excite_runs_cover_every_pair_and_are_few():
    assert uncovered_pairs(EXCITE_RUNS, {name: EXCITE[name] for name in CROSSED}) == []
    assert len(EXCITE_RUNS) <= 7 and EXCITE_RUNS[0] == EXCITE_DEFAULT  # not the 32 of all combinations


def acceleration_limits(robot) -> np.ndarray:
    """Per joint: 1 rad/s² for a revolute joint, 0.1 m/s² for a prismatic one (the default
    limits' fifth: they bind)."""
    return np.array([0.1 if joint.type == "prismatic" else 1.0 for joint in robot.joints])


def excite_keywords(options: dict, robot) -> dict:
    keywords = {name: options[name] for name in ("harmonics", "velocity_limit")}
    keywords["duration"], keywords["rate"] = options["duration_rate"]
    keywords["acceleration_limit"] = acceleration_limits(robot) if options["acceleration_limit"] else None
    return keywords | {"seed": options["seed"] or 0, "iterations": ITERATIONS}


def check_excite(options: dict, tmp_path) -> dict:
    robot = robot_of(options)
    keywords = excite_keywords(options, robot)
    out = tmp_path / f"excitation{options['out']}"
    argv = ["excite", *model_arguments(options), "--out", str(out), "--iterations", str(ITERATIONS)]
    argv += [f"--{name}={keywords[name]:g}" for name in ("duration", "harmonics", "rate")]
    argv += [f"--velocity-limit={options['velocity_limit']:g}"] if options["velocity_limit"] else []
    argv += (
        ["--acceleration-limit=" + ",".join(f"{x:g}" for x in keywords["acceleration_limit"])]
        if options["acceleration_limit"]
        else []
    )
    argv += [f"--seed={options['seed']}"] if options["seed"] else []
    code, printed, error = run_command(argv)
    assert code == 0, error
    columns = written_columns(out)
    assert sorted(columns) == sorted(expected_header(robot))
    names = list(robot.joint_names)
    q, v, a, tau = (np.column_stack([columns[f"{kind}[{n}]"] for n in names]) for kind in ("q", "v", "a", "tau"))
    duration, rate = options["duration_rate"]
    samples = round(duration * rate)
    np.testing.assert_allclose(columns["t"], np.arange(samples) / rate, atol=1e-12)
    # the torques of this robot (its gravity, locks), its damping and friction included
    np.testing.assert_allclose(robot.inverse_dynamics(q, v, a, joint_friction=True), tau, atol=1e-9 * np.abs(tau).max())
    assert np.abs(robot.inverse_dynamics(q, v, a) - tau).max() > 1e-6  # negative control: the friction is in
    velocity = np.array([options["velocity_limit"] or joint.velocity for joint in robot.joints])
    assert np.all(np.abs(v) <= velocity * 1.01)
    if options["acceleration_limit"]:
        assert np.all(np.abs(a) <= keywords["acceleration_limit"] * 1.01)
    lines = printed.splitlines()
    assert f"excitation of {duration:g} s, {options['harmonics']} harmonics" in lines[0]
    assert lines[-1] == f"wrote {out} ({samples} samples at {rate:g} Hz)"
    return columns


EXCITE_ALONE = [(name, value) for name, values in EXCITE.items() for value in values[1:]]


@pytest.fixture(scope="module")
def excite_default(tmp_path_factory):
    return check_excite(EXCITE_DEFAULT, tmp_path_factory.mktemp("excite"))


@pytest.mark.slow
@pytest.mark.parametrize(("option", "value"), EXCITE_ALONE, ids=[f"{n}={v}" for n, v in EXCITE_ALONE])
def test_each_excite_option_alone_changes_the_motion(option, value, tmp_path, excite_default):
    columns = check_excite(EXCITE_DEFAULT | {option: value}, tmp_path)
    if option == "out":
        for name, values in excite_default.items():
            np.testing.assert_array_equal(columns[name], values, err_msg=name)
    elif option in ("velocity_limit", "acceleration_limit"):  # it binds: the motion without it goes beyond
        robot = robot_of(EXCITE_DEFAULT)
        kind, limit = ("v", value) if option == "velocity_limit" else ("a", acceleration_limits(robot))
        default = np.column_stack([excite_default[f"{kind}[{name}]"] for name in robot.joint_names])
        assert np.any(np.abs(default) > limit * 1.01)
    elif set(columns) == set(excite_default) and len(columns["t"]) == len(excite_default["t"]):
        assert max(np.abs(columns[n] - excite_default[n]).max() for n in columns if n != "t") > 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("run", EXCITE_RUNS[1:], ids=[str(k) for k in range(1, len(EXCITE_RUNS))])
def test_excite_options_crossed_pairwise_write_the_librarys_motion(run, tmp_path):
    columns = check_excite(run, tmp_path)
    if EXCITE_RUNS.index(run) not in COMPARED:
        return
    robot = robot_of(run)
    keywords = excite_keywords(run, robot)
    excite_run(robot, out=tmp_path / "library.npz", **keywords)
    library = written_columns(tmp_path / "library.npz")
    for name, values in library.items():
        np.testing.assert_allclose(columns[name], values, rtol=1e-12, atol=1e-12, err_msg=name)


def test_a_limit_of_another_count_is_refused_naming_the_parameter():
    """acceleration_limit=[3, 3, 0.4] for a robot of four joints raised numpy's ValueError
    (robodyn excite: a traceback); now one InputError naming it, before any work."""
    from robodyn.exceptions import InputError
    from robodyn.ident.excitation import excite

    robot = robot_of(IDENTIFY_DEFAULT)
    with pytest.raises(InputError, match=r"^acceleration_limit must be one value or 4 \(j_yaw, .*got 3 values"):
        excite(robot, acceleration_limit=[3.0, 3.0, 0.4])
    with pytest.raises(InputError, match=r"^velocity_limit must be one value or 4 .*got 2 values"):
        excite(robot, velocity_limit=[1.0, 1.0])


@pytest.mark.slow
def test_a_limit_of_another_count_is_one_line_not_a_traceback(tmp_path):
    """The same on the command line: one line naming the flag."""
    oblique = ["excite", str(OBLIQUE), "--out", str(tmp_path / "e.csv"), "--iterations", "1"]
    refused_in_one_line([*oblique, "--acceleration-limit", "3,3,0.4"], "--acceleration-limit", "j_tool", "3 values")
    refused_in_one_line([*oblique, "--velocity-limit", "1,1"], "--velocity-limit", "2 values")
    assert not (tmp_path / "e.csv").exists()


@pytest.mark.slow
def test_what_excite_cannot_do_is_one_line(tmp_path):
    oblique = ["excite", str(OBLIQUE), "--out", str(tmp_path / "e.csv"), "--iterations", "1"]
    refused_in_one_line([*oblique, "--velocity-limit=-1"], "--velocity-limit")
    assert not (tmp_path / "e.csv").exists()
