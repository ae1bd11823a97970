"""Bad-input specs of robomech.multibody (the generic closed-chain layer) and its gallery."""

import tempfile

import numpy as np
from contract_spec import (
    BAD_BOOL,
    BAD_INT,
    BAD_NONNEGATIVE,
    BAD_REAL,
    BAD_STR,
    CONSTANT,
    RESULT_TYPE,
    Spec,
    exempt,
)

from robomech import multibody as mb

P = "robomech.multibody."
MECH = mb.gallery.load("four_bar")
QA = np.array([[0.2], [-0.4], [0.6]])  # crank angles (rad), 3 samples
Q = mb.forward_kinematics(MECH, QA).q  # (3, 3) assembled configurations
T = mb.site_pose(MECH, Q, "coupler_point")  # (3, 4, 4) reachable targets
QD = np.array([[1.0, 0.5, -0.3], [0.2, -0.1, 0.4], [0.0, 1.0, 1.0]])
V3 = np.array([0.1, -0.2, 0.3])
QUAT = np.array([1.0, 0.0, 0.0, 0.0])
BAD_NAME = (*BAD_STR, "")
URDF = (  # a one-joint URDF (text) for from_urdf
    "<robot name='r'><link name='a'/><link name='b'><inertial><mass value='1'/>"
    "<inertia ixx='1' iyy='1' izz='1' ixy='0' ixz='0' iyz='0'/></inertial></link>"
    "<joint name='j' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 1'/>"
    "<limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>"
)
BAD_LENGTH = (np.nan, np.inf, -1.0, 0.0, "1", True, 1j)
BAD_STEPS = (*BAD_INT, 0)
# the gallery's write() writes its files here, not into the package
WRITE_DIR = tempfile.mkdtemp(prefix="robomech-gallery-")

# the output of the type I test: a name among pose/position/orientation or distinct rows 0..5
BAD_OUTPUT = (None, "speed", 3, (), (3, 3), (0, 6), (-1,), (1.5,), ("a",))

SPECS = {
    # ---- description -------------------------------------------------------------------------------
    P + "Joint": Spec(
        args={"name": "j", "type": "hinge", "axis": V3, "pos": V3, "ref": 0.1},
        arrays={"axis": 1, "pos": 1},
        unbatched=("axis", "pos"),  # a joint's fields, one description
        options={"name": BAD_NAME, "type": ("cylindrical", 1, None), "ref": BAD_REAL},
    ),
    P + "Inertial": Spec(
        args={"mass": 1.0, "pos": V3, "quat": QUAT, "diaginertia": np.array([0.1, 0.2, 0.3])},
        arrays={"pos": 1, "quat": 1, "diaginertia": 1},
        unbatched=("pos", "quat", "diaginertia"),  # description fields
        options={"mass": BAD_NONNEGATIVE},
    ),
    P + "Body": Spec(
        args={
            "name": "b",
            "parent": "world",
            "pos": V3,
            "quat": QUAT,
            "joints": (mb.Joint("j"),),
            "inertial": mb.Inertial(1.0, diaginertia=(0.1, 0.1, 0.1)),
        },
        arrays={"pos": 1, "quat": 1},
        unbatched=("pos", "quat"),  # description fields
        options={
            "name": (*BAD_NAME, "world"),
            "parent": BAD_NAME,
            "joints": (None, "j", (1,)),
            "inertial": ("heavy", 1.0),
        },
    ),
    P + "Site": Spec(
        args={"name": "s", "body": "b", "pos": V3, "quat": QUAT},
        arrays={"pos": 1, "quat": 1},
        unbatched=("pos", "quat"),  # description fields
        options={"name": BAD_NAME, "body": BAD_NAME},
    ),
    P + "Closure": Spec(
        args={
            "name": "c",
            "kind": "point",
            "body1": "a",
            "body2": "b",
            "anchor1": V3,
            "anchor2": V3,
            "relpos": V3,
            "relquat": QUAT,
            "axis": V3,
            "axis2": V3,
        },
        arrays={"anchor1": 1, "anchor2": 1, "relpos": 1, "relquat": 1, "axis": 1, "axis2": 1},
        unbatched=("anchor1", "anchor2", "relpos", "relquat", "axis", "axis2"),  # description fields
        options={"name": BAD_NAME, "kind": ("ball", 3, None), "body1": BAD_NAME, "body2": (*BAD_NAME, "a")},
    ),
    P + "Coupling": Spec(
        args={"name": "c", "joint1": "j1", "joint2": "j2", "polycoef": np.array([0.0, 1.0, 0.0, 0.0, 0.0])},
        arrays={"polycoef": 1},
        options={"name": BAD_NAME, "joint1": BAD_NAME, "joint2": (1, 1.5, "")},
    ),
    P + "Mechanism": Spec(
        args={
            "bodies": MECH.bodies,
            "closures": MECH.closures,
            "sites": MECH.sites,
            "actuated": MECH.actuated,
            "gravity": np.array([0.0, 0.0, -9.81]),
            "name": "m",
            "characteristic_length": 0.5,
        },
        arrays={"gravity": 1},
        options={
            "bodies": (None, "crank", (1,), ()),
            "closures": (None, (1,)),
            "sites": ("s", (1,)),
            "actuated": ("theta2", (1,), ("nope",), ("theta2", "theta2")),
            "name": BAD_NAME,
            "characteristic_length": BAD_LENGTH,
        },
    ),
    P + "Builder": Spec(
        args={"name": "m", "gravity": np.array([0.0, 0.0, -9.81])},
        arrays={"gravity": 1},
        options={"name": BAD_NAME},
    ),
    # ---- MJCF --------------------------------------------------------------------------------------
    P + "from_urdf": Spec(
        args={"path_or_text": URDF, "actuated": ["j"], "closures": None},
        options={
            "path_or_text": (
                None,
                1,
                1.5,
                "/no/such/file.urdf",
                "<robot name='r'><link name='a'/><joint name='j' type='bogus'/></robot>",
                mb.to_mjcf(MECH),
            ),
            "actuated": ("j", [1], ["nope"]),
            "closures": ([1], "<notequality/>", "<equality"),
        },
        slow=False,
    ),
    P + "from_mjcf": Spec(
        args={"path_or_xml": mb.to_mjcf(MECH)},
        options={
            "path_or_xml": (
                None,
                1,
                1.5,
                "/no/such/file.xml",
                "<mujoco><worldbody><body><joint type='bogus'/></body></worldbody></mujoco>",
            )
        },
        slow=False,
    ),
    P + "to_mjcf": Spec(args={"mech": MECH, "comment": "c"}, params=("mech",), options={"comment": (1, 1.5)}),
    # ---- assembly ----------------------------------------------------------------------------------
    P + "forward_kinematics": Spec(
        args={"mech": MECH, "q_act": QA, "guess": Q, "steps": 1},
        arrays={"q_act": 1, "guess": 1},
        masked=("q_act",),
        nan_rows=("guess",),  # a failed sample's q as the guess: that sample is masked
        mask="converged",
        params=("mech",),
        options={"steps": (*BAD_STEPS, 10**7)},  # 10**7 stages: beyond MAX_STEPS, refused
    ),
    P + "inverse_kinematics": Spec(
        args={
            "mech": MECH,
            "site": "coupler_point",
            "T_target": T,
            "guess": Q,
            "weights": np.ones(6),
            "steps": 1,
        },
        arrays={"T_target": 2, "guess": 1, "weights": 1},
        nan_rows=("guess",),
        unbatched=("weights",),  # one weighting of the 6 pose residuals for the whole batch
        masked=("T_target",),
        mask="converged",
        params=("mech",),
        options={"site": (*BAD_STR, "nope"), "steps": BAD_STEPS},
    ),
    # ---- influence coefficients ---------------------------------------------------------------------
    P + "site_pose": Spec(
        args={"mech": MECH, "q": Q, "site": "coupler_point"},
        arrays={"q": 1},
        nan_rows=("q",),  # a failed FK sample chains: NaN out at that sample
        params=("mech",),
        options={"site": (*BAD_STR, "nope")},
    ),
    P + "site_jacobian": Spec(
        args={"mech": MECH, "q": Q, "site": "coupler_point"},
        arrays={"q": 1},
        nan_rows=("q",),  # a failed FK sample chains: NaN out at that sample
        params=("mech",),
        options={"site": (*BAD_STR, "nope")},
    ),
    P + "site_hessian": Spec(
        args={"mech": MECH, "q": Q, "site": "coupler_point"},
        arrays={"q": 1},
        nan_rows=("q",),  # a failed FK sample chains: NaN out at that sample
        params=("mech",),
        options={"site": (*BAD_STR, "nope")},
    ),
    P + "influence": Spec(
        args={"mech": MECH, "q": Q, "second_order": True},
        arrays={"q": 1},
        nan_rows=("q",),
        params=("mech",),
        options={"second_order": BAD_BOOL},
        finite_result=False,
    ),
    P + "constraint_residual": Spec(
        args={"mech": MECH, "q": Q}, arrays={"q": 1}, nan_rows=("q",), params=("mech",)
    ),
    P + "constraint_jacobian": Spec(
        args={"mech": MECH, "q": Q}, arrays={"q": 1}, nan_rows=("q",), params=("mech",)
    ),
    P + "constraint_jacobian_rate": Spec(
        args={"mech": MECH, "q": Q, "qd": QD}, arrays={"q": 1, "qd": 1}, nan_rows=("q",), params=("mech",)
    ),
    # ---- mobility, singularities, maps -------------------------------------------------------------
    P + "mobility": Spec(
        args={"mech": MECH, "q": Q[0], "platform": "coupler"},
        arrays={"q": 1},
        params=("mech",),
        options={"platform": (1, "nope", "world")},
        finite_result=False,
    ),
    P + "singularities": Spec(
        args={
            "mech": MECH,
            "q": Q,
            "site": "coupler_point",
            "reference": MECH.q0,
            "length": 0.5,
            "rtol": 1e-8,
            "output": "position",
        },
        arrays={"q": 1, "reference": 1},
        unbatched=("reference",),  # one reference configuration (the branch) for the whole batch
        nan_rows=("q",),
        params=("mech",),
        options={
            "site": (*BAD_STR, "nope"),
            "length": BAD_LENGTH,
            "rtol": (*BAD_REAL, 0.0, 1.0, -1.0),
            "output": BAD_OUTPUT,
        },
    ),
    P + "singularity_map": Spec(
        args={"mech": MECH, "site": "coupler_point", "q_act": QA, "guess": Q, "steps": 2, "output": (3, 4)},
        arrays={"q_act": 1, "guess": 1},
        masked=("q_act",),
        nan_rows=("guess",),  # a failed sample's q as the guess: that sample is masked
        mask="reachable",
        params=("mech",),
        options={"site": (*BAD_STR, "nope"), "steps": (*BAD_STEPS, 10**7), "output": BAD_OUTPUT},
    ),
    # ---- drawing -----------------------------------------------------------------------------------
    P + "body_segments": Spec(
        args={"mech": MECH, "q": Q[0]}, arrays={"q": 1}, params=("mech",), wrong_shapes={"q": ((2, 3),)}
    ),
    P + "draw": Spec(
        args={"mech": MECH, "q": Q[0], "color": "C1", "title": "t", "ax": None},
        arrays={"q": 1},
        params=("mech",),
        options={"color": (*BAD_STR, "notacolor"), "title": (1, 1.5), "ax": (1, "axes")},
        wrong_shapes={"q": ((2, 3),)},
        finite_result=False,
    ),
    # ---- gallery -----------------------------------------------------------------------------------
    P + "gallery.path": Spec(
        args={"name": "four_bar"}, options={"name": (*BAD_STR, "nope")}, finite_result=False
    ),
    P + "gallery.load": Spec(args={"name": "bennett"}, options={"name": (*BAD_STR, "nope")}),
    P + "gallery.write": Spec(
        args={"directory": WRITE_DIR}, options={"directory": (None, 1, "/no/such/dir")}, finite_result=False
    ),
    P + "gallery.NAMES": CONSTANT,
    P + "gallery.BUILDERS": CONSTANT,
    P + "CONVERGED_RTOL": CONSTANT,
    P + "to_pinocchio": Spec(args={"mech": MECH}, params=("mech",)),
    **exempt(
        "FKResult IKResult Influence MobilityReport SingularityResult SingularityMapResult PinocchioModel",
        RESULT_TYPE,
        P,
    ),
}
