"""Forward differentiation along a motion ``(q, q̇, q̈)``, batched (private): a :class:`Jet` carries a
quantity's value ``v``, time derivatives ``vd``, ``vdd`` and gradient ``g[k] = ∂x/∂q_k``, the derivative axis
leading (``(n, *S)`` for a value of shape ``S``) so that broadcasting applies the chain and product rules."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Jet:
    v: Array
    vd: Array
    vdd: Array
    g: Array

    # ndarray (+, *) Jet must call Jet's reflected operators, not broadcast the Jet as an object
    __array_ufunc__ = None

    @staticmethod
    def variables(q: Array, qd: Array, qdd: Array) -> list[Jet]:
        """The coordinates themselves: one jet per column of ``q (N, n)`` (flattened batch)."""
        N, n = q.shape
        out = []
        for k in range(n):
            g = np.zeros((n, N))
            g[k] = 1.0
            out.append(Jet(q[:, k], qd[:, k], qdd[:, k], g))
        return out

    def __add__(self, o: Jet | Array | float) -> Jet:
        if isinstance(o, Jet):
            return Jet(self.v + o.v, self.vd + o.vd, self.vdd + o.vdd, self.g + o.g)
        o = np.asarray(o, dtype=float)
        z = 0.0 * o
        return Jet(self.v + o, self.vd + z, self.vdd + z, self.g + z)

    __radd__ = __add__

    def __neg__(self) -> Jet:
        return Jet(-self.v, -self.vd, -self.vdd, -self.g)

    def __mul__(self, o: Jet | Array | float) -> Jet:
        return bilinear(self, o, np.multiply)

    __rmul__ = __mul__

    def expand(self) -> Jet:
        """Add a trailing value axis (a per-sample scalar that multiplies a vector)."""
        return Jet(self.v[..., None], self.vd[..., None], self.vdd[..., None], self.g[..., None])


def bilinear(a: Jet | Array | float, b: Jet | Array | float, op: Callable[[Array, Array], Array]) -> Jet:
    """Product rule for any bilinear ``op`` (multiply, cross, dot) of jets or constants."""
    if not isinstance(a, Jet):
        if not isinstance(b, Jet):
            raise TypeError("bilinear: expected at least one Jet operand")
        ca = np.asarray(a, dtype=float)
        return Jet(op(ca, b.v), op(ca, b.vd), op(ca, b.vdd), op(ca, b.g))
    if not isinstance(b, Jet):
        cb = np.asarray(b, dtype=float)
        return Jet(op(a.v, cb), op(a.vd, cb), op(a.vdd, cb), op(a.g, cb))
    return Jet(
        op(a.v, b.v),
        op(a.vd, b.v) + op(a.v, b.vd),
        op(a.vdd, b.v) + 2.0 * op(a.vd, b.vd) + op(a.v, b.vdd),
        op(a.g, b.v) + op(a.v, b.g),
    )


def unary(x: Jet, f: Array, f1: Array, f2: Array) -> Jet:
    """Chain rule for ``f(x)`` given ``f, f', f''`` evaluated at ``x.v``."""
    return Jet(f, f1 * x.vd, f2 * x.vd * x.vd + f1 * x.vdd, f1 * x.g)


def sin(x: Jet) -> Jet:
    s, c = np.sin(x.v), np.cos(x.v)
    return unary(x, s, c, -s)


def cos(x: Jet) -> Jet:
    s, c = np.sin(x.v), np.cos(x.v)
    return unary(x, c, -s, -c)


def tan(x: Jet) -> Jet:
    t = np.tan(x.v)
    d = 1.0 + t * t
    return unary(x, t, d, 2.0 * t * d)


def reciprocal(x: Jet) -> Jet:
    r = 1.0 / x.v
    return unary(x, r, -r * r, 2.0 * r * r * r)


def sqrt(x: Jet) -> Jet:
    s = np.sqrt(x.v)
    return unary(x, s, 0.5 / s, -0.25 / (s * x.v))


def stack(items: list[Jet | Array]) -> Jet:
    """Stack scalar-per-sample jets (or constant arrays) along a new last value axis."""
    jets = [i for i in items if isinstance(i, Jet)]
    ref = jets[0]
    n = ref.g.shape[0]
    shape = np.broadcast_shapes(*(j.v.shape for j in jets))

    def parts(i: Jet | Array) -> tuple[Array, Array, Array, Array]:
        if isinstance(i, Jet):
            return (
                np.broadcast_to(i.v, shape),
                np.broadcast_to(i.vd, shape),
                np.broadcast_to(i.vdd, shape),
                np.broadcast_to(i.g, (n, *shape)),
            )
        c = np.broadcast_to(np.asarray(i, dtype=float), shape)
        z = np.zeros(shape)
        return c, z, z, np.zeros((n, *shape))

    ps = [parts(i) for i in items]
    return Jet(*(np.stack([p[k] for p in ps], axis=-1) for k in range(4)))


def cross3(x: Array, y: Array) -> Array:
    """Cross product over the last axis (broadcasting), without np.cross's axis shuffling."""
    x0, x1, x2 = x[..., 0], x[..., 1], x[..., 2]
    y0, y1, y2 = y[..., 0], y[..., 1], y[..., 2]
    return np.stack([x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0], axis=-1)


def cross(a: Jet | Array, b: Jet | Array) -> Jet:
    return bilinear(a, b, cross3)


def dot(a: Jet, b: Jet | Array) -> Jet:
    return bilinear(a, b, lambda x, y: np.sum(x * y, axis=-1))


def atan2(y: Jet, x: Jet) -> Jet:
    """``atan2(y, x)`` of two scalar jets (x² + y² > 0)."""
    r2 = x.v * x.v + y.v * y.v
    num_d = x.v * y.vd - y.v * x.vd
    vd = num_d / r2
    vdd = (x.v * y.vdd - y.v * x.vdd) / r2 - num_d * 2.0 * (x.v * x.vd + y.v * y.vd) / (r2 * r2)
    g = (x.v * y.g - y.v * x.g) / r2
    return Jet(np.arctan2(y.v, x.v), vd, vdd, g)


def rotate_const(S: Array, x: Jet) -> Jet:
    """``S x`` for a constant matrix ``S (3, 3)`` and a vector jet (as one BLAS product per part)."""
    St = np.asarray(S, dtype=float).T
    return Jet(x.v @ St, x.vd @ St, x.vdd @ St, x.g @ St)
