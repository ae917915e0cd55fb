"""The README tells a user how robodyn really installs: from a clone, since it is on no
package index (issue 29, item 12; the wheel itself: tests/integration/test_wheel.py)."""

from __future__ import annotations

import re

from tests.conftest import ROOT


def _install_section() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    start = text.index("## Installing")
    end = text.index("\n## ", start + 1)
    return text[start:end]


def test_the_install_section_says_to_install_from_a_clone():
    section = _install_section()
    assert "no package index" in section
    commands = re.findall(r"`(pip install [^`]+)`", section) + re.findall(r"^(pip install \S+)", section, re.MULTILINE)
    assert "pip install ." in commands and "pip install '.[zoo]'" in commands
    offered = [c for c in commands if re.search(r"pip install '?robodyn", c)]
    # the only mention of the bare name is the warning that it finds nothing (or someone else's)
    assert offered == ["pip install robodyn"] and "someone else's" in section
