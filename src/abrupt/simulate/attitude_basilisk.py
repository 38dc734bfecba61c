"""The attitude simulator's noise-free scenario in Basilisk (``pip install bsk``), as an independent cross-check.

Hub + reaction wheels (``reactionWheelStateEffector``, balanced wheels), ``mrpFeedback`` (K, P,
Ki = -1 so no integral term, ``controlLawType = 1`` for the ω × H feed-forward of Bennett 2022
Eq. 2.5), ``rwMotorTorque`` (minimum-norm mapping, Eq. 2.4), ``extForceTorque`` applying ΔH/Δt during
one step, all at ``sim_rate_hz``. Basilisk is optional: it is imported inside the functions here.

The Basilisk scenario
---------------------

`spacecraft.Spacecraft` hub, `reactionWheelStateEffector` (balanced wheels, rwFactory `custom` with Js = 0.16
kg·m², u_max = 0.2 N·m, same axes), `simpleNav` → `attTrackingError` (reference `inertial3D` at σ = 0) →
`mrpFeedback` (K, P, Ki = -1, `controlLawType = 1`, wheel parameters and speeds connected so its ω×(Jω + G h_s)
term matches ours) → `rwMotorTorque` (3 control axes, minimum-norm) → wheels; `extForceTorque` holds ΔH/Δt for
one 0.01 s step. Basilisk's hub inertia excludes the wheels and the effector adds each wheel's Js ĝĝᵀ + Jt(I -
ĝĝᵀ) back, so the hub gets `J - Σ I_wheel` and both models have the same system inertia. Dynamics run before
flight software in each 0.01 s step so the command is computed from the state at the start of the step, as in
ours.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from abrupt.model.attitude_dynamics import AttitudeSimConfig, PreparedDynamics, Strike, prepare_dynamics, strike_arrays
from abrupt.model.rotations import quaternion_from_mrp
from abrupt.model.spacecraft import Spacecraft
from abrupt.types import FloatArray


def _hub_and_wheels(spacecraft: Spacecraft, prep: PreparedDynamics) -> tuple[Any, Any, Any, Any]:
    """Basilisk spacecraft hub with the wheels attached: (hub, wheel effector, wheel factory, torque effector).

    Basilisk's hub inertia excludes the wheels, whose full inertia (spin Js and transverse Jt = Jg = Js/2,
    at the centre of mass) it adds back, so the hub gets J - Σ I_wheel.
    """
    from Basilisk.simulation import extForceTorque, reactionWheelStateEffector
    from Basilisk.simulation import spacecraft as bsk_spacecraft
    from Basilisk.utilities import simIncludeRW

    axes = prep.axes
    factory = simIncludeRW.rwFactory()
    hub_inertia = prep.inertia.copy()
    for i in range(axes.shape[1]):
        g = axes[:, i]
        js = float(prep.spin_inertia[i])
        rw = factory.create(
            "custom",
            list(g),
            Js=js,
            Omega=float(prep.x0[7 + i] * 60.0 / (2.0 * math.pi)),  # [rpm]
            u_max=float(prep.max_torque[i]),
            useMaxTorque=True,
            RWModel=reactionWheelStateEffector.BalancedWheels,
        )
        jt = float(rw.Jt)
        hub_inertia -= js * np.outer(g, g) + jt * (np.eye(3) - np.outer(g, g))
    sc = bsk_spacecraft.Spacecraft()
    sc.ModelTag = "abrupt-hub"
    sc.hub.mHub = float(spacecraft.mass_kg) if math.isfinite(spacecraft.mass_kg) else 1000.0  # [kg]
    sc.hub.IHubPntBc_B = hub_inertia.tolist()
    q0 = prep.x0[:4]
    sigma0 = q0[1:] / (1.0 + q0[0])
    sc.hub.sigma_BNInit = [[float(v)] for v in sigma0]
    sc.hub.omega_BN_BInit = [[0.0], [0.0], [0.0]]
    rw_effector = reactionWheelStateEffector.ReactionWheelStateEffector()
    rw_effector.ModelTag = "wheels"
    factory.addToSpacecraft(sc.ModelTag, rw_effector, sc)
    ext = extForceTorque.ExtForceTorque()
    ext.ModelTag = "strike"
    sc.addDynamicEffector(ext)
    return sc, rw_effector, factory, ext


def _flight_software(
    config: AttitudeSimConfig, prep: PreparedDynamics, sc: Any, rw_effector: Any, factory: Any
) -> list[Any]:
    """Navigation, inertial reference, tracking error, MRP feedback and wheel mapping, wired to the hub."""
    from Basilisk.architecture import messaging
    from Basilisk.fswAlgorithms import attTrackingError, inertial3D, mrpFeedback, rwMotorTorque
    from Basilisk.simulation import simpleNav

    nav = simpleNav.SimpleNav()
    nav.ModelTag = "nav"
    nav.scStateInMsg.subscribeTo(sc.scStateOutMsg)
    ref = inertial3D.inertial3D()
    ref.ModelTag = "reference"
    ref.sigma_R0N = [0.0, 0.0, 0.0]
    err = attTrackingError.attTrackingError()
    err.ModelTag = "error"
    err.attRefInMsg.subscribeTo(ref.attRefOutMsg)
    err.attNavInMsg.subscribeTo(nav.attOutMsg)
    veh = messaging.VehicleConfigMsgPayload()
    veh.ISCPntB_B = prep.inertia.reshape(-1).tolist()
    veh_msg = messaging.VehicleConfigMsg().write(veh)
    rw_params_msg = factory.getConfigMessage()
    control = mrpFeedback.mrpFeedback()
    control.ModelTag = "mrpFeedback"
    control.guidInMsg.subscribeTo(err.attGuidOutMsg)
    control.vehConfigInMsg.subscribeTo(veh_msg)
    control.rwParamsInMsg.subscribeTo(rw_params_msg)
    control.rwSpeedsInMsg.subscribeTo(rw_effector.rwSpeedOutMsg)
    control.K = float(config.gain_K_Nm)
    control.P = float(config.gain_P_Nms)
    control.Ki = -1.0
    control.controlLawType = 1
    mapping = rwMotorTorque.rwMotorTorque()
    mapping.ModelTag = "rwMotorTorque"
    mapping.rwParamsInMsg.subscribeTo(rw_params_msg)
    mapping.vehControlInMsg.subscribeTo(control.cmdTorqueOutMsg)
    mapping.controlAxes_B = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    rw_effector.rwMotorCmdInMsg.subscribeTo(mapping.rwMotorTorqueOutMsg)
    # Keep the message payloads alive as long as the models that read them.
    return [nav, ref, err, control, mapping, veh_msg, rw_params_msg]


def simulate_attitude_basilisk(
    spacecraft: Spacecraft,
    config: AttitudeSimConfig | None = None,
    strikes: Sequence[Strike] = (),
) -> dict[str, FloatArray]:
    """The same noise-free scenario as :func:`abrupt.simulate.attitude.simulate_attitude` in Basilisk.

    The system inertia equals the spacecraft file's J (see :func:`_hub_and_wheels`). Returns ``t_s``,
    ``q_BN``, ``omega_B_rad_s`` and ``wheel_speed_rad_s`` at the telemetry rate. Raises ``ImportError``
    when Basilisk is not installed. ``config`` defaults to :class:`AttitudeSimConfig` ()
    """
    from Basilisk.utilities import SimulationBaseClass

    config = config if config is not None else AttitudeSimConfig()
    prep = prepare_dynamics(spacecraft, config)
    n_w = prep.axes.shape[1]
    dt_ns = round(1e9 / config.sim_rate_hz)
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("process")
    proc.addTask(sim.CreateNewTask("task", dt_ns))
    sc, rw_effector, factory, ext = _hub_and_wheels(spacecraft, prep)
    fsw = _flight_software(config, prep, sc, rw_effector, factory)
    # Priorities: dynamics first (integrates [t-Δt, t] with the command computed at t-Δt), then the
    # flight software computes the command at t from the state at t -- the same zero-order hold as ours.
    for k, model in enumerate([rw_effector, sc, *fsw[:5]]):
        sim.AddModelToTask("task", model, 100 - k)
    tlm_ns = dt_ns * config.decimation
    state_rec = sc.scStateOutMsg.recorder(tlm_ns)
    wheel_rec = rw_effector.rwSpeedOutMsg.recorder(tlm_ns)
    sim.AddModelToTask("task", state_rec)
    sim.AddModelToTask("task", wheel_rec)
    sim.InitializeSimulation()

    n_steps = round(config.duration_s * config.sim_rate_hz)
    steps, dh_b, _ = strike_arrays(strikes, config)
    for step in np.unique(steps):
        torque = dh_b[steps == step].sum(axis=0) * config.sim_rate_hz  # L = ΔH / Δt [N m]
        sim.ConfigureStopTime(int(step) * dt_ns)
        sim.ExecuteSimulation()
        ext.extTorquePntB_B = [[float(v)] for v in torque]
        sim.ConfigureStopTime((int(step) + 1) * dt_ns)
        sim.ExecuteSimulation()
        ext.extTorquePntB_B = [[0.0], [0.0], [0.0]]
    sim.ConfigureStopTime(n_steps * dt_ns)
    sim.ExecuteSimulation()

    t_s = np.asarray(state_rec.times(), dtype=np.float64) * 1e-9
    sigma = np.asarray(state_rec.sigma_BN, dtype=np.float64)
    return {
        "t_s": t_s,
        "q_BN": quaternion_from_mrp(sigma),
        "omega_B_rad_s": np.asarray(state_rec.omega_BN_B, dtype=np.float64),
        "wheel_speed_rad_s": np.asarray(wheel_rec.wheelSpeeds, dtype=np.float64)[:, :n_w],
    }
