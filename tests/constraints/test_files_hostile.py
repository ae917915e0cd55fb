"""A constraints file's hostile and edge inputs, each refused (or read) exactly: a list that is
no list, every key of every table, every refusal's sentence, the bounds just within and just past."""

from __future__ import annotations

import pytest

from robodyn.constraints.files import read_constraints
from robodyn.exceptions import InputError

WELD = "weld:\n  - frame1: crank\n"


@pytest.mark.parametrize("value", ["0", "false", "{}", "''", "1.5", "crank"])
def test_a_list_given_as_a_scalar_or_mapping_is_refused_not_read_as_empty(value):
    with pytest.raises(InputError, match=r"anchor must be a list of anchor entries \(each a '- ' item\)"):
        read_constraints(f"anchor: {value}\n" + WELD)


def test_an_empty_list_or_a_list_left_empty_adds_nothing():
    assert len(read_constraints("anchor: []\ncontact:\n" + WELD)) == 1
