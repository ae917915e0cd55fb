"""The differential harness's options: ``--differential-seed GENERATOR:SEED`` (declared in
tests/conftest.py) or ``ROBODYN_DIFFERENTIAL_SEED=GENERATOR:SEED`` replays one case."""
