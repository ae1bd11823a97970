"""The visual geometry of an MJCF file, per body, for the viewer (MuJoCo imported lazily).

A :class:`robomech.multibody.Mechanism` describes kinematics and inertia, not shapes; an MJCF file
also has geoms.  :func:`mjcf_geoms` compiles the file with MuJoCo (so defaults classes, ``fromto``
and meshes are MuJoCo's own) and returns each geom in its body's frame, keyed by body name, which
the viewer attaches to the description's body of the same name.  Planes and height fields (floors)
are left out: they are not part of the mechanism.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

__all__ = ["Geom", "mjcf_geoms"]

# MuJoCo's mjtGeom codes of the shapes drawn.
SHAPES = {2: "sphere", 3: "capsule", 4: "ellipsoid", 5: "cylinder", 6: "box", 7: "mesh"}


@dataclass(frozen=True)
class Geom:
    """One MJCF geom in its body's frame: ``type`` (sphere, capsule, ellipsoid, cylinder, box,
    mesh), MuJoCo's ``size`` (radii / half-lengths, m), pose ``pos`` / ``quat`` ``[w, x, y, z]``,
    ``rgba`` in [0, 1], and a mesh's ``vertices (n, 3)`` / ``faces (m, 3)`` (in the geom frame)."""

    body: str
    type: str
    size: NDArray[np.float64]
    pos: NDArray[np.float64]
    quat: NDArray[np.float64]
    rgba: NDArray[np.float64]
    vertices: NDArray[np.float64] | None = None
    faces: NDArray[np.int64] | None = None


def mjcf_geoms(path: str | Path) -> tuple[Geom, ...]:
    """The drawable geoms of the MJCF file ``path`` (needs MuJoCo: the ``verify`` extra)."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(path))
    out = []
    for g in range(model.ngeom):
        kind = SHAPES.get(int(model.geom_type[g]))
        if kind is None:
            continue
        verts = faces = None
        if kind == "mesh":
            k = int(model.geom_dataid[g])
            v0, nv = int(model.mesh_vertadr[k]), int(model.mesh_vertnum[k])
            f0, nf = int(model.mesh_faceadr[k]), int(model.mesh_facenum[k])
            verts = np.array(model.mesh_vert[v0 : v0 + nv], float)
            faces = np.array(model.mesh_face[f0 : f0 + nf], np.int64)
        out.append(
            Geom(
                body=model.body(int(model.geom_bodyid[g])).name,
                type=kind,
                size=np.array(model.geom_size[g], float),
                pos=np.array(model.geom_pos[g], float),
                quat=np.array(model.geom_quat[g], float),
                rgba=np.array(model.geom_rgba[g], float),
                vertices=verts,
                faces=faces,
            )
        )
    return tuple(out)
