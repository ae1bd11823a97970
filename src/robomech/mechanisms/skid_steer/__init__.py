"""Paper 4: the six-wheel skid-steer wheel-track exploration robot.

Velocity kinematics from the wheel chains (rear wheels on rockers, road wheels on a parallelogram bogie)
with instantaneously coincident contact frames, stacked into the 30×11 system ``A0 ṗ = J q̇`` and
solved per sample by batched Householder QR; skid-steer turning; dead reckoning.
See ``docs/mechanisms/skid_steer.md``.
"""

from ._chains import CONFIG_SIZE, N_WHEELS, SIDE_JOINTS, WHEEL_SIDE, WHEELS, contact_frames, wheel_jacobians
from ._icr import (
    SLIP_SPEED_FLOOR,
    ICRIdentification,
    ICRModel,
    PlanarVelocity,
    TrackSpeeds,
    WheelSlip,
    encoder_track_speeds,
    icr_velocity,
    identify_icr,
    wheel_radii,
    wheel_slip,
)
from ._odometry import (
    N_STATE,
    SAMPLE_RATE_RTOL,
    EKFResult,
    EncoderModel,
    EncoderReadings,
    ImuModel,
    encoder_rates,
    imu_measurements,
    planar_ekf,
    track_speed_sigma,
)
from ._params import ExplorationRobot
from ._skid import (
    LATERAL_SLIP_RTOL,
    STRAIGHT_RTOL,
    LateralSlip,
    SkidSteerTurn,
    dead_reckoning,
    paper_lateral_slip,
    skid_steer_turn,
    wheel_lateral_velocity,
)
from ._velocity import (
    I_ROCKER1,
    I_ROCKER2,
    I_ROLL,
    I_YAW,
    MEASURED_SIZE,
    N_ROWS,
    UNKNOWN_SIZE,
    BodyVelocity,
    assemble,
    body_velocity,
    wheel_measurements,
)

__all__ = [
    "CONFIG_SIZE",
    "I_ROCKER1",
    "I_ROCKER2",
    "I_ROLL",
    "I_YAW",
    "LATERAL_SLIP_RTOL",
    "MEASURED_SIZE",
    "N_ROWS",
    "N_STATE",
    "N_WHEELS",
    "SAMPLE_RATE_RTOL",
    "SIDE_JOINTS",
    "SLIP_SPEED_FLOOR",
    "STRAIGHT_RTOL",
    "UNKNOWN_SIZE",
    "WHEELS",
    "WHEEL_SIDE",
    "BodyVelocity",
    "EKFResult",
    "EncoderModel",
    "EncoderReadings",
    "ExplorationRobot",
    "ICRIdentification",
    "ICRModel",
    "ImuModel",
    "LateralSlip",
    "PlanarVelocity",
    "SkidSteerTurn",
    "TrackSpeeds",
    "WheelSlip",
    "assemble",
    "body_velocity",
    "contact_frames",
    "dead_reckoning",
    "encoder_rates",
    "encoder_track_speeds",
    "icr_velocity",
    "identify_icr",
    "imu_measurements",
    "paper_lateral_slip",
    "planar_ekf",
    "skid_steer_turn",
    "track_speed_sigma",
    "wheel_jacobians",
    "wheel_lateral_velocity",
    "wheel_measurements",
    "wheel_radii",
    "wheel_slip",
]
