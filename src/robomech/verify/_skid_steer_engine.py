"""Paper 4: a contact-physics ground truth for the skid-steer robot — MuJoCo, generated with ``MjSpec``.

The role RecurDyn plays in the paper: the six-wheel rocker robot built from an ``ExplorationRobot``
(free-floating chassis; per side a rocker on the body y axis, a bogie, two parallel side links and a
rear-wheel slide; the differential as a joint equality ``θ_left = -θ_right``, the parallelogram as
``θ02_rear = θ02_front``), six rolling wheels (cylinders on hinges) with Coulomb wheel–ground friction,
on a plane or a height field, each wheel driven by a velocity actuator (wheel-speed command).

MuJoCo's contact is *soft* (a penetration-dependent constraint with a time constant, ``solref``) and
its friction is a Coulomb cone on point contacts: it is not terramechanics.  There is no soil
shear-displacement relation (Janosi–Hanamoto), no sinkage, no bulldozing, no load-dependent slip
curve.  So the slip it produces — and the effective track-width factor χ identified from it — is the
slip of rigid wheels on rigid ground with friction μ, set by the friction cone and the actuator
gains; it shows *that* a skid-steer robot slides and how the estimators cope, not how much this robot
would slide on sand or grass.  Numbers identified here are not transferable to a real robot.

MuJoCo is imported inside the functions (optional extra): the library imports without it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robomech._validation import as_array, check_params, check_positive, coerce_float_fields
from robomech.mechanisms.skid_steer import WHEELS, ExplorationRobot, wheel_radii

__all__ = ["EngineParams", "EngineRun", "Terrain", "build_model", "simulate_engine"]

# Side order of the estimator: side 1 right (y = -b), side 2 left (y = +b).
_SIDES = (("right", -1.0), ("left", 1.0))
# Sample spacing of the recorded history must be a whole number of engine steps: relative slack of the
# division rate/timestep before it counts as not whole (rounding of the two floats).
_STEP_RTOL = 1e-9
# Joint equalities (differential, parallelogram) are soft constraints in MuJoCo; the default time
# constant 0.02 s let the two side links of a side differ by ~5 mrad under load, which the estimator's
# single θ02 per side cannot represent.  4 ms (4 engine steps, MuJoCo's stability bound is 2) and a
# near-1 impedance make them ~100x stiffer.
_EQ_SOLREF = (0.004, 1.0)
_EQ_SOLIMP = (0.99, 0.999, 0.001, 0.5, 2.0)


@dataclass(frozen=True)
class Terrain:
    """Height field ``z = Σ a_k sin(kx_k x + ky_k y + φ_k)`` (m); ``flat()`` has no terms.

    ``half_size`` (m): in the engine the height field covers ``[-half_size, half_size]²`` around the
    start; a wheel beyond it leaves the terrain and its samples are flagged (``EngineRun.on_terrain``).
    """

    amplitude: tuple[float, ...]
    kx: tuple[float, ...]
    ky: tuple[float, ...]
    phase: tuple[float, ...]
    half_size: float = 6.0

    def __post_init__(self) -> None:
        arrays = {}
        for name in ("amplitude", "kx", "ky", "phase"):
            a = as_array(getattr(self, name), name, (None,))
            if a.ndim != 1:
                raise ValueError(f"Expected {name} to be a sequence of numbers, got shape {a.shape}.")
            arrays[name] = a
        n = arrays["amplitude"].size
        for name in ("kx", "ky", "phase"):
            if arrays[name].size != n:
                raise ValueError(
                    f"Expected {name} to have {n} terms like amplitude, got {arrays[name].size}."
                )
        for name, a in arrays.items():
            object.__setattr__(self, name, tuple(float(v) for v in a))
        coerce_float_fields(self, ("half_size",), positive=True)

    @classmethod
    def uneven(cls, half_size: float = 6.0) -> Terrain:
        """Three crossing undulations, 8–12 mm high, wavelengths 0.9–1.6 m (rough ground)."""
        return cls((0.012, 0.010, 0.008), (4.0, 1.5, -2.5), (1.0, 5.0, 4.5), (0.3, 1.1, 2.0), half_size)

    @classmethod
    def flat(cls) -> Terrain:
        return cls((), (), (), ())

    @property
    def is_flat(self) -> bool:
        return len(self.amplitude) == 0

    def height(self, x: ArrayLike, y: ArrayLike) -> NDArray[np.float64]:
        x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
        z = np.zeros(np.broadcast_shapes(x.shape, y.shape))
        for a, kx, ky, ph in zip(self.amplitude, self.kx, self.ky, self.phase, strict=True):
            z = z + a * np.sin(kx * x + ky * y + ph)
        return z


@dataclass(frozen=True)
class EngineParams:
    """What the engine needs beyond the kinematic geometry (none of it is in paper 4; documented
    choices, ``docs/mechanisms/skid_steer.md``).  Masses in kg, stiffnesses N·m/rad or N/m."""

    chassis_mass: float = 15.0
    rocker_mass: float = 1.0
    bogie_mass: float = 0.5
    side_link_mass: float = 0.2
    road_wheel_mass: float = 0.3
    rear_wheel_mass: float = 1.0
    road_wheel_half_width: float = 0.02
    rear_wheel_half_width: float = 0.03
    friction: float = 0.6  # wheel–ground Coulomb coefficient (rubber on a hard, dusty surface)
    side_link_stiffness: float = 200.0  # torsion spring at each side-link hinge (paper: spring-damper Q)
    side_link_damping: float = 2.0
    slide_stiffness: float = 20000.0  # rear-wheel slide spring (N/m)
    slide_damping: float = 200.0
    joint_damping: float = 0.5  # rocker hinges
    # paper 4, Fig. 3: a spring-damper from the rocker (Q) to the suspension (C) holds the bogie
    bogie_stiffness: float = 150.0
    bogie_damping: float = 3.0
    # rad: the bogie spring's rest angle is this far nose-up, chosen so that the two road wheels carry
    # equal static loads (with a relaxed spring the bogie hinge, ahead of its wheels' midpoint, puts
    # 3/4 of the bogie's load on the front road wheel and the rear one lifts in every turn)
    bogie_preload: float = 0.021
    joint_limit: float = 0.4  # rad: end stops of the rocker, bogie and side-link hinges
    slide_travel: float = 0.04  # m: rear-wheel slide travel either side of its nominal extension
    wheel_gain: float = 5.0  # velocity actuator gain kv (N·m per rad/s)
    wheel_torque_limit: float = 8.0  # actuator torque limit (N·m)
    timestep: float = 1e-3  # s
    hfield_resolution: float = 0.04  # m between height-field samples

    def __post_init__(self) -> None:
        coerce_float_fields(self, tuple(self.__dataclass_fields__), positive=True)


def _site_local(robot: ExplorationRobot, kind: str) -> tuple[float, float, float]:
    if kind == "rear":
        return (0.0, 0.0, -robot.rear_wheel_radius)
    ls, rk = robot.side_link_length, robot.side_link_rake
    return (-ls * math.sin(rk), 0.0, -ls * math.cos(rk) - robot.road_wheel_radius)


def build_model(robot: ExplorationRobot, terrain: Terrain | None = None, params: EngineParams | None = None):
    """The robot and its ground as an ``mujoco.MjSpec`` (returned uncompiled: ``spec.compile()``).

    Names: joints ``rocker_{side}``, ``bogie_{side}``, ``link_front_{side}``, ``link_rear_{side}``,
    ``slide_{side}``, ``wheel_{w}`` (``w`` in ``WHEELS``); sites ``contact_{w}`` (the carrier-fixed
    contact points of the estimator) and ``imu``; actuators ``drive_{w}``; sensors ``gyro``, ``accel``.
    """
    import mujoco

    check_params(robot, ExplorationRobot, "robot")
    terrain = Terrain.flat() if terrain is None else terrain
    check_params(terrain, Terrain, "terrain")
    p = EngineParams() if params is None else params
    check_params(p, EngineParams, "params")
    spec = mujoco.MjSpec()
    spec.modelname = "skid_steer_robot"
    spec.compiler.degree = False  # joint ranges and spring references in radians (MJCF's default is degrees)
    spec.option.timestep = p.timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC  # friction cone, not its pyramid approximation
    world = spec.worldbody

    if terrain.is_flat:
        ground = world.add_geom(name="ground", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
    else:
        n = round(2.0 * terrain.half_size / p.hfield_resolution) + 1
        xs = np.linspace(-terrain.half_size, terrain.half_size, n)
        # MuJoCo height fields: row i runs along y (from -y to +y), column j along x.
        h = terrain.height(xs[None, :], xs[:, None])
        lo, hi = float(h.min()), float(h.max())
        span = max(hi - lo, 1e-6)
        spec.add_hfield(
            name="terrain",
            size=[terrain.half_size, terrain.half_size, span, 0.05],
            nrow=n,
            ncol=n,
            userdata=((h - lo) / span).ravel().tolist(),
        )
        ground = world.add_geom(
            name="ground", type=mujoco.mjtGeom.mjGEOM_HFIELD, hfieldname="terrain", pos=[0, 0, lo]
        )
    # MuJoCo takes the larger friction of the two geoms in contact: set both to μ.
    ground.friction = [p.friction, 0.0, 0.0]

    def hinge(body, name, damping, stiffness=0.0, limit=None, springref=0.0):
        j = body.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 1.0, 0.0])
        j.springref = springref
        _set_coef(j, "damping", damping)
        if stiffness:
            _set_coef(j, "stiffness", stiffness)
        if limit is not None:
            j.limited = mujoco.mjtLimited.mjLIMITED_TRUE
            j.range = [-limit, limit]
        return j

    z0 = (
        robot.ground_clearance_depth
        + 0.01
        + (0.0 if terrain.is_flat else float(terrain.height(0.0, 0.0)) + 0.03)
    )
    chassis = world.add_body(name="chassis", pos=[0.0, 0.0, z0])
    chassis.add_freejoint(name="root")
    chassis.add_geom(
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[0.3, 0.15, 0.05],
        mass=p.chassis_mass,
        contype=0,
        conaffinity=0,
    )
    chassis.add_site(name="imu", pos=[0.0, 0.0, 0.0])
    no_collide = {"contype": 0, "conaffinity": 0}
    wheel_quat = [math.cos(-math.pi / 4), math.sin(-math.pi / 4), 0.0, 0.0]  # cylinder axis z -> body y
    wheels_geoms = {}
    for side, sign in _SIDES:
        y = sign * robot.rocker_lateral_offset
        rocker = chassis.add_body(name=f"rocker_{side}", pos=[0.0, y, 0.0])
        hinge(rocker, f"rocker_{side}", p.joint_damping, limit=p.joint_limit)
        rocker.add_geom(
            type=mujoco.mjtGeom.mjGEOM_CAPSULE,
            fromto=[-robot.rear_arm_length, 0, 0, robot.bogie_hinge_x, 0, 0],
            size=[0.015, 0, 0],
            mass=p.rocker_mass,
            **no_collide,
        )
        # rear wheel: a slide along the rocker's -z (joint value s = rear_wheel_drop + slide qpos)
        slide = rocker.add_body(
            name=f"slide_{side}", pos=[-robot.rear_arm_length, 0.0, -robot.rear_wheel_drop]
        )
        sj = slide.add_joint(name=f"slide_{side}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0.0, 0.0, -1.0])
        _set_coef(sj, "stiffness", p.slide_stiffness)
        _set_coef(sj, "damping", p.slide_damping)
        sj.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        sj.range = [-p.slide_travel, p.slide_travel]
        slide.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.01, 0, 0], mass=0.05, **no_collide)
        slide.add_site(name=f"contact_rear_{side}", pos=list(_site_local(robot, "rear")))
        wheel = slide.add_body(name=f"wheel_rear_{side}")
        hinge(wheel, f"wheel_rear_{side}", 0.0)
        wheels_geoms[f"rear_{side}"] = wheel.add_geom(
            name=f"tyre_rear_{side}",
            type=mujoco.mjtGeom.mjGEOM_CYLINDER,
            size=[robot.rear_wheel_radius, p.rear_wheel_half_width, 0],
            quat=wheel_quat,
            mass=p.rear_wheel_mass,
            friction=[p.friction, 0.0, 0.0],
        )
        bogie = rocker.add_body(name=f"bogie_{side}", pos=[robot.bogie_hinge_x, 0.0, -robot.bogie_hinge_drop])
        hinge(bogie, f"bogie_{side}", p.bogie_damping, p.bogie_stiffness, p.joint_limit, -p.bogie_preload)
        bogie.add_geom(
            type=mujoco.mjtGeom.mjGEOM_CAPSULE,
            fromto=[-robot.side_link_hinge_offset, 0, 0, robot.side_link_hinge_offset, 0, 0],
            size=[0.01, 0, 0],
            mass=p.bogie_mass,
            **no_collide,
        )
        hub = _site_local(robot, "road")
        hub = (hub[0], 0.0, hub[2] + robot.road_wheel_radius)
        for pos_name, x in (("front", robot.side_link_hinge_offset), ("rear", -robot.side_link_hinge_offset)):
            link = bogie.add_body(name=f"link_{pos_name}_{side}", pos=[x, 0.0, 0.0])
            hinge(link, f"link_{pos_name}_{side}", p.side_link_damping, p.side_link_stiffness, p.joint_limit)
            link.add_geom(
                type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                fromto=[0, 0, 0, *hub],
                size=[0.006, 0, 0],
                mass=p.side_link_mass,
                **no_collide,
            )
            w = f"{pos_name}_road_{side}"
            link.add_site(name=f"contact_{w}", pos=list(_site_local(robot, "road")))
            wheel = link.add_body(name=f"wheel_{w}", pos=list(hub))
            hinge(wheel, f"wheel_{w}", 0.0)
            wheels_geoms[w] = wheel.add_geom(
                name=f"tyre_{w}",
                type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                size=[robot.road_wheel_radius, p.road_wheel_half_width, 0],
                quat=wheel_quat,
                mass=p.road_wheel_mass,
                friction=[p.friction, 0.0, 0.0],
            )
        # the parallelogram: both side links of a side turn together
        _joint_equality(spec, f"link_rear_{side}", f"link_front_{side}", 1.0)  # θ_rear = θ_front
    # the differential: the rockers turn oppositely relative to the body
    _joint_equality(spec, "rocker_left", "rocker_right", -1.0)  # θ_left = -θ_right
    for w in WHEELS:
        act = spec.add_actuator(name=f"drive_{w}", target=f"wheel_{w}", trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_velocity(kv=p.wheel_gain)
        act.forcelimited = True
        act.forcerange = [-p.wheel_torque_limit, p.wheel_torque_limit]
    spec.add_sensor(
        name="gyro", type=mujoco.mjtSensor.mjSENS_GYRO, objtype=mujoco.mjtObj.mjOBJ_SITE, objname="imu"
    )
    spec.add_sensor(
        name="accel",
        type=mujoco.mjtSensor.mjSENS_ACCELEROMETER,
        objtype=mujoco.mjtObj.mjOBJ_SITE,
        objname="imu",
    )
    return spec


def _set_coef(joint, attr: str, value: float) -> None:
    """Set a joint's damping/stiffness: a scalar in MuJoCo 3, polynomial coefficients in MuJoCo 4."""
    current = getattr(joint, attr)
    setattr(joint, attr, value if np.ndim(current) == 0 else [value] + [0.0] * (len(current) - 1))


def _joint_equality(spec, name1: str, name2: str, gain: float) -> None:
    """``q(name1) = gain · q(name2)`` as a stiffened joint equality (polycoef ``[0, gain, 0, ...]``)."""
    import mujoco

    eq = spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=name1, name2=name2)
    eq.data = [0.0, gain] + [0.0] * (len(eq.data) - 2)  # 11 entries in MuJoCo 3, 12 in MuJoCo 4
    eq.solref = list(_EQ_SOLREF)
    eq.solimp = list(_EQ_SOLIMP)


@dataclass(frozen=True)
class EngineRun:
    """A recorded engine run, ``N`` samples every ``1/rate`` s (after the settling time).

    ``T_GB (N, 4, 4)`` chassis poses; ``twist (N, 6)`` chassis twist ``[ω_B; v_B]`` in body axes;
    ``config``/``config_rate (N, 8)`` in the estimator's layout; ``wheel_rate (N, 6)`` wheel spin rates
    (rad/s, what encoders measure), ``wheel_command (N, 6)`` the commanded ones; ``contact_velocity
    (N, 6, 3)`` velocity of each carrier-fixed contact frame relative to the ground in its own axes;
    ``measured (N, 22)`` the 30×11 estimator's input (contact velocities, rocker pitch rates, yaw and
    roll rates); ``gyro``/``accel (N, 3)`` the IMU (angular velocity, specific force, body axes, noise
    free); ``in_contact (N, 6)`` whether each wheel touches the ground; ``on_terrain (N,)`` whether all
    wheels are inside the height field (always true on the plane).  Wheel order ``WHEELS``.
    """

    t: np.ndarray
    T_GB: np.ndarray
    twist: np.ndarray
    config: np.ndarray
    config_rate: np.ndarray
    wheel_rate: np.ndarray
    wheel_command: np.ndarray
    contact_velocity: np.ndarray
    measured: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray
    in_contact: np.ndarray
    on_terrain: np.ndarray
    rate: float


def simulate_engine(
    robot: ExplorationRobot,
    track_speeds: ArrayLike,
    duration: float,
    *,
    terrain: Terrain | None = None,
    rate: float = 100.0,
    settle: float = 0.5,
    ramp: float = 0.5,
    params: EngineParams | None = None,
) -> EngineRun:
    """Run the engine: the right/left wheels commanded to spin at ``track_speed / wheel radius``.

    ``track_speeds``: ``(2,)`` constant right/left track speeds (m/s), or ``(K, 3)`` rows
    ``(t_k, v_right, v_left)`` interpolated linearly in time (a manoeuvre).  The robot first settles
    for ``settle`` s at rest, then the commands ramp in over ``ramp`` s; ``duration`` s are recorded
    after the settling at ``rate`` Hz (a whole number of engine steps per sample).
    """
    import mujoco

    check_params(robot, ExplorationRobot, "robot")
    terrain = Terrain.flat() if terrain is None else terrain
    check_params(terrain, Terrain, "terrain")
    p = EngineParams() if params is None else params
    check_params(p, EngineParams, "params")
    T = check_positive(duration, "duration")
    fs = check_positive(rate, "rate")
    settle = check_positive(settle, "settle", allow_zero=True)
    ramp = check_positive(ramp, "ramp", allow_zero=True)
    ts = as_array(track_speeds, "track_speeds")
    if ts.shape == (2,):
        sched = np.array([[0.0, ts[0], ts[1]], [1.0, ts[0], ts[1]]])
    elif ts.ndim == 2 and ts.shape[1] == 3 and ts.shape[0] >= 2:
        sched = ts
        if np.any(np.diff(sched[:, 0]) <= 0):
            raise ValueError(
                "Expected track_speeds schedule times t_k strictly increasing, got non-increasing ones."
            )
    else:
        raise ValueError(f"Expected track_speeds to have shape (2,) or (K, 3), got {ts.shape}.")
    per = 1.0 / (fs * p.timestep)
    steps_per_sample = round(per)
    if steps_per_sample < 1 or abs(per - steps_per_sample) > _STEP_RTOL * per:
        raise ValueError(
            f"Expected rate to divide the engine rate 1/timestep = {1.0 / p.timestep:g} Hz into whole "
            f"steps, got {fs!r}."
        )
    spec = build_model(robot, terrain, p)
    model = spec.compile()
    data = mujoco.MjData(model)
    radii = wheel_radii(robot)
    side = np.array([0, 0, 0, 1, 1, 1])
    jid = {n: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in _joint_names()}
    qadr = {n: model.jnt_qposadr[i] for n, i in jid.items()}
    vadr = {n: model.jnt_dofadr[i] for n, i in jid.items()}
    act = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"drive_{w}") for w in WHEELS]
    sites = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"contact_{w}") for w in WHEELS]
    tyres = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"tyre_{w}") for w in WHEELS]
    wheel_bodies = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"wheel_{w}") for w in WHEELS]
    ground = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "ground")
    chassis = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "chassis")
    gyro_adr = model.sensor_adr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, "gyro")]
    acc_adr = model.sensor_adr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, "accel")]

    def command(t_rel: float) -> np.ndarray:
        if t_rel <= 0.0:
            return np.zeros(6)
        v = np.array([np.interp(t_rel, sched[:, 0], sched[:, k]) for k in (1, 2)])
        scale = min(1.0, t_rel / ramp) if ramp > 0 else 1.0
        return scale * v[side] / radii

    n_settle = round(settle / p.timestep)
    for _ in range(n_settle):
        mujoco.mj_step(model, data)
    n = round(T * fs) + 1
    out = {k: np.empty((n, *s)) for k, s in _SHAPES.items()}
    in_contact = np.zeros((n, 6), dtype=bool)
    on_terrain = np.ones(n, dtype=bool)
    vel = np.zeros(6)
    t0 = data.time
    for k in range(n):
        if k > 0:
            for _ in range(steps_per_sample):
                data.ctrl[act] = command(data.time - t0)
                mujoco.mj_step(model, data)
        mujoco.mj_forward(model, data)  # sensors and velocities at this state
        mujoco.mj_rnePostConstraint(model, data)  # accelerometer uses cacc
        out["t"][k] = data.time - t0
        out["wheel_command"][k] = command(data.time - t0)
        R = data.xmat[chassis].reshape(3, 3)
        Tk = np.eye(4)
        Tk[:3, :3], Tk[:3, 3] = R, data.xpos[chassis]
        out["T_GB"][k] = Tk
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, chassis, vel, 1)
        out["twist"][k] = vel
        for i, (sname, _sign) in enumerate(_SIDES):
            base = 4 * i
            names = (f"rocker_{sname}", f"bogie_{sname}", f"link_front_{sname}", f"slide_{sname}")
            for j, nm in enumerate(names):
                out["config"][k, base + j] = data.qpos[qadr[nm]]
                out["config_rate"][k, base + j] = data.qvel[vadr[nm]]
            out["config"][k, base + 3] += robot.rear_wheel_drop
        for w in range(6):
            out["wheel_rate"][k, w] = data.qvel[vadr[f"wheel_{WHEELS[w]}"]]
            mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_SITE, sites[w], vel, 1)
            out["contact_velocity"][k, w] = vel[3:]
        out["gyro"][k] = data.sensordata[gyro_adr : gyro_adr + 3]
        out["accel"][k] = data.sensordata[acc_adr : acc_adr + 3]
        for c in range(data.ncon):
            con = data.contact[c]
            pair = (con.geom1, con.geom2)
            if ground in pair:
                other = pair[1] if pair[0] == ground else pair[0]
                if other in tyres and con.dist <= 0.0:
                    in_contact[k, tyres.index(other)] = True
        if not terrain.is_flat:
            hubs = data.xpos[wheel_bodies, :2]
            on_terrain[k] = bool(np.all(np.abs(hubs) <= terrain.half_size - robot.rear_wheel_radius))
    meas = np.empty((n, 22))
    meas[:, :18] = out["contact_velocity"].reshape(n, 18)
    meas[:, 18] = out["twist"][:, 1] + out["config_rate"][:, 0]
    meas[:, 19] = out["twist"][:, 1] + out["config_rate"][:, 4]
    meas[:, 20] = out["twist"][:, 2]
    meas[:, 21] = out["twist"][:, 0]
    return EngineRun(measured=meas, in_contact=in_contact, on_terrain=on_terrain, rate=fs, **out)


_SHAPES = {
    "t": (),
    "T_GB": (4, 4),
    "twist": (6,),
    "config": (8,),
    "config_rate": (8,),
    "wheel_rate": (6,),
    "wheel_command": (6,),
    "contact_velocity": (6, 3),
    "gyro": (3,),
    "accel": (3,),
}


def _joint_names() -> list[str]:
    names = []
    for side, _ in _SIDES:
        names += [
            f"rocker_{side}",
            f"bogie_{side}",
            f"link_front_{side}",
            f"link_rear_{side}",
            f"slide_{side}",
        ]
    names += [f"wheel_{w}" for w in WHEELS]
    return names
