"""Continuous refinement of the embedded reduced joints (placeholder: identity)."""
from __future__ import annotations

__all__ = ["refine"]


def refine(field, template, positions, scale, frame):
    """Refined reduced joint positions (R, 3) and scale."""
    return positions, scale
