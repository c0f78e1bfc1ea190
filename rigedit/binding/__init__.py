"""Binding: the offline work that ties a skin to a skeleton (numpy + scipy).

Automatic weights (:mod:`.weights`: bone heat in :mod:`.heat` on the cotangent Laplacian of
:mod:`.laplacian`, with visibility from :mod:`.visibility` and bone tails from :mod:`.tails`;
inverse distance), weight painting (:mod:`.weight_paint`) and subdividing a skinned mesh with
its weights (:mod:`.subdivide`). What runs per frame (skinning) is in :mod:`rigedit.model`.
"""
from .weights import METHODS, compute_weights, default_method, idw_weights

__all__ = ["compute_weights", "default_method", "idw_weights", "METHODS"]
