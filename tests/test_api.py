"""The curated public API: every exported name exists."""

import robodyn


def test_every_exported_name_exists():
    for name in robodyn.__all__:
        assert getattr(robodyn, name) is not None, name


def test_version_is_a_release_string():
    major, minor, patch = robodyn.__version__.split(".")
    assert all(part.isdigit() for part in (major, minor, patch))


def test_unknown_attribute_is_an_attribute_error():
    try:
        robodyn.no_such_thing  # noqa: B018
    except AttributeError as error:
        assert "no_such_thing" in str(error)
    else:
        raise AssertionError("expected AttributeError")
