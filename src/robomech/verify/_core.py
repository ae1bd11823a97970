"""What a verification is: analytic model vs an independent engine or higher-fidelity model.

A module ``robomech/verify/<module>.py`` defines ``VERIFICATION = Verification(name=..., run=...)``;
``run()`` returns a list of :class:`Check`.  Each check names the quantity, the maximum error found,
the tolerance and *why* that tolerance (engine constraint stiffness, step size, model fidelity).
This layer is the only one that imports a multibody engine.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from robomech._validation import check_bool, check_positive

__all__ = ["Check", "Tolerance", "Verification", "VerificationReport"]


@dataclass(frozen=True)
class Tolerance:
    """A named tolerance with its reason; ``relative`` says how the error was normalised."""

    value: float
    reason: str
    relative: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "value", check_positive(self.value, "value"))
        if not isinstance(self.reason, str) or not self.reason.strip():
            raise ValueError(f"Expected reason to be a non-empty str (why this value), got {self.reason!r}.")
        object.__setattr__(self, "relative", check_bool(self.relative, "relative"))


@dataclass(frozen=True)
class Check:
    mechanism: str
    quantity: str
    max_error: float
    tolerance: Tolerance
    detail: str = ""

    @property
    def passed(self) -> bool:
        return math.isfinite(self.max_error) and self.max_error <= self.tolerance.value

    def as_dict(self) -> dict[str, Any]:
        return {
            "mechanism": self.mechanism,
            "quantity": self.quantity,
            "max_error": self.max_error,
            "tolerance": self.tolerance.value,
            "relative": self.tolerance.relative,
            "reason": self.tolerance.reason,
            "passed": self.passed,
            "detail": self.detail,
        }


@dataclass(frozen=True)
class Verification:
    name: str
    title: str
    engine: str
    run: Callable[[], Sequence[Check]]


@dataclass
class VerificationReport:
    checks: list[Check] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def table(self) -> str:
        wq = max([len("quantity"), *(len(c.quantity) for c in self.checks)])
        wm = max([len("mechanism"), *(len(c.mechanism) for c in self.checks)])
        header = f"{'mechanism':<{wm}} {'quantity':<{wq}} {'max error':>11} {'tolerance':>11}      result"
        lines = [header, "-" * len(header)]
        for c in self.checks:
            kind = " rel" if c.tolerance.relative else ""
            lines.append(
                f"{c.mechanism:<{wm}} {c.quantity:<{wq}} {c.max_error:>11.3e} "
                f"{c.tolerance.value:>11.1e}{kind:4}  {'pass' if c.passed else 'FAIL'}"
            )
        n_fail = sum(not c.passed for c in self.checks)
        lines.append(f"{len(self.checks) - n_fail} passed, {n_fail} failed")
        return "\n".join(lines)
