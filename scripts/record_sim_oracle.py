"""Record the simulation oracle: every case of tests/sim/oracle_cases.py, run on today's code.

Writes ``tests/sim/data/sim_oracle.npz`` (each run's ``t``, ``q``, ``v``, ``a``, ``tau``, and an
observer's residuals) and ``tests/sim/data/sim_oracle_refusals.json`` (the runs refused, with
the exception's class and message). Recorded once before the run-plan redesign; never
regenerate it to make a test pass: ``tests/sim/test_oracle.py`` holds the new code to it.

Usage: ``ROBODYN_CACHE=/tmp/cache python scripts/record_sim_oracle.py``
"""

from __future__ import annotations

import json
import sys
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.sim.oracle_cases import cases  # noqa: E402

DATA = ROOT / "tests" / "sim" / "data"


def main() -> int:
    arrays: dict[str, np.ndarray] = {}
    refusals: dict[str, list[str]] = {}
    for case in cases():
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                result = case.run()
        except Exception as error:
            refusals[case.key] = [type(error).__name__, str(error)]
            print(f"{case.key}: refused ({type(error).__name__})", flush=True)
            continue
        trajectory, residuals = result if isinstance(result, tuple) else (result, None)
        for field in ("t", "q", "v", "a", "tau"):
            arrays[f"{case.key}:{field}"] = np.asarray(getattr(trajectory, field))
        if residuals is not None:
            arrays[f"{case.key}:residuals"] = residuals
        print(f"{case.key}: {len(trajectory)} samples", flush=True)
    DATA.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(DATA / "sim_oracle.npz", **arrays)
    (DATA / "sim_oracle_refusals.json").write_text(json.dumps(refusals, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
