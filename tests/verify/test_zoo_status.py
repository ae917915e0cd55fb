"""docs/zoo.md is true: re-check every zoo robot and compare with the committed listing."""

from __future__ import annotations

import pytest

from robodyn.urdf.zoo import zoo_names
from robodyn.verify.zoo_status import zoo_status
from tests.conftest import ROOT


def committed_rows() -> dict[str, tuple[str, str, str]]:
    rows = {}
    for line in (ROOT / "docs" / "zoo.md").read_text(encoding="utf-8").splitlines():
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if len(cells) == 5 and cells[1] in ("pass", "fail", "excluded"):
            rows[cells[0]] = (cells[1], cells[2], cells[4])
    return rows


def test_listing_names_every_installed_zoo_robot():
    assert set(committed_rows()) == set(zoo_names())


def test_no_robot_of_the_listing_fails():
    assert all(status != "fail" for status, _, _ in committed_rows().values())


@pytest.mark.slow
@pytest.mark.parametrize("name", zoo_names())
def test_listing_row_is_reproduced(name):
    status = zoo_status(name)
    assert committed_rows()[name] == (status.status, str(status.dof) if status.dof else "", status.note.replace("|", "/"))
    if status.status != "excluded":
        assert status.worst_relative_error < 1e-9
