"""Every example in a public module's docstrings runs as a doctest (numpydoc ``Examples`` sections)."""

import doctest
import importlib
import pkgutil

import pytest

import robomech


def _modules() -> list[str]:
    names = ["robomech"]
    for m in pkgutil.walk_packages(robomech.__path__, "robomech."):
        if m.name.rsplit(".", 1)[-1] != "__main__":  # importing it would run the command
            names.append(m.name)
    return sorted(names)


MODULES = _modules()
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


@pytest.mark.parametrize("modname", MODULES)
def test_docstring_examples_run(modname):
    module = importlib.import_module(modname)
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    report: list[str] = []
    for test in finder.find(module, modname):
        if test.examples:
            runner.run(test, out=report.append)
    failed, _ = runner.summarize(verbose=False)
    assert failed == 0, "".join(report)


def test_there_are_examples_to_run():
    count = 0
    for modname in MODULES:
        module = importlib.import_module(modname)
        for test in doctest.DocTestFinder(exclude_empty=True).find(module, modname):
            count += len(test.examples)
    assert count >= 5, "the numpydoc Examples sections have gone"
