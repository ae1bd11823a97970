"""Analysis tools reusable across mechanisms: mobility, batched least squares, workspace maps."""

from . import lstsq, mobility, workspace

__all__ = ["lstsq", "mobility", "workspace"]
