"""The five papers robomech reproduces, cited once: every report and docs page takes its citation here.

Authors, titles and venues are as printed in each paper's English front matter (the papers are in
Chinese with English titles and abstracts); the DOI is the one printed on the paper's first page.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Paper:
    """A published paper, as cited in reports and in the documentation.

    Attributes
    ----------
    number : int
        robomech's number for the paper (1–5), used in the mechanism pages and in code comments.
    authors : tuple of str
        Authors, family name first, in the order printed.
    title : str
        English title as printed.
    venue : str
        Journal, volume and issue.
    year : int
        Year of publication.
    pages : str
        Page range, empty where the print does not give it.
    doi : str
        DOI as printed on the paper, empty where none is printed.
    """

    number: int
    authors: tuple[str, ...]
    title: str
    venue: str
    year: int
    pages: str = ""
    doi: str = ""

    def citation(self) -> str:
        """One-line citation: authors, title, venue, year, pages and DOI (plain text).

        Returns
        -------
        str
        """
        text = f"{', '.join(self.authors)}: {self.title}. {self.venue}, {self.year}"
        if self.pages:
            text += f", pp. {self.pages}"
        if self.doi:
            text += f". doi:{self.doi}"
        return text

    def short(self) -> str:
        """Short form for tables and lists: first author *et al.*, venue and year.

        Returns
        -------
        str
        """
        first = self.authors[0].split()[0].capitalize()
        more = " et al." if len(self.authors) > 1 else ""
        return f"{first}{more}, {self.venue}, {self.year}"


PAPERS: dict[int, Paper] = {
    1: Paper(
        1,
        ("CHEN Yuan", "HE Shulei", "JIANG Yuan", "SANG Donghui", "NING Shurong"),
        "Dynamic model of spherical parallel mechanism for wheel-leg hybrid mobile robot",
        "Optics and Precision Engineering 27(8)",
        2019,
        "1780-1790",
        "10.3788/OPE.20192708.1780",
    ),
    2: Paper(
        2,
        ("XU Yuze", "LU Zhongyue", "ZHU Yiming", "LUO Zirong"),
        "Kinematics and dynamics modeling and experiments of OmniLegs",
        "China Mechanical Engineering 36(4)",
        2025,
        "",
        "10.3969/j.issn.1004-132X.2025.04.018",
    ),
    3: Paper(
        3,
        ("QI Fei", "ZHANG Heng", "PEI Haishan", "CHEN Bai", "WU Hongtao"),
        "Drive error compensation of continuum manipulator based on force transfer model",
        "Transactions of the Chinese Society for Agricultural Machinery 54(1)",
        2023,
        "402-411",
        "10.6041/j.issn.1000-1298.2023.01.041",
    ),
    4: Paper(
        4,
        ("SHANG Weiyan", "QIU Faju", "YANG Chaozhen"),
        "Kinematics analysis of differential steering exploration robot with compound walking mechanism",
        "China Mechanical Engineering 23(2)",
        2012,
        "",
        "10.3969/j.issn.1004-132X.2012.02.010",
    ),
    5: Paper(
        5,
        ("XU Han", "LI Jing", "CHEN Yuan", "ZHANG Rongmin", "GAO Jun"),
        "Kinematic modeling of spherical parallel manipulator with vectored thrust function for "
        "underwater robot based on screw theory",
        "Robot 38(6)",
        2016,
        "738-745",
        "10.13973/j.cnki.robot.2016.0738",
    ),
}


def cite(number: int) -> str:
    """The full citation of paper ``number`` (1–5).

    Parameters
    ----------
    number : int
        robomech's paper number.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        If ``number`` is not one of the papers.
    """
    if number not in PAPERS:
        raise ValueError(f"Expected number to be one of {sorted(PAPERS)}, got {number!r}.")
    return PAPERS[number].citation()
