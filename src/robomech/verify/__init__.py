"""Independent verification of every mechanism model (the role ADAMS plays in the papers).

Modules ``robomech/verify/<module>.py`` define ``VERIFICATION``; they are discovered by name so that a
mechanism's verification needs no edit elsewhere.  Engines are imported inside those modules only.
"""

from __future__ import annotations

from collections.abc import Iterable

from robomech._registry import discover

from ._core import Check, Tolerance, Verification, VerificationReport

__all__ = [
    "Check",
    "Tolerance",
    "Verification",
    "VerificationReport",
    "available_verifications",
    "run_verifications",
]


def available_verifications() -> dict[str, Verification]:
    """All registered verifications by mechanism name, in a stable order."""
    return discover(__name__, __path__, "VERIFICATION", Verification)


def run_verifications(names: Iterable[str] | None = None) -> VerificationReport:
    """Run the named verifications (all when ``names`` is empty or None)."""
    available = available_verifications()
    if isinstance(names, str) or not (names is None or isinstance(names, Iterable)):
        raise ValueError(f"Expected names to be a list of mechanism names or None, got {names!r}.")
    names = list(names or available)
    unknown = [n for n in names if n not in available]
    if unknown:
        raise ValueError(
            f"Expected names of registered verifications, got unknown {', '.join(map(repr, unknown))}; "
            f"valid ones are: {', '.join(available)}."
        )
    report = VerificationReport()
    for n in names:
        report.checks.extend(available[n].run())
    return report
