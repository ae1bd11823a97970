"""Importing robomech never switches matplotlib's backend (a notebook's inline plots survive)."""

import subprocess
import sys

# A backend that is neither matplotlib's default choice nor Agg: if an import switched it, the
# backend read back would differ.
USER_BACKEND = "svg"


def _backend_after(code: str) -> str:
    prog = (
        f"import matplotlib; matplotlib.use({USER_BACKEND!r})\n"
        + code
        + "\nimport matplotlib; print(matplotlib.get_backend())"
    )
    out = subprocess.run([sys.executable, "-c", prog], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip().splitlines()[-1]


def test_importing_the_studies_and_their_plots_keeps_the_users_backend():
    code = (
        "import robomech.studies as s; s.available_studies()\n"  # imports every study and _plot
        "import robomech.studies._plot, robomech.studies._animate\n"
        "from robomech import multibody as mb; mb.draw"
    )
    assert _backend_after(code).lower() == USER_BACKEND


def test_animate_leaves_the_users_backend_and_figures_alone(tmp_path):
    gif = tmp_path / "f.gif"
    code = (
        "import numpy as np, matplotlib.pyplot as plt\n"
        "from robomech import multibody as mb\n"
        "m = mb.gallery.load('four_bar'); fig = plt.figure()\n"
        "fk = mb.forward_kinematics(m, np.linspace(0.2, 0.4, 3)[:, None])\n"
        f"mb.animate(m, fk.q, {str(gif)!r})\n"
        "assert plt.get_fignums() == [fig.number], plt.get_fignums()"
    )
    assert _backend_after(code).lower() == USER_BACKEND
    assert gif.stat().st_size > 0


def test_the_command_line_renders_with_agg():
    out = subprocess.run(
        [sys.executable, "-c", "import sys; from robomech.cli import main; main(['list']);"
         "import matplotlib; print(matplotlib.get_backend(), file=sys.stderr)"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    assert out.stderr.strip().splitlines()[-1].lower() == "agg"
