"""The numpy formulation of the compiled kernels, kept here as the tests' reference.

The library runs one implementation per algorithm (the compiled kernels of
``robomech/multibody/_compiled.py``, at every batch size).  The same algorithms written batched in
numpy, from the layer's own tree and closure functions, are the independent formulation the kernels
are checked against: :func:`numpy_reference` swaps them in for the kernels inside a ``with`` block.
"""

from __future__ import annotations

import contextlib

import numpy as np

from robomech.multibody import _compiled, _dynamics
from robomech.multibody._assembly import solve_closure
from robomech.multibody._influence import _influence_flat
from robomech.multibody._tree import frame_jacobian


def _no_rows(state, q, idx):
    """No extra rows: ``solve_closure`` then runs its numpy Levenberg–Marquardt iteration."""
    n = len(idx)
    return np.zeros((n, 0)), np.zeros((n, 0, state.S.shape[1]))


def numpy_fk(mech, q, free):
    """The assembly of ``_compiled.compiled_fk`` by the numpy iteration: (q, rc, iterations, residual)."""
    q, rc, res, it = solve_closure(mech, np.array(q, dtype=float), np.asarray(free), _no_rows)
    return q, rc, it, res


def numpy_site_jacobian(mech, q, site):
    """``J = J_f G`` (``_compiled.compiled_site_jacobian``) from the numpy influence coefficients."""
    tree = mech.tree
    state, _, G, _, _, _ = _influence_flat(mech, q, False)
    b = tree.site_body[site]
    p = (state.T[:, b] @ tree.T_site[site])[:, :3, 3]
    return frame_jacobian(tree, state, b, p) @ G


@contextlib.contextmanager
def numpy_reference():
    """Inside the block, FK, site Jacobians and inverse dynamics run the numpy formulation."""
    saved = (_compiled.compiled_fk, _compiled.compiled_site_jacobian, _dynamics._inverse_compiled)
    _compiled.compiled_fk = numpy_fk
    _compiled.compiled_site_jacobian = numpy_site_jacobian
    _dynamics._inverse_compiled = _dynamics._inverse_flat
    try:
        yield
    finally:
        _compiled.compiled_fk, _compiled.compiled_site_jacobian, _dynamics._inverse_compiled = saved
