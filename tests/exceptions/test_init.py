"""robodyn.exceptions stays the one import path of every error and warning class."""

from __future__ import annotations

import importlib
import pickle
import pkgutil

import robodyn.exceptions as exceptions


def _defined_in_submodules() -> set[str]:
    names = set()
    for info in pkgutil.iter_modules(exceptions.__path__):
        module = importlib.import_module(f"robodyn.exceptions.{info.name}")
        names |= {name for name, value in vars(module).items() if not name.startswith("_") and callable(value)}
    return names - {"annotations"}


def test_every_class_of_the_submodules_is_importable_from_robodyn_exceptions():
    defined = {name for name in _defined_in_submodules() if getattr(exceptions, name, None) is not None}
    assert defined >= {"RobodynError", "URDFError", "InputError", "OutputError", "CompileError", "one_line_warnings"}
    assert sorted(defined - set(exceptions.__all__)) == []  # nothing defined below is left out


def test_each_class_names_robodyn_exceptions_and_pickles_through_it():
    for name in exceptions.__all__:
        assert getattr(exceptions, name).__module__ == "robodyn.exceptions", name
    error = pickle.loads(pickle.dumps(exceptions.TrajectoryError("run.csv", "a row is short", (3, 4))))
    assert type(error) is exceptions.TrajectoryError and error.rows == (3, 4)
