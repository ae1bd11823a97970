"""The text of the study figures: titles say what is shown (the paper's figure numbers belong in
the captions), every 3-D panel labels its z axis, a legend names each source once (not "MuJoCo" per
curve)."""

import re

import pytest

from robomech.studies import Progress, get_study

# The quick studies (the demonstration in 1 s, the other two in about 7 s each: marked slow).
FAST = ("demo", pytest.param("vectored-thrust", marks=pytest.mark.slow),
        pytest.param("spherical-leg", marks=pytest.mark.slow))  # fmt: skip
FIGURE_NUMBER = re.compile(r"\bFig(ure)?\.? ?\d")


def _check_figure(fig) -> list[str]:
    problems = []
    titles = [fig._suptitle.get_text()] if fig._suptitle is not None else []
    for ax in fig.axes:
        titles.append(ax.get_title())
        if ax.name == "3d" and not ax.get_zlabel():
            problems.append(f"3-D panel {ax.get_title()!r} has no z label")
        legend = ax.get_legend()
        if legend is None:
            continue
        words = [w for t in legend.get_texts() for w in t.get_text().split()]
        for source in ("MuJoCo", "analytic", "robomech"):
            if words.count(source) > 1:
                problems.append(f"legend of {ax.get_title()!r} names {source} {words.count(source)} times")
    problems += [f"title {t!r} carries a figure number" for t in titles if FIGURE_NUMBER.search(t)]
    return problems


@pytest.mark.parametrize("name", FAST)
def test_figure_titles_axes_and_legends(name, tmp_path, monkeypatch):
    study = get_study(name)
    module = __import__(study.run.__module__, fromlist=["save_figure"])
    real = module.save_figure
    problems: list[str] = []

    def checking_save(fig, out_dir, fname, caption):
        fig.canvas.draw()
        problems.extend(f"{fname}: {p}" for p in _check_figure(fig))
        return real(fig, out_dir, fname, caption)

    monkeypatch.setattr(module, "save_figure", checking_save)
    study.run(tmp_path, Progress(enabled=False))
    assert not problems, "\n".join(problems)
