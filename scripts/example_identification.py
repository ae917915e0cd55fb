"""Example: identify a payload the nominal model does not know, from noisy measurements.

The "real" robot is the ur5 carrying 2.5 kg at its tool flange (``tool0``); the nominal
model is the plain ur5. The script

1. computes the base parameters and an exciting trajectory (Fourier series, SLSQP on the
   condition number of the base regressor) for the nominal model;
2. runs the real robot along it: a simulation (``robodyn.simulate``, RK4 at 1 kHz) under a
   computed-torque controller built on the nominal model, which tracks imperfectly since
   it does not know the payload (``--exact``: the exact trajectory and the real robot's
   inverse dynamics instead);
3. "measures" it at 200 Hz: the applied torques plus Gaussian noise (1 % of each joint's
   peak torque), and encoder noise on ``q`` (1e-4 rad); velocities and accelerations come
   from the noisy positions by a zero-phase low-pass filter and central differences, the
   torques go through the same filter, and the data are decimated, as on a real rig
   (Gautier's parallel filtering);
4. identifies (a) all base parameters (``ls`` and ``physical``) and (b) only the
   parameters of the body carrying the payload (``wrist_3_link``; the rest held at the
   URDF's values), whose change from the nominal model is the payload: its mass and centre
   of mass;
5. predicts the torques on a different validation trajectory and reports the errors.

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
from robodyn.sim.control import ComputedTorque
from robodyn.trajectory import Trajectory

PAYLOAD_MASS = 2.5  # [kg]
PAYLOAD_COM = np.array([0.03, -0.02, 0.06])  # in the tool0 frame, [m]
RATE = 200.0  # sampling rate [Hz]
TORQUE_NOISE = 0.01  # fraction of each joint's peak torque (standard deviation)
ENCODER_NOISE = 1e-4  # [rad]
CUTOFF = 8.0  # low-pass cut-off [Hz]
DECIMATION = 5  # keep every 5th filtered sample (the filtered noise is correlated over ~RATE / (2 CUTOFF) samples)


def motion(real: robodyn.Robot, nominal: robodyn.Robot, excitation, *, simulate: bool) -> Trajectory:
    """The real robot's motion and torques at ``RATE`` along an excitation: simulated under a
    1 kHz computed-torque controller built on the nominal model (so the unknown payload
    makes it track imperfectly), or (``simulate=False``) the exact trajectory with the real
    robot's inverse dynamics."""
    if not simulate:
        t, q, v, a, _ = excitation.sample(nominal, rate=RATE)
        return Trajectory(t, q, v, a, real.inverse_dynamics(q, v, a), list(real.joint_names), real.name)

    def reference(time: float):
        q, v, a = excitation.evaluate(np.array([time]))
        return q[0], v[0], a[0]

    q0, v0, _ = reference(0.0)
    controller = ComputedTorque(nominal, reference)
    run = robodyn.simulate(real, q0, v0, excitation.period, 1e-3, controller=controller, hold=True)
    keep = slice(None, None, round(1.0 / (1e-3 * RATE)))  # 1 kHz -> RATE
    return Trajectory(run.t[keep], run.q[keep], run.v[keep], run.a[keep], run.tau[keep], list(real.joint_names), real.name)


def measure(truth: Trajectory, rng: np.random.Generator) -> Trajectory:
    """What sensors give: noisy torques and encoders; v and a from the filtered positions
    by central differences, torques through the same zero-phase filter, the ends (filter
    transients) trimmed and the result decimated."""
    sigma = TORQUE_NOISE * np.abs(truth.tau).max(axis=0)
    tau = truth.tau + rng.normal(size=truth.tau.shape) * sigma
    q = truth.q + rng.normal(size=truth.q.shape) * ENCODER_NOISE
    sos = scipy.signal.butter(4, CUTOFF, fs=RATE, output="sos")
    q_filtered = scipy.signal.sosfiltfilt(sos, q, axis=0)
    dt = 1.0 / RATE
    v = np.gradient(q_filtered, dt, axis=0)
    a = np.gradient(v, dt, axis=0)
    keep = slice(int(0.25 * RATE), len(q) - int(0.25 * RATE), DECIMATION)
    return Trajectory(
        truth.t[keep], q_filtered[keep], v[keep], a[keep], scipy.signal.sosfiltfilt(sos, tau, axis=0)[keep],
        list(truth.joint_names), truth.robot,
    )  # fmt: skip


def run(quick: bool = False, simulate: bool = True) -> dict:
    nominal = robodyn.load("ur5")
    real = robodyn.attach_payload(nominal, "tool0", PAYLOAD_MASS, com=PAYLOAD_COM)
    rng = np.random.default_rng(7)
    base = base_parameters(nominal)
    excitation = excite(nominal, duration=10.0, harmonics=4, iterations=8 if quick else 40, base=base)
    validation_motion = excite(nominal, duration=8.0, harmonics=3, iterations=0, seed=1, base=base)
    data = measure(motion(real, nominal, excitation, simulate=simulate), rng)
    validation = motion(real, nominal, validation_motion, simulate=simulate)
    validation_measured = measure(validation, rng)
    q, v, a = validation.q, validation.v, validation.a

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
    reference_q = excitation.evaluate(data.t)[0]
    report["tracking_error"] = float(np.abs(data.q - reference_q).max())
    return report


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer optimiser iterations")
    parser.add_argument("--json", action="store_true", help="print the report as JSON")
    parser.add_argument("--exact", action="store_true", help="the exact excitation instead of a simulated tracking run")
    arguments = parser.parse_args()
    report = run(quick=arguments.quick, simulate=not arguments.exact)
    if arguments.json:
        print(json.dumps(report, indent=2))
        return
    truth = report["payload_true"]
    print(f"ur5 + {truth['mass']} kg payload at tool0 (unknown to the nominal model)")
    print(f"tracking error of the nominal controller: {report['tracking_error']:.3g} rad (largest)")
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
