"""Example: identify a payload the nominal model does not know, from noisy measurements.

The "real" robot is the ur5 carrying 2.5 kg at its tool flange (``tool0``); the nominal
model is the plain ur5. The script

1. computes the base parameters and an exciting trajectory (Fourier series, SLSQP on the
   condition number of the base regressor) for the nominal model;
2. "measures" the real robot along it: the torques of its inverse dynamics along the
   exact trajectory, plus Gaussian noise (1 % of each joint's peak torque), and encoder
   noise on ``q`` (1e-4 rad); velocities and accelerations come from the noisy positions
   by zero-phase low-pass filtering and central differences, and the torques go through
   the same filter and are decimated, as on a real rig (Gautier's parallel filtering);
3. identifies (a) all base parameters (``ls`` and ``physical``) and (b) only the
   parameters of the body carrying the payload (``wrist_3_link``; the rest held at the
   URDF's values), whose change from the nominal model is the payload: its mass and centre
   of mass;
4. predicts the torques on a different validation trajectory and reports the errors.

Run: ``python scripts/example_identification.py [--quick]`` (``--quick``: fewer optimiser
iterations).
"""

from __future__ import annotations

import argparse
import json

import numpy as np
import scipy.signal

import robodyn
from robodyn.dynamics.regressor import body_links, inertial_parameters
from robodyn.ident import base_parameters, excite, identify
from robodyn.sim.trajectory import Trajectory

PAYLOAD_MASS = 2.5  # [kg]
PAYLOAD_COM = np.array([0.03, -0.02, 0.06])  # in the tool0 frame, [m]
RATE = 200.0  # sampling rate [Hz]
TORQUE_NOISE = 0.01  # fraction of each joint's peak torque (standard deviation)
ENCODER_NOISE = 1e-4  # [rad]
CUTOFF = 8.0  # low-pass cut-off [Hz]
DECIMATION = 5  # keep every 5th filtered sample (the filtered noise is correlated over ~RATE / (2 CUTOFF) samples)


def measure(real: robodyn.Robot, t, q, v, a, rng: np.random.Generator) -> Trajectory:
    """Noisy measurements of the real robot along a periodic motion (see the docstring)."""
    tau = real.inverse_dynamics(q, v, a)
    sigma = TORQUE_NOISE * np.abs(tau).max(axis=0)
    tau_measured = tau + rng.normal(size=tau.shape) * sigma
    q_measured = q + rng.normal(size=q.shape) * ENCODER_NOISE
    sos = scipy.signal.butter(4, CUTOFF, fs=RATE, output="sos")

    def periodic_filter(x):  # the motion is periodic: filter three periods, keep the middle
        n = len(x)
        return scipy.signal.sosfiltfilt(sos, np.concatenate([x, x, x]), axis=0)[n : 2 * n]

    dt = 1.0 / RATE
    q_filtered = periodic_filter(q_measured)
    wrap = np.concatenate([q_filtered[-2:], q_filtered, q_filtered[:2]])
    v_est = (wrap[3:-1] - wrap[1:-3]) / (2 * dt)
    a_est = (wrap[3:-1] - 2 * wrap[2:-2] + wrap[1:-3]) / dt**2
    keep = slice(None, None, DECIMATION)
    return Trajectory(
        t[keep],
        q_filtered[keep],
        v_est[keep],
        a_est[keep],
        periodic_filter(tau_measured)[keep],
        list(real.joint_names),
        real.name,
    )


def run(quick: bool = False) -> dict:
    nominal = robodyn.load("ur5")
    real = robodyn.attach_payload(nominal, "tool0", PAYLOAD_MASS, com=PAYLOAD_COM)
    rng = np.random.default_rng(7)
    base = base_parameters(nominal)
    excitation = excite(nominal, duration=10.0, harmonics=4, iterations=8 if quick else 40, base=base)
    validation_motion = excite(nominal, duration=8.0, harmonics=3, iterations=0, seed=1, base=base)
    data = measure(real, *excitation.sample(nominal, rate=RATE)[:4], rng)
    t, q, v, a, _ = validation_motion.sample(nominal, rate=RATE)
    validation = Trajectory(t, q, v, a, real.inverse_dynamics(q, v, a), list(real.joint_names), real.name)
    validation_measured = measure(real, t, q, v, a, rng)

    # The payload in the frame of the body that carries it (wrist_3_link).
    links = body_links(nominal)
    carrier = links.index("wrist_3_link")
    tool = nominal.model.frames[nominal.frame_id("tool0")].placement
    com_true = tool.rotation @ PAYLOAD_COM + tool.translation
    nominal_body = inertial_parameters(nominal)[10 * carrier : 10 * carrier + 10]
    carrier_base = base_parameters(nominal, bodies=["wrist_3_link"])
    true_base = base_parameters(real).values

    report = {
        "base_counts": {},
        "excitation_condition": excitation.condition,
        "excitation_condition_start": excitation.initial_condition,
        "validation_condition": validation_motion.condition,
        "payload_true": {"mass": PAYLOAD_MASS, "com": com_true.tolist()},
        "methods": {},
    }
    for method in ("ls", "physical"):
        full = identify(nominal, data, method=method, base=base)
        payload = identify(nominal, data, method=method, base=carrier_base)
        body = payload.standard if payload.standard is not None else carrier_base.mapping.T @ payload.values
        mass = float(body[0] - nominal_body[0])
        com = (body[1:4] - nominal_body[1:4]) / mass
        report["methods"][method] = {
            "relative_error_data": full.relative_error,
            "validation_error": full.prediction_error(validation),
            "validation_error_measured": full.prediction_error(validation_measured),
            "base_relative_deviation": float(np.linalg.norm(full.values - true_base) / np.linalg.norm(true_base)),
            "payload_mass": mass,
            "payload_mass_error": mass - PAYLOAD_MASS,
            "payload_mass_std": float(payload.std[0]),
            "payload_com": com.tolist(),
            "payload_com_error": float(np.linalg.norm(com - com_true)),
            "payload_validation_error": payload.prediction_error(validation),
            "solver": full.solver,
        }
    nominal_error = float(np.linalg.norm(validation.tau - nominal.inverse_dynamics(q, v, a)) / np.linalg.norm(validation.tau))
    report["nominal_validation_error"] = nominal_error
    return report


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer optimiser iterations")
    parser.add_argument("--json", action="store_true", help="print the report as JSON")
    arguments = parser.parse_args()
    report = run(quick=arguments.quick)
    if arguments.json:
        print(json.dumps(report, indent=2))
        return
    truth = report["payload_true"]
    print(f"ur5 + {truth['mass']} kg payload at tool0 (unknown to the nominal model)")
    print(
        f"excitation: condition number {report['excitation_condition']:.4g} "
        f"(start {report['excitation_condition_start']:.4g}); validation motion {report['validation_condition']:.4g}"
    )
    print(f"nominal model on the validation motion: relative torque error {report['nominal_validation_error']:.3g}")
    com_true = ", ".join(f"{x:.4f}" for x in truth["com"])
    print(f"true payload: {truth['mass']:.3f} kg, centre of mass ({com_true}) m in wrist_3_link\n")
    for method, result in report["methods"].items():
        com = ", ".join(f"{x:.4f}" for x in result["payload_com"])
        print(f"[{method}]")
        print(
            f"  recovered payload mass {result['payload_mass']:.4f} kg "
            f"(error {result['payload_mass_error']:+.4f} kg, std {result['payload_mass_std']:.2g})"
        )
        print(f"  recovered centre of mass ({com}) m (error {1000 * result['payload_com_error']:.2f} mm)")
        print(
            f"  base parameters: data error {result['relative_error_data']:.3g}, "
            f"validation error {result['validation_error']:.3g} (vs measured {result['validation_error_measured']:.3g})"
        )


if __name__ == "__main__":
    main()
