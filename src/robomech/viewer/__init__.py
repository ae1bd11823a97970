"""See a described mechanism in 3-D, live, in the browser (viser; the ``view`` extra).

::

    from robomech import multibody as mb
    v = mb.view(mb.gallery.load("delta"))      # or robomech.viewer.view; `robomech view delta` from a shell
    v.url                                      # http://127.0.0.1:PORT (an iframe inline in Jupyter)
    v.set_q_act([0.1, 0.2, 0.3])               # what a slider does: re-assemble from the pose shown
    v.stop()

Every body is drawn as the links joining the points it carries (``_scene``), joints as spheres with
their axes, sites and (optionally) body frames as triads; one slider per actuated joint re-assembles
the mechanism from the pose shown (a pose that does not assemble turns red, with its residual), the
singularity measures of the output site are shown live, a path (``mb.simulate(...)``) plays back, and
a button downloads a screenshot.  viser is imported when a viewer starts, never at import.
"""

from __future__ import annotations

from ._server import Pose, Viewer, view

__all__ = ["Pose", "Viewer", "view"]
