"""Closed-loop attitude dynamics of an independent test spacecraft in Basilisk (no code from abrupt).

Used by ``basilisk_confounders.py``; needs the Basilisk package (``bsk``), which abrupt itself does
not depend on. Everything physical is Basilisk's own module:

* ``spacecraft.Spacecraft`` hub (true inertia), ``reactionWheelStateEffector`` (balanced wheels, body-
  relative speeds, torque and speed limits), ``GravityGradientEffector`` with Earth's point-mass field
  (``gravBodyFactory.createEarth``), ``extForceTorque`` for every other torque on the body;
* flight software at ``fsw_dt_s``: ``simpleNav`` (truth to the loop; the sensor noise of the telemetry
  is added later, the loop does not see it), ``hillPoint`` nadir reference, ``attRefCorrection`` for
  off-nadir slews, ``attTrackingError``, ``mrpFeedback`` (Schaub & Junkins 2018 Eq. 8.124, no integral
  term) and ``rwMotorTorque`` (minimum-norm wheel torques).

The run is cut into segments at every change of the applied torque or reference, so a piecewise
constant torque timeline costs one ``ExecuteSimulation`` per piece. A trigger (a momentum dump) reads
the wheels' momentum when it starts and adds its own torque pieces.
"""

from __future__ import annotations

import heapq
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from Basilisk.architecture import messaging
from Basilisk.fswAlgorithms import attRefCorrection, attTrackingError, hillPoint, mrpFeedback, rwMotorTorque
from Basilisk.simulation import (
    GravityGradientEffector,
    extForceTorque,
    reactionWheelStateEffector,
    simpleNav,
    spacecraft,
)
from Basilisk.utilities import RigidBodyKinematics as rbk
from Basilisk.utilities import SimulationBaseClass, macros, orbitalMotion, simIncludeGravBody, simIncludeRW

MU_EARTH_M3_S2 = 3.986004418e14
R_EARTH_M = 6_378_136.3


@dataclass
class Piece:
    """A constant body-frame torque [N m] on [start_s, end_s)."""

    start_s: float
    end_s: float
    torque_B_Nm: np.ndarray
    tag: str = ""


@dataclass
class Trigger:
    """A callback at ``time_s`` that reads the wheel momentum [N m s, body] and returns torque pieces."""

    time_s: float
    make: Callable[[np.ndarray, float], list[Piece]]


@dataclass
class SlewCommand:
    """Reference offset from nadir: ``sigma_BcB`` (MRP) held from ``time_s`` on."""

    time_s: float
    sigma: np.ndarray


@dataclass
class Vehicle:
    """What the dynamics need: true inertia, wheels, orbit, loop gains and the steps."""

    inertia_kgm2: np.ndarray
    mass_kg: float
    wheel_axes_B: np.ndarray  # (n, 3) unit spin axes
    wheel_spin_inertia_kgm2: float
    wheel_max_torque_Nm: float
    wheel_max_speed_rpm: float
    wheel_initial_rpm: np.ndarray
    altitude_m: float
    inclination_deg: float
    raan_deg: float
    arg_lat_deg: float
    gain_K: float
    gain_P: float
    background_torque_B_Nm: np.ndarray  # constant aerodynamic-like torque, fixed in the (nadir) body
    dyn_dt_s: float = 0.25
    fsw_dt_s: float = 0.5


@dataclass
class Record:
    """Recorded truth: at the dynamics step (``t_s``, ``omega_BN_B`` rad/s, ``sigma_BN``, wheel speeds
    rad/s relative to the body) and each second (``t1_s``, ``H_N`` total angular momentum about the
    centre of mass, inertial axes, N m s, from Basilisk's own bookkeeping)."""

    t_s: np.ndarray
    omega_BN_B: np.ndarray
    sigma_BN: np.ndarray
    wheel_speed_rad_s: np.ndarray
    t1_s: np.ndarray
    H_N: np.ndarray
    applied: list[Piece] = field(default_factory=list)


def _mrp_to_dcm(sigma: np.ndarray) -> np.ndarray:
    return np.asarray(rbk.MRP2C(list(sigma)))


def _initial_nadir(vehicle: Vehicle) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """Position, velocity [m, m/s], MRP and body rate of the Hill frame (x radial, z orbit normal) at t=0."""
    oe = orbitalMotion.ClassicElements()
    oe.a = R_EARTH_M + vehicle.altitude_m
    oe.e = 0.0001
    oe.i = np.radians(vehicle.inclination_deg)
    oe.Omega = np.radians(vehicle.raan_deg)
    oe.omega = 0.0
    oe.f = np.radians(vehicle.arg_lat_deg)
    r, v = orbitalMotion.elem2rv(MU_EARTH_M3_S2, oe)
    r, v = np.asarray(r), np.asarray(v)
    i_r = r / np.linalg.norm(r)
    i_h = np.cross(r, v) / np.linalg.norm(np.cross(r, v))
    i_t = np.cross(i_h, i_r)
    hn = np.vstack([i_r, i_t, i_h])
    n = np.linalg.norm(np.cross(r, v)) / np.dot(r, r)
    return r, v, np.asarray(rbk.C2MRP(hn)), np.array([0.0, 0.0, n]), 2 * np.pi / np.sqrt(MU_EARTH_M3_S2 / oe.a**3)


@dataclass
class _Sim:
    """The Basilisk objects the run loop touches."""

    sim: SimulationBaseClass.SimBaseClass
    rw_eff: reactionWheelStateEffector.ReactionWheelStateEffector
    ext: extForceTorque.ExtForceTorque
    corr: attRefCorrection.attRefCorrection
    logs: tuple
    keep: list


def _build(vehicle: Vehicle) -> _Sim:
    """The spacecraft, its environment and its flight software, wired by messages."""
    sim = SimulationBaseClass.SimBaseClass()
    dyn, fsw = sim.CreateNewProcess("dyn", 2), sim.CreateNewProcess("fsw", 1)
    dyn.addTask(sim.CreateNewTask("dynTask", macros.sec2nano(vehicle.dyn_dt_s)))
    fsw.addTask(sim.CreateNewTask("fswTask", macros.sec2nano(vehicle.fsw_dt_s)))

    sc = spacecraft.Spacecraft()
    sc.ModelTag = "bsk-sc"
    sc.hub.mHub = vehicle.mass_kg
    sc.hub.IHubPntBc_B = vehicle.inertia_kgm2.tolist()
    r0, v0, sigma0, omega0, _ = _initial_nadir(vehicle)
    sc.hub.r_CN_NInit, sc.hub.v_CN_NInit = r0.tolist(), v0.tolist()
    sc.hub.sigma_BNInit, sc.hub.omega_BN_BInit = sigma0.tolist(), omega0.tolist()
    sim.AddModelToTask("dynTask", sc, 10)

    grav = simIncludeGravBody.gravBodyFactory()
    earth = grav.createEarth()
    earth.isCentralBody = True
    grav.addBodiesTo(sc)
    gg = GravityGradientEffector.GravityGradientEffector()
    gg.ModelTag = "gg"
    gg.addPlanetName(earth.planetName)
    sc.addDynamicEffector(gg)
    sim.AddModelToTask("dynTask", gg, 9)

    rw_factory = simIncludeRW.rwFactory()
    for axis, rpm in zip(vehicle.wheel_axes_B, vehicle.wheel_initial_rpm, strict=True):
        rw_factory.create(
            "custom",
            list(axis),
            Js=float(vehicle.wheel_spin_inertia_kgm2),
            Omega=float(rpm),
            Omega_max=float(vehicle.wheel_max_speed_rpm),
            u_max=float(vehicle.wheel_max_torque_Nm),
            RWModel=messaging.BalancedWheels,
        )
    rw_eff = reactionWheelStateEffector.ReactionWheelStateEffector()
    rw_eff.ModelTag = "rw"
    rw_factory.addToSpacecraft("rw", rw_eff, sc)
    sim.AddModelToTask("dynTask", rw_eff, 11)

    ext = extForceTorque.ExtForceTorque()
    ext.ModelTag = "ext"
    ext.extTorquePntB_B = [[v] for v in vehicle.background_torque_B_Nm]
    sc.addDynamicEffector(ext)
    sim.AddModelToTask("dynTask", ext, 8)

    nav = simpleNav.SimpleNav()
    nav.ModelTag = "nav"
    nav.scStateInMsg.subscribeTo(sc.scStateOutMsg)
    sim.AddModelToTask("dynTask", nav, 7)

    hill = hillPoint.hillPoint()
    hill.ModelTag = "hill"
    hill.transNavInMsg.subscribeTo(nav.transOutMsg)
    sim.AddModelToTask("fswTask", hill, 20)
    corr = attRefCorrection.attRefCorrection()
    corr.ModelTag = "corr"
    corr.sigma_BcB = [0.0, 0.0, 0.0]
    corr.attRefInMsg.subscribeTo(hill.attRefOutMsg)
    sim.AddModelToTask("fswTask", corr, 19)
    err = attTrackingError.attTrackingError()
    err.ModelTag = "err"
    err.attNavInMsg.subscribeTo(nav.attOutMsg)
    err.attRefInMsg.subscribeTo(corr.attRefOutMsg)
    sim.AddModelToTask("fswTask", err, 18)

    veh_cfg = messaging.VehicleConfigMsgPayload()
    veh_cfg.ISCPntB_B = vehicle.inertia_kgm2.flatten().tolist()
    veh_msg = messaging.VehicleConfigMsg().write(veh_cfg)
    rw_param_msg = rw_factory.getConfigMessage()
    ctrl = mrpFeedback.mrpFeedback()
    ctrl.ModelTag = "mrpFeedback"
    ctrl.K, ctrl.P, ctrl.Ki = vehicle.gain_K, vehicle.gain_P, -1.0
    ctrl.guidInMsg.subscribeTo(err.attGuidOutMsg)
    ctrl.vehConfigInMsg.subscribeTo(veh_msg)
    ctrl.rwParamsInMsg.subscribeTo(rw_param_msg)
    ctrl.rwSpeedsInMsg.subscribeTo(rw_eff.rwSpeedOutMsg)
    sim.AddModelToTask("fswTask", ctrl, 17)
    motor = rwMotorTorque.rwMotorTorque()
    motor.ModelTag = "rwMotorTorque"
    motor.controlAxes_B = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    motor.vehControlInMsg.subscribeTo(ctrl.cmdTorqueOutMsg)
    motor.rwParamsInMsg.subscribeTo(rw_param_msg)
    sim.AddModelToTask("fswTask", motor, 16)
    rw_eff.rwMotorCmdInMsg.subscribeTo(motor.rwMotorTorqueOutMsg)

    state_log = sc.scStateOutMsg.recorder(macros.sec2nano(vehicle.dyn_dt_s))
    speed_log = rw_eff.rwSpeedOutMsg.recorder(macros.sec2nano(vehicle.dyn_dt_s))
    mom_log = sc.logger("totRotAngMomPntC_N", macros.sec2nano(1.0))
    for log in (state_log, speed_log, mom_log):
        sim.AddModelToTask("dynTask", log)

    sim.InitializeSimulation()
    keep = [sc, grav, gg, rw_factory, nav, hill, err, veh_msg, rw_param_msg, ctrl, motor]
    return _Sim(sim, rw_eff, ext, corr, (state_log, speed_log, mom_log), keep)


def simulate(
    vehicle: Vehicle,
    duration_s: float,
    pieces: list[Piece],
    triggers: list[Trigger],
    slews: list[SlewCommand],
) -> Record:
    """Run the closed loop for ``duration_s`` with the given torque timeline; return the truth record."""
    bsk = _build(vehicle)
    sim, rw_eff, ext, corr = bsk.sim, bsk.rw_eff, bsk.ext, bsk.corr
    state_log, speed_log, mom_log = bsk.logs
    n_wheels = len(vehicle.wheel_axes_B)
    js_g = vehicle.wheel_spin_inertia_kgm2 * vehicle.wheel_axes_B  # (n, 3)

    def wheel_momentum_B() -> np.ndarray:
        speeds = np.asarray(rw_eff.rwSpeedOutMsg.read().wheelSpeeds)[:n_wheels]
        return np.asarray(speeds @ js_g)

    applied: list[Piece] = []
    active: list[Piece] = []
    queue: list[tuple[float, int, str, object]] = []
    seq = 0
    for p in pieces:
        heapq.heappush(queue, (p.start_s, seq, "piece", p))
        seq += 1
    for trig in triggers:
        heapq.heappush(queue, (trig.time_s, seq, "trigger", trig))
        seq += 1
    for sl in slews:
        heapq.heappush(queue, (sl.time_s, seq, "slew", sl))
        seq += 1
    dt = vehicle.dyn_dt_s
    t_now = 0.0
    while True:
        # apply everything due now (times rounded to the dynamics step)
        while queue and round(queue[0][0] / dt) * dt <= t_now + 1e-9:
            _, _, what, obj = heapq.heappop(queue)
            if what == "piece":
                assert isinstance(obj, Piece)
                active.append(obj)
                applied.append(obj)
            elif what == "trigger":
                assert isinstance(obj, Trigger)
                for p in obj.make(wheel_momentum_B(), t_now):
                    heapq.heappush(queue, (p.start_s, seq, "piece", p))
                    seq += 1
            else:
                assert isinstance(obj, SlewCommand)
                corr.sigma_BcB = list(obj.sigma)
        active = [p for p in active if round(p.end_s / dt) * dt > t_now + 1e-9]
        torque = vehicle.background_torque_B_Nm + sum((p.torque_B_Nm for p in active), np.zeros(3))
        ext.extTorquePntB_B = [[float(v)] for v in torque]
        ends = [round(p.end_s / dt) * dt for p in active]
        t_next = min([duration_s, *ends, *([round(queue[0][0] / dt) * dt] if queue else [])])
        t_next = max(t_next, t_now + dt)
        sim.ConfigureStopTime(macros.sec2nano(round(t_next / dt) * dt))
        sim.ExecuteSimulation()
        t_now = round(t_next / dt) * dt
        if t_now >= duration_s - 1e-9:
            break

    t = np.asarray(state_log.times()) * macros.NANO2SEC
    return Record(
        t_s=t,
        omega_BN_B=np.asarray(state_log.omega_BN_B),
        sigma_BN=np.asarray(state_log.sigma_BN),
        wheel_speed_rad_s=np.asarray(speed_log.wheelSpeeds)[:, :n_wheels],
        t1_s=np.asarray(mom_log.times()) * macros.NANO2SEC,
        H_N=np.asarray(mom_log.totRotAngMomPntC_N),
        applied=applied,
    )


def whole_inertia(vehicle: Vehicle) -> np.ndarray:
    """The whole spacecraft's inertia [kg m^2]: the hub's plus the balanced wheels' rigid inertia
    (Basilisk's rwFactory sets the transverse inertia Jt = Js / 2; the wheels sit at B)."""
    js = vehicle.wheel_spin_inertia_kgm2
    extra = sum(js * np.outer(g, g) + 0.5 * js * (np.eye(3) - np.outer(g, g)) for g in vehicle.wheel_axes_B)
    return np.asarray(vehicle.inertia_kgm2 + extra)


def mrp_to_quaternion(sigma: np.ndarray) -> np.ndarray:
    """Euler parameters (scalar first, q0 >= 0) of MRP rows (Schaub & Junkins Eq. 3.116)."""
    s2 = np.sum(sigma**2, axis=1)
    q = np.column_stack([(1 - s2) / (1 + s2), 2 * sigma / (1 + s2)[:, None]])
    q[q[:, 0] < 0] *= -1
    return q


def slew_profile(
    start_s: float, axis_B: np.ndarray, angle_deg: float, ramp_s: float, hold_s: float
) -> list[SlewCommand]:
    """Reference offsets each second: a smooth (1 - cos) ramp out to ``angle_deg`` about ``axis_B``, hold,
    ramp back to nadir."""
    out: list[SlewCommand] = []
    total = 2 * ramp_s + hold_s
    axis = axis_B / np.linalg.norm(axis_B)
    for k in range(int(total) + 2):
        t = float(k)
        if t < ramp_s:
            frac = 0.5 * (1 - np.cos(np.pi * t / ramp_s))
        elif t < ramp_s + hold_s:
            frac = 1.0
        else:
            frac = max(0.0, 0.5 * (1 + np.cos(np.pi * (t - ramp_s - hold_s) / ramp_s)))
        phi = np.radians(angle_deg) * frac
        out.append(SlewCommand(start_s + t, np.tan(phi / 4) * axis))
    return out


def dcm_BN(sigma: np.ndarray) -> np.ndarray:
    """[BN] of MRP rows, (n, 3, 3)."""
    s2 = np.sum(sigma**2, axis=1)
    sk = np.zeros((len(sigma), 3, 3))
    sk[:, 0, 1], sk[:, 0, 2], sk[:, 1, 2] = -sigma[:, 2], sigma[:, 1], -sigma[:, 0]
    sk = sk - np.transpose(sk, (0, 2, 1))
    eye = np.eye(3)[None]
    return eye + (8 * sk @ sk - 4 * (1 - s2)[:, None, None] * sk) / ((1 + s2) ** 2)[:, None, None]


@dataclass
class Design:
    """One spacecraft: true dynamics, catalogue values and sensors."""

    name: str
    vehicle: Vehicle
    inertia_catalogue: np.ndarray
    pyramid_axis: str
    wheel_elevation_deg: float
    tach_pulses: int
    tach_gate_s: float
    gyro_noise_rad_s: float
    gyro_bias_walk_rad_s15: float
    st_rate_hz: float
    st_noise_arcsec: float
    st_boresight_factor: float
    st_boresight_B: np.ndarray
    thruster_torque_Nm: float
