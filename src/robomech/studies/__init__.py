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
    """All registered studies by name, in a stable order.

    Discovered from the modules ``robomech/studies/<module>.py`` that define ``STUDY``; nothing is run.

    Returns
    -------
    dict of str to Study

    Examples
    --------
    >>> from robomech.studies import available_studies
    >>> "omnileg" in available_studies()
    True
    """
    return discover(__name__, __path__, "STUDY", Study)


def get_study(name: str) -> Study:
    """The registered study ``name``; ``ValueError`` listing the valid names otherwise.

    Parameters
    ----------
    name : str
        A key of :func:`available_studies`.

    Returns
    -------
    Study

    Raises
    ------
    ValueError
        If ``name`` is not a str or not a registered study (the message lists the valid names).

    Examples
    --------
    >>> from robomech.studies import get_study
    >>> get_study("omnileg").name
    'omnileg'
    """
    studies = available_studies()
    if not isinstance(name, str) or name not in studies:
        raise ValueError(
            f"Expected name to be a registered study, got {name!r}; valid studies are: {', '.join(studies)}."
        )
    return studies[name]
