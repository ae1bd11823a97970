"""Paper reproductions: one module per study, discovered by name.

``robomech/studies/<module>.py`` defines ``STUDY = Study(name=..., ...)``; modules whose name starts
with an underscore are infrastructure.  This is the only layer (with ``cli``) that imports matplotlib.
"""

from __future__ import annotations

from robomech._registry import discover

from ._core import Figure, Progress, Study, StudyResult, Table, comparison_table
from ._report import write_index, write_study_report

__all__ = [
    "Figure",
    "Progress",
    "Study",
    "StudyResult",
    "Table",
    "available_studies",
    "comparison_table",
    "get_study",
    "write_index",
    "write_study_report",
]


def available_studies() -> dict[str, Study]:
    """All registered studies by name, in a stable order."""
    return discover(__name__, __path__, "STUDY", Study)


def get_study(name: str) -> Study:
    """The registered study ``name``; ``ValueError`` listing the valid names otherwise."""
    studies = available_studies()
    if not isinstance(name, str) or name not in studies:
        raise ValueError(
            f"Expected name to be a registered study, got {name!r}; valid studies are: {', '.join(studies)}."
        )
    return studies[name]
