"""Bad-input specs of the skid-steer names added by issue 17 (ICR kinematics, slip, sensors, EKF).

The names that existed before issue 17 are specified in ``mechanisms_skid_steer.py`` (or still
pending); these live in their own file so the two can be written at the same time.
"""

import numpy as np
from contract_spec import (
    BAD_INT,
    BAD_NONNEGATIVE,
    BAD_POSITIVE,
    BAD_REAL,
    CONSTANT,
    RESULT_TYPE,
    Spec,
    exempt,
)

from robomech.mechanisms import skid_steer as ss

P = "robomech.mechanisms.skid_steer."
ROBOT = ss.ExplorationRobot.paper()
MODEL = ss.ICRModel(0.6, -0.7, 0.02)
Q2 = np.zeros((2, 8))
Q2[:, [3, 7]] = ROBOT.rear_wheel_drop
RATES = np.array([[4.0, 4.0, 2.0, 2.0, 2.0, 1.0], [3.0, 3.1, 1.5, 1.0, 1.1, 0.5]])
N = 20
T = np.arange(N) * 0.01

SPECS = {
    **exempt("LATERAL_SLIP_RTOL SLIP_SPEED_FLOOR SAMPLE_RATE_RTOL N_STATE", CONSTANT, P),
    **exempt(
        "LateralSlip PlanarVelocity TrackSpeeds WheelSlip ICRIdentification EKFResult EncoderReadings",
        RESULT_TYPE,
        P,
    ),
    P + "ICRModel": Spec(
        args={"y_left": 0.6, "y_right": -0.7, "x_icr": 0.02},
        options={"y_left": BAD_REAL, "y_right": BAD_REAL, "x_icr": BAD_REAL},
    ),
    P + "icr_velocity": Spec(
        args={"model": MODEL, "v_right": np.array([0.3, 0.2, -0.1]), "v_left": np.array([0.1, 0.2, 0.1])},
        arrays={"v_right": 0, "v_left": 0},
        masked=("v_right", "v_left"),
        mask="valid",
        params=("model",),
    ),
    P + "wheel_radii": Spec(args={"robot": ROBOT}, params=("robot",)),
    P + "encoder_track_speeds": Spec(
        args={"robot": ROBOT, "wheel_rate": RATES},
        arrays={"wheel_rate": 1},
        masked=("wheel_rate",),
        mask="valid",
        params=("robot",),
    ),
    P + "identify_icr": Spec(
        args={
            "v_right": np.array([0.3, 0.2, 0.25, 0.1, 0.0, 0.2]),
            "v_left": np.array([0.1, 0.2, 0.05, 0.3, 0.2, -0.2]),
            "body_velocity": np.array(
                [
                    [0.2, 0.0, 0.1],
                    [0.2, 0.0, 0.0],
                    [0.15, 0.0, 0.11],
                    [0.2, 0.0, -0.1],
                    [0.1, 0.0, -0.1],
                    [0.0, 0.0, 0.2],
                ]
            ),
            "weights": np.ones(6),
        },
        arrays={"v_right": 0, "v_left": 0, "body_velocity": 1, "weights": 0},
        masked=("v_right", "v_left", "body_velocity"),
        mask="used",
        wrong_shapes={"v_right": ((6, 2),), "weights": ((5,),)},
    ),
    P + "wheel_slip": Spec(
        args={
            "robot": ROBOT,
            "wheel_rate": RATES,
            "body_velocity": np.array([[0.2, 0.0, 0.1], [0.1, 0.0, 0.0]]),
            "config": Q2,
        },
        arrays={"wheel_rate": 0, "body_velocity": 1, "config": 1},
        nan_rows=("body_velocity", "config"),  # wheel_rate masked per wheel
        masked=("wheel_rate",),
        mask="valid",
        params=("robot",),
        wrong_shapes={"wheel_rate": ((2, 5),)},
        batch_core={"wheel_rate": 1},  # its batch is everything before the wheel axis
    ),
    P + "EncoderModel": Spec(args={"counts_per_rev": 1024}, options={"counts_per_rev": (*BAD_INT, 0, -5)}),
    P + "ImuModel": Spec(
        args={
            "gyro_noise_density": 1e-4,
            "gyro_bias": np.array([0.0, 0.0, 0.001]),
            "accel_noise_density": 5e-3,
            "accel_bias": np.array([0.02, -0.01, 0.0]),
        },
        arrays={"gyro_bias": 1, "accel_bias": 1},
        unbatched=("gyro_bias", "accel_bias"),  # fields of one sensor model
        options={"gyro_noise_density": BAD_NONNEGATIVE, "accel_noise_density": BAD_NONNEGATIVE},
        wrong_shapes={"gyro_bias": ((2, 3),)},
    ),
    P + "encoder_rates": Spec(
        args={"model": ss.EncoderModel(), "wheel_rate": np.tile(RATES[0], (5, 1)), "dt": 0.01, "seed": 0},
        arrays={"wheel_rate": 1},
        mask="valid",
        params=("model",),
        options={"dt": BAD_POSITIVE, "seed": (*BAD_INT, -1)},
        wrong_shapes={"wheel_rate": ((6,), (2, 5, 6))},
    ),
    P + "imu_measurements": Spec(
        args={
            "model": ss.ImuModel(),
            "angular_velocity": np.zeros((4, 3)),
            "specific_force": np.tile([0.0, 0.0, 9.81], (4, 1)),
            "dt": 0.01,
            "seed": 1,
        },
        arrays={"angular_velocity": 1, "specific_force": 1},
        params=("model",),
        options={"dt": BAD_POSITIVE, "seed": (*BAD_INT, -1)},
        wrong_shapes={"specific_force": ((3, 3),)},
    ),
    P + "track_speed_sigma": Spec(
        args={"encoder": ss.EncoderModel(), "radii": np.array([0.05, 0.05, 0.1]), "dt": 0.01},
        arrays={"radii": 0},
        params=("encoder",),
        options={"dt": BAD_POSITIVE},
        wrong_shapes={"radii": ((2, 3),)},
        empty_batch=False,  # radii (k,) are one side's wheels, not samples
    ),
    P + "planar_ekf": Spec(
        args={
            "t": T,
            "v_right": np.full(N, 0.3),
            "v_left": np.full(N, 0.1),
            "gyro_z": np.full(N, 0.1),
            "icr": MODEL,
            "sigma_track": 1e-3,
            "sigma_gyro": 1e-3,
            "sigma_model": 0.0,
            "accel_psd": 0.5,
            "yaw_accel_psd": 2.0,
            "bias_psd": 1e-8,
            "initial_pose": np.zeros(3),
            "initial_bias_sigma": 0.01,
            "icr_sigma": 0.1,
            "icr_psd": 1e-4,
        },
        arrays={"t": 0, "v_right": 0, "v_left": 0, "gyro_z": 0, "initial_pose": 1},
        unbatched=("initial_pose",),  # one start pose of the one history (t, v_right, ... share its N)
        params=("icr",),
        options={
            "sigma_track": BAD_POSITIVE,
            "sigma_gyro": BAD_POSITIVE,
            "sigma_model": BAD_NONNEGATIVE,
            "accel_psd": BAD_POSITIVE,
            "yaw_accel_psd": BAD_POSITIVE,
            "bias_psd": BAD_NONNEGATIVE,
            "initial_bias_sigma": BAD_NONNEGATIVE,
            "icr_sigma": BAD_NONNEGATIVE,
            "icr_psd": BAD_NONNEGATIVE,
        },
        wrong_shapes={"t": ((2, N),), "gyro_z": ((N - 1,),), "v_right": ((N + 1,),)},
    ),
}
