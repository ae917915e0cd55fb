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


def test_new_refusals_belong_to_the_family():
    from robodyn.exceptions import AmbiguousEndEffectorError, JointLimitWarning, StaticFrameError

    assert issubclass(StaticFrameError, robodyn.FrameError) and issubclass(AmbiguousEndEffectorError, robodyn.FrameError)
    assert issubclass(JointLimitWarning, UserWarning)
    error = AmbiguousEndEffectorError("r", ["a", "b"])
    assert str(error).count("\n") == 0 and error.candidates == ["a", "b"]
