"""Independent verification of every mechanism model (the role ADAMS plays in the papers).

Modules ``robomech/verify/<module>.py`` define ``VERIFICATION``; they are discovered by name so that a
mechanism's verification needs no edit elsewhere.  Engines are imported inside those modules only, on
first use; a verification whose ``requires`` are not installed is skipped with the extra to install.
"""

from __future__ import annotations

from collections.abc import Iterable

from robomech._registry import discover, skip_reason

from ._core import (
    Check,
    EngineUnavailable,
    Tolerance,
    Verification,
    VerificationReport,
    dumps_json,
    optional_module,
    to_jsonable,
)

__all__ = [
    "Check",
    "EngineUnavailable",
    "Tolerance",
    "Verification",
    "VerificationReport",
    "available_verifications",
    "dumps_json",
    "optional_module",
    "run_verifications",
    "to_jsonable",
]


def available_verifications() -> dict[str, Verification]:
    """All registered verifications by mechanism name, in a stable order.

    Discovered from the modules ``robomech/verify/<module>.py`` that define ``VERIFICATION``; nothing
    is run and no engine is imported.

    Returns
    -------
    dict of str to Verification

    Examples
    --------
    >>> from robomech.verify import available_verifications
    >>> "omnileg" in available_verifications()
    True
    """
    return discover(__name__, __path__, "VERIFICATION", Verification)


def run_verifications(names: Iterable[str] | None = None) -> VerificationReport:
    """Run the named verifications (all when ``names`` is empty or None).

    Parameters
    ----------
    names : iterable of str, optional
        Mechanism names as listed by :func:`available_verifications`.

    Returns
    -------
    VerificationReport
        ``checks`` of every verification that ran; ``skipped`` lists ``(name, reason)`` for those
        whose optional engine is not installed (``reason`` names the extra, e.g. ``robomech[verify]``).

    Raises
    ------
    ValueError
        If a name is not a registered verification.
    """
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
        reason = skip_reason(available[n].requires)
        if reason is not None:
            report.skipped.append((n, reason))
            continue
        report.checks.extend(available[n].run())
    return report
