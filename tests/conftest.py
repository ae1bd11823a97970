"""Shared test configuration: hypothesis profile (bounded, deterministic in CI)."""

import os

from hypothesis import HealthCheck, settings

settings.register_profile(
    "robomech",
    max_examples=60,
    deadline=None,
    derandomize=bool(os.environ.get("CI")),
    suppress_health_check=[HealthCheck.too_slow],
)
settings.load_profile("robomech")
