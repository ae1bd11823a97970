"""The text of the study figures: titles say what is shown (the paper's figure numbers belong in
the captions), every 3-D panel labels its z axis, a legend names each source once (not "MuJoCo" per
curve).  The same runs check that each study plans its steps (the progress bar's n/N)."""

import importlib.util
import re

import pytest

from robomech.studies import Progress, get_study

# Every study: the demonstration in 1 s; the others take 7 s (vectored-thrust, spherical-leg) to
# minutes (skid-steer) and are marked slow.
FAST = ("demo", *(pytest.param(name, marks=pytest.mark.slow) for name in (
    "vectored-thrust", "spherical-leg", "omnileg", "continuum", "skid-steer")))  # fmt: skip
FIGURE_NUMBER = re.compile(r"\bFig(ure)?\.? ?\d")


class _CountingProgress(Progress):
    """Counts the steps taken against the plan (steps of ``iter`` without a bar are not counted)."""

    def __init__(self) -> None:
        super().__init__(enabled=False)
        self.planned: int | None = None
        self.taken = 0

    def plan(self, names) -> None:
        super().plan(names)
        self.planned = len(list(names))

    def step(self, message: str) -> None:
        super().step(message)
        self.taken += 1

    def iter(self, items, label, every=None):
        yield from items


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
    if hasattr(module, "animation_figure"):  # an animation's title is a figure title too
        real_animation = module.animation_figure

        def checking_animation(*args, title="", **kwargs):
            if FIGURE_NUMBER.search(title):
                problems.append(f"animation title {title!r} carries a figure number")
            return real_animation(*args, title=title, **kwargs)

        monkeypatch.setattr(module, "animation_figure", checking_animation)
    if requires := [m for m in study.requires if not importlib.util.find_spec(m)]:
        pytest.skip(f"{name} needs {requires}")
    progress = _CountingProgress()
    study.run(tmp_path, progress)
    assert not problems, "\n".join(problems)
    assert progress.planned == progress.taken, "the study's plan does not count its steps"
